"""spherewarp video against ffmpeg's v360 filter: frames a second, end to end, as a ratio.

    python bench/video.py [--size 3840x1920] [--frames 48]

Generates a clip (the bundled panorama turning, H.264), then in one run times
``spherewarp video IN -o OUT rotate --yaw 30`` and ``ffmpeg -i IN -vf
v360=e:e:yaw=30 OUT`` with the same encoder settings (libx264, CRF 18,
preset ultrafast, so that the warp dominates), each the minimum of
``--repeat`` runs, as separate processes. Prints frames a second for each and
their ratio. Needs the ``ffmpeg`` command.
"""

from __future__ import annotations

import argparse
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


def timed(cmd: list[str], out: Path, repeat: int) -> float:
    best = float("inf")
    for _ in range(repeat):
        out.unlink(missing_ok=True)
        t = time.perf_counter()
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        best = min(best, time.perf_counter() - t)
    return best


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", default="3840x1920")
    ap.add_argument("--frames", type=int, default=48)
    ap.add_argument("--repeat", type=int, default=2)
    a = ap.parse_args()
    w, h = (int(x) for x in a.size.split("x"))
    ffmpeg = shutil.which("ffmpeg")
    if ffmpeg is None:
        sys.exit("bench/video.py needs the ffmpeg command (apt-get install ffmpeg)")
    d = Path(tempfile.mkdtemp())
    clip, out = d / "in.mp4", d / "out.mp4"
    make_clip(clip, w, h, a.frames)
    enc = ["--crf", "18", "--preset", "ultrafast"]
    ours = [sys.executable, "-m", "spherewarp", "video", str(clip), "-o", str(out), "--quiet"]
    ours += [*enc, "rotate", "--yaw", "30"]
    theirs = [ffmpeg, "-y", "-v", "error", "-i", str(clip), "-vf", "v360=e:e:yaw=30"]
    theirs += ["-c:v", "libx264", "-crf", "18", "-preset", "ultrafast", "-c:a", "copy", str(out)]
    t_ours = timed(ours, out, a.repeat)
    t_ff = timed(theirs, out, a.repeat)
    n = a.frames
    print(f"{w}x{h}, {n} frames, libx264 CRF 18 ultrafast, minimum of {a.repeat} runs")
    print(f"  spherewarp video rotate --yaw 30 : {n / t_ours:6.2f} fps ({t_ours:.2f} s)")
    print(f"  ffmpeg -vf v360=e:e:yaw=30       : {n / t_ff:6.2f} fps ({t_ff:.2f} s)")
    print(f"  ratio (spherewarp fps / ffmpeg fps): {t_ff / t_ours:.2f}")
    shutil.rmtree(d)


if __name__ == "__main__":
    main()
