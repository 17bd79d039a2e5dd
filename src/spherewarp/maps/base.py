"""The map protocol: what every effect gives the renderer.

An effect is a map ``S`` from output points of the sphere to input points
(the paper's "pulling back via S"). The renderer walks the output pixels,
asks ``S`` where each one comes from and samples the input image there, so a
new effect is a new map, never a new renderer.

A map works on unit-norm homogeneous pairs (``cp1`` arrays of shape
``(..., 2)``, see :mod:`spherewarp.coords`), so infinity is an ordinary
point. It can say, per point, which of several input images to sample and
whether the point is defined at all (:class:`PullBack`), and it gives its
local magnification in the spherical metric, which anti-aliasing uses
(:meth:`SphereMap.local_scale`).

Composition is ``f @ g`` = "f after g" in mathematical order:
``(f @ g)(p) == f(g(p))``. Every map has a plain-data form
(:meth:`SphereMap.to_dict`, :func:`map_from_dict`) that round-trips through
JSON.
"""

from __future__ import annotations

import json
from abc import ABC, abstractmethod
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, ClassVar, TypeVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import coords
from ..errors import InvalidTypeError, InvalidValueError

__all__ = [
    "PullBack",
    "SphereMap",
    "Composite",
    "register_map",
    "map_from_dict",
    "map_from_json",
]

ComplexArray = NDArray[np.complex128]

_REGISTRY: dict[str, type[SphereMap]] = {}

M = TypeVar("M", bound="type[SphereMap]")


def register_map(cls: M) -> M:
    """Class decorator: make ``cls`` known to :func:`map_from_dict` by its ``kind``."""
    kind = cls.kind
    if not kind or kind in _REGISTRY and _REGISTRY[kind] is not cls:
        raise RuntimeError(f"map kind {kind!r} is empty or registered twice")
    _REGISTRY[kind] = cls
    return cls


@dataclass(frozen=True)
class PullBack:
    """Where output points come from.

    Attributes
    ----------
    points : ndarray, complex, shape (..., 2)
        Unit-norm homogeneous pairs of the input points.
    sheet : ndarray of int, shape (...), or None
        Index of the input image to sample for each point; None means image 0.
    valid : ndarray of bool, shape (...), or None
        False where the map is undefined (a hole: background colour or alpha
        0 in the output); None means defined everywhere.

    Examples
    --------
    >>> from spherewarp import coords
    >>> from spherewarp.maps import Mobius
    >>> zw = coords.cp1_from_lonlat(np.radians([[0.0, 0.0]]))  # a point on the equator
    >>> pb = Mobius.from_yaw_pitch_roll(30, 0, 0).pull(zw)
    >>> pb.points.shape, pb.sheet is None, pb.valid is None
    ((1, 2), True, True)
    """

    points: ComplexArray
    sheet: NDArray[np.intp] | None = None
    valid: NDArray[np.bool_] | None = None


def _tangent_frame(xyz: NDArray[np.float64]) -> tuple[NDArray[np.float64], ...]:
    """Two orthonormal tangent vectors at each point of the sphere."""
    helper = np.zeros_like(xyz)
    use_x = np.abs(xyz[..., 0]) < 0.9
    helper[..., 0] = np.where(use_x, 1.0, 0.0)
    helper[..., 1] = np.where(use_x, 0.0, 1.0)
    t1 = np.cross(xyz, helper)
    t1 /= np.linalg.norm(t1, axis=-1, keepdims=True)
    t2 = np.cross(xyz, t1)
    return t1, t2


