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
        report[name] = {"psnr_db": psnr, "seconds": times, "bins": rows}
    out = HERE / "results" / f"aa-profile-{time.strftime('%Y%m%d-%H%M%S')}.json"
    out.parent.mkdir(exist_ok=True)
    out.write_text(json.dumps(report, indent=1))
    print(f"\nwrote {out}")


if __name__ == "__main__":
    main()
