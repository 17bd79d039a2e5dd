"""Repair the bundled sample panoramas: clamp EXR negatives, fill the ringing around lamps.

The sample HDRs (CC0, Greg Zaal / HDRI Haven, from Debian's ``blender-data``) were
downsampled with ``oiiotool --resize`` (a filter with negative lobes), clamped to
``[0, 32000]`` and stored with lossy DWAB compression. Next to the blown-out lamps
(linear values up to ~34000) the filter's negative lobes undershoot by hundreds, so
after the clamp some pixels have one or more channels at 0: black, blue, cyan and
yellow rings inside and around the lamps (and one-pixel dark lines along the sunlit
edges of ``courtyard``). DWAB then adds noise of about +-0.003, which leaves small
negative values all over the EXR.

This script, run from the repository root::

    python tools/repair_samples.py [--src ../shared/data/panoramas] [--dest src/spherewarp/data]

1. reads the original ``NAME.exr`` files from ``--src``;
2. clamps every channel to ``>= 0`` (NaN/inf are refused: the originals have none);
3. finds the ring pixels with :func:`ring_spots` on the tone-mapped image, and
   the fainter undershoot beside the lamps with :func:`lamp_dips`, and replaces
   each by the per-channel linear mean of its 8 neighbours that are not marked,
   peeling the marked set from its edge inwards (so a ring inside a
   lamp takes the lamp's blown-out value), rounded to half float (the precision
   of the originals); this is repeated until the detector finds nothing;
4. writes ``NAME.png`` (and ``NAME.exr`` where one is bundled) into ``--dest``.
   The PNG is derived from the repaired EXR exactly as the shipped PNG was derived
   from the original one (checked: ``tone_map`` reproduces the shipped PNGs bit for
   bit): Reinhard ``x / (1 + x)``, gamma ``1 / 2.2``, rounded to 8 bits. The EXR is
   written lossless (PIZ, half float: every original value is exactly a half, and
   DWAB would bring the negatives back), keeping the original header attributes.

It prints the ring pixels/spots, lamp dips and negative values before and after.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
from pathlib import Path

import numpy as np
import OpenEXR
from PIL import Image
from scipy import ndimage

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from bench.data import SHARED_PANORAMAS  # noqa: E402

#: bundled sample -> whether its EXR is bundled too (the PNG always is)
SAMPLES = {"interior": True, "courtyard": False}
DEFAULT_SRC = SHARED_PANORAMAS
HISTORY = "spherewarp tools/repair_samples.py: negatives clamped to 0, lamp ringing filled"
DEFAULT_DEST = Path(__file__).resolve().parents[1] / "src" / "spherewarp" / "data"

#: ring-spot detector thresholds, on the 8-bit tone-mapped image
DARK = 30  # a channel at most this (linear <= ~0.007): clamped by the undershoot
BRIGHT = 100  # median of the 8 neighbours' mean at least this: a bright neighbourhood
CLIPPED = 250  # a pixel with a channel at least this is blown out (linear >= ~22)
REACH = 4  # ... and one lies within this many pixels (Chebyshev)
#: lamp dips, found on the linear EXR: pixels within LAMP_REACH of a lamp (a linear value
#: >= LAMP) whose darkest channel is at most DIP times the median of their neighbours'
LAMP = 100.0
LAMP_REACH = 8
DIP = 0.7


def tone_map(linear: np.ndarray) -> np.ndarray:
    """Linear RGB -> the samples' 8-bit RGB: Reinhard ``x/(1+x)``, gamma 1/2.2, rounded."""
    c = np.clip(linear.astype(np.float64), 0.0, None)
    return np.round(255.0 * (c / (1.0 + c)) ** (1.0 / 2.2)).astype(np.uint8)


def _neighbours(a: np.ndarray, reach: int = 1) -> np.ndarray:
    """Stack of the ``(2 reach + 1)^2 - 1`` shifted copies of the 2-D ``a``.

    Longitude wraps (equirectangular), latitude repeats the edge rows.
    """
    h, w = a.shape
    p = np.pad(a, ((reach, reach), (0, 0)), mode="edge")
    p = np.concatenate([p[:, w - reach :], p, p[:, :reach]], axis=1)
    span = range(-reach, reach + 1)
    return np.stack(
        [
            p[reach + dy : reach + dy + h, reach + dx : reach + dx + w]
            for dy in span
            for dx in span
            if dy or dx
        ]
    )


def ring_spots(rgb8: np.ndarray) -> np.ndarray:
    """Boolean ``(H, W)`` mask of the ringing pixels of an 8-bit RGB panorama.

    A pixel is marked when one of its channels is nearly black (``<= DARK``) while
    its 8 neighbours are bright (median of their channel mean ``>= BRIGHT``) and a
    blown-out pixel (a channel ``>= CLIPPED``) lies within ``REACH`` pixels. A real
    photograph downsampled to 1024 x 512 has no such pixels: the lens glare and the
    averaging keep every channel well above black next to a light.
    """
    a = rgb8[..., :3].astype(np.int16)
    dark = a.min(axis=-1) <= DARK
    bright = np.median(_neighbours(a.mean(axis=-1)), axis=0) >= BRIGHT
    near_clipped = _neighbours(a.max(axis=-1) >= CLIPPED, REACH).any(axis=0)
    return dark & bright & near_clipped


