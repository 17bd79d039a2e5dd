"""Where the anti-aliasing error comes from: a profile of target 6 of issue 4.

For each case of ``bench/run.py``'s anti-aliasing benchmark (a zoom by 8, the
exp variant, a Droste map, a rotation) this renders ``antialias="none"``,
``"auto"``, ``"area"`` and uniform 4x4 against a 16x16 supersampled reference
and splits each one's squared error by the pixel's *footprint*: how many
input pixels (along its larger axis, in the input's own chart) the output
pixel covers. ``"area"`` averages the bilinear surface over each pixel's
footprint in closed form, which is what the 16x16 reference converges to
wherever the map is smooth over a pixel.

    python bench/aa_profile.py            # about 2 minutes on 2 cores

Each case also profiles the cost of ``"area"`` with one thread: its base (every
pixel one area tap) and its parts (footprints longer than 2 input pixels are
split, each part pulled back through the map), with how many parts there are
and where they come from: what bounds ``auto``'s time on the exp variant.

The table shows where ``adaptive`` loses: pixels with footprints between 1/4
and 1 input pixel, where ``adaptive`` (like any renderer that only filters
where the map shrinks) takes one bilinear tap and the reference averages the
bilinear surface over the pixel; a rotation is all such pixels. That is why
``auto`` is ``area`` for a map that shrinks somewhere (and ``adaptive``, a
bilinear tap a pixel, for a rotation).
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import numpy as np
from PIL import Image

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))

from bench.maps import droste_map, exp_map  # noqa: E402
from bench.run import DETAIL, SAMPLE  # noqa: E402
from spherewarp import coords, warp  # noqa: E402
from spherewarp.maps import Mobius  # noqa: E402
from spherewarp.render import antialias as _aa  # noqa: E402

BINS = [0.0, 0.25, 0.5, 1.0, 2.0, 4.0, np.inf]


def _source_uv(m, w: int, h: int, ox: float = 0.5, oy: float = 0.5):
    px = np.stack(np.broadcast_arrays(np.arange(w)[None, :] + ox, np.arange(h)[:, None] + oy), -1)
    pb = m.pull(coords.cp1_from_lonlat(coords.lonlat_from_pixel(px, w, h)))
    xy = coords.pixel_from_lonlat(coords.lonlat_from_cp1(pb.points), w, h)
    return xy[..., 0] - 0.5, xy[..., 1] - 0.5


def footprint(m, w: int, h: int):
    """Source tap coordinates and the footprint's box widths (input pixels) per pixel."""
    u, v = _source_uv(m, w, h)
    e = 0.05
    ux, vx = _source_uv(m, w, h, 0.5 + e, 0.5)
    uy, vy = _source_uv(m, w, h, 0.5, 0.5 + e)

    def wrap(d):
        return (d + w / 2) % w - w / 2

    j00, j10 = wrap(ux - u) / e, (vx - v) / e
    j01, j11 = wrap(uy - u) / e, (vy - v) / e
    return u, v, np.hypot(j00, j01), np.hypot(j10, j11)


def _thread_ms(fn, repeat: int = 5) -> float:
    """Least CPU time of ``repeat`` runs (after one warm-up), in ms: steadier than wall
    time on a shared machine (run with threads=1). The process's CPU time: the kernels
    run on a pool thread (``fast._run``), so the calling thread's own time
    (``time.thread_time``, used here before) measured only its waiting."""
    fn()
    best = np.inf
    for _ in range(repeat):
        t0 = time.process_time()
        fn()
        best = min(best, time.process_time() - t0)
    return 1e3 * best


def cost_profile(img: np.ndarray, m) -> dict:
    """What ``antialias="area"`` spends its time on, with one thread: the base (every
    pixel one area tap: the split into parts capped at 1) and the parts (the rest), with
    how many parts there are and where their pixels' source points lie. The cap is
    lowered through ``antialias.AUTO_MAX``, which the compiled renderer reads at each
    call (the maps here have compiled stages)."""
    h, w = img.shape[:2]
    px = np.stack(np.broadcast_arrays(np.arange(w)[None, :] + 0.5, np.arange(h)[:, None] + 0.5), -1)
    lonlat = coords.lonlat_from_pixel(px, w, h)
    zw = coords.cp1_from_lonlat(lonlat)
    pb = m.pull(zw)
    uv = coords.pixel_from_lonlat(coords.lonlat_from_cp1(pb.points), w, h) - 0.5
    # as the renderer counts them: with the magnification (footprints smaller than it says
    # are jumps, plain taps) and without the slivers (one tap of their box: not parts; their
    # bend test aside)
    scale = np.nan_to_num(m.local_scale(zw), nan=1.0, posinf=1e6)
    J, nx, ny = _aa.area_footprints(uv[..., 0], uv[..., 1], pb.valid, lonlat[:, 0, 1], (h, w),
                                    (h, w), scale=scale)  # fmt: skip
    split = nx * ny > 1
    cos_src = np.sin(np.pi * (uv[..., 1] + 0.5) / h)
    sliver = (
        split & (np.hypot(J[2], J[3]) <= _aa.AREA_SLIVER_BOX) & (cos_src < _aa.AREA_SLIVER_ROWS)
    )
    parts = np.where(split & ~sliver, nx * ny, 0)
    polar = np.minimum(uv[..., 1] + 0.5, h - uv[..., 1] - 0.5) < 0.05 * h
    capped = np.maximum(nx, ny) >= _aa.AUTO_MAX
    t = {k: _thread_ms(lambda k=k: warp(img, m, antialias=k, threads=1)) for k in ("none", "area")}
    t["4x4"] = _thread_ms(lambda: warp(img, m, antialias=4, threads=1), 3)
    cap = _aa.AUTO_MAX
    try:
        _aa.AUTO_MAX = 1
        t["base"] = _thread_ms(lambda: warp(img, m, antialias="area", threads=1))
    finally:
        _aa.AUTO_MAX = cap
    n = int(parts.sum())
    return {
        "ms_1_thread": t,
        "parts": n,
        "sliver_pixels": float(sliver.mean()),
        "parts_per_pixel": n / parts.size,
        "parts_share_polar_5pct": float(parts[polar].sum() / max(n, 1)),
        "parts_share_capped": float(parts[capped].sum() / max(n, 1)),
        "ns_per_part": 1e6 * (t["area"] - t["base"]) / max(n, 1),
    }


