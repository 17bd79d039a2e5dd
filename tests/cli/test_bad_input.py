"""Bad input on the command line: one line on stderr, a non-zero exit, nothing lost.

Every case checks that the error is a single ``spherewarp: error: ...`` line
with no traceback, that no output (and no temporary file) is left behind and
that the input file's bytes are unchanged.
"""

from __future__ import annotations

import hashlib
import struct
import zlib
from pathlib import Path

import numpy as np
import pytest
from _cli import run

import spherewarp.render
from spherewarp.cli import main
from spherewarp.io import read_image, write_image
from spherewarp.testpattern import make_test_pattern as make_pattern

W, H = 128, 64


def run_in_process(capsys: pytest.CaptureFixture[str], *args: object) -> tuple[int, str, str]:
    """Run the CLI inside this process (for the tests that patch it to fail)."""
    try:
        main([str(a) for a in args])
        code = 0
    except SystemExit as exc:
        code = exc.code if isinstance(exc.code, int) else 1
    out, err = capsys.readouterr()
    return code, out, err


def digest(path: Path) -> str:
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


@pytest.fixture
def good_png(workdir: Path) -> Path:
    return write_image(workdir / "in.png", make_pattern(W, labels=False))


def fails(
    capsys: pytest.CaptureFixture[str],
    workdir: Path,
    *args: object,
    code: int = 2,
    needles: tuple[str, ...] = (),
    in_process: bool = False,
) -> str:
    """Run a command that must fail cleanly (in a fresh process); return its error line."""
    before = {p.name: digest(p) for p in workdir.iterdir() if p.is_file()}
    status, out, err = (run_in_process if in_process else run)(capsys, *args)
    assert status == code, (status, out, err)
    assert err.count("\n") == 1 and err.endswith("\n"), err
    assert err.startswith("spherewarp: "), err
    assert "Traceback" not in err and "internal error" not in err, err
    after = {p.name: digest(p) for p in workdir.iterdir() if p.is_file()}
    assert after == before, "files were created, removed or changed"
    for needle in needles:
        assert needle.lower() in err.lower(), (needle, err)
    return err


# ---------------------------------------------------------------- the input file


def test_non_2to1_image_refused_then_forced(capsys, workdir):
    write_image("wide.png", np.zeros((50, 120, 3), np.uint8))
    fails(
        capsys,
        workdir,
        "rotate",
        "wide.png",
        "--yaw",
        10,
        "-o",
        "out.png",
        needles=("2 x height", "120x50", "--force"),
    )
    code, out, err = run(capsys, "rotate", "wide.png", "--yaw", 10, "-o", "out.png", "--force")
    assert code == 0, err
    assert read_image("out.png").pixels.shape == (50, 120, 3)


def test_missing_file(capsys, workdir):
    fails(
        capsys,
        workdir,
        "zoom",
        "nope.png",
        "--at",
        "0,0",
        "--factor",
        2,
        needles=("nope.png", "no such file"),
    )


def test_directory_as_input(capsys, workdir):
    Path("adir").mkdir()
    fails(capsys, workdir, "info", "adir", needles=("directory",))


def test_info_words_a_directory_as_the_other_commands_do(capsys, workdir):
    Path("somedir.png").mkdir()
    said = [fails(capsys, workdir, *args) for args in (["info", "somedir.png"],
            ["rotate", "somedir.png", "--yaw", "3"])]  # fmt: skip
    assert said[0] == said[1] == (
        "spherewarp: error: cannot read 'somedir.png': is a directory, expected an image file\n"
    )


@pytest.mark.parametrize("command", [["rotate", "--yaw", "10"], ["info"]])
def test_not_an_image(capsys, workdir, command):
    Path("notes.png").write_text("this is not a picture\n" * 10)
    fails(capsys, workdir, command[0], "notes.png", *command[1:], needles=("notes.png",))


