"""The Droste maps: lattice symmetry, phase, annulus, derivative, sheets, plain data, errors."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import tolerances
from spherewarp import coords
from spherewarp.errors import InvalidTypeError, InvalidValueError
from spherewarp.maps import Droste, Mobius, SphereMap, TwistedDroste, map_from_dict
from spherewarp.maps.droste import SCALE_CAP, droste_chart

CENTER = (-40.0, 15.0)
#: a wobbly star-shaped hole: log r(theta) = log 0.2 + 0.3 cos(3 theta) + 0.1 sin(theta)
THETA = -np.pi + 2 * np.pi * np.arange(512) / 512
RHO = np.log(0.2) + 0.3 * np.cos(3 * THETA) + 0.1 * np.sin(THETA)

VARIANTS = [
    pytest.param(lambda **kw: Droste(CENTER, RHO, 5.0, **kw), id="straight"),
    pytest.param(lambda **kw: TwistedDroste(CENTER, RHO, 5.0, **kw), id="twisted-1-1"),
    pytest.param(
        lambda **kw: TwistedDroste(CENTER, RHO, 3.0, strands=2, periodicity=1, **kw),
        id="twisted-2-1",
    ),
    pytest.param(
        lambda **kw: TwistedDroste(CENTER, RHO, 4.0, strands=-1, periodicity=2, **kw),
        id="twisted--1-2",
    ),
    pytest.param(
        lambda **kw: Droste(CENTER, RHO, 6.0, far=(100.0, -20.0), **kw), id="straight-far"
    ),
    pytest.param(
        lambda **kw: TwistedDroste(CENTER, RHO, 6.0, far=(100.0, -20.0), **kw), id="twisted-far"
    ),
]


def random_points(n: int = 4000, seed: int = 7) -> np.ndarray:
    xyz = np.random.default_rng(seed).normal(size=(n, 3))
    xyz /= np.linalg.norm(xyz, axis=1, keepdims=True)
    return coords.cp1_from_xyz(xyz)


def chordal(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """|det| of unit pairs: the chordal distance / 2 between points."""
    return np.abs(a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0])


# -- the chart --------------------------------------------------------------------------------


def test_chart_puts_center_at_zero_far_at_infinity_and_up_at_90_degrees() -> None:
    for far in (None, (100.0, -20.0)):
        ch = droste_chart(CENTER, far)
        c = ch.pull_cp1(coords.cp1_from_lonlat(np.radians(CENTER)))
        assert abs(c[0]) < tolerances.POINTS
        a_ll = (CENTER[0] + 180.0, -CENTER[1]) if far is None else far
        a = ch.pull_cp1(coords.cp1_from_lonlat(np.radians(a_ll)))
        assert abs(a[1]) < tolerances.POINTS
        up = ch.pull_cp1(coords.cp1_from_lonlat(np.radians((CENTER[0], CENTER[1] + 1e-5))))
        assert math.degrees(np.angle(up[0] / up[1])) == pytest.approx(90.0, abs=1e-4)
    assert droste_chart(CENTER).is_rotation()
    with pytest.raises(InvalidValueError, match="differ"):
        droste_chart(CENTER, CENTER)


# -- the annulus and the tiles -------------------------------------------------------------------


def test_annulus_is_fixed_and_copies_are_scaled_by_powers_of_lambda() -> None:
    d = Droste(CENTER, RHO, 5.0)
    inv = d.chart.inverse()
    theta = np.linspace(-np.pi, np.pi, 50, endpoint=False)
    rho = d.log_radius(theta)
    for frac in (0.01, 0.5, 0.99):
        for k in (-3, -1, 0, 1, 2):
            zeta = np.exp(rho + (frac + k) * np.log(5.0) + 1j * theta)
            zw = inv.pull_cp1(coords.cp1_from_plane(zeta))
            np.testing.assert_array_equal(d.tile_index(zw), k)
            expected = inv.pull_cp1(coords.cp1_from_plane(zeta / 5.0**k))
            assert chordal(d.pull_cp1(zw), expected).max() < tolerances.POINTS


@pytest.mark.parametrize("make", VARIANTS)
def test_invariant_under_its_symmetry(make) -> None:
    d = make()
    zw = random_points()
    a = d.pull_cp1(zw)
    b = d.pull_cp1(d.symmetry().pull_cp1(zw))
    assert np.median(chordal(a, b)) < tolerances.POINTS
    # a point a hair from a tile boundary may fall on the other side: allow a few
    assert np.mean(chordal(a, b) > 1e-8) < 0.002


@pytest.mark.parametrize("make", VARIANTS)
def test_phase_one_is_phase_zero_and_phase_is_the_symmetry_path(make) -> None:
    d = make()
    zw = random_points()
    a = d.pull_cp1(zw)
    assert np.mean(chordal(a, d.with_phase(1.0).pull_cp1(zw)) > 1e-8) < 0.002
    assert np.mean(chordal(a, d.with_phase(-2.0).pull_cp1(zw)) > 1e-8) < 0.002
    # D_t = D_0 o symmetry(-t): the image at phase t is the image pushed by symmetry(t)
    t = 0.37
    shifted = d.pull_cp1(d.symmetry(-t).pull_cp1(zw))
    assert np.mean(chordal(shifted, d.with_phase(t).pull_cp1(zw)) > 1e-8) < 0.002
    assert np.mean(chordal(a, d.with_phase(t).pull_cp1(zw)) > 1e-3) > 0.5


def test_twist_factor_and_spiral_similarity() -> None:
    ell = math.log(5.0)
    straight = Droste(CENTER, RHO, 5.0)
    assert straight.beta == 1
    assert straight.symmetry_factor == pytest.approx(5.0)
    assert straight.symmetry() == Mobius.zoom_between(straight.far, straight.center, 5.0)
    d = TwistedDroste(CENTER, RHO, 5.0)
    assert d.beta == pytest.approx(1 - 1j * ell / (2 * math.pi))
    assert d.period == pytest.approx(ell + 2j * math.pi)
    # the spiral similarity exp(2 pi i ell / P): zoom exp(4 pi^2 ell / |P|^2)
    q = d.symmetry_factor
    assert abs(q) == pytest.approx(math.exp(4 * math.pi**2 * ell / (ell**2 + 4 * math.pi**2)))
    assert d.symmetry().classify() == "loxodromic"
    # strands 0, periodicity 1 is the straight map
    same = TwistedDroste(CENTER, RHO, 5.0, strands=0, periodicity=1)
    zw = random_points(500)
    assert chordal(same.pull_cp1(zw), straight.pull_cp1(zw)).max() < tolerances.POINTS


def test_twisted_output_is_continuous_round_the_centre() -> None:
    """Going once round the centre crosses the tiles but never jumps inside one."""
    for d in (TwistedDroste(CENTER, RHO, 5.0), TwistedDroste(CENTER, RHO, 3.0, strands=2)):
        phi = np.linspace(-np.pi, np.pi, 20001)  # crosses theta = +-pi
        zeta = 0.7 * np.exp(1j * phi)
        zw = d.chart.inverse().pull_cp1(coords.cp1_from_plane(zeta))
        src = d.pull_cp1(zw)
        k = d.tile_index(zw)
        jump = chordal(src[1:], src[:-1])
        same = k[1:] == k[:-1]
        assert jump[same].max() < 1e-3
        # going round once climbs `strands` copies (the spiral arms) and closes up
        assert k[-2] - k[1] == d.strands
        assert chordal(src[-1:], src[:1]).max() < 1e-9


# -- derivative, sheets, NaN ----------------------------------------------------------------


@pytest.mark.parametrize("make", VARIANTS)
def test_local_scale_is_the_derivative(make) -> None:
    d = make(phase=0.3)
    zw = random_points(3000)
    exact = d.local_scale(zw)
    fd = SphereMap.local_scale(d, zw)
    rel = np.abs(exact / fd - 1)
    assert np.median(rel) < tolerances.FINITE_DIFFERENCE_REL
    assert np.quantile(rel, 0.99) < 1e-4  # the rest: stencils across a tile boundary


def test_no_nan_at_the_fixed_points_and_the_poles() -> None:
    for d in (Droste(CENTER, RHO, 5.0), TwistedDroste(CENTER, RHO, 5.0, far=(0, -90))):
        pts = np.stack([d.center, d.far, coords.cp1_from_plane(0), coords.cp1_from_plane(np.inf)])
        pts = np.concatenate([pts, random_points(1000)])
        out = d.pull(pts)
        assert np.all(np.isfinite(out.points))
        assert np.allclose(np.linalg.norm(out.points, axis=-1), 1)
        s = d.local_scale(pts)
        assert np.all(np.isfinite(s)) and np.all(s > 0)
        assert s[0] == SCALE_CAP and s[1] == SCALE_CAP


def test_sheets_cycle_inwards() -> None:
    d = Droste(CENTER, RHO, 5.0, n_images=3)
    assert d.n_sheets == 3
    zw = random_points()
    pb = d.pull(zw)
    k = d.tile_index(zw)
    np.testing.assert_array_equal(pb.sheet, np.mod(-k, 3))
    assert set(np.unique(k)) >= {-1, 0, 1}
    assert Droste(CENTER, RHO, 5.0).pull(zw).sheet is None



@pytest.mark.parametrize("make", VARIANTS)
def test_a_huge_phase_is_reduced_by_its_period(make) -> None:
    """Phase 1e12 (or 1e308) is phase 0, not 1e12 log(lambda) away in the log plane;
    with n images the period is n whole zooms."""
    d = make()
    zw = random_points(300)
    a = d.pull_cp1(zw)
    for t in (1e12, 1e16, 1e308):
        assert np.array_equal(d.with_phase(t).pull_cp1(zw), a), t
    b = d.with_phase(0.25).pull_cp1(zw)
    assert chordal(d.with_phase(1e6 + 0.25).pull_cp1(zw), b).max() < 1e-6
    if not isinstance(d, TwistedDroste):
        two = make(n_images=2)
        sheets = [two.with_phase(t).pull(zw).sheet for t in (1e12 + 1, 1)]
        assert np.array_equal(*sheets)
        assert d.with_phase(1e12).phase == 1e12  # the phase given is kept (recipes, JSON)

# -- plain data and errors ---------------------------------------------------------------------


@pytest.mark.parametrize("make", VARIANTS)
def test_plain_data_round_trip(make) -> None:
    twisted = isinstance(make(), TwistedDroste)
    d = make(phase=0.25) if twisted else make(phase=0.25, n_images=2)
    back = map_from_dict(json.loads(json.dumps(d.to_dict())))
    assert type(back) is type(d)
    assert back == d
    zw = random_points(300)
    assert chordal(back.pull_cp1(zw), d.pull_cp1(zw)).max() < 1e-9
    assert "scale=" in repr(d)


@pytest.mark.parametrize(
    ("kwargs", "error", "needle"),
    [
        ({"scale": 1.0}, InvalidValueError, "scale > 1"),
        ({"scale": 0.5}, InvalidValueError, "scale > 1"),
        ({"scale": float("nan")}, InvalidValueError, "scale > 1"),
        ({"scale": "big"}, InvalidValueError, "scale"),
        ({"rho": [0.1, 0.2]}, InvalidValueError, "rho"),
        ({"rho": np.full(16, np.nan)}, InvalidValueError, "rho"),
        ({"phase": float("inf")}, InvalidValueError, "phase"),
        ({"n_images": 0}, InvalidValueError, "n_images"),
        ({"n_images": 1.5}, InvalidTypeError, "n_images"),
        ({"far": CENTER}, InvalidValueError, "differ"),
        ({"center": (0, 95)}, InvalidValueError, "lat"),
    ],
)
def test_bad_parameters(kwargs, error, needle) -> None:
    args = {"center": CENTER, "rho": RHO, "scale": 5.0, **kwargs}
    with pytest.raises(error, match=needle):
        Droste(args.pop("center"), args.pop("rho"), args.pop("scale"), **args)


@pytest.mark.parametrize(
    ("strands", "periodicity", "needle"),
    [(2, 2, "common factor"), (0, 0, "common factor"), (0, 3, "common factor"), (1, -1, ">= 0")],
)
def test_bad_twist(strands, periodicity, needle) -> None:
    with pytest.raises(InvalidValueError, match=needle):
        TwistedDroste(CENTER, RHO, 5.0, strands=strands, periodicity=periodicity)
    with pytest.raises(InvalidTypeError):
        TwistedDroste(CENTER, RHO, 5.0, strands=True)


def test_twisted_images_must_divide_the_strands() -> None:
    """One spiral strand runs through every copy: K images need K | strands."""
    with pytest.raises(InvalidValueError, match="strands"):
        TwistedDroste(CENTER, RHO, 5.0, strands=1, n_images=2)
    d = TwistedDroste(CENTER, RHO, 5.0, strands=2, n_images=2)
    phi = np.linspace(-np.pi, np.pi, 4001)
    zw = d.chart.inverse().pull_cp1(coords.cp1_from_plane(0.7 * np.exp(1j * phi)))
    sheet = d.pull(zw).sheet
    assert sheet[0] == sheet[-1]  # no seam along theta = +-pi
