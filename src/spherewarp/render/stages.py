"""The table of compiled stages: one record per kind of map the compiled renderer runs.

A map that the compiled kernel can evaluate describes itself as *stages*
(:meth:`~spherewarp.maps.SphereMap.kernel_stages`): ``(name, params)`` pairs
in application order, each ``params`` a float64 row packed with
:meth:`Stage.pack`. This module is the one place where a stage's layout
lives: its integer code, its named fields (the offsets the kernel and the
browser shader read), the variable-length tail some stages have, whether the
map jumps between neighbouring pixels, a bound of its magnification and the
check of its parameters.

* the maps pack their rows through it (``STAGE.pack(field=value, ...)``);
* :mod:`spherewarp.render.fast` validates rows, bounds the magnification and
  finds the stages with jumps through it;
* :mod:`spherewarp.render._kernels` takes its codes and offsets from the
  module constants made from the table (:func:`constants`: ``STAGE_<NAME>``,
  ``<NAME>_<FIELD>``, ...): numba reads module globals as compile-time
  constants;
* :func:`glsl_header` and :func:`as_json` give the same layout to a shader.

This module imports only NumPy and the standard library (no numba).

Adding a compiled map (a new map family)
----------------------------------------
1. its own file in :mod:`spherewarp.maps`: ``kernel_stages()`` returns
   ``(("name", BY_NAME["name"].pack(...)),)`` (with the Möbius stages of its chart
   around it, if any);
2. one :class:`Stage` entry in :data:`STAGES` here (the next code); its
   constants follow from it;
3. one kernel function ``_stage_<name>(p, T, X, Y, Z, G, valid, n)`` in
   :mod:`spherewarp.render._kernels`, reading ``p[NAME_FIELD]``, with its
   branch in ``run_stages``; then update ``_kernels._TABLE_FINGERPRINT``
   (numba's disk cache only sees ``_kernels.py``: the fingerprint check at
   import makes a table change touch that file, which recompiles it).

Examples
--------
>>> BY_NAME["power"].code, BY_NAME["power"].fields
(2, ('m',))
>>> row = BY_NAME["exp"].pack(lam=4.0, near=0.01, cap=1e9)
>>> row.tolist(), BY_NAME["exp"].offset("cap")
([4.0, 0.01, 1000000000.0], 2)
>>> BY_NAME["exp"].unpack(row)["lam"]
4.0
>>> print(glsl_header().splitlines()[1])
#define STAGE_MOBIUS 1
"""

from __future__ import annotations

import hashlib
import json
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "BY_CODE",
    "BY_NAME",
    "SCHOTTKY_RECORD",
    "STAGES",
    "Stage",
    "as_json",
    "constants",
    "fingerprint",
    "glsl_header",
    "lorentz_from_sl2",
]

Row = NDArray[np.float64]


def _unbounded(row: Row) -> float:
    return math.inf


def _no_problem(row: Row) -> str | None:
    return None


