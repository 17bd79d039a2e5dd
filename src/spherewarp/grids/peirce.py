"""Output and input projections other than the equirectangular one.

Peirce's quincuncial projection (1879) maps the whole sphere conformally
onto a square (the paper's section "Weierstrass and Schwarz–Christoffel").
The zenith is at the centre; the upper hemisphere is the inscribed diamond,
whose vertices (the midpoints of the square's sides) are the equator at
longitudes ``lon0 ± 45°`` and ``lon0 ± 135°``; the lower hemisphere is cut
into the four corner triangles and the nadir is at all four corners. The
``lon0`` meridian runs from the centre to the bottom-left corner, and
longitude grows counter-clockwise (``lon0 + 90°`` runs to the bottom-right
corner): the picture is the view from inside the sphere looking up, so a
panorama is not mirrored. It is PROJ's ``peirce_q`` (``+lon_0=lon0``) up to
a similarity of the plane (a rotation by 45°, a scale and a shift).

The sides of the square are glued by folding each one at its midpoint, so
the square tiles the plane by half-turns about the midpoints of its sides
and its images can be sampled across their edges without seams.

Coordinates: ``(u, v)`` in ``[-1, 1]²``, u to the right and v up. In a
square image of side N, pixel ``(x, y)`` (origin top-left, pixel centres at
half-integers) is ``u = 2x/N - 1``, ``v = 1 - 2y/N``.

Formulas: with the default chart coordinate z of a point and
``ζ = e^{i(π/4 - lon0)} z``, ``u + iv = SC_4(ζ)/K`` for |ζ| <= 1
(SC_4 the Schwarz–Christoffel map of the disk onto the square, ``K = SC_4(1)``),
and the reflection of ``SC_4(1/conj ζ)/K`` in the side of the diamond for
|ζ| > 1. The inverse is the lemniscatic sine, an elliptic function: with
``t = (u + iv)/2``, ``ζ = C e^{iπt} θ1(πt)/θ1(π(t - (1+i)/2))`` (theta
functions of the square lattice), smooth everywhere on the square,
including its diagonals.

Examples
--------
>>> import numpy as np
>>> from spherewarp.grids import peirce
>>> u, v = peirce.peirce_from_sphere(np.array([[0.0, 0.0, 1.0], [0.0, 0.0, -1.0]]))
>>> np.round(u, 12) + 0, np.round(np.abs(v), 12)
(array([0., 1.]), array([0., 1.]))
>>> xyz = peirce.sphere_from_peirce(np.array([0.3]), np.array([-0.8]))
>>> u, v = peirce.peirce_from_sphere(xyz)
>>> print(round(float(u[0]), 12), round(float(v[0]), 12))
0.3 -0.8
"""

from __future__ import annotations

import functools
import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import coords, special
from ..errors import InvalidValueError

__all__ = [
    "peirce_from_sphere",
    "sphere_from_peirce",
    "render_peirce",
    "peirce_to_equirect",
]

FloatArray = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]


def _rotation(lon0: float) -> complex:
    lon0 = float(lon0)
    if not math.isfinite(lon0):
        raise InvalidValueError(f"expected a finite lon0 in degrees, got {lon0!r}")
    return complex(np.exp(1j * (math.pi / 4 - math.radians(lon0))))


def _unit_pairs_of_xyz(xyz: ArrayLike) -> ComplexArray:
    v = np.asarray(xyz, dtype=np.float64)
    if v.shape[-1:] != (3,):
        raise InvalidValueError(f"expected unit vectors of shape (..., 3), got {v.shape}")
    if not np.all(np.isfinite(v)):
        raise InvalidValueError("expected finite vectors, got NaN or inf")
    return coords.cp1_from_xyz(v)


