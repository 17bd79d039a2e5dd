"""The Schottky map: the reduction, invariance, Droste as one generator, phase, validation."""

from __future__ import annotations

import numpy as np
import pytest

from spherewarp import coords
from spherewarp.errors import InvalidValueError
from spherewarp.maps import Mobius, Schottky, map_from_json
from spherewarp.maps.schottky import Cap, cap_image, generator_between

PAIRS = [((-163, 5, 12), (17, -5, 25)), ((-75, 10, 15), (105, 0, 20))]


def _points(n=3000, seed=1):
    v = np.random.default_rng(seed).normal(size=(n, 3))
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def _reference(s, xyz, depth=400):
    """Independent reduction, one point at a time: the issue's rule read literally (the first
    open disk the point lies in decides the step), plain complex arithmetic on pairs."""
    gens = []
    for (cap, m), t in zip(s.generators, s.target_disks(), strict=True):
        (a, b), (c, d) = m.matrix
        gens.append((cap.normal, np.cos(np.radians(cap.radius)), (a, b, c, d)))
        gens.append((t.normal, np.cos(np.radians(t.radius)), (d, -b, -c, a)))
    out = []
    for v in xyz:
        zw = coords.cp1_from_xyz(v)
        z, w = complex(zw[0]), complex(zw[1])
        for _ in range(depth):
            p = coords.xyz_from_cp1(np.array([z, w]))
            for n, cr, (a, b, c, d) in gens:
                if p @ n > cr:
                    z, w = a * z + b * w, c * z + d * w
                    nrm = np.sqrt(abs(z) ** 2 + abs(w) ** 2)
                    z, w = z / nrm, w / nrm
                    break
            else:
                break
        out.append(coords.xyz_from_cp1(np.array([z, w])))
    return np.array(out)


def _margin(s, xyz):
    """Angular distance (radians) of points to the nearest disk boundary."""
    caps = [c for c, _ in s.generators] + s.target_disks()
    d = [np.abs(np.arccos(np.clip(xyz @ c.normal, -1, 1)) - np.radians(c.radius)) for c in caps]
    return np.min(d, axis=0)


def test_reduction_matches_an_independent_reimplementation():
    s = Schottky.from_disk_pairs(PAIRS)
    xyz = _points()
    got = s.apply_xyz(xyz)
    want = _reference(s, xyz)
    ok = _margin(s, xyz) > 1e-6
    assert ok.mean() > 0.99
    assert np.abs(got - want)[ok].max() < 1e-9


def test_fundamental_region_is_fixed_and_disks_are_reduced():
    s = Schottky.from_disk_pairs(PAIRS)
    xyz = _points()
    caps = [c for c, _ in s.generators] + s.target_disks()
    inside = np.any([c.contains(xyz) for c in caps], axis=0)
    got = s.apply_xyz(xyz)
    assert np.allclose(got[~inside], xyz[~inside])
    assert not np.any([c.contains(got, strict=True) for c in caps])


@pytest.mark.parametrize("which", [0, 1])
def test_invariant_under_each_generator(which):
    s = Schottky.from_disk_pairs(PAIRS)
    xyz = _points()
    m = s.generators[which][1]
    a = s.apply_xyz(xyz)
    pb = s.pull(coords.cp1_from_xyz(m.apply_xyz(xyz)))
    b = coords.xyz_from_cp1(pb.points)
    ok = (_margin(s, xyz) > 1e-6) & (_margin(s, m.apply_xyz(xyz)) > 1e-6) & pb.valid
    assert ok.mean() > 0.95
    assert np.abs(a - b)[ok].max() < 1e-8


def test_one_generator_is_the_straight_droste():
    from spherewarp.effects.droste import droste_map, hole_from_radius

    lam, r, p = 10.0, 15.0, (-163.0, 5.0)
    s = Schottky([((p[0], p[1], r), Mobius.zoom(p, lam))])
    d = droste_map(hole_from_radius(p, r), lam)
    xyz = _points()
    got, want = s.apply_xyz(xyz), d.apply_xyz(xyz)
    ok = _margin(s, xyz) > 1e-6
    assert np.abs(got - want)[ok].max() < 1e-8
    # and the phase is the Droste phase
    got = s.with_phase(0.3).apply_xyz(xyz)
    want = d.with_phase(0.3).apply_xyz(xyz)
    far = np.abs(got - want).max(axis=1) > 1e-6
    assert far.mean() < 0.01  # only points next to a boundary differ