@dataclass(frozen=True)
class Stage:
    """One kind of compiled stage: its code and the layout of its parameter row.

    Attributes
    ----------
    name : str
        The kind's name, as maps return it from ``kernel_stages()``.
    code : int
        The integer the kernel dispatches on (``run_stages``).
    fields : tuple of str
        The named floats at the start of the kernel's row, in order
        (:meth:`offset`).
    tail : str or None
        The name of a variable-length float tail after the fields (None: none).
    tail_record : tuple of str
        The layout of one record of the tail (``("value",)``: plain floats);
        :meth:`tail_offset` gives the offsets inside a record.
    has_jumps : bool
        Whether the map jumps between neighbouring pixels (seams, disk edges):
        the renderer then looks for jumps and supersamples the pixels on them.
    max_scale : callable
        ``max_scale(row) -> float``: an upper bound of the stage's spherical
        magnification from its kernel row (``inf`` if none is known).
    validate : callable
        ``validate(row) -> str | None``: what is wrong with a (finite,
        long enough) packed row, or None.
    args : tuple of str or None
        What a map packs when it is not the kernel row (the Möbius stage packs
        its SL(2, C) matrix, which :attr:`lower` turns into the Lorentz matrix
        the kernel reads); None: the map packs the kernel row itself.
    lower : callable or None
        ``lower(packed) -> kernel row`` when :attr:`args` is set.
    doc : str
        One line on what the stage is.
    """

    name: str
    code: int
    fields: tuple[str, ...]
    tail: str | None = None
    tail_record: tuple[str, ...] = ("value",)
    has_jumps: bool = False
    max_scale: Callable[[Row], float] = _unbounded
    validate: Callable[[Row], str | None] = _no_problem
    args: tuple[str, ...] | None = None
    lower: Callable[[Row], Row] | None = None
    doc: str = ""

    # -- layout -------------------------------------------------------------------------------
    @property
    def packed_fields(self) -> tuple[str, ...]:
        """The fixed fields a map packs (:attr:`args`, else :attr:`fields`)."""
        return self.args if self.args is not None else self.fields

    def offset(self, field: str) -> int:
        """Index of ``field`` in the kernel's row (the tail's name: where the tail starts).

        Examples
        --------
        >>> BY_NAME["droste"].offset("cap"), BY_NAME["droste"].offset("rho")
        (7, 9)
        """
        if field in self.fields:
            return self.fields.index(field)
        if self.tail is not None and field == self.tail:
            return len(self.fields)
        raise KeyError(f"stage {self.name!r} has no field {field!r} (fields: {self.fields})")

    def tail_offset(self, field: str) -> int:
        """Index of ``field`` inside one record of the tail.

        Examples
        --------
        >>> BY_NAME["rational"].tail_offset("im"), BY_NAME["schottky"].tail_offset("l00")
        (1, 4)
        """
        if self.tail is None or field not in self.tail_record:
            raise KeyError(f"stage {self.name!r} has no tail field {field!r}")
        return self.tail_record.index(field)

    # -- rows -----------------------------------------------------------------------------------
    def pack(self, **values: ArrayLike) -> Row:
        """The float64 row of the given fields (and tail), as a map returns it.

        Fields are scalars; the tail (by its name) is an array, flattened (complex
        values become ``(re, im)`` pairs). Raises TypeError for a missing or an
        unknown field.

        Examples
        --------
        >>> BY_NAME["power"].pack(m=3).tolist()
        [3.0]
        >>> BY_NAME["power"].pack(n=3)
        Traceback (most recent call last):
        ...
        TypeError: stage 'power': unknown field(s) ['n'], missing ['m']
        """
        names = self.packed_fields
        want = set(names) | ({self.tail} if self.tail is not None else set())
        unknown = sorted(set(values) - want)
        missing = [f for f in (*names, *([self.tail] if self.tail else [])) if f not in values]
        if unknown or missing:
            raise TypeError(f"stage {self.name!r}: unknown field(s) {unknown}, missing {missing}")
        head = np.array([float(np.real(values[f])) for f in names], dtype=np.float64)
        if self.tail is None:
            return head
        t = np.asarray(values[self.tail])
        if np.iscomplexobj(t):
            t = np.ascontiguousarray(t, np.complex128).view(np.float64)
        return np.concatenate([head, np.asarray(t, dtype=np.float64).ravel()])

    def unpack(self, row: ArrayLike) -> dict[str, Any]:
        """The fields of a packed row by name (the tail as an array).

        Examples
        --------
        >>> BY_NAME["droste"].unpack(np.arange(11.0))["rho"].tolist()
        [9.0, 10.0]
        """
        row = np.asarray(row, dtype=np.float64).ravel()
        names = self.packed_fields
        if row.size < len(names) or (self.tail is None and row.size != len(names)):
            raise ValueError(f"stage {self.name!r}: a row of {row.size} floats does not fit")
        out: dict[str, Any] = {f: float(row[i]) for i, f in enumerate(names)}
        if self.tail is not None:
            out[self.tail] = row[len(names) :].copy()
        return out

    def problem(self, row: ArrayLike) -> str | None:
        """What is wrong with a packed row for the kernel, or None if it is fine.

        Examples
        --------
        >>> BY_NAME["power"].problem(np.array([2.5]))
        'power: m must be a non-zero integer of at most 1024'
        >>> BY_NAME["power"].problem(np.array([2.0])) is None
        True
        """
        row = np.asarray(row, dtype=np.float64).ravel()
        n = len(self.packed_fields)
        if not np.all(np.isfinite(row)):
            return f"{self.name}: parameters must be finite"
        if row.size < n + (1 if self.tail is not None else 0) or (
            self.tail is None and row.size != n
        ):
            return f"{self.name}: expected {n} floats{' and a tail' if self.tail else ''}"
        return self.validate(row)

    def kernel_row(self, packed: ArrayLike) -> Row:
        """The row the kernel reads from a packed row (:attr:`lower`, if any)."""
        packed = np.asarray(packed, dtype=np.float64).ravel()
        return self.lower(packed) if self.lower is not None else packed


