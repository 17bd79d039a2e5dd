"""The compiled Schottky stage against the NumPy reduction of ``maps.Schottky``."""

from __future__ import annotations

import numpy as np
import pytest

from spherewarp import coords
from spherewarp.maps import Mobius, Schottky
from spherewarp.render import fast, stages, warp

needs_jit = pytest.mark.skipif(not fast.available(), reason="numba is not installed")

IN_SHAPE = (64, 128)
OUT_SHAPE = (48, 96)
PAIRS = [((-163, 5, 12), (17, -5, 25)), ((-75, 10, 15), (105, 0, 20))]
MAPS = {
    "two": Schottky.from_disk_pairs(PAIRS),
    "twisted_phase": Schottky.from_disk_pairs(PAIRS, twists=[30, -20], phase=0.4),
    "one_matrix": Schottky([((0, 90, 20), Mobius([[30, 0], [0, 1]]))]),
    "shallow": Schottky.from_disk_pairs(
        [((0, 0, 40), (180, 0, 40)), ((90, 0, 40), (-90, 0, 40))], depth=1
    ),
}
KINDS = {"two": [6], "twisted_phase": [1, 6], "one_matrix": [6], "shallow": [6]}


def _margin(s, xyz):
    """Angular distance (radians) to the nearest disk boundary, along the reduction's first
    step too (a point near a boundary of a copy is ill-posed at rounding level)."""
    caps = [c for c, _ in s.generators] + s.target_disks()
    d = [np.abs(np.arccos(np.clip(xyz @ c.normal, -1, 1)) - np.radians(c.radius)) for c in caps]
    return np.min(d, axis=0)


def _grid(shape):
    h, w = shape
    g = np.stack(np.meshgrid(np.arange(w) + 0.5, np.arange(h) + 0.5), -1)
    return coords.cp1_from_lonlat(coords.lonlat_from_pixel(g, w, h))


@needs_jit
@pytest.mark.parametrize("name", MAPS)
def test_map_compiles_to_the_schottky_stage(name):
    spec = fast.kernel_spec(MAPS[name])
    assert spec is not None and spec.codes.tolist() == KINDS[name]
    assert spec.max_scale == np.inf
    assert stages.BY_NAME["schottky"].has_jumps


@needs_jit
@pytest.mark.parametrize("name", MAPS)
def test_pixel_centres_match_the_reduction(name):
    """Source points, magnification and validity of every pixel centre, as the NumPy path,
    away from the disk boundaries (the reference's own pixel grid of 1/20 pixel aside)."""
    m = MAPS[name]
    h_in, w_in = IN_SHAPE
    x, y, s, ok = fast.source_coords(fast.kernel_spec(m), IN_SHAPE, OUT_SHAPE)
    zw = _grid(OUT_SHAPE)
    pb = m.pull(zw)
    ll = coords.lonlat_from_cp1(pb.points)
    ref = coords.pixel_from_lonlat(ll, w_in, h_in)
    # the reduction of each point moves it through disks: keep the points whose whole path
    # stays clear of every boundary (the phase's pre-map first)
    pre = m._pre.pull_cp1(zw) if m._pre is not None else zw
    clear = _margin(m, coords.xyz_from_cp1(pre)) > 1e-6
    clear &= _margin(m, coords.xyz_from_cp1(pb.points)) > 1e-6
    assert clear.mean() > 0.9
    assert np.array_equal(ok[clear], pb.valid[clear])
    keep = clear & pb.valid
    dx = np.abs((x - ref[..., 0] + w_in / 2) % w_in - w_in / 2)
    at_pole = np.abs(ll[..., 1]) > np.pi / 2 - 1e-7
    assert dx[keep & ~at_pole].max() <= 1e-6
    assert np.abs(y - ref[..., 1])[keep].max() <= 1e-6
    rs = m.local_scale(zw)
    assert np.allclose(s[keep], rs[keep], rtol=1e-6)


@needs_jit
def test_depth_cap_makes_pixels_transparent_as_the_reference():
    """Pixels not reduced within ``depth`` moves are alpha 0 on both paths."""
    m = MAPS["shallow"]
    img = np.full((*IN_SHAPE, 3), 200, np.uint8)
    got = warp(img, m, output_shape=OUT_SHAPE, antialias="none", alpha=True)
    ref = warp(img, m, output_shape=OUT_SHAPE, antialias="none", alpha=True, method="reference")
    pb = m.pull(_grid(OUT_SHAPE))
    assert (~pb.valid).sum() > 50  # depth 1 leaves the copies of copies undefined
    clear = _margin(m, coords.xyz_from_cp1(_grid(OUT_SHAPE))) > np.radians(3)
    clear &= _margin(m, coords.xyz_from_cp1(pb.points)) > np.radians(3)
    assert np.array_equal(got[clear][:, 3] == 0, ~pb.valid[clear])
    assert np.array_equal(ref[clear][:, 3] == 0, ~pb.valid[clear])


@needs_jit
@pytest.mark.parametrize("name", ["two", "twisted_phase"])
def test_rendered_image_matches_reference(name):
    """Whole renders (uint8, no anti-aliasing) against the reference path."""
    rng = np.random.default_rng(3)
    img = np.kron(rng.uniform(0, 255, (8, 16, 3)), np.ones((8, 8, 1))).astype(np.uint8)
    m = MAPS[name]
    got = warp(img, m, antialias="none").astype(float)
    ref = warp(img, m, antialias="none", method="reference").astype(float)
    err = np.abs(got - ref)
    assert np.median(err) <= 1.0
    assert np.mean(err) <= 2.0


