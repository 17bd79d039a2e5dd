"""Segments a second: one local process, ``--jobs 2``, and a Dask cluster of 1 and 2 workers.

    python bench/scaleout.py [--size 1024x512] [--frames 96] [--segment 0.5] [--no-dask]
                             [--animate]

Makes a clip (the bundled panorama turning, H.264), then in one run times
``spherewarp video IN -o OUT --segment S rotate --yaw 30`` as a separate process with
``--jobs 1``, ``--jobs 2``, and ``--dask`` on a real ``dask scheduler`` with one, then two,
single-threaded ``dask worker`` processes on 127.0.0.1 (needs ``pip install
"spherewarp[dask]"``). ``--animate`` times ``spherewarp animate spin.json STILL --fps 24
-o OUT.mp4 --segment S`` instead (a spin of the bundled panorama at ``--size``, ``--frames``
frames). Prints segments a second and each one's ratio to ``--jobs 1``. The
processes of a pool and the Dask workers each warp with their share of the cores (numba
threads), so the figures show what splitting costs or gains on this machine, start-up
(spawn, imports, kernel loading) included.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "tests"))


def make_clip(path: Path, w: int, h: int, frames: int) -> None:
    import av
    import numpy as np
    from PIL import Image

    from spherewarp.demo import sample_path

    with Image.open(sample_path("interior.png")) as im:
        base = np.asarray(im.convert("RGB").resize((w, h), Image.BILINEAR))
    with av.open(str(path), "w") as c:
        v = c.add_stream("libx264", rate=24, options={"crf": "18", "preset": "ultrafast"})
        v.width, v.height, v.pix_fmt = w, h, "yuv420p"
        for k in range(frames):
            f = av.VideoFrame.from_ndarray(np.roll(base, -4 * k, axis=1), format="rgb24")
            c.mux(v.encode(f))
        c.mux(v.encode(None))


def make_still(d: Path, w: int, h: int, frames: int) -> tuple[Path, Path]:
    """A panorama at ``w x h`` and a recipe spinning it once in ``frames`` frames at 24 fps."""
    import json

    from PIL import Image

    from spherewarp.demo import sample_path

    with Image.open(sample_path("interior.png")) as im:
        im.convert("RGB").resize((w, h), Image.BILINEAR).save(d / "still.png")
    spin = {"keyframes": [[0, 0], [frames / 24, 360]]}
    data = {"spherewarp": 1, "duration": frames / 24, "loop": True,
            "steps": [{"rotate": {"yaw": spin}}]}  # fmt: skip
    (d / "spin.json").write_text(json.dumps(data))
    return d / "spin.json", d / "still.png"


def render(clip: Path | tuple[Path, Path], out: Path, segment: float, extra: list[str]) -> float:
    common = ["-o", str(out), "--overwrite", "--quiet", "--segment", str(segment), "--preset",
              "ultrafast", *extra]  # fmt: skip
    if isinstance(clip, tuple):  # animate: (recipe, still)
        what = ["animate", str(clip[0]), str(clip[1]), "--fps", "24", *common]
    else:
        what = ["video", str(clip), *common, "rotate", "--yaw", "30"]
    args = [sys.executable, "-m", "spherewarp", *what]
    t = time.perf_counter()
    subprocess.run(args, check=True)
    return time.perf_counter() - t


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", default="1024x512")
    ap.add_argument("--frames", type=int, default=96)
    ap.add_argument("--segment", type=float, default=0.5)
    ap.add_argument("--no-dask", action="store_true")
    ap.add_argument("--animate", action="store_true", help="time animate, not video")
    a = ap.parse_args()
    w, h = (int(x) for x in a.size.split("x"))
    segments = -(-a.frames // max(1, round(a.segment * 24)))
    with tempfile.TemporaryDirectory() as d:
        d = Path(d)
        if a.animate:
            clip: Path | tuple[Path, Path] = make_still(d, w, h, a.frames)
        else:
            clip = d / "in.mp4"
            make_clip(clip, w, h, a.frames)
        render(clip, d / "warm.mp4", a.segment, [])  # load the kernels once
        rows: list[tuple[str, float]] = []
        for jobs in (1, 2):
            rows.append((f"--jobs {jobs}", render(clip, d / "o.mp4", a.segment, ["-j", str(jobs)])))
        if not a.no_dask:
            from daskcluster import Cluster

            for n in (1, 2):
                c = Cluster(d / f"dask{n}", workers=n)
                try:
                    s = render(clip, d / "o.mp4", a.segment, ["--dask", c.address])
                finally:
                    c.close()
                rows.append((f"--dask, {n} worker{'s' * (n > 1)}", s))
    base = rows[0][1]
    print(f"{'animate' if a.animate else 'video'} {w}x{h}, {a.frames} frames, {segments} "
          f"segments of {a.segment:g} s, {os.cpu_count()} cores")  # fmt: skip
    print("| run | seconds | segments/s | ratio to --jobs 1 |")
    print("|---|---|---|---|")
    for name, s in rows:
        print(f"| {name} | {s:.2f} | {segments / s:.2f} | {base / s:.2f} |")


if __name__ == "__main__":
    main()