def lamp_dips(linear: np.ndarray) -> np.ndarray:
    """Boolean ``(H, W)`` mask of the fainter ringing beside the lamps of a linear panorama.

    The undershoot that did not reach black: a channel that dips below ``DIP`` times
    the median of its neighbours (on the tone-mapped values) in a bright neighbourhood
    within ``LAMP_REACH`` pixels of a lamp (linear ``>= LAMP``; the sunlit wall of
    ``courtyard``, at most ~55, is no lamp). Only the linear image tells a lamp from
    a merely clipped pixel, so this one needs the EXR.
    """
    rgb8 = tone_map(linear).astype(np.int16)
    darkest = rgb8.min(axis=-1).astype(np.float64)
    dip = darkest <= DIP * np.median(_neighbours(darkest), axis=0)
    bright = np.median(_neighbours(rgb8.mean(axis=-1)), axis=0) >= BRIGHT
    near_lamp = _neighbours(linear.max(axis=-1) >= LAMP, LAMP_REACH).any(axis=0)
    return dip & bright & near_lamp


def count_spots(mask: np.ndarray) -> int:
    """Number of 8-connected groups in ``mask``."""
    return int(ndimage.label(mask, structure=np.ones((3, 3)))[1])


def fill(linear: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """Replace the ``mask`` pixels by the mean of their unmasked 8 neighbours, edge inwards."""
    out = linear.copy()
    todo = mask.copy()
    while todo.any():
        known = (~todo).astype(np.float64)
        weight = _neighbours(known).sum(axis=0)
        ready = todo & (weight > 0)
        if not ready.any():  # a fully masked image: nothing to fill from
            break
        for ch in range(out.shape[2]):
            total = _neighbours(out[..., ch] * known).sum(axis=0)
            out[..., ch][ready] = (total[ready] / weight[ready]).astype(out.dtype)
        todo &= ~ready
    return out


def repair(linear: np.ndarray, rounds: int = 10) -> np.ndarray:
    """Clamp negatives to 0, then fill ring spots and lamp dips until none is left."""
    if not np.isfinite(linear).all():
        raise ValueError("the EXR has NaN or infinite values")
    out = np.clip(linear, 0.0, None)
    for _ in range(rounds):
        mask = ring_spots(tone_map(out)) | lamp_dips(out)
        if not mask.any():
            break
        # rounded to half floats, the precision of every original value
        out = fill(out, mask).astype(np.float16).astype(np.float32)
    return out


def read_exr(path: Path) -> tuple[np.ndarray, dict]:
    """``(H, W, 3)`` float32 RGB and the header of an OpenEXR file."""
    part = OpenEXR.File(str(path), separate_channels=True).parts[0]
    rgb = np.stack([part.channels[c].pixels.astype(np.float32) for c in "RGB"], axis=-1)
    return rgb, dict(part.header)


def _atomic(dest: Path, write) -> None:
    fd, tmp = tempfile.mkstemp(dir=dest.parent, prefix=f".{dest.name}.", suffix=dest.suffix)
    os.close(fd)
    try:
        write(tmp)
        os.chmod(tmp, 0o644)
        os.replace(tmp, dest)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def write_exr(path: Path, rgb: np.ndarray, header: dict) -> None:
    """Write ``rgb`` lossless (PIZ, half) keeping ``header``'s attributes."""
    half = rgb.astype(np.float16)
    if not np.array_equal(half.astype(np.float32), rgb):
        raise ValueError(f"{path.name}: values are not exact halves; half would lose them")
    head = {k: v for k, v in header.items() if k not in ("channels", "dataWindow", "type")}
    head["compression"] = OpenEXR.PIZ_COMPRESSION
    history = str(head.get("Exif:ImageHistory", ""))
    head["Exif:ImageHistory"] = f"{history}; {HISTORY}" if history else HISTORY
    head.pop("dwaCompressionLevel", None)
    channels = {c: np.ascontiguousarray(half[..., i]) for i, c in enumerate("RGB")}
    _atomic(path, lambda tmp: OpenEXR.File(head, channels).write(tmp))


def write_png(path: Path, rgb8: np.ndarray) -> None:
    _atomic(path, lambda tmp: Image.fromarray(rgb8).save(tmp, format="PNG", optimize=True))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--src", type=Path, default=DEFAULT_SRC, help="folder of the originals")
    parser.add_argument("--dest", type=Path, default=DEFAULT_DEST, help="folder to write to")
    args = parser.parse_args(argv)
    for name, with_exr in SAMPLES.items():
        linear, header = read_exr(args.src / f"{name}.exr")
        with Image.open(args.src / f"{name}.png") as im:
            shipped = np.asarray(im.convert("RGB"))
        if not np.array_equal(tone_map(linear), shipped):
            print(f"{name}: the shipped PNG is not tone_map(EXR); stopping", file=sys.stderr)
            return 1
        fixed = repair(linear)
        png = tone_map(fixed)
        before, after = ring_spots(shipped), ring_spots(png)
        dips = lamp_dips(np.clip(linear, 0.0, None)).sum(), lamp_dips(fixed).sum()
        changed = (png != shipped).any(axis=-1)
        print(
            f"{name}: ring pixels {before.sum()} in {count_spots(before)} spots -> "
            f"{after.sum()} in {count_spots(after)}; lamp dips {dips[0]} -> {dips[1]}; "
            f"EXR values < 0: {(linear < 0).sum()} -> "
            f"{(fixed < 0).sum()}; PNG pixels changed: {changed.sum()} "
            f"({changed.mean():.3%})"
        )
        write_png(args.dest / f"{name}.png", png)
        if with_exr:
            write_exr(args.dest / f"{name}.exr", fixed, header)
    return 0


if __name__ == "__main__":
    sys.exit(main())
