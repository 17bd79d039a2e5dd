"""Read and write equirectangular panoramas, keeping the sample type end to end.

Formats and what each one keeps:

======  ========================  ========  ====================================
format  sample types              channels  metadata carried
======  ========================  ========  ====================================
PNG     uint8, uint16             1-4       ICC (``iCCP``), EXIF (``eXIf``),
                                            XMP (``iTXt XML:com.adobe.xmp``)
JPEG    uint8                     1, 3      ICC, EXIF, XMP (APP1)
TIFF    uint8, uint16, float32    1-4       ICC (tag 34675), XMP (tag 700),
                                            EXIF: IFD0 tags only (see below)
WebP    uint8                     1-4 [1]_  ICC, EXIF, XMP chunks
EXR     float32 (half is read     1-4 [2]_  XMP as the string attribute ``xmp``;
        as float32)                         ``envmap`` = latlong for a full
                                            sphere; no ICC, no EXIF
======  ========================  ========  ====================================

.. [1] WebP stores grey as RGB: a 1- or 2-channel image reads back with 3 or 4.
.. [2] Channels ``Y``, ``Y A``, ``R G B`` or ``R G B A``.

Nothing is converted behind the caller's back: uint16 or float32 pixels given to
a format that cannot hold them raise :class:`~spherewarp.errors.ImageFormatError`
naming a format that can; :func:`convert_dtype` converts explicitly. The one
documented exception is EXR, which only holds floats, and by convention linear
light (scene-referred): uint8 and uint16 colour, sRGB-encoded as the other formats
hold it, is written linearised, ``srgb_to_linear(x / 255)`` (``x / 65535``;
:func:`~spherewarp.io.tonemap.srgb_to_linear`), and alpha scaled to 0..1. Float
pixels are taken as linear light everywhere: read from EXR or float TIFF they are
linear, and :func:`~spherewarp.io.tonemap.tonemap` ends in the sRGB transfer
function, so 8 or 16 bits written to EXR and read back come back through the
``clip`` tone map to the same integers.

Pixel arrays are always ``(H, W, C)`` with ``C`` in 1..4 (grey is ``C = 1``,
grey+alpha ``C = 2``), dtype uint8, uint16 or float32. Alpha is straight
(unassociated) in files and arrays (the renderer filters it premultiplied:
:func:`~spherewarp.render.plan.render_straight_alpha`).

EXIF orientation is applied on reading, as Pillow's ``ImageOps.exif_transpose``
does: the pixels come upright (as viewers display the file; a quarter turn swaps
width and height), and the EXIF keeps every tag but Orientation, which is set to 1.
:func:`write_image` writes pixels as they are displayed, so it sets an Orientation
tag of the ``exif`` it is given to 1 too (a viewer would turn them again).

Libraries: Pillow for 8-bit PNG decoding, JPEG and WebP and for reading PNG
metadata; ``imagecodecs`` (libpng) for PNG encoding and 16-bit PNG decoding,
since Pillow cannot hold 16-bit RGB(A); ``tifffile`` for TIFF (with
``imagecodecs`` for its compressions); ``OpenEXR`` for EXR.

TIFF EXIF: ``tifffile`` cannot write the EXIF and GPS sub-IFDs, so only the
IFD0 tags Make, Model, Orientation, Software, DateTime, Artist, Copyright and
ImageDescription of the ``exif`` blob are written, and a warning names what was
dropped. On reading, the EXIF of a TIFF is rebuilt from those IFD0 tags and the
EXIF/GPS sub-IFDs when the file has them.

Writing is atomic: the image is encoded to a hidden temporary file in the
destination directory (``.NAME.spherewarp-PID-XXXXXXXX.tmp.EXT``), flushed to disk
and renamed over the destination; on any failure, ``KeyboardInterrupt`` included,
the temporary file is removed and an existing destination is left untouched
(:mod:`spherewarp.io.atomic`, which also removes the temporary files a killed
process left for the same destination).

Examples
--------
>>> import os, tempfile
>>> import numpy as np
>>> from spherewarp.io import read_image, write_image
>>> d = tempfile.mkdtemp()
>>> px = np.zeros((4, 8, 3), np.uint16)
>>> out = write_image(os.path.join(d, "pano.png"), px)
>>> img = read_image(out)
>>> img.format, img.pixels.dtype, img.pixels.shape, img.gpano.full_width
('PNG', dtype('uint16'), (4, 8, 3), 8)
"""

from __future__ import annotations

import contextlib
import io
import logging
import os
import stat
import struct
import sys
import tempfile
import types
import warnings
import zlib
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .. import _signals
from ..errors import (
    ImageFormatError,
    InvalidTypeError,
    InvalidValueError,
    SpherewarpError,
)
from .atomic import atomic_file, exists_error, unwritable_error
from .xmp import GPano, gpano_xmp, parse_gpano

__all__ = [
    "DEFAULT_MAX_PIXELS",
    "SUPPORTED_EXTENSIONS",
    "ImageData",
    "convert_dtype",
    "pixel_limit",
    "place_on_full_sphere",
    "read_image",
    "write_image",
]

DEFAULT_MAX_PIXELS = 2**28
"""Default pixel-count limit of :func:`read_image` (268,435,456, e.g. 23170 x 11585).

See :func:`pixel_limit` for how the limit is chosen and what it covers."""

MAX_PIXELS_ENV = "SPHEREWARP_MAX_PIXELS"
"""Environment variable that sets the pixel limit when no ``max_pixels`` is given."""

SUPPORTED_EXTENSIONS: Mapping[str, str] = types.MappingProxyType(
    {
        ".png": "PNG",
        ".jpg": "JPEG",
        ".jpeg": "JPEG",
        ".tif": "TIFF",
        ".tiff": "TIFF",
        ".webp": "WEBP",
        ".exr": "EXR",
    }
)
"""File extensions :func:`write_image` accepts (lower case), mapped to format names."""

_DTYPES = (np.dtype(np.uint8), np.dtype(np.uint16), np.dtype(np.float32))
_FORMAT_DTYPES = {
    "PNG": (np.dtype(np.uint8), np.dtype(np.uint16)),
    "JPEG": (np.dtype(np.uint8),),
    "WEBP": (np.dtype(np.uint8),),
    "TIFF": _DTYPES,
    "EXR": _DTYPES,
}
_MAX_SIDE = {"JPEG": 65535, "WEBP": 16383}
_JPEG_MAX_EXIF = 65533  # an APP1 segment's payload (Pillow's MAX_BYTES_IN_MARKER)
_EXIF_HEADER = b"Exif\x00\x00"
_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
_XMP_JPEG_HEADER = b"http://ns.adobe.com/xap/1.0/\x00"
# IFD0 tags of an EXIF blob that tifffile can write as plain TIFF tags: code -> type.
_TIFF_EXIF_IFD0_TAGS = {
    270: "s",  # ImageDescription
    271: "s",  # Make
    272: "s",  # Model
    274: "H",  # Orientation
    305: "s",  # Software
    306: "s",  # DateTime
    315: "s",  # Artist
    33432: "s",  # Copyright
}
_EXIF_SUB_IFDS = (0x8769, 0x8825)  # Exif IFD, GPS IFD


