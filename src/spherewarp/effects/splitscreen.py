"""Seamless split-screen: several panoramas on the sheets of a branched cover.

The paper's spherical analogue of split screen ("Pulling back, pushing
forward, and branch points"): pull back by a k-fold branched cover (``z**k``,
or the exp variant with its infinitely many sheets) and let each sheet show a
different input panorama. Panoramas taken from the same spot (an empty room,
and the same room with a person in it) then combine into one panorama, in
which the seams run along arcs between the branch points.

Every output point ``q`` is pulled back to the input point ``S(q)``; which
input is sampled there depends on the sheet of ``q``: the sector around the
branch points for ``z**k`` (a lune between two meridians of the cover's
chart), the horizontal copy for the exp variant. All seams are lifts of one
input meridian (the *seam meridian*, at angle ``seam`` of the cover's chart),
so every sheet shows its whole input once and the seams are invisible where
the inputs agree along that meridian. ``seam="auto"`` picks the meridian
along which the inputs differ least (:func:`auto_seam`).

Across each seam the two inputs are cross-faded over a band of
``feather_deg`` degrees of input longitude around the seam meridian (in the
output of ``z**k`` the band is ``feather_deg / k`` degrees wide). The blend is
done in the inputs' own coordinates: each sheet samples a pre-blended copy of
its input (:func:`_blended_sheets`), so the renderer (:func:`~spherewarp.render.warp`, with
:attr:`~spherewarp.maps.PullBack.sheet`) is used unchanged and the result is
exactly the pull-back of the inputs wherever the feather band is not.

Convention: longitudes are in degrees; for a cover with other branch points
(``branch_points``) they are measured in the frame in which the branch points
are the zenith and the nadir (see
:func:`~spherewarp.maps.chart_for_branch_points`).

Examples
--------
>>> import numpy as np
>>> from spherewarp.effects.splitscreen import splitscreen
>>> red = np.zeros((32, 64, 3), np.uint8); red[..., 0] = 255
>>> blue = np.zeros((32, 64, 3), np.uint8); blue[..., 2] = 255
>>> out = splitscreen([red, blue], seam=0.0, feather_deg=0.0)   # seams at lon -90 and 90
>>> out[16, 32].tolist(), out[16, 0].tolist()       # front: sheet 0; back: sheet 1
([255, 0, 0], [0, 0, 255])
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import coords
from ..errors import InvalidTypeError, InvalidValueError
from ..maps.branched import ExpMap, Power
from ..maps.mobius import Mobius, PointLike
from ..maps.sheeted import COVERS, SheetedCover, _seam_angle, make_cover

_TWO_PI = 2.0 * math.pi
_ROW_BLOCK = 1 << 18  # pixels per block when building the blended sheets
_POLE_PIXELS = 3.0  # no cross-fade this close (in pixel heights) to the branch points

__all__ = [
    "COVERS",
    "SheetedCover",
    "auto_seam",
    "conform_images",
    "make_cover",
    "seam_costs",
    "splitscreen",
]

# -- the inputs -----------------------------------------------------------------------------


def _full(dtype: np.dtype) -> float:
    return float(np.iinfo(dtype).max) if dtype.kind == "u" else 1.0


def _convert(img: NDArray, dtype: np.dtype) -> NDArray:
    if img.dtype == dtype:
        return img
    if dtype.kind == "f":
        return (img.astype(np.float32) / np.float32(_full(img.dtype))).astype(dtype)
    # uint8 -> uint16 (the only widening between integer types used here)
    return img.astype(dtype) * np.array(_full(dtype) // _full(img.dtype), dtype=dtype)


def conform_images(
    images: Sequence[ArrayLike],
    *,
    shape: tuple[int, int] | None = None,
    force: bool = False,
) -> list[NDArray]:
    """Bring equirectangular images to one size, dtype and channel count.

    The size is ``shape`` (height, width) or the largest input's; smaller
    inputs are resampled on the sphere (bilinear). The dtype is float32 if
    any input is a float image, else uint16 if any is, else uint8. Grey
    becomes RGB when any input has colour, and an opaque alpha channel is
    added when any input has alpha (so RGB + RGBA gives RGBA).

    Examples
    --------
    >>> grey = np.full((16, 32), 128, np.uint8)
    >>> rgba = np.zeros((32, 64, 4), np.uint8)
    >>> [(a.shape, a.dtype.name) for a in conform_images([grey, rgba])]
    [((32, 64, 4), 'uint8'), ((32, 64, 4), 'uint8')]
    """
    from ..render.warp import as_image, check_equirect, warp

    if isinstance(images, np.ndarray) or not isinstance(images, Sequence) or not images:
        raise InvalidValueError("expected a non-empty sequence of images")
    arrays = [as_image(im, f"image {k}") for k, im in enumerate(images)]
    for k, im in enumerate(arrays):
        check_equirect(im, force, f"image {k}")
    kinds = {a.dtype for a in arrays}
    if any(d.kind == "f" for d in kinds):
        dtype = np.dtype(np.float32)
    elif np.dtype(np.uint16) in kinds:
        dtype = np.dtype(np.uint16)
    else:
        dtype = np.dtype(np.uint8)
    colour = any(a.shape[2] >= 3 for a in arrays)
    alpha = any(a.shape[2] in (2, 4) for a in arrays)
    if shape is None:
        big = max(arrays, key=lambda a: (a.shape[0] * a.shape[1], a.shape[1]))
        shape = big.shape[:2]
    h, w = (int(v) for v in shape)
    out = []
    for a in arrays:
        a = _convert(a, dtype)
        c = a.shape[2]
        has_alpha = c in (2, 4)
        base = a[..., : c - 1] if has_alpha else a
        if colour and base.shape[2] == 1:
            base = np.repeat(base, 3, axis=2)
        if alpha:
            a_ch = a[..., -1:] if has_alpha else np.full(a.shape[:2] + (1,), _full(dtype), dtype)
            a = np.concatenate([base, a_ch.astype(dtype)], axis=2)
        else:
            a = base
        if a.shape[:2] != (h, w):
            ss = max(1, min(8, math.ceil(max(a.shape[0] / h, a.shape[1] / w))))
            a = warp(a, Mobius.identity(), output_shape=(h, w), supersample=ss, force=True)
        out.append(np.ascontiguousarray(a))
    return out


# -- choosing the seam ----------------------------------------------------------------------


def _comparable(img: NDArray) -> NDArray[np.float32]:
    """Values in [0, 1] for comparing images (floats tone-mapped, so HDR does not dominate)."""
    if img.dtype.kind == "u":
        return img.astype(np.float32) / np.float32(_full(img.dtype))
    x = np.abs(img.astype(np.float32))
    return x / (1.0 + x)


def _circular_mean(values: NDArray[np.float64], k: int) -> NDArray[np.float64]:
    """Moving average over ``k`` (odd) neighbouring entries, wrapping around."""
    if k <= 1:
        return values
    k = min(k, 2 * (len(values) // 2) - 1)
    padded = np.concatenate([values[-(k // 2) :], values, values[: k // 2]])
    return np.convolve(padded, np.full(k, 1.0 / k), mode="valid")


def _column_costs(
    images: Sequence[ArrayLike],
    cover: str | Power | ExpMap,
    n: int | None,
    lam: float,
    branch_points: tuple[PointLike, PointLike] | None,
    feather_deg: float,
    width: int,
    force: bool,
) -> tuple[NDArray[np.float64], NDArray[np.float64], int]:
    """Candidate longitudes, the unsmoothed cost of each, and the smoothing window (columns)."""
    from ..render.warp import warp

    imgs = conform_images(images, force=force)
    m = len(imgs)
    cov = make_cover(cover, n=n if n is not None else m, lam=lam, branch_points=branch_points)
    feather = _check_feather(feather_deg)
    h, w = imgs[0].shape[:2]
    w_a = int(min(w, max(16, width)))
    w_a -= w_a % 2
    chart = cov._chart
    if chart is None and w_a == w:
        grids = [_comparable(im) for im in imgs]
    else:
        to_chart = Mobius.identity() if chart is None else chart.inverse()
        ss = max(1, min(4, math.ceil(w / w_a)))
        grids = [
            _comparable(
                warp(im, to_chart, output_shape=(w_a // 2, w_a), supersample=ss, force=True)
            )
            for im in imgs
        ]
    cols = np.zeros(w_a, np.float64)
    if m > 1:
        for j in range(m):
            diff = np.abs(grids[j] - grids[(j + 1) % m])
            cols += diff.mean(axis=(0, 2), dtype=np.float64)
    k = max(3, round(feather / 360.0 * w_a))
    k += 1 - k % 2  # odd, centred
    lons = (np.arange(w_a) + 0.5) * (360.0 / w_a) - 180.0
    return lons, cols, k


def seam_costs(
    images: Sequence[ArrayLike],
    *,
    cover: str | Power | ExpMap = "power",
    n: int | None = None,
    lam: float = 4.0,
    branch_points: tuple[PointLike, PointLike] | None = None,
    feather_deg: float = 10.0,
    width: int = 1024,
    force: bool = False,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """How badly the inputs disagree along each candidate seam meridian.

    For each meridian of the cover's chart, the mean absolute difference
    (values scaled to [0, 1], averaged over the meridian from pole to pole
    and over channels) between every pair of inputs that meet at a seam,
    summed over those pairs and averaged over a window of ``feather_deg``
    degrees of longitude (at least 3 columns) around the meridian.

    Returns
    -------
    lons, costs : ndarray
        Candidate seam longitudes (degrees, column centres of a grid at most
        ``width`` wide) and their costs.

    Examples
    --------
    >>> img = np.random.default_rng(0).integers(0, 256, (32, 64, 3), dtype=np.uint8)
    >>> lons, costs = seam_costs([img, img])
    >>> lons.shape, float(costs.max())
    ((64,), 0.0)
    """
    lons, cols, k = _column_costs(images, cover, n, lam, branch_points, feather_deg, width, force)
    return lons, _circular_mean(cols, k)


def auto_seam(
    images: Sequence[ArrayLike],
    *,
    cover: str | Power | ExpMap = "power",
    n: int | None = None,
    lam: float = 4.0,
    branch_points: tuple[PointLike, PointLike] | None = None,
    feather_deg: float = 10.0,
    force: bool = False,
) -> float:
    """The seam longitude (degrees) where the inputs agree best (see :func:`seam_costs`).

    Near-ties (costs within 2% of the range of costs from the minimum) go to
    the meridian farthest from any worse one: the middle of the band where
    the inputs agree.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> a = rng.integers(0, 256, (64, 128, 3), dtype=np.uint8)
    >>> b = a.copy(); b[:, :100] = 0           # they agree only in columns 100..127
    >>> seam = auto_seam([a, b], feather_deg=20)  # the middle of longitudes 101..180
    >>> bool(130 < seam < 150)
    True
    """
    lons, cols, k = _column_costs(images, cover, n, lam, branch_points, feather_deg, 1024, force)
    costs = _circular_mean(cols, k)
    return float(lons[_deepest_minimum(costs)])


def _deepest_minimum(costs: NDArray[np.float64], tol: float = 0.02) -> int:
    """Index of the minimum, ties (within ``tol`` of the cost range) broken toward the middle.

    Among the entries whose cost is within ``tol * (max - min)`` of the
    minimum, the one farthest (circularly) from any entry that is not.
    """
    lo, hi = float(costs.min()), float(costs.max())
    good = costs <= lo + tol * (hi - lo)
    n = len(costs)
    bad = np.flatnonzero(~good)
    if len(bad) == 0:
        return int(np.argmin(costs))
    idx = np.arange(n)
    pos = np.searchsorted(bad, idx)
    after = bad[pos % len(bad)] + np.where(pos == len(bad), n, 0)
    before = bad[(pos - 1) % len(bad)] - np.where(pos == 0, n, 0)
    dist = np.minimum(after - idx, idx - before)
    dist = np.where(good, dist, -1)
    return int(np.argmax(dist))


# -- the blend ------------------------------------------------------------------------------


def _check_feather(feather_deg: Any) -> float:
    if isinstance(feather_deg, bool) or not isinstance(feather_deg, numbers.Real):
        raise InvalidTypeError(f"expected feather_deg to be a number, got {feather_deg!r}")
    f = float(feather_deg)
    if not (0.0 <= f <= 180.0):
        raise InvalidValueError(f"expected a feather of 0 to 180 degrees, got {feather_deg!r}")
    return f


def _ramp(x: NDArray[np.float64], f: float) -> NDArray[np.float32]:
    """0 before ``-f/2``, 1 after ``f/2``, smoothstep between (a hard step for ``f = 0``)."""
    if f <= 0:
        return (x >= 0).astype(np.float32)
    t = np.clip((x + 0.5 * f) / f, 0.0, 1.0)
    return (t * t * (3.0 - 2.0 * t)).astype(np.float32)


def _seam_offsets(
    shape: tuple[int, int], chart: Mobius | None, phi: float, rows: slice
) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """Chart angle of input pixel centres from the seam meridian, and nearness to the poles.

    Returns arrays broadcastable to ``(rows, W)``: the angle, and whether the
    pixel is within :data:`_POLE_PIXELS` pixel heights of a pole of the chart
    (a branch point), where the samplers' stencils reach round the pole.
    """
    h, w = shape
    eps = math.sin(0.5 * _POLE_PIXELS * math.pi / h)
    if chart is None:
        cols = (np.arange(w) + 0.5) * (_TWO_PI / w)  # chart angle = lon + pi
        y = np.arange(h)[rows] + 0.5
        near = (y < _POLE_PIXELS) | (y > h - _POLE_PIXELS)
        return (cols - phi)[None, :], near[:, None]
    y, x = np.mgrid[rows, 0:w]
    px = np.stack([x + 0.5, y + 0.5], axis=-1)
    zc = chart.pull_cp1(coords.cp1_from_lonlat(coords.lonlat_from_pixel(px, w, h)))
    near = np.minimum(np.abs(zc[..., 0]), np.abs(zc[..., 1])) < eps
    return np.angle(zc[..., 0] * np.conj(zc[..., 1])) - phi, near


def _blended_sheets(
    imgs: list[NDArray], chart: Mobius | None, phi: float, feather_deg: float
) -> list[NDArray]:
    """The pre-blended images that the sheets sample (see :func:`splitscreen`).

    Sheet ``k`` covers the input from the seam meridian (angle 0) round to it
    again (angle 2 pi). Its field ``F_k`` is input ``k`` cross-faded into
    input ``k - 1`` near angle 0 and into input ``k + 1`` near 2 pi; it is
    continuous on the whole sphere except, for three or more inputs, along
    the seam meridian itself. So for two inputs the sheets sample ``F_k``;
    for more, each sheet is split in halves (``E_k``, ``X_k``) which are
    ``F_k`` continued smoothly across the seam meridian for a few pixels on
    the side that half's samples can reach. Within a few pixels of the branch
    points, where the samplers' stencils reach round the pole to every angle,
    each sheet is its own input, unblended.
    """
    m = len(imgs)
    h, w, _ = imgs[0].shape
    dtype = imgs[0].dtype
    f = math.radians(feather_deg)
    halves = m >= 3
    reach = 4 * _TWO_PI / w  # the samplers' reach, 2 pixels, with room to spare
    out = [np.empty_like(imgs[0]) for _ in range(2 * m if halves else m)]
    step = max(1, _ROW_BLOCK // w)
    for r0 in range(0, h, step):
        rows = slice(r0, min(h, r0 + step))
        delta, near_pole = _seam_offsets((h, w), chart, phi, rows)
        d = np.mod(delta, _TWO_PI)
        first = d < math.pi
        r_first = _ramp(d, f)  # near angle 0: from input k - 1 into input k
        r_last = _ramp(d - _TWO_PI, f)  # near 2 pi: from input k into input k + 1
        w_prev = np.where(first, 1.0 - r_first, 0.0)[..., None]
        w_next = np.where(first, 0.0, r_last)[..., None]
        weights = [(w_prev, w_next)]
        if halves:
            before = (d >= _TWO_PI - reach)[..., None]
            after = (d < reach)[..., None]
            weights = [
                (np.where(before, 1.0 - r_last[..., None], w_prev), np.where(before, 0.0, w_next)),
                (np.where(after, 0.0, w_prev), np.where(after, r_first[..., None], w_next)),
            ]
        # At the branch points stencils reach across to every angle: no blend there.
        far = (~near_pole)[..., None].astype(np.float32)
        weights = [(wp * far, wn * far) for wp, wn in weights]
        block = [im[rows].astype(np.float32) for im in imgs]
        for k in range(m):
            prev, cur, nxt = block[(k - 1) % m], block[k], block[(k + 1) % m]
            for half, (wp, wn) in enumerate(weights):
                val = (
                    cur + wp.astype(np.float32) * (prev - cur) + wn.astype(np.float32) * (nxt - cur)
                )
                if dtype.kind == "u":
                    info = np.iinfo(dtype)
                    val = np.clip(np.rint(val), info.min, info.max)
                out[len(weights) * k + half][rows] = val.astype(dtype)
    return out


def splitscreen(
    images: Sequence[ArrayLike],
    *,
    cover: str | Power | ExpMap = "power",
    n: int | None = None,
    lam: float = 4.0,
    branch_points: tuple[PointLike, PointLike] | None = None,
    seam: str | float = "auto",
    feather_deg: float = 10.0,
    view: Mobius | None = None,
    output_shape: tuple[int, int] | None = None,
    interp: str = "bilinear",
    supersample: int = 1,
    force: bool = False,
    antialias: str | int = "auto",
    threads: int | None = None,
    progress: Any = None,
    grid: Any = None,
) -> NDArray:
    """Combine panoramas on the sheets of a branched cover, with feathered seams.

    Parameters
    ----------
    images : sequence of ndarray
        Equirectangular panoramas (any sizes, 1-4 channels, uint8, uint16 or
        float); they are brought to a common size, dtype and channel count
        (:func:`conform_images`). Sheet ``k`` shows ``images[k % len(images)]``.
    cover : {"power", "exp"} or Power or ExpMap
        ``z**n`` (``n`` sheets around the branch points, default ``n =
        len(images)``; ``n`` must be a multiple of ``len(images)``) or the exp
        variant with parameter ``lam`` (infinitely many sheets, side by side).
    n, lam, branch_points
        Parameters of the cover (see :class:`~spherewarp.maps.Power` and
        :class:`~spherewarp.maps.ExpMap`).
    seam : "auto" or float
        Longitude (degrees) of the input meridian along which the sheets are
        cut; ``"auto"`` picks the one where the inputs agree best
        (:func:`auto_seam`). With ``z**n`` in the default chart the output
        seams are at longitudes ``(seam + 180 + 360 j)/n - 180``.
    feather_deg : float
        Width (degrees of input longitude, 0 to 180) of the band around the
        seam meridian over which neighbouring inputs cross-fade; 0 is a hard
        cut.
    view : Mobius, optional
        Pull the result back by this map too (applied first), e.g.
        ``Mobius.rotation_to((0, 0), (0, 90))`` to put the zenith branch
        point at the centre.
    output_shape, interp, supersample, force, antialias, threads, progress, grid
        As for :func:`~spherewarp.render.warp` (``output_shape`` defaults to
        the common input size). Supersample the exp cover: its sheets shrink
        to points at the back.

    Returns
    -------
    ndarray
        The combined panorama, in the common dtype. Where the inputs are
        identical it equals ``warp(image, cover)``.

    Examples
    --------
    >>> img = np.random.default_rng(1).integers(0, 256, (32, 64, 3), dtype=np.uint8)
    >>> from spherewarp.render import warp
    >>> from spherewarp.maps import Power
    >>> diff = splitscreen([img, img]).astype(int) - warp(img, Power(2))  # to float32 rounding
    >>> int(np.abs(diff).max()) <= 1
    True
    """
    from ..render.warp import warp

    imgs = conform_images(images, force=force)
    m = len(imgs)
    cov = make_cover(cover, n=n if n is not None else m, lam=lam, branch_points=branch_points)
    feather = _check_feather(feather_deg)
    if isinstance(seam, str):
        if seam.strip().lower() != "auto":
            raise InvalidValueError(f"expected seam='auto' or a longitude in degrees, got {seam!r}")
        seam_lon = auto_seam(imgs, cover=cov, feather_deg=feather, force=True) if m > 1 else 0.0
    elif isinstance(seam, Sequence) and not isinstance(seam, str):
        if len(seam) != 1:
            raise InvalidValueError(
                f"expected one seam longitude (all seams are lifts of one input meridian), "
                f"got {len(seam)}"
            )
        seam_lon = seam[0]
    else:
        seam_lon = seam
    kwargs: dict[str, Any] = {
        "output_shape": (
            output_shape if output_shape is not None or grid is not None else imgs[0].shape[:2]
        ),
        "grid": grid,
        "interp": interp,
        "supersample": supersample,
        "antialias": antialias,
        "threads": threads,
        "force": True,
        "progress": progress,
    }
    if m == 1 or feather == 0:
        sheets = SheetedCover(cov, m, seam_lon, view=view)
        return warp(imgs if m > 1 else imgs[0], sheets, **kwargs)
    sheets = SheetedCover(cov, m, seam_lon, view=view, halves=m >= 3)
    blended = _blended_sheets(imgs, cov._chart, _seam_angle(sheets.seam), feather)
    return warp(blended, sheets, **kwargs)
