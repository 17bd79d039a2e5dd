# ruff: noqa: B023  (lambdas are called at once, inside the loop)
"""Speed of the default filter and of the other interpolations (issue 16, item 7).

    python bench/speed.py [--width 4096] [--threads 1] [--repeat 3] [--ref 16] [--clock cpu]

Side by side in one process, on an RGB uint8 equirectangular image:

* interpolations: a rotation (nothing shrinks: one tap a pixel) with ``interp``
  nearest / bilinear / bicubic, beside ``cv2.remap`` (fixed-point maps) doing the
  same; the goal is bicubic within 2x of bilinear, nearest no slower;
* a plain zoom by 2.5 (``Mobius.zoom((0, 0), 2.5)``, shrinking round its antipode)
  with ``antialias="auto"`` (the area filter) against ``"none"``: goal auto within 2x;
* the exp variant (``ExpMap(4)``, the paper's) with ``"auto"`` against uniform
  4x4 supersampling: goal <= 0.3x; and its PSNR against 16x16 supersampling on
  forest.png (1024x512) beside 4x4's (``auto`` within 0.5 dB of what it was).

Prints the figures and the ratios and writes them as JSON to
``bench/results/speed-DATE.json``.
"""

from __future__ import annotations

import argparse
import datetime as _dt
import json
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "src"))
sys.path.insert(0, str(HERE.parent))

from bench.maps import exp_map  # noqa: E402
from bench.run import DETAIL, SAMPLE, load_image, pixel_maps, psnr  # noqa: E402
from spherewarp.maps import Mobius  # noqa: E402
from spherewarp.render import warp  # noqa: E402

ZOOM = "zoom 2.5 spherewarp"
EXP = "exp variant spherewarp"

try:
    import cv2
except ImportError:  # pragma: no cover
    cv2 = None


CLOCK = time.perf_counter