def peirce_from_sphere(xyz: ArrayLike, lon0: float = 0.0) -> tuple[FloatArray, FloatArray]:
    """Peirce quincuncial coordinates of points of the sphere.

    Parameters
    ----------
    xyz : array_like, shape (..., 3)
        Unit vectors (see :mod:`spherewarp.coords`).
    lon0 : float
        The central meridian in degrees (PROJ's ``+lon_0``): it runs from
        the centre to the bottom-left corner.

    Returns
    -------
    u, v : ndarray, shape (...)
        In ``[-1, 1]``; u right, v up. Points of the four half-meridians
        that are folded onto the sides of the square get one of their two
        images. Near the four vertices of the diamond (where the projection
        is not conformal) a rounding error δ of the input moves the output
        by about √δ.

    Examples
    --------
    >>> xyz = coords.xyz_from_lonlat(np.radians([[45.0, 0.0], [0.0, 0.0]]))
    >>> u, v = peirce_from_sphere(xyz)
    >>> np.round(u, 6) + 0, np.round(v, 6) + 0      # a vertex; middle of a diamond side
    (array([ 0. , -0.5]), array([-1. , -0.5]))
    """
    c = _rotation(lon0)
    zw = _unit_pairs_of_xyz(xyz)
    z, w = zw[..., 0] * c, zw[..., 1]
    k4 = special.schwarz_christoffel_vertex(4)
    inside = np.abs(z) <= np.abs(w)
    out = np.empty(z.shape, np.complex128)
    if np.any(inside):
        out[inside] = special.schwarz_christoffel(z[inside] / w[inside], 4) / k4
    outside = ~inside
    if np.any(outside):
        zo, wo = z[outside], w[outside]
        mirror = np.conj(wo) / np.conj(zo)  # 1/conj(zeta), in the disk
        p = special.schwarz_christoffel(mirror, 4) / k4
        ang = np.angle(zo * np.conj(wo))  # arg zeta
        quadrant = np.floor(np.mod(ang, 2 * np.pi) / (np.pi / 2)).astype(np.intp) % 4
        units = np.array([1.0, 1j, -1.0, -1j])
        turn = units[quadrant]
        p1 = p * np.conj(turn)
        p1 = (1 + 1j) - 1j * np.conj(p1)  # reflect in the side x + y = 1
        out[outside] = p1 * turn
    u = np.clip(out.real, -1.0, 1.0)
    v = np.clip(out.imag, -1.0, 1.0)
    return u, v


@functools.cache
def _sl_constant() -> complex:
    # w(t) = C e^{i pi t} theta1(pi t)/theta1(pi (t - a)), w ~ sqrt(e1) t at 0 (K/sqrt(e1) = 1/2)
    q = math.exp(-math.pi)
    a = (1 + 1j) / 2
    t1p = sum(
        2.0 * (-1) ** k * (2 * k + 1) * q ** ((k + 0.5) ** 2) for k in range(30)
    )  # theta1'(0)
    e1 = special.weierstrass_half_period_value("square")
    return complex(math.sqrt(e1) * special.jtheta(1, -math.pi * a, q) / (math.pi * t1p))


def sphere_from_peirce(u: ArrayLike, v: ArrayLike, lon0: float = 0.0) -> FloatArray:
    """Points of the sphere at Peirce quincuncial coordinates ``(u, v)``.

    Parameters
    ----------
    u, v : array_like
        Coordinates in the square ``[-1, 1]²`` (u right, v up); values
        outside continue the projection periodically (half-turns about the
        midpoints of the sides).
    lon0 : float
        The central meridian in degrees, as in :func:`peirce_from_sphere`.

    Returns
    -------
    ndarray, shape (..., 3)
        Unit vectors.

    Examples
    --------
    >>> np.round(sphere_from_peirce(np.array([1.0, 0.0]), np.array([1.0, 0.0])), 12) + 0
    array([[ 0.,  0., -1.],
           [ 0.,  0.,  1.]])
    """
    uu = np.asarray(u, dtype=np.float64)
    vv = np.asarray(v, dtype=np.float64)
    if not (np.all(np.isfinite(uu)) and np.all(np.isfinite(vv))):
        raise InvalidValueError("expected finite (u, v), got NaN or inf")
    uu, vv = np.broadcast_arrays(uu, vv)
    c = _rotation(lon0)
    t = (uu + 1j * vv) / 2.0
    q = math.exp(-math.pi)
    a = (1 + 1j) / 2
    # reduce t modulo the period lattice (1+i)Z + (1-i)Z of w; keeps Im small for the series
    s1 = np.round((t.real + t.imag) / 2.0)
    s2 = np.round((t.real - t.imag) / 2.0)
    t = t - s1 * (1 + 1j) - s2 * (1 - 1j)
    num = _sl_constant() * np.exp(1j * math.pi * t) * special.jtheta(1, math.pi * t, q)
    den = special.jtheta(1, math.pi * (t - a), q)
    zw = coords.normalize_cp1(np.stack([num * np.conj(c), den], axis=-1))
    return coords.xyz_from_cp1(zw)


