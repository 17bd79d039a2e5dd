"""Convert pixels for a format that cannot hold them: tone mapping, alpha flattening.

:func:`~spherewarp.io.write_image` never converts behind the caller's back; this
module does the conversions on request (the command line uses it when ``-o``
names a format that needs one):

* :func:`tonemap` turns HDR float pixels (linear light, as OpenEXR holds them)
  into display values in 0..1, sRGB-encoded, ready for
  :func:`~spherewarp.io.convert_dtype` to 8 or 16 bits;
* :func:`flatten_alpha` composites an image with alpha over a solid colour
  (JPEG has no alpha; a GPano-cropped panorama is transparent outside its
  crop);
* :func:`parse_color` reads a colour name or hex code.

Tone-mapping operators (:data:`TONEMAPS`), each applied per colour channel to
``x = pixel * 2**exposure``, then sRGB-encoded:

``aces`` (the default)
    The ACES filmic curve as fitted by Narkowicz (2015):
    ``x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14)``, clipped to 0..1.
    Keeps the contrast of the mid-tones and rolls the highlights (windows,
    lamps, the sun) off smoothly instead of cutting them to flat white.
``reinhard``
    ``x / (1 + x)``: never clips, but flattens the contrast (greyer image).
``clip``
    ``x`` clipped to 0..1: the linear image as it is, highlights cut off
    (what a straight conversion gives, with the sRGB transfer added).

Examples
--------
>>> import numpy as np
>>> hdr = np.array([[[0.0, 0.18, 4.0]]], np.float32)   # black, mid grey, a highlight
>>> tonemap(hdr, "clip").round(3)
array([[[0.   , 0.461, 1.   ]]], dtype=float32)
>>> tonemap(hdr, "aces").round(3)
array([[[0.   , 0.553, 0.988]]], dtype=float32)
>>> flatten_alpha(np.array([[[200, 100, 0, 0], [200, 100, 0, 255]]], np.uint8), "white")
array([[[255, 255, 255],
        [200, 100,   0]]], dtype=uint8)
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import InvalidTypeError, InvalidValueError

__all__ = [
    "COLORS",
    "DEFAULT_TONEMAP",
    "TONEMAPS",
    "flatten_alpha",
    "linear_to_srgb",
    "parse_color",
    "srgb_to_linear",
    "tonemap",
]

#: tone-mapping operators :func:`tonemap` knows
TONEMAPS: tuple[str, ...] = ("aces", "reinhard", "clip")
#: the operator used when none is named: filmic highlights, mid-tone contrast kept
DEFAULT_TONEMAP = "aces"

#: colour names :func:`parse_color` knows, as 0..1 sRGB values
COLORS: dict[str, tuple[float, float, float]] = {
    "black": (0.0, 0.0, 0.0),
    "white": (1.0, 1.0, 1.0),
    "grey": (0.5, 0.5, 0.5),
    "gray": (0.5, 0.5, 0.5),
    "red": (1.0, 0.0, 0.0),
    "green": (0.0, 1.0, 0.0),
    "blue": (0.0, 0.0, 1.0),
}


def linear_to_srgb(x: np.ndarray) -> np.ndarray:
    """The sRGB transfer function (IEC 61966-2-1) of linear values in 0..1.

    Examples
    --------
    >>> linear_to_srgb(np.array([0.0, 0.0031308, 0.18, 1.0])).round(4)
    array([0.    , 0.0404, 0.4614, 1.    ])
    """
    x = np.clip(x, 0.0, 1.0)
    high = 1.055 * np.power(np.maximum(x, 0.0031308), 1 / 2.4) - 0.055
    high = np.where(x < 1.0, high, 1.0)  # 1.055 - 0.055 rounds below 1 in float32
    return np.where(x <= 0.0031308, x * 12.92, high).astype(x.dtype, copy=False)


def srgb_to_linear(x: np.ndarray) -> np.ndarray:
    """The inverse of :func:`linear_to_srgb`: sRGB-encoded values in 0..1 to linear light.

    What :func:`~spherewarp.io.write_image` does to integer (sRGB-encoded) colour
    written to OpenEXR, which holds linear light; ``linear_to_srgb(srgb_to_linear(x))``
    gives ``x`` back to float rounding, so 8 and 16 bits survive the round trip.

    Examples
    --------
    >>> srgb_to_linear(np.array([0.0, 0.04045, 0.5, 1.0])).round(4)
    array([0.    , 0.0031, 0.214 , 1.    ])
    >>> x = np.arange(256) / 255
    >>> bool(np.all(np.rint(linear_to_srgb(srgb_to_linear(x)) * 255) == np.arange(256)))
    True
    """
    x = np.clip(x, 0.0, 1.0)
    low = x / 12.92
    high = np.power((np.maximum(x, 0.04045) + 0.055) / 1.055, 2.4)
    return np.where(x <= 0.04045, low, high).astype(x.dtype, copy=False)


_BRIGHTEST = np.float32(1e6)


def _aces(x: np.ndarray) -> np.ndarray:
    return x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14)


def _float_pixels(pixels: Any) -> np.ndarray:
    if not isinstance(pixels, np.ndarray):
        raise InvalidTypeError(f"pixels must be a numpy array, got {type(pixels).__name__}")
    if pixels.dtype.kind != "f":
        raise InvalidTypeError(f"pixels must be float32 or float64 (HDR), got {pixels.dtype}")
    if pixels.ndim != 3 or not 1 <= pixels.shape[2] <= 4:
        raise InvalidValueError(f"pixels must have shape (H, W, C), C in 1..4, got {pixels.shape}")
    return pixels


def tonemap(pixels: np.ndarray, method: str = DEFAULT_TONEMAP, exposure: float = 0.0) -> np.ndarray:
    """Map HDR (linear-light float) pixels to sRGB-encoded display values in 0..1.

    Parameters
    ----------
    pixels : numpy.ndarray
        ``(H, W, C)`` float32 or float64, ``C`` in 1..4, linear light (1.0 =
        diffuse white). Alpha (channel 2 of 2, 4 of 4) is only clipped to 0..1.
        NaN becomes 0, +inf the brightest value.
    method : {"aces", "reinhard", "clip"}
        The operator (see the module documentation); case-insensitive.
    exposure : float
        Scale the linear values by ``2**exposure`` first (photographic stops).

    Returns
    -------
    numpy.ndarray
        float32, same shape, values in 0..1; :func:`~spherewarp.io.convert_dtype`
        makes 8 or 16 bits of it.

    Raises
    ------
    InvalidTypeError
        If ``pixels`` is not a float array.
    InvalidValueError
        For an unknown ``method``, a non-finite ``exposure`` or a bad shape.

    Examples
    --------
    >>> px = np.full((1, 2, 3), 1.0, np.float32)
    >>> tonemap(px, "reinhard")[0, 0].round(3).tolist()
    [0.735, 0.735, 0.735]
    >>> tonemap(px, "clip", exposure=-1)[0, 0].round(3).tolist()
    [0.735, 0.735, 0.735]
    """
    px = _float_pixels(pixels)
    name = str(method).strip().lower()
    if name not in TONEMAPS:
        raise InvalidValueError(
            f"unknown tone map {method!r}; expected one of: {', '.join(TONEMAPS)}"
        )
    if not np.isfinite(exposure):
        raise InvalidValueError(f"exposure must be finite, got {exposure!r}")
    c = px.shape[2]
    nc = c - 1 if c in (2, 4) else c
    out = np.empty(px.shape, np.float32)
    x = np.nan_to_num(px[..., :nc].astype(np.float32), nan=0.0, posinf=_BRIGHTEST)
    # above _BRIGHTEST every operator is white to 8 and 16 bits; the clip keeps x * x finite
    x = np.clip(x * np.float32(2.0**exposure), 0.0, _BRIGHTEST)
    if name == "aces":
        x = _aces(x)
    elif name == "reinhard":
        x = x / (1.0 + x)
    out[..., :nc] = linear_to_srgb(x)
    if nc < c:
        out[..., nc] = np.clip(np.nan_to_num(px[..., nc], nan=0.0), 0.0, 1.0)
    return out


def parse_color(text: str) -> tuple[float, float, float]:
    """A colour as 0..1 sRGB values from a name (:data:`COLORS`) or ``#RGB``/``#RRGGBB``.

    Examples
    --------
    >>> parse_color("white"), parse_color("#ff8000"), parse_color("0f0")
    ((1.0, 1.0, 1.0), (1.0, 0.5019607843137255, 0.0), (0.0, 1.0, 0.0))
    """
    t = str(text).strip().lower()
    if t in COLORS:
        return COLORS[t]
    h = t[1:] if t.startswith("#") else t
    if len(h) == 3:
        h = "".join(ch * 2 for ch in h)
    try:
        if len(h) != 6:
            raise ValueError
        rgb = tuple(int(h[k : k + 2], 16) / 255.0 for k in (0, 2, 4))
    except ValueError:
        raise InvalidValueError(
            f"expected a colour name ({', '.join(COLORS)}) or hex code like #808080, got {text!r}"
        ) from None
    return rgb  # type: ignore[return-value]


def flatten_alpha(pixels: np.ndarray, background: str | tuple[float, ...] = "black") -> np.ndarray:
    """Composite an image with straight alpha over a solid colour; drop the alpha.

    Parameters
    ----------
    pixels : numpy.ndarray
        ``(H, W, 2)`` grey+alpha or ``(H, W, 4)`` RGBA, uint8, uint16 or float.
        Other channel counts are returned unchanged.
    background : str or tuple of float
        A colour for :func:`parse_color`, or 0..1 values (1 or 3).

    Returns
    -------
    numpy.ndarray
        ``(H, W, 1)`` or ``(H, W, 3)``, the input's dtype:
        ``colour * alpha + background * (1 - alpha)``.

    Examples
    --------
    >>> la = np.array([[[1.0, 0.25]]], np.float32)
    >>> flatten_alpha(la, "black")
    array([[[0.25]]], dtype=float32)
    """
    if not isinstance(pixels, np.ndarray) or pixels.ndim != 3:
        raise InvalidTypeError("pixels must be a numpy array of shape (H, W, C)")
    c = pixels.shape[2]
    if c not in (2, 4):
        return pixels
    bg = parse_color(background) if isinstance(background, str) else background
    bg_arr = np.asarray(bg, np.float32).reshape(-1)
    if bg_arr.size not in (1, 3):
        raise InvalidValueError(f"expected a background of 1 or 3 values, got {background!r}")
    if c == 2:  # grey: the background's luma (Rec. 709)
        bg_arr = bg_arr[:1] if bg_arr.size == 1 else np.float32([0.2126, 0.7152, 0.0722]) @ bg_arr
    bg_arr = np.broadcast_to(bg_arr, (c - 1,))
    top = 1.0 if pixels.dtype.kind == "f" else float(np.iinfo(pixels.dtype).max)
    px = pixels.astype(np.float32)
    a = np.clip(px[..., -1:] / np.float32(top), 0.0, 1.0)
    out = px[..., :-1] * a + (bg_arr * np.float32(top)) * (1.0 - a)
    if pixels.dtype.kind == "f":
        return out.astype(pixels.dtype)
    return np.clip(np.rint(out), 0, top).astype(pixels.dtype)