def test_phase_one_is_phase_zero():
    s = Schottky.from_disk_pairs(PAIRS)
    xyz = _points()
    a = s.apply_xyz(xyz)
    b = s.with_phase(1.0).apply_xyz(xyz)
    assert (np.abs(a - b).max(axis=1) < 1e-8).mean() > 0.99



def test_a_huge_phase_is_phase_zero():
    s = Schottky.from_disk_pairs(PAIRS)
    xyz = _points()
    assert np.array_equal(s.with_phase(1e17).apply_xyz(xyz), s.with_phase(0).apply_xyz(xyz))

def test_local_scale_matches_finite_differences():
    s = Schottky.from_disk_pairs(PAIRS)
    xyz = _points(300)
    ok = _margin(s, xyz) > 1e-3
    zw = coords.cp1_from_xyz(xyz[ok])
    exact = s.local_scale(zw)
    from spherewarp.maps.base import SphereMap

    numeric = SphereMap.local_scale(s, zw)
    assert np.allclose(exact, numeric, rtol=1e-4)


def test_generator_between_maps_outside_onto_inside():
    a, b = Cap(-163, 5, 12), Cap(17, -5, 25)
    for tw in (0.0, 40.0):
        m = generator_between(a, b, tw)
        n, r = cap_image(m, a)
        assert np.allclose(n, b.normal) and abs(r - 25) < 1e-9
    assert generator_between(a, b).classify() == "hyperbolic"
    assert generator_between(a, b, 40).classify() == "loxodromic"


def test_json_round_trip():
    s = Schottky.from_disk_pairs(PAIRS, depth=50, phase=0.25)
    t = map_from_json(s.to_json())
    assert t == s and t.depth == 50
    xyz = _points(100)
    assert np.allclose(t.apply_xyz(xyz), s.apply_xyz(xyz))


def test_errors_name_the_pair_and_the_overlap():
    with pytest.raises(InvalidValueError, match=r"generator 2 .* overlap by 3 degrees"):
        Schottky.from_disk_pairs([((0, 0, 10), (180, 0, 10)), ((12, 0, 5), (90, 0, 10))])
    with pytest.raises(InvalidValueError, match="overlap by"):
        Schottky.from_disk_pairs([((0, 0, 10), (15, 0, 10))])
    with pytest.raises(InvalidValueError, match="at most a hemisphere"):
        Schottky.from_disk_pairs([((0, 0, 100), (180, 0, 10))])
    with pytest.raises(InvalidValueError, match="hyperbolic"):
        Schottky([((0, 0, 10), Mobius.rotation((0, 0), 30))])
    with pytest.raises(InvalidValueError, match="more than a hemisphere"):
        Schottky([((0, 0, 10), Mobius.zoom((0, 0), 0.5))])  # pushes the outside outwards


def test_render_samples_the_reduced_point():
    """On an image whose pixels hold their own direction, each output pixel holds the
    direction the independent reduction gives (away from the disk boundaries)."""
    from spherewarp.render import warp

    w, h = 256, 128
    ys, xs = np.mgrid[0:h, 0:w] + 0.5
    lonlat = coords.lonlat_from_pixel(np.stack([xs, ys], axis=-1), w, h)
    xyz = coords.xyz_from_lonlat(lonlat)
    s = Schottky.from_disk_pairs(PAIRS)
    out = warp(xyz.astype(np.float64), s, antialias="none")
    ok = _margin(s, xyz) > np.radians(2 * 360 / w)
    want = _reference(s, xyz[ok])
    err = np.linalg.norm(out[ok] - want, axis=-1)
    assert ok.mean() > 0.8
    assert err.max() < 2e-3  # bilinear interpolation of a smooth field
    # the fundamental region is the input itself
    caps = [c for c, _ in s.generators] + s.target_disks()
    free = ok & ~np.any([c.contains(xyz) for c in caps], axis=0)
    assert np.abs(out[free] - xyz[free]).max() < 2e-3


def test_rendered_image_is_invariant_under_each_generator():
    """warp(out, X) == out within interpolation error, away from the disk boundaries."""
    from spherewarp.render import warp

    w, h = 256, 128
    ys, xs = np.mgrid[0:h, 0:w] + 0.5
    xyz = coords.xyz_from_lonlat(coords.lonlat_from_pixel(np.stack([xs, ys], axis=-1), w, h))
    s = Schottky.from_disk_pairs([((0, 0, 40), (180, 0, 40)), ((90, 0, 40), (-90, 0, 40))])
    out = warp(xyz, s, antialias="none")
    for _, m in s.generators:
        moved = warp(out, m, antialias="none")
        # where out is a copy shrunk by at most 4, interpolating it is accurate to ~1e-3
        mild = (s.local_scale(coords.cp1_from_xyz(xyz)) < 4) & (
            s.local_scale(coords.cp1_from_xyz(m.apply_xyz(xyz))) < 4
        )
        far = mild & (_margin(s, xyz) > np.radians(3 * 360 / w))
        far &= _margin(s, m.apply_xyz(xyz)) > np.radians(3 * 360 / w)
        err = np.linalg.norm(moved - out, axis=-1)[far]
        assert far.mean() > 0.05
        assert np.quantile(err, 0.99) < 0.01