# -- the stages ------------------------------------------------------------------------------------
def lorentz_from_sl2(m: NDArray[np.complex128]) -> NDArray[np.float64]:
    """The 4x4 Lorentz matrix of the Möbius map ``m`` on ``(t, x, y, z)``.

    A point ``(x, y, z)`` of the sphere is the null vector ``(1, x, y, z)``,
    that is the Hermitian matrix ``P = psi psi^H`` of its unit pair ``psi``
    (see :func:`spherewarp.coords.xyz_from_cp1`); the map acts as
    ``P -> m P m^H``. The image point is ``(x', y', z') / t'`` and the map's
    spherical magnification there is ``1 / t'``.

    Examples
    --------
    >>> from spherewarp.maps import Mobius
    >>> m = Mobius.zoom((30, 10), 2.0)
    >>> L = lorentz_from_sl2(m.matrix)
    >>> v = np.array([0.6, 0.0, 0.8])
    >>> t, *xyz = L @ np.r_[1.0, v]
    >>> bool(np.allclose(np.array(xyz) / t, m.apply_xyz(v)))
    True
    """
    m = np.asarray(m, dtype=np.complex128)

    def herm(t: float, x: float, y: float, z: float) -> NDArray[np.complex128]:
        return np.array([[(t - z) / 2, -(x + 1j * y) / 2], [-(x - 1j * y) / 2, (t + z) / 2]])

    out = np.empty((4, 4))
    for k, e in enumerate(np.eye(4)):
        p = m @ herm(*e) @ m.conj().T
        out[:, k] = [
            (p[0, 0] + p[1, 1]).real,
            -2 * p[0, 1].real,
            -2 * p[0, 1].imag,
            (p[1, 1] - p[0, 0]).real,
        ]
    return out


def _mobius_lower(packed: Row) -> Row:
    mat = packed.view(np.complex128).reshape(2, 2)
    return lorentz_from_sl2(mat / np.sqrt(np.linalg.det(mat))).ravel()


def _mobius_scale(row: Row) -> float:
    # magnification 1/t' >= ..., with min over the sphere of t' = L00 - |L0,1:|
    tmin = row[0] - np.linalg.norm(row[1:4])
    return 1.0 / tmin if tmin > 0 else math.inf


def _mobius_check(row: Row) -> str | None:
    mat = row.view(np.complex128).reshape(2, 2)
    return None if np.linalg.det(mat) != 0 else "mobius: the matrix is singular"


def _is_int(v: float) -> bool:
    return float(v).is_integer()


def _power_check(row: Row) -> str | None:
    m = row[0]
    if m != 0 and _is_int(m) and abs(m) <= 1024:
        return None
    return "power: m must be a non-zero integer of at most 1024"


def _exp_check(row: Row) -> str | None:
    return None if row[0] > 0 else "exp: lam must be positive"


def _rational_check(row: Row) -> str | None:
    d = row[0]
    if row.size >= 5 and _is_int(d) and row.size == 1 + 4 * (int(d) + 1):
        return None
    return "rational: expected the degree d, then 2 (d + 1) complex coefficients"


def _droste_check(row: Row) -> str | None:
    m = row[0]
    if row.size >= 9 + 1 and m >= 1 and row.size == 9 + int(m) and row[1] > 0:
        return None
    return "droste: expected m >= 1 rho samples after 9 fields, and ell > 0"


_LORENTZ = tuple(f"l{i}{j}" for i in range(4) for j in range(4))

#: one reduction move of the Schottky stage: the open disk ``n . v > cos_r`` a point must be
#: in, and the Lorentz matrix (row-major) applied to it there
SCHOTTKY_RECORD = ("nx", "ny", "nz", "cos_r", *_LORENTZ)


