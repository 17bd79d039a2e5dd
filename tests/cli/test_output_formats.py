"""Output formats from the command line: HDR and alpha are converted for formats
that cannot hold them (tone mapping, flattening), with one note line."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from _cli import fails, ok, run

from spherewarp.demo import sample_path
from spherewarp.io import GPano, read_image, write_image

EXR = Path(sample_path()).with_name("interior.exr")


@pytest.fixture
def cropped(tmp_path: Path) -> Path:
    """A GPano-cropped JPEG: the middle half of the rows, three quarters of the columns."""
    src = read_image(sample_path()).pixels[..., :3]
    h, w = src.shape[:2]
    crop = np.ascontiguousarray(src[h // 4 : 3 * h // 4, : 3 * w // 4])
    g = GPano(
        full_width=w,
        full_height=h,
        cropped_width=crop.shape[1],
        cropped_height=crop.shape[0],
        cropped_left=0,
        cropped_top=h // 4,
    )
    return write_image(tmp_path / "crop.jpg", crop, gpano=g)


def _note(err: str) -> str:
    lines = err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("spherewarp: note: "), err
    return lines[0]


def test_hdr_exr_to_jpeg_in_one_command(tmp_path: Path) -> None:
    out = tmp_path / "room.jpg"
    code, stdout, err = run(None, "rotate", EXR, "--yaw", "30", "-o", out)
    assert code == 0, err
    assert stdout.strip() == f"wrote {out}"
    note = _note(err)
    assert "tone-mapped HDR to 8-bit sRGB" in note and "--tonemap aces" in note
    px = read_image(out).pixels
    assert px.dtype == np.uint8 and px.shape == (512, 1024, 3)
    # a photo: neither black nor washed out, with contrast and some true whites (windows)
    assert 80 < px.mean() < 190 and px.std() > 40
    assert (px.min(axis=2) > 250).mean() > 0.001 and (px.max(axis=2) < 40).mean() > 0.01


@pytest.mark.parametrize("method", ["aces", "reinhard", "clip"])
def test_hdr_to_png_is_16_bit_and_tonemaps_differ(tmp_path: Path, method: str) -> None:
    out = tmp_path / f"{method}.png"
    code, _, err = run(None, "rotate", EXR, "--yaw", "0", "--tonemap", method, "-o", out)
    assert code == 0, err
    assert "16-bit" in _note(err)
    px = read_image(out).pixels
    assert px.dtype == np.uint16
    # reinhard never clips (so the windows are not white); clip cuts them to white
    white = (px.min(axis=2) == 65535).mean()
    if method == "reinhard":
        assert white == 0.0
    elif method == "clip":
        assert white > 0.005


def test_exposure_brightens(tmp_path: Path) -> None:
    a, b = tmp_path / "a.jpg", tmp_path / "b.jpg"
    ok(None, "rotate", EXR, "--yaw", "0", "-o", a, "-q")
    ok(None, "rotate", EXR, "--yaw", "0", "-o", b, "-q", "--exposure", "1")
    assert read_image(b).pixels.mean() > read_image(a).pixels.mean() + 10


@pytest.mark.parametrize("ext", [".exr", ".tif"])
def test_float_formats_keep_hdr_without_a_note(tmp_path: Path, ext: str) -> None:
    out = tmp_path / f"room{ext}"
    code, _, err = run(None, "rotate", EXR, "--yaw", "0", "-o", out)
    assert code == 0 and err == "", err
    px = read_image(out).pixels
    assert px.dtype == np.float32 and px.max() > 100


def test_nan_samples_in_an_input_are_said_once(tmp_path: Path) -> None:
    x = np.random.default_rng(0).random((32, 64, 3)).astype(np.float32)
    x[10, 10] = np.nan
    x[20, 20, 1] = np.inf
    write_image(tmp_path / "nan.exr", x)
    nan = tmp_path / "nan.exr"
    code, _, err = run(None, "rotate", nan, "--yaw", "30", "-o", tmp_path / "o.exr")
    assert code == 0 and "has 4 NaN or infinite sample(s)" in _note(err)
    code, _, err = run(None, "rotate", nan, "--yaw", "30", "-o", tmp_path / "q.exr", "-q")
    assert code == 0 and err == ""


def test_cropped_panorama_to_jpeg_in_one_command(tmp_path: Path, cropped: Path) -> None:
    out = tmp_path / "out.jpg"
    code, _, err = run(None, "rotate", cropped, "--yaw", "20", "-o", out)
    assert code == 0, err
    assert "flattened transparency onto black" in _note(err)
    px = read_image(out).pixels
    assert px.shape == (512, 1024, 3)
    assert px[:100].max() < 16  # above the crop: the background, black
    white = tmp_path / "white.jpg"
    code, _, err = run(None, "rotate", cropped, "--yaw", "20", "-o", white, "--background", "#fff")
    assert code == 0 and "onto #fff" in err, err
    assert read_image(white).pixels[:100].min() > 240


def test_cropped_panorama_to_png_keeps_alpha_unless_background(tmp_path: Path, cropped: Path):
    out = tmp_path / "out.png"
    code, _, err = run(None, "rotate", cropped, "--yaw", "20", "-o", out)
    assert code == 0 and err == "", err
    assert read_image(out).pixels.shape[2] == 4
    flat = tmp_path / "flat.png"
    ok(None, "rotate", cropped, "--yaw", "20", "-o", flat, "--background", "grey", "-q")
    assert read_image(flat).pixels.shape[2] == 3


def test_16_bit_to_jpeg_is_reduced(tmp_path: Path) -> None:
    src = write_image(tmp_path / "in.png", np.full((8, 16, 3), 40000, np.uint16))
    out = tmp_path / "out.jpg"
    code, _, err = run(None, "rotate", src, "--yaw", "10", "-o", out)
    assert code == 0 and "reduced 16-bit samples to 8-bit" in _note(err), err
    assert abs(int(read_image(out).pixels.mean()) - 40000 // 257) <= 2


def test_quiet_silences_the_note(tmp_path: Path) -> None:
    code, out, err = run(None, "rotate", EXR, "--yaw", "0", "-o", tmp_path / "q.jpg", "--quiet")
    assert code == 0 and err == "" and out.startswith("wrote "), err


def test_bad_tonemap_and_background_are_one_line_errors(tmp_path: Path) -> None:
    err = fails(None, "rotate", EXR, "--yaw", "0", "-o", tmp_path / "x.jpg", "--tonemap", "x")
    assert "--tonemap" in err
    err = fails(None, "rotate", EXR, "--yaw", "0", "-o", tmp_path / "x.jpg", "--background", "z")
    assert "--background" in err and "colour" in err
    assert not (tmp_path / "x.jpg").exists()


def test_help_tells_the_conversion_policy() -> None:
    text = " ".join(ok(None, "rotate", "--help").split())
    for words in ("--tonemap", "aces", "--exposure", "--background", "--quiet", "16-bit"):
        assert words in text


def test_metadata_a_format_cannot_hold_is_said(tmp_path: Path) -> None:
    """A JPEG's ICC profile and EXIF written to EXR (which holds neither), or its EXIF
    sub-IFD to TIFF, were dropped in silence: the writer's warning went to the discarded
    stderr of the C encoders. Now it is one line each."""
    from PIL import Image, ImageCms

    src = tmp_path / "meta.jpg"
    exif = Image.Exif()
    exif[0x010F] = "QA"
    exif.get_ifd(0x8769)[0x9003] = "2024:01:01 00:00:00"
    icc = ImageCms.ImageCmsProfile(ImageCms.createProfile("sRGB")).tobytes()
    Image.open(sample_path()).convert("RGB").save(src, exif=exif.tobytes(), icc_profile=icc)
    code, _, err = run(None, "rotate", src, "--yaw", "30", "-o", tmp_path / "m.exr")
    lines = err.splitlines()  # the linear-light note, and the metadata's warning
    assert code == 0 and len(lines) == 2 and lines[0].startswith("spherewarp: note: EXR:"), err
    assert lines[1].startswith("spherewarp: warning: EXR: ICC profile and EXIF are not stored")
    code, _, err = run(None, "rotate", src, "--yaw", "30", "-o", tmp_path / "m.tif")
    assert code == 0 and err.count("\n") == 1 and "dropped tags" in err, err


def test_a_cropped_panorama_turned_has_no_dark_outline(tmp_path: Path) -> None:
    """The uncovered part of a cropped panorama is transparent black; filtered straight,
    the crop's edge pixels came out partly transparent and darkened (to about 0.36 x
    their colour: a dark outline). Filtered premultiplied, they keep the crop's colour."""
    crop = np.empty((40, 80, 3), np.uint8)
    crop[...] = (180, 170, 160)
    g = GPano(
        full_width=256,
        full_height=128,
        cropped_width=80,
        cropped_height=40,
        cropped_left=60,
        cropped_top=30,
    )
    src = write_image(tmp_path / "crop.png", crop, gpano=g)
    out = tmp_path / "turned.png"
    ok(None, "rotate", src, "--yaw", "30", "--pitch", "10", "-o", out, "-q")
    px = read_image(out).pixels
    seen = px[..., 3] > 0
    assert ((px[..., 3] > 0) & (px[..., 3] < 255)).sum() > 100
    assert np.all(px[seen][:, :3] == (180, 170, 160))


