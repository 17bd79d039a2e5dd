"""spherewarp's output grids against ffmpeg's v360 doing the same reprojection, as ratios.

    python bench/grids.py [--size 4096x2048] [--repeat 3] [--threads N]

Makes an equirectangular JPEG (the bundled panorama, resized), then in one run,
for each view (rectilinear 90°, fisheye 180°, the 3x2 and 6x1 cube maps, the
little planet), times

* end to end, as separate processes (start-up, decode, reproject, encode):
  ``spherewarp project IN --to NAME -o OUT.jpg`` against ``ffmpeg -i IN -vf
  v360=e:OUT:... OUT.jpg`` at the same output size, each the minimum of
  ``--repeat`` runs;
* in this process, the reprojection alone (``warp(img, Mobius.identity(),
  grid=...)``): microseconds a pixel with the default ``antialias="auto"`` (what
  ``project`` does) and with ``"none"`` (one bilinear tap a pixel, as v360), a
  cached ``WarpMap`` of the ``"none"`` plan (its source coordinates kept: what
  v360's tables are), and
  ffmpeg's v360 per frame through a configured PyAV filter graph (tables built at
  configure time; packed ``rgb24``), the same per pixel.

Prints one table with the ratios (spherewarp time / ffmpeg time: below 1 is
faster). Needs the ``ffmpeg`` command and PyAV.
"""

from __future__ import annotations

import argparse
import math
import shutil
import subprocess
import sys
import tempfile
import time
from fractions import Fraction
from pathlib import Path

import numpy as np


def views(h: int) -> list[tuple[str, str, tuple[int, int], dict[str, str]]]:
    """(spherewarp grid, v360 output, (height, width), v360 options) for an input of
    height ``h``, at spherewarp's default sizes."""
    from spherewarp.grids import default_shape

    out = []
    for name, v360, opts in [
        ("rectilinear", "flat", {}),
        ("fisheye", "fisheye", {"h_fov": "180", "v_fov": "180"}),
        ("cubemap", "c3x2", {}),
        ("cubemap-6x1", "c6x1", {}),
        ("little-planet", "sg", {"h_fov": "270", "v_fov": "270", "pitch": "-90"}),
    ]:
        shape = default_shape(name, (h, 2 * h))
        if name == "rectilinear":
            v_fov = 2 * math.degrees(math.atan(shape[0] / shape[1]))
            opts = {"h_fov": "90", "v_fov": f"{v_fov:.6f}"}
        out.append((name, v360, shape, opts))
    return out


def make_input(path: Path, w: int, h: int) -> np.ndarray:
    from PIL import Image

    from spherewarp.demo import sample_path

    with Image.open(sample_path("interior.png")) as im:
        img = im.convert("RGB").resize((w, h), Image.BICUBIC)
        img.save(path, quality=92)
    return np.asarray(img)


def timed(cmd: list[str], out: Path, repeat: int) -> float:
    best = math.inf
    for _ in range(repeat):
        out.unlink(missing_ok=True)
        t = time.perf_counter()
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        best = min(best, time.perf_counter() - t)
    return best


def best_of(f, repeat: int) -> float:
    f()  # warm (compiled kernels loaded, caches filled)
    best = math.inf
    for _ in range(repeat):
        t = time.perf_counter()
        f()
        best = min(best, time.perf_counter() - t)
    return best