class SphereMap(ABC):
    """Base class of the maps of the sphere that effects are made of.

    Subclasses implement :meth:`pull_cp1` (and, where it applies,
    :meth:`pull`, :meth:`local_scale`, :meth:`inverse`, :meth:`as_mobius`,
    :meth:`to_dict`/:meth:`_from_params`). A map is immutable.

    Convention: points are unit-norm homogeneous pairs in the default chart
    (0 at the zenith, infinity at the nadir, see :mod:`spherewarp.coords`).

    Examples
    --------
    A map of one's own: the identity, pulling every output point back to itself.

    >>> class Same(SphereMap):
    ...     kind = "same-example"
    ...     def pull_cp1(self, zw):
    ...         return zw
    ...     def params(self):
    ...         return {}
    >>> m = Same()
    >>> m.apply_lonlat([10.0, 20.0]).round(6).tolist(), float(m.local_scale(
    ...     coords.cp1_from_lonlat(np.radians([10.0, 20.0]))).round(6))
    ([10.0, 20.0], 1.0)
    >>> from spherewarp import warp
    >>> img = np.zeros((16, 32, 3), np.uint8)
    >>> warp(img, m).shape
    (16, 32, 3)
    """

    kind: ClassVar[str] = ""
    #: how many input images the map addresses through :attr:`PullBack.sheet`
    n_sheets: ClassVar[int] = 1

    # -- the protocol -----------------------------------------------------
    @abstractmethod
    def pull_cp1(self, zw: ComplexArray) -> ComplexArray:
        """Image points of unit-norm pairs ``zw`` (shape ``(..., 2)``), unit-norm."""

    def pull(self, zw: ComplexArray) -> PullBack:
        """Image points, with the sheet and validity of each (see :class:`PullBack`)."""
        return PullBack(self.pull_cp1(zw))

    def local_scale(self, zw: ComplexArray) -> NDArray[np.float64]:
        """Local magnification of the map in the spherical metric.

        The length of the image of a short arc at each point divided by the
        arc's length (for a non-conformal map, the square root of the area
        ratio). Large values mean that an output pixel covers many input
        pixels. The default is a finite-difference estimate; maps that know
        their derivative override it.
        """
        zw = np.asarray(zw, dtype=np.complex128)
        xyz = coords.xyz_from_cp1(zw)
        t1, t2 = _tangent_frame(xyz)
        h = 1e-6
        cols = []
        for t in (t1, t2):
            plus = self.pull_cp1(coords.cp1_from_xyz(xyz + h * t))
            minus = self.pull_cp1(coords.cp1_from_xyz(xyz - h * t))
            d = coords.xyz_from_cp1(plus) - coords.xyz_from_cp1(minus)
            cols.append(d / (2 * h))
        area = np.linalg.norm(np.cross(cols[0], cols[1]), axis=-1)
        return np.sqrt(area)

    def as_mobius(self) -> Any:
        """The map as a :class:`~spherewarp.maps.Mobius`, or None if it is not one.

        The renderer takes a fast path for Möbius maps.
        """
        return None

    def kernel_stages(self) -> tuple[tuple[str, NDArray[np.float64]], ...] | None:
        """The map as stages of the compiled renderer, or None (the default).

        A map that the fast renderer can evaluate inside its compiled kernel
        returns ``((kind, params), ...)`` in the order the stages are applied
        (see :mod:`spherewarp.render.stages` for the kinds and how to add one).
        With None the renderer gets the map's points from :meth:`pull` and
        only samples them in compiled code.
        """
        return None

    def inverse(self) -> SphereMap:
        """The inverse map; raises :class:`InvalidValueError` if there is none."""
        raise InvalidValueError(f"{type(self).__name__} has no single-valued inverse")

    # -- plain data ---------------------------------------------------------
    def params(self) -> dict[str, Any]:
        """The map's parameters as JSON-ready plain data (without ``kind``)."""
        raise NotImplementedError

    @classmethod
    def _from_params(cls, params: dict[str, Any]) -> SphereMap:
        return cls(**params)

    def to_dict(self) -> dict[str, Any]:
        """Plain-data form ``{"kind": ..., **params}``; :func:`map_from_dict` reads it."""
        return {"kind": self.kind, **self.params()}

    def to_json(self) -> str:
        """The plain-data form as a JSON string."""
        return json.dumps(self.to_dict())

    # -- conveniences ---------------------------------------------------------
    def __call__(self, z: ArrayLike) -> ComplexArray:
        """Apply to points of the extended plane (default chart, ``inf`` allowed)."""
        return coords.plane_from_cp1(self.pull_cp1(coords.cp1_from_plane(z)))

    def apply_xyz(self, xyz: ArrayLike) -> NDArray[np.float64]:
        """Apply to unit vectors ``(..., 3)``."""
        return coords.xyz_from_cp1(self.pull_cp1(coords.cp1_from_xyz(xyz)))

    def apply_lonlat(self, lonlat_deg: ArrayLike) -> NDArray[np.float64]:
        """Apply to ``(lon, lat)`` in degrees, shape ``(..., 2)``."""
        zw = coords.cp1_from_lonlat(np.radians(lonlat_deg))
        return np.degrees(coords.lonlat_from_cp1(self.pull_cp1(zw)))

    def __matmul__(self, other: object) -> SphereMap:
        if not isinstance(other, SphereMap):
            return NotImplemented
        return Composite((self, other))

    def __repr__(self) -> str:
        inner = ", ".join(f"{k}={v!r}" for k, v in self.params().items())
        return f"{type(self).__name__}({inner})"


