"""spherewarp video against ffmpeg's v360 filter: frames a second, end to end, as a ratio;
and the peak memory of a 1-minute clip.

    python bench/video.py [--size 3840x1920] [--frames 48] [--repeat 2] [--pitch 0]
    python bench/video.py --memory [--memory-size 1280x640] [--memory-seconds 10,60]
    python bench/video.py --memory --memory-size 3840x1920 --memory-seconds 20 \
        --memory-segments 20,10,2,1,0.5

Generates a clip (the bundled panorama turning, H.264), then in one run times
``spherewarp video IN -o OUT rotate --yaw 30 --pitch P`` and ``ffmpeg -i IN -vf
v360=e:e:yaw=30:pitch=P OUT`` (``--pitch``, default 0) with the same encoder
settings (libx264, CRF 18, preset ultrafast, so that the warp dominates), each the minimum of
``--repeat`` runs, as separate processes. Prints frames a second for each and
their ratio, and the CPU seconds each spent (user + system, all threads: on a
shared machine the fairer measure of work), and the in-process cost of the
warp stage per frame, warping the 4:2:0 planes as they are against going
through RGB (``render_video(planar=False)``). Needs the ``ffmpeg`` command.

``--memory`` renders a 10-second and a 60-second clip of the same size (or the
``--memory-seconds`` given), each
in a fresh process, and prints each one's peak resident memory (the most any
child process held: ``getrusage(RUSAGE_CHILDREN).ru_maxrss``); it asserts the
design: the minute costs no more than a few frames over the 10 seconds (the
pipeline's queues hold a few frames, whatever the length), and a few MiB for
rendering in more than one segment. With ``--memory-segments S,...`` it renders the first
``--memory-seconds`` clip once for each ``--segment S`` instead (many segments without a long
clip), each in a fresh process, ``--memory-repeat`` times, and prints each run's peak: what
memory does with the number of segments.
"""

from __future__ import annotations

import argparse
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np


def make_clip(path: Path, w: int, h: int, frames: int) -> None:
    import av
    from PIL import Image

    from spherewarp.demo import sample_path

    with Image.open(sample_path("interior.png")) as im:
        base = np.asarray(im.convert("RGB").resize((w, h), Image.BILINEAR))
    with av.open(str(path), "w") as c:
        v = c.add_stream("libx264", rate=24, options={"crf": "18", "preset": "ultrafast"})
        v.width, v.height, v.pix_fmt = w, h, "yuv420p"
        for k in range(frames):
            img = np.ascontiguousarray(np.roll(base, -8 * k, axis=1))
            c.mux(v.encode(av.VideoFrame.from_ndarray(img, format="rgb24")))
        c.mux(v.encode(None))


def _children_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def timed(cmd: list[str], out: Path, repeat: int) -> tuple[float, float]:
    """The least wall seconds and the least CPU seconds of ``repeat`` runs of ``cmd``."""
    best, cpu = float("inf"), float("inf")
    for _ in range(repeat):
        out.unlink(missing_ok=True)
        c = _children_cpu()
        t = time.perf_counter()
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        best = min(best, time.perf_counter() - t)
        cpu = min(cpu, _children_cpu() - c)
    return best, cpu


def peak_rss(cmd: list[str]) -> int:
    """Peak resident memory (bytes) of ``cmd`` run in a fresh process of its own."""
    probe = (
        "import resource, subprocess, sys;"
        "subprocess.run(sys.argv[1:], check=True, stdout=subprocess.DEVNULL);"
        "print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)"
    )
    done = subprocess.run(
        [sys.executable, "-c", probe, *cmd], check=True, capture_output=True, text=True
    )
    return int(done.stdout.split()[-1]) * 1024  # Linux: kilobytes


