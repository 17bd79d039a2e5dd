# ruff: noqa: B023  (lambdas are called at once, inside the loop)
"""spherewarp against its peers, side by side in one process (see bench/README.md).

    python bench/run.py            # everything (about 10 minutes on 2 cores)
    python bench/run.py --quick    # 4096x2048 only, fewer repeats, no CLI (about 2 minutes)

Prints a table (ms, Mpix/s, peak memory) and the issue's targets as ratios to
the peers measured in the same run (cv2.remap, ffmpeg v360), and writes both
as JSON to bench/results/. OpenCV (opencv-python-headless) and PyAV/ffmpeg are
benchmark dependencies only; a peer that is missing is skipped.
"""

from __future__ import annotations

import argparse
import datetime as _dt
import gc
import json
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from fractions import Fraction
from pathlib import Path
from typing import Any

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "src"))
sys.path.insert(0, str(HERE.parent))

from PIL import Image  # noqa: E402

from bench.data import SHARED_PANORAMAS  # noqa: E402
from spherewarp import coords  # noqa: E402
from spherewarp.maps import Mobius  # noqa: E402
from spherewarp.render import fast, warp  # noqa: E402
from spherewarp.render.cache import WarpMap  # noqa: E402

YPR = (30.0, 20.0, 10.0)  # the rotation every peer does: v360 yaw/pitch/roll
SAMPLE = HERE.parent / "src" / "spherewarp" / "data" / "interior.png"
DETAIL = SHARED_PANORAMAS / "forest.png"

try:
    import cv2
except ImportError:  # pragma: no cover
    cv2 = None
try:
    import av
    import av.filter
except ImportError:  # pragma: no cover
    av = None


# -- measuring ----------------------------------------------------------------------------------
def _status(key: str) -> int:
    """A field of /proc/self/status in bytes (VmRSS, VmHWM), or 0 where there is none."""
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith(key + ":"):
                return int(line.split()[1]) * 1024
    except OSError:
        pass
    return 0


def _reset_peak() -> None:
    try:
        Path("/proc/self/clear_refs").write_text("5")  # resets VmHWM to VmRSS (Linux)
    except OSError:
        pass


def measure(fn, repeat: int, warmup: int = 1, memory: bool = False) -> dict[str, float]:
    """Min and median wall time of ``fn()`` (and the peak RSS above the start, in MiB)."""
    for _ in range(warmup):
        fn()
    times = []
    peak = 0.0
    for _ in range(repeat):
        gc.collect()
        if memory:
            _reset_peak()
            rss0 = _status("VmRSS")
        t = time.perf_counter()
        res = fn()
        times.append(time.perf_counter() - t)
        if memory:
            peak = max(peak, (_status("VmHWM") - rss0) / 2**20)
        del res
    out = {"s": min(times), "s_median": statistics.median(times)}
    if memory:
        out["peak_mib"] = peak
    return out


