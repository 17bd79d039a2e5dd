"""Branched maps: powers and roots, the exp variant and its log (spherewarp.maps.branched)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import tolerances
from spherewarp import coords
from spherewarp.errors import InvalidTypeError, InvalidValueError
from spherewarp.maps import (
    Composite,
    ExpMap,
    LogMap,
    Mobius,
    Power,
    SphereMap,
    chart_for_branch_points,
    map_from_dict,
    map_from_json,
)
from spherewarp.maps.branched import ESSENTIAL_RADIUS, SCALE_CAP
from spherewarp.render import warp

INF = complex("inf")


def chordal(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """|det| of unit pairs: the chordal distance of points of the sphere (up to a factor)."""
    p, q = coords.normalize_cp1(p), coords.normalize_cp1(q)
    return np.abs(p[..., 0] * q[..., 1] - p[..., 1] * q[..., 0])


@pytest.fixture(scope="module")
def points() -> np.ndarray:
    """Random points of the sphere as unit pairs, plus the poles and the back/front points."""
    gen = np.random.default_rng(5)
    xyz = gen.normal(size=(3000, 3))
    xyz /= np.linalg.norm(xyz, axis=1, keepdims=True)
    extra = np.array([[0, 0, 1], [0, 0, -1], [-1, 0, 0], [1, 0, 0], [0, 1, 0]], float)
    return coords.cp1_from_xyz(np.concatenate([xyz, extra]))


def zenith_rotation(angle: float) -> Mobius:
    return Mobius.rotation((0.0, 90.0), angle)


def finite_difference_scale(m: SphereMap, zw: np.ndarray) -> np.ndarray:
    return SphereMap.local_scale(m, zw)


# ------------------------------------------------------------------ Power: values


def test_power_values_match_the_plane_formula(points):
    z = coords.plane_from_cp1(points[:-5])
    for n in (2, 3, 5, -1, -2):
        expected = coords.cp1_from_plane(z.astype(complex) ** n)
        assert chordal(Power(n).pull_cp1(points[:-5]), expected).max() < tolerances.POINTS


def test_power_is_exact_at_zero_infinity_and_one():
    for n in (2, 3, 7, -2, 0.5, 1 / 3):
        out = Power(n)(np.array([0.0, INF, 1.0]))
        expected = [0.0, INF, 1.0] if n > 0 else [INF, 0.0, 1.0]
        assert out.tolist() == expected


def test_power_pairs_are_unit_norm_and_finite(points):
    for n in (2, 3, 50, -3, 0.5, 2.5, 1000):
        out = Power(n).pull_cp1(points)
        assert np.all(np.isfinite(out))
        assert np.allclose(np.linalg.norm(out, axis=-1), 1.0, atol=1e-14)


@pytest.mark.parametrize("theta", [30.0, -75.0, 123.0])
def test_power_commutes_with_zenith_rotations(points, theta):
    lhs = Power(2) @ zenith_rotation(theta)
    rhs = zenith_rotation(2 * theta) @ Power(2)
    assert chordal(lhs.pull_cp1(points), rhs.pull_cp1(points)).max() < tolerances.POINTS


def test_power_composition_is_a_power(points):
    six = Power(2) @ Power(3)
    assert isinstance(six, Power) and six == Power(6)
    chained = Composite((Power(2), Power(3)))
    assert chordal(chained.pull_cp1(points), Power(6).pull_cp1(points)).max() < tolerances.POINTS
    # Different charts or non-integer exponents stay a composite.
    assert isinstance(Power(2) @ Power(2, branch_points=((0, 0), (180, 0))), Composite)
    assert isinstance(Power(0.5) @ Power(2), Composite)


def test_rendered_identities(random_image):
    img = random_image(32)
    rot = warp(img, Power(2) @ zenith_rotation(45.0))
    rot2 = warp(img, zenith_rotation(90.0) @ Power(2))
    assert np.abs(rot.astype(int) - rot2.astype(int)).max() <= tolerances.rounding(img.dtype)
    six = warp(img, Composite((Power(2), Power(3))))
    assert np.abs(six.astype(int) - warp(img, Power(6)).astype(int)).max() <= 1


def test_z_squared_shows_two_copies(interior):
    """The paper's figure: z**2 is periodic with half a turn in longitude."""
    out = warp(interior, Power(2))
    w = out.shape[1]
    left, right = out[:, : w // 2].astype(int), out[:, w // 2 :].astype(int)
    assert np.abs(left - right).max() <= 1
    # and it is not trivially so: the input is not periodic
    half = interior.shape[1] // 2
    assert np.abs(interior[:, :half].astype(int) - interior[:, half:]).mean() > 10


def test_power_n_copies_around_other_branch_points(points):
    p, q = (30.0, 10.0), (100.0, -40.0)
    s = Power(3, branch_points=(p, q))
    fixed = s.apply_lonlat(np.array([p, q]))
    assert np.allclose(fixed, [p, q], atol=1e-9)
    # The map is 3-to-1 around the branch points: invariant under the chart's third turn.
    chart = chart_for_branch_points(p, q)
    turn = chart.inverse() @ zenith_rotation(120.0) @ chart
    assert chordal(s.pull_cp1(turn.pull_cp1(points)), s.pull_cp1(points)).max() < 1e-10


def test_chart_for_branch_points():
    assert chart_for_branch_points((0, 90), (0, -90)).is_identity()
    m = chart_for_branch_points((40, 20), (-140, -20))  # antipodal: a rotation
    assert m.is_rotation()
    m = chart_for_branch_points((40, 20), (60, -30))
    out = m(coords.plane_from_lonlat(np.radians([[40, 20], [60, -30]])))
    assert abs(out[0]) < 1e-12 and abs(out[1]) > 1e12
    with pytest.raises(InvalidValueError, match="different"):
        chart_for_branch_points((10, 10), (10, 10))


# ------------------------------------------------------------------ Power: roots, inverses


def test_principal_root_matches_numpy():
    z = np.array([4j, -4j, 2 + 1j, -3 + 0.5j, -3 - 0.5j, 0.25])
    assert np.allclose(Power(0.5, cut=0)(z), np.sqrt(z), rtol=1e-14, atol=0)
    assert np.allclose(Power(0.5, cut=0, branch=1)(z), -np.sqrt(z), rtol=1e-14, atol=0)
    assert np.allclose(Power(1 / 3, cut=0)(z), z ** (1 / 3), rtol=1e-13, atol=0)


def test_default_root_is_cut_at_the_back():
    """Default cut at longitude 180: continuous across the front, not across the back."""
    r = Power(0.5)
    front = r.apply_lonlat(np.array([[-0.1, 0.0], [0.1, 0.0]]))
    back = r.apply_lonlat(np.array([[179.9, 0.0], [-179.9, 0.0]]))
    assert abs(front[0, 0] - front[1, 0]) < 0.1
    assert abs(abs(back[0, 0] - back[1, 0]) - 180.0) < 0.2


@pytest.mark.parametrize("t", [2, 3, -2, 0.5, 1 / 3, -0.5, 2.5, -2.5, 0.4, -0.4, 1.5])
@pytest.mark.parametrize("branch", [0, 1, -2])
def test_inverse_undoes_the_power(points, t, branch):
    p = Power(t, branch=branch, cut=37.0)
    inv = p.inverse(branch=branch) if p.is_integer else p.inverse()
    if abs(t) >= 1:  # onto: p o p^-1 = id
        err = chordal(p.pull_cp1(inv.pull_cp1(points)), points)
    else:  # into: p^-1 o p = id
        err = chordal(inv.pull_cp1(p.pull_cp1(points)), points)
    assert err.max() < 1e-12


def test_root_inverse_is_the_integer_power():
    assert Power(0.5).inverse() == Power(2)
    assert Power(1 / 3).inverse() == Power(3)
    assert Power(-0.25).inverse() == Power(-4)


# ------------------------------------------------------------------ local scale


@pytest.mark.parametrize(
    "m",
    [
        Power(2),
        Power(3),
        Power(-2),
        Power(0.5),
        Power(2.5, branch=1),
        Power(2, branch_points=((30, 10), (100, -40))),
        ExpMap(4),
        ExpMap(1.5, branch_points=((0, 0), (180, 0))),
        LogMap(4),
        LogMap(2, branch=1),
    ],
    ids=repr,
)
def test_local_scale_matches_finite_differences(points, m):
    exact = m.local_scale(points)
    fd = finite_difference_scale(m, points)
    # Stay away from the branch points and the singularity, where the scale is 0 or infinite
    # and finite differences cannot follow it.
    ok = (exact > 1e-3) & (exact < 1e3) & (fd > 1e-3) & (fd < 1e3)
    if isinstance(m, (LogMap, Power)) and not getattr(m, "is_integer", False):
        # ... and from the cut along the meridian at longitude 180 (arg z = 0)
        ok &= np.abs(np.angle(points[:, 0] * np.conj(points[:, 1]))) > 1e-3
    assert ok.sum() > 1000
    assert np.allclose(exact[ok], fd[ok], rtol=tolerances.FINITE_DIFFERENCE_REL * 100)
    assert np.all(np.isfinite(exact)) and np.all(exact >= 0)


def test_local_scale_values():
    zenith, nadir = np.array([0, 1], complex), np.array([1, 0], complex)
    equator = coords.cp1_from_plane(np.exp(1j * np.linspace(0, 6, 7)))
    assert np.allclose(Power(3).local_scale(equator), 3.0)
    assert Power(3).local_scale(zenith) == 0 and Power(3).local_scale(nadir) == 0
    assert Power(0.5).local_scale(zenith) == SCALE_CAP
    assert np.isclose(ExpMap(4).local_scale(coords.cp1_from_plane(-1.0)), 2.0)
    assert ExpMap(4).local_scale(np.array([1, 1], complex) / np.sqrt(2)) == SCALE_CAP


# ------------------------------------------------------------------ the exp variant


def test_exp_matches_the_formula(points):
    z = coords.plane_from_cp1(points)
    keep = np.abs(z - 1) > 1e-3
    with np.errstate(all="ignore"):
        expected = -np.exp(-4 * (1 + z[keep]) / (1 - z[keep]))
    expected = np.where(np.isinf(z[keep]), -np.exp(4.0), expected)  # the nadir: u = -1
    out = ExpMap(4).pull_cp1(points[keep])
    assert chordal(out, coords.cp1_from_plane(expected)).max() < 1e-12


def test_exp_keeps_hemispheres_and_repeats(points):
    e = ExpMap(4)
    xyz_in = coords.xyz_from_cp1(points)
    xyz_out = coords.xyz_from_cp1(e.pull_cp1(points))
    clear = np.abs(xyz_in[:, 2]) > 1e-9
    assert np.all(np.sign(xyz_out[clear, 2]) == np.sign(xyz_in[clear, 2]))
    # u -> u + 2 pi i / lam gives the same image: another copy of the input.
    m = Mobius([[1, 1], [-1, 1]])  # u = (1 + z)/(1 - z)
    shift = m.inverse() @ Mobius([[1, 2j * np.pi / 4], [0, 1]]) @ m
    assert chordal(e.pull_cp1(shift.pull_cp1(points)), e.pull_cp1(points)).max() < 1e-9


def test_exp_has_many_copies_along_the_equator():
    lon = np.linspace(-150.0, 150.0, 20001)
    out = ExpMap(4).apply_lonlat(np.stack([lon, np.zeros_like(lon)], -1))
    turns = np.abs(np.diff(np.unwrap(np.radians(out[:, 0])))).sum() / (2 * np.pi)
    assert turns > 4  # the copies repeat horizontally
    assert np.allclose(out[:, 1], 0.0, atol=1e-9)  # the equator stays the equator


def test_exp_is_clean_at_the_essential_singularity():
    """No NaN and unit pairs at and near z = 1 (the back point), from every direction."""
    angles = np.linspace(0, 2 * np.pi, 16, endpoint=False)
    dists = np.array([1.0, 1e-3, 1e-6, ESSENTIAL_RADIUS * 2, ESSENTIAL_RADIUS / 2, 1e-200, 0.0])
    z = 1 + dists[:, None] * np.exp(1j * angles)[None, :]
    zw = coords.cp1_from_plane(z)
    for m in (ExpMap(4), ExpMap(0.1), ExpMap(100)):
        out = m.pull_cp1(zw)
        assert np.all(np.isfinite(out))
        assert np.allclose(np.linalg.norm(out, axis=-1), 1.0)
        assert np.all(np.isfinite(m.local_scale(zw)))
    # the limits inside the tiny disc: 0 from above the equator, infinity from below
    e = ExpMap(4)
    assert e(1.0) == 0
    assert e(1 - 1e-12) == 0  # |z| < 1: above the equator
    assert e(1 + 1e-12) == INF  # below it


def test_renders_are_finite(smooth_image):
    img = smooth_image(32)
    for m, shape in [(ExpMap(4), (32, 64)), (ExpMap(4), (33, 66)), (Power(0.5), (33, 64))]:
        out = warp(img, m, supersample=3, output_shape=shape)
        assert out.dtype == np.float32 and np.all(np.isfinite(out))
        assert out.min() >= 0 and out.max() <= 1.0 + 1e-6


@settings(max_examples=200, deadline=None)
@given(
    st.complex_numbers(allow_nan=False, allow_infinity=False),
    st.complex_numbers(allow_nan=False, allow_infinity=False),
)
def test_never_nan(z, w):
    """Any pair, however extreme, gives a unit pair and a finite scale."""
    zw = np.array([z, w], dtype=np.complex128)
    scale = np.abs(zw).max()
    if not (np.isfinite(scale) and scale > 0):
        zw, scale = np.array([1.0, 0.0], dtype=np.complex128), 1.0
    with np.errstate(over="ignore"):  # a denormal scale overflows: normalize_cp1 copes
        zw = coords.normalize_cp1(zw / scale)
    for m in (Power(2), Power(-3), Power(0.5), ExpMap(4), LogMap(4)):
        out = m.pull_cp1(zw)
        assert np.all(np.isfinite(out)) and np.isclose(np.linalg.norm(out), 1.0)
        assert np.isfinite(m.local_scale(zw))


def test_log_inverts_exp(points):
    e = ExpMap(3)
    for k in (0, 1, -2):
        lg = e.inverse(branch=k)
        assert isinstance(lg, LogMap) and lg.branch == k
        inner = points[:-5]  # not the poles: they go to the essential singularity
        assert chordal(e.pull_cp1(lg.pull_cp1(inner)), inner).max() < 1e-11
    assert LogMap(3).inverse() == e
    assert LogMap(3)(np.array([0.0, INF])).tolist() == [1.0, 1.0]


# ------------------------------------------------------------------ plain data, errors


@pytest.mark.parametrize(
    "m",
    [
        Power(2),
        Power(-3),
        Power(0.5, branch=2, cut=10.0),
        Power(3, branch_points=((30, 10), (100, -40))),
        ExpMap(4),
        ExpMap(2.5, branch_points=((0, 0), (180, 0))),
        LogMap(4, branch=-1),
    ],
    ids=repr,
)
def test_round_trip_through_json(m, points):
    back = map_from_json(json.dumps(m.to_dict()))
    assert back == m
    assert chordal(back.pull_cp1(points), m.pull_cp1(points)).max() < 1e-12
    assert map_from_dict(m.to_dict()) == m


def test_repr():
    assert repr(Power(2)) == "Power(exponent=2)"
    assert repr(Power(0.5)) == "Power(exponent=0.5, branch=0, cut=180)"
    assert repr(ExpMap(4)) == "ExpMap(lam=4)"
    assert "chart=Mobius" in repr(Power(2, branch_points=((0, 0), (180, 0))))


@pytest.mark.parametrize(
    "make, error, match",
    [
        (lambda: Power(0), InvalidValueError, "non-zero"),
        (lambda: Power(float("nan")), InvalidValueError, "finite"),
        (lambda: Power("2"), InvalidTypeError, "real number"),
        (lambda: Power(True), InvalidTypeError, "real number"),
        (lambda: Power(0.5, branch=0.5), InvalidTypeError, "integer"),
        (lambda: ExpMap(0), InvalidValueError, "lam > 0"),
        (lambda: ExpMap(-1), InvalidValueError, "lam > 0"),
        (lambda: ExpMap(float("inf")), InvalidValueError, "finite"),
        (
            lambda: Power(2, branch_points=((0, 0), (1, 1)), chart=Mobius.identity()),
            InvalidValueError,
            "not both",
        ),
        (lambda: Power(2, branch_points=((0, 0),)), InvalidValueError, "two points"),
        (lambda: Power(2, branch_points=((0, 0), (0, 0))), InvalidValueError, "different"),
    ],
)
def test_bad_parameters(make, error, match):
    with pytest.raises(error, match=match):
        make()
