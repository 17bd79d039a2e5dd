"""The pull-back renderer: one renderer for every effect.

For each output pixel the renderer takes its direction, asks the map where it
comes from, and samples the input there (the paper's "pulling back via S",
skimage's ``warp(image, inverse_map)``)::

    pixel -> (lon, lat) -> CP^1 -> S -> CP^1 -> (lon, lat) -> input pixel -> sample

Work is done in tiles of output rows, so memory stays bounded whatever the
output size.

Two paths render the same pull-back:

* the fast path (default, where it applies): compiled kernels
  (:mod:`spherewarp.render.fast`, numba) that evaluate maps which describe
  themselves as compiled stages (Möbius maps, compositions of them) inside
  the kernel, and sample any other map's NumPy-computed coordinates in
  compiled code;
* the reference path (``method="reference"``, or when numba is missing):
  float64 NumPy throughout, the yardstick the fast path is tested against.

Anti-aliasing (``antialias="auto"``, the default) averages every pixel over
its footprint in the input (the area filter) when the map shrinks the input
somewhere, and takes one bilinear tap a pixel when it shrinks nowhere (a
rotation); see :mod:`spherewarp.render.antialias`.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import coords
from ..errors import InvalidTypeError, InvalidValueError
from ..maps.base import SphereMap
from . import antialias as _aa
from .sampling import sample, sample_area

if TYPE_CHECKING:  # pragma: no cover
    from ..grids import Grid
    from .plan import Plan

__all__ = ["warp", "push", "check_equirect", "as_image"]

_DTYPES = (np.uint8, np.uint16, np.float32, np.float64)
_TILE_PIXELS = 1 << 17
#: samples evaluated at once on the NumPy side (bounds memory of adaptive anti-aliasing)
_SAMPLE_BATCH = 1 << 18
METHODS = ("auto", "fast", "reference")


def check_method(method: str) -> str:
    """Normalise a render method name, or raise listing the allowed ones."""
    name = str(method).strip().lower()
    if name not in METHODS:
        raise InvalidValueError(
            f"unknown render method {method!r}; expected one of: {', '.join(METHODS)}"
        )
    return name


def as_image(image: ArrayLike, name: str = "image") -> NDArray:
    """Check an image array and return it as ``(H, W, C)`` (a view, no copy).

    An :class:`~spherewarp.io.ImageData` (what :func:`~spherewarp.io.read_image`
    returns) stands for its ``pixels``.

    Raises
    ------
    InvalidTypeError
        For dtypes other than uint8, uint16, float32 and float64.
    InvalidValueError
        For shapes other than ``(H, W)`` or ``(H, W, C)`` with C in 1..4.
    """
    pixels = getattr(image, "pixels", None)  # an ImageData: its pixels
    arr = np.asarray(pixels if isinstance(pixels, np.ndarray) else image)
    if arr.dtype.type not in _DTYPES:
        raise InvalidTypeError(f"{name}: expected dtype uint8, uint16 or float32, got {arr.dtype}")
    if arr.ndim == 2:
        arr = arr[:, :, None]
    if arr.ndim != 3 or not 1 <= arr.shape[2] <= 4:
        raise InvalidValueError(
            f"{name}: expected an image of shape (H, W) or (H, W, C) with 1-4 channels, "
            f"got {arr.shape}"
        )
    if arr.shape[0] < 1 or arr.shape[1] < 2:
        raise InvalidValueError(
            f"{name}: expected an image at least 2 pixels wide and 1 high, got "
            f"{arr.shape[1]}x{arr.shape[0]}"
        )
    return arr


def check_equirect(image: NDArray, force: bool = False, name: str = "image") -> None:
    """Raise unless ``image`` has the 2:1 shape of an equirectangular image.

    Examples
    --------
    >>> check_equirect(np.zeros((600, 1000, 3), np.uint8))  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    spherewarp.errors.InvalidValueError: image: expected ... = 2 x height, got 1000x600 ...
    """
    h, w = image.shape[:2]
    if w != 2 * h and not force:
        what = f"{name}: expected an equirectangular image with width = 2 x height, got {w}x{h}"
        raise InvalidValueError(
            f"{what} (force=True treats it as equirectangular anyway)",
            cli=f"{what} (--force treats it as equirectangular anyway)",
        )


def _background(background: ArrayLike | None, channels: int) -> NDArray[np.float32]:
    if background is None:
        return np.zeros(channels, np.float32)
    try:
        bg = np.atleast_1d(np.asarray(background, dtype=np.float32))
    except (TypeError, ValueError):  # a colour name: the command line's --background takes it
        raise InvalidTypeError(
            f"expected a background of 1 or {channels} numbers (sample values), got "
            f"{background!r}"
        ) from None
    if bg.size == 1:
        bg = np.repeat(bg, channels)
    if bg.shape != (channels,) or not np.all(np.isfinite(bg)):
        raise InvalidValueError(
            f"expected a background of 1 or {channels} finite values, got {background!r}"
        )
    return bg


def _full_value(dtype: np.dtype) -> float:
    return float(np.iinfo(dtype).max) if dtype.kind in "ui" else 1.0


def warp(
    image: ArrayLike | Sequence[ArrayLike],
    inverse_map: SphereMap,
    *,
    output_shape: tuple[int, int] | None = None,
    interp: str = "bilinear",
    supersample: int | None = None,
    antialias: str | int = "auto",
    background: ArrayLike | None = None,
    alpha: bool = False,
    force: bool = False,
    method: str = "auto",
    threads: int | None = None,
    progress: Callable[[int, int], None] | None = None,
    grid: Grid | None = None,
) -> NDArray:
    """Pull an equirectangular image back through a map of the sphere.

    Output pixel ``p`` gets the colour of the input at ``inverse_map(p)``:
    ``out = in o inverse_map``. To move content forward by a map ``T``
    instead, use :func:`push` (or ``warp(image, T.inverse())``).

    Convention: pixel centres at half-integers; see :mod:`spherewarp.coords`.

    Parameters
    ----------
    image : ndarray (H, W[, C]), ImageData, or sequence of them
        Equirectangular image(s), uint8, uint16 or float32 (float64 too), 1-4
        channels; an :class:`~spherewarp.io.ImageData` from
        :func:`~spherewarp.io.read_image` gives its ``pixels`` (the result is
        pixels: pass the metadata on to :func:`~spherewarp.io.write_image`).
        A sequence gives the sheets that a map with several sheets
        (:attr:`~spherewarp.maps.PullBack.sheet`) samples; they must share
        dtype and channel count but may differ in size. The last of 2 or 4
        channels is straight (unassociated) alpha: colour is filtered
        premultiplied by it, so transparent pixels' colour does not bleed into
        their neighbours (:func:`~spherewarp.render.plan.render_straight_alpha`);
        warp other data of 2 or 4 channels (chroma planes...) one channel at a time.
    inverse_map : SphereMap
        The map from output points to input points.
    output_shape : (height, width), optional
        Default: the shape of the (first) input.
    interp : {"bilinear", "nearest", "bicubic"}
        Sampling; case-insensitive.
    supersample : int, optional
        Above 1: average ``supersample x supersample`` samples in every
        output pixel (the same as ``antialias=supersample``, and it wins over
        ``antialias``); 1 or None leave it to ``antialias``.
    antialias : "auto", "area", "adaptive", "none" or int
        ``"auto"`` (default): ``"area"`` for a map that shrinks the input
        somewhere (a pixel covers more than about one input pixel: a zoom, a
        downscale, the branched, exp, Droste and Lattès maps), else one
        bilinear tap a pixel (a rotation, an enlargement: as sharp as the
        input); ``"adaptive"`` where the interpolation is not bilinear.
        ``"area"``: every pixel is the average of the bilinear image over its
        footprint (4 x 4 taps of tent * box in closed form; a footprint with
        an axis over about 1.5 input pixels is split along its axes and each
        part pulled back): what heavy supersampling gives, in 1/6 to 1/4 of
        the time of uniform 4 x 4 and 3-5 times that of ``"none"`` on zooms
        and Droste maps (up to 1.6 times 4 x 4 where the map sends many
        pixels next to the input's poles, as the exp variant does).
        ``"adaptive"``: supersample only where an output pixel covers more
        than about one input pixel, as many samples as its footprint needs (up
        to 8 x 8), from the map's local magnification, and pixels on a jump of
        the map (a Droste seam) with 4 x 4 samples; one bilinear tap elsewhere
        (sharper and cheaper than ``"area"``, further from a supersampled
        render). ``"none"``: one sample a pixel. ``N``: ``N x N`` samples in
        every pixel.
    background : number or sequence, optional
        Colour where the map is undefined, in the image's units (default 0,
        which for an image with alpha means transparent).
    alpha : bool
        Append an alpha channel (opaque where the map is defined) to an
        image that has none (1 or 3 channels).
    force : bool
        Accept inputs that are not 2:1.
    method : {"auto", "fast", "reference"}
        ``"auto"``: the compiled fast path when numba is installed, else the
        NumPy reference path. ``"fast"`` requires numba. ``"reference"``:
        float64 NumPy only (slow; the yardstick of the tests).
    threads : int, optional
        Worker threads of the fast path (default: all cores).
    progress : callable, optional
        ``progress(done, total)``, called from the calling thread while the
        image renders: first with ``done = 0``, then with non-decreasing
        ``done`` (about every 0.1 s on the fast path, per band of rows on the
        others), last with ``done == total`` when the image is complete. The
        unit of work (tiles, rows) depends on the path: read ``done / total``
        as the fraction done. An exception it raises ends the call (on the
        fast path once the compiled workers have finished their share).
    grid : spherewarp.grids.Grid, optional
        The output's grid (:mod:`spherewarp.grids`): a little planet, a
        rectilinear or fisheye view, a cube map; its shape is the output's
        (``output_shape`` must then be None or equal). Default: the
        equirectangular panorama of ``output_shape``.

    Returns
    -------
    ndarray, shape (height, width, C) (+1 channel with ``alpha``)
        Same dtype as the input. Never NaN for finite input.

    Examples
    --------
    >>> from spherewarp.maps import Mobius
    >>> img = np.random.default_rng(0).integers(0, 255, (8, 16, 3), dtype=np.uint8)
    >>> out = warp(img, Mobius.rotation((0, 90), 45))   # 45 degrees = 2 pixels
    >>> bool(np.array_equal(out, np.roll(img, -2, axis=1)))
    True
    >>> seen = []
    >>> def report(done, total):
    ...     seen.append(done / total)
    >>> _ = warp(img, Mobius.zoom((0, 0), 2), progress=report)
    >>> seen[0], seen[-1], seen == sorted(seen)
    (0.0, 1.0, True)
    """
    if not isinstance(inverse_map, SphereMap):
        raise InvalidTypeError(
            f"expected a map (a spherewarp.maps.SphereMap), got {type(inverse_map).__name__}"
        )
    images = _check_images(image, force)
    if inverse_map.n_sheets > len(images):
        raise InvalidValueError(
            f"this map samples {inverse_map.n_sheets} input images, got {len(images)}"
        )
    if progress is not None and not callable(progress):
        raise InvalidTypeError(
            f"expected progress to be a callable (done, total), got {type(progress).__name__}"
        )
    from .plan import Options, plan

    options = Options(
        interp=interp, antialias=antialias, supersample=supersample, method=method,
        threads=threads, background=background, alpha=alpha,
    )  # fmt: skip
    p = plan(inverse_map, grid, images[0].shape[:2], output_shape, options, n_images=len(images))
    return p.run(images, progress=progress)


def _check_images(image: ArrayLike | Sequence[ArrayLike], force: bool) -> list[NDArray]:
    """The input image(s) as a list of native ``(H, W, C)`` arrays of one dtype and
    channel count, each equirectangular (2:1) unless ``force``."""
    if isinstance(image, np.ndarray) or not isinstance(image, Sequence):
        images = [as_image(image)]
    else:
        images = [as_image(im, f"image {k}") for k, im in enumerate(image)]
        if not images:
            raise InvalidValueError("expected at least one image, got an empty sequence")
    images = [im.astype(im.dtype.newbyteorder("="), copy=False) for im in images]
    for k, im in enumerate(images):
        check_equirect(im, force, "image" if len(images) == 1 else f"image {k}")
        if im.dtype != images[0].dtype or im.shape[2] != images[0].shape[2]:
            raise InvalidValueError(
                "expected images of one dtype and channel count, got "
                f"{images[0].dtype}/{images[0].shape[2]} and {im.dtype}/{im.shape[2]} (image {k})"
            )
    return images


def _rows_done(progress: Callable[[int, int], None] | None, done: int, total: int) -> None:
    """Report ``done`` of ``total`` output rows (when there is a ``progress`` callback)."""
    if progress is not None:
        progress(done, total)


def _warp_reference(
    images: list[NDArray],
    inverse_map: SphereMap,
    out: NDArray,
    interp: str,
    n: int,
    bg: NDArray[np.float32],
    add_alpha: bool,
    progress: Callable[[int, int], None] | None = None,
) -> None:
    """The float64 NumPy reference: ``n x n`` samples a pixel, any number of sheets."""
    h_out, w_out = out.shape[:2]
    channels = images[0].shape[2]
    dtype = images[0].dtype
    offsets = (np.arange(n) + 0.5) / n
    rows_per_tile = max(1, _TILE_PIXELS // (w_out * n * n))
    cols = np.arange(w_out, dtype=np.float64)
    for r0 in range(0, h_out, rows_per_tile):
        _rows_done(progress, r0, h_out)
        r1 = min(h_out, r0 + rows_per_tile)
        rows = np.arange(r0, r1, dtype=np.float64)
        acc = np.zeros((r1 - r0, w_out, channels), np.float32)
        cover = np.zeros((r1 - r0, w_out), np.float32)
        for oy in offsets:
            for ox in offsets:
                px = np.stack(np.broadcast_arrays(cols[None, :] + ox, rows[:, None] + oy), -1)
                zw = coords.cp1_from_lonlat(coords.lonlat_from_pixel(px, w_out, h_out))
                pb = inverse_map.pull(zw)
                lonlat = coords.lonlat_from_cp1(pb.points)
                valid = pb.valid
                if pb.sheet is None or len(images) == 1:
                    vals = _sample_one(images[0], lonlat, interp)
                else:
                    vals = np.zeros((r1 - r0, w_out, channels), np.float32)
                    for k, im in enumerate(images):
                        sel = pb.sheet == k
                        if np.any(sel):
                            vals[sel] = _sample_one(im, lonlat[sel], interp)
                if valid is None:
                    acc += vals
                    cover += 1.0
                else:
                    acc += np.where(valid[..., None], vals, 0.0)
                    cover += valid
        inv = np.float32(1.0 / (n * n))
        res = (acc + (n * n - cover)[..., None] * bg) * inv
        if add_alpha:
            res = np.concatenate([res, (cover * inv * _full_value(dtype))[..., None]], axis=-1)
        if dtype.kind == "u":
            info = np.iinfo(dtype)
            np.clip(np.rint(res), info.min, info.max, out=res)
        out[r0:r1] = res
    _rows_done(progress, h_out, h_out)


def _warp_by_samples(
    images: list[NDArray],
    plan: Plan,
    out: NDArray,
    bg: NDArray[np.float32],
    progress: Callable[[int, int], None] | None = None,
) -> None:
    """Any map, any anti-aliasing: NumPy geometry, sample lists per pixel.

    Rows are handled in bands; in each, the pixels' sample counts come from
    the anti-aliasing mode (adaptive: the map's ``local_scale``), and the
    samples are evaluated in batches of at most ``_SAMPLE_BATCH``. The
    samples are averaged by the compiled sampler (the plan's sampler ``"fast"``, one
    sheet) or by NumPy (``"reference"``, any number of sheets).
    """
    inverse_map, interp, threads = plan.inverse_map, plan.interp, plan.threads
    sampler = plan.sampler
    mode, n = plan.antialias
    if sampler == "reference":
        threads = None
    if mode == "area":  # compiled area taps sheet by sheet
        _warp_area(images, inverse_map, out, bg, sampler, threads, progress)
        return
    if len(images) > 1 and inverse_map.n_sheets > 1:
        sampler = "reference"
    h_in, w_in, _ = images[0].shape
    h_out, w_out, co = out.shape
    flat = out.reshape(-1)
    factors = _aa.footprint_factors((h_in, w_in), (h_out, w_out))
    factors = (factors[0] * _aa.AUTO_DENSITY, factors[1] * _aa.AUTO_DENSITY)
    rho_in = min(np.pi / h_in, 2 * np.pi / w_in)
    band = max(1, (1 << 16) // w_out)
    for r0 in range(0, h_out, band):
        _rows_done(progress, r0, h_out)
        r1 = min(h_out, r0 + band)
        # in "adaptive", the rows above and below the band too: neighbours, to find jumps
        px, lonlat, zw, pb, a = _pull_rows(inverse_map, r0, r1, w_out, h_out, mode == "adaptive")
        npx = (r1 - r0) * w_out
        inner = slice(a * w_out, a * w_out + npx)
        if mode == "uniform":
            nx = np.full(npx, n, np.int64)
            ny = nx
        elif mode == "adaptive":
            scale = np.nan_to_num(inverse_map.local_scale(zw), nan=1.0, posinf=1e6)
            nx, ny = _aa.sample_counts(
                scale[inner], lonlat[inner, 1], factors, _aa.AUTO_TOLERANCE, _aa.AUTO_MAX
            )
            jump = _jumps(pb, scale, lonlat[::w_out, 1], a, r1 - r0, w_out, rho_in, h_out)
            nx[jump] = np.maximum(nx[jump], _aa.JUMP_SAMPLES)
            ny[jump] = np.maximum(ny[jump], _aa.JUMP_SAMPLES)
        else:
            nx = ny = np.ones(npx, np.int64)
        _sample_batches(
            images, inverse_map, px[inner], nx, ny, _rows_of(pb, inner), (h_out, w_out), flat,
            co, r0 * w_out, interp, bg, sampler, threads,
        )  # fmt: skip
    _rows_done(progress, h_out, h_out)


def _pull_rows(
    inverse_map: SphereMap, r0: int, r1: int, w_out: int, h_out: int, halo: bool
) -> tuple[NDArray, NDArray, NDArray, Any, int]:
    """Pixel centres, their longitude/latitude, points and pull-back for output rows
    ``r0..r1`` (with ``halo``, also the rows just above and below, where there are
    any), and how many rows precede ``r0`` in them (0 or 1)."""
    ra = max(0, r0 - 1) if halo else r0
    rb = min(h_out, r1 + 1) if halo else r1
    rows = np.arange(ra, rb, dtype=np.float64) + 0.5
    cols = np.arange(w_out, dtype=np.float64) + 0.5
    px = np.stack(np.broadcast_arrays(cols[None, :], rows[:, None]), -1).reshape(-1, 2)
    lonlat = coords.lonlat_from_pixel(px, w_out, h_out)
    zw = coords.cp1_from_lonlat(lonlat)
    return px, lonlat, zw, inverse_map.pull(zw), r0 - ra


def _hole_edges(valid: NDArray[np.bool_], above: int, m: int) -> NDArray[np.bool_]:
    """Flat mask of the ``m`` rows after the first ``above`` of ``valid`` (rows of the
    output, whole): pixels whose validity differs from a neighbour's (round the seam)."""
    edge = valid != np.roll(valid, 1, axis=1)
    edge |= np.roll(edge, -1, axis=1)
    vert = valid[1:] != valid[:-1]
    edge[1:] |= vert
    edge[:-1] |= vert
    return edge[above : above + m].reshape(-1)


def _rows_of(pb: Any, inner: slice) -> tuple[Any, Any, Any]:
    """``(points, valid, sheet)`` of a pull-back, restricted to ``inner``."""
    return (
        pb.points[inner],
        None if pb.valid is None else pb.valid[inner],
        None if pb.sheet is None else pb.sheet[inner],
    )


def _sample_batches(
    images: list[NDArray],
    inverse_map: SphereMap,
    px: NDArray[np.float64],
    nx: NDArray[np.int64],
    ny: NDArray[np.int64],
    centre: tuple[Any, Any, Any],
    out_shape: tuple[int, int],
    flat: NDArray,
    co: int,
    p0: int,
    interp: str,
    bg: NDArray[np.float32],
    sampler: str,
    threads: int | None,
    boxes: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None,
    to_cp1: Callable[[NDArray, NDArray], NDArray] | None = None,
) -> None:
    """:func:`_sample_pixels` for pixels ``p0, p0 + 1, ...`` (centres ``px``, pulled back
    to ``centre``: points, validity, sheet) in batches of about ``_SAMPLE_BATCH``
    samples."""
    npx = len(px)
    ends = np.cumsum(nx * ny)
    p = 0
    while p < npx:
        base = ends[p - 1] if p > 0 else 0
        q = max(p + 1, int(np.searchsorted(ends, base + _SAMPLE_BATCH, side="right")))
        part = tuple(None if a is None else a[p:q] for a in centre)
        _sample_pixels(
            images, inverse_map, px[p:q], nx[p:q], ny[p:q], part, out_shape, flat, co, p0 + p,
            interp, bg, sampler, threads, None if boxes is None else (boxes[0][p:q], boxes[1][p:q]),
            to_cp1,
        )  # fmt: skip
        p = q


def _jumps(
    pb: Any,
    scale: NDArray[np.float64],
    lat: NDArray[np.float64],
    above: int,
    m: int,
    w_out: int,
    rho_in: float,
    h_out: int,
) -> NDArray[np.bool_]:
    """:func:`~spherewarp.render.antialias.jump_mask` of ``m`` pulled-back rows that
    follow ``above`` (0 or 1) others, with the row below where there is one; flat."""
    rows = len(scale) // w_out
    shape = (rows, w_out)
    valid = None if pb.valid is None else pb.valid.reshape(shape)
    xyz = coords.xyz_from_cp1(pb.points).reshape(*shape, 3)
    if rows == above + m:  # last band: no row below; repeat the last one (no jumps there)
        xyz = np.concatenate([xyz, xyz[-1:]])
        scale = np.concatenate([scale, scale[-w_out:]])
        valid = None if valid is None else np.concatenate([valid, valid[-1:]])
        lat = np.concatenate([lat, lat[-1:]])
    mask = _aa.jump_mask(xyz, scale.reshape(-1, w_out), lat, valid, rho_in, h_out)
    return mask[above : above + m].reshape(-1)


def _warp_area(
    images: list[NDArray],
    inverse_map: SphereMap,
    out: NDArray,
    bg: NDArray[np.float32],
    sampler: str,
    threads: int | None,
    progress: Callable[[int, int], None] | None = None,
) -> None:
    """``antialias="area"`` on the NumPy side: any map, any number of sheets.

    As the compiled renderer: each pixel is an area tap over its footprint
    (:func:`~spherewarp.render.antialias.area_footprints`); a long footprint is
    split into parts, each pulled back through the map and an area tap over its
    share; pixels on a jump of the map, and on either side of the edge of a hole
    (where it is undefined), get ``JUMP_SAMPLES`` plain taps a side.
    """
    h_in, w_in, _ = images[0].shape
    h_out, w_out, co = out.shape
    flat = out.reshape(-1)
    rho_in = min(np.pi / h_in, 2 * np.pi / w_in)
    band = max(1, (1 << 16) // w_out)
    js = _aa.JUMP_SAMPLES
    for r0 in range(0, h_out, band):
        _rows_done(progress, r0, h_out)
        r1 = min(h_out, r0 + band)
        m = r1 - r0
        npx = m * w_out
        # the rows above and below the band too: neighbours, to find jumps
        px, lonlat, zw, pb, a = _pull_rows(inverse_map, r0, r1, w_out, h_out, True)
        inner = slice(a * w_out, a * w_out + npx)
        scale = np.nan_to_num(inverse_map.local_scale(zw), nan=1.0, posinf=1e6)
        jump = _jumps(pb, scale, lonlat[::w_out, 1], a, m, w_out, rho_in, h_out)
        centre = _rows_of(pb, inner)
        with np.errstate(invalid="ignore"):
            uv = coords.pixel_from_lonlat(coords.lonlat_from_cp1(centre[0]), w_in, h_in)
        valid = centre[1]
        J, nx, ny = _aa.area_footprints(
            np.nan_to_num(uv[:, 0] - 0.5).reshape(m, w_out),
            np.nan_to_num(uv[:, 1] - 0.5).reshape(m, w_out),
            None if valid is None else valid.reshape(m, w_out),
            lonlat[inner][::w_out, 1], (h_in, w_in), (h_out, w_out),
            scale=scale[inner].reshape(m, w_out),
        )  # fmt: skip
        one = _aa.one_tap_pixels(
            scale[inner].reshape(m, w_out), np.nan_to_num(uv[:, 1] - 0.5).reshape(m, w_out),
            None if valid is None else valid.reshape(m, w_out), lonlat[inner][::w_out, 1],
            (h_in, w_in), (h_out, w_out),
        ).reshape(-1)  # fmt: skip
        J = J.reshape(4, -1)
        nx = nx.reshape(-1)
        ny = ny.reshape(-1)
        J[:, one & (nx * ny == 1)] = 0.0  # a box of (nearly) nothing: the bilinear tap
        if pb.valid is not None:  # the edges of holes: partly covered pixels
            jump = jump | _hole_edges(pb.valid.reshape(-1, w_out), a, m)
        J[:, jump] = 0.0
        nx[jump] = np.maximum(nx[jump], js)
        ny[jump] = np.maximum(ny[jump], js)
        # the box of each part (of the whole footprint where it is one part)
        bx = np.hypot(J[0] / nx, J[1] / ny)
        by = np.hypot(J[2] / nx, J[3] / ny)
        _sample_batches(
            images, inverse_map, px[inner], nx, ny, centre, (h_out, w_out), flat, co,
            r0 * w_out, "bilinear", bg, sampler, threads, (bx, by),
        )  # fmt: skip
    _rows_done(progress, h_out, h_out)


def _sample_pixels(
    images: list[NDArray],
    inverse_map: SphereMap,
    px: NDArray[np.float64],
    nx: NDArray[np.int64],
    ny: NDArray[np.int64],
    centre: tuple[Any, Any, Any],
    out_shape: tuple[int, int],
    flat: NDArray,
    co: int,
    p0: int,
    interp: str,
    bg: NDArray[np.float32],
    sampler: str,
    threads: int | None,
    boxes: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None,
    to_cp1: Callable[[NDArray, NDArray], NDArray] | None = None,
) -> None:
    """Average ``nx x ny`` samples in each pixel (centres already pulled back) into ``flat``.

    With ``boxes`` (the width and height of each pixel's samples, input pixels) the
    samples are area taps (:func:`~spherewarp.render.sampling.sample_area`).
    ``to_cp1(positions, centres)`` gives the points that output pixel positions show
    (default: those of the equirectangular output; a grid's otherwise).
    """
    h_out, w_out = out_shape
    image = images[0]
    c = image.shape[2]
    counts = nx * ny
    start = np.concatenate([[0], np.cumsum(counts)])
    points, valid, sheet = centre
    special = counts > 1
    if np.any(special):
        sp = np.flatnonzero(special)
        owner, ox, oy = _aa.subsample_offsets(nx[sp], ny[sp])
        spx = np.stack([px[sp[owner], 0] - 0.5 + ox, px[sp[owner], 1] - 0.5 + oy], -1)
        if to_cp1 is None:
            szw = coords.cp1_from_lonlat(coords.lonlat_from_pixel(spx, w_out, h_out))
        else:
            szw = to_cp1(spx, px[sp[owner]])
        pb = inverse_map.pull(szw)
        total = int(start[-1])
        first = np.cumsum(counts[sp]) - counts[sp]  # of each special pixel's subsamples
        where_sub = start[sp[owner]] + (np.arange(owner.size) - first[owner])
        where_one = start[:-1][~special]
        pts = np.empty((total, 2), np.complex128)
        pts[where_one] = points[~special]
        pts[where_sub] = pb.points
        if valid is None and pb.valid is None:
            vv = None
        else:
            vv = np.ones(total, bool)
            if valid is not None:
                vv[where_one] = valid[~special]
            if pb.valid is not None:
                vv[where_sub] = pb.valid
        if sheet is None and pb.sheet is None:
            ss = None
        else:
            ss = np.zeros(total, np.intp)
            if sheet is not None:
                ss[where_one] = sheet[~special]
            if pb.sheet is not None:
                ss[where_sub] = pb.sheet
        points, valid, sheet = pts, vv, ss
    if boxes is not None:
        own = np.repeat(np.arange(len(counts)), counts)
        boxes = (boxes[0][own], boxes[1][own])
    lonlat = coords.lonlat_from_cp1(points)
    if boxes is not None and sampler == "fast":
        from . import fast

        acc = np.zeros((len(counts), c), np.float32)
        cover = np.zeros(len(counts), np.int64)
        for k, im in enumerate(images if sheet is not None else images[:1]):
            sel = np.flatnonzero(sheet == k) if sheet is not None else slice(None)
            src = coords.pixel_from_lonlat(lonlat[sel], im.shape[1], im.shape[0])
            a, cv = fast.area_samples(
                im, src[:, 0] - 0.5, src[:, 1] - 0.5, boxes[0][sel], boxes[1][sel],
                None if valid is None else valid[sel], own[sel], len(counts),
            )  # fmt: skip
            acc += a
            cover += cv
        _finish(acc, cover, counts, image, bg, flat, co, p0)
        return
    if sampler == "fast":  # (area taps on this path returned above)
        from . import fast

        h_in, w_in = image.shape[:2]
        src = coords.pixel_from_lonlat(lonlat, w_in, h_in)
        fast.sample_samples(
            image, src[:, 0] - 0.5, src[:, 1] - 0.5, valid, start, flat, co, p0,
            interp=interp, background=bg, threads=threads,
        )  # fmt: skip
        return
    if sheet is None or len(images) == 1:
        vals = _sample_one(image, lonlat, interp, boxes)
    else:
        vals = np.zeros((len(lonlat), c), np.float32)
        for k, im in enumerate(images):
            sel = sheet == k
            if np.any(sel):
                bs = None if boxes is None else (boxes[0][sel], boxes[1][sel])
                vals[sel] = _sample_one(im, lonlat[sel], interp, bs)
    if valid is None:
        cover = counts.astype(np.float32)
    else:
        vals[~valid] = 0.0
        cover = np.add.reduceat(valid.astype(np.float32), start[:-1])
    acc = np.add.reduceat(vals, start[:-1], axis=0)
    _finish(acc, cover, counts, image, bg, flat, co, p0)


def _finish(
    acc: NDArray[np.float32],
    cover: NDArray[np.floating],
    counts: NDArray[np.int64],
    image: NDArray,
    bg: NDArray[np.float32],
    flat: NDArray,
    co: int,
    p0: int,
) -> None:
    """Pixels ``p0, p0 + 1, ...`` of ``flat``: the sums ``acc`` of ``cover`` samples out of
    ``counts``, the rest background (and alpha the share covered, where ``co`` has it)."""
    c = image.shape[2]
    cover = np.asarray(cover, np.float32)
    inv = (np.float32(1.0) / counts.astype(np.float32))[:, None]
    res = (acc + (counts - cover)[:, None].astype(np.float32) * bg) * inv
    if co > c:
        res = np.concatenate([res, cover[:, None] * inv * _full_value(image.dtype)], axis=-1)
    if image.dtype.kind == "u":
        info = np.iinfo(image.dtype)
        np.clip(np.rint(res), info.min, info.max, out=res)
    flat[p0 * co : (p0 + len(counts)) * co] = res.reshape(-1)


def _sample_one(
    image: NDArray,
    lonlat: NDArray[np.float64],
    interp: str,
    boxes: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None,
) -> NDArray[np.float32]:
    h, w = image.shape[:2]
    px = coords.pixel_from_lonlat(lonlat, w, h)
    if boxes is not None:
        return sample_area(image, px[..., 0], px[..., 1], boxes[0], boxes[1])
    return sample(image, px[..., 0], px[..., 1], interp)


def push(image: ArrayLike | Sequence[ArrayLike], forward_map: SphereMap, **kwargs: Any) -> NDArray:
    """Push an image forward by an invertible map: content at ``p`` moves to ``forward_map(p)``.

    The same as ``warp(image, forward_map.inverse(), **kwargs)``.

    Examples
    --------
    >>> from spherewarp.maps import Mobius
    >>> img = np.zeros((8, 16, 1), np.float32)
    >>> push(img, Mobius.zoom((0, 0), 2)).shape
    (8, 16, 1)
    """
    return warp(image, forward_map.inverse(), **kwargs)
