"""Hostile inputs to spherewarp.io: one pixel limit, non-regular files, XMP encodings, GPano.

The broad, seeded version of these cases is tests/test_fuzz.py; here each rule
has one direct test.
"""

from __future__ import annotations

import io
import os
import threading
import warnings

import numpy as np
import pytest
from PIL import Image

from spherewarp.errors import ImageFormatError, InvalidTypeError, InvalidValueError
from spherewarp.io import (
    DEFAULT_MAX_PIXELS,
    GPano,
    parse_gpano,
    place_on_full_sphere,
    read_image,
    write_image,
)
from spherewarp.io.images import pixel_limit
from spherewarp.io.xmp import gpano_xmp
from test_fuzz import endless_writer, jpeg_with_xmp, write_multipart_exr  # tests/ is on sys.path

# -- the pixel limit -----------------------------------------------------------------------


def test_pixel_limit_order(monkeypatch):
    monkeypatch.delenv("SPHEREWARP_MAX_PIXELS", raising=False)
    assert pixel_limit() == DEFAULT_MAX_PIXELS == 2**28
    monkeypatch.setenv("SPHEREWARP_MAX_PIXELS", "1_000")
    assert pixel_limit() == 1000
    assert pixel_limit(5) == 5  # an explicit limit wins
    for bad in ("0", "-3", "lots", "1e9"):
        monkeypatch.setenv("SPHEREWARP_MAX_PIXELS", bad)
        with pytest.raises(InvalidValueError, match="SPHEREWARP_MAX_PIXELS"):
            pixel_limit()
    monkeypatch.setenv("SPHEREWARP_MAX_PIXELS", str(2**63 - 1))  # beyond any image: no error
    assert pixel_limit() == 2**62
    with pytest.raises(InvalidTypeError):
        pixel_limit(2.5)  # type: ignore[arg-type]
    with pytest.raises(InvalidValueError):
        pixel_limit(0)


def test_environment_limit_applies_to_read_image(tmp_path, monkeypatch):
    path = write_image(tmp_path / "a.png", np.zeros((32, 64, 3), np.uint8))
    monkeypatch.setenv("SPHEREWARP_MAX_PIXELS", "100")
    with pytest.raises(ImageFormatError, match="--max-pixels"):
        read_image(path)
    assert read_image(path, max_pixels=2048).width == 64


@pytest.mark.parametrize("ext", [".png", ".jpg", ".tif", ".webp", ".exr"])
def test_every_format_obeys_the_limit(tmp_path, ext):
    path = write_image(tmp_path / f"a{ext}", np.zeros((32, 64, 3), np.uint8))
    with pytest.raises(ImageFormatError, match="pixel limit 2047"):
        read_image(path, max_pixels=2047)
    assert read_image(path, max_pixels=2048).pixels.shape[:2] == (32, 64)


def test_webp_is_not_held_to_pillows_own_limit(tmp_path, monkeypatch):
    path = write_image(tmp_path / "a.webp", np.zeros((32, 64, 3), np.uint8))
    monkeypatch.setattr(Image, "MAX_IMAGE_PIXELS", 10)
    assert read_image(path).width == 64
    assert Image.MAX_IMAGE_PIXELS == 10  # restored


def test_multipart_exr_counts_every_part(tmp_path):
    path = write_multipart_exr(tmp_path / "m.exr", [(32, 64), (256, 512), (256, 512)])
    with pytest.raises(ImageFormatError, match="part 2 of 3"):
        read_image(path, max_pixels=200_000)
    img = read_image(path, max_pixels=300_000)  # all parts fit: part 0 is the image
    assert img.pixels.shape == (32, 64, 3)


def _jpeg_with_xmp(path, xmp: bytes, shape=(128, 256)):
    path.write_bytes(jpeg_with_xmp(xmp, shape))
    return path


def test_declared_canvas_counts_against_the_limit(tmp_path):
    g = GPano(full_width=30000, full_height=15000, cropped_width=256, cropped_height=128)
    path = write_image(tmp_path / "c.jpg", np.zeros((128, 256, 3), np.uint8), gpano=g)
    with pytest.raises(ImageFormatError, match="canvas its GPano XMP declares is 30000x15000"):
        read_image(path)
    info = read_image(path, full_sphere=False)  # not placed: nothing is allocated
    assert info.gpano == g and info.width == 256
    small = GPano(full_width=512, full_height=256, cropped_width=256, cropped_height=128)
    path = write_image(tmp_path / "s.jpg", np.zeros((128, 256, 3), np.uint8), gpano=small)
    with pytest.raises(ImageFormatError, match="canvas"):
        read_image(path, max_pixels=100_000)
    assert read_image(path, max_pixels=512 * 256).width == 512


def test_place_on_full_sphere_obeys_the_limit():
    g = GPano(full_width=2**31 - 1, full_height=2**30, cropped_width=8, cropped_height=4)
    with pytest.raises(InvalidValueError, match="pixel limit"):
        place_on_full_sphere(np.zeros((4, 8, 3), np.uint8), g)
    small = GPano(full_width=16, full_height=8, cropped_width=8, cropped_height=4)
    with pytest.raises(InvalidValueError, match="pixel limit 100"):
        place_on_full_sphere(np.zeros((4, 8, 3), np.uint8), small, max_pixels=100)
    assert place_on_full_sphere(np.zeros((4, 8, 3), np.uint8), small).shape == (8, 16, 4)


