"""Droste images from a frame: the hole, the scale, the rendered properties, the log view."""

from __future__ import annotations

import math

import numpy as np
import pytest

from spherewarp import coords
from spherewarp.effects.droste import (
    Hole,
    animation_phases,
    auto_scale,
    droste_frames,
    droste_image,
    droste_map,
    hole_from_corners,
    hole_from_mask,
    hole_from_radius,
    log_view,
    log_view_layout,
)
from spherewarp.errors import InvalidTypeError, InvalidValueError
from spherewarp.maps import Droste, Mobius, TwistedDroste
from spherewarp.render import warp

SQUARE = [(-20.0, 20.0), (20.0, 20.0), (20.0, -20.0), (-20.0, -20.0)]
#: the framed picture on the wall of the bundled interior.png (the README demo)
PICTURE = [(-173.0, 23.6), (-153.8, 24.5), (-153.8, -14.8), (-173.0, -14.2)]
H, W = 64, 128


def angular_distance(lonlat_deg: np.ndarray, point: tuple[float, float]) -> np.ndarray:
    a = coords.xyz_from_lonlat(np.radians(lonlat_deg))
    b = coords.xyz_from_lonlat(np.radians(point))
    return np.degrees(np.arccos(np.clip(a @ b, -1, 1)))


def pixel_lonlat(h: int, w: int) -> np.ndarray:
    y, x = np.mgrid[0:h, 0:w] + 0.5
    return np.degrees(coords.lonlat_from_pixel(np.stack([x, y], -1), w, h))


def pixel_cp1(h: int, w: int) -> np.ndarray:
    return coords.cp1_from_lonlat(np.radians(pixel_lonlat(h, w)))


def interior_tile(d: Droste, h: int, w: int, k: int) -> np.ndarray:
    """Pixels whose 3x3 sub-pixel neighbourhood lies wholly in tile k (away from its edges)."""
    y, x = np.mgrid[0:h, 0:w] + 0.5
    ok = np.ones((h, w), bool)
    for dy in (-1.0, 0.0, 1.0):
        for dx in (-1.0, 0.0, 1.0):
            ll = coords.lonlat_from_pixel(np.stack([x + dx, y + dy], -1), w, h)
            ok &= d.tile_index(coords.cp1_from_lonlat(ll)) == k
    return ok


# -- the hole -------------------------------------------------------------------------------------


def test_corners_hole_contains_the_inside_of_the_frame() -> None:
    hole = hole_from_corners(SQUARE)
    assert isinstance(hole, Hole) and hole.source == "corners"
    assert hole.center == (0.0, 0.0)
    pts = np.array([[0, 0], [19, 0], [0, -19], [18, 18], [21, 0], [0, 25], [180, 0]], float)
    np.testing.assert_array_equal(hole.contains(pts), [1, 1, 1, 1, 0, 0, 0])
    # the edges are great circles: the top edge bulges above latitude 20 in the middle
    assert hole.contains([[0.0, 20.5]])[0] and not hole.contains([[19.9, 20.5]])[0]
    # either direction round the frame, any starting corner
    again = hole_from_corners(SQUARE[::-1][1:] + SQUARE[::-1][:1])
    np.testing.assert_allclose(again.rho, hole.rho, atol=1e-6)


def test_corners_across_the_seam_and_the_real_picture() -> None:
    hole = hole_from_corners([(170, 10), (-170, 10), (-170, -10), (170, -10)])
    assert abs(abs(hole.center[0]) - 180) < 1e-9 and hole.center[1] == 0
    assert hole.contains([[179.0, 0.0], [-179.0, 0.0]]).all()
    picture = hole_from_corners(PICTURE)
    assert picture.contains([[-163.4, 4.8]])[0]
    assert 10 < picture.mean_radius < 20


@pytest.mark.parametrize(
    ("corners", "center", "needle"),
    [
        ([(-20, 20), (20, -20), (20, 20), (-20, -20)], None, "not in order"),
        (SQUARE, (60.0, 0.0), "inside no frame"),
        (SQUARE, (180.0, 0.0), "inside no frame"),
        ([(-20, -10), (0, 20), (20, -10), (0, 5)], (-12.0, -3.0), "not star-shaped"),
        ([(-20, -10), (-20, -10), (20, -10), (0, 5)], None, "coincide"),
        ([(0, 0), (179.5, 0), (0, 10)], None, "spans"),
        (SQUARE[:2], None, "at least 3"),
        ([(-20, 20), (20, 20), (20, -95), (-20, -20)], None, "lat"),
    ],
)
def test_bad_frames_are_clear_errors(corners, center, needle) -> None:
    with pytest.raises(InvalidValueError, match=needle):
        hole_from_corners(corners, center)