@register_map
class Composite(SphereMap):
    """The composition of maps, in mathematical order.

    ``Composite((f, g))`` is ``f @ g``: ``g`` is applied first. Nested
    composites are flattened.

    The sheet of a composite is the sheet of the last map applied that gives
    one, and a point is defined where every map is defined at its stage.

    Examples
    --------
    >>> from spherewarp.maps import Mobius
    >>> from spherewarp.maps.base import Composite
    >>> f = Composite((Mobius.rotation((0, 90), 90), Mobius.zoom((0, 0), 2)))
    >>> len(f.maps)
    2
    >>> bool(np.allclose(f(0.3 + 0.1j), f.maps[0](f.maps[1](0.3 + 0.1j))))
    True
    """

    kind = "composite"

    def __init__(self, maps: Sequence[SphereMap]):
        flat: list[SphereMap] = []
        for m in maps:
            if isinstance(m, dict):
                m = map_from_dict(m)
            if not isinstance(m, SphereMap):
                raise InvalidTypeError(f"expected SphereMap instances, got {type(m).__name__}")
            flat.extend(m.maps if isinstance(m, Composite) else (m,))
        if not flat:
            raise InvalidValueError("a composite needs at least one map")
        self._maps = tuple(flat)

    @property
    def maps(self) -> tuple[SphereMap, ...]:
        """The maps, in mathematical order (the last one is applied first)."""
        return self._maps

    @property
    def n_sheets(self) -> int:  # type: ignore[override]
        return max(m.n_sheets for m in self._maps)

    def pull_cp1(self, zw: ComplexArray) -> ComplexArray:
        for m in reversed(self._maps):
            zw = m.pull_cp1(zw)
        return zw

    def pull(self, zw: ComplexArray) -> PullBack:
        sheet = None
        valid = None
        for m in reversed(self._maps):
            pb = m.pull(zw)
            zw = pb.points
            if pb.sheet is not None:
                sheet = pb.sheet
            if pb.valid is not None:
                valid = pb.valid if valid is None else valid & pb.valid
        return PullBack(zw, sheet, valid)

    def local_scale(self, zw: ComplexArray) -> NDArray[np.float64]:
        scale = np.ones(np.shape(zw)[:-1])
        for m in reversed(self._maps):
            scale = scale * m.local_scale(zw)
            zw = m.pull_cp1(zw)
        return scale

    def as_mobius(self) -> Any:
        parts = [m.as_mobius() for m in self._maps]
        if any(p is None for p in parts):
            return None
        out = parts[0]
        for p in parts[1:]:
            out = out @ p
        return out

    def inverse(self) -> SphereMap:
        return Composite(tuple(m.inverse() for m in reversed(self._maps)))

    def params(self) -> dict[str, Any]:
        return {"maps": [m.to_dict() for m in self._maps]}

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Composite):
            return NotImplemented
        return len(self.maps) == len(other.maps) and all(
            a == b for a, b in zip(self.maps, other.maps, strict=True)
        )

    __hash__ = None  # type: ignore[assignment]


