"""``spherewarp droste``: the command against the Python API, frames, log view, errors."""

from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np
import pytest
from _cli import ok, run  # noqa: F401

from spherewarp.cli.droste_cmds import frame_paths
from spherewarp.effects.droste import (
    droste_image,
    droste_map,
    hole_from_corners,
    hole_from_mask,
    hole_from_radius,
    log_view,
)
from spherewarp.errors import InvalidValueError
from spherewarp.io import read_image, write_image
from spherewarp.maps import TwistedDroste, map_from_json
from spherewarp.render import warp
from spherewarp.testpattern import make_test_pattern

W, H = 128, 64
FRAME = ["-20,20", "20,20", "20,-20", "-20,-20"]
CORNERS = [(-20.0, 20.0), (20.0, 20.0), (20.0, -20.0), (-20.0, -20.0)]


def digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


@pytest.fixture
def pattern(workdir: Path) -> tuple[Path, np.ndarray]:
    pixels = make_test_pattern(W, labels=False)
    return write_image(workdir / "in.png", pixels), pixels


def test_straight_and_twisted_match_the_api(capsys, pattern) -> None:
    path, pixels = pattern
    out = ok(capsys, "droste", path, "-o", "s.png", "--frame", *FRAME, "--scale", "6")
    assert "wrote s.png" in out
    d = droste_map(hole_from_corners(CORNERS), 6.0)
    np.testing.assert_array_equal(read_image("s.png").pixels, warp(pixels, d))
    ok(capsys, "droste", path, "-o", "t.png", "--frame", *FRAME, "--twist", "--strands", "2")
    t = droste_map(hole_from_corners(CORNERS), twist=True, strands=2)
    np.testing.assert_array_equal(read_image("t.png").pixels, warp(pixels, t))
    assert read_image("t.png").gpano is not None


def test_radius_mask_far_phase_and_print(capsys, pattern, workdir) -> None:
    path, pixels = pattern
    ok(capsys, "droste", path, "-o", "r.png", "--center", "10,5", "--inner-radius", "15",
       "--far", "0,-90", "--scale", "4", "--phase", "0.25")  # fmt: skip
    d = droste_map(hole_from_radius((10, 5), 15, far=(0, -90)), 4.0, phase=0.25)
    np.testing.assert_array_equal(read_image("r.png").pixels, warp(pixels, d))
    mask = hole_from_radius((10, 5), 15).mask(256, 128).astype(np.uint8) * 255
    write_image(workdir / "mask.png", mask)
    ok(capsys, "droste", path, "-o", "m.png", "--mask", "mask.png", "--scale", "4")
    dm = droste_map(hole_from_mask(mask), 4.0)
    np.testing.assert_array_equal(read_image("m.png").pixels, warp(pixels, dm))
    text = ok(capsys, "droste", path, "--frame", *FRAME, "--twist", "--print-map")
    m = map_from_json(text)
    assert isinstance(m, TwistedDroste) and not Path("in-droste.png").exists()


def test_frames_make_a_loop(capsys, pattern, workdir) -> None:
    path, pixels = pattern
    out = ok(capsys, "droste", path, "-o", "loop.png", "--frame", *FRAME, "--frames", "3")
    names = [f"loop_{k:04d}.png" for k in range(3)]
    assert all(n in out for n in names)
    d = droste_map(hole_from_corners(CORNERS))
    for k, name in enumerate(names):
        np.testing.assert_array_equal(read_image(name).pixels, warp(pixels, d.with_phase(k / 3)))
    # a pattern into a new directory; existing frames are refused before any work
    ok(capsys, "droste", path, "-o", "seq/f-%03d.png", "--frame", *FRAME, "--frames", "2")
    assert sorted(p.name for p in (workdir / "seq").iterdir()) == ["f-000.png", "f-001.png"]
    before = digest(workdir / "seq" / "f-000.png")
    code, _, err = run(
        capsys, "droste", path, "-o", "seq/f-%03d.png", "--frame", *FRAME, "--frames", "3"
    )
    assert code == 2 and "exists" in err and "--overwrite" in err
    assert not (workdir / "seq" / "f-002.png").exists()
    assert digest(workdir / "seq" / "f-000.png") == before
    assert not [p for p in workdir.rglob("*.tmp*")]


