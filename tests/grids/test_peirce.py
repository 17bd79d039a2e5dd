"""Peirce's quincuncial projection: against PROJ, round trips, seamless images."""

from __future__ import annotations

import numpy as np
import pytest

from spherewarp import coords
from spherewarp.errors import InvalidValueError
from spherewarp.grids.peirce import (
    peirce_from_sphere,
    peirce_to_equirect,
    render_peirce,
    sphere_from_peirce,
)

#: PROJ's forward against ours after the best similarity, in units of the square's side
PROJ_SIDE = 1e-6
#: forward then inverse (radians / unit vectors)
ROUND_TRIP = 1e-12


def random_xyz(rng: np.random.Generator, n: int) -> np.ndarray:
    v = rng.normal(size=(n, 3))
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def off_the_folds(xyz: np.ndarray, lon0: float) -> np.ndarray:
    """Points away from the four folded half-meridians (lon0 + 45 + 90k, south)."""
    lon, lat = np.degrees(coords.lonlat_from_xyz(xyz)).T
    d = np.abs((lon - lon0 - 45 + 45) % 90 - 45)
    return xyz[(d > 0.5) | (lat > 0)]


@pytest.mark.parametrize("lon0", [0.0, 30.0, -110.0])
def test_matches_proj_peirce_q_up_to_a_similarity(lon0, rng):
    pyproj = pytest.importorskip("pyproj")
    xyz = off_the_folds(random_xyz(rng, 4000), lon0)
    lon, lat = np.degrees(coords.lonlat_from_xyz(xyz)).T
    t = pyproj.Transformer.from_proj("+proj=longlat +R=1", f"+proj=peirce_q +R=1 +lon_0={lon0}")
    x, y = t.transform(lon, lat)
    theirs = np.asarray(x) + 1j * np.asarray(y)
    u, v = peirce_from_sphere(xyz, lon0=lon0)
    ours = u + 1j * v
    a = np.stack([ours, np.ones_like(ours)], axis=1)
    (scale, shift), *_ = np.linalg.lstsq(a, theirs, rcond=None)
    side = 2 * abs(scale)  # our square has side 2
    err = np.abs(a @ np.array([scale, shift]) - theirs) / side
    assert np.max(err) < PROJ_SIDE
    # the similarity is a turn by 45 degrees (PROJ's world is a diamond), no reflection
    assert np.degrees(np.angle(scale)) == pytest.approx(45.0, abs=1e-6)
    assert abs(shift) < 1e-6 * side


def test_layout_of_the_square():
    ll = np.radians([[0, 90], [0, -90], [45, 0], [135, 0], [-135, 0], [-45, 0], [0, 0], [90, 0]])
    u, v = peirce_from_sphere(coords.xyz_from_lonlat(ll))
    p = np.round(u + 1j * v, 6)
    assert p[0] == 0  # zenith at the centre
    assert abs(p[1].real) == 1 and abs(p[1].imag) == 1  # nadir at a corner
    # the equator's diamond: vertices at the midpoints of the sides
    np.testing.assert_allclose(p[2:6], [-1j, 1, 1j, -1], atol=1e-6)
    # lon0 runs to the bottom-left, lon0 + 90 to the bottom-right
    np.testing.assert_allclose(p[6:], [-0.5 - 0.5j, 0.5 - 0.5j], atol=1e-6)


def test_forward_then_inverse_returns_every_pixel_direction():
    h, w = 90, 180
    y, x = np.mgrid[0:h, 0:w] + 0.5
    lonlat = coords.lonlat_from_pixel(np.stack([x, y], -1), w, h)
    xyz = coords.xyz_from_lonlat(lonlat)
    for lon0 in (0.0, 17.0):
        u, v = peirce_from_sphere(xyz, lon0=lon0)
        assert np.all(np.abs(u) <= 1) and np.all(np.abs(v) <= 1)
        back = sphere_from_peirce(u, v, lon0=lon0)
        assert np.max(np.linalg.norm(back - xyz, axis=-1)) < ROUND_TRIP


