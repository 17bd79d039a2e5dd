"""Sampling an equirectangular image at continuous pixel positions.

The sphere has no edges, so neither do the samplers: columns wrap around the
longitude seam, and a tap above the top row (or below the bottom row) is the
pixel on the other side of the pole: row ``-1 - r``, half a turn round in
longitude. Interpolation is therefore continuous across the seam and over
both poles; there is no clamped black column and no pinch.

Convention: positions are pixel coordinates ``(x, y)`` with pixel centres at
half-integers (see :mod:`spherewarp.coords`).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..errors import InvalidValueError

__all__ = ["INTERPOLATIONS", "sample", "sample_area", "check_interp"]

INTERPOLATIONS = ("nearest", "bilinear", "bicubic")


def check_interp(interp: str) -> str:
    """Normalise an interpolation name (case-insensitive), or raise listing the allowed ones."""
    name = str(interp).strip().lower()
    aliases = {"linear": "bilinear", "cubic": "bicubic", "near": "nearest"}
    name = aliases.get(name, name)
    if name not in INTERPOLATIONS:
        raise InvalidValueError(
            f"unknown interpolation {interp!r}; expected one of: {', '.join(INTERPOLATIONS)}"
        )
    return name


def _flat_index(iy: NDArray[np.intp], ix: NDArray[np.intp], h: int, w: int) -> NDArray[np.intp]:
    """Flat indices of taps ``(iy, ix)``, folded over the poles and wrapped in longitude."""
    top = iy < 0
    bottom = iy >= h
    over = top | bottom
    if np.any(over):
        iy = np.where(top, -1 - iy, np.where(bottom, 2 * h - 1 - iy, iy))
        ix = np.where(over, ix + w // 2, ix)
        # Taps further than one image height away cannot occur for positions on the sphere.
        np.clip(iy, 0, h - 1, out=iy)
    ix = np.mod(ix, w)
    return iy * w + ix


def _tap_space(
    image: NDArray, x: NDArray[np.floating], y: NDArray[np.floating]
) -> tuple[int, int, int, NDArray, NDArray[np.float64], NDArray[np.float64]]:
    """Check an image's shape; ``(h, w, c)``, its pixels as rows ``(h * w, c)``, and the
    positions in tap space (pixel centres at integers)."""
    if image.ndim != 3:
        raise InvalidValueError(f"expected an image of shape (H, W, C), got {image.shape}")
    h, w, c = image.shape
    fx = np.asarray(x, dtype=np.float64) - 0.5
    fy = np.asarray(y, dtype=np.float64) - 0.5
    return h, w, c, image.reshape(h * w, c), fx, fy


def _cubic_weights(t: NDArray[np.float32]) -> list[NDArray[np.float32]]:
    """Keys cubic convolution weights (a = -0.5, Catmull-Rom) for taps -1, 0, 1, 2."""
    a = np.float32(-0.5)
    t2 = t * t
    t3 = t2 * t
    w0 = a * (t3 - 2 * t2 + t)
    w1 = (a + 2) * t3 - (a + 3) * t2 + 1
    w2 = -(a + 2) * t3 + (2 * a + 3) * t2 - a * t
    w3 = a * (t2 - t3)
    return [w0, w1, w2, w3]


def sample(
    image: NDArray, x: NDArray[np.floating], y: NDArray[np.floating], interp: str = "bilinear"
) -> NDArray[np.float32]:
    """Sample an equirectangular image at pixel positions.

    Parameters
    ----------
    image : ndarray, shape (H, W, C)
        Any real dtype; values are read as float32.
    x, y : ndarray
        Pixel coordinates of the same shape ``S`` (pixel centres at
        half-integers, any real values: ``x`` wraps, ``y`` is expected in
        ``[0, H]``).
    interp : {"nearest", "bilinear", "bicubic"}

    Returns
    -------
    ndarray, float32, shape ``S + (C,)``

    Examples
    --------
    >>> img = np.arange(8, dtype=np.uint8).reshape(2, 4, 1)
    >>> sample(img, np.array([0.5, 4.0]), np.array([0.5, 0.5]))[:, 0]
    array([0. , 1.5], dtype=float32)
    """
    interp = check_interp(interp)
    h, w, c, flat, fx, fy = _tap_space(image, x, y)
    shape = fx.shape
    if interp == "nearest":
        ix = np.floor(fx + 0.5).astype(np.intp)
        iy = np.floor(fy + 0.5).astype(np.intp)
        return flat[_flat_index(iy, ix, h, w)].astype(np.float32, copy=False).reshape(*shape, c)

    x0f = np.floor(fx)
    y0f = np.floor(fy)
    tx = (fx - x0f).astype(np.float32)
    ty = (fy - y0f).astype(np.float32)
    x0 = x0f.astype(np.intp)
    y0 = y0f.astype(np.intp)
    if interp == "bilinear":
        wx = [1 - tx, tx]
        wy = [1 - ty, ty]
        offsets = (0, 1)
    else:
        wx = _cubic_weights(tx)
        wy = _cubic_weights(ty)
        offsets = (-1, 0, 1, 2)
    out = np.zeros((*shape, c), dtype=np.float32)
    # a float image's bicubic value is clamped to its four nearest samples (no ringing of
    # an HDR image's unbounded steps), as the compiled sampler does
    clamp = interp == "bicubic" and np.asarray(image).dtype.kind == "f"
    lo = np.full((*shape, c), np.inf, np.float32) if clamp else None
    hi = np.full((*shape, c), -np.inf, np.float32) if clamp else None
    for j, oy in enumerate(offsets):
        row = np.zeros((*shape, c), dtype=np.float32)
        for i, ox in enumerate(offsets):
            taps = flat[_flat_index(y0 + oy, x0 + ox, h, w)]
            row += wx[i][..., None] * taps
            if clamp and oy in (0, 1) and ox in (0, 1):
                lo = np.fmin(lo, taps)
                hi = np.fmax(hi, taps)
        out += wy[j][..., None] * row
    if clamp:
        nan = np.isnan(out)
        out = np.clip(out, lo, hi).astype(np.float32, copy=False)
        out[nan] = np.nan
    return out


def _tent_integral(s: NDArray[np.float64]) -> NDArray[np.float64]:
    """``int_-inf^s tent``: the antiderivative of the bilinear (tent) kernel."""
    s = np.clip(s, -1.0, 1.0)
    a = 1.0 - np.abs(s)
    return np.where(s >= 0.0, 1.0 - 0.5 * a * a, 0.5 * a * a)


#: the widest box of :func:`sample_area` (``_kernels.AREA_BOX_MAX``)
_BOX_MAX = 4.0


def sample_area(
    image: NDArray,
    x: NDArray[np.floating],
    y: NDArray[np.floating],
    bx: NDArray[np.floating],
    by: NDArray[np.floating],
) -> NDArray[np.float32]:
    """Average the bilinear surface of an equirectangular image over boxes.

    The area tap of ``antialias="area"`` (float64 NumPy, the reference for the
    compiled one): the image's bilinear interpolant averaged over the box
    ``bx x by`` input pixels centred on ``(x, y)``, in closed form as 4 x 4
    taps of a tent convolved with a box (6 x 6 where a box is wider than 2
    input pixels). Box sides are clamped to ``[1e-3, 4]`` pixels (a side of
    ``1e-3`` is a bilinear tap; the compiled taps' ``AREA_BOX_MAX``). Taps wrap
    in longitude and fold over the poles as in :func:`sample`.

    Parameters
    ----------
    image : ndarray, shape (H, W, C)
    x, y : ndarray
        Pixel coordinates of the box centres (pixel centres at half-integers).
    bx, by : ndarray
        The box's width and height in input pixels, broadcastable to ``x``.

    Returns
    -------
    ndarray, float32, shape ``x.shape + (C,)``

    Examples
    --------
    A box one pixel wide centred on a pixel centre averages it with half of
    each neighbour's tent (weights 1/8, 3/4, 1/8):

    >>> img = np.array([[[0.0], [8.0], [0.0], [0.0]]], np.float32)
    >>> float(sample_area(img, np.array([1.5]), np.array([0.5]), 1.0, 1e-3)[0, 0])
    6.0
    """
    h, w, c, flat, fx, fy = _tap_space(image, x, y)
    shape = fx.shape
    hx = 0.5 * np.clip(np.broadcast_to(np.asarray(bx, np.float64), shape), 1e-3, _BOX_MAX)
    hy = 0.5 * np.clip(np.broadcast_to(np.asarray(by, np.float64), shape), 1e-3, _BOX_MAX)
    # a box up to 2 wide touches 4 pixels a side, up to 4 wide 6 (the others weigh 0)
    wide = hx.size > 0 and max(float(hx.max()), float(hy.max())) > 1.0
    n, lo = (6, 2.0) if wide else (4, 1.0)
    x0f = np.floor(fx) - lo
    y0f = np.floor(fy) - lo
    tx = x0f - fx
    ty = y0f - fy
    x0 = x0f.astype(np.intp)
    y0 = y0f.astype(np.intp)
    out = np.zeros((*shape, c), dtype=np.float64)
    for j in range(n):
        wy = (_tent_integral(ty + j + hy) - _tent_integral(ty + j - hy)) / (2 * hy)
        row = np.zeros((*shape, c), dtype=np.float64)
        for i in range(n):
            wx = (_tent_integral(tx + i + hx) - _tent_integral(tx + i - hx)) / (2 * hx)
            row += wx[..., None] * flat[_flat_index(y0 + j, x0 + i, h, w)]
        out += wy[..., None] * row
    return out.astype(np.float32)
