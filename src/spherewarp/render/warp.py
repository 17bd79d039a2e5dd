"""The pull-back renderer: one renderer for every effect.

For each output pixel the renderer takes its direction, asks the map where it
comes from, and samples the input there (the paper's "pulling back via S",
skimage's ``warp(image, inverse_map)``)::

    pixel -> (lon, lat) -> CP^1 -> S -> CP^1 -> (lon, lat) -> input pixel -> sample

Work is done in tiles of output rows, so memory stays bounded whatever the
output size.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import coords
from ..errors import InvalidTypeError, InvalidValueError
from ..maps.base import SphereMap
from .sampling import check_interp, sample

__all__ = ["warp", "push", "check_equirect", "as_image"]

_DTYPES = (np.uint8, np.uint16, np.float32, np.float64)
_TILE_PIXELS = 1 << 17


def as_image(image: ArrayLike, name: str = "image") -> NDArray:
    """Check an image array and return it as ``(H, W, C)`` (a view, no copy).

    Raises
    ------
    InvalidTypeError
        For dtypes other than uint8, uint16, float32 and float64.
    InvalidValueError
        For shapes other than ``(H, W)`` or ``(H, W, C)`` with C in 1..4.
    """
    arr = np.asarray(image)
    if arr.dtype.type not in _DTYPES:
        raise InvalidTypeError(f"{name}: expected dtype uint8, uint16 or float32, got {arr.dtype}")
    if arr.ndim == 2:
        arr = arr[:, :, None]
    if arr.ndim != 3 or not 1 <= arr.shape[2] <= 4 or arr.shape[0] < 1 or arr.shape[1] < 2:
        raise InvalidValueError(
            f"{name}: expected an image of shape (H, W) or (H, W, C) with 1-4 channels, "
            f"got {arr.shape}"
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
        raise InvalidValueError(
            f"{name}: expected an equirectangular image with width = 2 x height, got {w}x{h} "
            "(force=True, or --force, treats it as equirectangular anyway)"
        )


def _background(background: ArrayLike | None, channels: int) -> NDArray[np.float32]:
    if background is None:
        return np.zeros(channels, np.float32)
    bg = np.atleast_1d(np.asarray(background, dtype=np.float32))
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
    supersample: int = 1,
    background: ArrayLike | None = None,
    alpha: bool = False,
    force: bool = False,
) -> NDArray:
    """Pull an equirectangular image back through a map of the sphere.

    Output pixel ``p`` gets the colour of the input at ``inverse_map(p)``:
    ``out = in o inverse_map``. To move content forward by a map ``T``
    instead, use :func:`push` (or ``warp(image, T.inverse())``).

    Convention: pixel centres at half-integers; see :mod:`spherewarp.coords`.

    Parameters
    ----------
    image : ndarray (H, W[, C]) or sequence of them
        Equirectangular image(s), uint8, uint16 or float32 (float64 too), 1-4
        channels. A sequence gives the sheets that a map with several sheets
        (:attr:`~spherewarp.maps.PullBack.sheet`) samples; they must share
        dtype and channel count but may differ in size.
    inverse_map : SphereMap
        The map from output points to input points.
    output_shape : (height, width), optional
        Default: the shape of the (first) input.
    interp : {"bilinear", "nearest", "bicubic"}
        Sampling; case-insensitive.
    supersample : int
        Average ``supersample x supersample`` samples per output pixel.
    background : number or sequence, optional
        Colour where the map is undefined, in the image's units (default 0,
        which for an image with alpha means transparent).
    alpha : bool
        Append an alpha channel (opaque where the map is defined) to an
        image that has none (1 or 3 channels).
    force : bool
        Accept inputs that are not 2:1.

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
    """
    if not isinstance(inverse_map, SphereMap):
        raise InvalidTypeError(
            f"expected a map (a spherewarp.maps.SphereMap), got {type(inverse_map).__name__}"
        )
    if isinstance(image, np.ndarray) or not isinstance(image, Sequence):
        images = [as_image(image)]
    else:
        images = [as_image(im, f"image {k}") for k, im in enumerate(image)]
        if not images:
            raise InvalidValueError("expected at least one image, got an empty sequence")
    for k, im in enumerate(images):
        check_equirect(im, force, "image" if len(images) == 1 else f"image {k}")
        if im.dtype != images[0].dtype or im.shape[2] != images[0].shape[2]:
            raise InvalidValueError(
                "expected images of one dtype and channel count, got "
                f"{images[0].dtype}/{images[0].shape[2]} and {im.dtype}/{im.shape[2]} (image {k})"
            )
    if inverse_map.n_sheets > len(images):
        raise InvalidValueError(
            f"this map samples {inverse_map.n_sheets} input images, got {len(images)}"
        )
    interp = check_interp(interp)
    if (
        isinstance(supersample, bool)
        or not isinstance(supersample, (int, np.integer))
        or not (1 <= supersample <= 32)
    ):
        raise InvalidValueError(f"expected supersample to be an integer 1..32, got {supersample!r}")
    h_in, w_in, channels = images[0].shape
    if output_shape is None:
        output_shape = (h_in, w_in)
    try:
        h_out, w_out = (int(v) for v in output_shape)
    except (TypeError, ValueError):
        raise InvalidValueError(
            f"expected output_shape as (height, width), got {output_shape!r}"
        ) from None
    if h_out < 1 or w_out < 1 or h_out * w_out > 1 << 30:
        raise InvalidValueError(f"expected a positive output shape, got {output_shape!r}")

    dtype = images[0].dtype
    has_alpha = channels in (2, 4)
    add_alpha = alpha and not has_alpha
    bg = _background(background, channels)
    out_channels = channels + (1 if add_alpha else 0)
    out = np.empty((h_out, w_out, out_channels), dtype=dtype)

    n = int(supersample)
    offsets = (np.arange(n) + 0.5) / n
    rows_per_tile = max(1, _TILE_PIXELS // (w_out * n * n))
    cols = np.arange(w_out, dtype=np.float64)
    for r0 in range(0, h_out, rows_per_tile):
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
    return out


def _sample_one(image: NDArray, lonlat: NDArray[np.float64], interp: str) -> NDArray[np.float32]:
    h, w = image.shape[:2]
    px = coords.pixel_from_lonlat(lonlat, w, h)
    return sample(image, px[..., 0], px[..., 1], interp)


def push(image: ArrayLike | Sequence[ArrayLike], forward_map: SphereMap, **kwargs) -> NDArray:
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
