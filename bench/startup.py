"""Where a warm ``spherewarp rotate`` spends its time before and after the render.

    python bench/startup.py [IMAGE] [--runs N]

Times, in one process, the phases of a rotate of IMAGE (default: the bundled
interior.png): imports, numba's start-up, the first kernel call (cache load),
reading and rendering; then the interpreter teardown, from two extra processes
that load the kernels and exit normally or with ``os._exit``. Prints the
minimum over the runs (each run a fresh process). See "Start-up of a warm
command" in ``bench/README.md``.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import time
from pathlib import Path

PHASES = r"""
import sys, time
t = [time.perf_counter()]
def mark():
    t.append(time.perf_counter())
import click
from spherewarp import cli
mark()
import numpy as np
mark()
from spherewarp.maps import Mobius
from spherewarp.io import read_image
from spherewarp.render import fast, warp
import PIL.Image, PIL.JpegImagePlugin, PIL.PngImagePlugin
mark()
fast._kernels()
mark()
import numba.np.arraymath
mark()
m = Mobius.from_yaw_pitch_roll(30, 0, 0)
warp(np.zeros((8, 16, 3), np.uint8), m, threads=1)
mark()
img = read_image(sys.argv[1]).pixels
mark()
warp(img, m)
mark()
print(" ".join(f"{(b - a) * 1000:.1f}" for a, b in zip(t, t[1:])))
"""
NAMES = [
    "click and spherewarp.cli",
    "numpy",
    "spherewarp maps, io, render and Pillow",
    "import numba, define the kernels (_kernels.py)",
    "numba's registries (it imports scipy.linalg to probe for BLAS)",
    "first kernel call: cache load, numba target context",
    "read the image",
    "render",
]
TEARDOWN = r"""
import os, sys
import numpy as np
from spherewarp.maps import Mobius
from spherewarp.render import warp
warp(np.zeros((8, 16, 3), np.uint8), Mobius.from_yaw_pitch_roll(30, 0, 0), threads=1)
if sys.argv[1] == "exit":
    os._exit(0)
"""


def main() -> None:
    here = Path(__file__).resolve().parents[1]
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("image", nargs="?", default=str(here / "src/spherewarp/data/interior.png"))
    ap.add_argument("--runs", type=int, default=6)
    args = ap.parse_args()
    rows: list[list[float]] = []
    tear: dict[str, list[float]] = {"normal": [], "exit": []}
    for _ in range(args.runs):
        out = subprocess.run(
            [sys.executable, "-c", PHASES, args.image], capture_output=True, text=True, check=True
        )
        rows.append([float(x) for x in out.stdout.split()])
        for how in tear:
            t0 = time.perf_counter()
            subprocess.run([sys.executable, "-c", TEARDOWN, how], check=True)
            tear[how].append(time.perf_counter() - t0)
    for i, name in enumerate(NAMES):
        print(f"{min(r[i] for r in rows):8.1f} ms  {name}")
    teardown = (min(tear["normal"]) - min(tear["exit"])) * 1000
    print(f"{teardown:8.1f} ms  interpreter teardown after loading the kernels")


if __name__ == "__main__":
    main()