# -- the exact disks of a mask (the paper's workflow) ---------------------------------------------
def _mask():
    """A 180 x 360 mask: a red rectangle (lon -20..20, lat -8..8) and a green square."""
    m = np.zeros((180, 360, 3), np.uint8)
    m[82:98, 160:200] = (255, 0, 0)
    m[60:75, 60:75] = (0, 255, 0)  # lon -120..-105, lat 15..30
    return m


def _mask_map(regions=True):
    from spherewarp.maps.schottky import MaskRegions, cap_from_mask

    mask = _mask()
    red, green = cap_from_mask(mask, (1, 0, 0)), cap_from_mask(mask, (0, 1, 0))
    s = Schottky(
        [(red, generator_between(red, Cap(170, 0, 15))), (green, Mobius.zoom((-112.5, 22.5), 50))]
    )
    if regions:
        s = s.with_mask_regions(MaskRegions(mask, [(1, 0, 0), (0, 1, 0)], path="mask.png"))
    return s, mask


def _label(mask, v):
    """Independent mask lookup: the colour of the pixel a unit vector falls in."""
    lon = np.degrees(np.arctan2(v[1], v[0]))
    lat = np.degrees(np.arcsin(np.clip(v[2], -1, 1)))
    x = int(np.floor((lon + 180) / 360 * mask.shape[1])) % mask.shape[1]
    y = min(max(int(np.floor((90 - lat) / 180 * mask.shape[0])), 0), mask.shape[0] - 1)
    r, g, _ = mask[y, x]
    return 0 if r > 128 else 1 if g > 128 else -1


def _paper_reduction(s, mask, xyz, depth=60):
    """The paper's routine read literally, one point at a time: while q is not in the black
    region, if q is in D_X (X^-1(q) is not in D_x) replace it by X^-1(q), if q is in D_x
    replace it by X(q)."""
    mats = [np.asarray(m.matrix) for _, m in s.generators]
    out = []
    for v in xyz:
        zw = coords.cp1_from_xyz(v)
        z, w = complex(zw[0]), complex(zw[1])
        for _ in range(depth):
            p = coords.xyz_from_cp1(np.array([z, w]))
            moved = False
            for i, ((a, b), (c, d)) in enumerate(mats):
                if _label(mask, p) == i:
                    z, w = a * z + b * w, c * z + d * w
                    moved = True
                    break
                zi, wi = d * z - b * w, -c * z + a * w  # X^-1 (det 1)
                if _label(mask, coords.xyz_from_cp1(np.array([zi, wi]))) != i:
                    z, w = zi, wi
                    moved = True
                    break
            n = np.sqrt(abs(z) ** 2 + abs(w) ** 2)
            z, w = z / n, w / n
            if not moved:
                break
        out.append(coords.xyz_from_cp1(np.array([z, w])))
    return np.array(out)


def _mask_margin(mask, xyz):
    """Points whose 8 neighbours at 0.3 degrees have their label (clear of region edges)."""
    lab = np.array([_label(mask, v) for v in xyz])
    ok = np.ones(len(xyz), bool)
    for dl, dp in [(0.3, 0), (-0.3, 0), (0, 0.3), (0, -0.3)]:
        ll = np.degrees(coords.lonlat_from_xyz(xyz)) + [dl, dp]
        moved = coords.xyz_from_lonlat(np.radians(ll))
        ok &= np.array([_label(mask, v) for v in moved]) == lab
    return ok


def test_mask_regions_match_the_papers_routine():
    s, mask = _mask_map()
    xyz = _points(1500, seed=4)
    got = s.apply_xyz(xyz)
    want = _paper_reduction(s, mask, xyz)
    ok = _mask_margin(mask, xyz) & _mask_margin(mask, got)
    assert ok.mean() > 0.9
    assert np.abs(got - want)[ok].max() < 1e-8