def _schottky_check(row: Row) -> str | None:
    count, depth = row[0], row[1]
    rec = len(SCHOTTKY_RECORD)
    if not (_is_int(count) and count >= 1 and _is_int(depth) and 0 <= depth <= 1_000_000):
        return "schottky: count must be a positive integer and depth a non-negative one"
    if row.size != 2 + 2 * rec * int(count):
        return f"schottky: expected 2 moves of {rec} floats per generator"
    moves = row[2:].reshape(-1, rec)
    if np.any(np.abs(moves[:, 3]) > 1):
        return "schottky: cos_r must be in [-1, 1]"
    return None


def _schottky_mask_check(row: Row) -> str | None:
    count, depth, w, h = row[0], row[1], row[2], row[3]
    if not (_is_int(count) and count >= 1 and _is_int(depth) and 0 <= depth <= 1_000_000):
        return "schottky_mask: count must be a positive integer and depth a non-negative one"
    if not (_is_int(w) and _is_int(h) and w >= 1 and h >= 1):
        return "schottky_mask: width and height must be positive integers"
    if row.size != 4 + 2 * 16 * int(count) + int(w) * int(h):
        return "schottky_mask: expected 2 Lorentz matrices per generator, then the labels"
    labels = row[4 + 32 * int(count) :]
    if not np.all((labels == np.floor(labels)) & (labels >= -1) & (labels < count)):
        return "schottky_mask: labels must be -1 or a generator's index"
    return None


STAGES: tuple[Stage, ...] = (
    Stage(
        "mobius", 1, _LORENTZ,
        max_scale=_mobius_scale, validate=_mobius_check,
        args=("a_re", "a_im", "b_re", "b_im", "c_re", "c_im", "d_re", "d_im"),
        lower=_mobius_lower,
        doc="a Möbius map: packed as its matrix [[a, b], [c, d]], run as its Lorentz matrix "
        "l00..l33 (row-major) on (t, x, y, z); consecutive ones are multiplied into one",
    ),
    Stage(
        "power", 2, ("m",),
        max_scale=lambda row: abs(float(row[0])),  # |m| r^(|m|-1) (1 + r^2) / (1 + r^(2|m|))
        validate=_power_check,
        doc="(z, w) -> (z^m, w^m), m a non-zero integer (maps.Power)",
    ),
    Stage(
        "exp", 3, ("lam", "near", "cap"), has_jumps=True, validate=_exp_check,
        doc="S(z) = -exp(-lam (1 + z) / (1 - z)); within the squared chordal radius near "
        "of z = 1 the limit, with magnification cap (maps.ExpMap)",
    ),
    Stage(
        "rational", 4, ("degree",), tail="coefficients", tail_record=("re", "im"),
        validate=_rational_check,
        doc="(z, w) -> (N(z, w), D(z, w)): the d + 1 coefficients of N, then of D, highest "
        "degree first (maps.Rational)",
    ),
    Stage(
        "droste", 5,
        ("m", "ell", "beta_re", "beta_im", "pivot", "c_re", "c_im", "cap", "beta_abs"),
        tail="rho", has_jumps=True, validate=_droste_check,
        doc="a straight or twisted Droste map in its own chart: Ls = beta (log zeta - pivot) + "
        "c reduced into the strip rho(theta) <= Re < rho(theta) + ell (maps.Droste)",
    ),
    Stage(
        "schottky", 6, ("count", "depth"), tail="moves", tail_record=SCHOTTKY_RECORD,
        has_jumps=True, validate=_schottky_check,
        doc="the Schottky reduction: while the point is in the open disk of a move (not the "
        "undoing of the last one), apply that move's matrix; invalid after depth moves "
        "(maps.Schottky; moves 2i and 2i + 1: D_x with X, D_X with X^-1)",
    ),
    Stage(
        "schottky_mask", 7, ("count", "depth", "width", "height"), tail="data",
        has_jumps=True, validate=_schottky_mask_check,
        doc="the Schottky reduction with the exact disks of a mask: data holds the Lorentz "
        "matrices of X and X^-1 of each generator (16 floats each, row-major), then the "
        "mask's labels (width x height, row-major: -1 or the generator whose D_x holds the "
        "pixel). Move 2i (D_x: the point's label is i) applies X, move 2i + 1 (D_X: the "
        "label of X^-1 of the point is not i) applies X^-1; as schottky otherwise "
        "(maps.Schottky.with_mask_regions)",
    ),
)  # fmt: skip

