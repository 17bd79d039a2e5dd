"""Möbius transformations of the Riemann sphere.

A Möbius transformation ``z -> (a z + b)/(c z + d)`` is stored as its matrix
normalised to determinant 1 (an element of SL(2, C)); the matrix and its
negative are the same map. Rotations of the sphere are exactly the unitary
matrices (SU(2)); zooms fixing two antipodal points are the positive
Hermitian ones.

Points may be given to the constructors as

* ``(lon, lat)`` in degrees (a pair of real numbers),
* a unit vector ``(x, y, z)`` (three real numbers, see :mod:`spherewarp.coords`),
* a complex number: a point of the plane in the default chart (0 at the
  zenith, ``complex("inf")`` at the nadir, 1 at the back, -1 at the front),
* a complex NumPy array of shape (2,): a homogeneous pair ``(z, w)``.

Convention: a rotation by a positive angle about a point turns the sphere
counter-clockwise as seen from the centre of the sphere looking at that point
(in the equirectangular image, which shows the view from inside, content
near the point turns counter-clockwise).

Examples
--------
>>> from spherewarp.maps import Mobius
>>> r = Mobius.rotation((0, 0), 90)        # about the front point
>>> r.apply_lonlat([10.0, 0.0]).round(9)   # right of the front goes up
array([ 0., 10.])
>>> Mobius.zoom((0, 0), 2).classify()
'hyperbolic'
"""

from __future__ import annotations

import cmath
import math
import numbers
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import coords
from ..errors import InvalidTypeError, InvalidValueError
from .base import SphereMap, register_map

__all__ = ["Mobius", "PointLike", "as_cp1_point"]

PointLike = complex | float | Sequence[float] | NDArray[Any]

_TOL = 1e-9


def as_cp1_point(point: PointLike, name: str = "point") -> NDArray[np.complex128]:
    """One point of the sphere as a unit-norm pair (see the module docstring).

    Examples
    --------
    >>> as_cp1_point((0.0, 90.0)).round(12)
    array([-0.+0.j,  1.+0.j])
    >>> as_cp1_point(complex("inf"))
    array([1.+0.j, 0.+0.j])
    """
    if isinstance(point, (complex, float, int, np.number)):
        c = complex(point)
        if cmath.isnan(c):
            raise InvalidValueError(f"{name}: expected a number or inf, got {point!r}")
        return coords.cp1_from_plane(c)
    if isinstance(point, np.ndarray) and np.iscomplexobj(point):
        if point.shape != (2,) or not np.all(np.isfinite(point)) or not np.any(point):
            raise InvalidValueError(f"{name}: expected a homogeneous pair (z, w), got {point!r}")
        return coords.normalize_cp1(point)
    try:
        arr = np.asarray(point, dtype=np.float64)
    except (TypeError, ValueError):
        raise InvalidValueError(
            f"{name}: expected (lon, lat) in degrees, an (x, y, z) vector or a complex "
            f"number, got {point!r}"
        ) from None
    if arr.shape == (2,):
        if not np.all(np.isfinite(arr)) or abs(arr[1]) > 90:
            raise InvalidValueError(f"{name}: expected lat in [-90, 90], got {tuple(arr)}")
        return coords.cp1_from_lonlat(np.radians(arr))
    if arr.shape == (3,):
        n = np.linalg.norm(arr)
        if not np.isfinite(n) or n == 0:
            raise InvalidValueError(f"{name}: expected a non-zero finite vector, got {tuple(arr)}")
        return coords.cp1_from_xyz(arr / n)
    raise InvalidValueError(
        f"{name}: expected (lon, lat) in degrees, an (x, y, z) vector or a complex number, "
        f"got an array of shape {arr.shape}"
    )


def _det(p: NDArray[np.complex128], q: NDArray[np.complex128]) -> complex:
    return complex(p[0] * q[1] - p[1] * q[0])


def _complex_to_json(c: complex) -> list[float]:
    return [float(c.real), float(c.imag)]


def _complex_from_json(v: Any) -> complex:
    if isinstance(v, (list, tuple)) and len(v) == 2:
        return complex(float(v[0]), float(v[1]))
    if isinstance(v, str):
        return complex(v.replace(" ", "").replace("i", "j"))
    return complex(v)