def v360_graph(img: np.ndarray, output: str, shape: tuple[int, int], opts: dict[str, str], threads):
    """A configured v360 graph and a function that pushes and pulls one frame."""
    import av
    import av.filter

    h, w = img.shape[:2]
    frame = av.VideoFrame.from_ndarray(np.ascontiguousarray(img), format="rgb24")
    graph = av.filter.Graph()
    src = graph.add_buffer(width=w, height=h, format="rgb24", time_base=Fraction(1, 25))
    node = graph.add(
        "v360", input="e", output=output, w=str(shape[1]), h=str(shape[0]), interp="linear",
        **opts,
    )  # fmt: skip
    fmt = graph.add("format", pix_fmts="rgb24")
    sink = graph.add("buffersink")
    graph.link_nodes(src, node, fmt, sink)
    if threads is not None:
        graph.nb_threads = threads  # pragma: no cover - only where PyAV exposes it
    graph.configure()
    pts = [0]

    def one() -> None:
        frame.pts = pts[0]
        pts[0] += 1
        graph.push(frame)
        graph.pull()

    return one


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", default="4096x2048")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--threads", type=int, default=None)
    ap.add_argument("--no-cli", action="store_true", help="skip the end-to-end runs")
    a = ap.parse_args()
    w, h = (int(x) for x in a.size.split("x"))
    ffmpeg = shutil.which("ffmpeg")
    if ffmpeg is None:
        sys.exit("bench/grids.py needs the ffmpeg command (apt-get install ffmpeg)")
    from spherewarp import warp
    from spherewarp.grids import make_grid
    from spherewarp.maps import Mobius
    from spherewarp.render import WarpMap

    d = Path(tempfile.mkdtemp())
    src = d / "in.jpg"
    img = make_input(src, w, h)
    rows = []
    for name, v360, shape, opts in views(h):
        g = make_grid(name, (h, w))
        npx = shape[0] * shape[1]
        ident = Mobius.identity()
        t_auto = best_of(lambda g=g, m=ident: warp(img, m, grid=g, threads=a.threads), a.repeat)
        t_none = best_of(
            lambda g=g, m=ident: warp(img, m, grid=g, antialias="none", threads=a.threads),
            a.repeat,
        )
        wm = WarpMap(ident, (h, w), grid=g, antialias="none", threads=a.threads)
        t_cached = best_of(lambda wm=wm: wm.apply(img), a.repeat)
        t_v = best_of(v360_graph(img, v360, shape, opts, a.threads), a.repeat)
        row = {
            "name": name, "v360": v360, "shape": shape, "auto_us": t_auto / npx * 1e6,
            "none_us": t_none / npx * 1e6, "cached_us": t_cached / npx * 1e6,
            "v360_us": t_v / npx * 1e6,
        }  # fmt: skip
        if not a.no_cli:
            out = d / f"{name}.jpg"
            ours = [sys.executable, "-m", "spherewarp", "project", str(src), "--to", name]
            ours += ["-o", str(out), "--quiet"]
            if a.threads is not None:
                ours += ["--threads", str(a.threads)]
            vf = ":".join([f"v360=e:{v360}", f"w={shape[1]}", f"h={shape[0]}"])
            vf += "".join(f":{k}={v}" for k, v in opts.items())
            theirs = [ffmpeg, "-y", "-v", "error", "-i", str(src), "-vf", vf, "-q:v", "2", str(out)]
            row["cli_s"] = timed(ours, out, a.repeat)
            row["ffmpeg_s"] = timed(theirs, out, a.repeat)
        rows.append(row)
    print(f"{w}x{h} RGB input, default view sizes, minimum of {a.repeat} runs")
    print(
        f"{'view':<14}{'output':>11} | {'auto':>7}{'none':>7}{'cached':>7}{'v360':>7} us/px |"
        f" {'auto/v360':>9}{'none/v360':>10}{'cached/v360':>12} |"
        f"{'project':>9}{'ffmpeg':>8}{'ratio':>7}"
    )
    for r in rows:
        line = (
            f"{r['name']:<14}{r['shape'][1]:>6}x{r['shape'][0]:<4} |"
            f" {r['auto_us']:7.3f}{r['none_us']:7.3f}{r['cached_us']:7.3f}{r['v360_us']:7.3f}"
            f"       | {r['auto_us'] / r['v360_us']:9.2f}{r['none_us'] / r['v360_us']:10.2f}"
            f"{r['cached_us'] / r['v360_us']:12.2f} |"
        )
        if "cli_s" in r:
            line += f"{r['cli_s']:8.2f}s{r['ffmpeg_s']:7.2f}s{r['cli_s'] / r['ffmpeg_s']:7.2f}"
        print(line)
    print("ratios: spherewarp time / ffmpeg time (below 1: spherewarp is faster)")
    shutil.rmtree(d)


if __name__ == "__main__":
    main()