def warp_stage(clip: Path, frames: int = 4, pitch: float = 0.0) -> dict[str, tuple[float, float]]:
    """Wall and CPU milliseconds a frame of the warp stage, by plane and through RGB (and
    the RGB path's conversion back to yuv420p, which the encoder does)."""
    import av

    from spherewarp.io.planes import frame_plan
    from spherewarp.io.stereo import FramePlan
    from spherewarp.maps import Mobius

    turn = Mobius.from_yaw_pitch_roll(30, pitch, 0)
    with av.open(str(clip)) as c:
        got = [f for _, f in zip(range(frames), c.decode(video=0), strict=False)]
    shape = (got[0].height, got[0].width)

    def make(s, out):
        return FramePlan(turn, s, out_shape=out)

    plans = {
        "planes": frame_plan(make, shape, "yuv420p", "yuv420p", "rgb24"),
        "rgb": frame_plan(make, shape, "yuv420p", "yuv420p", "rgb24", planar=False),
    }
    res: dict[str, tuple[float, float]] = {}
    for _ in range(2):
        for name, plan in plans.items():
            w, c = time.perf_counter(), time.process_time()
            for f in got:
                g = plan.apply(f)
                if g.format.name != "yuv420p":
                    g.reformat(format="yuv420p")
            wall = 1000 * (time.perf_counter() - w) / len(got)
            cpu = 1000 * (time.process_time() - c) / len(got)
            old = res.get(name, (float("inf"), float("inf")))
            res[name] = (min(old[0], wall), min(old[1], cpu))
    return res


def memory(a: argparse.Namespace, d: Path) -> None:
    w, h = (int(x) for x in a.memory_size.split("x"))
    rows = []
    for seconds in (int(x) for x in a.memory_seconds.split(",")):
        clip, out = d / f"m{seconds}.mp4", d / f"m{seconds}-out.mp4"
        make_clip(clip, w, h, 24 * seconds)
        cmd = [sys.executable, "-m", "spherewarp", "video", str(clip), "-o", str(out), "--quiet"]
        cmd += ["--crf", "18", "--preset", "ultrafast", "rotate", "--yaw", "30"]
        rows.append((seconds, peak_rss(cmd)))
    frame = w * h * 3
    print(f"{w}x{h}, libx264 CRF 18 ultrafast, peak resident memory (one fresh process each)")
    for seconds, rss in rows:
        print(f"  {seconds:3d} s ({24 * seconds:5d} frames): {rss / 2**20:7.1f} MiB")
    grown = rows[-1][1] - rows[0][1]
    print(
        f"  {rows[-1][0]} s over {rows[0][0]} s: {grown / 2**20:+.1f} MiB = "
        f"{grown / frame:+.1f} RGB frames"
    )
    # a few frames, and the fixed cost of a render in several segments (the second encoder,
    # the join: ~5 MiB), whatever the length
    assert grown < 8 * frame + 16 * 2**20, "memory grows with the length: frames are being held"