def _smooth_rgb(h: int = 64, w: int = 128, dtype: type = np.uint8) -> np.ndarray:
    y, x = np.mgrid[0:h, 0:w] / np.array([h, w])[:, None, None]
    f = np.stack([x, y, 0.5 + 0.5 * np.sin(6 * x + 3 * y)], -1)
    return np.rint(f * np.iinfo(dtype).max).astype(dtype)


@pytest.mark.parametrize("dtype", [np.uint8, np.uint16])
def test_integer_through_exr_and_back_is_the_same_image(tmp_path: Path, dtype: type) -> None:
    """EXR holds linear light: 8/16-bit (sRGB) samples are written linearised, with a
    note, and the clip tone map encodes them back: the round trip gives the image again
    (it was 11.4 dB off: sRGB values written as linear, 128 came back as 188)."""
    src = _smooth_rgb(dtype=dtype)
    src[0, :3] = 128 * (np.iinfo(dtype).max // 255)
    png = write_image(tmp_path / "in.png", src)
    exr = tmp_path / "c.exr"
    code, _, err = run(None, "rotate", png, "--yaw", "90", "-o", exr)
    assert code == 0 and "EXR: converted the sRGB-encoded samples to linear-light" in _note(err)
    lin = read_image(exr).pixels
    top = np.iinfo(dtype).max
    x = src[0, 0, 0] / top  # sRGB 128/255 is 0.2158 linear
    assert lin[0, 3 * 128 // 4, 0] == pytest.approx(((x + 0.055) / 1.055) ** 2.4, rel=1e-6)
    back = tmp_path / "back.png"
    ok(None, "rotate", exr, "--yaw", "-90", "--tonemap", "clip", "-o", back, "-q")
    px = read_image(back).pixels
    assert px.dtype == np.uint16  # float to PNG is 16-bit
    if dtype == np.uint8:
        px = (px.astype(np.uint32) + 128) // 257
    assert np.abs(px.astype(np.int64) - src).max() <= 1
    ok(None, "rotate", exr, "--yaw", "-90", "--tonemap", "clip", "-o", tmp_path / "b.jpg", "-q")
    if dtype == np.uint8:  # a JPEG of the same: close (the codec's loss only)
        jpg = read_image(tmp_path / "b.jpg").pixels.astype(float)
        assert np.abs(jpg - src).mean() < 2


def _with_orientation(path: Path, pixels: np.ndarray, orientation: int) -> Path:
    from PIL import Image

    exif = Image.Exif()
    exif[0x010F] = "SphereCam"
    exif[0x0112] = orientation
    Image.fromarray(pixels).save(path, exif=exif.tobytes(), quality=95)
    return path


def _orientation_and_make(path: Path) -> tuple:
    from PIL import Image

    with Image.open(path) as im:
        exif = im.getexif()
        return exif.get(0x0112), exif.get(0x010F)


def test_exif_orientation_is_applied_and_written_as_1(tmp_path: Path) -> None:
    """A file stored turned 180 degrees with Orientation 3 (shown upright) renders as the
    upright image; the output says Orientation 1, its other EXIF kept. (The tag was
    ignored on input and copied to the output: viewers turned the result.)"""
    up = _smooth_rgb()
    upright = write_image(tmp_path / "up.png", up)
    turned = _with_orientation(tmp_path / "o3.png", np.ascontiguousarray(up[::-1, ::-1]), 3)
    args = ("--yaw", "30", "--pitch", "20", "-q")
    ok(None, "rotate", upright, *args, "-o", tmp_path / "want.png")
    ok(None, "rotate", turned, *args, "-o", tmp_path / "got.png")
    np.testing.assert_array_equal(
        read_image(tmp_path / "got.png").pixels, read_image(tmp_path / "want.png").pixels
    )
    assert _orientation_and_make(tmp_path / "got.png") == (1, "SphereCam")
    jpg = _with_orientation(tmp_path / "o3.jpg", np.ascontiguousarray(up[::-1, ::-1]), 3)
    ok(None, "rotate", jpg, *args, "-o", tmp_path / "got.jpg")
    assert _orientation_and_make(tmp_path / "got.jpg") == (1, "SphereCam")
    got = read_image(tmp_path / "got.jpg").pixels.astype(float)
    want = read_image(tmp_path / "want.png").pixels.astype(float)
    assert 10 * np.log10(255**2 / np.mean((got - want) ** 2)) > 30  # the codec's loss only
    # Orientation 6: stored turned a quarter, displayed 1:2, which is no panorama
    six = _with_orientation(tmp_path / "o6.png", up, 6)
    err = fails(None, "rotate", six, "--yaw", "30", "-o", tmp_path / "x.png")
    assert "width = 2 x height, got 64x128" in err and "--force" in err