def test_far_point_inside_the_frame_is_an_error() -> None:
    with pytest.raises(InvalidValueError, match="far fixed point is inside"):
        hole_from_corners(SQUARE, far=(5.0, 5.0))


def test_radius_hole() -> None:
    hole = hole_from_radius((30, -10), 15)
    np.testing.assert_allclose(hole.rho, math.log(math.tan(math.radians(7.5))))
    assert hole.mean_radius == pytest.approx(15, abs=1e-9)
    far = hole_from_radius((30, -10), 15, far=(100, 40))
    edge = far.boundary()
    np.testing.assert_allclose(angular_distance(edge, (30, -10)), 15, atol=1e-3)
    for bad in (0, 180, -5, float("nan")):
        with pytest.raises(InvalidValueError, match="radius"):
            hole_from_radius((0, 0), bad)


def test_mask_hole_agrees_with_corners_and_radius() -> None:
    """The same region given three ways gives the same hole (to the mask's resolution)."""
    corners = hole_from_corners(SQUARE)
    mask = corners.mask(1024, 512)
    from_mask = hole_from_mask(mask, (0, 0))
    assert from_mask.source == "mask"
    # half a pixel (0.18 deg) at a radius of 20-28 deg: about 0.01 in log r
    assert np.abs(from_mask.rho - corners.rho).max() < 0.02
    round_hole = hole_from_radius((40, 30), 25)
    from_round = hole_from_mask(round_hole.mask(1024, 512).astype(np.uint8) * 255, (40, 30))
    assert np.abs(from_round.rho - round_hole.rho).max() < 0.02
    # a polygon with many corners on the circle is the round hole too
    phi = np.linspace(0, 2 * np.pi, 361)[:-1]
    pts = []
    c = coords.xyz_from_lonlat(np.radians([40, 30]))
    e1 = np.cross([0, 0, 1], c)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(c, e1)
    d = math.radians(25)
    for p in phi:
        v = math.cos(d) * c + math.sin(d) * (math.cos(p) * e1 + math.sin(p) * e2)
        pts.append(tuple(np.degrees(coords.lonlat_from_xyz(v))))
    poly = hole_from_corners(pts, (40, 30))
    assert np.abs(poly.rho - round_hole.rho).max() < 1e-3


def test_same_region_gives_the_same_droste_image(smooth_image) -> None:
    img = smooth_image(H)
    corners = hole_from_corners(SQUARE)
    mask = hole_from_mask(corners.mask(1024, 512), (0, 0))
    outs = [warp(img, droste_map(h, 6.0)) for h in (corners, mask)]
    diff = np.abs(outs[0].astype(float) - outs[1].astype(float)).max(axis=-1)
    assert np.mean(diff > 0.02) < 0.02  # a few pixels along the tile edges
    assert np.median(diff) < 1e-6


def test_mask_uses_the_white_region_of_the_centre_only() -> None:
    mask = hole_from_radius((0, 0), 20).mask(512, 256)
    mask |= hole_from_radius((120, 0), 10).mask(512, 256)  # another white blob: ignored
    hole = hole_from_mask(mask, (0, 0))
    assert hole.mean_radius == pytest.approx(20, abs=0.5)
    # default centre: the centroid of the largest white region
    assert np.allclose(hole_from_mask(mask).center, (0, 0), atol=0.5)
    # a region across the seam is one region
    seam = hole_from_radius((180, 0), 20).mask(512, 256)
    assert hole_from_mask(seam, (180, 0)).mean_radius == pytest.approx(20, abs=0.5)