def map_from_dict(data: dict[str, Any]) -> SphereMap:
    """Build a map from its plain-data form (see :meth:`SphereMap.to_dict`).

    Examples
    --------
    >>> from spherewarp.maps import Mobius
    >>> m = Mobius.zoom((30, 10), 2.0)
    >>> map_from_dict(m.to_dict()) == m
    True
    """
    if not isinstance(data, dict) or "kind" not in data:
        raise InvalidValueError(f"expected a dict with a 'kind' key, got {data!r:.80}")
    params = dict(data)
    kind = params.pop("kind")
    if str(kind).lower() not in _REGISTRY:
        # The map families register themselves when imported; import them all.
        import importlib

        from . import MAP_MODULES

        for name in MAP_MODULES:
            importlib.import_module(name)
    try:
        cls = _REGISTRY[str(kind).lower()]
    except KeyError:
        allowed = ", ".join(sorted(_REGISTRY))
        raise InvalidValueError(f"unknown map kind {kind!r}; expected one of: {allowed}") from None
    try:
        return cls._from_params(params)
    except InvalidValueError:
        raise
    except KeyError as exc:
        raise InvalidValueError(
            f"bad parameters for map kind {kind!r}: missing field {exc.args[0]!r}"
        ) from None
    except RecursionError:
        raise InvalidValueError(f"map kind {kind!r} is nested too deeply") from None
    except (TypeError, ValueError, ArithmeticError, IndexError, AttributeError) as exc:
        # Hostile values (huge or non-numeric numbers, wrong shapes) end here, not as
        # plain exceptions: name the fields given, since the error may not.
        fields = ", ".join(repr(k) for k in params) or "none"
        message = " ".join(str(exc).split())[:200]
        raise InvalidValueError(
            f"bad parameters for map kind {kind!r} (fields {fields}): "
            f"{type(exc).__name__}: {message}"
        ) from None


def map_from_json(text: str) -> SphereMap:
    """Build a map from a JSON string (see :meth:`SphereMap.to_json`).

    Any document that is not a valid map raises :class:`InvalidValueError`
    (never a plain exception), and only the registered map kinds can be built.

    Examples
    --------
    >>> map_from_json('{"kind": "droste"}')  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    spherewarp.errors.InvalidValueError: bad parameters for map kind 'droste': missing field ...
    """
    if not isinstance(text, (str, bytes, bytearray)):
        raise InvalidValueError(f"expected a map as JSON text, got {type(text).__name__}")
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise InvalidValueError(f"expected a map as JSON, got invalid JSON: {exc}") from None
    except RecursionError:
        raise InvalidValueError("expected a map as JSON, got one nested too deeply") from None
    except (ValueError, UnicodeDecodeError):  # e.g. an integer of over 4300 digits
        raise InvalidValueError(
            "expected a map as JSON, got JSON that cannot be read (a number too long, "
            "or text that is not UTF-8)"
        ) from None
    try:
        return map_from_dict(data)
    except RecursionError:
        raise InvalidValueError("expected a map as JSON, got one nested too deeply") from None


def vectorize_plane_function(
    func: Callable[[ComplexArray], ComplexArray],
) -> Callable[[ComplexArray], ComplexArray]:
    """Turn a function of plane points into one of unit-norm pairs.

    Non-finite results become the point at infinity.
    """

    def pull_cp1(zw: ComplexArray) -> ComplexArray:
        z = coords.plane_from_cp1(zw)
        with np.errstate(all="ignore"):
            w = func(z)
        return coords.cp1_from_plane(w)

    return pull_cp1
