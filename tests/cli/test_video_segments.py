"""``spherewarp video`` in segments: resume after SIGINT or SIGKILL, a refused manifest,
``--progress json``, ``--jobs`` (``--dask``: test_dask.py)."""

from __future__ import annotations

import hashlib
import json
import os
import signal
import subprocess
import sys
import time
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest
from _cli import fails, ok, run

from videoclip import make_clip

av = pytest.importorskip("av")

SEG = "0.25"  # 6 frames a segment at 24 fps
ROTATE = ("rotate", "--yaw", "30")


@pytest.fixture
def clip(workdir):
    return make_clip(workdir / "in.mp4", frames=48)


def digest(path) -> str:
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def packets(path, kind):
    with av.open(str(path)) as c:
        streams = getattr(c.streams, kind)
        return [(p.pts, p.dts, bytes(p)) for p in c.demux(streams[0]) if p.size]


def times(path):
    return sorted(p[0] for p in packets(path, "video"))


def frames(path):
    with av.open(str(path)) as c:
        return [f.to_ndarray(format="rgb24") for f in c.decode(video=0)]


def psnr(a, b):
    mse = np.mean((a.astype(np.float64) - b) ** 2)
    return np.inf if mse == 0 else 10 * np.log10(255.0**2 / mse)


def start(*args, env=None):
    return subprocess.Popen(
        [sys.executable, "-m", "spherewarp", *args], stdout=subprocess.PIPE,
        stderr=subprocess.PIPE, text=True, stdin=subprocess.DEVNULL, env=env,
    )  # fmt: skip


def wait_for_segments(parts: Path, n: int, proc, timeout=300) -> None:
    """Until the manifest in ``parts`` lists ``n`` finished segments."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        try:
            if len(json.loads((parts / "manifest.json").read_text())["done"]) >= n:
                return
        except (OSError, ValueError, KeyError):
            pass
        assert proc.poll() is None, proc.communicate()
        time.sleep(0.05)
    raise AssertionError("no segment finished in time")


def test_segments_keep_times_frames_and_audio(clip):
    ok(None, "video", clip.name, "-o", "seg.mp4", "--segment", SEG, "--quiet", *ROTATE)
    assert not Path("seg.mp4.parts").exists()
    assert times("seg.mp4") == times(clip)  # every frame, at its time
    assert packets("seg.mp4", "audio") == packets(clip, "audio")  # the audio as it was
    keys = [p for p in packets("seg.mp4", "video")]
    with av.open("seg.mp4") as c:
        key = sum(p.is_keyframe for p in c.demux(c.streams.video[0]) if p.size)
    assert key == 8 and len(keys) == 48  # a keyframe at each segment's start
    ok(None, "video", clip.name, "-o", "one.mp4", "--segment", "100", "--quiet", *ROTATE)
    for a, b in zip(frames("seg.mp4"), frames("one.mp4"), strict=True):
        assert psnr(a, b) >= 35  # within codec error (other keyframes)


def stop_midway(args, out: str, sig, after: int = 2, segments: int = 8) -> dict:
    """Start ``spherewarp ARGS -o OUT``, send ``sig`` once ``after`` segments are done, check
    that no output (nor a temporary file) is left and that SIGINT says to resume in one line;
    return the manifest's finished segments."""
    p = start(*args, "-o", out)
    wait_for_segments(Path(f"{out}.parts"), after, p)
    p.send_signal(sig)
    _, err = p.communicate(timeout=60)
    assert not Path(out).exists()  # no output, not even a broken one
    assert not [f for f in os.listdir() if ".spherewarp-" in f]
    if sig == signal.SIGINT:
        assert p.returncode == 130
        assert err.count("\n") == 1 and "--resume" in err, err
    done = json.loads(Path(f"{out}.parts/manifest.json").read_text())["done"]
    assert after <= len(done) < segments
    return done


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGKILL])
def test_resume_after_a_kill_gives_the_same_file(clip, sig):
    ok(None, "video", clip.name, "-o", "whole.mp4", "--segment", SEG, "--quiet", *ROTATE)
    done = stop_midway(("video", clip.name, "--segment", SEG, "--quiet", *ROTATE), "cut.mp4", sig)
    code, _, err = run(None, "video", clip.name, "-o", "cut.mp4", "--segment", SEG, "--resume",
                       "--progress", "json", *ROTATE)  # fmt: skip
    assert code == 0, err
    first = json.loads(err.splitlines()[0])
    assert first["frames"] >= 6 * len(done)  # the finished segments are not rendered again
    assert digest("cut.mp4") == digest("whole.mp4")
    assert not Path("cut.mp4.parts").exists()