@register_map
class Mobius(SphereMap):
    """A Möbius transformation, stored as a normalised SL(2, C) matrix.

    Build it with the named constructors (:meth:`rotation`, :meth:`zoom`,
    :meth:`from_points`, ...) or from a raw matrix ``Mobius([[a, b], [c, d]])``.
    Instances are immutable; ``f @ g`` is f after g and stays a Möbius map;
    ``f == g`` compares the maps (the matrices up to sign, to 1e-12).

    Parameters
    ----------
    matrix : array_like, shape (2, 2)
        Any invertible complex matrix; it is scaled to determinant 1.

    Raises
    ------
    InvalidValueError
        If the matrix is not 2x2, not finite, or singular.

    Examples
    --------
    >>> m = Mobius([[1, 0.5], [0, 1]])   # the paper's parabolic z + 1/2
    >>> complex(m(1j))
    (0.5+1j)
    >>> m.classify()
    'parabolic'
    """

    kind = "mobius"

    def __init__(self, matrix: ArrayLike):
        try:
            m = np.array(matrix, dtype=np.complex128)
        except (TypeError, ValueError):
            raise InvalidValueError(f"expected a 2x2 complex matrix, got {matrix!r:.80}") from None
        if m.shape != (2, 2):
            raise InvalidValueError(f"expected a 2x2 matrix, got shape {m.shape}")
        if not np.all(np.isfinite(m)):
            raise InvalidValueError("expected a finite matrix, got NaN or inf entries")
        # max of |re|, |im| cannot overflow where |entry| could
        scale = max(float(np.abs(m.real).max()), float(np.abs(m.imag).max()))
        if scale == 0:
            raise InvalidValueError("expected an invertible matrix, got the zero matrix")
        with np.errstate(over="ignore", invalid="ignore"):
            m = m / scale  # complex division of subnormals can overflow: checked below
        det = m[0, 0] * m[1, 1] - m[0, 1] * m[1, 0]
        if not np.all(np.isfinite(m)) or not abs(det) >= 1e-13:
            # Scale-free (the matrix is projective) and bounded, so it cannot overflow.
            rel = abs(det) if np.isfinite(det) else 0.0
            raise InvalidValueError(
                "expected an invertible matrix (ad - bc != 0), got one that is singular in "
                f"double precision (|ad - bc| / max|entry|^2 = {rel:.3g}, below 1e-13)"
            )
        m = m / np.sqrt(det)
        m.flags.writeable = False
        self._m = m

    # -- basic access -----------------------------------------------------
    @property
    def matrix(self) -> NDArray[np.complex128]:
        """The read-only SL(2, C) matrix ``[[a, b], [c, d]]``."""
        return self._m

    @property
    def trace(self) -> complex:
        """Trace of the normalised matrix (defined up to sign)."""
        return complex(self._m[0, 0] + self._m[1, 1])

    def params(self) -> dict[str, Any]:
        return {"matrix": [[_complex_to_json(c) for c in row] for row in self._m]}

    @classmethod
    def _from_params(cls, params: dict[str, Any]) -> Mobius:
        if set(params) != {"matrix"}:
            raise InvalidValueError(
                f"expected the parameter 'matrix' for a Möbius map, got {sorted(params)}"
            )
        rows = params["matrix"]
        try:
            entries = [[_complex_from_json(c) for c in row] for row in rows]
        except (TypeError, ValueError):
            raise InvalidValueError(
                f"expected a 2x2 matrix of complex numbers ([re, im] pairs, numbers or "
                f"strings like '1+2i'), got {rows!r:.80}"
            ) from None
        return cls(entries)

    def __repr__(self) -> str:
        def fmt(c: complex) -> str:
            return f"{c.real:.6g}{c.imag:+.6g}j"

        (a, b), (c, d) = self._m
        return f"Mobius([[{fmt(a)}, {fmt(b)}], [{fmt(c)}, {fmt(d)}]])"

    def isclose(self, other: Mobius, atol: float = 1e-12) -> bool:
        """True if both are the same map (matrices equal up to sign) to ``atol``."""
        return bool(
            np.allclose(self._m, other._m, rtol=0, atol=atol)
            or np.allclose(self._m, -other._m, rtol=0, atol=atol)
        )

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Mobius):
            return NotImplemented
        return self.isclose(other)

    __hash__ = None  # type: ignore[assignment]

    # -- the map protocol ----------------------------------------------------
    def pull_cp1(self, zw: NDArray[np.complex128]) -> NDArray[np.complex128]:
        zw = np.asarray(zw, dtype=np.complex128)
        (a, b), (c, d) = self._m
        z, w = zw[..., 0], zw[..., 1]
        return coords.normalize_cp1(np.stack([a * z + b * w, c * z + d * w], axis=-1))

    def local_scale(self, zw: NDArray[np.complex128]) -> NDArray[np.float64]:
        """Spherical magnification ``1/|M v|^2`` at unit-norm ``v`` (det M = 1)."""
        zw = coords.normalize_cp1(zw)
        (a, b), (c, d) = self._m
        z, w = zw[..., 0], zw[..., 1]
        return 1.0 / (np.abs(a * z + b * w) ** 2 + np.abs(c * z + d * w) ** 2)

    def as_mobius(self) -> Mobius:
        return self

    def kernel_stages(self) -> tuple[tuple[str, NDArray[np.float64]], ...]:
        """One ``"mobius"`` stage: ``a, b, c, d`` as 8 floats (re, im) for the compiled renderer."""
        from ..render.stages import MOBIUS

        (a, b), (c, d) = self._m
        row = MOBIUS.pack(
            a_re=a.real, a_im=a.imag, b_re=b.real, b_im=b.imag,
            c_re=c.real, c_im=c.imag, d_re=d.real, d_im=d.imag,
        )  # fmt: skip
        return (("mobius", row),)

    def inverse(self) -> Mobius:
        """The inverse map.

        Examples
        --------
        >>> m = Mobius.zoom((20, 30), 3)
        >>> (m @ m.inverse()).is_identity()
        True
        """
        (a, b), (c, d) = self._m
        return Mobius([[d, -b], [-c, a]])

    def __matmul__(self, other: object) -> SphereMap:
        if isinstance(other, Mobius):
            return Mobius(self._m @ other._m)
        return super().__matmul__(other)

    def __pow__(self, t: float) -> Mobius:
        return self.power(t)

    # -- structure --------------------------------------------------------------
    def is_identity(self, atol: float = 1e-12) -> bool:
        """True for the identity map."""
        return self.isclose(Mobius.identity(), atol)

    def is_rotation(self, atol: float = 1e-10) -> bool:
        """True if the map is a rotation of the sphere (a unitary matrix).

        Examples
        --------
        >>> Mobius.rotation((10, 20), 33).is_rotation(), Mobius.zoom((0, 0), 2).is_rotation()
        (True, False)
        """
        return bool(np.allclose(self._m @ self._m.conj().T, np.eye(2), rtol=0, atol=atol))

    def classify(self, atol: float = _TOL) -> str:
        """``"identity"``, ``"elliptic"``, ``"parabolic"``, ``"hyperbolic"`` or ``"loxodromic"``.

        By the trace ``t`` of the SL(2, C) matrix: real with ``|t| < 2``
        elliptic, ``|t| = 2`` parabolic, real with ``|t| > 2`` hyperbolic,
        otherwise loxodromic. Numerically the tests are made on the
        multiplier ``k`` at a fixed point (``|k| = 1`` elliptic, ``k > 0``
        hyperbolic), relative to ``|log k|``, so that a rotation by a tiny
        angle is still elliptic and a tiny zoom still hyperbolic; a map is
        parabolic when its two fixed points merge to within ``sqrt(atol)``
        relative to the size of its traceless part.

        Examples
        --------
        >>> Mobius.rotation((10, 20), 1e-3).classify(), Mobius.zoom((0, 0), 1.00001).classify()
        ('elliptic', 'hyperbolic')
        """
        if self.is_identity(atol):
            return "identity"
        (a, b), (c, d) = self._m
        half = complex(a + d) / 2
        # sqrt(half**2 - 1) (half the eigenvalue gap), accurate when half is near +-1
        disc = cmath.sqrt(complex((a - d) ** 2 / 4 + b * c))
        size = max(abs(a - d) / 2, abs(b), abs(c))  # the traceless part; > 0 (not identity)
        if abs(disc) <= math.sqrt(atol) * size:
            return "parabolic"
        lam = half + disc if abs(half + disc) >= abs(half - disc) else half - disc
        zoom = 2 * math.log(abs(lam))  # log |k| >= 0 for the eigenvalue with |lam| >= 1
        turn = math.remainder(2 * cmath.phase(lam), 2 * math.pi)  # arg k in [-pi, pi]
        scale = math.hypot(zoom, turn)
        if zoom <= atol * scale:
            return "elliptic"
        if abs(turn) <= atol * scale:
            return "hyperbolic"
        return "loxodromic"

    def fixed_points(self) -> NDArray[np.complex128]:
        """The fixed points as unit-norm pairs, shape ``(k, 2)``, k = 1 or 2.

        The identity fixes everything: it gives the two poles. For a
        non-parabolic map the attracting fixed point (of iterating the map)
        comes first; for a rotation, the point it turns counter-clockwise about.

        Examples
        --------
        >>> fp = Mobius.zoom((0, 0), 2).fixed_points()
        >>> coords.xyz_from_cp1(fp).round(9) + 0.0   # the back, then the front
        array([[-1.,  0.,  0.],
               [ 1.,  0.,  0.]])
        """
        if self.is_identity():
            return np.array([[0, 1], [1, 0]], dtype=np.complex128)
        m = self._m
        vals, vecs = np.linalg.eig(m)
        kind = self.classify()
        if kind == "parabolic":
            # One eigenvector: the kernel of m - (t/2) I.
            t2 = self.trace / 2
            a, b = m[0, 0] - t2, m[0, 1]
            c, d = m[1, 0], m[1, 1] - t2
            v = np.array([-b, a]) if abs(a) + abs(b) > abs(c) + abs(d) else np.array([-d, c])
            return coords.normalize_cp1(v)[None, :]
        if kind == "elliptic":
            # Representative with real trace >= 0: eigenvalues exp(-+i theta/2),
            # |theta| <= pi; exp(-i theta/2) belongs to the counter-clockwise centre.
            sign = 1.0 if self.trace.real >= 0 else -1.0
            order = np.argsort(np.angle(sign * vals))
        else:
            order = np.argsort(-np.abs(vals))  # attracting (larger |eigenvalue|) first
        return coords.normalize_cp1(vecs[:, order].T)

    def conjugate(self, by: Mobius) -> Mobius:
        """``by @ self @ by.inverse()``: the same motion moved by ``by``."""
        out = by @ self @ by.inverse()
        assert isinstance(out, Mobius)
        return out

    def power(self, t: float) -> Mobius:
        """``M**t`` for real ``t``: the one-parameter subgroup through ``M``.

        ``M**0`` is the identity, ``M**1`` is ``M`` and
        ``M**s @ M**t == M**(s + t)``. The representative of the matrix with
        non-negative real trace is used, so a rotation by more than 180 degrees
        is taken the short way round (by its angle minus 360).

        Examples
        --------
        >>> z = Mobius.zoom((0, 0), 4)
        >>> (z ** 0.5) == Mobius.zoom((0, 0), 2)
        True
        >>> z ** 1000  # doctest: +ELLIPSIS
        Traceback (most recent call last):
        ...
        spherewarp.errors.InvalidValueError: the power 1000 of this map is out of range ...
        """
        if isinstance(t, bool) or not isinstance(t, numbers.Real):
            raise InvalidTypeError(f"expected a real power, got {t!r}")
        t = float(t)
        if not math.isfinite(t):
            raise InvalidValueError(f"expected a finite real power, got {t!r}")
        m = self._m if self.trace.real >= 0 else -self._m
        if self.is_identity():
            return Mobius.identity()
        tr = complex(m[0, 0] + m[1, 1])
        # Closed form: M = cosh(s) I + sinh(s)/s N with N = M - tr/2 I, N^2 = (tr^2/4 - 1) I.
        n = m - (tr / 2) * np.eye(2)
        s = cmath.acosh(tr / 2)
        if abs(s) < 1e-7:  # parabolic: M = I + N, M^t = I + t N
            return Mobius(np.eye(2) + t * n)
        try:  # e**710 and beyond overflows; far less is already singular in double precision
            return Mobius(cmath.cosh(t * s) * np.eye(2) + (cmath.sinh(t * s) / cmath.sinh(s)) * n)
        except (OverflowError, InvalidValueError):
            raise InvalidValueError(
                f"the power {t:g} of this map is out of range (it would squeeze the whole sphere "
                "onto a fixed point); expected a smaller power"
            ) from None

    def to_rotation_matrix(self) -> NDArray[np.float64]:
        """The 3x3 rotation matrix of a rotation (acting on ``xyz`` column vectors).

        Raises
        ------
        InvalidValueError
            If the map is not a rotation.
        """
        if not self.is_rotation(1e-8):
            raise InvalidValueError("this Möbius map is not a rotation (its matrix is not unitary)")
        return np.stack([self.apply_xyz(e) for e in np.eye(3)], axis=-1)

    # -- constructors -------------------------------------------------------------
    @classmethod
    def identity(cls) -> Mobius:
        """The identity map."""
        return cls(np.eye(2))

    @classmethod
    def from_matrix(cls, matrix: ArrayLike) -> Mobius:
        """From a raw invertible 2x2 complex matrix (same as the constructor)."""
        return cls(matrix)

    @classmethod
    def rotation(cls, axis: PointLike, angle: float) -> Mobius:
        """Rotation about the axis through ``axis`` by ``angle`` degrees.

        Positive angles turn counter-clockwise as seen from the centre of the
        sphere looking at ``axis``.

        Examples
        --------
        >>> r = Mobius.rotation((0, 90), 30)   # about the zenith
        >>> r.apply_lonlat([0.0, 0.0]).round(9)
        array([30.,  0.])
        """
        v = as_cp1_point(axis, "axis")
        u = np.stack([v, coords.antipode_cp1(v)], axis=-1)  # unitary, columns v, -v
        half = math.radians(float(angle)) / 2
        d = np.diag([cmath.exp(-1j * half), cmath.exp(1j * half)])
        return cls(u @ d @ u.conj().T)

    @classmethod
    def from_rotation_matrix(cls, rot: ArrayLike) -> Mobius:
        """From a 3x3 rotation matrix acting on ``xyz`` column vectors."""
        r = np.asarray(rot, dtype=np.float64)
        if (
            r.shape != (3, 3)
            or not np.allclose(r @ r.T, np.eye(3), atol=1e-8)
            or (np.linalg.det(r) < 0)
        ):
            raise InvalidValueError("expected a 3x3 rotation matrix (orthonormal, det +1)")
        from scipy.spatial.transform import Rotation

        rotvec = Rotation.from_matrix(r).as_rotvec()
        angle = float(np.linalg.norm(rotvec))
        if angle < 1e-15:
            return cls.identity()
        # Right-handed rotation about +rotvec == counter-clockwise seen from the centre.
        return cls.rotation(rotvec / angle, math.degrees(angle))

    @classmethod
    def from_yaw_pitch_roll(cls, yaw: float = 0.0, pitch: float = 0.0, roll: float = 0.0) -> Mobius:
        """The view rotation of ffmpeg's ``v360`` filter (order yaw, pitch, roll).

        Pulling an image back by this map (``warp(image, m)``) turns the view
        the way ``v360=e:e:yaw=..:pitch=..:roll=..`` does: positive yaw looks to
        the right (the input at longitude ``yaw`` comes to the centre), positive
        pitch looks up (latitude ``pitch`` comes to the centre) and positive
        roll rolls the view clockwise (the scene appears turned
        counter-clockwise). All in degrees.

        Examples
        --------
        >>> m = Mobius.from_yaw_pitch_roll(yaw=30)
        >>> m.apply_lonlat([0.0, 0.0]).round(9)   # the output centre shows lon 30
        array([30.,  0.])
        """
        # In the xyz frame of spherewarp.coords v360's rotation is
        # Rz(yaw) Ry(-pitch) Rx(-roll) (right-handed rotations, measured against
        # ffmpeg in tests/oracles), and a right-handed rotation about a point
        # is counter-clockwise seen from the centre, as Mobius.rotation is.
        m_yaw = cls.rotation((0.0, 0.0, 1.0), float(yaw))
        m_pitch = cls.rotation((0.0, 1.0, 0.0), -float(pitch))
        m_roll = cls.rotation((1.0, 0.0, 0.0), -float(roll))
        out = m_yaw @ m_pitch @ m_roll
        assert isinstance(out, Mobius)
        return out

    @classmethod
    def rotation_to(cls, p: PointLike, q: PointLike) -> Mobius:
        """The rotation taking ``p`` to ``q`` along the great circle through them.

        For antipodal points the axis is any one perpendicular to both.
        """
        a = coords.xyz_from_cp1(as_cp1_point(p, "p"))
        b = coords.xyz_from_cp1(as_cp1_point(q, "q"))
        axis = np.cross(a, b)
        s, c = float(np.linalg.norm(axis)), float(np.dot(a, b))
        if s < 1e-12:
            if c > 0:
                return cls.identity()
            # Antipodal: a half turn about any axis perpendicular to both.
            helper = np.array([1.0, 0.0, 0.0]) if abs(a[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
            axis = np.cross(a, helper)
            return cls.rotation(axis / np.linalg.norm(axis), 180.0)
        return cls.rotation(axis / s, math.degrees(math.atan2(s, c)))

    @classmethod
    def zoom(cls, at: PointLike, factor: complex) -> Mobius:
        """Zoom by ``factor`` toward ``at``, fixing it and its antipode.

        The map magnifies by ``|factor|`` at ``at`` and by ``1/|factor|`` at the
        antipode. A complex factor also turns by its argument (a loxodromic
        "spiral zoom"). To magnify the *content* of an image at ``at``, push
        the image forward by this map (``warp(image, m.inverse())``).

        Examples
        --------
        >>> m = Mobius.zoom((0, 0), 2)
        >>> float(m.local_scale(as_cp1_point((0, 0)))), float(m.local_scale(as_cp1_point((180, 0))))
        (2.0, 0.5)
        """
        v = as_cp1_point(at, "at")
        return cls.zoom_between(coords.antipode_cp1(v), v, factor)

    @classmethod
    def zoom_between(cls, source: PointLike, sink: PointLike, factor: complex) -> Mobius:
        """The map fixing two points that magnifies by ``factor`` at ``sink``.

        It multiplies by ``factor`` in a chart with ``sink`` at 0 and ``source``
        at infinity; at ``source`` the magnification is ``1/|factor|``.

        Raises
        ------
        InvalidValueError
            If the points coincide or the factor is 0 or not finite.
        """
        f = complex(factor)
        if not cmath.isfinite(f) or f == 0:
            raise InvalidValueError(f"expected a finite non-zero zoom factor, got {factor!r}")
        a = as_cp1_point(source, "source")
        b = as_cp1_point(sink, "sink")
        if abs(_det(a, b)) < 1e-9:
            raise InvalidValueError("the two fixed points of a zoom must be different")
        u = np.stack([a, b], axis=-1)  # (1,0) -> source, (0,1) -> sink
        r = cmath.sqrt(f)
        return cls(u @ np.diag([r, 1 / r]) @ np.linalg.inv(u))

    @classmethod
    def translation(cls, at: PointLike, shift: complex) -> Mobius:
        """Parabolic translation fixing ``at``.

        It is ``z -> z + shift`` in a chart with ``at`` at infinity.

        The chart is a rotation of the default chart, so the paper's
        ``z -> z + 1/2`` is ``Mobius.translation(complex("inf"), 0.5)``.

        Examples
        --------
        >>> Mobius.translation(complex("inf"), 0.5) == Mobius([[1, 0.5], [0, 1]])
        True
        """
        v = as_cp1_point(at, "at")
        u = np.stack([v, coords.antipode_cp1(v)], axis=-1)
        # Keep the default chart's orientation when at is the nadir.
        return cls(u @ np.array([[1, complex(shift)], [0, 1]]) @ u.conj().T)

    @classmethod
    def from_points(cls, p: Sequence[PointLike], q: Sequence[PointLike]) -> Mobius:
        """The unique map sending three points ``p[k]`` to ``q[k]``.

        Raises
        ------
        InvalidValueError
            If the points of either triple are not three distinct points.

        Examples
        --------
        >>> m = Mobius.from_points([0, 1, complex("inf")], [1, 1j, -1])
        >>> np.round(m([0, 1, np.inf]), 12)
        array([ 1.+0.j,  0.+1.j, -1.+0.j])
        """
        if len(p) != 3 or len(q) != 3:
            raise InvalidValueError(f"expected three points each, got {len(p)} and {len(q)}")
        a = cls._to_zero_one_inf([as_cp1_point(x, "from point") for x in p])
        b = cls._to_zero_one_inf([as_cp1_point(x, "to point") for x in q])
        return cls(np.linalg.inv(b) @ a)

    @staticmethod
    def _to_zero_one_inf(pts: list[NDArray[np.complex128]]) -> NDArray[np.complex128]:
        p1, p2, p3 = pts
        for i, j in ((0, 1), (0, 2), (1, 2)):
            if abs(_det(pts[i], pts[j])) < 1e-9:
                raise InvalidValueError(
                    "expected three distinct points, got coincident points "
                    f"(numbers {i + 1} and {j + 1})"
                )
        d23, d21 = _det(p2, p3), _det(p2, p1)
        return np.array(
            [[d23 * p1[1], -d23 * p1[0]], [d21 * p3[1], -d21 * p3[0]]], dtype=np.complex128
        )