BY_NAME: Mapping[str, Stage] = {s.name: s for s in STAGES}
BY_CODE: Mapping[int, Stage] = {s.code: s for s in STAGES}
assert [s.code for s in STAGES] == list(range(1, len(STAGES) + 1))

MOBIUS = BY_NAME["mobius"]
POWER = BY_NAME["power"]
EXP = BY_NAME["exp"]
RATIONAL = BY_NAME["rational"]
DROSTE = BY_NAME["droste"]
SCHOTTKY = BY_NAME["schottky"]
SCHOTTKY_MASK = BY_NAME["schottky_mask"]


# -- compile-time constants of the kernels (numba reads module globals as constants) ---------------
def _macro(s: str) -> str:
    return s.upper()


def constants(extra: tuple[Stage, ...] = ()) -> dict[str, int]:
    """The codes and offsets by name, as :func:`glsl_header` defines them.

    ``STAGE_<NAME>`` is a stage's code, ``<NAME>_<FIELD>`` the offset of a
    field in its kernel row (the tail's name: where the tail starts), and for a
    tail of records ``<NAME>_<TAIL>_SIZE`` and ``<NAME>_<TAIL>_<FIELD>`` the
    record's size and the offsets inside it. Each is also a module constant
    (:mod:`spherewarp.render._kernels` imports them).

    Examples
    --------
    >>> c = constants()
    >>> c["STAGE_DROSTE"], c["DROSTE_RHO"], c["SCHOTTKY_MOVES_SIZE"], c["SCHOTTKY_MOVES_L00"]
    (5, 9, 20, 4)
    """
    table = (*STAGES, *extra)
    out = {f"STAGE_{_macro(s.name)}": s.code for s in table}
    for s in table:
        n = _macro(s.name)
        out.update({f"{n}_{_macro(f)}": s.offset(f) for f in s.fields})
        if s.tail is not None:
            t = _macro(s.tail)
            out[f"{n}_{t}"] = s.offset(s.tail)
            if s.tail_record != ("value",):
                out[f"{n}_{t}_SIZE"] = len(s.tail_record)
                out.update({f"{n}_{t}_{_macro(f)}": i for i, f in enumerate(s.tail_record)})
    return out


globals().update(constants())


# -- for shaders and tools -------------------------------------------------------------------------
def glsl_header(extra: tuple[Stage, ...] = ()) -> str:
    """``#define`` lines of the stage codes and field offsets, for a GLSL shader.

    The names and values of :func:`constants` (with those of ``extra``: stages only
    a shader has, such as the viewer's expression stage).

    Examples
    --------
    >>> "#define DROSTE_RHO 9" in glsl_header().splitlines()
    True
    """
    lines = ["// generated by spherewarp.render.stages.glsl_header(): do not edit"]
    lines += [f"#define {k} {v}" for k, v in constants(extra).items()]
    return "\n".join(lines) + "\n"


def as_json(extra: tuple[Stage, ...] = ()) -> str:
    """The table as JSON: for each stage its name, code, fields, tail, tail record,
    jumps, what a map packs (``args``, when it is not the row) and a line of doc
    (``extra``: stages only a shader has, after the table's).

    Examples
    --------
    >>> table = json.loads(as_json())
    >>> table["stages"][0]["name"], table["stages"][0]["code"], len(table["stages"][0]["fields"])
    ('mobius', 1, 16)
    """
    table = (*STAGES, *extra)
    return json.dumps({"version": 1, "stages": [_record(s) for s in table]}, indent=1)


def _record(s: Stage) -> dict[str, Any]:
    return {
        "name": s.name,
        "code": s.code,
        "fields": list(s.fields),
        "tail": s.tail,
        "tail_record": list(s.tail_record) if s.tail is not None else None,
        "has_jumps": s.has_jumps,
        "args": list(s.args) if s.args is not None else None,
        "doc": s.doc,
    }


def fingerprint() -> str:
    """A short hash of the codes and layouts (checked by the kernels at import).

    Examples
    --------
    >>> len(fingerprint())
    12
    """
    layout = [[s.name, s.code, s.fields, s.tail, s.tail_record] for s in STAGES]
    return hashlib.sha256(json.dumps(layout).encode()).hexdigest()[:12]