def test_bad_masks_are_clear_errors() -> None:
    mask = hole_from_radius((0, 0), 20).mask(512, 256)
    with pytest.raises(InvalidValueError, match="inside no frame"):
        hole_from_mask(mask, (90, 0))
    with pytest.raises(InvalidValueError, match="white region"):
        hole_from_mask(np.zeros((64, 128)), (0, 0))
    with pytest.raises(InvalidValueError, match="2 x height"):
        hole_from_mask(np.ones((64, 64)), (0, 0))
    # a C shape round the centre is not star-shaped
    ll = pixel_lonlat(256, 512)
    dist = angular_distance(ll, (0, 0))
    c_shape = (dist < 30) & ~((dist > 15) & (dist < 25) & (ll[..., 0] > -5))
    with pytest.raises(InvalidValueError, match="not star-shaped"):
        hole_from_mask(c_shape, (0, 0))


# -- the scale --------------------------------------------------------------------------------


def test_auto_scale() -> None:
    small = hole_from_radius((0, 0), 20)
    # balanced: the portal round the antipode is as large as the hole
    assert auto_scale(small) == pytest.approx(1 / math.tan(math.radians(10)) ** 2)
    d = droste_map(small)
    pts = np.array([[180.0, 19.9], [180.0, 20.1]])
    k = d.tile_index(coords.cp1_from_lonlat(np.radians(pts)))
    np.testing.assert_array_equal(k, [1, 0])  # the portal's edge is 20 deg from the antipode
    # the same far point given explicitly (bisection) agrees with the closed form
    explicit = hole_from_radius((0, 0), 20, far=(180, 0))
    assert auto_scale(explicit) == pytest.approx(auto_scale(small), rel=1e-6)
    # a large hole: the scaled hole must hold the frame (border) plus the margin
    big = hole_from_radius((0, 0), 100)
    lam = auto_scale(big, border=5, margin=5)
    assert lam == pytest.approx(math.tan(math.radians(55)) / math.tan(math.radians(50)), rel=1e-3)
    assert auto_scale(big, border=10, margin=5) > lam
    with pytest.raises(InvalidValueError, match="border"):
        auto_scale(big, border=-1)
    with pytest.raises(InvalidTypeError):
        auto_scale("hole")  # type: ignore[arg-type]


def test_droste_map_options() -> None:
    hole = hole_from_corners(SQUARE)
    assert type(droste_map(hole, 4.0)) is Droste
    tw = droste_map(hole, 4.0, twist=True, strands=2, periodicity=1, n_images=2, phase=0.5)
    assert type(tw) is TwistedDroste and tw.strands == 2 and tw.n_images == 2
    assert droste_map(hole, "auto").scale == pytest.approx(auto_scale(hole))
    for bad in (1.0, 0.3, -2.0):
        with pytest.raises(InvalidValueError, match="scale"):
            droste_map(hole, bad)
    with pytest.raises(InvalidValueError, match="scale"):
        droste_map(hole, "huge")


# -- the rendered image ---------------------------------------------------------------------------


def test_annulus_tile_equals_the_input(random_image) -> None:
    img = random_image(H)
    d = droste_map(hole_from_corners(SQUARE), 4.0)
    out = warp(img, d, antialias="adaptive")  # one bilinear tap where nothing shrinks
    inside = interior_tile(d, H, W, 0)
    assert inside.sum() > 0.2 * H * W
    diff = np.abs(out.astype(int) - img.astype(int))[inside]
    assert diff.max() <= 1  # the identity up to rounding
    assert not np.array_equal(out[~inside], img[~inside])
    # the default filters every pixel by its footprint (the map shrinks the inner copies):
    # the tile is the input averaged over each pixel, as uniform supersampling gives
    area = warp(img, d).astype(float)[inside]
    u4 = warp(img, d, antialias=4).astype(float)[inside]
    assert np.sqrt(np.mean((area - u4) ** 2)) < 0.2 * np.sqrt(np.mean((area - img[inside]) ** 2))


@pytest.mark.parametrize("twist", [False, True])
def test_self_similar_under_its_symmetry(smooth_image, twist) -> None:
    """Zoomed by lambda (twisted: its spiral similarity) about the centre, it is itself."""
    h = 128
    img = smooth_image(h)
    d = droste_map(hole_from_corners(SQUARE), 5.0, twist=twist)
    out = warp(img, d, supersample=2)
    again = warp(out, d.symmetry())
    ll = pixel_lonlat(h, 2 * h)
    # near the fixed points the copies shrink to a few pixels: leave them out
    away = (angular_distance(ll, d_center(d)) > 12) & (angular_distance(ll, d_far(d)) > 25)
    # interpolation across the edges between copies differs: leave them out, both where
    # they are in the output and where the symmetry takes them
    edges = near_tile_edges(d, h, 2 * h, 2)
    moved = warp(edges.astype(np.float32), d.symmetry(), interp="nearest")[..., 0] > 0
    away &= ~edges & ~moved
    assert away.mean() > 0.4
    diff = np.abs(again.astype(float) - out.astype(float)).max(axis=-1)[away]
    assert np.median(diff) < 1e-3
    assert diff.max() < 0.03
    # a different zoom is not a symmetry
    other = warp(out, Mobius.zoom_between(d.far, d.center, 2.0))
    assert np.median(np.abs(other.astype(float) - out.astype(float)).max(axis=-1)[away]) > 0.02


