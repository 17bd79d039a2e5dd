"""spherewarp's yaw/pitch/roll rotation against ffmpeg's ``v360=e:e`` filter (via PyAV).

Both render bilinearly. ffmpeg reads its input at ``x * (W-1)/W + 0.5`` instead
of ``x`` (see ``_v360_convention``): up to half a pixel apart at the edges, so
the two are compared after a 4x4 box filter, where that offset no longer
matters but a wrong angle, sign or axis order would.
"""

from __future__ import annotations

import numpy as np
import pytest
from _v360_convention import v360_matrix

from spherewarp.maps import Mobius
from spherewarp.render import warp
from tolerances import V360_PSNR_DB

PANORAMAS = ["courtyard.png", "city.png", "interior.png"]
ANGLES = [
    (30.0, 0.0, 0.0),
    (0.0, 25.0, 0.0),
    (0.0, 0.0, 15.0),
    (30.0, 20.0, 10.0),
    (-75.0, 40.0, -25.0),
    (170.0, -60.0, 90.0),
]


def _ids(ypr) -> str:
    return "y{:g}_p{:g}_r{:g}".format(*ypr)


def box_down(img: np.ndarray, k: int = 4) -> np.ndarray:
    h, w, c = img.shape
    return img.astype(np.float64).reshape(h // k, k, w // k, k, c).mean(axis=(1, 3))


def psnr(a: np.ndarray, b: np.ndarray) -> float:
    mse = np.mean((np.asarray(a, np.float64) - np.asarray(b, np.float64)) ** 2)
    return float("inf") if mse == 0 else float(10.0 * np.log10(255.0**2 / mse))


@pytest.fixture(scope="module")
def v360():
    pytest.importorskip("av")
    from _v360 import have_v360
    from _v360 import v360 as run

    if not have_v360():
        pytest.skip("this libavfilter has no v360 filter")
    return run


# -- geometry only (no PyAV needed) -------------------------------------------------------------
@pytest.mark.parametrize("ypr", [*ANGLES, (-180.0, 90.0, -180.0), (0.0, 0.0, 0.0)], ids=_ids)
def test_yaw_pitch_roll_is_v360_rotation(ypr):
    m = Mobius.from_yaw_pitch_roll(*ypr)
    assert m.is_rotation()
    np.testing.assert_allclose(m.to_rotation_matrix(), v360_matrix(*ypr), atol=1e-12)


# -- against ffmpeg ----------------------------------------------------------------------------
@pytest.mark.parametrize("name", PANORAMAS)
@pytest.mark.parametrize("ypr", ANGLES, ids=_ids)
def test_rotation_matches_v360(v360, panorama, name, ypr):
    img = panorama(name)
    ours = warp(img, Mobius.from_yaw_pitch_roll(*ypr), interp="bilinear")
    theirs = v360(img, yaw=ypr[0], pitch=ypr[1], roll=ypr[2], interp="linear")
    assert ours.shape == theirs.shape and ours.dtype == theirs.dtype
    p = psnr(box_down(ours), box_down(theirs))
    assert p >= V360_PSNR_DB, (name, ypr, p)


@pytest.mark.parametrize("ypr", ANGLES[3:], ids=_ids)
def test_wrong_sense_is_rejected(v360, panorama, ypr):
    """Sanity of the comparison: the inverse rotation is far below the threshold."""
    img = panorama("courtyard.png")
    wrong = warp(img, Mobius.from_yaw_pitch_roll(*ypr).inverse(), interp="bilinear")
    theirs = v360(img, yaw=ypr[0], pitch=ypr[1], roll=ypr[2])
    assert psnr(box_down(wrong), box_down(theirs)) < V360_PSNR_DB - 10