def test_corrupt_png(capsys, workdir, good_png):
    data = good_png.read_bytes()
    Path("cut.png").write_bytes(data[: len(data) // 2])  # truncated
    fails(capsys, workdir, "rotate", "cut.png", "--yaw", 10, needles=("cut.png",))
    Path("junk.png").write_bytes(b"\x89PNG\r\n\x1a\n" + bytes(range(256)) * 4)
    fails(capsys, workdir, "mobius", "junk.png", "--matrix", "1,1,0,1", needles=("junk.png",))


def _png_header_only(width: int, height: int) -> bytes:
    def chunk(kind: bytes, payload: bytes) -> bytes:
        body = kind + payload
        return struct.pack(">I", len(payload)) + body + struct.pack(">I", zlib.crc32(body))

    ihdr = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    idat = zlib.compress(b"\x00" * 64)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", idat) + chunk(b"IEND", b"")


@pytest.mark.parametrize("command", [["zoom", "--at", "0,0", "--factor", "2"], ["info"]])
def test_decompression_bomb(capsys, workdir, command):
    Path("bomb.png").write_bytes(_png_header_only(200_000, 100_000))
    fails(
        capsys,
        workdir,
        command[0],
        "bomb.png",
        *command[1:],
        needles=("bomb.png", "decompression bomb"),
    )


# ---------------------------------------------------------------- option values


@pytest.mark.parametrize(
    "args, needles",
    [
        (["mobius", "--matrix", "1,2,2,4"], ("singular",)),
        (["mobius", "--matrix", "0,0,0,0"], ("--matrix",)),
        (["mobius", "--matrix", "1,nan,0,1"], ("finite", "b = 'nan'")),
        (["mobius", "--matrix", "1,0,inf,1"], ("finite",)),
        (["mobius", "--matrix", "1,0,1"], ("four",)),
        (["mobius", "--matrix", "1,zz,0,1"], ("complex",)),
        (
            ["mobius", "--from", "0,0", "0,0", "0,90", "--to", "0,0", "60,0", "0,60"],
            ("--from", "distinct"),
        ),
        (
            ["mobius", "--from", "0,0", "90,0", "0,90", "--to", "0,0", "60,0", "360,0"],
            ("--to", "distinct"),
        ),
        (["mobius", "--from", "0,0", "90,0", "0,90"], ("--to",)),
        (
            [
                "mobius",
                "--matrix",
                "1,0,0,1",
                "--from",
                "0,0",
                "90,0",
                "0,90",
                "--to",
                "0,0",
                "60,0",
                "0,60",
            ],
            ("not both",),
        ),
        (["mobius"], ("--matrix",)),
        (["rotate", "--yaw", "10", "--interp", "lanczos"], ("bilinear", "bicubic", "nearest")),
        (["rotate", "--yaw", "10", "--supersample", "0"], ("--supersample",)),
        (["rotate", "--yaw", "10", "--size", "big"], ("WxH",)),
        (["rotate", "--yaw", "nan"], ("finite",)),
        (["rotate", "--yaw", "ten"], ("--yaw",)),
        (["rotate"], ("--yaw",)),
        (["rotate", "--yaw", "10", "--axis", "0,0", "--angle", "5"], ("not both",)),
        (["rotate", "--axis", "0,0"], ("--angle",)),
        (["rotate", "--angle", "5"], ("--axis",)),
        (["rotate", "--axis", "abc", "--angle", "5"], ("LON,LAT",)),
        (["rotate", "--axis", "1,2,3", "--angle", "5"], ("LON,LAT",)),
        (["rotate", "--axis", "10", "--angle", "5"], ("LON,LAT",)),
        (["zoom", "--at", "0,91", "--factor", "2"], ("latitude",)),
        (["zoom", "--at", "0,-90.5", "--factor", "2"], ("latitude",)),
        (["zoom", "--at", "0,0", "--factor", "0"], ("1e-09 to 1e+09",)),
        (["zoom", "--at", "0,0", "--factor", "-2"], ("1e-09 to 1e+09",)),
        (["zoom", "--at", "0,0", "--factor", "nan"], ("1e-09 to 1e+09",)),
        (["zoom", "--at", "0,0"], ("--factor",)),
        (["zoom", "--factor", "2"], ("--at",)),
        (["zoom", "--at", "0,0", "--at-pixel", "3,3", "--factor", "2"], ("exactly one",)),
        (["zoom", "--at-pixel", "10,65", "--factor", "2"], ("inside",)),
        (["zoom", "--at-pixel", "10", "--factor", "2"], ("X,Y",)),
        (["rotate", "--yaw", "10", "-o", "out.bmp"], (".bmp", ".png")),
        (["rotate", "--yaw", "10", "-o", "nodir/out.png"], ("nodir",)),
        (["rotate", "--yaw", "10", "-o", "out.jpg", "--quality", "0"], ("--quality",)),
        (["rotate", "--bogus"], ("--bogus",)),
    ],
)
def test_bad_option_values(capsys, workdir, good_png, args, needles):
    fails(capsys, workdir, args[0], good_png, *args[1:], needles=needles)


def test_unknown_command(capsys, workdir):
    fails(capsys, workdir, "rotat", needles=("rotat",))


@pytest.mark.parametrize(
    "args",
    [
        ["--chart", "north"],
        ["--dtype", "float64"],
        ["--size", "4x2"],
        ["-o", "p.jpg", "--dtype", "uint16"],
        ["-o", "p.png", "--dtype", "float32"],
    ],
)
def test_bad_testpattern_values(capsys, workdir, args):
    err = fails(capsys, workdir, "testpattern", *args)
    if "--chart" in args:
        assert "zenith" in err and "front" in err


# ---------------------------------------------------------------- outputs


@pytest.mark.parametrize("spelling", ["in.png", "./in.png", "{abs}", "sub/../in.png"])
def test_output_equal_to_input(capsys, workdir, good_png, spelling):
    Path("sub").mkdir()
    out = spelling.format(abs=good_png.resolve())
    fails(
        capsys,
        workdir,
        "rotate",
        good_png,
        "--yaw",
        10,
        "-o",
        out,
        "--overwrite",
        needles=("is the input",),
    )


def test_output_hard_link_to_input(capsys, workdir, good_png):
    import os

    os.link(good_png, "alias.png")
    fails(
        capsys,
        workdir,
        "rotate",
        good_png,
        "--yaw",
        10,
        "-o",
        "alias.png",
        "--overwrite",
        needles=("is the input",),
    )


@pytest.mark.parametrize(
    "command",
    [
        ["rotate", "--yaw", "10"],
        ["zoom", "--at", "0,0", "--factor", "2"],
        ["mobius", "--matrix", "1,1,0,1"],
    ],
)
def test_existing_output_without_overwrite(capsys, workdir, good_png, command):
    Path("out.png").write_bytes(b"precious")
    fails(
        capsys,
        workdir,
        command[0],
        good_png,
        *command[1:],
        "-o",
        "out.png",
        needles=("out.png", "--overwrite"),
    )
    assert Path("out.png").read_bytes() == b"precious"


def test_existing_default_output(capsys, workdir, good_png):
    Path("in-zoom.png").write_bytes(b"precious")
    fails(capsys, workdir, "zoom", good_png, "--at", "0,0", "--factor", 2, needles=("in-zoom.png",))


def test_demo_into_a_file(capsys, workdir):
    Path("afile").write_text("x")
    fails(capsys, workdir, "demo", "afile", "--size", "64x32")


def test_demo_size_too_small_names_the_option(capsys, workdir):
    fails(capsys, workdir, "demo", "d", "--size", "10x3", needles=("'--size'", "8x4"))
    assert not Path("d").exists()


@pytest.mark.parametrize(
    ("text", "needle"),
    [("x", "not JSON"), ('{"spherewarp": 1, "steps": [{"zoom": {"factor": -1}}]}', "factor")],
)
def test_a_bad_recipe_file_is_named(capsys, workdir, good_png, text, needle):
    """Its error names the file (a recipe need not be called *.json), then what is wrong."""
    Path("some.png").write_text(text)
    for args in (["render", "some.png", good_png, "-o", "r.png"],
                 ["video", good_png, "-o", "v.png", "recipe", "some.png"]):  # fmt: skip
        fails(capsys, workdir, *args, needles=("recipe 'some.png': ", needle))


def test_format_without_the_dtype_is_converted(capsys, workdir):
    # once refused after the render; now tone-mapped (tests/cli/test_output_formats.py)
    write_image("hdr.exr", np.full((H, W, 3), 3.5, np.float32))
    status, out, err = run(capsys, "rotate", "hdr.exr", "--yaw", 10, "-o", "out.png")
    assert status == 0 and "tone-mapped" in err, err


# ---------------------------------------------------------------- interruption


def test_interrupted_render_leaves_nothing(capsys, workdir, good_png, monkeypatch):
    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(spherewarp.render, "warp", interrupted)
    err = fails(
        capsys, workdir, "rotate", good_png, "--yaw", 10, "-o", "out.png", code=130, in_process=True
    )
    assert "interrupted" in err


def test_interrupted_write_leaves_no_temp_file(capsys, workdir, good_png, monkeypatch):
    import spherewarp.io.atomic as atomic

    def interrupted(path):
        assert Path(path).exists()  # the temporary file exists at this point
        raise KeyboardInterrupt

    monkeypatch.setattr(atomic, "_fsync", interrupted)
    err = fails(
        capsys,
        workdir,
        *("zoom", good_png, "--at", "0,0", "--factor", 2, "-o", "o.png"),
        code=130,
        in_process=True,
    )
    assert "interrupted" in err
    assert sorted(p.name for p in workdir.iterdir()) == ["in.png"]


def _limited(size: int):
    """A preexec_fn: files of at most ``size`` bytes (a write past it fails with EFBIG, as a
    full disk's does with ENOSPC; Python ignores SIGXFSZ)."""
    import resource

    return lambda: resource.setrlimit(resource.RLIMIT_FSIZE, (size, size))


def test_a_write_that_fails_names_the_output_not_a_temporary_file(workdir, good_png):
    """A still, a segmented video and the demo that cannot be written (here: too large,
    as on a full disk) name what the user named; the demo leaves no empty folder."""
    import json

    from _cli import run_cli

    r = workdir / "loop.json"
    steps = [{"zoom": {"at": [0, 0], "factor": {"keyframes": [[0, 1], [1, 3]]}}}]
    r.write_text(json.dumps({"spherewarp": 1, "duration": 1, "steps": steps}))
    cases = [
        (["rotate", good_png, "--yaw", "3", "-o", "out.exr"], "cannot write 'out.exr'"),
        (["animate", r, good_png, "--fps", "12", "-o", "loop.mp4"], "/loop.mp4': File too"),
        (["demo", "demo", "--size", "64x32"], "demo"),
    ]
    for args, needle in cases:
        code, out, err = run_cli(*args, preexec_fn=_limited(1000))
        said = [ln for ln in err.splitlines() if not ln.startswith("spherewarp: note: ")]
        assert code == 2 and len(said) == 1 and needle in said[0], err  # notes aside (EXR)
        assert ".tmp" not in err and "spherewarp-" not in err and ".parts/" not in err, err
    code, _, err = run_cli(*cases[1][0], preexec_fn=_limited(1000))
    assert "rerun with --resume to continue from '" in err and "/loop.mp4.parts'" in err, err
    assert not Path("demo").exists()
    assert not list(Path().glob(".*spherewarp-*"))