# -- rendering ---------------------------------------------------------------------------
def _check_image(image: ArrayLike, name: str = "image") -> NDArray:
    from ..render.warp import as_image

    return as_image(image, name)


def _check_size(size: object, name: str = "size") -> int:
    if isinstance(size, bool) or not isinstance(size, (int, np.integer)) or not 2 <= size <= 32768:
        raise InvalidValueError(f"expected {name} as an integer 2..32768, got {size!r}")
    return int(size)


def _to_dtype(acc: NDArray[np.float32], dtype: np.dtype) -> NDArray:
    if dtype.kind == "u":
        info = np.iinfo(dtype)
        return np.clip(np.rint(acc), info.min, info.max).astype(dtype)
    return acc.astype(dtype)


_TILE_PIXELS = 1 << 17


def render_peirce(
    image: ArrayLike,
    size: int | None = None,
    *,
    lon0: float = 0.0,
    interp: str = "bilinear",
    supersample: int = 1,
    force: bool = False,
    progress: Any = None,
) -> NDArray:
    """Render an equirectangular image in Peirce's quincuncial projection.

    Parameters
    ----------
    image : ndarray (H, W[, C])
        Equirectangular image (uint8, uint16, float32).
    size : int, optional
        Side of the square output. Default ``3H/2`` (rounded to even), about
        the input's resolution at the centre.
    lon0 : float
        Central meridian in degrees (see the module docstring).
    interp : {"bilinear", "nearest", "bicubic"}
    supersample : int
        Average ``n x n`` samples per output pixel.
    force : bool
        Accept an input that is not 2:1.
    progress : callable, optional
        ``progress(done, total)`` per band of output rows, as for
        :func:`~spherewarp.render.warp`.

    Returns
    -------
    ndarray, shape (size, size, C)
        Same dtype as the input.

    Examples
    --------
    >>> img = np.zeros((32, 64, 3), np.uint8)
    >>> render_peirce(img, 40).shape
    (40, 40, 3)
    """
    from ..render.sampling import check_interp, sample
    from ..render.warp import check_equirect

    img = _check_image(image)
    check_equirect(img, force)
    h, w = img.shape[:2]
    n = _check_size(size if size is not None else 2 * round(0.75 * h))
    interp = check_interp(interp)
    ss = _check_supersample(supersample)
    out = np.empty((n, n, img.shape[2]), img.dtype)
    offsets = (np.arange(ss) + 0.5) / ss
    rows_per_tile = max(1, _TILE_PIXELS // (n * ss * ss))
    cols = np.arange(n, dtype=np.float64)
    for r0 in range(0, n, rows_per_tile):
        _report(progress, r0, n)
        r1 = min(n, r0 + rows_per_tile)
        rows = np.arange(r0, r1, dtype=np.float64)
        acc = np.zeros((r1 - r0, n, img.shape[2]), np.float32)
        for oy in offsets:
            for ox in offsets:
                uu = 2.0 * (cols[None, :] + ox) / n - 1.0
                vv = 1.0 - 2.0 * (rows[:, None] + oy) / n
                xyz = sphere_from_peirce(*np.broadcast_arrays(uu, vv), lon0=lon0)
                px = coords.pixel_from_lonlat(coords.lonlat_from_xyz(xyz), w, h)
                acc += sample(img, px[..., 0], px[..., 1], interp)
        out[r0:r1] = _to_dtype(acc / np.float32(ss * ss), img.dtype)
    _report(progress, n, n)
    return out


def _report(progress: Any, done: int, total: int) -> None:
    if progress is not None:
        progress(done, total)


def _check_supersample(supersample: object) -> int:
    if (
        isinstance(supersample, bool)
        or not isinstance(supersample, (int, np.integer))
        or not 1 <= supersample <= 32
    ):
        raise InvalidValueError(f"expected supersample to be an integer 1..32, got {supersample!r}")
    return int(supersample)


def _padded(square: NDArray, pad: int) -> NDArray:
    """The square image with a border of ``pad`` pixels continued across its folded sides."""
    n = square.shape[0]
    idx = np.arange(-pad, n + pad) + 0.5  # pixel centres in the padded frame
    x, y = np.meshgrid(idx, idx)
    # fold into [0, n]^2: beyond a side, a half-turn about its midpoint
    for _ in range(2):
        right, left = x > n, x < 0
        x = np.where(right, 2 * n - x, np.where(left, -x, x))
        y = np.where(right | left, n - y, y)
        bottom, top = y > n, y < 0
        y = np.where(bottom, 2 * n - y, np.where(top, -y, y))
        x = np.where(bottom | top, n - x, x)
    ix = np.clip(np.floor(x).astype(np.intp), 0, n - 1)
    iy = np.clip(np.floor(y).astype(np.intp), 0, n - 1)
    return square[iy, ix]


def peirce_to_equirect(
    square_image: ArrayLike,
    output_shape: tuple[int, int] | None = None,
    *,
    lon0: float = 0.0,
    interp: str = "bilinear",
    supersample: int = 1,
    progress: Any = None,
) -> NDArray:
    """Turn a Peirce quincuncial square image back into an equirectangular one.

    The inverse of :func:`render_peirce`: every output pixel's direction is
    projected into the square (:func:`peirce_from_sphere`) and sampled there;
    the square's sides are continued by their folding, so there are no seams.

    Parameters
    ----------
    square_image : ndarray (N, N[, C])
    output_shape : (height, width), optional
        Default ``(2N/3, 4N/3)`` rounded, the inverse of render_peirce's default.
    lon0 : float
        Central meridian in degrees, as the square was made with.
    interp : {"bilinear", "nearest", "bicubic"}
    supersample : int
    progress : callable, optional
        ``progress(done, total)`` per band of output rows, as for
        :func:`~spherewarp.render.warp`.

    Returns
    -------
    ndarray, shape (height, width, C)
        Same dtype as the input.

    Examples
    --------
    >>> sq = np.zeros((48, 48, 3), np.uint8)
    >>> peirce_to_equirect(sq).shape
    (32, 64, 3)
    """
    from ..render.sampling import check_interp, sample

    sq = _check_image(square_image, "square image")
    n = sq.shape[0]
    if sq.shape[1] != n:
        raise InvalidValueError(
            f"expected a square Peirce quincuncial image, got {sq.shape[1]}x{sq.shape[0]}"
        )
    if output_shape is None:
        h_out = max(1, round(n / 1.5))
        output_shape = (h_out, 2 * h_out)
    try:
        h_out, w_out = (int(v) for v in output_shape)
    except (TypeError, ValueError):
        raise InvalidValueError(
            f"expected output_shape as (height, width), got {output_shape!r}"
        ) from None
    if not (1 <= h_out <= 32768 and 1 <= w_out <= 65536):
        raise InvalidValueError(f"expected a positive output shape, got {output_shape!r}")
    interp = check_interp(interp)
    ss = _check_supersample(supersample)
    pad = 3
    padded = _padded(sq, pad)
    out = np.empty((h_out, w_out, sq.shape[2]), sq.dtype)
    offsets = (np.arange(ss) + 0.5) / ss
    rows_per_tile = max(1, _TILE_PIXELS // (w_out * ss * ss))
    cols = np.arange(w_out, dtype=np.float64)
    for r0 in range(0, h_out, rows_per_tile):
        _report(progress, r0, h_out)
        r1 = min(h_out, r0 + rows_per_tile)
        rows = np.arange(r0, r1, dtype=np.float64)
        acc = np.zeros((r1 - r0, w_out, sq.shape[2]), np.float32)
        for oy in offsets:
            for ox in offsets:
                px = np.stack(np.broadcast_arrays(cols[None, :] + ox, rows[:, None] + oy), -1)
                xyz = coords.xyz_from_lonlat(coords.lonlat_from_pixel(px, w_out, h_out))
                u, v = peirce_from_sphere(xyz, lon0=lon0)
                x = (u + 1.0) * (n / 2.0) + pad
                y = (1.0 - v) * (n / 2.0) + pad
                acc += sample(padded, x, y, interp)
        out[r0:r1] = _to_dtype(acc / np.float32(ss * ss), sq.dtype)
    _report(progress, h_out, h_out)
    return out