def test_resume_refuses_another_render(clip):
    p = start("video", clip.name, "-o", "x.mp4", "--segment", SEG, "--quiet", *ROTATE)
    wait_for_segments(Path("x.mp4.parts"), 1, p)
    p.send_signal(signal.SIGINT)
    p.communicate(timeout=60)
    code, _, err = run(None, "video", clip.name, "-o", "x.mp4", "--segment", SEG, "--resume",
                       "rotate", "--yaw", "31")  # fmt: skip
    assert code == 2 and err.count("\n") == 1, err
    assert "--resume" in err and "other options" in err and "without --resume" in err
    assert not Path("x.mp4").exists()


def test_a_video_into_a_missing_folder_is_refused_as_a_still_is(clip):
    err = fails(None, "video", clip.name, "-o", "no/x.mp4", "--quiet", *ROTATE)
    assert "cannot write 'no/x.mp4': directory 'no' does not exist" in err
    assert not Path("no").exists()


def test_progress_json_lines(clip):
    code, _, err = run(None, "video", clip.name, "-o", "p.mp4", "--segment", SEG,
                       "--progress", "json", *ROTATE)  # fmt: skip
    assert code == 0, err
    lines = [json.loads(line) for line in err.splitlines()]
    assert lines[-1]["frames"] == lines[-1]["total"] == 48 and lines[-1]["eta"] == 0
    assert all(set(x) == {"frames", "total", "fps", "eta"} for x in lines)
    code, _, err = run(None, "video", clip.name, "-o", "q.mp4", "--quiet", *ROTATE)
    assert code == 0 and err == "", err


def test_jobs_two_gives_the_same_file(clip):
    ok(None, "video", clip.name, "-o", "one.mp4", "--segment", SEG, "--quiet", *ROTATE)
    ok(None, "video", clip.name, "-o", "two.mp4", "--segment", SEG, "--jobs", "2", "--quiet",
       *ROTATE)  # fmt: skip
    assert digest("one.mp4") == digest("two.mp4")


def test_ctrl_c_with_jobs_says_one_line(clip):
    p = start("video", clip.name, "-o", "j.mp4", "--segment", SEG, "--jobs", "2", "--quiet",
              *ROTATE)  # fmt: skip
    wait_for_segments(Path("j.mp4.parts"), 1, p)
    p.send_signal(signal.SIGINT)
    _, err = p.communicate(timeout=60)
    assert p.returncode == 130 and err.count("\n") == 1 and "--resume" in err, err
    assert not Path("j.mp4").exists()


def test_dask_without_dask_says_how_to_install(clip, workdir):
    blocker = workdir / "nodask"
    blocker.mkdir()
    for name in ("distributed", "dask"):  # modules that fail to import, ahead of the real ones
        (blocker / f"{name}.py").write_text("raise ImportError('hidden for the test')\n")
    env = {**os.environ, "PYTHONPATH": f"{blocker}{os.pathsep}{os.environ.get('PYTHONPATH', '')}"}
    p = start("video", clip.name, "-o", "d.mp4", "--dask", "tcp://127.0.0.1:1", *ROTATE, env=env)
    _, err = p.communicate(timeout=120)
    assert p.returncode == 2 and err.count("\n") == 1, err
    assert 'pip install "spherewarp[dask]"' in err
    assert not Path("d.mp4").exists()


def test_urls_with_jobs_give_the_local_file(clip, ftp):
    import shutil

    shutil.copy(clip, ftp.root / "url-in.mp4")
    ok(None, "video", clip.name, "-o", "local.mp4", "--segment", SEG, "--quiet", *ROTATE)
    out = f"{ftp.url}/out/url-out.mp4"
    ok(None, "video", f"{ftp.url}/url-in.mp4", "-o", out, "--segment", SEG, "--jobs", "2",
       "--quiet", *ROTATE)  # fmt: skip
    assert digest(ftp.root / "out" / "url-out.mp4") == digest("local.mp4")
    assert sorted(p.name for p in (ftp.root / "out").iterdir()) == ["url-out.mp4"]  # no parts
    err = fails(None, "video", f"{ftp.url}/url-in.mp4", "-o", out, "--quiet", *ROTATE)
    assert "exists; pass --overwrite" in err


