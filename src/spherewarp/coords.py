"""Coordinates on the sphere and the conversions between them.

Every function here is vectorised over leading axes and named ``b_from_a``.
The layouts never mix:

==================  ===========================  ===================================
frame               array                        meaning
==================  ===========================  ===================================
pixel               ``(..., 2)`` float ``(x, y)``  equirectangular pixel coordinates
lonlat              ``(..., 2)`` float radians    longitude, latitude
xyz                 ``(..., 3)`` float            unit vector on the sphere
cp1                 ``(..., 2)`` complex          unit-norm homogeneous pair ``(z, w)``
plane               ``(...)`` complex             point ``z/w`` of the Riemann sphere,
                                                  with ``inf`` for the point at infinity
==================  ===========================  ===================================

Units: every ``lonlat`` array here is in **radians**, as NumPy's trigonometry
takes them. The rest of the API (maps, the command line) speaks degrees; the
``_deg`` functions (:func:`lonlat_deg_from_cp1`, :func:`cp1_from_lonlat_deg`,
:func:`lonlat_deg_from_pixel`, :func:`pixel_from_lonlat_deg`) convert in degrees.

Convention: pixel ``(x, y)`` has its origin at the top-left corner of the
image and pixel centres at half-integers; ``lon = 2*pi*x/W - pi`` and
``lat = pi/2 - pi*y/H``, so the image centre is longitude 0 (the front),
longitude grows to the right and latitude grows upwards. The unit vector is
``xyz = (cos lat cos lon, cos lat sin lon, sin lat)``: +x is the front, +y is
longitude +90 degrees and +z is the zenith.

The default chart of the Riemann sphere is the paper's own: 0 at the zenith,
infinity at the nadir, 1 at the back (longitude 180 degrees), i at longitude
-90 degrees, -1 at the front and -i at longitude +90 degrees,
``z = tan((pi/2 - lat)/2) * exp(1j*(lon + pi))``. It is stereographic
projection from the nadir. Homogeneous pairs are kept with unit norm, so the
point at infinity, ``(1, 0)``, is an ordinary point and no NaN or inf ever
appears in ``cp1`` arrays.

Examples
--------
>>> import numpy as np
>>> from spherewarp import coords
>>> coords.plane_from_lonlat(np.radians([[180.0, 0.0], [-90.0, 0.0]])).round(12)
array([ 1.+0.j, -0.+1.j])
>>> coords.xyz_from_cp1(coords.cp1_from_plane(np.array([0, np.inf]))).round(12)
array([[ 0.,  0.,  1.],
       [ 0.,  0., -1.]])
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .errors import InvalidValueError

__all__ = [
    "lonlat_from_pixel",
    "pixel_from_lonlat",
    "xyz_from_lonlat",
    "lonlat_from_xyz",
    "cp1_from_xyz",
    "xyz_from_cp1",
    "cp1_from_plane",
    "plane_from_cp1",
    "plane_from_lonlat",
    "lonlat_from_plane",
    "normalize_cp1",
    "antipode_cp1",
    "cp1_from_lonlat",
    "lonlat_from_cp1",
    "lonlat_deg_from_cp1",
    "cp1_from_lonlat_deg",
    "lonlat_deg_from_pixel",
    "pixel_from_lonlat_deg",
    "parse_lonlat",
]

FloatArray = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]


def lonlat_from_pixel(pixel: ArrayLike, width: int, height: int) -> FloatArray:
    """Longitude and latitude (radians) of equirectangular pixel coordinates.

    Convention: origin at the top-left corner, pixel centres at half-integers.

    Parameters
    ----------
    pixel : array_like, shape (..., 2)
        ``(x, y)`` in pixels.
    width, height : int
        Size of the equirectangular image.

    Returns
    -------
    ndarray, shape (..., 2)
        ``(lon, lat)`` in radians.

    Examples
    --------
    >>> lonlat_from_pixel([512.0, 256.0], 1024, 512)
    array([0., 0.])
    """
    p = np.asarray(pixel, dtype=np.float64)
    # Written so that the edges are exact: x = 0, W give -pi, pi; y = 0, H give pi/2, -pi/2.
    lon = np.pi * (2.0 * p[..., 0] / width - 1.0)
    lat = np.pi * (0.5 - p[..., 1] / height)
    return np.stack([lon, lat], axis=-1)


def pixel_from_lonlat(lonlat: ArrayLike, width: int, height: int) -> FloatArray:
    """Equirectangular pixel coordinates of longitude and latitude (radians).

    Convention: origin at the top-left corner, pixel centres at half-integers.
    Longitude is not wrapped: callers wrap ``x`` modulo ``width`` as needed.

    Examples
    --------
    >>> pixel_from_lonlat([np.pi / 2, np.pi / 4], 1024, 512)
    array([768., 128.])
    """
    ll = np.asarray(lonlat, dtype=np.float64)
    x = (ll[..., 0] / np.pi + 1.0) * (0.5 * width)
    y = (0.5 - ll[..., 1] / np.pi) * height
    return np.stack([x, y], axis=-1)


def xyz_from_lonlat(lonlat: ArrayLike) -> FloatArray:
    """Unit vectors from longitude and latitude (radians).

    Examples
    --------
    >>> xyz_from_lonlat([0.0, 0.0])
    array([1., 0., 0.])
    """
    ll = np.asarray(lonlat, dtype=np.float64)
    lon, lat = ll[..., 0], ll[..., 1]
    c = np.cos(lat)
    return np.stack([c * np.cos(lon), c * np.sin(lon), np.sin(lat)], axis=-1)


def lonlat_from_xyz(xyz: ArrayLike) -> FloatArray:
    """Longitude and latitude (radians) of vectors (need not be unit length).

    Longitude is in ``[-pi, pi]``; at the poles it is whatever ``arctan2``
    gives (0 for an exact pole).

    Examples
    --------
    >>> np.degrees(lonlat_from_xyz([0.0, 1.0, 1.0])).round(9)
    array([90., 45.])
    """
    v = np.asarray(xyz, dtype=np.float64)
    x, y, z = v[..., 0], v[..., 1], v[..., 2]
    lon = np.arctan2(y, x)
    lat = np.arctan2(z, np.hypot(x, y))
    return np.stack([lon, lat], axis=-1)


def normalize_cp1(zw: ArrayLike) -> ComplexArray:
    """Scale homogeneous pairs to unit norm.

    A pair ``(0, 0)`` (no point at all) is replaced by ``(0, 1)``, the origin,
    so that nothing downstream ever divides by zero; callers that can produce
    it mark such points as undefined.

    Examples
    --------
    >>> normalize_cp1([3.0, 4.0j])
    array([0.6+0.j , 0. +0.8j])
    """
    v = np.asarray(zw, dtype=np.complex128)
    with np.errstate(over="ignore", under="ignore"):
        n = np.sqrt(np.abs(v[..., 0]) ** 2 + np.abs(v[..., 1]) ** 2)
    odd = ~((n > 1e-150) & (n < 1e150))  # also NaN
    if np.any(odd):
        # Rescale by the larger entry first, so that huge and tiny (even
        # subnormal) pairs neither overflow nor underflow.
        v = v.copy()
        sub = v[odd]
        s = np.maximum(np.abs(sub[..., 0]), np.abs(sub[..., 1]))
        bad = ~(s > 0) | ~np.isfinite(s)
        sub[bad] = (0.0, 1.0)
        # divide the real and imaginary parts as reals (complex division can overflow)
        parts = sub.view(np.float64) / np.where(bad, 1.0, s)[..., None]
        sub = parts.view(np.complex128)
        v[odd] = sub
        n = n.copy() if n.ndim else np.array(n)
        n[odd] = np.sqrt(np.abs(sub[..., 0]) ** 2 + np.abs(sub[..., 1]) ** 2)
    return v / n[..., None]


def cp1_from_xyz(xyz: ArrayLike) -> ComplexArray:
    """Unit-norm homogeneous pairs of points of the sphere (default chart).

    Stereographic projection from the nadir: ``z/w = -(x + iy)/(1 + z)``.
    Each point uses the one of two proportional formulas that is far from
    ``0/0``, so the poles are exact.

    Examples
    --------
    >>> zw = cp1_from_xyz([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])
    >>> plane_from_cp1(zw).round(12) + 0   # zenith, back, lon -90
    array([0.+0.j, 1.+0.j, 0.+1.j])
    """
    v = np.asarray(xyz, dtype=np.float64)
    x, y, z = v[..., 0], v[..., 1], v[..., 2]
    north = z >= 0
    # (-(x+iy), 1+z) is proportional to (1-z, -(x-iy)) on the unit sphere.
    a = np.where(north, -(x + 1j * y), 1.0 - z)
    b = np.where(north, 1.0 + z, -(x - 1j * y))
    return normalize_cp1(np.stack([a, b], axis=-1))


def xyz_from_cp1(zw: ArrayLike) -> FloatArray:
    """Points of the sphere of homogeneous pairs (default chart).

    The pairs need not be normalised. No division by the second coordinate
    is made, so infinity is an ordinary point.

    Examples
    --------
    >>> xyz_from_cp1([1.0, 0.0])
    array([ 0.,  0., -1.])
    """
    v = normalize_cp1(zw)
    a, b = v[..., 0], v[..., 1]
    s = -2.0 * a * np.conj(b)
    zc = np.abs(b) ** 2 - np.abs(a) ** 2
    return np.stack([s.real, s.imag, zc], axis=-1)


def cp1_from_plane(z: ArrayLike) -> ComplexArray:
    """Homogeneous pairs of points of the extended plane.

    ``inf`` (or any non-finite complex) is the point at infinity ``(1, 0)``.
    Large finite values are handled without overflow.

    Examples
    --------
    >>> cp1_from_plane([0, 1, np.inf]).round(12)
    array([[0.        +0.j, 1.        +0.j],
           [0.70710678+0.j, 0.70710678+0.j],
           [1.        +0.j, 0.        +0.j]])
    """
    zz = np.asarray(z, dtype=np.complex128)
    finite = np.isfinite(zz)
    zs = np.where(finite, zz, 0.0)
    # Scale (z, 1) by the largest component of z when that exceeds 1: both
    # entries stay finite and non-zero even for |z| near the float64 limit
    # (1/z itself would overflow inside the complex division).
    m = np.maximum(np.abs(zs.real), np.abs(zs.imag))
    scale = np.where(m > 1.0, m, 1.0)
    a = np.where(finite, zs / scale, 1.0)
    b = np.where(finite, 1.0 / scale, 0.0)
    return normalize_cp1(np.stack([a, b], axis=-1))


def plane_from_cp1(zw: ArrayLike) -> ComplexArray:
    """Points ``z/w`` of the extended plane, ``inf`` where ``w == 0``.

    Examples
    --------
    >>> plane_from_cp1([[1.0, 2.0], [1.0, 0.0]])
    array([0.5+0.j,  inf+0.j])
    """
    v = np.asarray(zw, dtype=np.complex128)
    a, b = v[..., 0], v[..., 1]
    zero = b == 0
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        out = a / np.where(zero, 1.0, b)
    return np.where(zero, complex(np.inf, 0.0), out)


def plane_from_lonlat(lonlat: ArrayLike) -> ComplexArray:
    """Default-chart coordinate ``tan((pi/2 - lat)/2) * exp(i (lon + pi))``.

    Examples
    --------
    >>> plane_from_lonlat(np.radians([0.0, 0.0])).round(12)
    np.complex128(-1+0j)
    """
    return plane_from_cp1(cp1_from_xyz(xyz_from_lonlat(lonlat)))


def lonlat_from_plane(z: ArrayLike) -> FloatArray:
    """Longitude and latitude (radians) of default-chart coordinates.

    Examples
    --------
    >>> np.degrees(lonlat_from_plane(1j)).round(9)
    array([-90.,   0.])
    """
    return lonlat_from_xyz(xyz_from_cp1(cp1_from_plane(z)))


def cp1_from_lonlat(lonlat: ArrayLike) -> ComplexArray:
    """Unit-norm homogeneous pairs straight from longitude and latitude.

    With colatitude ``c = pi/2 - lat`` the pair is
    ``(-sin(c/2) exp(i lon), cos(c/2))``: unit norm by construction, exact at
    both poles, and the same points as ``cp1_from_xyz(xyz_from_lonlat(.))``.

    Examples
    --------
    >>> cp1_from_lonlat(np.radians([0.0, 0.0])).round(12)
    array([-0.70710678+0.j,  0.70710678+0.j])
    """
    ll = np.asarray(lonlat, dtype=np.float64)
    half = 0.25 * np.pi - 0.5 * ll[..., 1]
    a = -np.sin(half) * np.exp(1j * ll[..., 0])
    # cos(half) as sin(pi/2 - half), so that it is exactly 0 at the nadir.
    b = np.sin(0.25 * np.pi + 0.5 * ll[..., 1])
    return np.stack([a, b.astype(np.complex128)], axis=-1)


def lonlat_from_cp1(zw: ArrayLike) -> FloatArray:
    """Longitude and latitude (radians) of homogeneous pairs.

    The pairs need not be normalised; at the poles the longitude is arbitrary.
    :func:`lonlat_deg_from_cp1` gives degrees, the unit of the rest of the API.

    Examples
    --------
    >>> np.degrees(lonlat_from_cp1([[1.0, 1.0], [1.0j, 1.0]])).round(9)
    array([[180.,   0.],
           [-90.,   0.]])
    """
    v = np.asarray(zw, dtype=np.complex128)
    a, b = v[..., 0], v[..., 1]
    colat = 2.0 * np.arctan2(np.abs(a), np.abs(b))
    lon = np.angle(-a * np.conj(b))
    return np.stack([lon, 0.5 * np.pi - colat], axis=-1)


def lonlat_deg_from_cp1(zw: ArrayLike) -> FloatArray:
    """Longitude and latitude in **degrees** of homogeneous pairs.

    :func:`lonlat_from_cp1` in the units of the rest of the API (maps and the
    command line take points as ``(lon, lat)`` in degrees).

    Examples
    --------
    >>> from spherewarp.maps import Mobius
    >>> m = Mobius.zoom((-163, 5), 3.0)
    >>> lonlat_deg_from_cp1(m.pull_cp1(cp1_from_lonlat_deg([-163.0, 5.0]))).round(9)
    array([-163.,    5.])
    """
    return np.degrees(lonlat_from_cp1(zw))


def cp1_from_lonlat_deg(lonlat_deg: ArrayLike) -> ComplexArray:
    """Unit-norm homogeneous pairs of longitude and latitude in **degrees**.

    Examples
    --------
    >>> cp1_from_lonlat_deg([0.0, 90.0]).round(12)     # the zenith is 0 in the default chart
    array([-0.+0.j,  1.+0.j])
    """
    return cp1_from_lonlat(np.radians(np.asarray(lonlat_deg, dtype=np.float64)))


def lonlat_deg_from_pixel(pixel: ArrayLike, width: int, height: int) -> FloatArray:
    """Longitude and latitude in **degrees** of equirectangular pixel coordinates.

    Examples
    --------
    >>> lonlat_deg_from_pixel([512.0, 256.0], 1024, 512)
    array([0., 0.])
    """
    return np.degrees(lonlat_from_pixel(pixel, width, height))


def pixel_from_lonlat_deg(lonlat_deg: ArrayLike, width: int, height: int) -> FloatArray:
    """Equirectangular pixel coordinates of longitude and latitude in **degrees**.

    Examples
    --------
    >>> pixel_from_lonlat_deg([90.0, 45.0], 1024, 512)
    array([768., 128.])
    """
    return pixel_from_lonlat(np.radians(np.asarray(lonlat_deg, dtype=np.float64)), width, height)


def antipode_cp1(zw: ArrayLike) -> ComplexArray:
    """The antipodal points: ``(a, b) -> (-conj(b), conj(a))``.

    Examples
    --------
    >>> antipode_cp1([0.0, 1.0])
    array([-0.+0.j,  1.-0.j])
    """
    v = np.asarray(zw, dtype=np.complex128)
    return np.stack([-np.conj(v[..., 1]), np.conj(v[..., 0])], axis=-1)


def parse_lonlat(text: str) -> tuple[float, float]:
    """Parse ``"LON,LAT"`` in degrees, checking the ranges.

    Raises
    ------
    InvalidValueError
        If the text is not two numbers, or latitude is outside [-90, 90].

    Examples
    --------
    >>> parse_lonlat("30,-45.5")
    (30.0, -45.5)
    """
    parts = str(text).replace(" ", "").split(",")
    try:
        lon, lat = (float(p) for p in parts)
    except ValueError:
        raise InvalidValueError(
            f"expected a point as LON,LAT in degrees (e.g. 30,-10), got {text!r}"
        ) from None
    if not (np.isfinite(lon) and np.isfinite(lat)) or abs(lat) > 90:
        raise InvalidValueError(
            f"expected latitude in [-90, 90] and finite longitude, got {text!r}"
        )
    return lon, lat
