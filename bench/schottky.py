"""Schottky renders: the compiled stage against the NumPy reduction it replaces, one run.

    python bench/schottky.py [--sizes 1024x512,4096x2048] [--threads N] [--repeat R]

For each output size, two maps of the README on the bundled ``interior``
panorama (upscaled to the output size) with the default filter: ``disks``, the
two-generator map of round disks, and ``mask``, the paper's mask workflow (the
bundled ``interior-mask.png``, its exact disks, ``--target red 40 --target green 60``):

* ``compiled``: ``warp(img, s)``, the ``schottky`` stage inside the kernel;
* ``numpy``: the same map with its compiled stage hidden, so that the renderer
  takes the path it took before the stage existed (the NumPy reduction for the
  points, compiled sampling);

and the ratio numpy / compiled (compiled: best of ``R`` runs; numpy: one run).
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from spherewarp import demo
from spherewarp.io import read_image
from spherewarp.maps import Mobius, Schottky
from spherewarp.maps.schottky import MaskRegions, cap_from_mask
from spherewarp.render import warp


class NoStage(Schottky):
    """The same map without its compiled stage (the path before the stage)."""

    kind = "bench-schottky-numpy"

    def kernel_stages(self):
        return None


def _best(fn, repeat: int) -> tuple[float, np.ndarray]:
    best, out = np.inf, None
    for _ in range(repeat):
        t = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t)
    return best, out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", default="1024x512,4096x2048")
    ap.add_argument("--threads", type=int, default=None)
    ap.add_argument("--repeat", type=int, default=2)
    args = ap.parse_args()
    src = read_image(demo.sample_path()).pixels
    pairs = [((38, 8, 24), (-40, -55, 22)), ((-163, 5, 9), (-110, 55, 18))]
    mask = read_image(demo.sample_path("interior-mask.png")).pixels
    colours = [(1.0, 0.0, 0.0), (0.0, 1.0, 0.0)]
    caps = [cap_from_mask(mask, c, inside=True) for c in colours]
    zooms = [(c, Mobius.zoom((c.lon, c.lat), f)) for c, f in zip(caps, (40, 60), strict=True)]
    regions = MaskRegions(mask, colours)
    cases = {
        "disks": lambda cls: cls(Schottky.from_disk_pairs(pairs).generators),
        "mask": lambda cls: cls(zooms).with_mask_regions(regions),
    }
    print(
        f"{'map':>6} {'size':>10} {'compiled s':>11} {'numpy s':>9} {'ratio':>7} {'max |diff|':>10}"
    )
    for name, make in cases.items():
        for size in args.sizes.split(","):
            w, h = (int(v) for v in size.split("x"))
            s, slow = make(Schottky).for_output(w), make(NoStage).for_output(w)
            kw = {"output_shape": (h, w), "threads": args.threads}
            warp(src, s, output_shape=(64, 128))  # compile / warm up
            tc, a = _best(lambda s=s, kw=kw: warp(src, s, **kw), args.repeat)
            tn, b = _best(lambda slow=slow, kw=kw: warp(src, slow, **kw), 1)
            diff = np.abs(a.astype(float) - b).max()
            print(f"{name:>6} {size:>10} {tc:11.3f} {tn:9.3f} {tn / tc:7.1f} {diff:10.1f}")


if __name__ == "__main__":
    main()