def test_a_url_without_fsspec_says_how_to_install(clip, workdir):
    blocker = workdir / "nofsspec"
    blocker.mkdir()
    (blocker / "fsspec.py").write_text("raise ImportError('hidden for the test')\n")
    env = {**os.environ, "PYTHONPATH": f"{blocker}{os.pathsep}{os.environ.get('PYTHONPATH', '')}"}
    for more in ((), ("--dask", "tcp://127.0.0.1:1")):
        p = start("video", "ftp://127.0.0.1:1/in.mp4", "-o", "u.mp4", *more, *ROTATE, env=env)
        _, err = p.communicate(timeout=120)
        assert p.returncode == 2 and err.count("\n") == 1, err
        assert 'pip install "spherewarp[dask]"' in err and "ftp://127.0.0.1:1/in.mp4" in err
        assert not Path("u.mp4").exists()


def test_an_output_url_naming_the_input_url_is_refused():
    url = "ftp://127.0.0.1:1/in.mp4"  # refused before any connection
    err = fails(None, "video", url, "-o", url, "--overwrite", *ROTATE)
    assert "names the input; an input is never overwritten" in err


@pytest.mark.parametrize("value", ["nan", "inf", "-inf"])
def test_a_segment_length_that_is_not_finite_is_refused(clip, value):
    err = fails(None, "video", clip.name, "-o", "n.mp4", "--segment", value, *ROTATE)
    assert "'--segment'" in err and "finite" in err and value in err, err
    assert not Path("n.mp4").exists() and not Path("n.mp4.parts").exists()


@pytest.mark.parametrize(
    "case",
    ["a note", "a note and --resume", "a note beside a manifest", "a junk manifest", "a file"],
)
def test_a_work_folder_spherewarp_did_not_make_is_refused_and_kept(clip, case):
    """OUT.parts/ holding anything spherewarp does not write there is someone else's: refused in
    one line naming it, and left as it was (it used to be removed, whatever it held)."""
    parts = Path("p.mp4.parts")
    if case == "a file":
        parts.write_text("precious\n")
    else:
        parts.mkdir()
        if case == "a junk manifest":
            (parts / "manifest.json").write_text("precious\n")
        else:
            (parts / "notes.txt").write_text("precious\n")
        if case == "a note beside a manifest":
            (parts / "manifest.json").write_text(json.dumps({"spherewarp_segments": 1}))
    before = {p.name: p.read_bytes() for p in parts.iterdir()} if parts.is_dir() else None
    more = ("--resume",) if "resume" in case or "beside" in case else ()
    err = fails(None, "video", clip.name, "-o", "p.mp4", "--segment", SEG, *more, *ROTATE)
    assert "'p.mp4.parts' is not a spherewarp work folder" in err and "-o" in err, err
    assert "remove it, or choose another -o" in err
    if before is None:
        assert parts.read_text() == "precious\n"
    else:
        assert {p.name: p.read_bytes() for p in parts.iterdir()} == before
    assert not Path("p.mp4").exists()


def test_a_work_folder_left_by_an_earlier_render_is_still_replaced(clip):
    parts = Path("w.mp4.parts")
    parts.mkdir()
    (parts / "manifest.json").write_text(json.dumps({"spherewarp_segments": 1, "done": {}}))
    (parts / "seg-00000-0123abcd.mp4").write_bytes(b"old")  # another render's segment
    (parts / ".seg-00001-0123abcd.mp4.spherewarp-99999-0123abcd.tmp.mp4").write_bytes(b"")
    (parts / "..seg-00002-0123abcd.mp4.spherewarp-99999-0123abcd.tmp.mp4.spherewarp-99999-"
     "4567abcd.tmp.mp4").write_bytes(b"")  # a temporary file's own (an atomic writer inside)
    ok(None, "video", clip.name, "-o", "w.mp4", "--segment", SEG, "--quiet", *ROTATE)
    assert not parts.exists() and times("w.mp4") == times(clip)


def test_an_output_under_a_file_names_the_output(clip):
    err = fails(None, "video", clip.name, "-o", f"{clip.name}/x.mp4", *ROTATE)
    assert f"cannot write '{clip.name}/x.mp4': '{clip.name}' is not a directory" in err, err


def test_an_output_in_a_read_only_folder_names_the_output(clip):
    Path("ro").mkdir()
    os.chmod("ro", 0o555)
    try:
        if os.access("ro", os.W_OK):
            pytest.skip("this user writes into a read-only folder (root)")
        err = fails(None, "video", clip.name, "-o", "ro/x.mp4", *ROTATE)
        assert "cannot write 'ro/x.mp4': Permission denied" in err and ".parts" not in err, err
    finally:
        os.chmod("ro", 0o755)


