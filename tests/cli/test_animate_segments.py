"""``spherewarp animate R.json STILL -o OUT.mp4`` in segments: ``--jobs``, resume after SIGINT
or SIGKILL, refused options (``--dask``: test_dask.py). Fresh processes, as users run it."""

from __future__ import annotations

import json
import signal
from pathlib import Path

import pytest
from _cli import fails, ok, run
from test_video_segments import digest, frames, psnr, stop_midway

from spherewarp.io import read_image, write_image
from videoclip import ffprobe_side_data, panorama

av = pytest.importorskip("av")

SEG = "0.25"  # 6 frames a segment at 24 fps: 8 segments
SPIN = {
    "duration": 2,
    "loop": True,
    "steps": [{"rotate": {"yaw": {"keyframes": [[0, 0], [2, 360]]}}}],
}


@pytest.fixture
def spin(workdir):
    write_image(workdir / "pano.png", panorama())
    (workdir / "spin.json").write_text(json.dumps({"spherewarp": 1, **SPIN}))
    return ("spin.json", "pano.png", "--fps", "24")


def keyframes(path):
    with av.open(str(path)) as c:
        return [p.is_keyframe for p in c.demux(c.streams.video[0]) if p.size]


def test_animate_in_segments_jobs_two_gives_the_same_file(spin):
    ok(None, "animate", *spin, "-o", "one.mp4", "--segment", SEG, "-q")
    ok(None, "animate", *spin, "-o", "two.mp4", "--segment", SEG, "--jobs", "2", "-q")
    assert digest("one.mp4") == digest("two.mp4")
    assert not Path("one.mp4.parts").exists()
    assert keyframes("one.mp4") == [k % 6 == 0 for k in range(48)]  # one at each segment
    with av.open("one.mp4") as c:
        v = c.streams.video[0]
        pts = sorted(float(p.pts * p.time_base) for p in c.demux(v) if p.size)
        assert v.average_rate == 24
    assert pts == pytest.approx([k / 24 for k in range(48)])  # frame k at k / fps
    sides = ffprobe_side_data(Path("one.mp4"))  # an independent parser reads the 360° metadata
    assert sides["Spherical Mapping"]["projection"] == "equirectangular"
    ok(None, "render", "spin.json", "pano.png", "--time", "0.5", "-o", "t.png", "-q")
    got = frames("one.mp4")
    assert psnr(got[12], read_image("t.png").pixels[..., :3]) >= 35  # frame 12: t = 0.5 s


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGKILL])
def test_animate_resume_after_a_kill_gives_the_same_file(spin, sig):
    ok(None, "animate", *spin, "-o", "whole.mp4", "--segment", SEG, "-q")
    done = stop_midway(("animate", *spin, "--segment", SEG, "-q"), "cut.mp4", sig)
    code, _, err = run(None, "animate", *spin, "-o", "cut.mp4", "--segment", SEG, "--resume",
                       "--progress", "json")  # fmt: skip
    assert code == 0, err
    first = json.loads(err.splitlines()[0])
    assert first["frames"] >= 6 * len(done) and first["total"] == 48  # not rendered again
    assert digest("cut.mp4") == digest("whole.mp4")
    assert not Path("cut.mp4.parts").exists()


def test_animate_segment_options_need_a_video_output(spin):
    err = fails(None, "animate", *spin, "-o", "f.png", "--jobs", "2")
    assert "--jobs" in err and "video output" in err
    assert not list(Path().glob("f_*.png"))
    err = fails(None, "animate", *spin, "-o", "v.mp4", "--crf", "99")
    assert "--crf" in err and not Path("v.mp4").exists()
    err = fails(None, "animate", *spin, "-o", "v.mp4", "--preset", "no-such-preset")
    assert "--preset" in err and not Path("v.mp4").exists() and not Path("v.mp4.parts").exists()


@pytest.mark.parametrize("value", ["nan", "inf"])
def test_a_segment_length_that_is_not_finite_is_refused(spin, value):
    err = fails(None, "animate", *spin, "-o", "n.mp4", "--segment", value, "-q")
    assert "'--segment'" in err and "finite" in err and value in err, err
    assert not Path("n.mp4").exists() and not Path("n.mp4.parts").exists()


def test_animate_at_an_ntsc_rate_keeps_frame_k_at_k_over_fps(workdir):
    """At 29.97 fps a segment of 0.2 s (6 frames) starts at 0.2002 s, no whole millisecond: the
    part's MP4 file holds its start in milliseconds, and the join copied the rounded times."""
    from fractions import Fraction

    write_image(workdir / "pano.png", panorama())
    (workdir / "spin.json").write_text(json.dumps({"spherewarp": 1, **SPIN, "duration": 0.4}))
    ok(None, "animate", "spin.json", "pano.png", "--fps", "29.97", "-o", "n.mp4",
       "--segment", "0.2", "-q")  # fmt: skip
    with av.open("n.mp4") as c:
        got = sorted(Fraction(p.pts) * p.time_base for p in c.demux(c.streams.video[0]) if p.size)
    assert got == [Fraction(1001 * k, 30000) for k in range(12)]