def memory_segments(a: argparse.Namespace, d: Path) -> None:
    """Peak memory of one clip rendered in segments of each ``--memory-segments`` length."""
    w, h = (int(x) for x in a.memory_size.split("x"))
    seconds = int(a.memory_seconds.split(",")[0])
    clip, out = d / f"m{seconds}.mp4", d / f"m{seconds}-out.mp4"
    make_clip(clip, w, h, 24 * seconds)
    print(f"{w}x{h}, {seconds} s ({24 * seconds} frames), libx264 CRF 18 ultrafast, rotate yaw 30,")
    print("peak resident memory by segment length (one fresh process each run)")
    for seg in a.memory_segments.split(","):
        segments = -(-24 * seconds // max(1, round(24 * float(seg))))
        cmd = [sys.executable, "-m", "spherewarp", "video", str(clip), "-o", str(out), "--quiet"]
        cmd += ["--overwrite", "--crf", "18", "--preset", "ultrafast", "--segment", seg]
        cmd += ["rotate", "--yaw", "30"]
        peaks = [peak_rss(cmd) / 2**20 for _ in range(a.memory_repeat)]
        shown = " / ".join(f"{p:.1f}" for p in peaks)
        print(f"  --segment {seg:>4s} ({segments:3d} segments): {shown} MiB", flush=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", default="3840x1920")
    ap.add_argument("--frames", type=int, default=48)
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument(
        "--pitch",
        type=float,
        default=0.0,
        help="the turn's pitch too (0: a yaw alone, which "
        "takes rows to rows, so that spherewarp skips the lower taps)",
    )
    ap.add_argument("--memory", action="store_true", help="peak memory of a 1-minute clip")
    ap.add_argument("--memory-size", default="1280x640")
    ap.add_argument("--memory-seconds", default="10,60", help="clip lengths, shortest first")
    ap.add_argument(
        "--memory-segments",
        default="",
        help="segment lengths (seconds, e.g. 20,2,1): render the first --memory-seconds clip "
        "with each --segment instead",
    )
    ap.add_argument("--memory-repeat", type=int, default=1, help="runs of each --memory-segments")
    a = ap.parse_args()
    w, h = (int(x) for x in a.size.split("x"))
    d = Path(tempfile.mkdtemp())
    if a.memory:
        (memory_segments if a.memory_segments else memory)(a, d)
        shutil.rmtree(d)
        return
    ffmpeg = shutil.which("ffmpeg")
    if ffmpeg is None:
        sys.exit("bench/video.py needs the ffmpeg command (apt-get install ffmpeg)")
    n = a.frames
    enc = ["--crf", "18", "--preset", "ultrafast"]
    runs: dict[tuple[str, int], tuple[float, float]] = {}
    for frames in (n, 2 * n):  # the second length gives the cost of a frame, start-up aside
        clip, out = d / f"in{frames}.mp4", d / "out.mp4"
        make_clip(clip, w, h, frames)
        ours = [sys.executable, "-m", "spherewarp", "video", str(clip), "-o", str(out), "--quiet"]
        ours += [*enc, "rotate", "--yaw", "30", "--pitch", f"{a.pitch:g}"]
        v360 = f"v360=e:e:yaw=30:pitch={a.pitch:g}"
        theirs = [ffmpeg, "-y", "-v", "error", "-i", str(clip), "-vf", v360]
        theirs += ["-c:v", "libx264", "-crf", "18", "-preset", "ultrafast", str(out)]
        runs["ours", frames] = timed(ours, out, a.repeat)
        runs["v360", frames] = timed(theirs, out, a.repeat)
    print(f"{w}x{h}, libx264 CRF 18 ultrafast, minimum of {a.repeat} runs")
    print(f"  {os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f} at the end")
    turn = f"--yaw 30 --pitch {a.pitch:g}"
    names = {"ours": f"spherewarp video rotate {turn}", "v360": f"ffmpeg -vf {v360}"}
    for key, name in names.items():
        for frames in (n, 2 * n):
            t, c = runs[key, frames]
            fps = frames / t
            print(f"  {name:44s} {frames:4d} frames: {fps:6.2f} fps ({t:6.2f} s, {c:5.1f} CPU s)")
    (t1, c1), (t2, c2) = runs["ours", n], runs["ours", 2 * n]
    (f1, g1), (f2, g2) = runs["v360", n], runs["v360", 2 * n]
    print(
        f"  ratio, {n} frames (spherewarp fps / ffmpeg fps): {f1 / t1:.2f} wall, {g1 / c1:.2f} CPU"
    )
    print(f"  ratio, {2 * n} frames: {f2 / t2:.2f} wall, {g2 / c2:.2f} CPU")
    print(
        f"  ratio, a frame more (the {n} frames between the two runs, start-up and planning "
        f"aside): {(f2 - f1) / (t2 - t1):.2f} wall, {(g2 - g1) / (c2 - c1):.2f} CPU"
    )
    stage = warp_stage(clip, pitch=a.pitch)
    print("  warp stage a frame (in process; the RGB path with its conversion back to yuv420p):")
    for name, (wall, cpu) in stage.items():
        print(f"    {name:6s}: {wall:6.1f} ms wall, {cpu:6.1f} ms CPU")
    print(f"    planes / rgb CPU: {stage['planes'][1] / stage['rgb'][1]:.2f}")
    shutil.rmtree(d)


if __name__ == "__main__":
    main()
