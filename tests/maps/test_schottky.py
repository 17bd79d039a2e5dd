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
    from spherewarp.droste import droste_map, hole_from_radius

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