def best(fn, repeat: int) -> float:
    fn()
    times = []
    for _ in range(repeat):
        t0 = CLOCK()
        fn()
        times.append(CLOCK() - t0)
    return min(times)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--width", type=int, default=4096)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--ref", type=int, default=16, help="supersampling of the PSNR reference")
    ap.add_argument("--only", default="interp,zoom,exp,quality")
    ap.add_argument(
        "--sliver",
        type=float,
        default=None,
        help="set antialias.AREA_SLIVER_BOX (the area filter's sliver taps; 0: off)",
    )
    ap.add_argument(
        "--clock",
        choices=("wall", "cpu"),
        default="wall",
        help="cpu: the process's CPU time (time.process_time), steadier than the wall clock "
        "on a shared machine; the same as wall for one thread on an idle one",
    )
    a = ap.parse_args()
    global CLOCK
    CLOCK = time.process_time if a.clock == "cpu" else time.perf_counter
    if a.sliver is not None:
        from spherewarp.render import antialias

        antialias.AREA_SLIVER_BOX = a.sliver
    only = set(a.only.split(","))
    w = a.width
    h = w // 2
    t = a.threads
    img = load_image(w)
    res: dict[str, float] = {}

    def case(name: str, fn) -> float:
        s = best(fn, a.repeat)
        res[name] = s
        print(f"{name:48s} {s * 1e3:9.1f} ms", flush=True)
        return s

    if cv2 is not None:
        cv2.setNumThreads(t)
    rot = Mobius.from_yaw_pitch_roll(30.0, 20.0, 10.0)
    zoom = Mobius.zoom((0.0, 0.0), 2.5)
    print(f"{w}x{h} uint8 RGB, {t} thread(s), minimum of {a.repeat}")
    if "interp" in only:
        if cv2 is not None:
            mx, my = pixel_maps(h, w, rot)
            m1, m2 = cv2.convertMaps(mx, my, cv2.CV_16SC2)
            for name, flag in (("nearest", cv2.INTER_NEAREST), ("bilinear", cv2.INTER_LINEAR),
                               ("bicubic", cv2.INTER_CUBIC)):  # fmt: skip
                case(f"rotation cv2.remap {name}",
                     lambda: cv2.remap(img, m1, m2, flag, borderMode=cv2.BORDER_WRAP))  # fmt: skip
        for name in ("nearest", "bilinear", "bicubic"):
            case(f"rotation spherewarp {name}", lambda: warp(img, rot, interp=name, threads=t))
    if "zoom" in only:
        if cv2 is not None:
            mx, my = pixel_maps(h, w, zoom)
            m1, m2 = cv2.convertMaps(mx, my, cv2.CV_16SC2)
            case(
                "zoom 2.5 cv2.remap bilinear",
                lambda: cv2.remap(img, m1, m2, cv2.INTER_LINEAR, borderMode=cv2.BORDER_WRAP),
            )
        for aa in ("none", "auto"):
            case(f"{ZOOM} antialias {aa}", lambda: warp(img, zoom, antialias=aa, threads=t))
    em, ename = exp_map(4.0)
    if "exp" in only:
        for aa in ("none", "auto", 4):
            case(f"{EXP} antialias {aa}",
                 lambda: warp(img, em, antialias=aa, threads=t))  # fmt: skip
    quality: dict[str, float] = {}
    if "quality" in only:
        from PIL import Image

        path = DETAIL if DETAIL.exists() else SAMPLE
        with Image.open(path) as im:
            det = np.ascontiguousarray(np.asarray(im.convert("RGB").resize((1024, 512))))
        for mname, m in (("exp variant", em), ("zoom 2.5", zoom)):
            ref = warp(det, m, antialias=a.ref)
            for aa in ("none", "auto", 4):
                quality[f"{mname} {aa}"] = p = psnr(warp(det, m, antialias=aa), ref)
                print(f"PSNR {mname} antialias {aa} vs {a.ref}x{a.ref} on {path.name} "
                      f"1024x512: {p:.2f} dB", flush=True)  # fmt: skip

    def ratio(x: str, y: str) -> float | None:
        return res[x] / res[y] if x in res and y in res else None

    pairs = [
        ("bicubic / bilinear", "rotation spherewarp bicubic", "rotation spherewarp bilinear"),
        ("nearest / bilinear", "rotation spherewarp nearest", "rotation spherewarp bilinear"),
        ("bilinear / cv2 bilinear", "rotation spherewarp bilinear", "rotation cv2.remap bilinear"),
        ("bicubic / cv2 bicubic", "rotation spherewarp bicubic", "rotation cv2.remap bicubic"),
        ("nearest / cv2 nearest", "rotation spherewarp nearest", "rotation cv2.remap nearest"),
        ("zoom auto / none", f"{ZOOM} antialias auto", f"{ZOOM} antialias none"),
        ("zoom auto / cv2", f"{ZOOM} antialias auto", "zoom 2.5 cv2.remap bilinear"),
        ("zoom none / cv2", f"{ZOOM} antialias none", "zoom 2.5 cv2.remap bilinear"),
        ("exp auto / 4x4", f"{EXP} antialias auto", f"{EXP} antialias 4"),
        ("exp auto / none", f"{EXP} antialias auto", f"{EXP} antialias none"),
    ]
    ratios = {k: ratio(x, y) for k, x, y in pairs}
    print()
    for k, v in ratios.items():
        if v is not None:
            print(f"{k:28s} {v:6.2f}")
    out = HERE / "results" / f"speed-{_dt.datetime.now():%Y%m%d-%H%M%S}.json"
    out.parent.mkdir(exist_ok=True)
    out.write_text(
        json.dumps(
            {"size": [w, h], "threads": t, "clock": a.clock, "seconds": res, "ratios": ratios,
             "psnr_db": quality, "exp_map": ename, "sliver_box": a.sliver},
            indent=1,
        )
    )  # fmt: skip
    print(f"\nwritten {out.relative_to(HERE.parent)}")


if __name__ == "__main__":
    main()
