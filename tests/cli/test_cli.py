"""The command line: every subcommand on small images, against the Python API."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from _cli import ok, run  # noqa: F401

from spherewarp import coords
from spherewarp.cli import COMMANDS
from spherewarp.io import GPano, read_image, write_image
from spherewarp.maps import Mobius, map_from_json
from spherewarp.render import warp
from spherewarp.testpattern import make_test_pattern

W, H = 128, 64


@pytest.fixture
def pattern_png(workdir: Path) -> Path:
    """A 128x64 test pattern (no labels) as an 8-bit PNG."""
    return write_image(workdir / "in.png", make_test_pattern(W, labels=False))


def pushed(image: np.ndarray, forward: Mobius, **kw: object) -> np.ndarray:
    return warp(image, forward.inverse(), **kw)


# ---------------------------------------------------------------- help and wiring


def test_top_level_help_lists_every_command(capsys):
    out = ok(capsys, "--help")
    for name in COMMANDS:
        assert name in out


@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_every_command_help_shows_an_example(capsys, command):
    out = ok(capsys, command, "--help")
    assert "Example" in out
    assert f"spherewarp {command} " in out.split("Example", 1)[1]


def _help_examples() -> dict[str, list[list[str]]]:
    """The example command lines of every command's --help (video's effects too), split."""
    import shlex

    import click

    from spherewarp.cli import cli

    ctx = click.Context(cli)
    found: dict[str, list[list[str]]] = {}

    def walk(cmd: click.Command, name: str) -> None:
        lines = [ln.strip() for ln in (cmd.epilog or "").splitlines()]
        found[name] = [shlex.split(ln) for ln in lines if ln.startswith("spherewarp ")]
        if isinstance(cmd, click.Group):
            for sub in cmd.list_commands(ctx):
                walk(cmd.get_command(ctx, sub), f"{name} {sub}")

    for name in COMMANDS:
        walk(cli.get_command(ctx, name), name)
    return found


def test_a_commands_help_examples_write_distinct_files():
    """Pasted in order in one folder, no example of a command's --help is refused because an
    earlier one wrote its file ('exists; pass --overwrite')."""
    for name, examples in _help_examples().items():
        written: dict[str, str] = {}
        for argv in examples:
            if "--overwrite" in argv:
                continue
            for flag in ("-o", "--output", "--save-recipe"):
                if flag in argv:
                    path = argv[argv.index(flag) + 1]
                    line = " ".join(argv)
                    assert path not in written, f"{name}: {line!r} writes {path} again"
                    written[path] = line


def test_zooms_help_examples_run_in_sequence(workdir):
    """zoom's examples, pasted in order in one folder (the sample as room.jpg), all run."""
    from spherewarp.demo import sample_path

    px = read_image(sample_path()).pixels
    write_image(workdir / "room.jpg", px)
    for argv in _help_examples()["zoom"]:
        ok(None, *argv[1:], "--size", "128x64", "-q")


@pytest.mark.parametrize("command", ["rotate", "zoom", "mobius"])
def test_render_commands_have_the_common_options(capsys, command):
    out = ok(capsys, command, "--help")
    for option in ("--output", "--overwrite", "--force", "--size", "--interp", "--supersample"):
        assert option in out
    assert "--quality" in out and "--print" in out


def test_version(capsys):
    assert "version" in ok(capsys, "--version").lower()


# ---------------------------------------------------------------- rotate