def test_an_mpeg_ts_input_gives_the_frames_of_a_one_piece_render(workdir):
    """MPEG-TS has no index: FFmpeg seeks it by byte position and lands on the packet nearest
    the segment's first frame, a keyframe or not; the decoder then dropped every frame up to
    the next keyframe ("segment 1 gave 0 frames, expected 12": an internal error, and the
    work folder left). Lossless encodes (--crf 0): the frames are compared exactly."""
    make_clip(workdir / "in.ts", frames=48, gop=10)  # keyframes at 0, 10, 20...
    ok(None, "video", "in.ts", "-o", "seg.mp4", "--segment", "0.5", "--crf", "0", "--quiet",
       *ROTATE)  # fmt: skip
    assert not Path("seg.mp4.parts").exists()
    ok(None, "video", "in.ts", "-o", "one.mp4", "--segment", "100", "--crf", "0", "--quiet",
       *ROTATE)  # fmt: skip
    assert exact_times("seg.mp4") == exact_times("one.mp4") == exact_times("in.ts")
    got, whole = frames("seg.mp4"), frames("one.mp4")
    assert len(got) == len(whole) == 48
    for k, (a, b) in enumerate(zip(got, whole, strict=True)):
        assert np.array_equal(a, b), k  # frame for frame


def exact_times(path):
    """The video frames' presentation times in seconds, exactly (Fractions), sorted."""
    with av.open(str(path)) as c:
        return sorted(Fraction(p.pts) * p.time_base for p in c.demux(c.streams.video[0]) if p.size)


def test_a_boundary_at_no_whole_millisecond_keeps_every_frame_time(workdir):
    """Frame 6 of a 30000/1001 fps clip is at 0.2002 s: a part's MP4 file holds its start (its
    edit list) in milliseconds, and the join copied the rounded times (0.2 s, and all of the
    part's frames 0.2 ms early); the output's own edit list rounded a start as well."""
    make_clip(workdir / "ntsc.mp4", frames=12, rate=Fraction(30000, 1001))
    ok(None, "video", "ntsc.mp4", "-o", "out.mp4", "--segment", "0.2", "--quiet", *ROTATE)
    assert exact_times("out.mp4") == exact_times("ntsc.mp4")  # 0.2002 s, not 0.2
    assert packets("out.mp4", "audio") == packets("ntsc.mp4", "audio")
    make_clip(workdir / "late.ts", frames=12, gop=4)  # MPEG-TS: the first frame at 1/12 s
    ok(None, "video", "late.ts", "-o", "late.mp4", "--segment", "0.2", "--quiet", *ROTATE)
    assert exact_times("late.mp4") == exact_times("late.ts")


def test_a_variable_frame_rate_with_a_gap_is_joined_with_its_times(workdir):
    """After a gap, a part's first decode time (its first frame's time less the encoder's
    B-frame delay) came before the previous part's last: the MP4 muxer refused the join
    (an internal 'Invalid argument'). The decode times are made anew across the parts."""
    times = [Fraction(k, 12) + (Fraction(3, 10) if k > 10 else 0) for k in range(24)]
    make_clip(workdir / "vfr.mp4", frames=24, times=times)
    ok(None, "video", "vfr.mp4", "-o", "out.mp4", "--segment", "0.5", "--quiet", *ROTATE)
    assert exact_times("out.mp4") == exact_times("vfr.mp4")  # times to the millisecond
    assert len(times) == 24 and exact_times("vfr.mp4")[11] - exact_times("vfr.mp4")[10] > 0.3
    got = packets("out.mp4", "video")
    assert all(a[1] < b[1] for a, b in zip(got, got[1:], strict=False))  # rising dts
    assert all(dts <= pts for pts, dts, _ in got)


