"""The viewer's shader frame time (issue 21), against the Python renderer in the same run.

Headless chromium (Debian's, via Playwright) with SwiftShader's software WebGL here;
set SPHEREWARP_CHROMIUM_ARGS to try a GPU (e.g. "--use-angle=vulkan"). The source is a
4096x2048 texture (the bundled courtyard, upscaled); each case renders the flat view at
the given size and sub-sampling, timed as draw + a 1-pixel readPixels (which waits for
the frame), the minimum of --repeat frames. The CPU column is ``Recipe.render`` of the
same recipe at that size (bilinear, antialias auto, all threads), the minimum of the
same number of runs.

    PYTHONPATH=src:/path/to/playwright python bench/viewer.py [--quick] [--repeat N]
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from PIL import Image

RECIPES = {
    "zoom": [{"zoom": {"at": [20, 10], "factor": 3}}],
    "droste twisted": [{"droste": {"center": [0, 0], "inner_radius": 20, "twist": True}}],
    "lattes 1+i": [{"lattes": {"alpha": "1+i"}}],
}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument(
        "--quick", action="store_true", help="4096x2048 (ss=1) for the first recipe only"
    )
    ap.add_argument("--repeat", type=int, default=2)
    args = ap.parse_args()

    from playwright.sync_api import sync_playwright

    from spherewarp.io.images import read_image
    from spherewarp.recipe import Recipe
    from spherewarp.viewer.server import ViewerServer

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "viewer"))
    from test_browser import ARGS, find_chromium

    extra = os.environ.get("SPHEREWARP_CHROMIUM_ARGS")
    launch_args = extra.split() if extra else ARGS
    tmp = Path(tempfile.mkdtemp())
    src = tmp / "courtyard-4096.png"
    base = Path(__file__).resolve().parents[1] / "src/spherewarp/data/courtyard.png"
    Image.open(base).convert("RGB").resize((4096, 2048), Image.BICUBIC).save(src)
    img = read_image(src)
    cases = [((4096, 2048), 1), ((1024, 512), 2), ((1024, 512), 1), ((256, 128), 2)]
    if not args.quick:
        cases.insert(1, ((4096, 2048), 2))
    srv = ViewerServer(src, None)
    rows = []
    with sync_playwright() as p:
        b = p.chromium.launch(executable_path=find_chromium(), args=launch_args)
        page = b.new_page(viewport={"width": 1400, "height": 900})
        page.goto(srv.url + "?view=flat&size=256x128")
        page.wait_for_function("window.spherewarp && window.spherewarp.ready")
        renderer = page.evaluate(
            "(() => { const g = document.createElement('canvas').getContext('webgl2');"
            " const e = g.getExtension('WEBGL_debug_renderer_info');"
            " return e ? g.getParameter(e.UNMASKED_RENDERER_WEBGL)"
            " : g.getParameter(g.RENDERER); })()"
        )
        print(f"WebGL renderer: {renderer}")
        for name, steps in RECIPES.items():
            recipe = {"spherewarp": 1, "steps": steps}
            page.evaluate(
                "r => { window.spherewarp.setRecipe(r); return window.spherewarp.settle(); }",
                recipe,
            )
            for (w, h), ss in cases:
                if args.quick and w > 1024 and name != next(iter(RECIPES)):
                    continue
                page.evaluate(
                    "([w, h, ss]) => { const S = window.spherewarp.S; S.size = [w, h];"
                    " S.ss = ss; }",
                    [w, h, ss],
                )
                page.evaluate("window.spherewarp.frameTime(1)")  # warm-up (resize, compile)
                gpu = min(
                    page.evaluate("window.spherewarp.frameTime(1)") for _ in range(args.repeat)
                )
                r = Recipe.from_dict({**recipe, "view": {"size": [w, h]}})
                cpu = []
                for _ in range(args.repeat):
                    t0 = time.perf_counter()
                    r.render(img)
                    cpu.append((time.perf_counter() - t0) * 1e3)
                row = {
                    "recipe": name, "size": f"{w}x{h}", "ss": ss, "shader_ms": gpu,
                    "cpu_ms": min(cpu), "shader_over_cpu": gpu / min(cpu),
                }  # fmt: skip
                rows.append(row)
                print(
                    f"{name:15s} {w}x{h:<5d} ss={ss}  shader {gpu:9.1f} ms  "
                    f"cpu {min(cpu):8.1f} ms  shader/cpu {gpu / min(cpu):6.2f}",
                    flush=True,
                )
        b.close()
    srv.close()
    out = Path(__file__).with_name("results") / f"viewer-{time.strftime('%Y%m%d-%H%M')}.json"
    load = os.getloadavg()[0]
    print(f"load average {load:.1f} on {os.cpu_count()} CPUs")
    data = {"renderer": renderer, "args": launch_args, "load": load, "rows": rows}
    out.write_text(json.dumps(data, indent=1))
    print(f"wrote {out}")


if __name__ == "__main__":
    np.seterr(all="ignore")
    main()