def near_tile_edges(d: Droste, h: int, w: int, pixels: int) -> np.ndarray:
    """Pixels within ``pixels`` of an edge between two copies of the annulus."""
    from scipy import ndimage

    k = d.tile_index(pixel_cp1(h, w))
    edge = np.zeros((h, w), bool)
    edge[:, :-1] |= k[:, :-1] != k[:, 1:]
    edge[:-1] |= k[:-1] != k[1:]
    edge[:, -1] |= k[:, -1] != k[:, 0]
    edge = np.pad(edge, ((0, 0), (pixels, pixels)), mode="wrap")
    edge = ndimage.binary_dilation(edge, iterations=pixels)
    return edge[:, pixels:-pixels]


def d_center(d: Droste) -> tuple[float, float]:
    return tuple(np.degrees(coords.lonlat_from_cp1(d.center)))


def d_far(d: Droste) -> tuple[float, float]:
    return tuple(np.degrees(coords.lonlat_from_cp1(d.far)))


@pytest.mark.parametrize("twist", [False, True])
def test_phase_one_equals_phase_zero_and_frames_loop(random_image, twist) -> None:
    img = random_image(H)
    d = droste_map(hole_from_corners(SQUARE), 4.0, twist=twist)
    first = warp(img, d)
    for t in (1.0, -1.0, 3.0):
        diff = np.abs(warp(img, d.with_phase(t)).astype(int) - first.astype(int))
        assert np.mean(diff > 1) < 0.002
    frames = list(droste_frames(img, d, 3))
    assert len(frames) == 3
    np.testing.assert_array_equal(frames[0], first)
    np.testing.assert_array_equal(frames[1], warp(img, d.with_phase(1 / 3)))
    assert np.mean(frames[1] != frames[0]) > 0.2
    assert animation_phases(4, 0.5) == [0.5, 0.75, 1.0, 1.25]
    with pytest.raises(InvalidValueError):
        animation_phases(0)


def test_two_images_alternate_inward() -> None:
    hole = hole_from_radius((0, 0), 20)
    d = droste_map(hole, 4.0, n_images=2)
    a = np.full((H, W, 3), 50, np.uint8)
    b = np.full((H, W, 3), 200, np.uint8)
    out = droste_image([a, b], d, antialias="none")
    ll = pixel_lonlat(H, W)
    k = d.tile_index(coords.cp1_from_lonlat(np.radians(ll)))
    np.testing.assert_array_equal(out[..., 0][k % 2 == 0], 50)
    np.testing.assert_array_equal(out[..., 0][k % 2 != 0], 200)
    assert {-1, 0, 1} <= set(np.unique(k))
    with pytest.raises(InvalidValueError, match="2 input images"):
        droste_image(a, d)


def test_no_nan_and_finite_local_scale_on_float_images(smooth_image) -> None:
    img = smooth_image(H, np.float32)
    for d in (
        droste_map(hole_from_corners(SQUARE), 3.0),
        droste_map(hole_from_corners(SQUARE, far=(0, -90)), 3.0, twist=True),
    ):
        out = warp(img, d, supersample=2)
        assert np.all(np.isfinite(out))
        assert np.all(np.isfinite(d.local_scale(pixel_cp1(H, W))))


def test_demo_frame_on_the_interior(interior) -> None:
    """The README demo: the room inside its picture, and a portal opposite."""
    hole = hole_from_corners(PICTURE)
    d = droste_map(hole)
    out = warp(interior, d, output_shape=(128, 256))
    small = warp(interior, Mobius.identity(), output_shape=(128, 256))
    ll = pixel_lonlat(128, 256)
    in_hole = hole.contains(ll)
    # the picture's own content is gone from the hole: it shows the room instead
    assert np.abs(out[in_hole].astype(float) - small[in_hole]).mean() > 20
    # the portal round the antipode is as large as the hole
    portal = d.tile_index(coords.cp1_from_lonlat(np.radians(ll))) >= 1
    assert 0.5 < portal.sum() / in_hole.sum() < 2.0