def test_frames_at_one_time_are_refused_in_one_line(workdir):
    """Two frames at one time (a Matroska file keeps milliseconds: frames 0.1 ms apart): x264's
    decode times stopped rising and the part's muxer failed ('Invalid argument', an internal
    error). Refused before any work, naming the input."""
    import shutil

    ffmpeg = shutil.which("ffmpeg")
    if ffmpeg is None:
        pytest.skip("no ffmpeg")
    apart = "setpts='N/12/TB+eq(N,5)*(-1/12+0.0001)/TB'"  # frame 5 0.1 ms after frame 4
    subprocess.run([ffmpeg, "-v", "error", "-f", "lavfi", "-i", "testsrc=size=128x64:rate=12",
                    "-t", "1", "-vf", apart, "-fps_mode", "passthrough", "-bf", "0",
                    "-pix_fmt", "yuv420p", "-c:v", "libx264", "dup.mkv"], check=True)  # fmt: skip
    err = fails(None, "video", "dup.mkv", "-o", "out.mp4", "--segment", SEG, *ROTATE)
    assert "'dup.mkv' has two frames at one time" in err and "frames 4 and 5" in err, err
    assert not Path("out.mp4").exists() and not Path("out.mp4.parts").exists()


@pytest.mark.skipif(not hasattr(signal, "SIGHUP"), reason="no SIGHUP on this platform")
@pytest.mark.parametrize("jobs", ["1", "2"])
def test_a_hang_up_is_handled_as_a_termination_and_resume_works(clip, jobs):
    """SIGHUP (the terminal closed, an ssh session lost) killed the process at once: exit 129
    with no message and a hidden .seg-...tmp.mp4 left in OUT.parts/. It unwinds as SIGTERM
    does: one line, exit 129, no output and no temporary file; --resume then gives the file
    of an uninterrupted render."""
    args = ("video", clip.name, "--segment", SEG, "--jobs", jobs, "--quiet")
    ok(None, *args, *ROTATE, "-o", "whole.mp4")
    p = start(*args, *ROTATE, "-o", "cut.mp4")
    wait_for_segments(Path("cut.mp4.parts"), 1, p)
    p.send_signal(signal.SIGHUP)
    _, err = p.communicate(timeout=60)
    assert p.returncode == 129, (p.returncode, err)
    assert err.startswith("spherewarp: hung up") and err.count("\n") == 1, err
    assert "--resume" in err and "Traceback" not in err
    assert not Path("cut.mp4").exists()
    assert [f.name for f in Path("cut.mp4.parts").iterdir() if ".tmp" in f.name] == []
    assert not [f for f in os.listdir() if ".spherewarp-" in f]
    ok(None, *args, "--resume", *ROTATE, "-o", "cut.mp4")
    assert digest("cut.mp4") == digest("whole.mp4")


def has_encoder(name: str) -> bool:
    from spherewarp.io.video import video_encoders

    return name in video_encoders()


@pytest.mark.skipif(not has_encoder("libsvtav1"), reason="no libsvtav1 in this build")
@pytest.mark.parametrize("suffix", [".mkv", ".mp4", ".webm"])
def test_svt_av1_parts_are_joined_and_quiet_says_nothing(workdir, suffix):
    """The join added the output's stream by the part's decoder's name as an encoder's
    (libdav1d: an internal 'UnknownCodecError' after the whole render), and SVT-AV1 printed
    its 20-line banner through --quiet."""
    make_clip(workdir / "in.mp4", frames=12, audio=False)
    code, out, err = run(None, "video", "in.mp4", "-o", f"av1{suffix}", "--segment", SEG,
                         "--codec", "libsvtav1", "--quiet", *ROTATE)  # fmt: skip
    assert code == 0 and err == "", err
    assert out.startswith(f"wrote av1{suffix}")
    ms = [round(float(t), 3) for t in exact_times("in.mp4")]  # Matroska keeps milliseconds
    assert [round(float(t), 3) for t in exact_times(f"av1{suffix}")] == ms  # every frame
    with av.open(f"av1{suffix}") as c:
        assert c.streams.video[0].codec_context.codec.canonical_name == "av1"
    assert not Path(f"av1{suffix}.parts").exists()


def ms_times(path):
    """The video frames' presentation times, in whole milliseconds (Matroska's)."""
    return [round(float(t), 3) for t in exact_times(path)]


@pytest.mark.parametrize(
    "out, codec", [("r.mkv", "rawvideo"), ("q.mov", "qtrle"), ("v.webm", "libvpx")]
)
def test_parts_are_written_in_a_container_of_the_outputs_kind(workdir, out, codec):
    """The parts were MP4 files whatever the output: rawvideo into .mkv, qtrle into .mov and
    VP8 into .webm (as the WebM refusal recommends) failed with an internal error after the
    first segment, and left OUT.parts/. The joined file keeps every frame at its time."""
    make_clip(workdir / "in.mp4", frames=12, audio=False)
    ok(None, "video", "in.mp4", "-o", out, "--segment", SEG, "--codec", codec, "--quiet",
       *ROTATE)  # fmt: skip
    assert not Path(f"{out}.parts").exists()
    with av.open(out) as c:
        assert c.streams.video[0].codec_context.name in (codec, "vp8")
    if out.endswith(".mov"):
        assert exact_times(out) == exact_times("in.mp4")
    else:
        assert ms_times(out) == ms_times("in.mp4")
    assert len(frames(out)) == 12