# -- files that are not regular files ---------------------------------------------------


@pytest.mark.parametrize("device", ["/dev/zero", "/dev/urandom"])
def test_devices_are_refused_unread(device):
    if not os.path.exists(device):
        pytest.skip(f"no {device}")
    with pytest.raises(ImageFormatError, match="not a regular file"):
        read_image(device)


def test_fifos_are_refused_without_hanging(tmp_path):
    idle = tmp_path / "idle"
    os.mkfifo(idle)
    with pytest.raises(ImageFormatError, match="not a regular file"):
        read_image(idle)  # no writer: the open must not block
    busy = tmp_path / "busy"
    os.mkfifo(busy)
    stop = threading.Event()
    t = threading.Thread(target=endless_writer, args=(busy, stop), daemon=True)
    t.start()
    with pytest.raises(ImageFormatError, match="not a regular file"):
        read_image(busy)
    stop.set()
    with open(os.open(busy, os.O_RDONLY | os.O_NONBLOCK), "rb") as fh:
        fh.read(1 << 20)
    t.join(5)


# -- XMP in every encoding ---------------------------------------------------------------

_PACKET = gpano_xmp(GPano.full_sphere(64, 32))
_DECL = '<?xml version="1.0" encoding="UTF-16"?>'


@pytest.mark.parametrize("encoding", ["utf-8", "utf-16-be", "utf-16-le", "utf-16", "utf-32"])
def test_xmp_is_read_in_every_encoding(encoding):
    prefix = "" if encoding == "utf-8" else _DECL
    data = (prefix + _PACKET).encode(encoding)
    assert parse_gpano(data) == GPano.full_sphere(64, 32)
    assert parse_gpano(data + b"\0\0\0\0") == GPano.full_sphere(64, 32)  # NUL padding
    if encoding in ("utf-16-be", "utf-16-le"):  # no BOM, blanks before the first "<"
        assert parse_gpano(("\n  " + _PACKET).encode(encoding)) == GPano.full_sphere(64, 32)


@pytest.mark.parametrize("encoding", ["utf-8", "utf-16-be", "utf-16-le", "utf-16"])
def test_a_dtd_is_refused_in_every_encoding(encoding):
    body = _PACKET.split("?>", 1)[1].replace(
        'FullPanoWidthPixels="64"', 'FullPanoWidthPixels="&fw;"'
    )
    text = _DECL + '<!DOCTYPE x [<!ENTITY fw "512">]>' + body
    with pytest.raises(InvalidValueError, match="DTD"):
        parse_gpano(text.encode(encoding))


def test_a_utf16_entity_never_becomes_the_panorama_width(tmp_path):
    body = _PACKET.split("?>", 1)[1].replace(
        'FullPanoWidthPixels="64"', 'FullPanoWidthPixels="&fw;"'
    )
    text = _DECL + '<!DOCTYPE x [<!ENTITY fw "512">]>' + body
    path = _jpeg_with_xmp(tmp_path / "e.jpg", text.encode("utf-16-be"), shape=(32, 64))
    with pytest.warns(UserWarning, match="DTD"):
        img = read_image(path)
    assert img.gpano is None and img.width == 64


@pytest.mark.parametrize(
    "value", ["inf", "Infinity", "-inf", "nan", "1e999", "9" * 5000, "1e308", str(10**30),
              str(2**62), "-1", "6.5"],
)  # fmt: skip
def test_hostile_gpano_numbers_are_one_value_error(value):
    packet = _PACKET.replace('FullPanoWidthPixels="64"', f'FullPanoWidthPixels="{value}"')
    with pytest.raises(InvalidValueError, match="FullPanoWidthPixels") as err:
        parse_gpano(packet)
    assert len(str(err.value)) < 200


def test_hostile_gpano_in_a_file_is_one_warning(tmp_path):
    packet = _PACKET.replace('FullPanoWidthPixels="64"', 'FullPanoWidthPixels="1e999"')
    path = _jpeg_with_xmp(tmp_path / "g.jpg", packet.encode(), shape=(32, 64))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        img = read_image(path)
    assert img.gpano is None
    assert len(caught) == 1 and "GPano" in str(caught[0].message)


# -- metadata checked on reading, not after the render ------------------------------------


def test_unreadable_icc_and_exif_are_dropped_on_reading(tmp_path):
    buf = io.BytesIO()
    Image.fromarray(np.zeros((32, 64, 3), np.uint8)).save(
        buf, "PNG", icc_profile=b"\1" * 200, exif=b"Exif\0\0garbage-not-tiff"
    )
    path = tmp_path / "m.png"
    path.write_bytes(buf.getvalue())
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        img = read_image(path)
    assert img.icc_profile is None and img.exif is None
    text = " ".join(str(w.message) for w in caught)
    assert "ICC" in text and "EXIF" in text
    write_image(tmp_path / "out.tif", img.pixels, icc_profile=img.icc_profile, exif=img.exif)


def test_exif_too_long_for_jpeg_is_dropped_with_a_warning(tmp_path):
    exif = Image.Exif()
    exif[270] = "x" * 70_000
    with pytest.warns(UserWarning, match="APP1"):
        path = write_image(tmp_path / "a.jpg", np.zeros((8, 16, 3), np.uint8), exif=exif.tobytes())
    assert read_image(path).exif is None
