"""Split-screen on branched covers (spherewarp.effects.splitscreen)."""

from __future__ import annotations

import numpy as np
import pytest

import tolerances
from spherewarp import coords
from spherewarp.effects.splitscreen import (
    SheetedCover,
    auto_seam,
    conform_images,
    make_cover,
    seam_costs,
    splitscreen,
)
from spherewarp.errors import InvalidTypeError, InvalidValueError
from spherewarp.maps import ExpMap, Mobius, Power, map_from_dict
from spherewarp.render import warp

H, W = 64, 128


def solid(rgb, h=H, dtype=np.uint8) -> np.ndarray:
    img = np.zeros((h, 2 * h, len(rgb)), dtype)
    img[...] = np.asarray(rgb, dtype)
    return img


RED, GREEN, BLUE = solid((255, 0, 0)), solid((0, 255, 0)), solid((0, 0, 255))


def column_of_lon(lon: float, w: int = W) -> int:
    return int((lon + 180.0) / 360.0 * w)


def max_diff(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.abs(a.astype(np.float64) - b.astype(np.float64)).max())


# ------------------------------------------------------------------ identical inputs


@pytest.mark.parametrize(
    "kwargs, cover",
    [
        ({}, Power(2)),
        ({"seam": 33.0, "feather_deg": 40.0}, Power(2)),
        ({"n": 4, "seam": -100.0}, Power(4)),
        ({"cover": "exp", "seam": 10.0, "feather_deg": 25.0}, ExpMap(4)),
        ({"cover": "exp", "lam": 2.0, "seam": "auto"}, ExpMap(2)),
        (
            {"branch_points": ((30, 10), (-150, -10)), "seam": 50.0},
            Power(2, branch_points=((30, 10), (-150, -10))),
        ),
    ],
)
def test_copies_of_one_panorama_give_the_plain_pull_back(random_image, kwargs, cover):
    img = random_image(32)
    out = splitscreen([img, img], **kwargs)
    assert out.dtype == img.dtype and out.shape == img.shape
    assert max_diff(out, warp(img, cover)) <= tolerances.rounding(img.dtype)


def test_three_copies_and_a_view(smooth_image):
    img = smooth_image(32)
    view = Mobius.from_yaw_pitch_roll(0.0, 90.0)
    out = splitscreen([img] * 3, seam=20.0, feather_deg=30.0, view=view, supersample=2)
    ref = warp(img, Power(3) @ view, supersample=2)
    assert max_diff(out, ref) <= tolerances.rounding(img.dtype)


# ------------------------------------------------------------------ different inputs


def test_each_input_on_its_own_sheet():
    out = splitscreen([RED, BLUE], seam=0.0, feather_deg=0.0)
    # z**2 in the default chart: seams at longitudes -90 and 90; the front on sheet 0
    for lon, colour in [
        (0, (255, 0, 0)),
        (-60, (255, 0, 0)),
        (120, (0, 0, 255)),
        (-170, (0, 0, 255)),
    ]:
        col = out[:, column_of_lon(lon)]
        assert np.all(col == colour), lon


