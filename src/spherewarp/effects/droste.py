"""Spherical Droste images from a real picture frame.

The paper's Droste images need a source image composited by hand; here the
frame is simply named and everything else follows:

1. The *hole* (:class:`Hole`): the inside of the frame, star-shaped about its
   centre, from the four corners of a picture frame read off a viewer
   (:func:`hole_from_corners`), from a mask image (:func:`hole_from_mask`,
   white = hole) or from an angular radius (:func:`hole_from_radius`). All
   three describe it the same way, by ``rho(theta) = log r(theta)`` in the
   chart ``zeta`` with 0 at the centre and infinity at the antipode (or a
   chosen far point), see :func:`spherewarp.maps.droste.droste_chart`.
2. The scale ``lambda`` (:func:`auto_scale`, or given).
3. The map (:func:`droste_map`): a :class:`~spherewarp.maps.Droste` or
   :class:`~spherewarp.maps.TwistedDroste`, rendered by
   :func:`spherewarp.render.warp` like every other effect
   (:func:`droste_image`, :func:`droste_frames` for a seamless zoom loop).
4. The log view (:func:`log_view`): the picture in log coordinates, with the
   period rectangle drawn, which shows what the parameters do.

Convention: points are ``(lon, lat)`` in degrees (see
:mod:`spherewarp.coords`); frame corners go round the frame in either order.

Examples
--------
>>> import numpy as np
>>> from spherewarp.effects.droste import hole_from_corners, droste_map
>>> hole = hole_from_corners([(-10, 10), (10, 10), (10, -10), (-10, -10)])
>>> hole.center
(0.0, 0.0)
>>> d = droste_map(hole, scale=20.0)
>>> img = np.random.default_rng(0).integers(0, 255, (32, 64, 3), dtype=np.uint8)
>>> from spherewarp.render import warp
>>> warp(img, d).shape
(32, 64, 3)
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import coords
from ..errors import InvalidTypeError, InvalidValueError
from ..maps.droste import Droste, TwistedDroste, droste_chart
from ..maps.mobius import Mobius

__all__ = [
    "Hole",
    "hole_from_corners",
    "hole_from_mask",
    "hole_from_radius",
    "auto_scale",
    "droste_map",
    "droste_image",
    "droste_frames",
    "animation_phases",
    "LogViewLayout",
    "log_view_layout",
    "log_view",
]

#: samples of rho(theta) a hole keeps
DEFAULT_SAMPLES = 2048
_TWO_PI = 2.0 * math.pi


# ---------------------------------------------------------------------------------------------
# sphere helpers


def _xyz(point: Any, name: str) -> NDArray[np.float64]:
    """A ``(lon, lat)`` pair in degrees as a unit vector, validated."""
    try:
        arr = np.asarray(point, dtype=np.float64)
    except (TypeError, ValueError):
        raise InvalidValueError(f"{name}: expected (lon, lat) in degrees, got {point!r}") from None
    if arr.shape != (2,) or not np.all(np.isfinite(arr)) or abs(arr[1]) > 90:
        raise InvalidValueError(
            f"{name}: expected (lon, lat) in degrees with lat in [-90, 90], got {point!r}"
        )
    return coords.xyz_from_lonlat(np.radians(arr))


def _lonlat_tuple(xyz: NDArray[np.float64]) -> tuple[float, float]:
    lon, lat = np.degrees(coords.lonlat_from_xyz(xyz))
    return (float(round(lon, 9)) + 0.0, float(round(lat, 9)) + 0.0)


def _fmt(xyz: NDArray[np.float64]) -> str:
    lon, lat = np.degrees(coords.lonlat_from_xyz(xyz))
    return f"({lon:.1f}, {lat:.1f})"


def _tangent_basis(c: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    helper = np.array([0.0, 0.0, 1.0]) if abs(c[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    e1 = np.cross(helper, c)
    e1 /= np.linalg.norm(e1)
    return e1, np.cross(c, e1)


def _angle(p: NDArray[np.float64], q: NDArray[np.float64]) -> NDArray[np.float64]:
    """Angular distance (radians) between unit vectors, accurate for small angles."""
    return np.arctan2(np.linalg.norm(np.cross(p, q), axis=-1), np.sum(p * q, axis=-1))


def _slerp_edge(p: NDArray, q: NDArray, n: int) -> NDArray[np.float64]:
    """``n`` points of the great-circle arc from ``p`` (included) to ``q`` (excluded)."""
    t = np.arange(n)[:, None] / n
    omega = float(_angle(p, q))
    if omega < 1e-12:
        return np.repeat(p[None, :], n, axis=0)
    return (np.sin((1 - t) * omega) * p + np.sin(t * omega) * q) / math.sin(omega)


def _first_crossing(pts: NDArray[np.float64]) -> tuple[int, int] | None:
    """The first pair of non-adjacent edges of a closed polygon whose minor arcs cross."""
    n = len(pts)
    ii, jj = np.triu_indices(n, 2)
    keep = ~((ii == 0) & (jj == n - 1))
    ii, jj = ii[keep], jj[keep]
    if ii.size == 0:
        return None
    p1, p2, p3, p4 = pts[ii], pts[(ii + 1) % n], pts[jj], pts[(jj + 1) % n]
    n1, n2 = np.cross(p1, p2), np.cross(p3, p4)
    d = np.cross(n1, n2)
    nd = np.linalg.norm(d, axis=1)
    ok = nd > 1e-15  # edges on one great circle are left to the star-shape check
    d = d / np.where(ok, nd, 1.0)[:, None]

    def on_arc(a, b, nrm, x):
        return (np.einsum("ij,ij->i", np.cross(a, x), nrm) >= 0) & (
            np.einsum("ij,ij->i", np.cross(x, b), nrm) >= 0
        )

    cross = np.zeros(ii.size, bool)
    for x in (d, -d):
        cross |= on_arc(p1, p2, n1, x) & on_arc(p3, p4, n2, x)
    cross &= ok
    if not np.any(cross):
        return None
    k = int(np.argmax(cross))
    return int(ii[k]), int(jj[k])


def _fan_area(c: NDArray, curve: NDArray) -> float:
    """Signed solid angle of a closed curve seen from ``c`` (Van Oosterom-Strackee fan)."""
    p, q = curve, np.roll(curve, -1, axis=0)
    num = np.einsum("i,ni->n", c, np.cross(p, q))
    den = 1.0 + p @ c + np.sum(p * q, axis=1) + q @ c
    return float(2.0 * np.arctan2(num, den).sum())


def _winding(zeta: NDArray[np.complex128]) -> tuple[int, NDArray[np.float64]]:
    """Winding number about 0 of a closed polygon in the plane, and its angle steps."""
    steps = np.angle(np.roll(zeta, -1) / zeta)
    return int(round(steps.sum() / _TWO_PI)), steps


def _rho_from_curve(
    curve: NDArray[np.float64], chart: Mobius, samples: int, what: str
) -> NDArray[np.float64]:
    """``log r(theta)`` on the uniform grid from a dense closed curve on the sphere."""
    zw = chart.pull_cp1(coords.cp1_from_xyz(curve))
    if np.min(np.abs(zw[:, 1])) < 1e-9:
        raise InvalidValueError(f"the far fixed point lies on the {what}'s edge")
    zeta = zw[:, 0] / zw[:, 1]
    if np.min(np.abs(zeta)) < 1e-12:
        raise InvalidValueError(f"the centre lies on the {what}'s edge")
    wind, steps = _winding(zeta)
    if wind == 0:
        raise InvalidValueError(
            f"the far fixed point is inside the {what} (or the centre is outside it)"
        )
    if abs(wind) != 1:
        raise InvalidValueError(
            f"the {what}'s edge goes {abs(wind)} times round the centre; expected once"
        )
    if wind < 0:
        zeta = zeta[::-1]
        curve = curve[::-1]
        steps = -np.roll(steps[::-1], -1)
    bad = steps < -1e-9
    if np.any(bad):
        j = int(np.argmax(bad))
        raise InvalidValueError(
            f"the {what} is not star-shaped about the centre: the ray from the centre "
            f"towards {_fmt(curve[j])} crosses its edge more than once (choose a centre "
            "from which the whole edge is visible)"
        )
    theta = np.angle(zeta)
    rho = np.log(np.abs(zeta))
    grid = -math.pi + _TWO_PI * np.arange(samples) / samples
    return np.interp(grid, theta, rho, period=_TWO_PI)


# ---------------------------------------------------------------------------------------------
# the hole


@dataclass(frozen=True, eq=False)
class Hole:
    """The inside of a frame: a region star-shaped about ``center``.

    Stored as ``rho(theta) = log r(theta)``, the log of the radius of the hole
    in direction ``theta`` of the Droste chart
    (:func:`~spherewarp.maps.droste.droste_chart`), sampled at
    ``theta_j = -pi + 2 pi j / n``. Build it with :func:`hole_from_corners`,
    :func:`hole_from_mask` or :func:`hole_from_radius`.

    Attributes
    ----------
    center : (float, float)
        ``(lon, lat)`` in degrees.
    far : (float, float) or None
        The second fixed point; None for the antipode of the centre.
    rho : ndarray, shape (n,)
        Read-only samples of ``log r(theta)``.
    source : str
        ``"corners"``, ``"mask"`` or ``"radius"``.
    """

    center: tuple[float, float]
    far: tuple[float, float] | None
    rho: NDArray[np.float64]
    source: str

    @property
    def chart(self) -> Mobius:
        """The Droste chart of the hole."""
        return droste_chart(self.center, self.far)

    def log_radius(self, theta: ArrayLike) -> NDArray[np.float64]:
        """``rho(theta)`` by periodic linear interpolation."""
        return Droste(self.center, self.rho, 2.0, far=self.far).log_radius(theta)

    def boundary(self) -> NDArray[np.float64]:
        """The edge of the hole as ``(lon, lat)`` degrees, shape ``(n, 2)``."""
        theta = -math.pi + _TWO_PI * np.arange(self.rho.size) / self.rho.size
        zeta = np.exp(self.rho + 1j * theta)
        zw = self.chart.inverse().pull_cp1(coords.cp1_from_plane(zeta))
        return np.degrees(coords.lonlat_from_cp1(zw))

    def contains(self, lonlat: ArrayLike) -> NDArray[np.bool_]:
        """Whether points ``(lon, lat)`` (degrees, shape ``(..., 2)``) are inside the hole.

        Examples
        --------
        >>> hole = hole_from_radius((0, 0), 10)
        >>> hole.contains([[0, 9.9], [0, 10.1], [180, 0]])
        array([ True, False, False])
        """
        zw = coords.cp1_from_lonlat(np.radians(np.asarray(lonlat, dtype=np.float64)))
        d = Droste(self.center, self.rho, 2.0, far=self.far)
        L = d.log_chart(zw)
        return L.real < d.log_radius(L.imag)

    def mask(self, width: int, height: int) -> NDArray[np.bool_]:
        """The hole rasterised on an equirectangular grid (pixel centres inside).

        Examples
        --------
        >>> hole_from_radius((0, 0), 30).mask(16, 8).sum()
        np.int64(4)
        """
        out = np.empty((height, width), bool)
        x = np.arange(width) + 0.5
        step = max(1, (1 << 20) // width)
        for r0 in range(0, height, step):
            y = np.arange(r0, min(height, r0 + step)) + 0.5
            px = np.stack(np.broadcast_arrays(x[None, :], y[:, None]), -1)
            ll = coords.lonlat_from_pixel(px, width, height)
            out[r0 : r0 + step] = self.contains(np.degrees(ll))
        return out

    @property
    def mean_radius(self) -> float:
        """Mean angular radius of the hole about its centre, in degrees."""
        c = _xyz(self.center, "center")
        b = coords.xyz_from_lonlat(np.radians(self.boundary()))
        return float(np.degrees(_angle(b, c[None, :]).mean()))

    def __repr__(self) -> str:
        return (
            f"Hole(center={self.center}, far={self.far}, source={self.source!r}, "
            f"mean_radius={self.mean_radius:.3g} deg, samples={self.rho.size})"
        )


def _finish(center_xyz, far, rho, source) -> Hole:
    rho = np.asarray(rho, dtype=np.float64)
    rho.flags.writeable = False
    far_t = None if far is None else _lonlat_tuple(_xyz(far, "far"))
    return Hole(_lonlat_tuple(center_xyz), far_t, rho, source)


def _check_samples(samples: Any) -> int:
    if isinstance(samples, bool) or not isinstance(samples, (int, np.integer)):
        raise InvalidTypeError(f"samples: expected an integer, got {samples!r}")
    if not 16 <= samples <= 1 << 16:
        raise InvalidValueError(f"samples: expected 16..65536, got {samples}")
    return int(samples)


def hole_from_corners(
    corners: Sequence[Any],
    center: Any = None,
    *,
    far: Any = None,
    samples: int = DEFAULT_SAMPLES,
) -> Hole:
    """The hole inside a frame given by its corners.

    The corners (at least 3, usually the 4 corners of a picture frame read
    off a viewer) are joined by great-circle arcs: the edges of a flat frame
    on a wall are straight lines in space, hence great circles on the sphere.

    Parameters
    ----------
    corners : sequence of (lon, lat)
        In degrees, in order round the frame (either direction).
    center : (lon, lat), optional
        The fixed point inside the frame (default: the normalised mean of the
        corners' unit vectors).
    far : (lon, lat), optional
        The second fixed point (default: the antipode of the centre).
    samples : int
        Samples of ``rho(theta)``.

    Raises
    ------
    InvalidValueError
        If corners coincide, an edge is 180 degrees or more, the corners are
        not in order round the frame (the edges cross), the centre is inside
        no frame (not on the smaller side of the edges), the far point is
        inside the frame, or the frame is not star-shaped about the centre.

    Examples
    --------
    >>> hole = hole_from_corners([(-10, 10), (10, 10), (10, -10), (-10, -10)])
    >>> round(hole.mean_radius, 1)
    11.3
    >>> hole_from_corners([(-10, 10), (10, -10), (10, 10), (-10, -10)])  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    spherewarp.errors.InvalidValueError: the frame's corners are not in order ...
    """
    samples = _check_samples(samples)
    if isinstance(corners, (str, bytes)) or not isinstance(corners, Sequence | np.ndarray):
        raise InvalidTypeError(f"corners: expected a sequence of (lon, lat), got {corners!r:.80}")
    if len(corners) < 3:
        raise InvalidValueError(f"corners: expected at least 3 corners, got {len(corners)}")
    pts = np.array([_xyz(p, f"corner {i + 1}") for i, p in enumerate(corners)])
    n = len(pts)
    for i in range(n):
        p, q = pts[i], pts[(i + 1) % n]
        ang = math.degrees(float(_angle(p, q)))
        if ang < 1e-6:
            raise InvalidValueError(f"corners {i + 1} and {(i + 1) % n + 1} coincide")
        if ang > 179.0:
            raise InvalidValueError(
                f"the edge from corner {i + 1} to corner {(i + 1) % n + 1} spans {ang:.1f} "
                "degrees; expected less than 179"
            )
    crossing = _first_crossing(pts)
    if crossing is not None:
        i, j = crossing
        raise InvalidValueError(
            f"the frame's corners are not in order round the frame: the edge "
            f"{i + 1}-{(i + 1) % n + 1} crosses the edge {j + 1}-{(j + 1) % n + 1} "
            "(give the corners going round the frame, e.g. top-left, top-right, "
            "bottom-right, bottom-left)"
        )
    if center is None:
        m = pts.sum(axis=0)
        if np.linalg.norm(m) < 1e-9:
            raise InvalidValueError("the corners have no mean direction; give the centre")
        c = m / np.linalg.norm(m)
    else:
        c = _xyz(center, "center")
    # dense edge, ~8 points per output sample, distributed by edge length
    lengths = np.array([float(_angle(pts[i], pts[(i + 1) % n])) for i in range(n)])
    counts = np.maximum(8, np.ceil(8 * samples * lengths / lengths.sum())).astype(int)
    curve = np.concatenate([_slerp_edge(pts[i], pts[(i + 1) % n], counts[i]) for i in range(n)])
    # the centre must be on the smaller side of the edge, which must not reach its antipode
    rot = droste_chart(coords.cp1_from_xyz(c))
    zw = rot.pull_cp1(coords.cp1_from_xyz(curve))
    wind = 0
    if np.min(np.abs(zw[:, 1])) > 1e-9 and np.min(np.abs(zw[:, 0])) > 1e-12:
        wind, _ = _winding(zw[:, 0] / zw[:, 1])
    area = abs(_fan_area(c, curve))
    if wind == 0 or area > _TWO_PI:
        raise InvalidValueError(
            f"the centre {_fmt(c)} is inside no frame: it is not enclosed by the edges of "
            "the corners given (on the smaller side of them)"
        )
    rho = _rho_from_curve(curve, droste_chart(coords.cp1_from_xyz(c), far), samples, "frame")
    return _finish(c, far, rho, "corners")


def hole_from_radius(
    center: Any,
    radius: float,
    *,
    far: Any = None,
    samples: int = DEFAULT_SAMPLES,
) -> Hole:
    """A round hole: the points within ``radius`` degrees of ``center``.

    Examples
    --------
    >>> hole = hole_from_radius((30, 0), 20)
    >>> bool(np.allclose(hole.rho, np.log(np.tan(np.radians(10)))))
    True
    """
    samples = _check_samples(samples)
    c = _xyz(center, "center")
    try:
        r = float(radius)
    except (TypeError, ValueError):
        raise InvalidValueError(f"radius: expected degrees in (0, 180), got {radius!r}") from None
    if not (math.isfinite(r) and 0 < r < 180):
        raise InvalidValueError(f"radius: expected an angular radius in (0, 180) degrees, got {r}")
    chart = droste_chart(coords.cp1_from_xyz(c), far)
    if far is None:
        rho = np.full(samples, math.log(math.tan(math.radians(r) / 2)))
    else:
        e1, e2 = _tangent_basis(c)
        phi = _TWO_PI * np.arange(8 * samples) / (8 * samples)
        d = math.radians(r)
        curve = math.cos(d) * c + math.sin(d) * (
            np.cos(phi)[:, None] * e1 + np.sin(phi)[:, None] * e2
        )
        rho = _rho_from_curve(curve, chart, samples, "round hole")
    return _finish(c, far, rho, "radius")


def _mask_values(mask: ArrayLike) -> NDArray[np.float32]:
    """A mask image as float32 values in [0, 1], shape (H, W)."""
    m = np.asarray(mask)
    if m.dtype == np.bool_:
        m = m.astype(np.float32)
    if m.ndim == 3:
        c = m.shape[2]
        if c not in (1, 2, 3, 4):
            raise InvalidValueError(f"mask: expected 1-4 channels, got shape {m.shape}")
        m = m[..., 0] if c <= 2 else m[..., :3].mean(axis=2)
    if m.ndim != 2 or m.shape[0] < 2:
        raise InvalidValueError(f"mask: expected an image (H, W) or (H, W, C), got {m.shape}")
    if m.shape[1] != 2 * m.shape[0]:
        raise InvalidValueError(
            f"mask: expected an equirectangular mask with width = 2 x height, got "
            f"{m.shape[1]}x{m.shape[0]}"
        )
    if m.dtype.kind == "u":
        return (m.astype(np.float32) / np.iinfo(m.dtype).max).astype(np.float32)
    if m.dtype.kind == "f":
        if not np.all(np.isfinite(m)):
            raise InvalidValueError("mask: expected finite values, got NaN or inf")
        return m.astype(np.float32)
    raise InvalidTypeError(f"mask: expected uint8, uint16, float or bool values, got {m.dtype}")


def _components(inside: NDArray[np.bool_]) -> NDArray[np.intp]:
    """Connected components of an equirectangular mask, joined across the seam and poles."""
    from scipy import ndimage

    labels, n = ndimage.label(inside, structure=np.ones((3, 3), int))
    if n == 0:
        return labels
    parent = np.arange(n + 1)

    def find(a: int) -> int:
        while parent[a] != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        return a

    def union(a: int, b: int) -> None:
        ra, rb = find(a), find(b)
        if ra != rb:
            parent[max(ra, rb)] = min(ra, rb)

    h, w = inside.shape
    left, right = labels[:, 0], labels[:, -1]
    for dy in (-1, 0, 1):
        a = left[max(0, -dy) : h - max(0, dy)]
        b = right[max(0, dy) : h - max(0, -dy)]
        for la, lb in zip(a[(a > 0) & (b > 0)], b[(a > 0) & (b > 0)], strict=True):
            union(int(la), int(lb))
    for row in (labels[0], labels[-1]):  # the pixels of a pole row all touch the pole
        ids = np.unique(row[row > 0])
        for other in ids[1:]:
            union(int(ids[0]), int(other))
    roots = np.array([find(i) for i in range(n + 1)])
    return roots[labels]


def hole_from_mask(
    mask: ArrayLike,
    center: Any = None,
    *,
    far: Any = None,
    samples: int = DEFAULT_SAMPLES,
) -> Hole:
    """The hole from an equirectangular mask image: white (>= 0.5 of full scale) = hole.

    The hole is the white region that contains the centre (regions elsewhere
    are ignored). Its edge is found along ``samples`` great-circle rays from
    the centre at sub-pixel precision (the 0.5 crossing of the bilinearly
    interpolated mask).

    Parameters
    ----------
    mask : ndarray (H, W[, C])
        Any size with ``W = 2 H``; uint8/uint16/float/bool. RGB is averaged;
        for 2 or 4 channels the first one (or the mean colour) is used,
        alpha is ignored.
    center : (lon, lat), optional
        Default: the centroid of the largest white region.
    far, samples
        As for :func:`hole_from_corners`.

    Raises
    ------
    InvalidValueError
        If the mask has no white region, the centre is not white (inside no
        frame), the hole reaches the far point, or the hole is not
        star-shaped about the centre.

    Examples
    --------
    >>> m = hole_from_radius((0, 0), 20).mask(256, 128)
    >>> hole = hole_from_mask(m, (0, 0))
    >>> bool(abs(hole.mean_radius - 20) < 0.5)
    True
    """
    from ..render.sampling import sample

    samples = _check_samples(samples)
    values = _mask_values(mask)
    h, w = values.shape
    inside = values >= 0.5
    labels = _components(inside)
    if not np.any(inside):
        raise InvalidValueError("mask: expected a white region (the hole), got none")

    def xyz_of(where: NDArray[np.bool_]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Unit vectors and area weights (cos lat) of the pixels of a mask."""
        iy, ix = np.nonzero(where)
        ll = coords.lonlat_from_pixel(np.stack([ix + 0.5, iy + 0.5], -1), w, h)
        return coords.xyz_from_lonlat(ll), np.cos(ll[:, 1])

    if center is None:
        iy, ix = np.nonzero(inside)
        row_area = np.cos(np.pi * (0.5 - (np.arange(h) + 0.5) / h))
        area = np.bincount(labels[iy, ix], weights=row_area[iy])
        area[0] = 0.0
        label = int(np.argmax(area))
        pts, wts = xyz_of(labels == label)
        m = (pts * wts[:, None]).sum(axis=0)
        if np.linalg.norm(m) < 1e-9:
            raise InvalidValueError("mask: the white region has no centroid; give the centre")
        c = m / np.linalg.norm(m)
    else:
        c = _xyz(center, "center")
    px, py = coords.pixel_from_lonlat(coords.lonlat_from_xyz(c), w, h)
    ix, iy = int(np.floor(px)) % w, min(h - 1, max(0, int(np.floor(py))))
    label = labels[iy, ix]
    if label == 0:
        raise InvalidValueError(
            f"the centre {_fmt(c)} is inside no frame: it is not in a white region of the mask"
        )
    comp = labels == label
    indicator = comp.astype(np.float32)[:, :, None]
    pixel = math.pi / h
    reach = float(_angle(xyz_of(comp)[0], c[None, :]).max()) + 3 * pixel
    if reach >= math.pi - pixel:
        raise InvalidValueError("mask: the white region round the centre reaches its antipode")
    step = pixel / 3
    deltas = np.arange(1, int(math.ceil(reach / step)) + 2) * step
    e1, e2 = _tangent_basis(c)
    phi = _TWO_PI * np.arange(samples) / samples
    boundary = np.empty((samples, 3))
    chunk = max(1, (1 << 18) // deltas.size)
    cos_d, sin_d = np.cos(deltas), np.sin(deltas)
    for j0 in range(0, samples, chunk):
        ph = phi[j0 : j0 + chunk]
        dirs = np.cos(ph)[:, None] * e1 + np.sin(ph)[:, None] * e2  # (r, 3)
        pts = cos_d[None, :, None] * c + sin_d[None, :, None] * dirs[:, None, :]
        p = coords.pixel_from_lonlat(coords.lonlat_from_xyz(pts), w, h)
        v = sample(indicator, p[..., 0], p[..., 1], "bilinear")[..., 0]  # (r, nd)
        below = v < 0.5
        first = np.argmax(below, axis=1)
        if not np.all(below.any(axis=1)):
            raise InvalidValueError("mask: the hole does not end along some ray; is it closed?")
        v0 = np.where(first > 0, v[np.arange(len(ph)), np.maximum(first - 1, 0)], 1.0)
        v1 = v[np.arange(len(ph)), first]
        d0 = np.where(first > 0, deltas[np.maximum(first - 1, 0)], 0.0)
        frac = np.clip((v0 - 0.5) / np.maximum(v0 - v1, 1e-6), 0.0, 1.0)
        db = d0 + frac * (deltas[first] - d0)
        # star-shaped: no way back into the hole further out along the ray
        later = deltas[None, :] > db[:, None] + 1.5 * pixel
        again = later & ~below
        if np.any(again):
            r = int(np.argmax(again.any(axis=1)))
            i = int(np.argmax(again[r]))
            raise InvalidValueError(
                f"the mask's hole is not star-shaped about the centre {_fmt(c)}: the ray "
                f"towards {_fmt(pts[r, i])} leaves the hole and comes back"
            )
        boundary[j0 : j0 + chunk] = np.cos(db)[:, None] * c + np.sin(db)[:, None] * dirs
    chart = droste_chart(coords.cp1_from_xyz(c), far)
    rho = _rho_from_curve(boundary, chart, samples, "mask's hole")
    return _finish(c, far, rho, "mask")


# ---------------------------------------------------------------------------------------------
# the scale


def _balanced_log_scale(hole: Hole) -> float:
    """log(lambda) that makes the portal round ``far`` as large as the hole round the centre.

    Sizes are the mean of ``log tan(d/2)`` over the edge, ``d`` the angular
    distance from the fixed point; for ``far`` the antipode this is
    ``-2 mean(rho)``.
    """
    chart = hole.chart
    inv = chart.inverse()
    theta = -math.pi + _TWO_PI * np.arange(hole.rho.size) / hole.rho.size
    c = _xyz(hole.center, "center")
    a = -c if hole.far is None else _xyz(hole.far, "far")
    edge = coords.xyz_from_cp1(inv.pull_cp1(coords.cp1_from_plane(np.exp(hole.rho + 1j * theta))))
    size_hole = float(np.mean(np.log(np.tan(_angle(edge, c[None, :]) / 2))))

    def portal(ell: float) -> float:
        zeta = np.exp(hole.rho + ell + 1j * theta)
        pts = coords.xyz_from_cp1(inv.pull_cp1(coords.cp1_from_plane(zeta)))
        d = np.maximum(_angle(pts, a[None, :]), 1e-300)
        return float(np.mean(np.log(np.tan(d / 2))))

    if hole.far is None:
        return max(0.0, -2.0 * float(hole.rho.mean()))
    lo, hi = 0.0, 300.0
    if portal(lo) <= size_hole:
        return 0.0
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        if portal(mid) > size_hole:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def _fit_scale(hole: Hole, width: float) -> float:
    """The smallest lambda with ``lambda H`` containing every point within ``width`` deg of H."""
    if width <= 0:
        return 1.0
    c = _xyz(hole.center, "center")
    e = coords.xyz_from_lonlat(np.radians(hole.boundary()))  # (n, 3)
    d = math.radians(width)
    phi = _TWO_PI * np.arange(32) / 32
    ref = np.array([0.0, 0.0, 1.0]) if abs(c[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    t1 = np.cross(e, ref)
    t1 /= np.linalg.norm(t1, axis=1, keepdims=True)
    t2 = np.cross(e, t1)
    pts = math.cos(d) * e[:, None, :] + math.sin(d) * (
        np.cos(phi)[None, :, None] * t1[:, None, :] + np.sin(phi)[None, :, None] * t2[:, None, :]
    )
    droste = Droste(hole.center, hole.rho, 2.0, far=hole.far)
    L = droste.log_chart(coords.cp1_from_xyz(pts))
    return float(max(1.0, np.exp((L.real - droste.log_radius(L.imag)).max())))


def auto_scale(hole: Hole, *, border: float = 0.0, margin: float | None = None) -> float:
    """The automatic Droste scale ``lambda`` of a hole.

    ``lambda = max(lambda_balanced, lambda_fit)``:

    * ``lambda_balanced`` makes the "flower-shaped portal" (the region beyond
      the scaled frame, round the far point) as large, seen from the far
      point, as the hole is seen from the centre (``exp(-2 mean(rho))`` for
      the antipode). The two ends of the Droste tunnel then look alike, and
      the copy of the room that fills each annulus is as large as it can be
      without the portal shrinking to a dot.
    * ``lambda_fit`` is the smallest scale that makes the scaled hole contain
      the frame itself (the moulding round the hole, ``border`` degrees wide)
      plus ``margin`` degrees of wall, so that each copy shows the whole
      frame. It only matters for a very large hole.

    Parameters
    ----------
    hole : Hole
    border : float
        Width of the frame round the hole, in degrees (0 for a canvas).
    margin : float, optional
        Extra wall beyond the frame, degrees (default: a quarter of the
        hole's mean angular radius).

    Examples
    --------
    >>> round(auto_scale(hole_from_radius((0, 0), 20)), 3)   # 1 / tan(10 deg)**2
    32.163
    >>> round(auto_scale(hole_from_radius((0, 0), 100)), 3)   # huge hole: the fit decides
    1.612
    """
    if not isinstance(hole, Hole):
        raise InvalidTypeError(f"expected a Hole, got {type(hole).__name__}")
    for name, v in (("border", border), ("margin", margin)):
        if v is not None and not (math.isfinite(float(v)) and 0 <= float(v) < 90):
            raise InvalidValueError(f"{name}: expected degrees in [0, 90), got {v!r}")
    if margin is None:
        margin = 0.25 * hole.mean_radius
    lam_fit = _fit_scale(hole, float(border) + float(margin))
    with np.errstate(all="ignore"):
        log_bal = float(_balanced_log_scale(hole))
    if not log_bal < math.log(1e100):  # the scale limit of droste maps (NaN too)
        why = (
            f"the hole (mean radius {hole.mean_radius:.3g} degrees) is too small for an "
            "automatic scale; use a larger hole or give the scale"
        )
        raise InvalidValueError(why + " (scale=)", cli=why + " (--scale)")
    return float(max(lam_fit, math.exp(log_bal), 1.01))


# ---------------------------------------------------------------------------------------------
# maps, images, animation


def droste_map(
    hole: Hole,
    scale: float | str | None = None,
    *,
    twist: bool = False,
    strands: int = 1,
    periodicity: int = 1,
    phase: float = 0.0,
    n_images: int = 1,
    border: float = 0.0,
    margin: float | None = None,
) -> Droste:
    """The Droste map of a hole (pull-back: render it with :func:`spherewarp.render.warp`).

    Parameters
    ----------
    hole : Hole
    scale : float or "auto", optional
        ``lambda > 1``; None or ``"auto"`` for :func:`auto_scale` (with
        ``border`` and ``margin``).
    twist : bool
        A :class:`~spherewarp.maps.TwistedDroste` with ``strands`` and
        ``periodicity``; otherwise a straight :class:`~spherewarp.maps.Droste`.
    phase : float
        Zoom phase ``t`` (``t`` and ``t + 1`` give the same image).
    n_images : int
        How many input images the copies cycle through (copy at depth ``d``
        inside the frame shows image ``d mod n_images``).

    Examples
    --------
    >>> d = droste_map(hole_from_radius((0, 0), 20), 5.0, twist=True)
    >>> type(d).__name__, d.scale, d.strands
    ('TwistedDroste', 5.0, 1)
    """
    if not isinstance(hole, Hole):
        raise InvalidTypeError(f"expected a Hole, got {type(hole).__name__}")
    if scale is None or (isinstance(scale, str) and scale.strip().lower() == "auto"):
        lam = auto_scale(hole, border=border, margin=margin)
    elif isinstance(scale, str):
        raise InvalidValueError(f"scale: expected a number > 1 or 'auto', got {scale!r}")
    else:
        lam = scale  # validated by the map
    common = {"far": hole.far, "phase": phase, "n_images": n_images}
    if twist:
        return TwistedDroste(
            hole.center, hole.rho, lam, strands=strands, periodicity=periodicity, **common
        )
    return Droste(hole.center, hole.rho, lam, **common)


def _image_list(images: Any) -> list[Any]:
    if isinstance(images, np.ndarray) or not isinstance(images, Sequence):
        return [images]
    return list(images)


def droste_image(images: Any, droste: Droste, **warp_kwargs: Any) -> NDArray:
    """Render a Droste map: ``warp(images, droste, **warp_kwargs)``.

    ``images`` is one image or a list (one per ``n_images``; image 0 is the
    room outside the frame).
    """
    from ..render import warp

    if not isinstance(droste, Droste):
        raise InvalidTypeError(f"expected a Droste map, got {type(droste).__name__}")
    return warp(_image_list(images), droste, **warp_kwargs)


def animation_phases(n_frames: int, start: float = 0.0) -> list[float]:
    """The phases ``start + k / n_frames`` of a seamless loop of ``n_frames`` frames.

    Examples
    --------
    >>> animation_phases(4)
    [0.0, 0.25, 0.5, 0.75]
    """
    if isinstance(n_frames, bool) or not isinstance(n_frames, (int, np.integer)):
        raise InvalidTypeError(f"n_frames: expected an integer, got {n_frames!r}")
    if not 1 <= n_frames <= 100000:
        raise InvalidValueError(f"n_frames: expected 1..100000, got {n_frames}")
    if not math.isfinite(float(start)):
        raise InvalidValueError(f"start: expected a finite phase, got {start!r}")
    return [float(start) + k / n_frames for k in range(int(n_frames))]


def droste_frames(
    images: Any, droste: Droste, n_frames: int, *, start: float = 0.0, **warp_kwargs: Any
) -> Iterator[NDArray]:
    """The frames of a seamless zoom loop, one at a time.

    Frame ``k`` is ``droste`` at phase ``start + k / n_frames``; the frame
    after the last would be the first again.
    """
    for t in animation_phases(n_frames, start):
        yield droste_image(images, droste.with_phase(t), **warp_kwargs)


# ---------------------------------------------------------------------------------------------
# the log view


@dataclass(frozen=True)
class LogViewLayout:
    """Where the log plane lies in a log view image.

    Column ``x`` (pixel centre ``x + 0.5``) shows ``u = u_left + (x + 0.5) /
    pixels_per_unit`` and row ``y`` shows ``theta = theta_top - (y + 0.5) /
    pixels_per_unit``: pixels are square in log units, ``u`` grows to the
    right (away from the centre) and ``theta`` upwards. A period ``log(lambda)``
    of the straight image is ``log(lambda) * pixels_per_unit`` pixels wide and
    ``2 pi`` is ``2 pi * pixels_per_unit`` pixels high.
    """

    width: int
    height: int
    u_left: float
    theta_top: float
    pixels_per_unit: float
    plane: str
    #: corners of the period rectangle, complex log coordinates, in order
    rectangle: tuple[complex, complex, complex, complex]

    def log_from_pixel(self, x: ArrayLike, y: ArrayLike) -> NDArray[np.complex128]:
        """Log coordinates of pixel positions (centres at half-integers)."""
        s = self.pixels_per_unit
        return (self.u_left + np.asarray(x, float) / s) + 1j * (
            self.theta_top - np.asarray(y, float) / s
        )

    def pixel_from_log(self, log_zeta: ArrayLike) -> NDArray[np.float64]:
        """Pixel positions ``(x, y)`` of log coordinates, shape ``(..., 2)``."""
        L = np.asarray(log_zeta, dtype=np.complex128)
        s = self.pixels_per_unit
        return np.stack([(L.real - self.u_left) * s, (self.theta_top - L.imag) * s], axis=-1)


def _rectangle(droste: Droste, plane: str) -> tuple[complex, complex, complex, complex]:
    """The period rectangle in the input log plane (or its image in the output one).

    Its sides are ``P`` and the perpendicular ``beta log(lambda) / |beta|^2``, so its
    area is the lattice's, ``2 pi log(lambda)``; it is centred on the middle of the strip,
    ``mean(rho) + log(lambda) / 2``.
    """
    beta = droste.beta
    ell = math.log(droste.scale)
    P = droste.period  # = 2 pi i beta
    side = beta * ell / abs(beta) ** 2  # perpendicular to P, |side| * |P| = 2 pi ell
    middle = float(droste.rho.mean()) + 0.5 * ell
    origin = middle - (P + side) / 2
    corners = [origin, origin + side, origin + side + P, origin + P]
    if plane == "output":
        corners = [complex(c) for c in droste.output_log(np.array(corners))]
    return tuple(complex(c) for c in corners)  # type: ignore[return-value]


def log_view_layout(
    droste: Droste, height: int = 512, periods: float = 3.0, plane: str = "input"
) -> LogViewLayout:
    """The geometry of :func:`log_view` (see :class:`LogViewLayout`).

    The view is centred on the period rectangle. Its height covers ``2 pi``
    (or the rectangle, if taller, with a little room); its width covers
    ``periods`` periods ``log(lambda)`` (or the rectangle).

    Examples
    --------
    >>> d = droste_map(hole_from_radius((0, 0), 20), np.exp(np.pi))
    >>> lay = log_view_layout(d, height=200, periods=2)
    >>> lay.width, lay.height, float(round(lay.pixels_per_unit * np.log(d.scale), 6))
    (200, 200, 100.0)
    """
    if not isinstance(droste, Droste):
        raise InvalidTypeError(f"expected a Droste map, got {type(droste).__name__}")
    plane = str(plane).strip().lower()
    if plane not in ("input", "output"):
        raise InvalidValueError(f"plane: expected 'input' or 'output', got {plane!r}")
    if isinstance(height, bool) or not isinstance(height, (int, np.integer)):
        raise InvalidTypeError(f"height: expected an integer, got {height!r}")
    if not 8 <= height <= 16384:
        raise InvalidValueError(f"height: expected 8..16384 pixels, got {height}")
    if not (math.isfinite(float(periods)) and 0 < float(periods) <= 100):
        raise InvalidValueError(f"periods: expected a number in (0, 100], got {periods!r}")
    rect = np.array(_rectangle(droste, plane))
    centre = rect.mean()
    ext_u = float(np.ptp(rect.real))
    ext_t = float(np.ptp(rect.imag))
    ell = math.log(droste.scale)
    span_t = _TWO_PI if ext_t <= _TWO_PI + 1e-9 else 1.1 * ext_t
    span_u = max(float(periods) * ell, 1.1 * ext_u if ext_u > ell + 1e-9 else ext_u)
    s = height / span_t
    width = max(8, int(round(span_u * s)))
    if width > 65536:
        raise InvalidValueError(f"the log view would be {width} pixels wide; use fewer periods")
    u_left = centre.real - 0.5 * width / s
    theta_top = centre.imag + 0.5 * span_t if span_t > _TWO_PI else math.pi
    return LogViewLayout(
        width, int(height), float(u_left), float(theta_top), float(s), plane, tuple(rect)
    )


def _segment_distance(p: NDArray[np.complex128], a: complex, b: complex) -> NDArray[np.float64]:
    d = b - a
    t = np.clip(((p - a) * np.conj(d)).real / max(abs(d) ** 2, 1e-300), 0.0, 1.0)
    return np.abs(p - (a + t * d))


def log_view(
    images: Any,
    droste: Droste,
    *,
    height: int | None = None,
    periods: float = 3.0,
    plane: str = "input",
    dim: float = 0.5,
    draw_period: bool = True,
    color: ArrayLike | None = None,
    interp: str = "bilinear",
    supersample: int = 1,
) -> NDArray:
    """The Droste image in log coordinates, with the period rectangle drawn.

    ``plane="input"`` shows the straight tiling of the log plane (paper,
    "Log of the Droste annulus"): the strip of the annulus at full
    brightness, its translates by ``log(lambda)`` dimmed by ``dim``; for a
    twisted map the drawn rectangle has the period ``P`` as one side ("A
    different fundamental rectangle"). ``plane="output"`` shows the log of
    the rendered image, where that rectangle stands upright, ``2 pi`` high.
    The picture is flat (not equirectangular); :func:`log_view_layout` gives
    its geometry.

    Parameters
    ----------
    images : ndarray or list of ndarrays
        As for :func:`droste_image`.
    droste : Droste
    height : int, optional
        Height in pixels (default: the first image's height).
    periods : float
        How many periods ``log(lambda)`` fit across.
    dim : float
        Brightness factor of the tiles other than the annulus (1: none).
    draw_period : bool
        Draw the period rectangle.
    color : sequence, optional
        Its colour in the image's units (default: full-scale red, or white
        for grey images).
    interp, supersample
        As for :func:`~spherewarp.render.warp`.

    Returns
    -------
    ndarray, shape (height, width, C), the images' dtype.

    Examples
    --------
    >>> img = np.zeros((32, 64, 3), np.uint8)
    >>> d = droste_map(hole_from_radius((0, 0), 20), np.exp(np.pi))
    >>> out = log_view(img, d, height=64, periods=2)
    >>> out.shape, out[0, :, 0].max()     # the rectangle's top edge, drawn in red
    ((64, 64, 3), np.uint8(255))
    """
    from ..render.sampling import check_interp, sample
    from ..render.warp import as_image

    if not isinstance(droste, Droste):
        raise InvalidTypeError(f"expected a Droste map, got {type(droste).__name__}")
    imgs = [as_image(im, f"image {k}") for k, im in enumerate(_image_list(images))]
    if not imgs:
        raise InvalidValueError("expected at least one image, got none")
    for k, im in enumerate(imgs):
        if im.dtype != imgs[0].dtype or im.shape[2] != imgs[0].shape[2]:
            raise InvalidValueError(
                f"expected images of one dtype and channel count, got {imgs[0].dtype}/"
                f"{imgs[0].shape[2]} and {im.dtype}/{im.shape[2]} (image {k})"
            )
    if droste.n_images > len(imgs):
        raise InvalidValueError(f"this map samples {droste.n_images} input images, got {len(imgs)}")
    interp = check_interp(interp)
    if isinstance(supersample, bool) or not isinstance(supersample, (int, np.integer)):
        raise InvalidValueError(f"expected supersample to be an integer 1..32, got {supersample!r}")
    if not 1 <= supersample <= 32:
        raise InvalidValueError(f"expected supersample to be an integer 1..32, got {supersample!r}")
    if not (math.isfinite(float(dim)) and 0 <= float(dim) <= 1):
        raise InvalidValueError(f"dim: expected a brightness factor in [0, 1], got {dim!r}")
    layout = log_view_layout(
        droste, int(imgs[0].shape[0] if height is None else height), periods, plane
    )
    dtype = imgs[0].dtype
    channels = imgs[0].shape[2]
    full = float(np.iinfo(dtype).max) if dtype.kind == "u" else 1.0
    h, w = layout.height, layout.width
    n = int(supersample)
    acc = np.zeros((h, w, channels), np.float32)
    ys, xs = np.mgrid[0:h, 0:w].astype(np.float64)
    for oy in (np.arange(n) + 0.5) / n:
        for ox in (np.arange(n) + 0.5) / n:
            L = layout.log_from_pixel(xs + ox, ys + oy)
            if plane == "output":
                L = droste.source_log(L)
            Ls, k = droste.reduce_log(L)
            zw = droste.chart.inverse().pull_cp1(coords.cp1_from_plane(np.exp(Ls)))
            lonlat = coords.lonlat_from_cp1(zw)
            sheet = np.mod(-k, droste.n_images) if droste.n_images > 1 else np.zeros_like(k)
            vals = np.zeros((h, w, channels), np.float32)
            for j, im in enumerate(imgs[: max(1, droste.n_images)]):
                sel = sheet == j
                if np.any(sel):
                    p = coords.pixel_from_lonlat(lonlat[sel], im.shape[1], im.shape[0])
                    vals[sel] = sample(im, p[..., 0], p[..., 1], interp)
            factor = np.where(k == 0, 1.0, float(dim)).astype(np.float32)
            if channels in (2, 4):  # keep alpha
                factor = np.repeat(factor[..., None], channels, axis=-1)
                factor[..., -1] = 1.0
                acc += vals * factor
            else:
                acc += vals * factor[..., None]
    out = acc / np.float32(n * n)
    if draw_period:
        if color is None:
            col = np.full(channels, full, np.float32)
            if channels >= 3:
                col[1:3] = 0.0
        else:
            col = np.atleast_1d(np.asarray(color, dtype=np.float32))
            if col.size == 1:
                col = np.repeat(col, channels)
            if col.shape != (channels,) or not np.all(np.isfinite(col)):
                raise InvalidValueError(f"color: expected 1 or {channels} values, got {color!r}")
        P = layout.log_from_pixel(xs + 0.5, ys + 0.5)
        half = max(1.0, h / 256) / layout.pixels_per_unit
        rect = layout.rectangle
        dist = np.min([_segment_distance(P, rect[i], rect[(i + 1) % 4]) for i in range(4)], axis=0)
        out[dist <= half] = col
    if dtype.kind == "u":
        out = np.clip(np.rint(out), 0, full)
    return out.astype(dtype)