@pytest.mark.parametrize("yaw, shift", [(90, -W // 4), (-90, W // 4), (180, W // 2)])
def test_rotate_yaw_is_a_roll_of_the_columns(capsys, pattern_png, yaw, shift):
    # --yaw 90 looks right: lon +90 comes to the centre, the columns move left by W/4.
    ok(capsys, "rotate", pattern_png, "--yaw", yaw, "-o", "out.png")
    src = read_image(pattern_png).pixels
    out = read_image("out.png").pixels
    np.testing.assert_array_equal(out, np.roll(src, shift, axis=1))


def test_rotate_yaw_brings_lon_90_to_the_centre(capsys, pattern_png):
    out = json.loads(ok(capsys, "rotate", pattern_png, "--yaw", 90, "--print-map"))
    forward = map_from_json(json.dumps(out))
    np.testing.assert_allclose(forward.apply_lonlat([90.0, 0.0]), [0.0, 0.0], atol=1e-9)


def test_rotate_about_the_zenith_moves_the_content_east(capsys, pattern_png):
    # Counter-clockwise about the zenith as seen from the centre: content moves to larger lon.
    ok(capsys, "rotate", pattern_png, "--axis", "0,90", "--angle", 90, "-o", "out.png")
    src = read_image(pattern_png).pixels
    np.testing.assert_array_equal(read_image("out.png").pixels, np.roll(src, W // 4, axis=1))


def test_rotate_ypr_matches_the_api(capsys, pattern_png):
    ok(capsys, "rotate", pattern_png, "--yaw", 30, "--pitch", -20, "--roll", 10, "-o", "out.png")
    src = read_image(pattern_png).pixels
    expected = warp(src, Mobius.from_yaw_pitch_roll(30, -20, 10))
    np.testing.assert_array_equal(read_image("out.png").pixels, expected)


def test_rotate_axis_angle_matches_the_api(capsys, pattern_png):
    ok(capsys, "rotate", pattern_png, "--axis", "-40,25", "--angle", 33, "-o", "out.png")
    src = read_image(pattern_png).pixels
    expected = pushed(src, Mobius.rotation((-40, 25), 33))
    np.testing.assert_array_equal(read_image("out.png").pixels, expected)


def test_rotate_pitch_alone_defaults_the_others(capsys, pattern_png):
    ok(capsys, "rotate", pattern_png, "--pitch", 15, "-o", "out.png")
    expected = warp(read_image(pattern_png).pixels, Mobius.from_yaw_pitch_roll(0, 15, 0))
    np.testing.assert_array_equal(read_image("out.png").pixels, expected)


def test_default_output_name(capsys, pattern_png):
    out = ok(capsys, "rotate", pattern_png, "--yaw", 10)
    assert Path("in-rotate.png").is_file()
    assert "in-rotate.png" in out


def test_overwrite_replaces(capsys, pattern_png):
    ok(capsys, "rotate", pattern_png, "--yaw", 10, "-o", "out.png")
    first = Path("out.png").read_bytes()
    ok(capsys, "rotate", pattern_png, "--yaw", 40, "-o", "out.png", "--overwrite")
    assert Path("out.png").read_bytes() != first


@pytest.mark.parametrize("mode", ["auto", "area", "none", "3"])
def test_antialias_modes(capsys, pattern_png, mode):
    ok(capsys, "zoom", pattern_png, "--at", "20,10", "--factor", 3, "-o", "out.png",
       "--antialias", mode)  # fmt: skip
    src = read_image(pattern_png).pixels
    aa = int(mode) if mode.isdigit() else mode
    expected = warp(src, Mobius.zoom((20.0, 10.0), 3.0).inverse(), antialias=aa)
    np.testing.assert_array_equal(read_image("out.png").pixels, expected)


@pytest.mark.parametrize("interp", ["nearest", "bilinear", "bicubic", "BICUBIC"])
def test_interp_supersample_and_size(capsys, pattern_png, interp):
    ok(
        capsys,
        "rotate",
        pattern_png,
        "--yaw",
        17,
        "-o",
        "out.png",
        "--interp",
        interp,
        "--supersample",
        2,
        "--size",
        "64x32",
    )
    src = read_image(pattern_png).pixels
    expected = warp(
        src,
        Mobius.from_yaw_pitch_roll(17, 0, 0),
        interp=interp.lower(),
        supersample=2,
        output_shape=(32, 64),
    )
    out = read_image("out.png")
    np.testing.assert_array_equal(out.pixels, expected)
    assert (out.gpano.full_width, out.gpano.full_height) == (64, 32)


# ---------------------------------------------------------------- zoom


def test_zoom_matches_the_api(capsys, pattern_png):
    ok(capsys, "zoom", pattern_png, "--at", "30,20", "--factor", 2.5, "-o", "out.png")
    expected = pushed(read_image(pattern_png).pixels, Mobius.zoom((30, 20), 2.5))
    np.testing.assert_array_equal(read_image("out.png").pixels, expected)


def test_zoom_at_pixel_is_zoom_at_its_lonlat(capsys, pattern_png):
    x, y = 40.0, 20.0
    lon, lat = np.degrees(coords.lonlat_from_pixel([x, y], W, H))
    ok(capsys, "zoom", pattern_png, "--at-pixel", f"{x},{y}", "--factor", 3, "-o", "a.png")
    ok(
        capsys,
        "zoom",
        pattern_png,
        "--at",
        f"{float(lon)!r},{float(lat)!r}",
        "--factor",
        3,
        "-o",
        "b.png",
    )
    np.testing.assert_array_equal(read_image("a.png").pixels, read_image("b.png").pixels)
    forward = map_from_json(
        ok(capsys, "zoom", pattern_png, "--at-pixel", f"{x},{y}", "--factor", 3, "--print-map")
    )
    assert forward == Mobius.zoom((lon, lat), 3)


def test_zoom_center_brings_the_point_to_the_front(capsys, pattern_png):
    forward = map_from_json(
        ok(capsys, "zoom", pattern_png, "--at", "-120,30", "--factor", 2, "--center", "--print-map")
    )
    np.testing.assert_allclose(forward.apply_lonlat([-120.0, 30.0]), [0.0, 0.0], atol=1e-9)
    assert forward.local_scale(coords.cp1_from_lonlat(np.radians([-120.0, 30.0]))) == (
        pytest.approx(2.0)
    )


def test_zoom_magnifies_the_content(capsys, workdir):
    # The -1 disc at the front (a cap of radius r) comes out with radius 2 atan(4 tan(r/2)).
    w = 512
    write_image("big.png", make_test_pattern(w, labels=False))
    ok(capsys, "zoom", "big.png", "--at", "0,0", "--factor", 4, "-o", "out.png")
    # The pattern's colours (disc, rim, equator, meridian, checker): each pixel is classified
    # by the nearest, so anti-aliased edges split at 50% coverage.
    palette = np.array(
        [
            [230, 77, 191],
            [20, 20, 26],
            [26, 84, 217],
            [217, 31, 31],
            [251, 246, 233],
            [231, 221, 199],
            [236, 242, 249],
            [204, 215, 230],
        ]
    )

    def disc_width(img):  # pixels of the disc's colour along the two rows at the equator
        row = img[w // 4 - 1 : w // 4 + 1].astype(float)
        nearest = np.argmin(np.linalg.norm(row[..., None, :] - palette, axis=-1), axis=-1)
        return np.sum(nearest == 0) / 2

    before = disc_width(read_image("big.png").pixels)
    after = disc_width(read_image("out.png").pixels)
    r = np.radians(before / 2 * 360 / w)
    expected = 2 * np.degrees(np.arctan(4 * np.tan(r / 2))) * 2 * w / 360
    assert before >= 6
    assert after == pytest.approx(expected, rel=0.1)


# ---------------------------------------------------------------- mobius


def test_mobius_matrix_pushes_forward(capsys, pattern_png):
    ok(capsys, "mobius", pattern_png, "--matrix", "1+1j,0.5i,0,1-1j", "-o", "out.png")
    m = Mobius([[1 + 1j, 0.5j], [0, 1 - 1j]])
    expected = pushed(read_image(pattern_png).pixels, m)
    np.testing.assert_array_equal(read_image("out.png").pixels, expected)


def test_mobius_matrix_print(capsys, pattern_png):
    forward = map_from_json(
        ok(capsys, "mobius", pattern_png, "--matrix", "1,0.5,0,1", "--print-map")
    )
    assert forward == Mobius([[1, 0.5], [0, 1]])
    assert complex(forward(1j)) == pytest.approx(0.5 + 1j)
    assert not Path("in-mobius.png").exists()


def test_mobius_three_points(capsys, pattern_png):
    p = [(0, 0), (90, 0), (0, 90)]
    q = [(10, 5), (60, -10), (-30, 70)]
    args = ["--from", *(f"{a},{b}" for a, b in p), "--to", *(f"{a},{b}" for a, b in q)]
    forward = map_from_json(ok(capsys, "mobius", pattern_png, *args, "--print-map"))
    for a, b in zip(p, q, strict=True):
        moved = coords.xyz_from_lonlat(np.radians(forward.apply_lonlat(np.asarray(a, float))))
        np.testing.assert_allclose(moved, coords.xyz_from_lonlat(np.radians(b)), atol=1e-9)
    ok(capsys, "mobius", pattern_png, *args, "-o", "out.png")
    expected = pushed(read_image(pattern_png).pixels, Mobius.from_points(p, q))
    np.testing.assert_array_equal(read_image("out.png").pixels, expected)


# ---------------------------------------------------------------- formats, dtypes, metadata


@pytest.mark.parametrize(
    "ext, fmt, dtype",
    [
        (".png", "PNG", np.uint8),
        (".jpg", "JPEG", np.uint8),
        (".tif", "TIFF", np.uint8),
        (".webp", "WEBP", np.uint8),
        (".exr", "EXR", np.float32),
    ],
)
def test_output_format_from_extension(capsys, pattern_png, ext, fmt, dtype):
    ok(capsys, "rotate", pattern_png, "--yaw", 90, "-o", f"out{ext}")
    out = read_image(f"out{ext}")
    assert out.format == fmt
    assert out.pixels.dtype == dtype
    assert out.pixels.shape == (H, W, 3)
    assert out.gpano is not None and out.gpano.full_width == W


def test_uint16_png_stays_uint16(capsys, workdir):
    src = make_test_pattern(W, dtype=np.uint16, labels=False)
    write_image("in16.png", src)
    ok(capsys, "rotate", "in16.png", "--yaw", 90, "-o", "out16.png")
    out = read_image("out16.png").pixels
    assert out.dtype == np.uint16
    np.testing.assert_array_equal(out, np.roll(src, -W // 4, axis=1))


def test_exr_float32_stays_hdr(capsys, workdir):
    src = (make_test_pattern(W, dtype=np.float32, labels=False) * 40.0).astype(np.float32)
    write_image("in.exr", src)
    ok(capsys, "zoom", "in.exr", "--at", "0,0", "--factor", 2, "-o", "out.exr")
    out = read_image("out.exr")
    assert out.format == "EXR" and out.pixels.dtype == np.float32
    assert out.pixels.max() > 30.0  # no clipping to 1
    np.testing.assert_allclose(out.pixels, pushed(src, Mobius.zoom((0, 0), 2)), rtol=1e-6)


def test_icc_exif_and_gpano_are_carried(capsys, workdir):
    from PIL import Image, ImageCms

    icc = ImageCms.ImageCmsProfile(ImageCms.createProfile("sRGB")).tobytes()
    exif = Image.Exif()
    exif[0x010F] = "SpherewarpTestCam"
    pattern = make_test_pattern(W, labels=False)
    write_image("meta.png", pattern, icc_profile=icc, exif=exif.tobytes())
    ok(capsys, "mobius", "meta.png", "--matrix", "2,0,0,1", "-o", "out.png", "--size", "96x48")
    out = read_image("out.png")
    assert out.icc_profile == icc
    assert out.exif is not None and b"SpherewarpTestCam" in out.exif
    assert out.gpano == GPano.full_sphere(96, 48)
    ok(capsys, "rotate", "meta.png", "--yaw", 5, "-o", "out.jpg")
    jpg = read_image("out.jpg")
    assert jpg.icc_profile == icc and b"SpherewarpTestCam" in jpg.exif


def test_grey_and_alpha_images(capsys, workdir, random_image):
    for channels in (1, 2, 4):
        img = random_image(height=H, channels=channels, seed=channels)
        write_image(f"c{channels}.png", img)
        ok(capsys, "rotate", f"c{channels}.png", "--yaw", -90, "-o", f"o{channels}.png")
        out = read_image(f"o{channels}.png").pixels
        np.testing.assert_array_equal(out, np.roll(img, W // 4, axis=1))


# ---------------------------------------------------------------- testpattern, info, demo


def test_testpattern_command(capsys, workdir):
    ok(capsys, "testpattern", "-o", "tp.png", "--size", "256x128")
    img = read_image("tp.png")
    assert img.pixels.shape == (128, 256, 3) and img.pixels.dtype == np.uint8
    np.testing.assert_array_equal(img.pixels, make_test_pattern(256))
    assert img.gpano == GPano.full_sphere(256, 128)
    ok(
        capsys,
        "testpattern",
        "-o",
        "tp16.png",
        "--size",
        "64x32",
        "--dtype",
        "uint16",
        "--chart",
        "FRONT",
        "--no-labels",
    )
    img = read_image("tp16.png").pixels
    np.testing.assert_array_equal(img, make_test_pattern(64, chart="front", dtype=np.uint16))
    ok(capsys, "testpattern", "-o", "tp.exr", "--size", "64x32", "--dtype", "float32")
    assert read_image("tp.exr").pixels.dtype == np.float32


def test_testpattern_default_output_and_overwrite(capsys, workdir):
    ok(capsys, "testpattern", "--size", "64x32")
    assert Path("testpattern.png").is_file()
    code, _, err = run(capsys, "testpattern", "--size", "64x32")
    assert code == 2 and "--overwrite" in err
    ok(capsys, "testpattern", "--size", "64x32", "--overwrite")


def test_info_text_and_json(capsys, workdir):
    src = (make_test_pattern(64, dtype=np.float32, labels=False) * 8).astype(np.float32)
    write_image("a.exr", src)
    text = ok(capsys, "info", "a.exr")
    for needle in ("EXR", "64x32", "float32", "2:1", "equirectangular", "RGB"):
        assert needle in text
    data = json.loads(ok(capsys, "info", "a.exr", "--json"))
    assert data["format"] == "EXR" and data["dtype"] == "float32"
    assert (data["width"], data["height"], data["channels"]) == (64, 32, 3)
    assert data["equirectangular_2to1"] is True
    assert data["value_range"]["R"]["max"] == pytest.approx(float(src[..., 0].max()))
    assert data["gpano"]["projection"] == "equirectangular"


def test_info_gives_a_near_2to1_ratio_the_digits_that_tell_it_from_2(workdir):
    """A 1025x512 log view is not 2:1: its ratio reads 2.002, not '2'."""
    write_image("log.png", np.zeros((512, 1025, 3), np.uint8))
    text = ok(None, "info", "log.png")
    assert "1025x512 (not 2:1 (ratio 2.002); commands need --force)" in text


def test_info_reports_crop_icc_and_non_2to1(capsys, workdir):
    from PIL import ImageCms

    icc = ImageCms.ImageCmsProfile(ImageCms.createProfile("sRGB")).tobytes()
    crop = GPano(
        full_width=200,
        full_height=100,
        cropped_width=200,
        cropped_height=40,
        cropped_left=0,
        cropped_top=30,
    )
    write_image("crop.png", np.full((40, 200, 3), 7, np.uint8), gpano=crop, icc_profile=icc)
    data = json.loads(ok(capsys, "info", "crop.png", "--json"))
    assert data["gpano"]["cropped"] is True
    assert data["gpano"]["full_size"] == [200, 100]
    assert data["gpano"]["cropped_left_top"] == [0, 30]
    assert data["equirectangular_2to1"] is False
    assert data["icc_profile"]["bytes"] == len(icc)
    assert data["value_range"]["G"] == {"min": 7, "max": 7}
    text = ok(capsys, "info", "crop.png")
    assert data["full_sphere_size"] == [200, 100]
    # the commands place the crop on its 2:1 sphere, so they need no --force
    assert "cropped 200x40 at 0,30" in text and "--force" not in text
    assert "200x100 sphere" in text
    assert ok(capsys, "rotate", "crop.png", "--yaw", "10", "-o", "turned.png")


def test_demo_command(capsys, workdir):
    out = ok(capsys, "demo", "d", "--size", "128x64", "--supersample", "1")
    files = sorted(Path("d").glob("*.png"))
    assert len(files) >= 7
    assert out.count("wrote ") == len(files)
    # a second run replaces the demo's own files
    ok(capsys, "demo", "d", "--size", "128x64", "--supersample", "1")
    files[0].write_bytes(b"not the demo's any more")
    code, _, err = run(capsys, "demo", "d", "--size", "128x64")
    assert code == 2 and "--overwrite" in err and err.count("\n") == 1
    ok(capsys, "demo", "d", "--size", "128x64", "--supersample", "1", "--overwrite")


# ---------------------------------------------------------------- the installed script


def _script() -> str:
    found = shutil.which("spherewarp", path=str(Path(sys.executable).parent)) or shutil.which(
        "spherewarp"
    )
    if found is None:
        pytest.skip("the spherewarp console script is not installed")
    return found


def test_console_script_runs(workdir):
    script = _script()
    write_image("in.png", make_test_pattern(W, labels=False))
    done = subprocess.run(
        [script, "rotate", "in.png", "--yaw", "90", "-o", "out.png"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "wrote out.png"
    src = read_image("in.png").pixels
    np.testing.assert_array_equal(read_image("out.png").pixels, np.roll(src, -W // 4, axis=1))


def test_console_script_bad_input_is_one_line(workdir):
    script = _script()
    Path("bad.png").write_bytes(b"\x89PNG\r\n\x1a\n" + b"garbage" * 20)
    done = subprocess.run(
        [script, "zoom", "bad.png", "--at", "0,0", "--factor", "2"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 2
    assert done.stderr.startswith("spherewarp: error:") and done.stderr.count("\n") == 1
    assert "Traceback" not in done.stderr
    assert not Path("bad-zoom.png").exists()


def test_no_arguments_prints_the_help_not_an_error_line(workdir):
    code, out, err = run(None)
    assert code == 2
    assert "spherewarp: error" not in err
    assert "Commands:" in err and err.count("\n") > 10


def test_a_file_system_error_names_the_file_then_says_why():
    from spherewarp.cli import error_line

    line, code = error_line(FileNotFoundError(2, "No such file or directory", "/x/out.mp4.parts"))
    assert (line, code) == ("spherewarp: error: '/x/out.mp4.parts': No such file or directory", 2)


@pytest.mark.parametrize(
    "args",
    [
        ("droste", "{a}", "--center", "0,0", "--inner-radius", "20"),
        ("droste", "{a}", "--center", "0,0", "--inner-radius", "20", "--frames", "2"),
        ("schottky", "{a}", "--generator", "0,0,20 -> 180,0,20"),
        ("schottky", "{a}", "--generator", "0,0,20 -> 180,0,20", "--frames", "2"),
        ("splitscreen", "{a}", "{b}"),
    ],
    ids=lambda a: " ".join(a[:1] + a[-2:]),
)
def test_quiet_prints_only_what_it_wrote(workdir, pattern_png, args):
    """--quiet: 'No progress bar and no notes (the 'wrote …' line stays)': not the Droste
    scale, the Schottky depth nor the split screen's seam."""
    b = write_image(workdir / "b.png", make_test_pattern(W, chart="front", labels=False))
    argv = [str(a).format(a=pattern_png, b=b) for a in args]
    loud = ok(None, *argv, "-o", workdir / "loud.png")
    assert any(not line.startswith("wrote") for line in loud.splitlines()), loud  # a note
    code, out, err = run(None, *argv, "-o", workdir / "quiet.png", "--quiet")
    assert code == 0 and err == "", err
    assert out and all(line.startswith("wrote ") for line in out.splitlines()), out