def test_sheets_cycle_through_more_images():
    out = splitscreen([RED, GREEN, BLUE], n=6, seam=0.0, feather_deg=0.0)
    colours = [tuple(out[H // 2, column_of_lon(lon)]) for lon in (0, 60, 120, 180 - 1, -120, -60)]
    assert len(set(colours)) == 3
    assert colours[0] == (255, 0, 0)


def test_feather_blends_across_the_seam():
    f = 40.0
    out = splitscreen([RED, BLUE], seam=0.0, feather_deg=f).astype(float)
    # In the output of z**2 the band is f/2 = 20 degrees wide around longitude 90.
    lons = (np.arange(W) + 0.5) * 360.0 / W - 180.0
    row = out[H // 2]
    inside = np.abs(lons - 90.0) < 9.0
    outside = (np.abs(lons - 90.0) > 11.0) & (np.abs(lons + 90.0) > 11.0)
    assert np.all(row[outside].max(axis=1) == 255)  # pure colours away from the seams
    assert np.all(row[outside].min(axis=1) == 0)
    mixed = row[inside]
    assert np.all((mixed[:, 0] > 0) & (mixed[:, 2] > 0))
    assert np.allclose(mixed[:, 0] + mixed[:, 2], 255, atol=1)
    # monotone cross-fade from blue (west of 90: sheet 1 is east) ... either way, monotone
    assert np.all(np.diff(mixed[:, 0]) <= 0) or np.all(np.diff(mixed[:, 0]) >= 0)


def test_seam_is_invisible_where_the_inputs_agree(interior):
    """The paper's use: the same room, once with a 'person' in it; the person shows once."""
    empty = interior
    person = interior.copy()
    yy, xx = np.mgrid[0 : empty.shape[0], 0 : empty.shape[1]]
    blob = (xx - 700) ** 2 / 40**2 + (yy - 300) ** 2 / 90**2 < 1
    person[blob] = (200, 30, 30)
    seam = auto_seam([empty, person])
    blob_lon = 700 / 1024 * 360 - 180
    assert abs(((seam - blob_lon + 180) % 360) - 180) > 30  # away from the person
    out = splitscreen([empty, person], seam=seam)
    plain = warp(empty, Power(2))
    differs = np.abs(out.astype(int) - plain.astype(int)).max(axis=2) > 3
    # Only the person differs from the empty room's pull-back: no seam anywhere.
    warped_blob = warp(blob.astype(np.uint8)[..., None] * 255, Power(2))[..., 0] > 0
    assert differs.sum() > 100
    assert not np.any(differs & ~warped_blob)
    # and it appears on one sheet only (one of the two copies around the branch points)
    h, w = out.shape[:2]
    left, right = differs[:, : w // 2].sum(), differs[:, w // 2 :].sum()
    assert min(left, right) == 0


def test_no_contamination_near_the_branch_points():
    """Three different inputs: the rows at the poles keep each sheet's own colour."""
    out = splitscreen([RED, GREEN, BLUE], seam=180.0, feather_deg=30.0)  # seams at -60, 60, 180
    sheet_centres = [column_of_lon(lon) for lon in (0.0, 120.0, -120.0)]
    for row in (0, 1, 2, H - 1, H - 2):
        for col, colour in zip(sheet_centres, [(255, 0, 0), (0, 255, 0), (0, 0, 255)], strict=True):
            assert tuple(out[row, col]) == colour


def test_exp_cover_alternates_and_stays_finite():
    red = RED.astype(np.float32) / 255
    blue = BLUE.astype(np.float32) / 255
    out = splitscreen([red, blue], cover="exp", seam=180.0, feather_deg=0.0, supersample=3)
    assert out.dtype == np.float32 and np.all(np.isfinite(out))
    row = out[H // 2 - 1]
    front = row[column_of_lon(0.0) - 3]
    assert front[0] > 0.99  # the front is on sheet 0 (image 0)
    # along the equator the copies alternate red/blue many times
    reds = row[:, 0] > 0.9
    assert np.count_nonzero(np.diff(reds.astype(int))) >= 6


# ------------------------------------------------------------------ choosing the seam


def test_auto_seam_finds_where_inputs_agree(random_image):
    a = random_image(32, seed=1)
    b = random_image(32, seed=2)
    b[:, 20:30] = a[:, 20:30]  # they agree only on longitudes -67.5 .. -11.25
    lons, costs = seam_costs([a, b], feather_deg=5.0)
    assert lons.shape == (64,) and costs.shape == (64,)
    seam = auto_seam([a, b], feather_deg=5.0)
    assert -67.5 < seam < -11.25


def test_auto_seam_with_branch_points(random_image):
    a = random_image(32, seed=3)
    b = a.copy()
    b[:, :40] = 0
    bp = ((0.0, 0.0), (180.0, 0.0))
    seam = auto_seam([a, b], branch_points=bp, feather_deg=5.0)
    assert -180.0 <= seam <= 180.0


# ------------------------------------------------------------------ inputs of different kinds


def test_inputs_are_conformed():
    grey = np.full((16, 32), 100, np.uint8)
    rgb = np.full((32, 64, 3), 50, np.uint8)
    rgba = np.full((8, 16, 4), 200, np.uint16)
    out = conform_images([grey, rgb, rgba])
    assert [a.shape for a in out] == [(32, 64, 4)] * 3
    assert all(a.dtype == np.uint16 for a in out)
    assert out[0][0, 0].tolist() == [100 * 257] * 3 + [65535]
    assert out[2][0, 0].tolist() == [200] * 4
    f = conform_images([rgb, np.zeros((32, 64, 3), np.float32)])
    assert f[0].dtype == np.float32 and np.allclose(f[0], 50 / 255)


def test_splitscreen_of_mixed_inputs():
    small = solid((0, 0, 255), h=16)
    grey = np.full((H, W), 255, np.uint8)
    out = splitscreen([grey, small, RED.copy()[..., :3]], n=3, seam=0.0, feather_deg=0.0)
    assert out.shape == (H, W, 3)
    rgba = np.concatenate([RED, np.full((H, W, 1), 255, np.uint8)], axis=2)
    out = splitscreen([rgba, BLUE], seam=0.0)
    assert out.shape == (H, W, 4) and np.all(out[..., 3] == 255)


def test_output_shape_and_options(random_image):
    img = random_image(32)
    out = splitscreen([img, img], output_shape=(16, 32), interp="bicubic", supersample=2)
    assert out.shape == (16, 32, 3)


# ------------------------------------------------------------------ the sheeted map


def test_sheeted_cover():
    s = SheetedCover(Power(4), 2, seam=0.0)
    assert s.n_sheets == 2
    lon = np.array([0.0, 60.0, 150.0, -150.0, -60.0])
    zw = coords.cp1_from_lonlat(np.radians(np.stack([lon, np.zeros_like(lon)], -1)))
    pb = s.pull(zw)
    assert pb.sheet.tolist() == [0, 1, 0, 0, 1]
    assert SheetedCover(Power(2), 2, halves=True).n_sheets == 4
    assert map_from_dict(s.to_dict()).to_dict() == s.to_dict()
    assert np.allclose(s.local_scale(zw), Power(4).local_scale(zw))


@pytest.mark.parametrize(
    "call, error, match",
    [
        (lambda: splitscreen([]), InvalidValueError, "non-empty"),
        (lambda: splitscreen([RED, BLUE], n=3), InvalidValueError, "multiple of 2"),
        (lambda: splitscreen([RED, BLUE], feather_deg=200), InvalidValueError, "0 to 180"),
        (lambda: splitscreen([RED, BLUE], feather_deg=-1), InvalidValueError, "0 to 180"),
        (lambda: splitscreen([RED, BLUE], seam="left"), InvalidValueError, "auto"),
        (lambda: splitscreen([RED, BLUE], seam=[10.0, 20.0]), InvalidValueError, "one seam"),
        (lambda: splitscreen([RED, BLUE], cover="log"), InvalidValueError, "power, exp"),
        (lambda: splitscreen([RED, BLUE], cover=Power(0.5)), InvalidValueError, "integer n"),
        (lambda: splitscreen([RED, np.zeros((10, 30, 3), np.uint8)]), InvalidValueError, "2 x"),
        (lambda: SheetedCover(Power(2), 0), InvalidValueError, "at least one"),
        (lambda: SheetedCover(Power(2), 2, seam=float("nan")), InvalidValueError, "finite"),
        (lambda: SheetedCover(Power(2), 2, view="up"), InvalidTypeError, "Mobius"),
        (lambda: make_cover(3), InvalidTypeError, "cover"),
    ],
)
def test_errors(call, error, match):
    with pytest.raises(error, match=match):
        call()