def load_image(width: int) -> np.ndarray:
    with Image.open(SAMPLE) as im:
        im = im.convert("RGB")
        if im.size != (width, width // 2):
            im = im.resize((width, width // 2), Image.BILINEAR)
        return np.ascontiguousarray(np.asarray(im))


def pixel_maps(h: int, w: int, m: Mobius) -> tuple[np.ndarray, np.ndarray]:
    """cv2-style float32 maps (x, y of the source, pixel centres at integers) of a pull-back."""
    mx = np.empty((h, w), np.float32)
    my = np.empty((h, w), np.float32)
    cols = np.arange(w) + 0.5
    for r0 in range(0, h, 256):
        r1 = min(h, r0 + 256)
        px = np.stack(np.broadcast_arrays(cols[None, :], np.arange(r0, r1)[:, None] + 0.5), -1)
        zw = coords.cp1_from_lonlat(coords.lonlat_from_pixel(px, w, h))
        src = coords.pixel_from_lonlat(coords.lonlat_from_cp1(m.pull_cp1(zw)), w, h)
        mx[r0:r1] = src[..., 0] - 0.5
        my[r0:r1] = src[..., 1] - 0.5
    return mx, my


# -- ffmpeg v360 through PyAV --------------------------------------------------------------------
class V360:
    """``v360=e:e:yaw:pitch:roll`` in a filter graph (tables built at configure time)."""

    def __init__(self, w: int, h: int, threads: int, fmt: str = "gbrp"):
        g = av.filter.Graph()
        g.threads = threads
        src = g.add_buffer(width=w, height=h, format=fmt, time_base=Fraction(1, 25))
        rot = g.add(
            "v360", input="e", output="e", yaw=str(YPR[0]), pitch=str(YPR[1]), roll=str(YPR[2])
        )
        keep = g.add("format", pix_fmts=fmt)
        sink = g.add("buffersink")
        g.link_nodes(src, rot, keep, sink)
        g.configure()
        self.graph = g
        self.pts = 0

    def __call__(self, frame) -> Any:
        frame.pts = self.pts
        self.pts += 1
        self.graph.push(frame)
        return self.graph.pull()


def v360_frame(img: np.ndarray, fmt: str = "gbrp"):
    """A frame in v360's fastest full-RGB format (planar; packed rgb24 is slower)."""
    f = av.VideoFrame.from_ndarray(img, format="rgb24").reformat(format=fmt)
    f.time_base = Fraction(1, 25)
    return f


# -- the table ------------------------------------------------------------------------------------
ROWS: list[dict[str, Any]] = []


def row(
    group: str, name: str, size: tuple[int, int], threads: int | None, m: dict, **extra
) -> None:
    w, h = size
    r = {
        "group": group,
        "case": name,
        "size": f"{w}x{h}",
        "threads": threads,
        "ms": 1e3 * m["s"],
        "ms_median": 1e3 * m["s_median"],
        "mpix_s": w * h / m["s"] / 1e6,
    }
    if "peak_mib" in m:
        r["peak_mib"] = m["peak_mib"]
    r.update(extra)
    ROWS.append(r)
    print(
        f"  {name:<40} {r['size']:>9} t={threads!s:<2} {r['ms']:9.1f} ms  "
        f"{r['mpix_s']:7.1f} Mpix/s"
        + (f"  peak +{r['peak_mib']:.0f} MiB" if "peak_mib" in r else ""),
        flush=True,
    )


def bench_rotation(width: int, threads_list: list[int], repeat: int, numpy_ref: bool) -> None:
    h, w = width // 2, width
    img = load_image(width)
    m = Mobius.from_yaw_pitch_roll(*YPR)
    size = (w, h)
    mem = False  # peak memory: measured in fresh processes (bench_memory)
    print(f"\n== rotation yaw/pitch/roll {YPR}, {w}x{h} RGB uint8, bilinear", flush=True)
    out = np.empty_like(img)
    row("rotate", "memory copy (floor)", size, 1, measure(lambda: np.copyto(out, img), repeat))
    mx = my = None
    if cv2 is not None:
        mx, my = pixel_maps(h, w, m)
        m1, m2 = cv2.convertMaps(mx, my, cv2.CV_16SC2)
    wm = None
    for t in threads_list:
        if cv2 is not None:
            cv2.setNumThreads(t)
            row("rotate", "cv2.remap float32 maps", size, t, measure(
                lambda: cv2.remap(img, mx, my, cv2.INTER_LINEAR, borderMode=cv2.BORDER_WRAP),
                repeat, memory=mem))  # fmt: skip
            row("rotate", "cv2.remap fixed-point maps", size, t, measure(
                lambda: cv2.remap(img, m1, m2, cv2.INTER_LINEAR, borderMode=cv2.BORDER_WRAP),
                repeat, memory=mem))  # fmt: skip
        if av is not None:
            v = V360(w, h, t)
            frame = v360_frame(img)
            row("rotate", "ffmpeg v360 per frame", size, t, measure(lambda: v(frame), repeat))
            v420 = V360(w, h, t, "yuv420p")
            f420 = v360_frame(img, "yuv420p")
            row("rotate", "ffmpeg v360 per frame, yuv420p (half the samples)", size, t,
                measure(lambda: v420(f420), repeat))  # fmt: skip
            row("rotate", "ffmpeg v360 one-off (set-up + frame)", size, t, measure(
                lambda: V360(w, h, t)(frame), max(1, repeat // 3), warmup=0))  # fmt: skip
        row("rotate", "spherewarp on the fly", size, t, measure(
            lambda: warp(img, m, threads=t), repeat, memory=mem))  # fmt: skip
        mb = measure(lambda: WarpMap.build(m, (h, w), threads=t), 1, warmup=0)
        wm = WarpMap.build(m, (h, w), threads=t)
        buf = np.empty_like(img)
        row("rotate", "spherewarp cached (WarpMap.apply)", size, t, measure(
            lambda: wm.apply(img, out=buf, threads=t), repeat, memory=mem),
            build_ms=1e3 * mb["s"], map_mib=wm.nbytes / 2**20)  # fmt: skip
    if numpy_ref:
        row("rotate", "plain NumPy pipeline (reference path)", size, 1, measure(
            lambda: warp(img, m, method="reference", antialias="none"), 1, warmup=0,
            memory=mem))  # fmt: skip
    wm = None  # free it before the next cases
    # zoom by 8 on the fly: anti-aliasing costs
    z = Mobius.zoom((0.0, 0.0), 8.0)
    for t in threads_list:
        for label, aa in (("none", "none"), ("auto", "auto"), ("adaptive", "adaptive"),
                          ("area", "area"), ("uniform 4x4", 4)):  # fmt: skip
            row("zoom8", f"spherewarp zoom x8, antialias {label}", size, t, measure(
                lambda aa=aa: warp(img, z.inverse(), antialias=aa, threads=t),
                max(1, repeat // (4 if aa == 4 else 1)), memory=mem))  # fmt: skip
        row("zoom8", "spherewarp rotation, antialias auto", size, t, measure(
            lambda: warp(img, m, antialias="auto", threads=t), repeat))  # fmt: skip
        row("zoom8", "spherewarp rotation, antialias none", size, t, measure(
            lambda: warp(img, m, antialias="none", threads=t), repeat))  # fmt: skip
        row("zoom8", "spherewarp rotation, antialias area", size, t, measure(
            lambda: warp(img, m, antialias="area", threads=t), repeat))  # fmt: skip


def effect_maps() -> dict[str, Any]:
    """The non-Möbius effects of the issue's target 2 (compiled stages on the fly)."""
    from spherewarp.maps import Droste, ExpMap, Lattes, Power

    rho = np.full(64, np.log(np.tan(np.radians(20.0) / 2)))  # a round frame, radius 20 deg
    return {
        "Power(2)": (Power(2), 3.0),
        "ExpMap(4)": (ExpMap(4.0), 3.0),
        "Lattes 2+1j": (Lattes((2, 1)), 4.0),
        "Droste x4": (Droste((0.0, 0.0), rho, 4.0), 4.0),
    }


def bench_effects(width: int, threads_list: list[int], repeat: int) -> None:
    """Branched, exp, Lattès and Droste maps on the fly, beside cv2.remap (fixed point)."""
    h, w = width // 2, width
    img = load_image(width)
    size = (w, h)
    print(f"\n== effects on the fly, {w}x{h} RGB uint8, bilinear", flush=True)
    maps = effect_maps()
    out = np.empty_like(img)
    bg = np.zeros(3, np.float32)
    for t in threads_list:
        for name, (m, _) in maps.items():
            for aa in ("auto", "none"):
                row("rotate", f"spherewarp on the fly, {name}, AA {aa}", size, t, measure(
                    lambda: warp(img, m, antialias=aa, threads=t), repeat))  # fmt: skip
            # the compiled stages, opt-in kinds included (fast.OPT_IN_KINDS), no AA
            spec = fast.kernel_spec(m, opt_in="all")
            if spec is not None:
                row("rotate", f"spherewarp compiled stages, {name}, AA none", size, t, measure(
                    lambda: fast.render_spec(img, spec, out, interp="bilinear", aa=("none", 1),
                                             background=bg, threads=t), repeat))  # fmt: skip


MEMORY_CASES = {
    "cv2.remap float32 maps": "cv2f",
    "cv2.remap fixed-point maps": "cv2i",
    "spherewarp on the fly": "fly",
    "spherewarp on the fly, zoom x8 antialias auto": "zoom_auto",
    "spherewarp cached (WarpMap.apply into a new buffer)": "cached",
    "plain NumPy pipeline (reference path)": "numpy",
}


def memory_case(case: str, width: int, threads: int) -> dict[str, float]:
    """Run one case in this (fresh) process: peak RSS growth above the state before it."""
    h, w = width // 2, width
    img = load_image(width)
    m = Mobius.from_yaw_pitch_roll(*YPR)
    tiny = np.zeros((16, 32, 3), np.uint8)
    warp(tiny, m)
    warp(tiny, Mobius.zoom((0, 0), 8))  # load the compiled kernels
    if case in ("cv2f", "cv2i"):
        cv2.setNumThreads(threads)
        mx, my = pixel_maps(h, w, m)
        if case == "cv2i":
            mx, my = cv2.convertMaps(mx, my, cv2.CV_16SC2)
        fn = lambda: cv2.remap(img, mx, my, cv2.INTER_LINEAR, borderMode=cv2.BORDER_WRAP)  # noqa: E731
    elif case == "fly":
        fn = lambda: warp(img, m, threads=threads)  # noqa: E731
    elif case == "zoom_auto":
        z = Mobius.zoom((0.0, 0.0), 8.0).inverse()
        fn = lambda: warp(img, z, threads=threads)  # noqa: E731
    elif case == "cached":
        wm = WarpMap.build(m, (h, w), threads=threads)
        buf = np.empty_like(img)
        fn = lambda: wm.apply(img, out=buf, threads=threads)  # noqa: E731
    else:
        fn = lambda: warp(img, m, method="reference", antialias="none")  # noqa: E731
    gc.collect()
    _reset_peak()
    rss0 = _status("VmRSS")
    t = time.perf_counter()
    out = fn()
    dt = time.perf_counter() - t
    peak = (_status("VmHWM") - rss0) / 2**20
    del out
    return {"peak_mib": peak, "s": dt, "rss0_mib": rss0 / 2**20}


def bench_memory(width: int, threads: int) -> None:
    if not Path("/proc/self/clear_refs").exists():
        print("\n== peak memory: skipped (needs Linux /proc)")
        return
    out_mib = width * width // 2 * 3 / 2**20
    print(f"\n== peak memory, {width}x{width // 2}, each case in a fresh process "
          f"(output image {out_mib:.0f} MiB)", flush=True)  # fmt: skip
    for name, key in MEMORY_CASES.items():
        if key.startswith("cv2") and cv2 is None:
            continue
        res = subprocess.run(
            [sys.executable, __file__, "--memory-case", key, "--width", str(width),
             "--threads", str(threads)],
            capture_output=True, text=True, check=True,
        )  # fmt: skip
        d = json.loads(res.stdout.strip().splitlines()[-1])
        row("memory", name, (width, width // 2), threads,
            {"s": d["s"], "s_median": d["s"], "peak_mib": d["peak_mib"]},
            overhead_mib=d["peak_mib"] - out_mib)  # fmt: skip


def psnr(a: np.ndarray, ref: np.ndarray, mask: np.ndarray | None = None) -> float:
    e = np.mean((a.astype(np.float64) - ref.astype(np.float64)) ** 2, axis=-1)
    if mask is not None:
        e = e[mask]
    mse = float(np.mean(e))
    return float("inf") if mse == 0 else 10 * np.log10(255.0**2 / mse)


def bench_antialias(threads: int, ref_n: int) -> None:
    from bench.maps import droste_map, exp_map

    path = DETAIL if DETAIL.exists() else SAMPLE
    with Image.open(path) as im:
        img = np.ascontiguousarray(np.asarray(im.convert("RGB")))
    h, w = img.shape[:2]
    print(
        f"\n== anti-aliasing on {path.name} ({w}x{h}), against uniform {ref_n}x{ref_n}", flush=True
    )
    em, ename = exp_map(4.0)
    dm, dname = droste_map(3.0)
    cases = [
        ("zoom x8", Mobius.zoom((0.0, 0.0), 8.0).inverse(), "Mobius.zoom((0, 0), 8).inverse()"),
        ("exp variant lam=4", em, ename),
        ("Droste scale 3", dm, dname),
        ("rotation", Mobius.from_yaw_pitch_roll(*YPR), "Mobius.from_yaw_pitch_roll"),
    ]
    for name, m, src in cases:
        ref = warp(img, m, antialias=ref_n, threads=threads)
        # where the footprint covers more than one input pixel (the aliasing region)
        cols = np.arange(w) + 0.5
        px = np.stack(np.broadcast_arrays(cols[None, :], np.arange(h)[:, None] + 0.5), -1)
        zw = coords.cp1_from_lonlat(coords.lonlat_from_pixel(px, w, h))
        shrink = np.nan_to_num(m.local_scale(zw), nan=1e6, posinf=1e6) > 1.0 + 1e-6
        res = {}
        for label, aa in (("none", "none"), ("auto", "auto"), ("adaptive", "adaptive"),
                          ("area", "area"), ("uniform 4x4", 4)):  # fmt: skip
            tm = measure(lambda aa=aa: warp(img, m, antialias=aa, threads=threads), 3)
            out = warp(img, m, antialias=aa, threads=threads)
            res[label] = (psnr(out, ref), psnr(out, ref, shrink) if shrink.any() else None, tm)
        for label, (p, ps, tm) in res.items():
            row("antialias", f"{name}: {label}", (w, h), threads, tm,
                psnr_db=p, psnr_shrinking_db=ps, map=src,
                time_vs_uniform4=tm["s"] / res["uniform 4x4"][2]["s"],
                time_vs_none=tm["s"] / res["none"][2]["s"])  # fmt: skip
            print(
                f"      PSNR {p:6.2f} dB"
                + (f", where shrinking ({shrink.mean():.0%} of pixels) {ps:6.2f} dB" if ps else ""),
                flush=True,
            )


def bench_scaling(threads_list: list[int], repeat: int) -> None:
    m = Mobius.from_yaw_pitch_roll(*YPR)
    print("\n== scaling with output size (on the fly, 1 thread, no anti-aliasing)", flush=True)
    img = load_image(4096)
    for wo in (1024, 2048, 4096, 8192):
        row("scaling", "spherewarp on the fly, output", (wo, wo // 2), 1, measure(
            lambda wo=wo: warp(img, m, output_shape=(wo // 2, wo), antialias="none", threads=1),
            repeat))  # fmt: skip


def bench_cli(width: int) -> None:
    ff = shutil.which("ffmpeg")
    sw = shutil.which("spherewarp")
    if ff is None or sw is None:
        print("\n== CLI: skipped (ffmpeg or spherewarp not on PATH)")
        return
    print(f"\n== command line, {width}x{width // 2} JPEG, end to end (decode, rotate, encode)")
    with tempfile.TemporaryDirectory() as d:
        src = Path(d) / "in.jpg"
        Image.fromarray(load_image(width)).save(src, quality=95)
        y, p, r = YPR
        cmds = {
            "ffmpeg -vf v360": [ff, "-v", "error", "-y", "-i", str(src), "-vf",
                                f"v360=e:e:yaw={y}:pitch={p}:roll={r}", "-q:v", "2",
                                str(Path(d) / "ff.jpg")],
            "spherewarp rotate": [sw, "rotate", str(src), "--yaw", str(y), "--pitch", str(p),
                                  "--roll", str(r), "-o", str(Path(d) / "sw.jpg"), "--overwrite"],
        }  # fmt: skip
        for name, cmd in cmds.items():
            times = []
            for _ in range(3):
                t = time.perf_counter()
                subprocess.run(cmd, check=True, capture_output=True)
                times.append(time.perf_counter() - t)
            row("cli", name, (width, width // 2), None,
                {"s": min(times), "s_median": statistics.median(times)},
                first_run_ms=1e3 * times[0])  # fmt: skip


def add_ratios() -> None:
    """Each row's time relative to cv2.remap (fixed-point maps) of the same size and threads."""
    ref = {
        (r["size"], r["threads"]): r["ms"]
        for r in ROWS
        if r["case"] == "cv2.remap fixed-point maps"
    }
    for r in ROWS:
        base = ref.get((r["size"], r["threads"]))
        if base:
            r["x_cv2_fixed"] = r["ms"] / base


def print_table() -> None:
    print(f"\n{'case':<52} {'size':>9} {'thr':>3} {'ms':>9} {'Mpix/s':>8} {'x cv2':>6} {'peak':>9}")
    for r in ROWS:
        ratio = f"{r['x_cv2_fixed']:6.2f}" if "x_cv2_fixed" in r else " " * 6
        peak = f"+{r['peak_mib']:.0f} MiB" if "peak_mib" in r else ""
        name = f"{r['group']}: {r['case']}"[:52]
        print(
            f"{name:<52} {r['size']:>9} {r['threads']!s:>3} {r['ms']:9.1f} "
            f"{r['mpix_s']:8.1f} {ratio} {peak:>9}"
        )


def summary() -> list[str]:
    """The issue's targets, as ratios from this run."""

    def get(group: str, case: str, size: str, threads: int | None) -> float | None:
        for r in ROWS:
            if (r["group"], r["case"], r["size"], r["threads"]) == (group, case, size, threads):
                return r["ms"]
        return None

    lines = []
    sizes = sorted(
        {r["size"] for r in ROWS if r["group"] == "rotate"}, key=lambda s: int(s.split("x")[0])
    )
    for size in sizes:
        for t in sorted(
            {r["threads"] for r in ROWS if r["group"] == "rotate" and r["size"] == size}
        ):
            cached = get("rotate", "spherewarp cached (WarpMap.apply)", size, t)
            fly = get("rotate", "spherewarp on the fly", size, t)
            fixed = get("rotate", "cv2.remap fixed-point maps", size, t)
            flt = get("rotate", "cv2.remap float32 maps", size, t)
            v360 = get("rotate", "ffmpeg v360 per frame", size, t)
            if cached and v360:
                lines.append(
                    f"{size} t={t}: cached / v360 per frame = {cached / v360:.2f} (target <= 0.85)"
                )
            if cached and fixed:
                lines.append(
                    f"{size} t={t}: cached / cv2 fixed = {cached / fixed:.2f} (target <= 1.0)"
                )
            if fly and fixed:
                lines.append(
                    f"{size} t={t}: on the fly / cv2 fixed = {fly / fixed:.2f}, "
                    f"/ cv2 float = {fly / flt:.2f} (target <= 2.5)"
                )
        f1 = get("rotate", "spherewarp on the fly", size, 1)
        f2 = get("rotate", "spherewarp on the fly", size, 2)
        if f1 and f2:
            lines.append(
                f"{size}: on the fly, 1 thread / 2 threads = {f1 / f2:.2f} (target >= 1.7)"
            )
        c1 = get("rotate", "spherewarp cached (WarpMap.apply)", size, 1)
        c2 = get("rotate", "spherewarp cached (WarpMap.apply)", size, 2)
        if c1 and c2:
            lines.append(f"{size}: cached, 1 thread / 2 threads = {c1 / c2:.2f} (target >= 1.7)")
    for size in sizes:
        for t in sorted({r["threads"] for r in ROWS if r["size"] == size} - {None}):
            fixed = get("rotate", "cv2.remap fixed-point maps", size, t)
            for name, (_, target) in effect_maps().items():
                cases = [f"on the fly, {name}, AA {aa}" for aa in ("auto", "none")]
                for case in [*cases, f"compiled stages, {name}, AA none"]:
                    ms = get("rotate", f"spherewarp {case}", size, t)
                    if ms and fixed:
                        lines.append(
                            f"{size} t={t}: {case} / cv2 fixed = {ms / fixed:.2f} "
                            f"(target <= {target:g})"
                        )
    for r in ROWS:
        if r["group"] == "memory":
            lines.append(
                f"{r['size']} t={r['threads']} {r['case']}: peak +{r['peak_mib']:.0f} MiB above "
                f"the input, {r['overhead_mib']:.0f} MiB beyond the output (target <= 300)"
            )
    for t in sorted({r["threads"] for r in ROWS if r["group"] == "zoom8"}):
        for size in sorted({r["size"] for r in ROWS if r["group"] == "zoom8"}):
            a = get("zoom8", "spherewarp rotation, antialias auto", size, t)
            n = get("zoom8", "spherewarp rotation, antialias none", size, t)
            if a and n:
                lines.append(f"{size} t={t}: rotation AA auto / none = {a / n:.2f} (target <= 1.5)")
            ar = get("zoom8", "spherewarp rotation, antialias area", size, t)
            if ar and n:
                lines.append(f"{size} t={t}: rotation AA area / none = {ar / n:.2f}")
            z = {
                k: get("zoom8", f"spherewarp zoom x8, antialias {k}", size, t)
                for k in ("none", "auto", "adaptive", "area", "uniform 4x4")
            }
            if all(z.values()):
                lines.append(
                    f"{size} t={t}: zoom x8 auto / 4x4 = {z['auto'] / z['uniform 4x4']:.2f}, "
                    f"adaptive / 4x4 = {z['adaptive'] / z['uniform 4x4']:.2f}, "
                    f"area / 4x4 = {z['area'] / z['uniform 4x4']:.2f}, "
                    f"auto / none = {z['auto'] / z['none']:.2f}"
                )
    aa = [r for r in ROWS if r["group"] == "antialias"]
    for name in dict.fromkeys(r["case"].split(":")[0] for r in aa):
        res = {r["case"].split(": ")[1]: r for r in aa if r["case"].startswith(name + ":")}
        if {"auto", "uniform 4x4", "none"} <= set(res):
            a, u, n = res["auto"], res["uniform 4x4"], res["none"]
            lines.append(
                f"AA {name}: PSNR none {n['psnr_db']:.2f} / auto {a['psnr_db']:.2f} / "
                f"4x4 {u['psnr_db']:.2f} dB (target auto >= 4x4 - 0.5); "
                f"time auto / 4x4 = {a['time_vs_uniform4']:.2f} (target <= 0.25)"
            )
            for k in ("area", "adaptive"):
                if k in res:
                    ar = res[k]
                    lines.append(
                        f"AA {name}: {k} {ar['psnr_db']:.2f} dB (4x4 - 0.5 = "
                        f"{u['psnr_db'] - 0.5:.2f}), time {k} / 4x4 = "
                        f"{ar['time_vs_uniform4']:.2f}, {k} / none = {ar['time_vs_none']:.1f}"
                    )
    for size in sorted({r["size"] for r in ROWS if r["group"] == "cli"}):
        s = get("cli", "spherewarp rotate", size, None)
        f = get("cli", "ffmpeg -vf v360", size, None)
        if s and f:
            lines.append(f"CLI {size}: ffmpeg / spherewarp = {f / s:.2f} (target >= 1, goal 2)")
    return lines


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="4096x2048 only, fewer repeats, no CLI")
    ap.add_argument("--repeat", type=int, default=None, help="timed runs per case (min is kept)")
    ap.add_argument("--threads", default="1,2", help="thread counts, e.g. 1,2")
    ap.add_argument("--only", default="", help="comma list of: rotate,memory,antialias,scaling,cli")
    ap.add_argument("--memory-case", default=None, help=argparse.SUPPRESS)
    ap.add_argument("--width", type=int, default=8192, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.memory_case:
        print(json.dumps(memory_case(args.memory_case, args.width, int(args.threads))))
        return
    threads = [int(t) for t in args.threads.split(",")]
    repeat = args.repeat or (3 if args.quick else 7)
    only = set(filter(None, args.only.split(",")))
    want = lambda g: not only or g in only  # noqa: E731
    jit = "on" if fast.available() else "off"
    cpu = platform.processor() or platform.machine()
    print(f"spherewarp bench: {cpu}, {os.cpu_count()} CPUs, numba {jit}", flush=True)
    t0 = time.perf_counter()
    warp(np.zeros((8, 16, 3), np.uint8), Mobius.zoom((0, 0), 2))  # load the compiled kernels
    print(
        f"first render (imports, compiled kernels from the cache): {time.perf_counter() - t0:.2f} s"
    )
    if want("rotate"):
        bench_rotation(4096, threads, repeat, numpy_ref=True)
        bench_effects(4096, threads, repeat)
        if not args.quick:
            bench_rotation(8192, threads, max(2, repeat // 2), numpy_ref=True)
    if want("memory") and not args.quick:
        bench_memory(8192, max(threads))
    if want("antialias"):
        bench_antialias(max(threads), 8 if args.quick else 16)
    if want("scaling") and not args.quick:
        bench_scaling(threads, repeat)
    if want("cli") and not args.quick:
        bench_cli(8192)
    add_ratios()
    print_table()
    out = HERE / "results"
    out.mkdir(exist_ok=True)
    stamp = _dt.datetime.now().strftime("%Y%m%d-%H%M%S")
    meta = {
        "date": stamp,
        "machine": platform.machine(),
        "cpus": os.cpu_count(),
        "python": sys.version.split()[0],
        "numpy": np.__version__,
        "numba": __import__("numba").__version__ if fast.available() else None,
        "opencv": cv2.__version__ if cv2 is not None else None,
        "pyav": av.__version__ if av is not None else None,
        "quick": args.quick,
    }
    path = out / f"bench-{stamp}{'-quick' if args.quick else ''}.json"
    # the measurements first: a fault in the summary must not lose them
    path.write_text(json.dumps({"meta": meta, "rows": ROWS}, indent=1))
    lines = summary()
    print("\n== targets (ratios from this run)")
    for line in lines:
        print("  " + line)
    path.write_text(json.dumps({"meta": meta, "rows": ROWS, "summary": lines}, indent=1))
    print(f"\nwrote {path}")


if __name__ == "__main__":
    main()
