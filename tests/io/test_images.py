"""Tests of spherewarp.io: image round trips, metadata, GPano, errors, atomic writes."""

from __future__ import annotations

import dataclasses
import os
import struct
import zlib
from importlib.resources import files
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from PIL import Image, ImageCms

from spherewarp.errors import (
    ImageFormatError,
    InvalidTypeError,
    InvalidValueError,
    OutputExistsError,
    SpherewarpError,
)
from spherewarp.io import (
    SUPPORTED_EXTENSIONS,
    GPano,
    ImageData,
    convert_dtype,
    gpano_xmp,
    parse_gpano,
    place_on_full_sphere,
    read_image,
    write_image,
)
from spherewarp.io import images as images_mod

DATA = Path(str(files("spherewarp") / "data"))
H, W = 8, 16


def _random(dtype, channels, shape=(H, W), seed=0):
    rng = np.random.default_rng(seed)
    dt = np.dtype(dtype)
    if dt.kind == "f":
        return (rng.random((*shape, channels)) * 4.0 - 0.5).astype(dt)  # HDR and negatives
    return rng.integers(0, np.iinfo(dt).max, (*shape, channels), dtype=dt, endpoint=True)


def _smooth(channels, shape=(32, 64)):
    """A smooth uint8 image that lossy codecs reproduce closely."""
    y, x = np.mgrid[0 : shape[0], 0 : shape[1]]
    planes = [(x * 255 // shape[1]), (y * 255 // shape[0]), ((x + y) * 2) % 256, 255 - x * 2]
    return np.stack(planes[:channels], axis=-1).astype(np.uint8)


@pytest.fixture(scope="module")
def icc_rgb():
    return ImageCms.ImageCmsProfile(ImageCms.createProfile("sRGB")).tobytes()


@pytest.fixture(scope="module")
def exif_blob():
    exif = Image.Exif()
    exif[0x010F] = "SphereCam"  # Make
    exif[0x0110] = "Model 360"  # Model
    exif[0x0112] = 1  # Orientation
    return exif.tobytes()


def _exif_tags(blob):
    exif = Image.Exif()
    exif.load(blob)
    return {k: exif[k] for k in (0x010F, 0x0110, 0x0112) if k in exif}


# ----------------------------------------------------------------------------
# Round trips
# ----------------------------------------------------------------------------

LOSSLESS = [
    (ext, dtype, c)
    for ext, dtypes in [
        (".png", ["uint8", "uint16"]),
        (".tif", ["uint8", "uint16", "float32"]),
        (".exr", ["float32"]),
    ]
    for dtype in dtypes
    for c in (1, 2, 3, 4)
]


@pytest.mark.parametrize(("ext", "dtype", "channels"), LOSSLESS)
def test_lossless_round_trip(tmp_path, ext, dtype, channels):
    px = _random(dtype, channels)
    out = write_image(tmp_path / f"img{ext}", px)
    assert out == tmp_path / f"img{ext}"
    img = read_image(out)
    assert img.format == SUPPORTED_EXTENSIONS[ext]
    assert img.pixels.dtype == np.dtype(dtype)
    assert img.pixels.shape == (H, W, channels)
    np.testing.assert_array_equal(img.pixels, px)


@pytest.mark.parametrize("ext", [".png", ".tif", ".exr", ".jpg", ".webp"])
def test_grey_2d_reads_back_as_one_channel(tmp_path, ext):
    px = _smooth(1)[:, :, 0]
    if ext == ".exr":
        px = px.astype(np.float32) / 255
    img = read_image(write_image(tmp_path / f"g{ext}", px, quality=100))
    expected_channels = 3 if ext == ".webp" else 1  # WebP stores grey as RGB
    assert img.pixels.shape == (*px.shape, expected_channels)
    if ext in (".png", ".tif", ".exr", ".webp"):
        for c in range(expected_channels):
            np.testing.assert_array_equal(img.pixels[:, :, c], px)
    else:
        assert np.abs(img.pixels[:, :, 0].astype(int) - px).mean() < 2


@pytest.mark.parametrize("channels", [1, 3])
def test_jpeg_round_trip_is_close(tmp_path, channels):
    px = _smooth(channels)
    img = read_image(write_image(tmp_path / "a.JPG", px, quality=95))
    assert img.format == "JPEG"
    assert img.pixels.dtype == np.uint8 and img.pixels.shape == px.shape
    assert np.abs(img.pixels.astype(int) - px).mean() < 3


@pytest.mark.parametrize("channels", [1, 2, 3, 4])
def test_webp_round_trips(tmp_path, channels):
    px = _smooth(channels)
    stored = {1: 3, 2: 4}.get(channels, channels)
    expected = px
    if channels < 3:
        expected = np.concatenate([px[:, :, :1]] * 3 + [px[:, :, 1:]], axis=2)
    exact = read_image(write_image(tmp_path / "l.webp", px, quality=100))
    assert exact.format == "WEBP" and exact.pixels.shape == (*px.shape[:2], stored)
    np.testing.assert_array_equal(exact.pixels, expected)
    lossy = read_image(write_image(tmp_path / "q.webp", px, quality=90))
    assert lossy.pixels.shape == expected.shape
    assert np.abs(lossy.pixels.astype(int) - expected).mean() < 4


@pytest.mark.parametrize(("dtype", "scale"), [("uint8", 255), ("uint16", 65535)])
@pytest.mark.parametrize("channels", [1, 2, 3, 4])
def test_integer_pixels_to_exr_become_linear_float(tmp_path, dtype, scale, channels):
    """EXR holds linear light: integer colour (sRGB-encoded) is linearised by the sRGB
    transfer function, alpha only scaled to 0..1; the sRGB encoding of what is read
    back gives the integers again."""
    from spherewarp.io.tonemap import linear_to_srgb

    px = _random(dtype, channels)
    img = read_image(write_image(tmp_path / "i.exr", px))
    assert img.pixels.dtype == np.float32 and img.pixels.shape == px.shape
    x = px.astype(np.float64) / scale
    lin = np.where(x <= 0.04045, x / 12.92, ((x + 0.055) / 1.055) ** 2.4)
    colour = channels - 1 if channels in (2, 4) else channels
    np.testing.assert_allclose(img.pixels[..., :colour], lin[..., :colour], rtol=1e-5, atol=1e-9)
    np.testing.assert_allclose(img.pixels[..., colour:], x[..., colour:], rtol=1e-6)
    back = np.rint(linear_to_srgb(img.pixels[..., :colour]) * scale)
    np.testing.assert_array_equal(back, px[..., :colour])


def test_float64_is_written_as_float32(tmp_path):
    px = _random("float32", 3).astype(np.float64)
    img = read_image(write_image(tmp_path / "f.tiff", px))
    assert img.pixels.dtype == np.float32
    np.testing.assert_array_equal(img.pixels, px.astype(np.float32))


def test_half_exr_reads_as_float32(tmp_path):
    import OpenEXR

    half = _random("float32", 1)[:, :, 0].astype(np.float16)
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    OpenEXR.File(header, {"R": half, "G": half, "B": half}).write(str(tmp_path / "h.exr"))
    img = read_image(tmp_path / "h.exr")
    assert img.pixels.dtype == np.float32 and img.pixels.shape == (H, W, 3)
    np.testing.assert_array_equal(img.pixels[:, :, 1], half.astype(np.float32))
    assert img.gpano is None


def test_sample_interior_png():
    img = read_image(DATA / "interior.png")
    assert (img.format, img.pixels.shape, img.pixels.dtype) == ("PNG", (512, 1024, 3), np.uint8)
    assert (img.width, img.height, img.channels) == (1024, 512, 3)
    assert img.path == DATA / "interior.png"
    assert img.pixels.flags.writeable and img.pixels.std() > 0


def test_sample_interior_exr():
    img = read_image(str(DATA / "interior.exr"))
    assert (img.format, img.pixels.shape, img.pixels.dtype) == ("EXR", (512, 1024, 3), np.float32)
    assert np.isfinite(img.pixels).all() and img.pixels.max() > 1.0  # HDR kept


def test_image_data_is_frozen_and_has_short_repr():
    img = ImageData(pixels=np.zeros((2, 4, 3), np.uint8), format="PNG", icc_profile=b"x" * 9)
    with pytest.raises(dataclasses.FrozenInstanceError):
        img.format = "JPEG"  # type: ignore[misc]
    assert "<9 bytes>" in repr(img) and "(2, 4, 3)" in repr(img)


# ----------------------------------------------------------------------------
# Metadata
# ----------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("ext", "dtype"),
    [
        (".png", "uint8"),
        (".png", "uint16"),
        (".jpg", "uint8"),
        (".webp", "uint8"),
        (".tif", "uint8"),
        (".tif", "float32"),
    ],
)
def test_icc_and_exif_survive(tmp_path, icc_rgb, exif_blob, ext, dtype):
    px = _random(dtype, 3) if dtype != "uint8" else _smooth(3)
    img = read_image(write_image(tmp_path / f"m{ext}", px, icc_profile=icc_rgb, exif=exif_blob))
    assert img.icc_profile == icc_rgb
    assert img.exif is not None and img.exif.startswith(b"Exif\x00\x00")
    assert _exif_tags(img.exif) == _exif_tags(exif_blob)
    if ext != ".tif":  # TIFF rebuilds the blob from tags; the others keep it byte for byte
        assert img.exif == exif_blob


def test_exif_without_header_is_accepted(tmp_path, exif_blob):
    img = read_image(write_image(tmp_path / "e.jpg", _smooth(3), exif=exif_blob[6:]))
    assert img.exif == exif_blob


def test_tiff_exif_sub_ifd_is_dropped_with_warning(tmp_path, exif_blob):
    exif = Image.Exif()
    exif.load(exif_blob)
    exif[0x8769] = {0x9003: "2024:01:02 03:04:05"}  # DateTimeOriginal in the Exif IFD
    with pytest.warns(UserWarning, match="sub-IFDs"):
        out = write_image(tmp_path / "s.tif", _smooth(3), exif=exif.tobytes())
    assert _exif_tags(read_image(out).exif) == _exif_tags(exif_blob)


def test_exr_warns_that_icc_and_exif_are_not_stored(tmp_path, icc_rgb):
    with pytest.warns(UserWarning, match="not stored"):
        out = write_image(tmp_path / "x.exr", _random("float32", 3), icc_profile=icc_rgb)
    assert read_image(out).icc_profile is None


@pytest.mark.parametrize("ext", [".png", ".jpg", ".webp", ".tif", ".exr"])
@pytest.mark.parametrize("dtype", ["uint8", "uint16"])
def test_gpano_written_and_read_back(tmp_path, ext, dtype):
    if dtype == "uint16" and ext in (".jpg", ".webp"):
        pytest.skip("format holds uint8 only")
    px = _random(dtype, 3)
    img = read_image(write_image(tmp_path / f"p{ext}", px))
    assert img.gpano == GPano.full_sphere(W, H)
    raw = (tmp_path / f"p{ext}").read_bytes()
    if ext != ".exr":
        assert b"http://ns.google.com/photos/1.0/panorama/" in raw
        assert b'GPano:UsePanoramaViewer="True"' in raw
    none = read_image(write_image(tmp_path / f"n{ext}", px, gpano=False))
    assert none.gpano is None


def test_png_xmp_is_an_itxt_chunk_with_the_adobe_keyword(tmp_path):
    raw = write_image(tmp_path / "k.png", _smooth(3)).read_bytes()
    assert b"iTXtXML:com.adobe.xmp\x00" in raw
    with Image.open(tmp_path / "k.png") as im:  # Pillow sees it too
        xmp = im.info.get("xmp") or im.info["XML:com.adobe.xmp"]  # Pillow < 11 key
        assert parse_gpano(xmp) == GPano.full_sphere(64, 32)


def test_cropped_gpano_is_written_and_kept_when_not_placing(tmp_path):
    g = GPano(
        full_width=64,
        full_height=32,
        cropped_width=W,
        cropped_height=H,
        cropped_left=60,
        cropped_top=4,
    )
    out = write_image(tmp_path / "c.png", _random("uint8", 3), gpano=g)
    img = read_image(out, full_sphere=False)
    assert img.gpano == g and img.pixels.shape == (H, W, 3)


# ----------------------------------------------------------------------------
# GPano: placement on the full sphere, XMP parsing
# ----------------------------------------------------------------------------


@pytest.mark.parametrize(("dtype", "opaque"), [("uint8", 255), ("uint16", 65535), ("float32", 1.0)])
def test_cropped_pano_is_placed_on_full_sphere_across_the_seam(tmp_path, dtype, opaque):
    px = _random(dtype, 3)
    g = GPano(
        full_width=40,
        full_height=20,
        cropped_width=W,
        cropped_height=H,
        cropped_left=30,
        cropped_top=5,
    )
    ext = ".tif"
    img = read_image(write_image(tmp_path / f"c{ext}", px, gpano=g))
    out = img.pixels
    assert out.shape == (20, 40, 4) and out.dtype == np.dtype(dtype)
    assert img.gpano == GPano.full_sphere(40, 20)
    # columns 30..39 then 0..5 (wrapping across the seam), rows 5..12
    cols = np.r_[30:40, 0:6]
    np.testing.assert_array_equal(out[5:13, cols, :3], px)
    assert (out[5:13, cols, 3] == opaque).all()
    uncovered = np.ones((20, 40), bool)
    uncovered[5:13, cols] = False
    assert (out[uncovered] == 0).all()


def test_placement_keeps_existing_alpha_and_grey():
    rgba = _random("uint8", 4)
    g = GPano(full_width=32, full_height=10, cropped_width=W, cropped_height=H, cropped_top=1)
    out = place_on_full_sphere(rgba, g)
    assert out.shape == (10, 32, 4)
    np.testing.assert_array_equal(out[1:9, :W], rgba)
    grey = place_on_full_sphere(rgba[:, :, 0], g)
    assert grey.shape == (10, 32, 2) and (grey[1:9, :W, 1] == 255).all()
    assert (grey[0, :, 1] == 0).all()


def test_full_width_shift_is_a_roll_without_alpha():
    px = _random("uint16", 3)
    g = GPano(full_width=W, full_height=H, cropped_left=3)
    out = place_on_full_sphere(px, g)
    np.testing.assert_array_equal(out, np.roll(px, 3, axis=1))


def test_gpano_of_a_resized_copy_is_scaled():
    px = _random("uint8", 3)  # 8 x 16: half of the 16 x 32 crop the GPano describes
    g = GPano(
        full_width=64,
        full_height=32,
        cropped_width=32,
        cropped_height=16,
        cropped_left=8,
        cropped_top=8,
    )
    out = place_on_full_sphere(px, g)
    assert out.shape == (16, 32, 4)
    np.testing.assert_array_equal(out[4:12, 4:20, :3], px)


def test_mismatched_gpano_warns_on_read_and_raises_when_placing(tmp_path):
    bad = GPano(full_width=100, full_height=50, cropped_width=30, cropped_height=29)
    with pytest.raises(InvalidValueError, match="aspect ratio"):
        place_on_full_sphere(_random("uint8", 3), bad)
    path = tmp_path / "m.png"
    write_image(path, _random("uint8", 3), gpano=False)
    _add_png_itxt(path, gpano_xmp(bad))
    with pytest.warns(UserWarning, match="not placed"):
        img = read_image(path)
    assert img.pixels.shape == (H, W, 3) and img.gpano == bad


def test_place_on_full_sphere_rejects_other_projections():
    g = GPano(projection_type="cylindrical", full_width=W, full_height=H, cropped_left=1)
    with pytest.raises(InvalidValueError, match="cylindrical"):
        place_on_full_sphere(_random("uint8", 3), g)
    with pytest.raises(InvalidTypeError):
        place_on_full_sphere(_random("uint8", 3), {"full_width": 1})  # type: ignore[arg-type]


def test_gpano_validation():
    with pytest.raises(InvalidValueError):
        GPano(full_width=0, full_height=10)
    with pytest.raises(InvalidValueError):
        GPano(full_width=10, full_height=10, cropped_height=8, cropped_top=5)
    with pytest.raises(InvalidTypeError):
        GPano(full_width=10.0, full_height=10)  # type: ignore[arg-type]
    with pytest.raises(TypeError):
        GPano(10, 5)  # type: ignore[misc]  # keyword-only


ELEMENT_FORM = b"""<?xpacket begin='' id='W5M0MpCehiHzreSzNTczkc9d'?>
<x:xmpmeta xmlns:x="adobe:ns:meta/">
 <rdf:RDF xmlns:rdf="http://www.w3.org/1999/02/22-rdf-syntax-ns#">
  <rdf:Description rdf:about="" xmlns:GPano="http://ns.google.com/photos/1.0/panorama/">
   <GPano:ProjectionType>equirectangular</GPano:ProjectionType>
   <GPano:FullPanoWidthPixels>8000</GPano:FullPanoWidthPixels>
   <GPano:FullPanoHeightPixels>4000</GPano:FullPanoHeightPixels>
   <GPano:CroppedAreaImageWidthPixels>8000</GPano:CroppedAreaImageWidthPixels>
   <GPano:CroppedAreaImageHeightPixels>2000</GPano:CroppedAreaImageHeightPixels>
   <GPano:CroppedAreaLeftPixels>0</GPano:CroppedAreaLeftPixels>
   <GPano:CroppedAreaTopPixels>1000</GPano:CroppedAreaTopPixels>
  </rdf:Description>
 </rdf:RDF>
</x:xmpmeta>
<?xpacket end='w'?>\x00\x00"""


def test_parse_gpano_forms_and_failures():
    expected = GPano(
        full_width=8000, full_height=4000, cropped_width=8000, cropped_height=2000, cropped_top=1000
    )
    assert parse_gpano(ELEMENT_FORM) == expected
    assert parse_gpano(gpano_xmp(expected)) == expected
    assert parse_gpano(gpano_xmp(expected).encode()) == expected
    assert parse_gpano(b"") is None
    no_gpano = (
        b'<x:xmpmeta xmlns:x="adobe:ns:meta/"><rdf:RDF xmlns:rdf="'
        b'http://www.w3.org/1999/02/22-rdf-syntax-ns#"/></x:xmpmeta>'
    )
    assert parse_gpano(no_gpano) is None
    with pytest.raises(InvalidValueError, match="well-formed"):
        parse_gpano(b"<x:xmpmeta><unclosed></x:xmpmeta>")
    with pytest.raises(InvalidValueError, match="DTD"):
        parse_gpano(b'<!DOCTYPE x [<!ENTITY a "aaaa">]><x>&a;</x>')
    with pytest.raises(InvalidValueError, match="integer"):
        parse_gpano(ELEMENT_FORM.replace(b">8000<", b">wide<", 1))
    with pytest.raises(InvalidTypeError):
        parse_gpano(42)  # type: ignore[arg-type]


def test_unreadable_xmp_is_ignored_with_a_warning(tmp_path):
    path = tmp_path / "x.png"
    write_image(path, _random("uint8", 3), gpano=False)
    _add_png_itxt(path, "<x:xmpmeta><broken")
    with pytest.warns(UserWarning, match="GPano"):
        img = read_image(path)
    assert img.gpano is None


def _add_png_itxt(path, xmp):
    raw = path.read_bytes()
    payload = b"XML:com.adobe.xmp\x00\x00\x00\x00\x00" + xmp.encode()
    chunk = images_mod._png_chunk(b"iTXt", payload)
    path.write_bytes(raw[:33] + chunk + raw[33:])


# ----------------------------------------------------------------------------
# Reading errors
# ----------------------------------------------------------------------------


def _png_header_only(width, height, bitdepth=8, colortype=2):
    ihdr = struct.pack(">IIBBBBB", width, height, bitdepth, colortype, 0, 0, 0)
    idat = zlib.compress(b"\x00" * 64)
    return (
        b"\x89PNG\r\n\x1a\n"
        + images_mod._png_chunk(b"IHDR", ihdr)
        + images_mod._png_chunk(b"IDAT", idat)
        + images_mod._png_chunk(b"IEND", b"")
    )


def test_garbage_file_named_png(tmp_path):
    (tmp_path / "x.png").write_bytes(b"this is not an image at all" * 3)
    with pytest.raises(ImageFormatError, match="not an image file"):
        read_image(tmp_path / "x.png")


@pytest.mark.parametrize("dtype", ["uint8", "uint16"])
def test_truncated_png(tmp_path, dtype):
    raw = write_image(tmp_path / "t.png", _random(dtype, 3, shape=(64, 64))).read_bytes()
    (tmp_path / "t.png").write_bytes(raw[: len(raw) // 2])
    with pytest.raises(ImageFormatError, match="corrupt or truncated"):
        read_image(tmp_path / "t.png")


@pytest.mark.parametrize("ext", [".jpg", ".webp", ".tif", ".exr"])
def test_truncated_other_formats(tmp_path, ext):
    px = _smooth(3, shape=(64, 128))
    if ext == ".exr":
        px = px.astype(np.float32)
    raw = write_image(tmp_path / f"t{ext}", px).read_bytes()
    (tmp_path / f"t{ext}").write_bytes(raw[: len(raw) // 2])
    with pytest.raises(ImageFormatError, match="cannot read"):
        read_image(tmp_path / f"t{ext}")


@pytest.mark.parametrize("ext", [".png", ".jpg", ".webp", ".tif", ".exr"])
def test_over_max_pixels(tmp_path, ext):
    px = _smooth(3)
    out = write_image(tmp_path / f"big{ext}", px.astype(np.float32) if ext == ".exr" else px)
    with pytest.raises(ImageFormatError, match="pixel limit 1000"):
        read_image(out, max_pixels=1000)
    assert read_image(out, max_pixels=32 * 64).pixels.shape == (32, 64, 3)


def test_bomb_header_is_refused_before_decoding(tmp_path):
    (tmp_path / "bomb.png").write_bytes(_png_header_only(100_000, 100_000))
    with pytest.raises(ImageFormatError, match="decompression bomb"):
        read_image(tmp_path / "bomb.png")


def test_max_pixels_not_pillow_limit_governs(tmp_path, monkeypatch):
    out = write_image(tmp_path / "p.png", _smooth(3))
    monkeypatch.setattr(Image, "MAX_IMAGE_PIXELS", 100)  # Pillow would refuse 2048 px
    assert read_image(out).pixels.shape == (32, 64, 3)


def test_missing_directory_and_empty_files(tmp_path):
    with pytest.raises(ImageFormatError, match="no such file"):
        read_image(tmp_path / "missing.png")
    with pytest.raises(ImageFormatError, match="is a directory"):
        read_image(tmp_path)
    (tmp_path / "empty.png").write_bytes(b"")
    with pytest.raises(ImageFormatError, match="empty"):
        read_image(tmp_path / "empty.png")


def test_unsupported_format_is_named(tmp_path):
    Image.new("RGB", (4, 4)).save(tmp_path / "a.gif")
    with pytest.raises(ImageFormatError, match="GIF images are not supported"):
        read_image(tmp_path / "a.gif")


@pytest.mark.parametrize(
    ("dtype", "what"), [(bool, "bool"), (np.int16, "int16"), (np.float64, "float64")]
)
def test_unsupported_tiff_sample_types(tmp_path, dtype, what):
    import tifffile

    tifffile.imwrite(tmp_path / "s.tif", np.zeros((4, 8), dtype=dtype))
    with pytest.raises(ImageFormatError, match=what):
        read_image(tmp_path / "s.tif")


def test_read_argument_checks(tmp_path):
    with pytest.raises(InvalidTypeError):
        read_image(123)  # type: ignore[arg-type]
    with pytest.raises(InvalidValueError):
        read_image(tmp_path / "a.png", max_pixels=0)
    with pytest.raises(InvalidTypeError):
        read_image(tmp_path / "a.png", max_pixels=True)


# ----------------------------------------------------------------------------
# Writing errors
# ----------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("name", "dtype", "channels", "match"),
    [
        ("a.jpg", "uint16", 3, "JPEG cannot store uint16.*\\.png or \\.tif"),
        ("a.jpeg", "float32", 3, "JPEG cannot store float32.*\\.exr or \\.tif"),
        ("a.webp", "uint16", 3, "WEBP cannot store uint16"),
        ("a.png", "float32", 3, "PNG cannot store float32.*\\.exr or \\.tif"),
        ("a.jpg", "uint8", 4, "JPEG has no alpha"),
        ("a.jpg", "uint8", 2, "JPEG has no alpha"),
    ],
)
def test_format_cannot_hold_pixels(tmp_path, name, dtype, channels, match):
    with pytest.raises(ImageFormatError, match=match):
        write_image(tmp_path / name, _random(dtype, channels))
    assert list(tmp_path.iterdir()) == []


def test_unknown_extension_lists_allowed(tmp_path):
    with pytest.raises(ImageFormatError, match=r"'\.bmp'.*\.png, \.jpg, .*\.exr"):
        write_image(tmp_path / "a.bmp", _smooth(3))
    with pytest.raises(ImageFormatError, match="none"):
        write_image(tmp_path / "noext", _smooth(3))


def test_existing_output_needs_overwrite(tmp_path):
    path = tmp_path / "o.png"
    write_image(path, _smooth(3))
    with pytest.raises(OutputExistsError, match="overwrite=True") as info:
        write_image(path, _smooth(1))
    assert "--overwrite" in info.value.cli_message
    assert read_image(path).pixels.shape[2] == 3
    write_image(path, _smooth(1), overwrite=True)
    assert read_image(path).pixels.shape[2] == 1
    assert [p.name for p in tmp_path.iterdir()] == ["o.png"]


def test_missing_parent_directory(tmp_path):
    with pytest.raises(ImageFormatError, match="does not exist"):
        write_image(tmp_path / "nope" / "a.png", _smooth(3))
    with pytest.raises(ImageFormatError, match="is a directory"):
        (tmp_path / "d.png").mkdir()
        write_image(tmp_path / "d.png", _smooth(3), overwrite=True)


@pytest.mark.parametrize(
    ("pixels", "error"),
    [
        (np.zeros((4, 8), bool), InvalidTypeError),
        (np.zeros((4, 8, 3), np.int32), InvalidTypeError),
        ([[0, 1], [2, 3]], InvalidTypeError),
        (np.zeros((4, 8, 5), np.uint8), InvalidValueError),
        (np.zeros(8, np.uint8), InvalidValueError),
        (np.zeros((0, 8, 3), np.uint8), InvalidValueError),
    ],
)
def test_bad_pixels(tmp_path, pixels, error):
    with pytest.raises(error):
        write_image(tmp_path / "a.png", pixels)


def test_bad_write_arguments(tmp_path, icc_rgb):
    px = _smooth(3)
    with pytest.raises(InvalidValueError):
        write_image(tmp_path / "a.jpg", px, quality=0)
    with pytest.raises(InvalidTypeError):
        write_image(tmp_path / "a.jpg", px, quality=9.5)  # type: ignore[arg-type]
    with pytest.raises(InvalidValueError, match="cropped area is 10x10"):
        write_image(tmp_path / "a.png", px, gpano=GPano(full_width=10, full_height=10))
    with pytest.raises(InvalidTypeError):
        write_image(tmp_path / "a.png", px, gpano="yes")  # type: ignore[arg-type]
    with pytest.raises(InvalidTypeError):
        write_image(tmp_path / "a.png", px, exif="Exif")  # type: ignore[arg-type]
    with pytest.raises(InvalidValueError, match="needs a GRAY profile"):
        write_image(tmp_path / "a.png", px[:, :, :1], icc_profile=icc_rgb)
    with pytest.raises(ImageFormatError, match="at most 16383"):
        write_image(tmp_path / "a.webp", np.zeros((1, 16384, 3), np.uint8))
    assert list(tmp_path.iterdir()) == []


def test_all_errors_are_spherewarp_errors():
    for exc in (ImageFormatError, InvalidTypeError, InvalidValueError, OutputExistsError):
        assert issubclass(exc, SpherewarpError)


# ----------------------------------------------------------------------------
# Atomic writing
# ----------------------------------------------------------------------------


@pytest.mark.parametrize("exc_type", [RuntimeError, KeyboardInterrupt])
def test_failed_encoder_leaves_no_temp_file_and_keeps_existing(tmp_path, monkeypatch, exc_type):
    path = tmp_path / "keep.png"
    write_image(path, _smooth(3))
    before = path.read_bytes()

    def broken(tmp, arr, meta):
        Path(tmp).write_bytes(b"partial")
        raise exc_type("encoder exploded")

    monkeypatch.setitem(images_mod._WRITERS, "PNG", broken)
    expected = ImageFormatError if exc_type is RuntimeError else KeyboardInterrupt
    with pytest.raises(expected, match="encoder exploded"):
        write_image(path, _smooth(1), overwrite=True)
    assert path.read_bytes() == before
    assert [p.name for p in tmp_path.iterdir()] == ["keep.png"]


def test_failing_library_encoder_is_wrapped(tmp_path, monkeypatch):
    import imagecodecs

    def boom(*args, **kwargs):
        raise MemoryError("no memory for PNG")

    monkeypatch.setattr(imagecodecs, "png_encode", boom)
    with pytest.raises(ImageFormatError, match="PNG encoding or writing failed.*no memory"):
        write_image(tmp_path / "a.png", _smooth(3))
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    "exc", [PermissionError(13, "Permission denied"), OSError(28, "No space left on device")]
)
def test_a_refused_file_says_why_not_the_temporary_name(tmp_path, monkeypatch, exc):
    """A folder without write permission, a full or read-only disk: the line says what the
    file system said, not the hidden temporary file's name nor 'encoding failed'."""

    def refuse(tmp, *args):
        exc.filename = str(tmp)
        raise exc

    monkeypatch.setitem(images_mod._WRITERS, "PNG", refuse)
    with pytest.raises(ImageFormatError) as info:
        write_image(tmp_path / "a.png", _smooth(3))
    assert str(info.value) == f"cannot write '{tmp_path / 'a.png'}': {exc.strerror}"
    assert list(tmp_path.iterdir()) == []


def test_temp_file_is_hidden_next_to_target_with_same_suffix(tmp_path, monkeypatch):
    seen = []
    real = images_mod._WRITERS["TIFF"]

    def spy(tmp, arr, meta):
        seen.append(Path(tmp))
        real(tmp, arr, meta)

    monkeypatch.setitem(images_mod._WRITERS, "TIFF", spy)
    write_image(tmp_path / "pano.TIF", _smooth(3))
    (tmp,) = seen
    assert tmp.parent == tmp_path and tmp.name.startswith(".pano.TIF.")
    assert tmp.name.endswith(".tmp.TIF") and not tmp.exists()


def test_written_file_has_normal_permissions(tmp_path):
    if os.name != "posix":
        pytest.skip("POSIX permissions")
    umask = os.umask(0o022)
    os.umask(umask)
    out = write_image(tmp_path / "perm.png", _smooth(3))
    assert out.stat().st_mode & 0o777 == 0o666 & ~umask


# ----------------------------------------------------------------------------
# convert_dtype
# ----------------------------------------------------------------------------


def test_convert_dtype_scaling():
    u8 = np.array([0, 1, 128, 255], np.uint8)
    assert convert_dtype(u8, np.uint16).tolist() == [0, 257, 32896, 65535]
    assert convert_dtype(np.array([0, 128, 32767, 65535], np.uint16), "uint8").tolist() == [
        0,
        0,
        127,
        255,
    ]
    f = np.array([np.nan, -1.0, 0.5, 1.0, 7.0], np.float32)
    assert convert_dtype(f, np.uint8).tolist() == [0, 0, 128, 255, 255]
    assert convert_dtype(f, np.uint16).tolist() == [0, 0, 32768, 65535, 65535]
    assert convert_dtype(u8, np.float32).dtype == np.float32
    assert convert_dtype(u8, np.uint8) is u8
    with pytest.raises(InvalidValueError):
        convert_dtype(u8, np.int32)
    with pytest.raises(InvalidTypeError):
        convert_dtype(u8.astype(bool), np.uint8)


@given(st.lists(st.integers(0, 255), min_size=1, max_size=50))
def test_convert_dtype_uint8_survives_uint16_and_float(values):
    u8 = np.array(values, np.uint8)
    np.testing.assert_array_equal(convert_dtype(convert_dtype(u8, np.uint16), np.uint8), u8)
    np.testing.assert_array_equal(convert_dtype(convert_dtype(u8, np.float32), np.uint8), u8)


def test_files_from_other_writers(tmp_path):
    pal = Image.new("P", (6, 4))
    pal.putpalette([0, 0, 0, 255, 0, 0] + [0] * 762)
    pal.putpixel((1, 1), 1)
    pal.save(tmp_path / "pal.png", transparency=0)
    img = read_image(tmp_path / "pal.png")
    assert img.pixels.shape == (4, 6, 4) and img.gpano is None and img.exif is None
    assert img.pixels[1, 1].tolist() == [255, 0, 0, 255] and img.pixels[0, 0, 3] == 0

    grey16 = np.arange(24, dtype=np.uint16).reshape(4, 6) * 2000
    Image.fromarray(grey16).save(tmp_path / "g16.png")  # Pillow's I;16 PNG
    np.testing.assert_array_equal(read_image(tmp_path / "g16.png").pixels[:, :, 0], grey16)


def test_an_interrupt_while_fds_are_put_back_still_puts_them_back(monkeypatch):
    """_quiet_fds sends fds 1 and 2 to a discarded file round a C decoder; a Ctrl-C while it
    put them back left stderr there, and the command's 'interrupted' line was lost (seen in
    a CI dry run: exit 130, empty stderr)."""
    import signal
    import sys

    class Interrupting:
        def write(self, text):
            return len(text)

        def flush(self):
            signal.raise_signal(signal.SIGINT)  # arrives during the put-back

    before = os.fstat(2)
    with pytest.raises(KeyboardInterrupt), images_mod._quiet_fds():
        monkeypatch.setattr(sys, "stdout", Interrupting())
    after = os.fstat(2)
    assert (after.st_dev, after.st_ino) == (before.st_dev, before.st_ino)


# -- EXIF orientation ------------------------------------------------------------------------------
def _oriented_exif(orientation):
    exif = Image.Exif()
    exif[0x010F] = "SphereCam"  # Make
    exif[0x0112] = orientation
    exif[0x8769] = {0x9003: "2024:01:02 03:04:05"}  # DateTimeOriginal, in the Exif sub-IFD
    return exif.tobytes()


def _exif_view(blob):
    exif = Image.Exif()
    exif.load(blob)
    return exif.get(0x010F), exif.get(0x0112), exif.get_ifd(0x8769).get(0x9003)


@pytest.mark.parametrize("orientation", range(1, 9))
@pytest.mark.parametrize("ext", [".png", ".jpg"])
def test_exif_orientation_is_applied_on_reading_as_pillow_does(tmp_path, ext, orientation):
    """The pixels come as viewers show the file (``ImageOps.exif_transpose``); the EXIF
    keeps its tags, sub-IFDs included, with Orientation 1, the value written back."""
    from PIL import ImageOps

    px = _random("uint8", 3, shape=(6, 10)) if ext == ".png" else _smooth(3, (16, 24))
    path = tmp_path / f"o{orientation}{ext}"
    Image.fromarray(px).save(path, exif=_oriented_exif(orientation), quality=95)
    with Image.open(path) as im:
        want = np.asarray(ImageOps.exif_transpose(im))
    img = read_image(path)
    np.testing.assert_array_equal(img.pixels, want)
    assert _exif_view(img.exif) == ("SphereCam", 1, "2024:01:02 03:04:05")
    if orientation == 1:
        assert img.exif == _exif_with_header(_oriented_exif(1))
    out = write_image(tmp_path / f"back{ext}", img.pixels, exif=img.exif)
    with Image.open(out) as im:
        assert im.getexif().get(0x0112) == 1  # shown as written, unturned


def _exif_with_header(blob):
    return blob if blob.startswith(b"Exif\x00\x00") else b"Exif\x00\x00" + blob


def test_write_image_writes_orientation_1(tmp_path):
    """Pixels are written as they are displayed: a turning Orientation in the EXIF given
    would make viewers turn them again; only that value changes, in place."""
    blob = _exif_with_header(_oriented_exif(6))
    px = _random("uint8", 3)
    for ext in (".jpg", ".png", ".webp"):
        out = write_image(tmp_path / f"w{ext}", px, exif=blob, quality=100)
        with Image.open(out) as im:
            assert im.getexif().get(0x0112) == 1 and im.size == (W, H), ext
    with pytest.warns(UserWarning, match="sub-IFDs"):  # TIFF: the IFD0 tags only
        out = write_image(tmp_path / "w.tif", px, exif=blob)
    assert read_image(out).exif is not None and _exif_view(read_image(out).exif)[:2] == (
        "SphereCam",
        1,
    )
    stored = read_image(tmp_path / "w.png").exif
    assert len(stored) == len(blob)
    assert sum(a != b for a, b in zip(stored, blob, strict=True)) == 1  # the value, 6 -> 1
    assert _exif_view(stored) == ("SphereCam", 1, "2024:01:02 03:04:05")