def main() -> None:
    path = DETAIL if DETAIL.exists() else SAMPLE
    with Image.open(path) as im:
        img = np.ascontiguousarray(np.asarray(im.convert("RGB")))
    h, w = img.shape[:2]
    cases = {
        "zoom x8": Mobius.zoom((0.0, 0.0), 8.0).inverse(),
        "exp variant lam=4": exp_map(4.0)[0],
        "Droste scale 3": droste_map(3.0)[0],
        "rotation": Mobius.from_yaw_pitch_roll(30, 20, 10),
    }
    report = {}
    print(f"anti-aliasing error by footprint, {path.name} {w}x{h}, against 16x16")
    for name, m in cases.items():
        ref = warp(img, m, antialias=16).astype(np.float64)
        _, _, bx, by = footprint(m, w, h)
        fp = np.maximum(bx, by)
        outs, times = {}, {}
        for label, aa in (
            ("none", "none"), ("auto", "auto"), ("adaptive", "adaptive"), ("area", "area"),
            ("4x4", 4),
        ):  # fmt: skip
            t0 = time.perf_counter()
            outs[label] = warp(img, m, antialias=aa)
            times[label] = time.perf_counter() - t0
        err = {k: ((o.astype(np.float64) - ref) ** 2).mean(-1) for k, o in outs.items()}
        psnr = {k: 10 * np.log10(255.0**2 / e.mean()) for k, e in err.items()}
        print(f"\n== {name}: PSNR " + ", ".join(f"{k} {p:.2f} dB" for k, p in psnr.items()))
        print("   footprint      pixels   mean squared error: " + " / ".join(err))
        rows = []
        for lo, hi in zip(BINS[:-1], BINS[1:], strict=True):
            sel = (fp >= lo) & (fp < hi)
            if not sel.any():
                continue
            mse = {k: float(e[sel].mean()) for k, e in err.items()}
            share = {k: float(e[sel].sum() / e.sum()) for k, e in err.items()}
            rows.append({"footprint": [lo, hi], "pixels": float(sel.mean()), "mse": mse,
                         "share_of_error": share})  # fmt: skip
            print(
                f"   [{lo:4.2f}, {hi:4.2f})  {sel.mean():6.1%}   "
                + " / ".join(f"{mse[k]:7.3f} ({share[k]:4.0%})" for k in err)
            )
        cost = cost_profile(img, m)
        t = cost["ms_1_thread"]
        print(
            f"   cost of area, 1 thread (CPU time): {t['area']:.1f} ms = base {t['base']:.1f} ms "
            f"(one tap a pixel) + parts {t['area'] - t['base']:.1f} ms ({cost['parts'] / 1e6:.2f} M"
            f" parts, {cost['parts_per_pixel']:.2f} a pixel, {cost['ns_per_part']:.0f} ns each, "
            f"slivers aside: {cost['sliver_pixels']:.0%} of the pixels; "
            f"{cost['parts_share_polar_5pct']:.0%} from pixels whose source lies within 5% of "
            f"the rows from a pole of the input, {cost['parts_share_capped']:.0%} from pixels "
            f"split {_aa.AUTO_MAX} ways along an axis, the cap); none {t['none']:.1f} ms, "
            f"4x4 {t['4x4']:.1f} ms: area / 4x4 = {t['area'] / t['4x4']:.2f}, "
            f"base / 4x4 = {t['base'] / t['4x4']:.2f}"
        )
        report[name] = {"psnr_db": psnr, "seconds": times, "bins": rows, "area_cost": cost}
    out = HERE / "results" / f"aa-profile-{time.strftime('%Y%m%d-%H%M%S')}.json"
    out.parent.mkdir(exist_ok=True)
    out.write_text(json.dumps(report, indent=1))
    print(f"\nwrote {out}")


if __name__ == "__main__":
    main()