def test_frame_paths() -> None:
    assert frame_paths(Path("a/b.exr"), 2) == [Path("a/b_0000.exr"), Path("a/b_0001.exr")]
    assert frame_paths(Path("x_{:02d}.png"), 2) == [Path("x_00.png"), Path("x_01.png")]
    assert frame_paths(Path("d/%d.png"), 2) == [Path("d/0.png"), Path("d/1.png")]
    with pytest.raises(InvalidValueError, match="frame pattern"):
        frame_paths(Path("x%.0s.png"), 2)
    with pytest.raises(InvalidValueError, match="frame pattern"):
        frame_paths(Path("x%%.png"), 2)


def test_log_view_and_inside_images(capsys, pattern, workdir) -> None:
    path, pixels = pattern
    out = ok(capsys, "droste", path, "-o", "log.png", "--frame", *FRAME, "--view", "log")
    assert "log plane" in out
    view = read_image("log.png")
    d = droste_map(hole_from_corners(CORNERS))
    np.testing.assert_array_equal(view.pixels, log_view(pixels, d))
    assert view.gpano is None  # a flat picture, not a panorama
    ok(capsys, "droste", path, "-o", "lo.png", "--frame", *FRAME, "--twist", "--view",
       "log-output", "--size", "200x80")  # fmt: skip
    assert read_image("lo.png").pixels.shape[0] == 80
    other = np.full_like(pixels, 17)
    write_image(workdir / "other.png", other)
    ok(capsys, "droste", path, "-o", "two.png", "--frame", *FRAME, "--inside", "other.png")
    d2 = droste_map(hole_from_corners(CORNERS), n_images=2)
    np.testing.assert_array_equal(read_image("two.png").pixels, droste_image([pixels, other], d2))


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        ((), "exactly one of --frame, --mask or --inner-radius"),
        (("--frame", *FRAME, "--inner-radius", "10", "--center", "0,0"), "exactly one"),
        (("--inner-radius", "10"), "--inner-radius needs --center"),
        (("--frame", *FRAME, "--scale", "1"), "scale > 1"),
        (("--frame", *FRAME, "--scale", "0.5"), "scale > 1"),
        (("--frame", "-20,20", "20,-20", "20,20", "-20,-20"), "not in order"),
        (("--frame", *FRAME, "--center", "90,0"), "inside no frame"),
        (("--frame", *FRAME, "--strands", "2"), "go with --twist"),
        (("--frame", *FRAME, "--twist", "--strands", "2", "--periodicity", "2"), "common factor"),
        (("--frame", *FRAME, "--frames", "2", "--view", "log"), "--frames"),
        (("--frame", *FRAME, "--inside", "in.png", "--twist"), "divide the strands"),
        (("--center", "0,0", "--inner-radius", "200"), "radius"),
        (("--center", "0,0", "--inner-radius", "200"), "--inner-radius: expected an angular"),
        (("--center", "0,0", "--inner-radius", "0"), "--inner-radius: expected an angular"),
        (("--frame", *FRAME, "-o", "out.xyz"), "extension"),
        (("--frame", *FRAME, "--view", "log", "--size", "100x1"), "--size: a Droste log view"),
    ],
)
def test_bad_input_is_one_line(capsys, pattern, workdir, args, needle) -> None:
    path, _ = pattern
    before = sorted(p.name for p in workdir.iterdir())
    code, out, err = run(capsys, "droste", path, *args)
    assert code == 2, err
    assert err.startswith("spherewarp: error:") and err.count("\n") == 1, err
    assert needle in err
    assert "Traceback" not in err
    assert sorted(p.name for p in workdir.iterdir()) == before