# ----------------------------------------------------------------------------
# Public data types and helpers
# ----------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class ImageData:
    """An image read by :func:`read_image`.

    Attributes
    ----------
    pixels : numpy.ndarray
        Shape ``(H, W, C)``, ``C`` in 1..4, dtype uint8, uint16 or float32.
    icc_profile : bytes or None
        The embedded ICC profile.
    exif : bytes or None
        The EXIF blob, always starting with ``b"Exif\\x00\\x00"`` (as Pillow's
        ``exif=`` save parameter takes it).
    gpano : GPano or None
        The GPano metadata, describing ``pixels`` (after placement on the full
        sphere when that was done).
    format : str
        ``"PNG"``, ``"JPEG"``, ``"TIFF"``, ``"WEBP"`` or ``"EXR"``.
    path : pathlib.Path
        The file that was read.
    """

    pixels: np.ndarray
    icc_profile: bytes | None = None
    exif: bytes | None = None
    gpano: GPano | None = None
    format: str = ""
    path: Path = field(default_factory=Path)

    @property
    def height(self) -> int:
        """Number of rows."""
        return int(self.pixels.shape[0])

    @property
    def width(self) -> int:
        """Number of columns."""
        return int(self.pixels.shape[1])

    @property
    def channels(self) -> int:
        """Number of channels (1 grey, 2 grey+alpha, 3 RGB, 4 RGBA)."""
        return int(self.pixels.shape[2])

    def __repr__(self) -> str:
        def size(b: bytes | None) -> str:
            return "None" if b is None else f"<{len(b)} bytes>"

        return (
            f"ImageData(format={self.format!r}, shape={self.pixels.shape}, "
            f"dtype={self.pixels.dtype}, icc_profile={size(self.icc_profile)}, "
            f"exif={size(self.exif)}, gpano={self.gpano!r}, path={str(self.path)!r})"
        )


def pixel_limit(max_pixels: int | None = None) -> int:
    """The pixel-count limit of :func:`read_image`: the one place it is decided.

    The limit is ``max_pixels`` when given, else the environment variable
    ``SPHEREWARP_MAX_PIXELS`` when set, else :data:`DEFAULT_MAX_PIXELS`
    (2**28 = 268,435,456 pixels). The CLI option ``--max-pixels`` passes its
    value here. Every format obeys the same limit, checked on the header
    before anything is decoded: the image itself, the sum of all the parts of
    a multi-part OpenEXR file (every part is decoded), and the full-sphere
    canvas that a GPano XMP packet declares (the image is placed on it).

    Parameters
    ----------
    max_pixels : int, optional
        An explicit limit, >= 1.

    Returns
    -------
    int

    Raises
    ------
    InvalidTypeError, InvalidValueError
        If ``max_pixels`` or the environment variable is not a positive integer.

    Examples
    --------
    >>> pixel_limit(1000)
    1000
    >>> import os
    >>> os.environ.get("SPHEREWARP_MAX_PIXELS") is None and pixel_limit() == DEFAULT_MAX_PIXELS
    True
    """
    if max_pixels is None:
        text = os.environ.get(MAX_PIXELS_ENV, "").strip()
        if not text:
            return DEFAULT_MAX_PIXELS
        try:
            max_pixels = int(text.replace("_", ""))
        except ValueError:
            max_pixels = 0
        if max_pixels < 1:
            raise InvalidValueError(
                f"{MAX_PIXELS_ENV} must be a positive integer pixel count, got {text[:40]!r}"
            )
        return min(max_pixels, 2**62)  # beyond any image (as a huge --max-pixels is)
    if isinstance(max_pixels, bool) or not isinstance(max_pixels, (int, np.integer)):
        raise InvalidTypeError(f"max_pixels must be an int, got {type(max_pixels).__name__}")
    if max_pixels < 1:
        raise InvalidValueError(f"max_pixels must be >= 1, got {max_pixels}")
    return int(max_pixels)


def _dtype_arg(dtype: Any) -> np.dtype:
    try:
        dt = np.dtype(dtype)
    except TypeError:
        raise InvalidTypeError(f"dtype must be uint8, uint16 or float32, got {dtype!r}") from None
    if dt not in _DTYPES:
        raise InvalidValueError(f"dtype must be uint8, uint16 or float32, got {dt}")
    return dt