def test_mask_black_is_the_fundamental_region():
    """A point of the round disk about the red rectangle but outside the rectangle (black in
    the mask) is fixed with the exact disks, and moved with the round ones; each compiles to
    its own stage."""
    s, mask = _mask_map()
    r, _ = _mask_map(regions=False)
    q = coords.xyz_from_lonlat(np.radians([[0.0, 15.0], [18.0, -12.0]]))  # black, in the cap
    assert all(_label(mask, v) == -1 for v in q)
    assert np.allclose(s.apply_xyz(q), q)
    assert not np.allclose(r.apply_xyz(q), q)
    assert fast_spec(s).codes[-1] == 7 and fast_spec(r).codes[-1] == 6  # schottky_mask


def fast_spec(m):
    from spherewarp.render import fast

    return fast.kernel_spec(m)


def test_mask_regions_are_invariant_under_each_generator():
    s, mask = _mask_map()
    xyz = _points(1500, seed=5)
    for _, m in s.generators:
        a = s.apply_xyz(xyz)
        pb = s.pull(coords.cp1_from_xyz(m.apply_xyz(xyz)))
        b = coords.xyz_from_cp1(pb.points)
        ok = _mask_margin(mask, a) & _mask_margin(mask, b) & pb.valid
        ok &= _mask_margin(mask, xyz) & _mask_margin(mask, m.apply_xyz(xyz))
        assert ok.mean() > 0.8
        assert np.abs(a - b)[ok].max() < 1e-8


def test_mask_regions_round_trip_through_json(tmp_path, monkeypatch):
    from spherewarp.io import write_image

    monkeypatch.chdir(tmp_path)
    s, mask = _mask_map()
    write_image("mask.png", mask)
    t = map_from_json(s.to_json())
    assert t == s and t.regions is not None
    assert '"mask"' in s.to_json()
    xyz = _points(200)
    assert np.allclose(t.apply_xyz(xyz), s.apply_xyz(xyz))


def test_mask_region_errors():
    from spherewarp.maps.schottky import MaskRegions, cap_from_mask

    # a thin vertical bar: its round disk is mostly black, which X takes into the exact D_X
    # (X^-1 of the bar is a small patch about X's fixed point, off the bar): D_X holds the bar
    bar = np.zeros((180, 360, 3), np.uint8)
    bar[70:110, 179:181] = (255, 0, 0)
    cap = cap_from_mask(bar, (1, 0, 0))
    s = Schottky([(cap, generator_between(cap, Cap(42, 0, 15)))])
    with pytest.raises(InvalidValueError, match=r"D_x of generator 1 .* and D_X of generator 1"):
        s.with_mask_regions(MaskRegions(bar, [(1, 0, 0)]))
    mask = _mask()
    red = cap_from_mask(mask, (1, 0, 0))
    near = Schottky([(red, generator_between(red, Cap(42, 0, 15)))])
    with pytest.raises(InvalidValueError, match="one mask colour per generator"):
        near.with_mask_regions(MaskRegions(mask, [(1, 0, 0), (0, 1, 0)]))
    with pytest.raises(InvalidValueError, match="within the tolerance"):
        MaskRegions(mask, [(1, 0, 0), (0.9, 0, 0)])
    with pytest.raises(InvalidValueError, match="no pixel of the colour"):
        MaskRegions(mask, [(0, 0, 1)])


def test_a_generator_from_the_inside_disk_keeps_the_exact_D_X_in_its_target():
    """Built from the round disk inside the region, X takes the region's outside into the
    target disk: every point of the exact D_X lies in the target (the README's interior
    picture relies on it); built from the disk round the region, D_X spills far outside."""
    from spherewarp.maps.schottky import MaskRegions, cap_from_mask

    mask = _mask()
    inner, outer = cap_from_mask(mask, (1, 0, 0), inside=True), cap_from_mask(mask, (1, 0, 0))
    assert 7 < inner.radius < 9 < 20 < outer.radius < 22  # the rectangle: 40 x 16 degrees
    xyz = _points(20000, seed=6)
    assert all(_label(mask, v) == 0 for v in xyz[inner.contains(xyz)])  # the disk is red
    target = Cap(170, 0, 15)
    for cap, spills in ((inner, False), (outer, True)):
        s = Schottky([(cap, generator_between(cap, target))])
        s = s.with_mask_regions(MaskRegions(mask, [(1, 0, 0)]))
        m = s.generators[0][1]
        in_d_big = ~s.regions.contains(0, m.inverse().apply_xyz(xyz))
        assert in_d_big.any()
        assert bool((in_d_big & ~target.contains(xyz)).any()) is spills
