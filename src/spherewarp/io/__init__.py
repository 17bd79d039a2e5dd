"""Image input and output for equirectangular panoramas.

:func:`read_image` and :func:`write_image` read and write PNG, JPEG, TIFF, WebP
and OpenEXR, keeping the sample type (uint8, uint16, float32), the ICC profile,
EXIF and the GPano XMP that marks a 360° panorama; :func:`pixel_limit` is the
one pixel limit every input obeys. See
:mod:`spherewarp.io.images` and :mod:`spherewarp.io.xmp`.
"""

from .images import (
    DEFAULT_MAX_PIXELS,
    SUPPORTED_EXTENSIONS,
    ImageData,
    convert_dtype,
    pixel_limit,
    place_on_full_sphere,
    read_image,
    write_image,
)
from .xmp import GPANO_NAMESPACE, GPano, gpano_xmp, parse_gpano

__all__ = [
    "DEFAULT_MAX_PIXELS",
    "GPANO_NAMESPACE",
    "SUPPORTED_EXTENSIONS",
    "GPano",
    "ImageData",
    "convert_dtype",
    "gpano_xmp",
    "parse_gpano",
    "pixel_limit",
    "place_on_full_sphere",
    "read_image",
    "write_image",
]
