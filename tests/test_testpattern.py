"""The procedural test pattern: sizes, dtypes, colours where they belong, round discs."""

from __future__ import annotations

import numpy as np
import pytest

from spherewarp import coords
from spherewarp.errors import InvalidTypeError, InvalidValueError
from spherewarp.maps import Mobius
from spherewarp.testpattern import CHARTS, chart_points
from spherewarp.testpattern import make_test_pattern as make_pattern

# Colours of the pattern (uint8), as drawn.
DISC = {
    "0": (26, 166, 64),
    "1": (255, 140, 13),
    "i": (13, 191, 217),
    "-1": (230, 77, 191),
    "-i": (242, 217, 26),
    "inf": (115, 56, 166),
}
BLUE, RED = (26, 84, 217), (217, 31, 31)
CHART_VALUES = {"0": 0, "1": 1, "i": 1j, "-1": -1, "-i": -1j, "inf": complex("inf")}


def pixel_of(lon: float, lat: float, w: int, h: int) -> tuple[int, int]:
    """(row, column) of the pixel containing (lon, lat) degrees."""
    x, y = coords.pixel_from_lonlat(np.radians([lon, lat]), w, h)
    return min(int(y), h - 1), int(x) % w


def angle_to(lon: float, lat: float, w: int, h: int) -> np.ndarray:
    """Angle (degrees) from every pixel centre to (lon, lat)."""
    y, x = np.mgrid[0:h, 0:w] + 0.5
    xyz = coords.xyz_from_lonlat(coords.lonlat_from_pixel(np.stack([x, y], -1), w, h))
    c = coords.xyz_from_lonlat(np.radians([lon, lat]))
    return np.degrees(np.arccos(np.clip(xyz @ c, -1, 1)))


@pytest.fixture(scope="module")
def plain() -> np.ndarray:
    return make_pattern(512, labels=False)


def test_shape_and_dtypes():
    for dtype in (np.uint8, np.uint16, np.float32, "uint16"):
        img = make_pattern(64, dtype=dtype)
        assert img.shape == (32, 64, 3) and img.dtype == np.dtype(dtype)
    assert make_pattern(100, 30).shape == (30, 100, 3)  # any size, not only 2:1
    assert make_pattern().shape == (512, 1024, 3)
    f = make_pattern(256, dtype=np.float32)
    assert np.all(np.isfinite(f)) and f.min() >= 0 and f.max() <= 1


def test_dtypes_agree(plain):
    u8 = plain.astype(float)
    u16 = make_pattern(512, dtype=np.uint16, labels=False).astype(float) / 257
    f32 = make_pattern(512, dtype=np.float32, labels=False).astype(float) * 255
    assert np.abs(u16 - u8).max() <= 0.51
    assert np.abs(f32 - u8).max() <= 0.51


def test_equator_is_blue_and_front_meridian_red(plain):
    h, w = plain.shape[:2]
    for lon in (-100.0, -30.0, 20.0, 130.0):
        r, c = pixel_of(lon, 0.0, w, h)
        np.testing.assert_allclose(plain[r - 1 : r + 1, c].mean(0), BLUE, atol=40)
    for lon in (0.0, 179.9):
        for lat in (30.0, -50.0):
            r, c = pixel_of(lon, lat, w, h)
            np.testing.assert_allclose(plain[r, c], RED, atol=40)


@pytest.mark.parametrize("chart", sorted(CHARTS))
def test_discs_mark_the_chart_points(chart):
    w, h = 512, 256
    img = make_pattern(w, chart=chart, labels=False)
    for name, (lon, lat) in CHARTS[chart].items():
        theta = angle_to(lon, lat, w, h)
        inside = theta < 2.0
        assert inside.any()
        np.testing.assert_allclose(
            img[inside], np.broadcast_to(DISC[name], img[inside].shape), atol=2
        )


def test_discs_are_spherical_caps(plain):
    # Every pixel of a disc's colour lies within the cap's radius, and the cap is
    # filled out to the rim in every direction, at the poles as on the equator.
    h, w = plain.shape[:2]
    for name, (lon, lat) in CHARTS["zenith"].items():
        theta = angle_to(lon, lat, w, h)
        close = np.all(np.abs(plain.astype(int) - DISC[name]) <= 2, axis=-1)
        assert theta[close].max() < 4.0  # the radius at 512 wide
        ring = (theta > 2.2) & (theta < 2.9)  # inside the rim (radius 4 - 0.7)
        assert close[ring].mean() > 0.95


def test_seam_is_continuous(plain):
    # The pattern wraps: the first and last columns are neighbours on the sphere.
    a, b = plain[:, 0].astype(float), plain[:, -1].astype(float)
    neighbour = np.abs(plain[:, 1].astype(float) - a).mean()
    assert np.abs(a - b).mean() <= neighbour + 2


def test_no_label_mode_is_symmetric_under_half_turn(plain):
    # Without labels, turning by 180 degrees about the vertical axis maps the grid onto itself
    # (only the disc colours at the front and back differ).
    turned = np.roll(plain, plain.shape[1] // 2, axis=1)
    same = np.all(plain == turned, axis=-1)
    assert same.mean() > 0.98


def test_labels_are_drawn_near_their_points():
    w, h = 512, 256
    with_text = make_pattern(w).astype(int)
    without = make_pattern(w, labels=False).astype(int)
    diff = np.any(with_text != without, axis=-1)
    assert 0.002 < diff.mean() < 0.1
    for _name, (lon, lat) in CHARTS["zenith"].items():
        if abs(lat) < 89:
            r, c = pixel_of(lon, lat, w, h)
            box = np.roll(diff, -c, axis=1)[r - 20 : r, :30]  # up and to the right
            assert box.any()


def test_chart_points_are_the_default_chart():
    for name, (lon, lat) in chart_points("zenith").items():
        z = coords.plane_from_lonlat(np.radians([lon, lat]))
        want = CHART_VALUES[name]
        if np.isinf(want):
            assert abs(z) > 1e12
        else:
            assert abs(z - want) < 1e-12


def test_front_chart_is_a_rotation_of_the_default_chart():
    zen, front = chart_points("ZENITH"), chart_points("front")
    keys = ["0", "1", "inf"]
    r = Mobius.from_points([zen[k] for k in keys], [front[k] for k in keys])
    assert r.is_rotation()
    for name in CHART_VALUES:
        moved = r.apply_xyz(coords.xyz_from_lonlat(np.radians(zen[name])))
        np.testing.assert_allclose(
            moved, coords.xyz_from_lonlat(np.radians(front[name])), atol=1e-12
        )
    # Its formula, z = (y + i z3) / (1 + x): real axis to the right, imaginary axis up.
    for name, (lon, lat) in front.items():
        x, y, z3 = coords.xyz_from_lonlat(np.radians([lon, lat]))
        if name == "inf":
            assert abs(1 + x) < 1e-12
        else:
            assert abs((y + 1j * z3) / (1 + x) - CHART_VALUES[name]) < 1e-12


def test_bad_arguments():
    with pytest.raises(InvalidValueError, match="zenith, front"):
        make_pattern(64, chart="north")
    with pytest.raises(InvalidTypeError, match="uint8, uint16 or float32"):
        make_pattern(64, dtype=np.float64)
    with pytest.raises(InvalidTypeError):
        make_pattern(64, dtype="rgb")
    with pytest.raises(InvalidValueError, match="8x4"):
        make_pattern(4)
    with pytest.raises(InvalidTypeError):
        make_pattern(64.0)
    with pytest.raises(InvalidTypeError):
        make_pattern(True)