def test_inverse_then_forward_returns_every_square_pixel():
    n = 101
    y, x = np.mgrid[0:n, 0:n] + 0.5
    u, v = 2 * x / n - 1, 1 - 2 * y / n
    xyz = sphere_from_peirce(u, v)
    np.testing.assert_allclose(np.linalg.norm(xyz, axis=-1), 1.0, atol=1e-14)
    uu, vv = peirce_from_sphere(xyz)
    assert np.max(np.hypot(uu - u, vv - v)) < 1e-9


def test_inverse_is_smooth_across_the_diagonals_and_folds():
    # where PROJ's inverse fails (bands along the diagonals) ours is an elliptic function
    t = np.linspace(-1, 1, 2001)
    for u, v in ((t, t), (t, -t), (np.ones_like(t), t), (t, -np.ones_like(t))):
        xyz = sphere_from_peirce(u, v)
        assert np.all(np.isfinite(xyz))
        steps = np.linalg.norm(np.diff(xyz, axis=0), axis=-1)
        assert np.max(steps) < 0.01
    # the sides are folded at their midpoints: (1, v) and (1, -v) are one point
    a = sphere_from_peirce(np.ones_like(t), t)
    b = sphere_from_peirce(np.ones_like(t), -t)
    assert np.max(np.linalg.norm(a - b, axis=-1)) < 1e-12
    a = sphere_from_peirce(t, -np.ones_like(t))
    b = sphere_from_peirce(-t, -np.ones_like(t))
    assert np.max(np.linalg.norm(a - b, axis=-1)) < 1e-12


def test_render_samples_the_right_directions(smooth_image):
    img = smooth_image(64)  # value 0.5 + 0.5 xyz
    sq = render_peirce(img, 96)
    assert sq.shape == (96, 96, 3) and sq.dtype == np.float32
    y, x = np.mgrid[0:96, 0:96] + 0.5
    expected = 0.5 + 0.5 * sphere_from_peirce(2 * x / 96 - 1, 1 - 2 * y / 96)
    assert np.max(np.abs(sq - expected)) < 2e-3  # bilinear interpolation of a smooth image
    # the square is seamless across its folded sides: column N-1 read upwards equals itself
    # read downwards (the points (1 - e, v) and (1 - e, -v) are near one point)
    assert np.max(np.abs(sq[:, -1] - sq[::-1, -1])) < 0.05
    assert np.max(np.abs(sq[0, :] - sq[0, ::-1])) < 0.05


def test_round_trip_of_an_image_through_the_square(smooth_image):
    img = smooth_image(64)
    sq = render_peirce(img, 128, interp="bicubic")
    back = peirce_to_equirect(sq, (64, 128), interp="bicubic")
    assert back.shape == img.shape and np.all(np.isfinite(back))
    err = np.abs(back - img)
    assert np.max(err) < 0.02  # no seams: the largest error stays small everywhere
    assert np.mean(err) < 2e-3


def test_uint8_panorama_round_trip(interior):
    img = interior[::4, ::4]
    sq = render_peirce(img, supersample=2)
    assert sq.dtype == np.uint8 and sq.shape == (192, 192, 3)
    back = peirce_to_equirect(sq, img.shape[:2])
    assert back.dtype == np.uint8 and back.shape == img.shape
    assert np.mean(np.abs(back.astype(int) - img)) < 12


def test_bad_input_is_refused():
    with pytest.raises(InvalidValueError, match="square"):
        peirce_to_equirect(np.zeros((10, 12, 3), np.uint8))
    with pytest.raises(InvalidValueError, match="size"):
        render_peirce(np.zeros((8, 16, 3), np.uint8), 1)
    with pytest.raises(InvalidValueError, match="2 x height"):
        render_peirce(np.zeros((8, 12, 3), np.uint8))
    with pytest.raises(InvalidValueError, match=r"\(\.\.\., 3\)"):
        peirce_from_sphere(np.zeros((4, 2)))
    with pytest.raises(InvalidValueError, match="finite"):
        sphere_from_peirce(np.array([np.nan]), np.array([0.0]))
    with pytest.raises(InvalidValueError, match="lon0"):
        peirce_from_sphere(np.array([0.0, 0.0, 1.0]), lon0=float("inf"))
