"""Make ``src/spherewarp/data/interior-mask.png``: the Schottky mask of the bundled interior.

The paper's Schottky workflow traces the disks ``D_x`` over the panorama in one colour each
(its window red, its mirror green). Here the television's screen is red and the framed
picture on the wall green: each region is the spherical quadrilateral (geodesic edges) whose
corners were read off ``interior.png`` (pixel coordinates below), the rest black. Run from the
repository root: ``python tools/make_interior_mask.py``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PIL import Image

from spherewarp import coords

W, H = 1024, 512
#: (colour, corners in pixel coordinates of interior.png, clockwise from the top left)
REGIONS = [
    ((255, 0, 0), [(276, 223), (381, 222), (381, 281), (276, 281)]),  # the television's screen
    ((0, 255, 0), [(21, 200), (74, 196), (74, 290), (21, 295)]),  # the framed picture
]


def _xyz(px: np.ndarray) -> np.ndarray:
    return coords.xyz_from_lonlat(coords.lonlat_from_pixel(np.asarray(px, float), W, H))


def make_mask() -> np.ndarray:
    """The mask: a pixel takes a region's colour when its centre lies in the quadrilateral."""
    ys, xs = np.mgrid[0:H, 0:W] + 0.5
    centres = _xyz(np.stack([xs.ravel(), ys.ravel()], axis=-1))
    mask = np.zeros((H * W, 3), np.uint8)
    for colour, corners in REGIONS:
        c = _xyz(corners)
        inside = np.ones(len(centres), bool)
        for i in range(len(c)):
            normal = np.cross(c[i], c[(i + 1) % len(c)])  # the great circle through an edge
            if normal @ c.mean(axis=0) < 0:
                normal = -normal
            inside &= centres @ normal >= 0
        mask[inside] = colour
    return mask.reshape(H, W, 3)


if __name__ == "__main__":
    out = Path("src/spherewarp/data/interior-mask.png")
    Image.fromarray(make_mask()).save(out, optimize=True)
    print(f"wrote {out}")