def convert_dtype(pixels: np.ndarray, dtype: Any) -> np.ndarray:
    """Convert pixels between uint8, uint16 and float32, explicitly.

    Scaling: uint8 <-> uint16 multiplies or divides by 257 (rounding), so
    255 <-> 65535 and a uint8 value survives the round trip; an integer type
    maps to float as 0..1 (``x / 255`` or ``x / 65535``); float to an integer
    type clips to 0..1 first (HDR values above 1 become the maximum, NaN
    becomes 0) and rounds. float64 input is accepted.

    Parameters
    ----------
    pixels : numpy.ndarray
        Any shape; dtype uint8, uint16, float32 or float64.
    dtype : dtype-like
        ``numpy.uint8``, ``numpy.uint16`` or ``numpy.float32``.

    Returns
    -------
    numpy.ndarray
        A new array, or ``pixels`` itself when it already has ``dtype``.

    Raises
    ------
    InvalidTypeError
        If ``pixels`` is not an array of a supported dtype.
    InvalidValueError
        If ``dtype`` is not one of the three.

    Examples
    --------
    >>> import numpy as np
    >>> convert_dtype(np.array([0, 128, 255], np.uint8), np.uint16)
    array([    0, 32896, 65535], dtype=uint16)
    >>> convert_dtype(np.array([-0.5, 0.5, 2.0], np.float32), np.uint8)
    array([  0, 128, 255], dtype=uint8)
    >>> convert_dtype(np.array([65535], np.uint16), np.float32)
    array([1.], dtype=float32)
    """
    if not isinstance(pixels, np.ndarray):
        raise InvalidTypeError(f"pixels must be a numpy array, got {type(pixels).__name__}")
    target = _dtype_arg(dtype)
    src = pixels.dtype
    if src.kind == "f" and src.itemsize == 8:
        pixels = pixels.astype(np.float32)
        src = pixels.dtype
    if src.byteorder not in "=|" and src.newbyteorder("=") in _DTYPES:
        pixels = pixels.astype(src.newbyteorder("="))
        src = pixels.dtype
    if src not in _DTYPES:
        raise InvalidTypeError(f"pixels must be uint8, uint16, float32 or float64, got {src}")
    if src == target:
        return pixels
    if target.kind == "f":
        return (pixels.astype(np.float32) / np.float32(np.iinfo(src).max)).astype(np.float32)
    top = np.iinfo(target).max
    if src.kind == "f":
        clipped = np.clip(np.nan_to_num(pixels, nan=0.0, posinf=1.0, neginf=0.0), 0.0, 1.0)
        return np.rint(clipped * np.float32(top)).astype(target)
    if target == np.uint16:  # uint8 -> uint16
        return pixels.astype(np.uint16) * np.uint16(257)
    # uint16 -> uint8: round(x / 257) in integer arithmetic
    return ((pixels.astype(np.uint32) + 128) // 257).astype(np.uint8)


def _validate_pixels(pixels: object, name: str = "pixels") -> np.ndarray:
    """Return ``pixels`` as a native-endian (H, W, C) array of a supported dtype."""
    if not isinstance(pixels, np.ndarray):
        raise InvalidTypeError(f"{name} must be a numpy array, got {type(pixels).__name__}")
    dt = pixels.dtype
    if dt.kind == "f" and dt.itemsize == 8:
        pixels = pixels.astype(np.float32)
    elif dt.byteorder not in "=|" and dt.newbyteorder("=") in _DTYPES:
        pixels = pixels.astype(dt.newbyteorder("="))
    elif dt not in _DTYPES:
        raise InvalidTypeError(
            f"{name} must have dtype uint8, uint16 or float32 (float64 is converted), got {dt}"
        )
    if pixels.ndim == 2:
        pixels = pixels[:, :, np.newaxis]
    if pixels.ndim != 3 or not 1 <= pixels.shape[2] <= 4:
        raise InvalidValueError(
            f"{name} must have shape (H, W) or (H, W, C) with C in 1..4, got {pixels.shape}"
        )
    if pixels.shape[0] == 0 or pixels.shape[1] == 0:
        raise InvalidValueError(f"{name} must not be empty, got shape {pixels.shape}")
    return pixels


def _opaque(dtype: np.dtype) -> int | float:
    return 1.0 if dtype.kind == "f" else int(np.iinfo(dtype).max)


def _scaled_placement(gpano: GPano, height: int, width: int) -> tuple[int, int, int, int]:
    """Return (full_w, full_h, left, top) for an image of ``height`` x ``width``."""
    cw, ch = int(gpano.cropped_width or 0), int(gpano.cropped_height or 0)
    fw, fh, left, top = gpano.full_width, gpano.full_height, gpano.cropped_left, gpano.cropped_top
    if (cw, ch) == (width, height):
        return fw, fh, left, top
    s = width / cw
    if abs(ch * s - height) > 1.0:
        raise InvalidValueError(
            f"GPano cropped area is {cw}x{ch} but the image is {width}x{height}, "
            "and the two do not have the same aspect ratio"
        )
    fw, fh = max(round(fw * s), width), max(round(fh * s), height)
    left, top = round(left * s) % fw, min(round(top * s), fh - height)
    return fw, fh, left, top


def place_on_full_sphere(
    pixels: np.ndarray, gpano: GPano, *, max_pixels: int | None = None
) -> np.ndarray:
    """Paste a cropped equirectangular image onto its full-sphere canvas.

    The canvas is ``gpano.full_height`` x ``gpano.full_width``; the image goes
    at (``cropped_left``, ``cropped_top``), wrapping horizontally across the
    ±180° seam. Uncovered pixels are 0. When the image does not cover the whole
    canvas it gets an alpha channel if it has none (grey -> grey+alpha, RGB ->
    RGBA), at full opacity (255, 65535 or 1.0) where covered and 0 elsewhere;
    an existing alpha channel is kept. An image that covers the whole canvas
    (only shifted) is just rolled, with no alpha added.

    If the image size is not the GPano cropped size but has the same aspect
    ratio (a resized copy that kept its XMP), the GPano values are scaled to
    the image.

    Parameters
    ----------
    pixels : numpy.ndarray
        ``(H, W)`` or ``(H, W, C)``, ``C`` in 1..4, uint8, uint16 or float32.
    gpano : GPano
        Placement, with ``projection_type == "equirectangular"``.
    max_pixels : int, optional
        Refuse a canvas of more pixels (default: :func:`pixel_limit`).

    Returns
    -------
    numpy.ndarray
        ``(full_height, full_width, C')``, a new array.

    Raises
    ------
    InvalidTypeError
        If ``pixels`` or ``gpano`` has the wrong type.
    InvalidValueError
        If the projection is not equirectangular, the image size does not
        match the GPano cropped area, or the canvas is over the pixel limit.

    Examples
    --------
    >>> import numpy as np
    >>> crop = np.full((1, 3, 1), 7, np.uint8)
    >>> g = GPano(full_width=4, full_height=2, cropped_width=3, cropped_height=1,
    ...           cropped_left=2, cropped_top=1)
    >>> out = place_on_full_sphere(crop, g)
    >>> out.shape
    (2, 4, 2)
    >>> out[..., 0]
    array([[0, 0, 0, 0],
           [7, 0, 7, 7]], dtype=uint8)
    >>> out[..., 1]
    array([[  0,   0,   0,   0],
           [255,   0, 255, 255]], dtype=uint8)
    """
    arr = _validate_pixels(pixels)
    if not isinstance(gpano, GPano):
        raise InvalidTypeError(f"gpano must be a GPano, got {type(gpano).__name__}")
    if gpano.projection_type.lower() != "equirectangular":
        raise InvalidValueError(
            f"can only place an equirectangular image, GPano ProjectionType is "
            f"{gpano.projection_type!r}"
        )
    h, w, c = arr.shape
    fw, fh, left, top = _scaled_placement(gpano, h, w)
    limit = pixel_limit(max_pixels)
    if fw * fh > limit:
        raise InvalidValueError(
            f"the GPano canvas {fw}x{fh} = {fw * fh} pixels is more than the pixel limit {limit}"
        )
    if (w, h) == (fw, fh):
        return np.roll(arr, left, axis=1)
    out_c = c + 1 if c in (1, 3) else c
    canvas = np.zeros((fh, fw, out_c), dtype=arr.dtype)
    cols = (left + np.arange(w)) % fw
    canvas[top : top + h, cols, :c] = arr
    if out_c != c:
        canvas[top : top + h, cols, c] = _opaque(arr.dtype)
    return canvas


# ----------------------------------------------------------------------------
# Reading
# ----------------------------------------------------------------------------


def _as_path(path: object, what: str) -> Path:
    if isinstance(path, (str, os.PathLike)):
        p = Path(path)
        if str(p) in ("", "."):
            raise InvalidValueError(f"{what} must name a file, got {str(path)!r}")
        return p
    raise InvalidTypeError(f"{what} must be a str or os.PathLike, got {type(path).__name__}")


@contextlib.contextmanager
def _quiet_fds() -> Any:
    """Send what C libraries (libpng, OpenEXR) print on fds 1 and 2 to a discarded file."""
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(Exception):
            stream.flush()
    try:
        saved = (os.dup(1), os.dup(2))
    except OSError:  # no stdout or stderr to protect
        yield
        return
    try:
        with tempfile.TemporaryFile() as sink:
            try:
                with _signals.held():  # a Ctrl-C here must not skip the restore below
                    os.dup2(sink.fileno(), 1)
                    os.dup2(sink.fileno(), 2)
                yield
            finally:
                with _signals.held():  # nor here: stderr would stay discarded (a lost line)
                    for stream in (sys.stdout, sys.stderr):
                        with contextlib.suppress(Exception):
                            stream.flush()
                    os.dup2(saved[0], 1)
                    os.dup2(saved[1], 2)
    finally:
        os.close(saved[0])
        os.close(saved[1])


@contextlib.contextmanager
def _quiet_decoder(p: Path) -> Any:
    """Silence a decoder: C output, tifffile's log; its warnings only if it succeeds.

    A decoder that fails ends in one error, without the warnings it gave on the
    way; one that succeeds passes on each distinct warning once, naming the file.
    """
    log = logging.getLogger("tifffile")
    was_disabled = log.disabled
    log.disabled = True
    try:
        with warnings.catch_warnings(record=True) as caught, _quiet_fds():
            warnings.simplefilter("always")
            yield
    finally:
        log.disabled = was_disabled
    _warn_once(caught, f"{p}: ", stacklevel=5)


def _warn_once(
    caught: list[warnings.WarningMessage], prefix: str = "", stacklevel: int = 3
) -> None:
    """Say each distinct warning of ``caught`` (held by ``catch_warnings(record=True)``)
    once, on one line, after ``prefix``."""
    seen = set()
    for w in caught:
        text = " ".join(str(w.message).split())
        if text not in seen:
            seen.add(text)
            warnings.warn(prefix + text, w.category, stacklevel=stacklevel)


def _sniff(head: bytes) -> str | None:
    if head.startswith(_PNG_SIGNATURE):
        return "PNG"
    if head.startswith(b"\xff\xd8\xff"):
        return "JPEG"
    if head[:4] in (b"II*\x00", b"MM\x00*", b"II+\x00", b"MM\x00+"):
        return "TIFF"
    if head[:4] == b"RIFF" and head[8:12] == b"WEBP":
        return "WEBP"
    if head.startswith(b"\x76\x2f\x31\x01"):
        return "EXR"
    return None


def _unidentified(p: Path, data: bytes) -> ImageFormatError:
    other = None
    try:
        from PIL import Image

        with Image.open(io.BytesIO(data)) as im:
            other = im.format
    except Exception:
        pass
    if other:
        return ImageFormatError(
            f"cannot read '{p}': {other} images are not supported "
            "(expected PNG, JPEG, TIFF, WebP or OpenEXR)"
        )
    return ImageFormatError(
        f"cannot read '{p}': not an image file (expected PNG, JPEG, TIFF, WebP or "
        f"OpenEXR data, the file starts with {data[:8]!r}; PIL cannot identify it either)"
    )


_RAISE_LIMIT = f"if the file is trusted, raise the limit with --max-pixels or {MAX_PIXELS_ENV}"
_RAISE_LIMIT_PY = _RAISE_LIMIT + " (Python: max_pixels=)"


def _check_size(
    p: Path, width: int, height: int, max_pixels: int, what: str = "image", count: int = 0
) -> None:
    """Refuse an empty image or one of more than ``max_pixels`` (plus ``count`` already read)."""
    if width <= 0 or height <= 0:
        raise ImageFormatError(f"cannot read '{p}': header gives an empty {what} {width}x{height}")
    total = width * height + count
    if total > max_pixels:
        extra = f" (with {count} pixels of the parts before it)" if count else ""
        why = (
            f"cannot read '{p}': {what} is {width}x{height} = {width * height} pixels{extra}, "
            f"more than the pixel limit {max_pixels} (possible decompression bomb); "
        )
        raise ImageFormatError(why + _RAISE_LIMIT_PY, cli=why + _RAISE_LIMIT)


def _exif_with_header(exif: bytes | None) -> bytes | None:
    if not exif:
        return None
    exif = bytes(exif)
    return exif if exif.startswith(_EXIF_HEADER) else _EXIF_HEADER + exif


def _exif_without_header(exif: bytes) -> bytes:
    while exif.startswith(_EXIF_HEADER):
        exif = exif[len(_EXIF_HEADER) :]
    return exif


def _pil_to_array(p: Path, im: Any) -> np.ndarray:
    mode = im.mode
    has_trns = "transparency" in im.info
    if mode == "1":
        im = im.convert("L")
    elif mode in ("P", "PA"):
        im = im.convert("RGBA" if mode == "PA" or has_trns else "RGB")
    elif mode == "L" and has_trns:
        im = im.convert("LA")
    elif mode == "RGB" and has_trns:
        im = im.convert("RGBA")
    elif mode == "YCbCr":
        im = im.convert("RGB")
    elif mode in ("La", "RGBa"):
        im = im.convert(mode.upper())
    elif mode in ("I;16", "I;16L", "I;16B"):
        return np.asarray(im).astype(np.uint16)[:, :, np.newaxis]
    if im.mode not in ("L", "LA", "RGB", "RGBA", "F"):
        raise ImageFormatError(
            f"cannot read '{p}': pixel mode {im.mode!r} is not supported "
            "(expected grey, grey+alpha, RGB, RGBA or palette)"
        )
    arr = np.array(im)
    return arr[:, :, np.newaxis] if arr.ndim == 2 else arr


def _pillow_class(fmt: str) -> Any:
    from PIL import JpegImagePlugin, PngImagePlugin

    if fmt == "PNG":
        return PngImagePlugin.PngImageFile
    if fmt == "JPEG":
        return JpegImagePlugin.JpegImageFile
    try:
        from PIL import WebPImagePlugin

        return WebPImagePlugin.WebPImageFile
    except ImportError as exc:  # pragma: no cover - depends on the Pillow build
        raise ImageFormatError("this Pillow was built without WebP support") from exc


@contextlib.contextmanager
def _pillow_limit_lifted() -> Any:
    from PIL import Image

    saved = Image.MAX_IMAGE_PIXELS
    Image.MAX_IMAGE_PIXELS = None
    try:
        yield
    finally:
        Image.MAX_IMAGE_PIXELS = saved


def _read_pillow(p: Path, data: bytes, fmt: str, max_pixels: int) -> tuple:
    from PIL import Image

    cls = _pillow_class(fmt)
    # The plugin class is used directly rather than Image.open(): Image.open checks
    # Image.MAX_IMAGE_PIXELS (warning above 89 Mpx, error above 179 Mpx), but here
    # max_pixels is the limit, checked on the header before anything is decoded.
    # The WebP plugin allocates its canvas when the file is opened and checks
    # Pillow's limit first: check ours on the header instead, and lift Pillow's.
    if fmt == "WEBP":
        from PIL import WebPImagePlugin

        size = WebPImagePlugin._get_size(data[:30])
        if size:
            _check_size(p, size[0], size[1], max_pixels)
    try:
        with _pillow_limit_lifted(), cls(io.BytesIO(data)) as im:
            _check_size(p, im.size[0], im.size[1], max_pixels)
            info = im.info
            icc = info.get("icc_profile") or None
            exif = info.get("exif") or None
            xmp = None
            if fmt == "JPEG":
                for marker, payload in getattr(im, "applist", []):
                    if marker == "APP1" and payload.startswith(_XMP_JPEG_HEADER):
                        xmp = payload[len(_XMP_JPEG_HEADER) :]
                        break
            else:
                xmp = info.get("xmp") or info.get("XML:com.adobe.xmp") or None
            if fmt == "PNG" and len(data) > 25 and data[12:16] == b"IHDR" and data[24] == 16:
                import imagecodecs

                arr = imagecodecs.png_decode(data)
                if arr.ndim == 2:
                    arr = arr[:, :, np.newaxis]
            else:
                im.load()
                arr = _pil_to_array(p, im)
    except SpherewarpError:
        raise
    except (Image.DecompressionBombError, Image.DecompressionBombWarning) as exc:
        raise ImageFormatError(f"cannot read '{p}': {exc}") from exc
    except Exception as exc:
        raise ImageFormatError(
            f"cannot read '{p}': corrupt or truncated {fmt} file ({type(exc).__name__}: {exc})"
        ) from exc
    if isinstance(xmp, str):
        xmp = xmp.encode("utf-8")
    return arr, icc, exif, xmp


def _tiff_exif(data: bytes) -> bytes | None:
    """Rebuild a standalone EXIF blob from the IFD0 and EXIF/GPS sub-IFDs of a TIFF."""
    from PIL import Image

    try:
        src = Image.Exif()
        src.load(data)
        out = Image.Exif()
        for tag in _TIFF_EXIF_IFD0_TAGS:
            if tag in src:
                out[tag] = src[tag]
        for tag in _EXIF_SUB_IFDS:
            if tag in src:
                sub = src.get_ifd(tag)
                if sub:
                    out[tag] = dict(sub)
        return out.tobytes() if len(out) else None
    except Exception:
        return None


def _read_tiff(p: Path, data: bytes, max_pixels: int) -> tuple:
    import tifffile

    try:
        with tifffile.TiffFile(io.BytesIO(data)) as tif:
            if not len(tif.pages):
                raise ImageFormatError(f"cannot read '{p}': TIFF file has no image")
            page = tif.pages[0]
            _check_size(p, int(page.imagewidth), int(page.imagelength), max_pixels)
            if int(getattr(page, "imagedepth", 1)) != 1:
                raise ImageFormatError(f"cannot read '{p}': volumetric TIFF (ImageDepth > 1)")
            photometric = int(page.photometric)
            if photometric not in (0, 1, 2, 3, 6):
                name = getattr(page.photometric, "name", photometric)
                raise ImageFormatError(
                    f"cannot read '{p}': TIFF photometric {name} is not supported "
                    "(expected grey, RGB or palette)"
                )
            arr = page.asarray()
            samples = int(page.samplesperpixel)
            if (
                arr.ndim == 3
                and samples > 1
                and arr.shape[0] == samples
                and int(page.planarconfig) == 2
            ):
                arr = np.moveaxis(arr, 0, -1)
            if arr.ndim == 2:
                arr = arr[:, :, np.newaxis]
            if (
                arr.dtype.kind not in "uf"
                or arr.dtype.itemsize > 4
                or arr.dtype.kind == "u"
                and (arr.dtype.itemsize > 2)
            ):
                kind = "bilevel (1-bit) " if arr.dtype == np.bool_ else ""
                raise ImageFormatError(
                    f"cannot read '{p}': {kind}TIFF samples of type {arr.dtype} are not "
                    "supported (expected uint8, uint16, float16 or float32)"
                )
            if photometric == 3:  # palette
                cmap = np.asarray(page.colormap)
                arr = np.ascontiguousarray(cmap[:, arr[:, :, 0]].transpose(1, 2, 0))
                if not (arr % 257).any():
                    arr = (arr // 257).astype(np.uint8)
            elif photometric == 0:  # MinIsWhite
                if arr.dtype.kind != "u":
                    raise ImageFormatError(f"cannot read '{p}': float MinIsWhite TIFF")
                arr = np.iinfo(arr.dtype).max - arr
            tags = page.tags
            icc = tags[34675].value if 34675 in tags else None
            xmp = tags[700].value if 700 in tags else None
    except SpherewarpError:
        raise
    except Exception as exc:
        raise ImageFormatError(
            f"cannot read '{p}': corrupt, truncated or unsupported TIFF file "
            f"({type(exc).__name__}: {exc})"
        ) from exc
    if arr.ndim != 3:
        raise ImageFormatError(f"cannot read '{p}': unexpected TIFF image shape {arr.shape}")
    if isinstance(icc, (tuple, list)):
        icc = bytes(icc)
    if isinstance(xmp, str):
        xmp = xmp.encode("utf-8")
    elif isinstance(xmp, (tuple, list, np.ndarray)):
        xmp = bytes(np.asarray(xmp, dtype=np.uint8))
    return arr, icc, _tiff_exif(data), xmp


def _exr_check_parts(p: Path, parts: list, max_pixels: int) -> None:
    """Check every part: the binding decodes them all, so their sizes add up."""
    count = 0
    for k, part in enumerate(parts):
        header = part.header
        (x0, y0), (x1, y1) = (tuple(int(v) for v in corner) for corner in header["dataWindow"])
        what = "image" if len(parts) == 1 else f"EXR part {k} of {len(parts)}"
        _check_size(p, x1 - x0 + 1, y1 - y0 + 1, max_pixels, what, count)
        count += (x1 - x0 + 1) * (y1 - y0 + 1)
        storage = header.get("type")
        if storage is not None and "deep" in str(storage).lower():
            raise ImageFormatError(f"cannot read '{p}': deep EXR images are not supported")


def _read_exr(p: Path, max_pixels: int) -> tuple:
    import OpenEXR

    try:
        head = OpenEXR.File(str(p), header_only=True)
        # OpenEXR 3.3.x returns no parts for header_only (fixed in 3.4): the size is
        # then checked after decoding.
        checked = bool(head.parts)
        if checked:
            _exr_check_parts(p, head.parts, max_pixels)
        f = OpenEXR.File(str(p), separate_channels=True)
        part = f.parts[0]
        channels = part.channels
        header = part.header
        if not checked:
            _exr_check_parts(p, f.parts, max_pixels)
    except SpherewarpError:
        raise
    except Exception as exc:
        raise ImageFormatError(
            f"cannot read '{p}': corrupt, truncated or unsupported EXR file "
            f"({type(exc).__name__}: {exc})"
        ) from exc
    names = set(channels)
    alpha = ["A"] if "A" in names else []
    if {"R", "G", "B"} <= names:
        order = ["R", "G", "B", *alpha]
    elif "Y" in names:
        order = ["Y", *alpha]
    elif len(names) == 1:
        order = list(names)
    else:
        raise ImageFormatError(
            f"cannot read '{p}': EXR has no R,G,B or Y channels (channels: {sorted(names)})"
        )
    planes = []
    for name in order:
        ch = channels[name]
        if int(ch.xSampling) != 1 or int(ch.ySampling) != 1:
            raise ImageFormatError(
                f"cannot read '{p}': EXR channel {name!r} is subsampled "
                f"({ch.xSampling}x{ch.ySampling}), not supported"
            )
        px = np.asarray(ch.pixels)
        if px.dtype.kind != "f":
            raise ImageFormatError(
                f"cannot read '{p}': EXR channel {name!r} holds {px.dtype} samples, "
                "expected half or float"
            )
        planes.append(px.astype(np.float32, copy=False))
    arr = np.stack(planes, axis=-1)
    xmp = header.get("xmp")
    if isinstance(xmp, str):
        xmp = xmp.encode("utf-8")
    elif not isinstance(xmp, bytes):
        xmp = None
    latlong = "latlong" in str(header.get("envmap", "")).lower()
    return arr, None, None, xmp, latlong


def _read_file(p: Path) -> bytes:
    """The bytes of a regular file; devices, FIFOs and sockets are refused unread."""
    flags = os.O_RDONLY | getattr(os, "O_BINARY", 0) | getattr(os, "O_NONBLOCK", 0)
    try:
        fd = os.open(p, flags)  # O_NONBLOCK: opening a FIFO with no writer does not hang
    except FileNotFoundError:
        raise ImageFormatError(f"cannot read '{p}': no such file") from None
    except IsADirectoryError:
        raise ImageFormatError(
            f"cannot read '{p}': is a directory, expected an image file"
        ) from None
    except OSError as exc:
        raise ImageFormatError(f"cannot read '{p}': {exc.strerror or exc}") from exc
    mode = os.fstat(fd).st_mode
    if not stat.S_ISREG(mode):
        os.close(fd)
        if stat.S_ISDIR(mode):
            raise ImageFormatError(f"cannot read '{p}': is a directory, expected an image file")
        raise ImageFormatError(
            f"cannot read '{p}': not a regular file (a device, FIFO or socket); "
            "expected an image file"
        )
    with open(fd, "rb", closefd=True) as fh:
        try:
            data = fh.read()
        except OSError as exc:
            raise ImageFormatError(f"cannot read '{p}': {exc.strerror or exc}") from exc
    if not data:
        raise ImageFormatError(f"cannot read '{p}': the file is empty, expected an image")
    return data


def _checked_icc(p: Path, icc: object, channels: int) -> bytes | None:
    """The ICC profile if its header is sane and fits the pixels, else None and a warning.

    Checked on reading so that a bad profile cannot fail the write of a result
    after the whole render."""
    if isinstance(icc, (tuple, list)):
        icc = bytes(icc)
    if not icc:
        return None
    if isinstance(icc, str):
        icc = icc.encode("latin-1", "replace")
    icc = bytes(icc)
    ok = len(icc) >= 128 and icc[36:40] == b"acsp"
    if ok and struct.unpack(">I", icc[:4])[0] > len(icc):
        ok = False
    if not ok:
        warnings.warn(f"{p}: ignoring an unreadable ICC profile ({len(icc)} bytes)", stacklevel=3)
        return None
    space = icc[16:20]
    if space == b"RGB " and channels < 3 or space == b"GRAY" and channels >= 3:
        warnings.warn(
            f"{p}: ignoring the ICC profile: it is for colour space "
            f"{space.decode('latin-1').strip()} but the image has {channels} channel(s)",
            stacklevel=3,
        )
        return None
    return icc


def _checked_exif(p: Path, exif: object) -> bytes | None:
    """The EXIF blob if Pillow can parse it (as writing needs), else None and a warning."""
    if not exif:
        return None
    if not isinstance(exif, (bytes, bytearray, memoryview)):
        return None
    blob = _exif_with_header(bytes(exif))
    from PIL import Image

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            parsed = Image.Exif()
            parsed.load(blob)
            parsed.tobytes()
    except Exception:
        warnings.warn(f"{p}: ignoring unreadable EXIF ({len(blob or b'')} bytes)", stacklevel=3)
        return None
    return blob


_ORIENTATION = 0x0112  # EXIF IFD0 tag Orientation


def _exif_orientation(exif: bytes) -> int:
    """The EXIF Orientation (1..8) of a blob (with its header); 1 if absent or invalid."""
    from PIL import Image

    parsed = Image.Exif()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            parsed.load(exif)
            value = parsed.get(_ORIENTATION, 1)
        except Exception:
            return 1
    if isinstance(value, tuple) and value:
        value = value[0]
    return int(value) if isinstance(value, int) and 1 <= value <= 8 else 1


def _exif_upright(exif: bytes, orientation: int | None = None) -> bytes:
    """``exif`` (with its header) with Orientation = 1 where it has another value.

    The value is patched in place in IFD0 (a SHORT entry), so that every other byte,
    the sub-IFDs and maker notes included, is kept as it was; a blob whose entry
    cannot be patched so is rewritten by Pillow with the tag set to 1.
    """
    if (_exif_orientation(exif) if orientation is None else orientation) == 1:
        return exif
    tiff = exif[len(_EXIF_HEADER) :]
    try:
        order = {b"II": "<", b"MM": ">"}[tiff[:2]]
        (ifd,) = struct.unpack(order + "I", tiff[4:8])
        (count,) = struct.unpack(order + "H", tiff[ifd : ifd + 2])
        for k in range(count):
            at = ifd + 2 + 12 * k
            tag, kind, n = struct.unpack(order + "HHI", tiff[at : at + 8])
            if tag == _ORIENTATION and kind == 3 and n == 1:  # SHORT, one value, inline
                patched = tiff[: at + 8] + struct.pack(order + "H", 1) + tiff[at + 10 :]
                return _EXIF_HEADER + patched
    except (KeyError, struct.error):
        pass
    from PIL import Image

    parsed = Image.Exif()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            parsed.load(exif)
            parsed[_ORIENTATION] = 1
            return _exif_with_header(parsed.tobytes()) or exif
        except Exception:  # kept as it was: Pillow read the tag, so this is not expected
            return exif


def _upright(arr: np.ndarray, exif: bytes) -> tuple[np.ndarray, bytes]:
    """Pixels turned as the EXIF Orientation says they are displayed, and the EXIF with
    Orientation = 1 (Pillow's ``ImageOps.exif_transpose``, on the array)."""
    o = _exif_orientation(exif)
    if o == 1:
        return arr, exif
    turned = {
        2: lambda a: a[:, ::-1],  # mirrored left-right
        3: lambda a: a[::-1, ::-1],  # turned 180 degrees
        4: lambda a: a[::-1],  # mirrored top-bottom
        5: lambda a: a.transpose(1, 0, 2),  # mirrored about the main diagonal
        6: lambda a: np.rot90(a, -1),  # stored turned 90 degrees anticlockwise
        7: lambda a: a[::-1, ::-1].transpose(1, 0, 2),  # mirrored about the other diagonal
        8: lambda a: np.rot90(a, 1),  # stored turned 90 degrees clockwise
    }[o](arr)
    return np.ascontiguousarray(turned), _exif_upright(exif, o)


def read_image(
    path: str | os.PathLike[str],
    *,
    max_pixels: int | None = None,
    full_sphere: bool = True,
) -> ImageData:
    """Read a panorama, keeping its sample type.

    The format is found from the file's content, not its name. 8- and 16-bit
    PNG (grey, grey+alpha, RGB, RGBA; palette and low bit depths decode to
    uint8), JPEG, 8/16-bit and float32 TIFF (first page; float16 becomes
    float32), WebP (first frame) and OpenEXR (first part, data window; half
    becomes float32; channels ``R G B [A]``, ``Y [A]`` or a single channel).
    An EXIF Orientation is applied: the pixels come as viewers display the file,
    and the returned EXIF says Orientation 1.

    Parameters
    ----------
    path : str or os.PathLike
        The file to read.
    max_pixels : int, optional
        Refuse images with more pixels than this, checked on the header before
        decoding; default: :func:`pixel_limit` (``SPHEREWARP_MAX_PIXELS`` or
        :data:`DEFAULT_MAX_PIXELS`). It covers every part of a multi-part EXR
        and the full-sphere canvas a GPano packet declares, and replaces
        Pillow's own ``Image.MAX_IMAGE_PIXELS`` check for every format.
    full_sphere : bool
        If the file's GPano XMP says it holds a cropped part of an
        equirectangular panorama, place it on the full-sphere canvas with
        :func:`place_on_full_sphere` (``gpano`` then describes the full
        canvas). If the GPano cannot be applied (its size does not match the
        image), a warning is issued and the pixels are returned as stored.

    Returns
    -------
    ImageData

    Raises
    ------
    InvalidTypeError, InvalidValueError
        For bad arguments.
    ImageFormatError
        If the file is missing, a directory, unreadable, not a supported image,
        not a regular file (a device, FIFO or socket), corrupt or truncated,
        larger than ``max_pixels`` (or declares a GPano canvas that is), or
        holds samples of another type (bilevel TIFF, int16, float64, ...).

    Warns
    -----
    UserWarning
        When the GPano XMP, the ICC profile or the EXIF is unreadable: it is
        ignored (dropped), so that it cannot fail the write of a result.

    Examples
    --------
    >>> from importlib.resources import files
    >>> img = read_image(files("spherewarp") / "data" / "interior.png")
    >>> img.format, img.pixels.shape, img.pixels.dtype
    ('PNG', (512, 1024, 3), dtype('uint8'))
    """
    p = _as_path(path, "path")
    max_pixels = pixel_limit(max_pixels)
    if not isinstance(full_sphere, bool):
        raise InvalidTypeError(f"full_sphere must be a bool, got {type(full_sphere).__name__}")
    data = _read_file(p)
    fmt = _sniff(data[:16])
    latlong = False
    with _quiet_decoder(p):
        if fmt is None:
            raise _unidentified(p, data)
        if fmt == "TIFF":
            arr, icc, exif, xmp = _read_tiff(p, data, max_pixels)
        elif fmt == "EXR":
            del data
            arr, icc, exif, xmp, latlong = _read_exr(p, max_pixels)
        else:
            arr, icc, exif, xmp = _read_pillow(p, data, fmt, max_pixels)

    if arr.dtype == np.float16:
        arr = arr.astype(np.float32)
    if arr.dtype.byteorder not in "=|":
        arr = arr.astype(arr.dtype.newbyteorder("="))
    if arr.dtype not in _DTYPES:
        raise ImageFormatError(
            f"cannot read '{p}': {fmt} samples of type {arr.dtype} are not supported "
            "(expected uint8, uint16 or float32)"
        )
    if arr.ndim != 3 or not 1 <= arr.shape[2] <= 4:
        raise ImageFormatError(
            f"cannot read '{p}': expected 1 to 4 channels, got image shape {arr.shape}"
        )

    exif = _checked_exif(p, exif)
    if exif is not None:
        arr, exif = _upright(arr, exif)
    icc = _checked_icc(p, icc, arr.shape[2])
    gpano = None
    if xmp:
        try:
            gpano = parse_gpano(xmp)
        except InvalidValueError as exc:
            warnings.warn(f"{p}: ignoring unreadable GPano XMP: {exc}", stacklevel=2)
    if gpano is None and latlong:
        gpano = GPano.full_sphere(arr.shape[1], arr.shape[0])
    if gpano is not None and full_sphere and gpano.projection_type == "equirectangular":
        h, w = arr.shape[:2]
        if gpano.is_cropped or (gpano.cropped_width, gpano.cropped_height) != (w, h):
            try:
                fw, fh = _scaled_placement(gpano, h, w)[:2]
                _check_size(p, fw, fh, max_pixels, "the full-sphere canvas its GPano XMP declares")
                arr = place_on_full_sphere(arr, gpano, max_pixels=max_pixels)
            except InvalidValueError as exc:
                warnings.warn(f"{p}: not placed on the full sphere: {exc}", stacklevel=2)
            else:
                gpano = gpano.as_full_sphere(arr.shape[1], arr.shape[0])
    return ImageData(
        pixels=np.ascontiguousarray(arr),
        icc_profile=icc,
        exif=exif,
        gpano=gpano,
        format=fmt,
        path=p,
    )


# ----------------------------------------------------------------------------
# Writing
# ----------------------------------------------------------------------------


@dataclass(frozen=True)
class _Meta:
    icc_profile: bytes | None
    exif: bytes | None  # with the b"Exif\0\0" header
    xmp: str | None
    quality: int
    full_sphere: bool  # an uncovered-free, unshifted equirectangular sphere


def _png_chunk(ctype: bytes, payload: bytes) -> bytes:
    crc = zlib.crc32(ctype + payload) & 0xFFFFFFFF
    return struct.pack(">I", len(payload)) + ctype + payload + struct.pack(">I", crc)


def _png_with_chunks(png: bytes, chunks: list[bytes]) -> bytes:
    """Insert ancillary chunks right after IHDR (always the first chunk)."""
    if not png.startswith(_PNG_SIGNATURE) or png[12:16] != b"IHDR":
        raise ImageFormatError("PNG encoder returned data without an IHDR chunk")
    end = 8 + 12 + struct.unpack(">I", png[8:12])[0]
    return png[:end] + b"".join(chunks) + png[end:]


def _write_png(tmp: Path, arr: np.ndarray, meta: _Meta) -> None:
    import imagecodecs

    encoded = imagecodecs.png_encode(
        np.ascontiguousarray(arr[:, :, 0] if arr.shape[2] == 1 else arr)
    )
    chunks = []
    if meta.icc_profile:
        chunks.append(_png_chunk(b"iCCP", b"ICC profile\x00\x00" + zlib.compress(meta.icc_profile)))
    if meta.exif:
        chunks.append(_png_chunk(b"eXIf", _exif_without_header(meta.exif)))
    if meta.xmp:
        itxt = b"XML:com.adobe.xmp\x00\x00\x00\x00\x00" + meta.xmp.encode("utf-8")
        chunks.append(_png_chunk(b"iTXt", itxt))
    with open(tmp, "wb") as fh:
        fh.write(_png_with_chunks(bytes(encoded), chunks))


def _pil_image(arr: np.ndarray) -> Any:
    from PIL import Image

    mode = {1: "L", 2: "LA", 3: "RGB", 4: "RGBA"}[arr.shape[2]]
    data = np.ascontiguousarray(arr[:, :, 0] if arr.shape[2] == 1 else arr)
    return Image.frombytes(mode, (arr.shape[1], arr.shape[0]), data.tobytes())


def _pillow_major() -> int:
    import PIL

    return int(PIL.__version__.split(".")[0])


def _write_jpeg(tmp: Path, arr: np.ndarray, meta: _Meta) -> None:
    im = _pil_image(arr)
    kwargs: dict[str, Any] = {"quality": meta.quality}
    if meta.icc_profile:
        kwargs["icc_profile"] = meta.icc_profile
    if meta.exif:
        kwargs["exif"] = meta.exif
    if meta.xmp:
        xmp = meta.xmp.encode("utf-8")
        if _pillow_major() >= 11:
            kwargs["xmp"] = xmp
        else:  # Pillow 10: no xmp= parameter; 'extra' adds raw APP segments
            size = struct.pack(">H", 2 + len(_XMP_JPEG_HEADER) + len(xmp))
            kwargs["extra"] = b"\xff\xe1" + size + _XMP_JPEG_HEADER + xmp
    im.save(tmp, format="JPEG", **kwargs)


def _write_webp(tmp: Path, arr: np.ndarray, meta: _Meta) -> None:
    if arr.shape[2] in (1, 2):  # WebP has no grey: store grey as RGB
        arr = np.concatenate([arr[:, :, :1]] * 3 + [arr[:, :, 1:]], axis=2)
    im = _pil_image(arr)
    lossless = meta.quality == 100
    kwargs: dict[str, Any] = {"quality": meta.quality, "lossless": lossless, "exact": True}
    if meta.icc_profile:
        kwargs["icc_profile"] = meta.icc_profile
    if meta.exif:
        kwargs["exif"] = _exif_without_header(meta.exif)
    if meta.xmp:
        kwargs["xmp"] = meta.xmp.encode("utf-8")
    im.save(tmp, format="WEBP", **kwargs)


def _tiff_exif_tags(exif: bytes) -> list[tuple]:
    from PIL import Image

    src = Image.Exif()
    try:
        src.load(exif)
    except Exception as exc:
        raise InvalidValueError(
            f"exif is not a valid EXIF blob ({type(exc).__name__}: {exc})"
        ) from exc
    tags: list[tuple] = []
    dropped = []
    for tag, value in src.items():
        kind = _TIFF_EXIF_IFD0_TAGS.get(tag)
        if kind == "H" and isinstance(value, int):
            tags.append((tag, "H", 1, value, True))
        elif kind == "s" and isinstance(value, str) and value.isascii():
            tags.append((tag, "s", 0, value, True))
        else:
            dropped.append(tag)
    if dropped:
        warnings.warn(
            "TIFF: tifffile can only write the IFD0 tags Make, Model, Orientation, Software, "
            "DateTime, Artist, Copyright and ImageDescription of the EXIF; dropped tags "
            f"{sorted(dropped)} (0x8769/0x8825 are the EXIF and GPS sub-IFDs)",
            stacklevel=4,
        )
    return tags


def _write_tiff(tmp: Path, arr: np.ndarray, meta: _Meta) -> None:
    import tifffile

    c = arr.shape[2]
    extratags: list[tuple] = []
    if meta.icc_profile:
        extratags.append((34675, 7, len(meta.icc_profile), meta.icc_profile, True))
    if meta.xmp:
        xmp = meta.xmp.encode("utf-8")
        extratags.append((700, 1, len(xmp), xmp, True))
    description = None
    if meta.exif:
        for tag in _tiff_exif_tags(meta.exif):
            if tag[0] == 270:
                description = tag[3]
            else:
                extratags.append(tag)
    kwargs: dict[str, Any] = {
        "photometric": "rgb" if c >= 3 else "minisblack",
        "compression": "zlib",
        "predictor": True,
        "metadata": None,
        "software": False,
        "description": description,
        "extratags": extratags,
    }
    if c > 1:
        kwargs["planarconfig"] = "contig"
    if c in (2, 4):
        kwargs["extrasamples"] = ["unassalpha"]
    tifffile.imwrite(tmp, arr[:, :, 0] if c == 1 else arr, **kwargs)


def _write_exr(tmp: Path, arr: np.ndarray, meta: _Meta) -> None:
    import OpenEXR

    if meta.icc_profile or meta.exif:
        warnings.warn(
            "EXR: ICC profile and EXIF are not stored in OpenEXR files; dropped",
            stacklevel=3,
        )
    arr = _linear_float(arr)
    names = {1: ["Y"], 2: ["Y", "A"], 3: ["R", "G", "B"], 4: ["R", "G", "B", "A"]}[arr.shape[2]]
    channels = {n: np.ascontiguousarray(arr[:, :, i]) for i, n in enumerate(names)}
    header: dict[str, Any] = {
        "compression": OpenEXR.ZIP_COMPRESSION,
        "type": OpenEXR.scanlineimage,
    }
    if meta.xmp:
        header["xmp"] = meta.xmp
    if meta.full_sphere:
        header["envmap"] = OpenEXR.ENVMAP_LATLONG
    OpenEXR.File(header, channels).write(str(tmp))


def _linear_float(arr: np.ndarray) -> np.ndarray:
    """float32 pixels for OpenEXR, which holds linear light: integer colour (taken as
    sRGB-encoded, as PNG, JPEG, WebP and TIFF hold it) through the sRGB transfer
    function, alpha scaled to 0..1; float pixels as they are (linear already)."""
    if arr.dtype.kind == "f":
        return convert_dtype(arr, np.float32)
    from .tonemap import srgb_to_linear

    out = convert_dtype(arr, np.float32)
    c = arr.shape[2]
    colour = c - 1 if c in (2, 4) else c
    out[..., :colour] = srgb_to_linear(out[..., :colour])
    return out


_WRITERS: dict[str, Callable[[Path, np.ndarray, _Meta], None]] = {
    "PNG": _write_png,
    "JPEG": _write_jpeg,
    "WEBP": _write_webp,
    "TIFF": _write_tiff,
    "EXR": _write_exr,
}


def _bytes_arg(value: object, name: str) -> bytes | None:
    if value is None:
        return None
    if isinstance(value, (bytes, bytearray, memoryview)):
        return bytes(value) or None
    raise InvalidTypeError(f"{name} must be bytes or None, got {type(value).__name__}")


def _check_format(p: Path, fmt: str, arr: np.ndarray) -> None:
    dt, (h, w, c) = arr.dtype, arr.shape
    if dt not in _FORMAT_DTYPES[fmt]:
        if fmt == "PNG":
            keep, to = "write .exr or .tif to keep float32", "np.uint16"
        elif dt == np.uint16:
            keep, to = "write .png or .tif to keep 16 bits", "np.uint8"
        else:
            keep, to = "write .exr or .tif to keep float32", "np.uint8"
        what = f"cannot write '{p}': {fmt} cannot store {dt} pixels; {keep}"
        raise ImageFormatError(
            f"{what}, or convert_dtype(pixels, {to})",
            cli=what,
        )
    if fmt == "JPEG" and c in (2, 4):
        what = (
            f"cannot write '{p}': JPEG has no alpha channel and the image has {c} channels; "
            "write .png, .webp or .tif"
        )
        raise ImageFormatError(
            f"{what}, or drop the alpha channel (pixels[..., :-1])",
            cli=f"{what}, or flatten it with --background COLOR",
        )
    limit = _MAX_SIDE.get(fmt)
    if limit is not None and max(h, w) > limit:
        raise ImageFormatError(
            f"cannot write '{p}': {fmt} images are at most {limit}x{limit} pixels, "
            f"the image is {w}x{h}; write .png or .tif"
        )


def _check_icc(p: Path, fmt: str, icc: bytes | None, channels: int) -> None:
    if not icc or fmt == "EXR":
        return
    if len(icc) < 128:
        raise InvalidValueError(
            f"icc_profile is {len(icc)} bytes, shorter than the 128-byte ICC header"
        )
    stored = 3 if fmt == "WEBP" else channels  # WebP stores grey as RGB
    space = icc[16:20]
    if space == b"RGB " and stored < 3 or space == b"GRAY" and stored >= 3:
        want = "GRAY" if stored < 3 else "RGB"
        raise InvalidValueError(
            f"cannot write '{p}': the ICC profile is for colour space {space.decode().strip()} "
            f"but the {fmt} image has {channels} channel(s) and needs a {want} profile"
        )


def _gpano_arg(gpano: object, h: int, w: int) -> GPano | None:
    if gpano is None or gpano is False:
        return None
    if gpano is True:
        return GPano.full_sphere(w, h)
    if not isinstance(gpano, GPano):
        raise InvalidTypeError(f"gpano must be a GPano, a bool or None, got {type(gpano).__name__}")
    if (gpano.cropped_width, gpano.cropped_height) != (w, h):
        raise InvalidValueError(
            f"gpano cropped area is {gpano.cropped_width}x{gpano.cropped_height} "
            f"but the image is {w}x{h}"
        )
    return gpano


def write_image(
    path: str | os.PathLike[str],
    pixels: np.ndarray,
    *,
    icc_profile: bytes | None = None,
    exif: bytes | None = None,
    gpano: GPano | bool | None = True,
    quality: int = 95,
    overwrite: bool = False,
) -> Path:
    """Write a panorama atomically, keeping its sample type.

    The format comes from the extension (case-insensitive): ``.png``, ``.jpg``/
    ``.jpeg``, ``.tif``/``.tiff``, ``.webp``, ``.exr``; see the module
    documentation for which sample types, channel counts and metadata each
    format takes.

    Parameters
    ----------
    path : str or os.PathLike
        Destination file; its directory must exist.
    pixels : numpy.ndarray
        ``(H, W)`` or ``(H, W, C)``, ``C`` in 1..4; uint8, uint16 or float32
        (float64 is converted to float32 without warning). To EXR, uint8 and
        uint16 colour is written linearised to float32 (EXR holds linear light;
        see the module documentation).
    icc_profile : bytes, optional
        ICC profile to embed (not stored in EXR: a warning says so).
    exif : bytes, optional
        EXIF blob, with or without the ``b"Exif\\x00\\x00"`` header (not stored
        in EXR; TIFF keeps the IFD0 tags only, see the module documentation). An
        Orientation tag is written as 1: the pixels are written as displayed.
    gpano : GPano, bool or None
        ``True`` (default): GPano XMP for an uncropped equirectangular sphere of
        the image's size; a :class:`GPano` whose cropped size is the image
        size: that XMP; ``False`` or ``None``: no XMP. EXR stores it as the
        string attribute ``xmp`` (and ``envmap = latlong`` for a full sphere).
    quality : int
        1..100, for JPEG and WebP. For WebP, 100 means lossless.
    overwrite : bool
        Replace an existing file; otherwise an existing file is an error.

    Returns
    -------
    pathlib.Path
        ``path``.

    Raises
    ------
    InvalidTypeError, InvalidValueError
        For bad arguments (pixels of another dtype or shape, a GPano that does
        not match the image size, quality out of range, ...).
    ImageFormatError
        For an unknown extension, pixels the format cannot hold (uint16 or
        float32 to JPEG/WebP, float32 to PNG, alpha to JPEG, too large for
        JPEG/WebP), a missing directory, or an encoder or disk failure.
    OutputExistsError
        If ``path`` exists and ``overwrite`` is false.

    Examples
    --------
    >>> import os, tempfile
    >>> import numpy as np
    >>> d = tempfile.mkdtemp()
    >>> hdr = np.full((8, 16, 3), 4.5, np.float32)
    >>> write_image(os.path.join(d, "sky.exr"), hdr).name
    'sky.exr'
    >>> write_image(os.path.join(d, "sky.png"), hdr)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    spherewarp.errors.ImageFormatError: cannot write '...sky.png': PNG cannot store float32 pixels; write .exr or .tif to keep float32, or convert_dtype(pixels, np.uint16)
    """  # noqa: E501
    p = _as_path(path, "path")
    fmt = SUPPORTED_EXTENSIONS.get(p.suffix.lower())
    if fmt is None:
        allowed = ", ".join(SUPPORTED_EXTENSIONS)
        raise ImageFormatError(
            f"cannot write '{p}': unknown extension {p.suffix or '(none)'!r}; use one of {allowed}"
        )
    arr = _validate_pixels(pixels)
    if isinstance(quality, bool) or not isinstance(quality, int):
        raise InvalidTypeError(f"quality must be an int, got {type(quality).__name__}")
    if not 1 <= quality <= 100:
        raise InvalidValueError(f"quality must be in 1..100, got {quality}")
    if not isinstance(overwrite, bool):
        raise InvalidTypeError(f"overwrite must be a bool, got {type(overwrite).__name__}")
    icc = _bytes_arg(icc_profile, "icc_profile")
    exif_blob = _exif_with_header(_bytes_arg(exif, "exif"))
    if fmt == "JPEG" and exif_blob and len(exif_blob) > _JPEG_MAX_EXIF:
        warnings.warn(
            f"{p}: EXIF of {len(exif_blob)} bytes does not fit a JPEG APP1 segment "
            f"({_JPEG_MAX_EXIF} bytes at most); dropped",
            stacklevel=2,
        )
        exif_blob = None
    if exif_blob:  # pixels are written as they are displayed: no turn for a viewer to do
        exif_blob = _exif_upright(exif_blob)
    h, w = arr.shape[:2]
    g = _gpano_arg(gpano, h, w)
    _check_format(p, fmt, arr)
    _check_icc(p, fmt, icc, arr.shape[2])

    parent = p.parent
    if not parent.is_dir():
        raise ImageFormatError(
            f"cannot write '{p}': directory '{parent}' does not exist"
            if not parent.exists()
            else f"cannot write '{p}': '{parent}' is not a directory"
        )
    if p.is_dir():
        raise ImageFormatError(f"cannot write '{p}': is a directory")
    if not overwrite and os.path.lexists(p):
        raise exists_error(p)

    meta = _Meta(
        icc_profile=icc,
        exif=exif_blob,
        xmp=gpano_xmp(g) if g is not None else None,
        quality=quality,
        full_sphere=g is not None and not g.is_cropped and g.projection_type == "equirectangular",
    )
    caught: list[warnings.WarningMessage] = []
    try:
        with atomic_file(p, overwrite=overwrite) as tmp:
            # the writer's own warnings (metadata a format cannot hold...) are held while
            # stderr goes nowhere, then said: they used to be discarded with the C output
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                with _quiet_fds():  # C encoders' own messages: the error says what failed
                    _WRITERS[fmt](tmp, arr, meta)
    except SpherewarpError:
        raise
    except Exception as exc:
        if isinstance(exc, OSError) and exc.errno is not None and exc.strerror:
            raise unwritable_error(p, exc) from exc  # the file system's (a full disk...)
        raise ImageFormatError(
            f"cannot write '{p}': {fmt} encoding or writing failed ({type(exc).__name__}: {exc})"
        ) from exc
    _warn_once(caught)
    return p
