"""Adaptive anti-aliasing: how many samples each output pixel needs.

A conformal map magnifies a small disc by its local scale ``s`` (the
spherical magnification, :meth:`~spherewarp.maps.SphereMap.local_scale`) and
turns it, without shearing it. An output pixel of an equirectangular image
of size ``W_out x H_out`` at latitude ``lat`` spans ``2 pi cos(lat) / W_out``
by ``pi / H_out`` radians, so its pre-image in the input spans ``s`` times
that, which is

* ``nx = s cos(lat) (2 pi / W_out) / rho`` input pixels along the image of
  the output's rows, and
* ``ny = s (pi / H_out) / rho`` input pixels along the image of its columns,

with ``rho = min(pi / H_in, 2 pi / W_in)`` the angular size of an input pixel.
Since the map is conformal these two numbers hold whatever the rotation. A
bilinear tap is a fine filter for a footprint up to about one input pixel;
beyond that the pixel is supersampled on a ``ceil(nx - tol) x ceil(ny - tol)``
grid (capped), and only there: on a rotation nothing is supersampled at all.

The magnification says nothing where the map jumps (the seams between the
copies of a Droste image): an output pixel there straddles points far apart
in the input. :func:`jump_mask` finds them by comparing the distance between
the source points of neighbouring pixels with what the magnification allows,
and those pixels get ``JUMP_SAMPLES x JUMP_SAMPLES`` samples. The compiled
renderer makes the same test in its kernel (for maps with a stage in
:data:`spherewarp.render.fast.JUMP_KINDS`), and cached maps
(:class:`~spherewarp.render.cache.WarpMap`) call :func:`jump_mask`, so all
three paths supersample the same pixels.

What ``auto`` does not do is filter pixels whose footprint is under one input
pixel: they get one bilinear tap, the sharpest choice and what a rotation
needs. A supersampled reference averages the bilinear surface over every
pixel, so it differs from ``auto`` there (measured by ``bench/aa_profile.py``).

The equirectangular input is oversampled along its rows near its poles
(``rho`` is the size of a pixel at the equator), so a footprint there is not
made smaller by the input's tiny pole pixels: the sampling rate follows the
sphere, not the chart.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from ..errors import InvalidValueError

__all__ = [
    "AUTO_DENSITY",
    "AUTO_MAX",
    "AUTO_TOLERANCE",
    "JUMP_SAMPLES",
    "footprint_factors",
    "jump_mask",
    "parse_antialias",
    "sample_counts",
    "subsample_offsets",
]

#: samples per input pixel of footprint, per axis
AUTO_DENSITY = 1.0
#: ``ceil(AUTO_DENSITY * footprint - AUTO_TOLERANCE)`` samples per axis: a footprint up to
#: ``(1 + AUTO_TOLERANCE) / AUTO_DENSITY`` input pixels gets a single bilinear sample
AUTO_TOLERANCE = 0.1
#: at most this many samples per axis and output pixel in ``antialias="auto"``
AUTO_MAX = 8
#: largest uniform supersampling accepted
MAX_UNIFORM = 32
#: samples per axis, in ``"auto"``, for pixels on a jump of the map (a seam of a Droste map)
JUMP_SAMPLES = 4
#: what ``"area"`` renders as where the area filter is not compiled (maps without kernel
#: stages, several input images, interpolations other than bilinear, cached maps): uniform
#: supersampling, which the area filter approximates
AREA_FALLBACK = ("uniform", 4)


def parse_antialias(antialias: str | int | None, supersample: int | None = None) -> tuple[str, int]:
    """Normalise the anti-aliasing options to ``(mode, n)``.

    ``mode`` is ``"none"``, ``"auto"``, ``"area"`` or ``"uniform"`` (``n x n``
    samples a pixel). ``supersample`` is the older option for uniform supersampling:
    a value above 1 wins over ``antialias``; 1 (its old default) or None
    leave the choice to ``antialias``.

    Examples
    --------
    >>> parse_antialias("AUTO"), parse_antialias("none"), parse_antialias(4), parse_antialias("3")
    (('auto', 0), ('none', 1), ('uniform', 4), ('uniform', 3))
    >>> parse_antialias("area")
    ('area', 0)
    >>> parse_antialias("auto", supersample=1), parse_antialias("none", supersample=2)
    (('auto', 0), ('uniform', 2))
    """
    if supersample is not None:
        if (
            isinstance(supersample, bool)
            or not isinstance(supersample, (int, np.integer))
            or not (1 <= supersample <= MAX_UNIFORM)
        ):
            raise InvalidValueError(
                f"expected supersample to be an integer 1..{MAX_UNIFORM}, got {supersample!r}"
            )
        if supersample > 1:
            return ("uniform", int(supersample))
    if antialias is None:
        return ("none", 1)
    if isinstance(antialias, str):
        name = antialias.strip().lower()
        if name in ("auto", "adaptive"):
            return ("auto", 0)
        if name in ("none", "off", "no"):
            return ("none", 1)
        if name == "area":
            return ("area", 0)
        if name.isdigit():
            antialias = int(name)
    if (
        isinstance(antialias, (int, np.integer))
        and not isinstance(antialias, bool)
        and 1 <= antialias <= MAX_UNIFORM
    ):
        n = int(antialias)
        return ("none", 1) if n == 1 else ("uniform", n)
    raise InvalidValueError(
        f"expected antialias to be 'auto', 'area', 'none' or an integer 1..{MAX_UNIFORM}, "
        f"got {antialias!r}"
    )


def footprint_factors(in_shape: tuple[int, int], out_shape: tuple[int, int]) -> tuple[float, float]:
    """``(kx, ky)``: input pixels spanned by an output pixel per unit of magnification.

    Along the output's rows the span is ``s * kx * cos(lat)``, along its
    columns ``s * ky`` (see the module docstring).

    Examples
    --------
    >>> footprint_factors((512, 1024), (256, 512))
    (2.0, 2.0)
    """
    h_in, w_in = in_shape
    h_out, w_out = out_shape
    rho = min(math.pi / h_in, 2 * math.pi / w_in)
    return (2 * math.pi / w_out) / rho, (math.pi / h_out) / rho


def sample_counts(
    scale: NDArray[np.floating],
    lat_out: NDArray[np.floating],
    factors: tuple[float, float],
    tol: float = AUTO_TOLERANCE,
    cap: int = AUTO_MAX,
) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """Samples per axis ``(nx, ny)`` for pixels of magnification ``scale`` at ``lat_out``.

    Examples
    --------
    >>> nx, ny = sample_counts(np.array([1.0, 3.0, 3.0]), np.radians([0.0, 0.0, 60.0]), (1.0, 1.0))
    >>> nx.tolist(), ny.tolist()
    ([1, 3, 2], [1, 3, 3])
    """
    kx, ky = factors
    s = np.asarray(scale, dtype=np.float64)
    cl = np.cos(np.asarray(lat_out, dtype=np.float64))
    nx = np.clip(np.ceil(s * kx * cl - tol), 1, cap).astype(np.int64)
    ny = np.clip(np.ceil(s * ky - tol), 1, cap).astype(np.int64)
    return nx, ny


def subsample_offsets(
    nx: NDArray[np.integer], ny: NDArray[np.integer]
) -> tuple[NDArray[np.int64], NDArray[np.float64], NDArray[np.float64]]:
    """Owner pixel and in-pixel offsets of ``nx[k] x ny[k]`` subsamples of each pixel.

    Subsamples are the centres of an ``nx x ny`` grid on the pixel, in row
    order, pixel after pixel.

    Returns
    -------
    owner : ndarray of int64, shape (total,)
        Index of the pixel each subsample belongs to (non-decreasing).
    ox, oy : ndarray of float64, shape (total,)
        Offsets in ``(0, 1)`` from the pixel's top-left corner.

    Examples
    --------
    >>> owner, ox, oy = subsample_offsets(np.array([1, 2]), np.array([1, 1]))
    >>> owner.tolist(), ox.tolist(), oy.tolist()
    ([0, 1, 1], [0.5, 0.25, 0.75], [0.5, 0.5, 0.5])
    """
    nx = np.asarray(nx, dtype=np.int64)
    ny = np.asarray(ny, dtype=np.int64)
    per = nx * ny
    owner = np.repeat(np.arange(per.size), per)
    start = np.cumsum(per) - per
    m = np.arange(owner.size) - start[owner]
    nxo = nx[owner]
    a = m % nxo
    b = m // nxo
    return owner, (a + 0.5) / nxo, (b + 0.5) / ny[owner]


def jump_mask(
    xyz: NDArray[np.floating],
    scale: NDArray[np.floating],
    lat_out: NDArray[np.floating],
    valid: NDArray[np.bool_] | None,
    rho_in: float,
    out_height: int,
) -> NDArray[np.bool_]:
    """Pixels next to a jump of the map, for rows of an equirectangular output.

    Parameters
    ----------
    xyz : ndarray, shape (rows, W, 3)
        Source points of the pixel centres (unit vectors); the last row is
        only a neighbour of the one above (pass one row more than you need).
    scale : ndarray, shape (rows, W)
        The map's magnification at the pixel centres.
    lat_out : ndarray, shape (rows,)
        Latitude of each row of the output.
    valid : ndarray of bool, shape (rows, W), or None
        Where the map is defined (holes do not make jumps).
    rho_in : float
        Angular size of an input pixel.
    out_height : int
        Rows of the whole output (the step between rows is ``pi / out_height``).

    Returns
    -------
    ndarray of bool, shape (rows - 1, W)
        True for both pixels of a neighbouring pair (in a row, across the
        seam too, or in a column) whose source points are further apart than
        twice what the magnification allows, plus two input pixels.

    Examples
    --------
    >>> lon = np.linspace(-np.pi, np.pi, 16, endpoint=False)
    >>> xyz = np.stack([np.cos(lon), np.sin(lon), 0 * lon], -1)[None].repeat(2, 0)
    >>> xyz[:, 3] = (0.0, 0.0, 1.0)      # one column jumps to the zenith
    >>> jump_mask(xyz, np.ones((2, 16)), np.zeros(2), None, 0.01, 8).astype(int)
    array([[0, 0, 1, 1, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0]])
    """
    rows, w = scale.shape
    h_step = 2 * np.pi / w * np.cos(np.asarray(lat_out, np.float64))[:, None]
    ok = np.ones(scale.shape, bool) if valid is None else np.asarray(valid, bool)
    # along rows (with the seam): pixel j and j + 1
    d = np.linalg.norm(np.roll(xyz, -1, axis=1) - xyz, axis=-1)
    allow = 2 * np.maximum(scale, np.roll(scale, -1, axis=1)) * h_step + 2 * rho_in
    jump = (d > allow) & ok & np.roll(ok, -1, axis=1)
    mask = jump | np.roll(jump, 1, axis=1)
    # along columns: row i and i + 1
    v_step = np.pi / out_height
    d = np.linalg.norm(xyz[1:] - xyz[:-1], axis=-1)
    allow = 2 * np.maximum(scale[1:], scale[:-1]) * v_step + 2 * rho_in
    vj = (d > allow) & ok[1:] & ok[:-1]
    mask[:-1] |= vj
    mask[1:] |= vj
    return mask[:-1]
