"""``spherewarp power``, ``exp``, ``map`` and ``splitscreen`` against the Python API."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from _cli import fails, ok, run  # noqa: F401

from spherewarp.cli import COMMANDS
from spherewarp.effects.splitscreen import splitscreen
from spherewarp.io import read_image, write_image
from spherewarp.maps import ExpMap, ExpressionMap, Mobius, Power
from spherewarp.render import warp

H, W = 32, 64


@pytest.fixture
def image() -> np.ndarray:
    return np.random.default_rng(3).integers(0, 256, (H, W, 3), dtype=np.uint8)


@pytest.fixture
def png(workdir: Path, image: np.ndarray) -> Path:
    return write_image(workdir / "in.png", image)


@pytest.fixture
def png2(workdir: Path) -> Path:
    other = np.random.default_rng(4).integers(0, 256, (H // 2, W // 2, 3), dtype=np.uint8)
    return write_image(workdir / "other.png", other)


def test_commands_are_registered():
    for name in ("power", "exp", "map", "splitscreen"):
        assert COMMANDS[name].startswith("branched_cmds:")


@pytest.mark.parametrize("command", ["power", "exp", "map", "splitscreen"])
def test_help_has_an_example(capsys, command):
    out = ok(capsys, command, "--help")
    assert f"spherewarp {command} " in out.split("Example", 1)[1]
    for option in ("--output", "--overwrite", "--size", "--supersample", "--look-at"):
        assert option in out


def test_power(capsys, workdir, png, image):
    out = ok(capsys, "power", png, "--n", "3", "-o", "p.png")
    assert "wrote" in out
    assert np.array_equal(read_image(workdir / "p.png").pixels, warp(image, Power(3)))
    ok(capsys, "power", png, "-o", "default.png")  # --n 2
    assert np.array_equal(read_image(workdir / "default.png").pixels, warp(image, Power(2)))


def test_power_options(capsys, workdir, png, image):
    ok(capsys, "power", png, "--n", "1/2", "--cut", "0", "--branch", "1", "-o", "r.png")
    expected = warp(image, Power(0.5, cut=0.0, branch=1))
    assert np.array_equal(read_image(workdir / "r.png").pixels, expected)
    ok(
        capsys,
        *("power", png, "--n", "2", "--branch-points", "0,0", "180,0"),
        *("--look-at", "0,90", "-o", "b.png"),
    )
    pull = Power(2, branch_points=((0, 0), (180, 0))) @ Mobius.from_yaw_pitch_roll(0, 90)
    assert np.array_equal(read_image(workdir / "b.png").pixels, warp(image, pull))


def test_exp_supersamples_by_default(capsys, workdir, png, image):
    ok(capsys, "exp", png, "--lam", "3", "-o", "e.png")
    expected = warp(image, ExpMap(3), supersample=3)
    assert np.array_equal(read_image(workdir / "e.png").pixels, expected)
    ok(capsys, "exp", png, "--supersample", "1", "-o", "e1.png")
    assert np.array_equal(read_image(workdir / "e1.png").pixels, warp(image, ExpMap(4)))
    # --antialias chooses the filter too: the default supersampling must not hide it
    ok(capsys, "exp", png, "--antialias", "none", "-o", "e2.png")
    expected = warp(image, ExpMap(4), antialias="none")
    assert np.array_equal(read_image(workdir / "e2.png").pixels, expected)
    assert not np.array_equal(expected, warp(image, ExpMap(4), supersample=3))


def test_map(capsys, workdir, png, image):
    ok(capsys, "map", png, "--expr", "z**2", "-o", "m.png")
    assert np.array_equal(read_image(workdir / "m.png").pixels, warp(image, ExpressionMap("z**2")))
    ok(capsys, "map", png, "--expr", "(z-1)/(z+1)", "--chart", "FRONT", "-o", "f.png")
    expected = warp(image, ExpressionMap("(z-1)/(z+1)", chart="front"))
    assert np.array_equal(read_image(workdir / "f.png").pixels, expected)


def test_splitscreen(capsys, workdir, png, png2, image):
    out = ok(capsys, "splitscreen", png, png2, "--seam", "30", "--feather", "20", "-o", "s.png")
    other = read_image(png2).pixels
    expected = splitscreen([image, other], seam=30.0, feather_deg=20.0)
    assert np.array_equal(read_image(workdir / "s.png").pixels, expected)
    assert "wrote" in out
    out = ok(capsys, "splitscreen", png, png, "-o", "same.png")
    assert "seam: input meridian at longitude" in out
    same = read_image(workdir / "same.png").pixels.astype(int)
    # split-screen renders through its own cover, warp(Power) through the compiled path
    assert np.abs(same - warp(image, Power(2))).max() <= 1
    ok(capsys, "splitscreen", png, png2, "--cover", "exp", "--seam", "0", "-o", "x.png")
    expected = splitscreen([image, other], cover="exp", seam=0.0, supersample=3)
    assert np.array_equal(read_image(workdir / "x.png").pixels, expected)
    args = ("--n", "4", "--seam", "0", "--size", "32x16", "-o", "n.png")
    ok(capsys, "splitscreen", png, png2, *args)
    assert read_image(workdir / "n.png").pixels.shape == (16, 32, 3)


@pytest.mark.parametrize(
    "args, message",
    [
        (("power", "{in}", "--n", "0"), "non-zero exponent"),
        (("power", "{in}", "--n", "x"), "exponent"),
        (("power", "{in}", "--branch-points", "0,0", "0,0"), "different"),
        (("exp", "{in}", "--lam", "-1"), "> 0"),
        (("map", "{in}", "--expr", "__import__('os')"), "unknown function '__import__'"),
        (("map", "{in}", "--expr", "z.real"), "column 2"),
        (("map", "{in}", "--expr", "z", "--chart", "back"), "chart"),
        (("splitscreen", "{in}"), "at least two inputs"),
        (("splitscreen", "{in}", "{in}", "--seam", "1,2"), "one seam longitude"),
        (("splitscreen", "{in}", "{in}", "--n", "3"), "multiple"),
        (("splitscreen", "{in}", "{in}", "--cover", "exp", "--n", "2"), "power only"),
        (("splitscreen", "{in}", "{in}", "--feather", "200"), "0 to 180"),
        (("splitscreen", "{in}", "missing.png"), "missing.png"),
    ],
)
def test_bad_input_is_one_line(capsys, workdir, png, args, message):
    args = [str(png) if a == "{in}" else a for a in args]
    err = fails(capsys, *args, "-o", "out.png")
    assert message in err
    assert not (workdir / "out.png").exists()


def test_refuses_to_overwrite(capsys, workdir, png):
    ok(capsys, "power", png, "-o", "p.png")
    assert "exists" in fails(capsys, "power", png, "-o", "p.png")
    ok(capsys, "power", png, "-o", "p.png", "--overwrite")
    assert "is the input" in fails(capsys, "splitscreen", png, png, "-o", str(png))
