"""The bundled sample panoramas are repaired: no ringing around the lamps, no negative EXR values.

The repair is ``tools/repair_samples.py`` (see ``src/spherewarp/data/LICENSE.md``); its
ring-spot detector is the shared helper these tests use.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest

from shared_data import SHARED_PANORAMAS
from spherewarp.io.images import read_image

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "src" / "spherewarp" / "data"
ORIGINALS = SHARED_PANORAMAS
SAMPLES = ["interior.png", "courtyard.png"]


def _load_tool():
    spec = importlib.util.spec_from_file_location(
        "repair_samples", ROOT / "tools" / "repair_samples.py"
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


repair = _load_tool()


def _rgb(path: Path) -> np.ndarray:
    return read_image(path).pixels


def _original(name: str) -> Path:
    path = ORIGINALS / name
    if not path.exists():
        pytest.skip(f"the original {name} is not available")
    return path


def test_detector_finds_a_ring_and_passes_a_clean_lamp():
    y, x = np.mgrid[:64, :128]
    r = np.hypot(y - 32, x - 64)
    lamp = np.where(r < 4, 255, np.clip(255 - 12 * (r - 4), 140, 255)).astype(np.uint8)
    clean = np.repeat(lamp[..., None], 3, axis=2)
    assert not repair.ring_spots(clean).any()
    ringed = clean.copy()
    ringed[32, 61] = 0  # black, inside the blown-out disc
    ringed[29, 67, :2] = 0  # blue: red and green clamped
    assert repair.ring_spots(ringed).sum() == 2
    assert repair.count_spots(repair.ring_spots(ringed)) == 2


def test_detectors_see_the_original_rings():
    original = _rgb(_original("interior.png"))
    assert repair.count_spots(repair.ring_spots(original)) >= 20
    hdr = np.clip(read_image(_original("interior.exr")).pixels, 0.0, None)
    assert repair.lamp_dips(hdr).sum() >= 100


@pytest.mark.parametrize("name", SAMPLES)
def test_bundled_sample_has_no_ring_spots(name):
    pixels = _rgb(DATA / name)
    assert (pixels.shape, pixels.dtype) == ((512, 1024, 3), np.uint8)
    assert not repair.ring_spots(pixels).any()


def test_bundled_exr_is_clean_and_makes_the_png():
    hdr = read_image(DATA / "interior.exr").pixels
    assert (hdr.shape, hdr.dtype) == ((512, 1024, 3), np.float32)
    assert np.isfinite(hdr).all() and hdr.min() >= 0.0 and hdr.max() > 1000.0
    assert not repair.lamp_dips(hdr).any()
    np.testing.assert_array_equal(repair.tone_map(hdr), _rgb(DATA / "interior.png"))


@pytest.mark.parametrize("name", SAMPLES)
def test_repair_changes_only_pixels_near_the_lamps(name):
    before, after = _rgb(_original(name)), _rgb(DATA / name)
    assert before.shape == after.shape
    changed = (before != after).any(axis=-1)
    assert 0 < changed.mean() < 0.001
    clipped = before.max(axis=-1) >= repair.CLIPPED
    reach = max(repair.REACH, repair.LAMP_REACH) + 1
    near = repair._neighbours(clipped, reach).any(axis=0)
    assert not (changed & ~near).any()


def test_repair_reproduces_the_bundled_files(tmp_path):
    _original("interior.exr")
    assert repair.main(["--src", str(ORIGINALS), "--dest", str(tmp_path)]) == 0
    for name in [*SAMPLES, "interior.exr"]:
        np.testing.assert_array_equal(_rgb(tmp_path / name), _rgb(DATA / name))