@needs_jit
@pytest.mark.parametrize("mode", ["area", "auto"])
@pytest.mark.parametrize("dtype", [np.uint8, np.float32])
def test_area_filter_matches_reference(mode, dtype):
    """The default filter (the area filter, with the disk edges found as jumps) against the
    float64 NumPy reference, on a smooth image."""
    y, x = np.mgrid[0:64, 0:128] + 0.5
    lon, lat = x / 128 * 2 * np.pi, (0.5 - y / 64) * np.pi
    base = 128 + 60 * np.sin(3 * lon) * np.cos(lat) + 50 * np.cos(5 * lat + lon)
    img = np.stack([base, 255 - base, 0.5 * base + 40], -1).astype(dtype)
    m = MAPS["two"]
    got = warp(img, m, output_shape=(70, 140), antialias=mode).astype(float)
    ref = warp(img, m, output_shape=(70, 140), antialias=mode, method="reference")
    err = np.abs(got - ref).max(-1)
    assert np.mean(err > 1.0) < 0.01, (np.mean(err > 1.0), err.max())
    assert np.median(err) < 0.2


@needs_jit
def test_disk_edges_are_supersampled():
    """In ``auto`` the compiled renderer finds the disk edges as jumps: on an image of fine
    detail the pixels along them differ from the render without anti-aliasing."""
    rng = np.random.default_rng(11)
    img = rng.integers(0, 256, (64, 128, 3), dtype=np.uint8)
    m = Schottky.from_disk_pairs([((0, 0, 30), (180, 0, 30))])
    auto = warp(img, m, output_shape=OUT_SHAPE).astype(float)
    none = warp(img, m, output_shape=OUT_SHAPE, antialias="none").astype(float)
    zw = _grid(OUT_SHAPE)
    xyz = coords.xyz_from_cp1(zw)
    edge = _margin(m, xyz) < np.radians(360 / OUT_SHAPE[1])
    inside = _margin(m, xyz) > np.radians(4 * 360 / OUT_SHAPE[1])
    free = inside & ~np.any([c.contains(xyz) for c in m.target_disks()], axis=0)
    free &= ~m.generators[0][0].contains(xyz)
    assert edge.sum() > 10
    assert np.abs(auto - none).max(-1)[edge].mean() > 5
    # the fundamental region: the input, filtered as the identity map filters it
    plain = warp(img, Mobius.identity(), output_shape=OUT_SHAPE).astype(float)
    assert np.abs(auto - plain).max(-1)[free].max() <= 1.0


def test_output_sized_depth():
    s = MAPS["two"]
    assert s.for_output(512).depth <= s.depth <= s.for_output(1 << 16).depth
    assert Schottky.from_disk_pairs(PAIRS, depth=7).for_output(64).depth == 7
    again = s.for_output(64).with_phase(0.5)
    assert again.depth == s.for_output(64).depth


def _mask_map():
    """The paper's workflow on a synthetic mask: a red rectangle and a green square, the
    generators built from the disks inside them."""
    from spherewarp.maps.schottky import Cap, MaskRegions, cap_from_mask, generator_between

    mask = np.zeros((90, 180, 3), np.uint8)
    mask[41:49, 80:100] = (255, 0, 0)  # lon -20..20, lat -8..8
    mask[30:38, 30:38] = (0, 255, 0)  # lon -120..-104, lat 14..30
    red, green = (cap_from_mask(mask, c, inside=True) for c in ((1, 0, 0), (0, 1, 0)))
    s = Schottky(
        [(red, generator_between(red, Cap(170, 0, 15))), (green, Mobius.zoom((-112, 22), 40))],
        phase=0.3,
    )
    return s.with_mask_regions(MaskRegions(mask, [(1, 0, 0), (0, 1, 0)])), mask


@needs_jit
def test_mask_regions_compile_and_match_the_reduction():
    """The exact disks of a mask (schottky_mask stage): every pixel centre's source point,
    magnification and validity as the NumPy reduction, away from the mask's region edges;
    rendered, the two paths agree to rounding (the pixels on region edges aside)."""
    m, mask = _mask_map()
    spec = fast.kernel_spec(m)
    assert spec.codes.tolist() == [1, 7] and stages.BY_NAME["schottky_mask"].has_jumps
    h_in, w_in = IN_SHAPE
    out_shape = (90, 180)
    x, y, s, ok = fast.source_coords(spec, IN_SHAPE, out_shape)
    zw = _grid(out_shape)
    pb = m.pull(zw)
    ref = coords.pixel_from_lonlat(coords.lonlat_from_cp1(pb.points), w_in, h_in)
    same = ok == pb.valid
    assert same.mean() > 0.99
    keep = same & pb.valid
    dx = np.abs((x - ref[..., 0] + w_in / 2) % w_in - w_in / 2)
    close = (dx <= 1e-6) & (np.abs(y - ref[..., 1]) <= 1e-6)
    assert close[keep].mean() > 0.99  # the rest: points on a region's pixel edge
    assert np.allclose(s[keep & close], m.local_scale(zw)[keep & close], rtol=1e-6)
    img = np.random.default_rng(3).integers(0, 256, (*IN_SHAPE, 3), dtype=np.uint8)
    a = warp(img, m, output_shape=OUT_SHAPE).astype(int)
    b = warp(img, m, output_shape=OUT_SHAPE, method="reference").astype(int)
    assert (np.abs(a - b).max(axis=-1) <= 1).mean() > 0.98
