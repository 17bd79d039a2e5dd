"""rotate, zoom and mobius carry the input's GPano pose when it still holds, else drop it."""

from __future__ import annotations

import numpy as np
import pytest
from _cli import run

from spherewarp.io import GPano, read_image, write_image


@pytest.fixture
def posed(tmp_path, monkeypatch):
    """posed.png (level pose, heading 100) and tilted.png (pitch 3, roll -2), 64x32."""
    monkeypatch.chdir(tmp_path)
    px = np.random.default_rng(0).integers(0, 255, (32, 64, 3), dtype=np.uint8)
    write_image("posed.png", px, gpano=GPano(full_width=64, full_height=32, pose_heading=100.0))
    tilted = GPano(full_width=64, full_height=32, pose_heading=100.0, pose_pitch=3, pose_roll=-2)
    write_image("tilted.png", px, gpano=tilted)
    return tmp_path


def _pose(*args):
    code, out, err = run(None, *args, "-o", "out.png", "--overwrite")
    assert code == 0, err
    g = read_image("out.png").gpano
    return (g.pose_heading, g.pose_pitch, g.pose_roll), err


@pytest.mark.parametrize(
    ("args", "pose"),
    [
        (("rotate", "posed.png", "--yaw", "30"), (130.0, None, None)),
        (("rotate", "posed.png", "--yaw", "-120"), (340.0, None, None)),
        (("zoom", "posed.png", "--at", "10,20", "--factor", "2"), (100.0, None, None)),
        (("zoom", "tilted.png", "--at", "10,20", "--factor", "2"), (100.0, 3.0, -2.0)),
        (("zoom", "posed.png", "--at", "40,0", "--factor", "2", "--center"), (140.0, None, None)),
        # z -> -z: a half turn about the poles
        (("mobius", "posed.png", "--matrix", "1j,0,0,-1j"), (280.0, None, None)),
    ],
)
def test_pose_follows_or_is_kept(posed, args, pose):
    got, err = _pose(*args)
    assert got[0] == pytest.approx(pose[0]) and got[1:] == pose[1:]
    assert err == ""


@pytest.mark.parametrize(
    "args",
    [
        ("rotate", "posed.png", "--yaw", "30", "--pitch", "10"),
        ("rotate", "tilted.png", "--yaw", "30"),
        ("mobius", "posed.png", "--matrix", "1,0.5,0,1"),
    ],
)
def test_pose_dropped_with_a_note_when_it_no_longer_holds(posed, args):
    got, err = _pose(*args)
    assert got == (None, None, None)
    assert err.startswith("note:") and "pose" in err and err.count("\n") == 1
    assert read_image("out.png").gpano.projection_type == "equirectangular"


def test_info_shows_the_pose(posed):
    code, out, err = run(None, "info", "tilted.png")
    assert code == 0, err
    assert "pose heading 100°, pitch 3°, roll -2°" in out


def test_quiet_hides_the_dropped_pose_note(posed):
    """--quiet: no notes (the 'wrote' line stays)."""
    code, out, err = run(None, "rotate", "tilted.png", "--yaw", "30", "-o", "out.png", "--quiet")
    assert code == 0 and err == "" and out == "wrote out.png\n", (out, err)
    assert read_image("out.png").gpano.pose_heading is None
