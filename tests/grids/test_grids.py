"""Output grids: directions where the projection formulas put them, v360's cube maps and
flat view, round trips through --to/--from, and every effect in every grid."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from spherewarp import coords, warp
from spherewarp.grids import GRIDS, from_grid, make_grid
from spherewarp.maps import Droste, ExpMap, ExpressionMap, Lattes, Mobius, Power
from spherewarp.render import WarpMap

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "oracles"))
from _v360 import have_v360  # noqa: E402

DATA = Path(__file__).resolve().parents[2] / "src" / "spherewarp" / "data"


@pytest.fixture(scope="module")
def interior():
    from spherewarp.io import read_image

    return read_image(DATA / "interior.png").pixels


@pytest.fixture(scope="module")
def direction_image():
    """A panorama whose pixels hold their own direction (float32 xyz)."""
    h, w = 512, 1024
    y, x = np.mgrid[0:h, 0:w] + 0.5
    ll = coords.lonlat_from_pixel(np.stack([x, y], -1), w, h)
    return coords.xyz_from_lonlat(ll).astype(np.float32)


def _expected(name: str, shape, look_at, fov):
    """Directions by the formulas alone (radius ~ tan(t/2), tan t, t, sin(t/2) from the
    look-at point; up in the picture is up at the look-at point)."""
    h, w = shape
    y, x = np.mgrid[0:h, 0:w] + 0.5
    lon, lat = np.radians(look_at)
    f = np.array([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)])
    r = np.array([-np.sin(lon), np.cos(lon), 0.0])
    u = np.array([-np.sin(lat) * np.cos(lon), -np.sin(lat) * np.sin(lon), np.cos(lat)])
    half = np.radians(fov) / 2
    if name == "rectilinear":
        s = w / 2
        a, b = (x - w / 2) / s * np.tan(half), (h / 2 - y) / s * np.tan(half)
        d = f + a[..., None] * r + b[..., None] * u
        return d / np.linalg.norm(d, axis=-1, keepdims=True), np.ones((h, w), bool)
    s = min(h, w) / 2
    a, b = (x - w / 2) / s, (h / 2 - y) / s
    rho = np.hypot(a, b)
    if name == "little-planet":
        t = 2 * np.arctan(rho * np.tan(half / 2))
    else:  # fisheye
        t = rho * half
    phi = np.arctan2(b, a)
    d = (
        np.cos(t)[..., None] * f
        + (np.sin(t) * np.cos(phi))[..., None] * r
        + (np.sin(t) * np.sin(phi))[..., None] * u
    )
    return d, rho <= 1 if name == "fisheye" else np.ones((h, w), bool)


@pytest.mark.parametrize(
    "name, look_at, fov",
    [
        ("little-planet", (0, -90), 270),
        ("little-planet", (30, 20), 200),
        ("rectilinear", (30, 20), 90),
        ("rectilinear", (-120, -60), 40),
        ("fisheye", (30, 20), 180),
        ("fisheye", (100, 70), 300),
    ],
)
@pytest.mark.parametrize("antialias", ["none", "auto"])
def test_directions_follow_the_formula(direction_image, name, look_at, fov, antialias):
    shape = (96, 128) if name == "rectilinear" else (112, 112)
    g = make_grid(name, shape=shape, look_at=look_at, fov=fov)
    out = warp(direction_image, Mobius.identity(), grid=g, antialias=antialias).astype(float)
    want, inside = _expected(name, shape, look_at, fov)
    got = out / np.maximum(np.linalg.norm(out, axis=-1, keepdims=True), 1e-30)
    err = np.degrees(np.arccos(np.clip(np.sum(got * want, -1), -1, 1)))[inside]
    assert np.percentile(err, 99) < 0.05
    # and the grid's own directions and inverse agree with the formula
    d, _ = g.directions()
    assert np.max(np.abs(d - want)[inside]) < 1e-9
    px, ok = g.inverse(want[inside])
    y, x = np.mgrid[0 : shape[0], 0 : shape[1]] + 0.5
    assert ok.all()
    assert np.max(np.abs(px - np.stack([x, y], -1)[inside])) < 1e-6


def test_little_planet_defaults():
    g = make_grid("little-planet", (512, 1024))
    assert g.shape == (512, 512) and g.look_at == (0.0, -90.0)
    px, ok = g.inverse(np.array([[0.0, 0.0, -1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]))
    assert ok.all()
    np.testing.assert_allclose(px[0], (256, 256), atol=1e-9)  # the nadir in the middle
    assert px[1, 1] < 256 and abs(px[1, 0] - 256) < 1e-9  # the front above it
    # the horizon: a circle round the centre
    lon = np.radians(np.arange(0, 360, 15))
    hz = np.stack([np.cos(lon), np.sin(lon), 0 * lon], -1)
    r = np.hypot(*(g.inverse(hz)[0] - 256).T)
    np.testing.assert_allclose(r, r[0], rtol=1e-12)
    assert 0.3 * 256 < r[0] < 0.6 * 256
    # the zenith is off the picture (the sky is round the planet)
    assert not g.inverse([0.0, 0.0, 1.0])[1]


def _box4(a):
    h, w = (s // 4 * 4 for s in a.shape[:2])
    return a[:h, :w].reshape(h // 4, 4, w // 4, 4, -1).astype(float).mean((1, 3))


def _psnr(a, b, mask=None):
    d = (a.astype(float) - b.astype(float)) ** 2
    d = d if mask is None else d[mask]
    return 10 * np.log10(255.0**2 / max(d.mean(), 1e-12))


@pytest.mark.skipif(not have_v360(), reason="PyAV with ffmpeg's v360 is not installed")
@pytest.mark.parametrize(
    "name, v360_name, shape, view",
    [
        ("cubemap", "c3x2", (256, 384), {}),
        ("cubemap-6x1", "c6x1", (128, 768), {}),
        ("rectilinear", "flat", (240, 320), {"fov": 90}),
        ("rectilinear", "flat", (240, 320), {"fov": 70, "look_at": (30, 20), "roll": 10}),
    ],
)
def test_matches_v360(interior, name, v360_name, shape, view):
    from _v360_views import v360_view

    opts = {}
    if "fov" in view:
        h_fov = view["fov"]
        v_fov = 2 * np.degrees(np.arctan(np.tan(np.radians(h_fov / 2)) * shape[0] / shape[1]))
        opts = {"h_fov": h_fov, "v_fov": v_fov}
        lon, lat = view.get("look_at", (0, 0))
        opts.update(yaw=lon, pitch=lat, roll=view.get("roll", 0))
    ref = v360_view(interior, v360_name, shape[1], shape[0], **opts)
    g = make_grid(name, shape=shape, **view)
    mine = warp(interior, Mobius.identity(), grid=g, antialias="none")
    assert _psnr(_box4(ref), _box4(mine)) >= 36


@pytest.mark.parametrize(
    "name, shape, floor",
    [
        ("cubemap", None, 35),
        ("cubemap-6x1", None, 35),
        ("fisheye", (1024, 1024), 35),
        ("equirect", None, 60),
    ],
)
def test_round_trip(interior, name, shape, floor):
    """--to then --from gives the panorama back where the view covers it, the cube maps
    over the whole sphere at their default size and filter (36.2 dB measured; 28.8 dB
    with faces half the panorama's height and bilinear back)."""
    g = make_grid(name, interior.shape[:2], shape=shape)
    view = warp(interior, Mobius.identity(), grid=g)
    back = from_grid(view, g, interior.shape[:2], alpha=True)
    covered = back[..., 3] == 255
    assert covered.mean() > (0.45 if name == "fisheye" else 0.999)
    assert _psnr(back[..., :3], interior, covered) >= floor


MAPS = {
    "rotation": Mobius.from_yaw_pitch_roll(30, 20, 10),
    "zoom": Mobius.zoom((0, -90), 3).inverse(),
    "power": Power(2),
    "exp": ExpMap(3),
    "droste": Droste((0, 0), np.full(16, np.log(0.3)), 3.0),
    "lattes": Lattes((2, 1)),
    "expression": ExpressionMap("z**2 + 0.5"),
}


@pytest.mark.parametrize("grid", [n for n in GRIDS if n != "stereographic"])
@pytest.mark.parametrize("map_name", list(MAPS))
def test_every_effect_in_every_grid(grid, map_name):
    """A constant panorama stays constant in every grid: no NaN, no seam, no hole."""
    img = np.full((32, 64, 3), 0.75, np.float32)
    g = make_grid(grid, (32, 64), look_at=(20, 10) if grid != "little-planet" else None)
    out = warp(img, MAPS[map_name], grid=g, alpha=True)
    assert out.shape[:2] == g.shape and np.isfinite(out).all()
    _, inside = g.directions()
    a = out[..., 3]
    assert np.all(a[inside] > 0.999)  # no holes
    np.testing.assert_allclose(out[..., :3][inside], 0.75, atol=1e-4)  # no seams
    assert np.all(a[~inside] == 0)  # outside a fisheye's circle: transparent


@pytest.fixture(scope="module")
def noise():
    return np.random.default_rng(5).integers(0, 256, (32, 64, 3), dtype=np.uint8)


@pytest.mark.parametrize("grid", [n for n in GRIDS if n != "stereographic"])
@pytest.mark.parametrize("map_name", list(MAPS))
@pytest.mark.parametrize("antialias", ["auto", "none"])
def test_stills_are_cached_map_frames(noise, grid, map_name, antialias):
    g = make_grid(grid, (32, 64), look_at=(20, 10) if grid != "little-planet" else None)
    m = MAPS[map_name]
    wm = WarpMap(m, (32, 64), grid=g, antialias=antialias)
    still = warp(noise, m, grid=g, antialias=antialias)
    np.testing.assert_array_equal(wm.apply(noise), still)
    np.testing.assert_array_equal(
        wm.apply(noise, alpha=True), warp(noise, m, grid=g, antialias=antialias, alpha=True)
    )


@pytest.mark.parametrize("map_name", list(MAPS))
def test_plain_panorama_too(noise, map_name):
    m = MAPS[map_name]
    for shape in ((32, 64), (24, 48)):
        wm = WarpMap(m, (32, 64), shape)
        np.testing.assert_array_equal(wm.apply(noise), warp(noise, m, output_shape=shape))


def test_peirce_and_torus_grids_are_the_existing_projections(interior):
    from spherewarp.effects import torus
    from spherewarp.grids import peirce as projections

    small = interior[::4, ::4]
    g = make_grid("peirce", small.shape[:2])
    mine = warp(small, Mobius.identity(), grid=g, antialias="none")
    assert _psnr(mine, projections.render_peirce(small, g.shape[0])) > 60
    g = make_grid("torus", small.shape[:2])
    mine = warp(small, Mobius.identity(), grid=g, antialias="none")
    assert _psnr(mine, torus.render_torus(small, "square", width=g.shape[1])) > 60


def _resolved(g, shape):
    """Panorama pixels that the grid covers at least at the panorama's resolution (a
    pixel step of the panorama is at least one pixel of the grid, both ways)."""
    h, w = shape
    y, x = np.mgrid[0:h, 0:w] + 0.5

    def inv(xx, yy):
        ll = coords.lonlat_from_pixel(np.stack([xx, yy], -1), w, h)
        return g.inverse(coords.xyz_from_lonlat(ll))

    _, ok = inv(x, y)
    sx = np.linalg.norm(inv(x + 0.5, y)[0] - inv(x - 0.5, y)[0], axis=-1)
    sy = np.linalg.norm(inv(x, y + 0.5)[0] - inv(x, y - 0.5)[0], axis=-1)
    return ok & (np.minimum(sx, sy) >= 0.99)


@pytest.mark.parametrize(
    "name", ["little-planet", "rectilinear", "fisheye", "equisolid", "cubemap", "peirce"]
)
def test_round_trip_where_the_view_resolves_the_panorama(interior, name):
    """At the default sizes: --to then --from gives the panorama back (>= 35 dB; 40-47 dB
    measured) wherever the view has at least the panorama's resolution."""
    g = make_grid(name, interior.shape[:2])
    view = warp(interior, Mobius.identity(), grid=g, antialias="none")
    back = from_grid(view, g, interior.shape[:2], alpha=True)
    m = _resolved(g, interior.shape[:2]) & (back[..., 3] == 255)
    assert m.mean() > 0.05
    assert _psnr(back[..., :3], interior, m) >= 35


def test_turned_equirect_takes_the_fast_path_and_agrees_with_the_grid_path(interior):
    from dataclasses import replace

    from spherewarp.grids.render import render_into
    from spherewarp.render.plan import plan

    small = interior[::2, ::2]
    g = make_grid("equirect", small.shape[:2], look_at=(30, 20), roll=10)
    m = Power(2)
    fast = warp(small, m, grid=g, antialias="none")
    ref = np.empty_like(fast)
    bg = np.zeros(3, np.float32)
    p = plan(m, None, small.shape[:2], antialias="none", method="reference")
    p = replace(p, grid=g, path="grid")  # the grid's own geometry, not the turned map's
    render_into([small], p, ref, bg)
    assert np.abs(fast.astype(int) - ref).max() <= 1


@pytest.mark.skipif(not have_v360(), reason="PyAV with ffmpeg's v360 is not installed")
@pytest.mark.parametrize("fov, view", [(180, {}), (120, {"look_at": (30, 20), "roll": 10})])
def test_fisheye_matches_v360(interior, fov, view):
    """v360's fisheye is the equidistant one (48-51 dB inside the circle)."""
    from _v360_views import v360_view

    opts = {"h_fov": fov, "v_fov": fov}
    if view:
        opts.update(yaw=view["look_at"][0], pitch=view["look_at"][1], roll=view["roll"])
    ref = v360_view(interior, "fisheye", 256, 256, **opts)
    g = make_grid("fisheye", shape=(256, 256), fov=fov, **view)
    mine = warp(interior, Mobius.identity(), grid=g, antialias="none")
    _, inside = g.directions()
    whole = _box4(inside[..., None].astype(float))[..., 0] == 1  # 4x4 boxes inside the circle
    assert _psnr(_box4(ref), _box4(mine), whole) >= 36


@pytest.mark.parametrize("name", ["rectilinear", "little-planet", "cubemap", "fisheye"])
def test_no_seam_where_the_view_crosses_the_panoramas_edge(interior, name):
    """Looking at the back (the panorama's left/right edge) gives the picture of the
    panorama turned half round looking at the front: the edge leaves no trace, with
    the area filter too."""
    small = interior[::2, ::2]
    turned = np.roll(small, small.shape[1] // 2, axis=1)
    lat = -90 if name == "little-planet" else 0
    m = Mobius.rotation((0, 90), 0.0)
    a = warp(small, m, grid=make_grid(name, small.shape[:2], look_at=(180, lat)), antialias="area")
    b = warp(turned, m, grid=make_grid(name, small.shape[:2], look_at=(0, lat)), antialias="area")
    assert np.abs(a.astype(int) - b).max() <= 1


@pytest.mark.parametrize(
    "name, m",
    [
        ("little-planet", Mobius.zoom((0, -90), 0.5).inverse()),
        ("cubemap", Droste((0, 0), np.full(16, np.log(0.3)), 3.0)),
    ],
)
def test_area_filter_in_a_grid_is_what_supersampling_converges_to(interior, name, m):
    """The grid's area filter against 8 x 8 supersampling (70 and 54 dB measured; single
    taps: 40 and 34 dB)."""
    g = make_grid(name, interior.shape[:2], shape=(128, 128) if name != "cubemap" else (128, 192))
    ref = warp(interior, m, grid=g, antialias=8)
    area = warp(interior, m, grid=g, antialias="area")
    one = warp(interior, m, grid=g, antialias="none")
    assert _psnr(area, ref) >= 45
    assert _psnr(area, ref) > _psnr(one, ref) + 8