# -- the log view ---------------------------------------------------------------------------------


def _best_shift(img: np.ndarray, axis: int, lo: int, hi: int) -> int:
    a = img.astype(float)
    n = a.shape[axis]
    errs = []
    for s in range(lo, hi):
        x = np.take(a, np.arange(0, n - s), axis=axis)
        y = np.take(a, np.arange(s, n), axis=axis)
        errs.append(np.abs(x - y).mean())
    return lo + int(np.argmin(errs))


def test_log_view_period_is_measurable_in_pixels(random_image) -> None:
    img = random_image(128)
    d = droste_map(hole_from_radius((0, 0), 20), 3.0)
    view = log_view(img, d, height=200, periods=4, dim=1.0, draw_period=False)
    lay = log_view_layout(d, height=200, periods=4)
    assert view.shape == (200, lay.width, 3)
    period_px = math.log(3.0) * lay.pixels_per_unit
    assert lay.pixels_per_unit * 2 * math.pi == pytest.approx(200)
    assert abs(_best_shift(view, 1, 10, lay.width // 2) - period_px) <= 1
    # twisted, input plane: the view is taller than 2 pi; both periods show
    tw = droste_map(hole_from_radius((0, 0), 20), 3.0, twist=True)
    tview = log_view(img, tw, height=200, periods=4, dim=1.0, draw_period=False)
    tlay = log_view_layout(tw, height=200, periods=4)
    assert abs(_best_shift(tview, 0, 20, 199) - 2 * math.pi * tlay.pixels_per_unit) <= 1
    assert abs(_best_shift(tview, 1, 10, tlay.width // 2) - math.log(3) * tlay.pixels_per_unit) <= 1


def test_log_view_draws_the_period_rectangle() -> None:
    img = np.zeros((64, 128, 3), np.uint8)
    d = droste_map(hole_from_radius((0, 0), 20), math.exp(2.0))
    view = log_view(img, d, height=100, periods=3)
    lay = log_view_layout(d, height=100, periods=3)
    red = (view[..., 0] == 255) & (view[..., 1] == 0)
    cols = np.flatnonzero(red[50])
    left = (d.rho.mean() - lay.u_left) * lay.pixels_per_unit
    assert abs(cols.min() - left) <= 2 and abs(cols.max() - (left + 2 * lay.pixels_per_unit)) <= 2
    assert red[0].sum() > 0.5 * 2 * lay.pixels_per_unit  # top edge at theta = pi
    # the output plane of a twisted map: the rectangle stands upright, 2 pi high
    tw = droste_map(hole_from_radius((0, 0), 20), math.exp(2.0), twist=True)
    out_lay = log_view_layout(tw, height=100, plane="output")
    rect = np.array(out_lay.rectangle)
    sides = np.diff(np.append(rect, rect[0]))
    assert np.allclose(np.abs(sides[1]), 2 * math.pi) and abs(sides[1].real) < 1e-9
    out_view = log_view(img, tw, height=100, plane="output")
    assert out_view.shape[0] == 100


def test_log_view_dims_the_copies_and_keeps_dtype(smooth_image) -> None:
    img = smooth_image(64, np.float32)
    d = droste_map(hole_from_radius((0, 0), 20), 3.0)
    bright = log_view(img, d, height=64, dim=1.0, draw_period=False)
    dimmed = log_view(img, d, height=64, dim=0.5, draw_period=False)
    assert dimmed.dtype == np.float32
    lay = log_view_layout(d, height=64)
    y, x = np.mgrid[0:64, 0 : lay.width] + 0.5
    k = d.reduce_log(lay.log_from_pixel(x, y))[1]
    np.testing.assert_allclose(dimmed[k == 0], bright[k == 0])
    np.testing.assert_allclose(dimmed[k != 0], 0.5 * bright[k != 0], rtol=1e-5)
    with pytest.raises(InvalidValueError, match="plane"):
        log_view(img, d, plane="sideways")
    with pytest.raises(InvalidValueError, match="dim"):
        log_view(img, d, dim=2)