def test_resume_of_a_matroska_output_reuses_its_matroska_parts(clip):
    """Parts of a .mkv output are Matroska files (seg-...mkv); a render killed midway resumes
    from them and gives the frames, times and packets of an uninterrupted render."""
    args = ("video", clip.name, "--segment", SEG, "--quiet")
    ok(None, *args, *ROTATE, "-o", "whole.mkv")
    stop_midway((*args, *ROTATE), "cut.mkv", signal.SIGKILL)
    parts = sorted(p.name for p in Path("cut.mkv.parts").iterdir() if p.name.startswith("seg-"))
    assert parts and all(p.endswith(".mkv") for p in parts), parts
    ok(None, *args, "--resume", *ROTATE, "-o", "cut.mkv")
    assert not Path("cut.mkv.parts").exists()
    assert packets("cut.mkv", "video") == packets("whole.mkv", "video")
    assert ms_times("cut.mkv") == ms_times("whole.mkv") and len(times("cut.mkv")) == 48


def ffprobe_rates(path) -> tuple[str, str]:
    """The first video stream's r_frame_rate and avg_frame_rate, as ffprobe reads them."""
    import shutil

    text = subprocess.run(
        [shutil.which("ffprobe") or "ffprobe", "-v", "error", "-select_streams", "v:0",
         "-show_entries", "stream=r_frame_rate,avg_frame_rate", "-of", "json", str(path)],
        check=True, capture_output=True, text=True,
    ).stdout  # fmt: skip
    stream = json.loads(text)["streams"][0]
    return stream["r_frame_rate"], stream["avg_frame_rate"]


@pytest.mark.skipif(__import__("shutil").which("ffprobe") is None, reason="no ffprobe")
@pytest.mark.parametrize("source", ["in.mp4", "in.mkv"])
def test_a_matroska_output_says_the_inputs_frame_rate(workdir, source):
    """The joined Matroska file's DefaultDuration was its time base's tick (1/12288 s from an
    MP4 input, 1 ms from a Matroska one): ffprobe read 12288 or 1000 fps for a 12 fps clip."""
    make_clip(workdir / source, frames=12, rate=12)
    ok(None, "video", source, "-o", "out.mkv", "--segment", SEG, "--quiet", *ROTATE)
    assert ffprobe_rates("out.mkv") == ("12/1", "12/1")
    assert len(times("out.mkv")) == 12


def test_a_truncated_recording_gives_its_whole_frames_with_one_warning(clip):
    """A recording cut short (its index at the front, 'faststart', and its data cut in the middle
    of a frame) failed with an internal 'segment 0 gave 28 frames, expected 31': the frame cut
    short was counted, and decoding it stopped the decoder. The whole frames are rendered,
    each at its time, with one warning that the input ends early."""
    with av.open(clip.name) as i, av.open("fast.mp4", "w", options={"movflags": "faststart"}) as o:
        copies = {s.index: o.add_stream_from_template(s) for s in i.streams}
        for p in i.demux():
            if p.dts is not None:
                p.stream = copies[p.stream_index]
                o.mux(p)
    with av.open("fast.mp4") as c:
        video = [(p.pos, p.size, p.pts) for p in c.demux(c.streams.video[0]) if p.size]
    pos, size, _ = video[40]
    cut = pos + size // 2  # in the middle of the 41st frame's data
    Path("cut.mp4").write_bytes(Path("fast.mp4").read_bytes()[:cut])
    whole = sorted(t for p, n, t in video if p + n <= cut)
    assert 30 < len(whole) <= 40
    code, _, err = run(None, "video", "cut.mp4", "-o", "out.mp4", "--segment", SEG, "--quiet",
                       *ROTATE)  # fmt: skip
    assert code == 0, err
    assert err.count("\n") == 1 and "'cut.mp4' ends early" in err, err
    with av.open("cut.mp4") as c:
        tb = c.streams.video[0].time_base
    assert exact_times("out.mp4") == [t * tb for t in whole]
    assert len(frames("out.mp4")) == len(whole)
