"""Regenerate the README pictures in docs/images from the demo effects.

Run from the repository root:  python docs/make_images.py
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from PIL import Image

from spherewarp.demo import run_demo

OUT = Path(__file__).parent / "images"
PICKS = {  # demo file stem -> README picture
    "01-original": "original.jpg",
    "05-zoom-picture": "zoom.jpg",
    "09-power-2-branch-point": "power-2.jpg",
    "11-droste": "droste.jpg",
    "12-droste-twisted": "droste-twisted.jpg",
    "13-lattes-square": "lattes.jpg",
    "15-peirce-torus": "peirce-torus.jpg",
}

#: the README's Schottky picture, the paper's mask workflow: the TV's screen (red) and the
#: framed picture (green) as the disks D_a, D_b, each outside zoomed into a disk round the
#: region's antipode (the window and the mirror)
SCHOTTKY = ["--mask", "src/spherewarp/data/interior-mask.png", "--target", "red", "40",
            "--target", "green", "60"]  # fmt: skip


def main() -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        run_demo(Path(tmp) / "demo", supersample=3, echo=None)
        for path in sorted((Path(tmp) / "demo").glob("*.png")):
            stem = path.stem
            pixels = np.asarray(Image.open(path).convert("RGB"))
            if stem == "02-testpattern":
                Image.fromarray(pixels).save(OUT / "testpattern.png", optimize=True)
            elif stem in PICKS:
                Image.fromarray(pixels).save(OUT / PICKS[stem], quality=82, optimize=True)
        # a little planet framed by a Mobius zoom (the nadir shrunk to 3/4: more sky round it)
        planet, src = Path(tmp) / "planet.png", Path(tmp) / "demo" / "01-original.png"
        subprocess.run(
            [sys.executable, "-m", "spherewarp", "zoom", str(src), "--at", "0,-90", "--factor",
             "0.75", "--projection", "little-planet", "--size", "512x512", "-q", "-o", str(planet)],
            check=True,
        )  # fmt: skip
        pixels = np.asarray(Image.open(planet).convert("RGB"))
        Image.fromarray(pixels).save(OUT / "little-planet.jpg", quality=82, optimize=True)
        # a Schottky group from the bundled mask
        schottky = Path(tmp) / "schottky.png"
        subprocess.run(
            [sys.executable, "-m", "spherewarp", "schottky", str(src), *SCHOTTKY, "--size",
             "1024x512", "--supersample", "2", "-q", "-o", str(schottky)],
            check=True,
        )  # fmt: skip
        pixels = np.asarray(Image.open(schottky).convert("RGB"))
        Image.fromarray(pixels).save(OUT / "schottky.jpg", quality=82, optimize=True)
    print("\n".join(sorted(p.name for p in OUT.iterdir())))


if __name__ == "__main__":
    main()
