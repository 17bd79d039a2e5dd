"""``spherewarp video a.mp4 b.mp4 -o OUT splitscreen`` in segments: ``--jobs``, ``--resume``
after an interrupt, the first clip's frame times and audio (the rest: test_video_effects.py)."""

from __future__ import annotations

import json
import signal
from pathlib import Path

import pytest
from _cli import ok, run
from test_video_segments import digest, packets, stop_midway, times

from videoclip import make_clip

av = pytest.importorskip("av")

SEG = "0.25"  # 6 frames a segment at 24 fps
SPLIT = ("--segment", SEG, "--quiet", "splitscreen", "--seam", "0")


def test_splitscreen_jobs_two_gives_the_same_file_with_the_first_clips_times_and_audio(workdir):
    make_clip(workdir / "a.mp4", frames=20)
    make_clip(workdir / "b.mp4", frames=16)  # shorter: it ends the output
    auto = (*SPLIT[:-1], "auto")  # chosen on the first frames, before any segment
    ok(None, "video", "a.mp4", "b.mp4", "-o", "one.mp4", *auto)
    code, _, err = run(None, "video", "a.mp4", "b.mp4", "-o", "two.mp4", "--jobs", "2", *auto)
    assert code == 0, err
    assert "ends with the shortest, 'b.mp4', after 16 frames" in err
    assert digest("one.mp4") == digest("two.mp4")
    assert not Path("one.mp4.parts").exists() and not Path("two.mp4.parts").exists()
    assert times("one.mp4") == times("a.mp4")[:16]  # the first clip's frame times
    with av.open("one.mp4") as c:  # a keyframe at each segment's start
        keys = [p.is_keyframe for p in c.demux(c.streams.video[0]) if p.size]
    assert keys == [k % 6 == 0 for k in range(16)]
    audio, whole = packets("one.mp4", "audio"), packets("a.mp4", "audio")
    assert 0 < len(audio) < len(whole) and audio == whole[: len(audio)]  # up to its end


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGKILL])
def test_splitscreen_resume_after_a_kill_gives_the_same_file(workdir, sig):
    make_clip(workdir / "a.mp4", frames=48)
    make_clip(workdir / "b.mp4", frames=48)
    args = ("video", "a.mp4", "b.mp4", *SPLIT)
    ok(None, *args, "-o", "whole.mp4")
    done = stop_midway(args, "cut.mp4", sig)  # no output left (SIGINT: says --resume)
    code, _, err = run(None, "video", "a.mp4", "b.mp4", "--resume", "--progress", "json",
                       "--segment", SEG, "splitscreen", "--seam", "0", "-o", "cut.mp4")  # fmt: skip
    assert code == 0, err
    first = json.loads(err.splitlines()[0])
    assert first["frames"] >= 6 * len(done) and first["total"] == 48  # not rendered again
    assert digest("cut.mp4") == digest("whole.mp4")
    assert not Path("cut.mp4.parts").exists()
    assert packets("whole.mp4", "audio") == packets("a.mp4", "audio")


def test_matroska_clips_are_counted_by_their_frames(workdir):
    """An MKV records no frame count (VideoInfo.frames 0): the clips are counted from their
    packets, as a single video is, so one of equal length gives no note and a shorter one
    the right count (it said 'b.mkv' 0 frames, after 0 frames)."""
    from spherewarp.io.multiclip import check_clips

    make_clip(workdir / "a.mp4", frames=12)
    make_clip(workdir / "same.mkv", frames=12)
    make_clip(workdir / "short.mkv", frames=6)
    _, n, note = check_clips([Path("a.mp4"), Path("same.mkv")])
    assert (n, note) == (12, None)
    code, out, err = run(None, "video", "a.mp4", "short.mkv", "-o", "o.mp4", *SPLIT)
    assert code == 0 and out == "wrote o.mp4 (6 frames)\n", err
    said = [line for line in err.splitlines() if "compiling kernels" not in line]
    assert said == [
        "spherewarp: note: the clips differ in length ('a.mp4' 12, 'short.mkv' 6 frames): "
        "the output ends with the shortest, 'short.mkv', after 6 frames"
    ]
