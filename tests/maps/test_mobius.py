"""Möbius maps: group laws over a registry of examples, structure, rotations, plain data."""

from __future__ import annotations

import json

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from spherewarp import coords
from spherewarp.errors import InvalidValueError
from spherewarp.maps import Composite, Mobius, SphereMap, as_cp1_point, map_from_dict
from spherewarp.maps.base import map_from_json
from tolerances import FINITE_DIFFERENCE_REL, MATRIX, POINTS

PROPERTY = settings(max_examples=150, deadline=None)
INF = complex("inf")


def _random_sl2(seed: int) -> Mobius:
    r = np.random.default_rng(seed)
    return Mobius(r.normal(size=(2, 2)) + 1j * r.normal(size=(2, 2)))


def _random_su2(seed: int) -> np.ndarray:
    r = np.random.default_rng(seed)
    v = r.normal(size=4)
    a, b = complex(v[0], v[1]), complex(v[2], v[3])
    n = np.hypot(abs(a), abs(b))
    a, b = a / n, b / n
    return np.array([[a, -np.conj(b)], [b, np.conj(a)]])


#: example maps of every kind and constructor: name -> (map, expected class)
EXAMPLES: dict[str, tuple[Mobius, str]] = {
    "identity": (Mobius.identity(), "identity"),
    "rotation_zenith": (Mobius.rotation((0, 90), 30), "elliptic"),
    "rotation_generic": (Mobius.rotation((37, -21), 123), "elliptic"),
    "rotation_half_turn": (Mobius.rotation((10, 20), 180), "elliptic"),
    "rotation_negative": (Mobius.rotation((-100, 5), -250), "elliptic"),
    "rotation_xyz_axis": (Mobius.rotation((1.0, 2.0, -0.5), 77), "elliptic"),
    "rotation_complex_axis": (Mobius.rotation(0.3 - 0.4j, 45), "elliptic"),
    "yaw_pitch_roll": (Mobius.from_yaw_pitch_roll(30, 20, 10), "elliptic"),
    "yaw_pitch_roll_big": (Mobius.from_yaw_pitch_roll(-170, 80, 120), "elliptic"),
    "rotation_to": (Mobius.rotation_to((0, 0), (90, 45)), "elliptic"),
    "rotation_to_antipode": (Mobius.rotation_to((20, 30), (-160, -30)), "elliptic"),
    "zoom_real": (Mobius.zoom((20, 10), 2.5), "hyperbolic"),
    "zoom_shrink": (Mobius.zoom((-60, -40), 0.3), "hyperbolic"),
    "zoom_at_nadir": (Mobius.zoom(INF, 4.0), "hyperbolic"),
    "zoom_complex": (Mobius.zoom((45, 30), 2 * np.exp(0.7j)), "loxodromic"),
    "zoom_negative": (Mobius.zoom((0, 0), -2.0), "loxodromic"),
    "zoom_between": (Mobius.zoom_between((0, 90), (0, 0), 3.0), "hyperbolic"),
    "translation_paper": (Mobius.translation(INF, 0.5), "parabolic"),
    "translation_generic": (Mobius.translation((30, 10), 0.2 + 0.3j), "parabolic"),
    "raw_parabolic": (Mobius([[1, 0.5], [0, 1]]), "parabolic"),
    "raw_hyperbolic": (Mobius([[2, 0], [0, 0.5]]), "hyperbolic"),
    "three_points": (Mobius.from_points([0, 1, INF], [1, 1j, -1]), "elliptic"),
    "three_points_lonlat": (
        Mobius.from_points([(0, 0), (90, 0), (0, 90)], [(10, 5), (80, -20), (30, 60)]),
        None,
    ),
    "random_a": (_random_sl2(1), None),
    "random_b": (_random_sl2(2), None),
    "random_c": (_random_sl2(3), None),
    "random_su2": (Mobius(_random_su2(4)), "elliptic"),
}
NAMES = list(EXAMPLES)
NON_IDENTITY = [n for n in NAMES if n != "identity"]


def ex(name: str) -> Mobius:
    return EXAMPLES[name][0]


def chordal(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """sin(angle/2) between points given as pairs (normalised here)."""
    p, q = coords.normalize_cp1(p), coords.normalize_cp1(q)
    return np.abs(p[..., 0] * q[..., 1] - p[..., 1] * q[..., 0])


def _test_points() -> np.ndarray:
    r = np.random.default_rng(7)
    xyz = r.normal(size=(40, 3))
    special = [(0, 0, 1), (0, 0, -1), (1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0)]
    xyz = np.concatenate([xyz, special])
    xyz /= np.linalg.norm(xyz, axis=-1, keepdims=True)
    return coords.cp1_from_xyz(xyz)


POINTS_CP1 = _test_points()


def assert_same_points(p: np.ndarray, q: np.ndarray, tol: float = POINTS) -> None:
    d = chordal(p, q)
    assert np.all(np.isfinite(p)) and np.all(np.isfinite(q))
    assert d.max() <= tol, f"max chordal distance {d.max():.3g}"


def assert_same_map(f: Mobius, g: Mobius, tol: float = MATRIX) -> None:
    assert isinstance(f, Mobius) and isinstance(g, Mobius)
    assert f.isclose(g, atol=tol), f"{f!r} != {g!r}"


# -- construction and validation -------------------------------------------------------------------
def test_examples_are_sl2_and_classified():
    for name, (m, kind) in EXAMPLES.items():
        a = m.matrix
        assert a.shape == (2, 2) and a.dtype == np.complex128
        assert abs(np.linalg.det(a) - 1) < 1e-12, name
        assert not a.flags.writeable, name
        if kind is not None:
            assert m.classify() == kind, name


@pytest.mark.parametrize(
    "matrix",
    [
        [[1, 2], [2, 4]],  # singular
        [[0, 0], [0, 0]],
        [[1, np.nan], [0, 1]],
        [[1, np.inf], [0, 1]],
        [[1, 0, 0], [0, 1, 0]],
        [1, 2, 3, 4],
        [[1, 2], [3]],
        "not a matrix",
    ],
)
def test_bad_matrices_raise(matrix):
    with pytest.raises(InvalidValueError):
        Mobius(matrix)


@pytest.mark.parametrize(
    ("p", "q"),
    [
        ([0, 0, INF], [0, 1, 2]),  # repeated point
        ([0, 1, 2], [5, 5j, 5]),
        ([(0, 90), 0j, 1], [0, 1, 2]),  # the zenith twice, in two spellings
        ([INF, (0, -90), 1], [0, 1, 2]),  # the nadir twice
        ([(180, 0), (-180, 0), 0], [0, 1, 2]),  # the back twice, across the seam
        ([(10, 90), (50, 90), 1], [0, 1, 2]),  # the zenith at two longitudes
        ([0, 1], [0, 1]),
        ([0, 1, 2, 3], [0, 1, 2, 3]),
        ([0, 1, complex("nan")], [0, 1, 2]),
        ([0, 1, (0, 95)], [0, 1, 2]),
        ([0, 1, (0, 0, 0)], [0, 1, 2]),
        ([0, 1, np.array([0j, 0j])], [0, 1, 2]),
        ([0, 1, (1, 2, 3, 4)], [0, 1, 2]),
    ],
)
def test_from_points_bad_points_raise(p, q):
    with pytest.raises(InvalidValueError):
        Mobius.from_points(p, q)


@pytest.mark.parametrize(
    "call",
    [
        lambda: Mobius.zoom((0, 0), 0),
        lambda: Mobius.zoom((0, 0), np.inf),
        lambda: Mobius.zoom((0, 0), complex("nan")),
        lambda: Mobius.zoom_between((0, 0), (0, 0), 2),
        lambda: Mobius.zoom_between(1, (180, 0), 2),
        lambda: Mobius.rotation((0, 100), 10),
        lambda: Mobius.from_rotation_matrix(np.diag([1.0, 1.0, -1.0])),
        lambda: Mobius.from_rotation_matrix(np.eye(2)),
        lambda: Mobius.zoom((0, 0), 2).to_rotation_matrix(),
        lambda: Mobius.identity().power(np.nan),
    ],
)
def test_constructor_errors(call):
    with pytest.raises(InvalidValueError):
        call()


def test_point_spellings_agree():
    spellings = [
        [(0, 90), (0.0, 0.0, 1.0), 0j, np.array([0j, 1 + 0j])],
        [(0, -90), (0.0, 0.0, -2.0), INF, np.array([3 + 0j, 0j])],
        [(180, 0), (-180, 0), (-1.0, 0.0, 0.0), 1 + 0j, 1.0],
        [(0, 0), (1.0, 0.0, 0.0), -1 + 0j],
        [(-90, 0), (0.0, -1.0, 0.0), 1j],
    ]
    for group in spellings:
        pts = [as_cp1_point(p) for p in group]
        for p in pts[1:]:
            assert chordal(pts[0], p) < 1e-15, group


# -- group laws ------------------------------------------------------------------------------------
@pytest.mark.parametrize("f", NAMES)
def test_inverse(f):
    m = ex(f)
    inv = m.inverse()
    assert isinstance(inv, Mobius)
    assert_same_points(inv.pull_cp1(m.pull_cp1(POINTS_CP1)), POINTS_CP1)
    assert_same_points(m.pull_cp1(inv.pull_cp1(POINTS_CP1)), POINTS_CP1)
    assert (m @ inv).is_identity(1e-11) and (inv @ m).is_identity(1e-11)
    assert_same_map(m.inverse().inverse(), m)


@pytest.mark.parametrize("f", NAMES)
@pytest.mark.parametrize("g", NAMES[::3] + ["random_a", "zoom_complex"])
def test_composition_is_application(f, g):
    fg = ex(f) @ ex(g)
    assert isinstance(fg, Mobius)
    assert_same_points(fg.pull_cp1(POINTS_CP1), ex(f).pull_cp1(ex(g).pull_cp1(POINTS_CP1)))
    # on plane points too, infinity included
    z = np.array([0, 1, -1j, 0.3 + 0.2j, 1e6, INF])
    np.testing.assert_allclose(
        coords.xyz_from_cp1(coords.cp1_from_plane(fg(z))),
        coords.xyz_from_cp1(coords.cp1_from_plane(ex(f)(ex(g)(z)))),
        atol=POINTS,
    )


@pytest.mark.parametrize(
    "triple",
    [
        ("random_a", "random_b", "random_c"),
        ("zoom_complex", "rotation_generic", "translation_generic"),
        ("three_points_lonlat", "zoom_shrink", "yaw_pitch_roll"),
    ],
)
def test_associativity_and_identity(triple):
    f, g, h = (ex(n) for n in triple)
    assert_same_map((f @ g) @ h, f @ (g @ h))
    ident = Mobius.identity()
    for m in (f, g, h):
        assert_same_map(ident @ m, m)
        assert_same_map(m @ ident, m)


def test_equality_up_to_sign_and_scale():
    m = ex("random_a")
    a = m.matrix
    assert Mobius(-a) == m
    assert Mobius(3.7j * a) == m
    assert Mobius(a + 1e-6) != m
    assert m != "not a map" and (m == 3) is False
    assert Mobius.identity() == Mobius(-np.eye(2))
    assert Mobius.rotation((0, 0), 360) == Mobius.identity()  # the matrix is -I


def _cross_ratio(p: np.ndarray) -> complex:
    """Cross-ratio [z1, z2; z3, z4] of four homogeneous pairs (scale invariant)."""

    def br(i: int, j: int) -> complex:
        return p[i, 0] * p[j, 1] - p[i, 1] * p[j, 0]

    return br(0, 2) * br(1, 3) / (br(1, 2) * br(0, 3))


@pytest.mark.parametrize("f", NAMES)
def test_cross_ratio_preserved(f):
    r = np.random.default_rng(11)
    for _ in range(5):
        z = r.normal(size=4) + 1j * r.normal(size=4)
        z[r.integers(4)] = INF if r.random() < 0.5 else z[0] * 1e-3
        p = coords.cp1_from_plane(z)
        cr = _cross_ratio(p)
        cr_mapped = _cross_ratio(ex(f).pull_cp1(p))
        assert abs(cr_mapped - cr) <= 1e-9 * max(1.0, abs(cr))


# -- powers ----------------------------------------------------------------------------------------
@pytest.mark.parametrize("f", NAMES)
def test_power_basics(f):
    m = ex(f)
    assert_same_map(m**1, m)
    assert_same_map(m**0, Mobius.identity())
    assert_same_map(m**-1, m.inverse())
    assert_same_map(m**2, m @ m)
    half = m**0.5
    assert_same_map(half @ half, m)
    third = m ** (1 / 3)
    assert_same_map(third @ third @ third, m)


@PROPERTY
@given(
    name=st.sampled_from(NAMES),
    s=st.floats(-2.5, 2.5),
    t=st.floats(-2.5, 2.5),
)
def test_power_is_a_one_parameter_group(name, s, t):
    m = ex(name)
    assert_same_map((m**s) @ (m**t), m ** (s + t), tol=1e-9)


@PROPERTY
@given(entries=st.lists(st.floats(-3, 3), min_size=8, max_size=8), s=st.floats(-2, 2))
def test_power_of_random_matrices(entries, s):
    a = np.array(entries[:4]).reshape(2, 2) + 1j * np.array(entries[4:]).reshape(2, 2)
    if abs(np.linalg.det(a)) < 1e-2 * max(1.0, np.abs(a).max()) ** 2:
        return
    m = Mobius(a)
    if np.abs(m.matrix).max() > 30:  # keep the conditioning sane for a fixed tolerance
        return
    assert_same_map((m**s) @ (m ** (1 - s)), m, tol=1e-8)


@pytest.mark.parametrize(
    ("m", "t", "expected"),
    [
        (Mobius.zoom((20, 30), 4.0), 0.5, Mobius.zoom((20, 30), 2.0)),  # hyperbolic
        (Mobius.zoom((20, 30), 4.0), -1.5, Mobius.zoom((20, 30), 1 / 8)),
        (Mobius.zoom((5, -5), 2 * np.exp(0.8j)), 0.5, Mobius.zoom((5, -5), 2**0.5 * np.exp(0.4j))),
        (Mobius.rotation((10, 20), 90), 1 / 3, Mobius.rotation((10, 20), 30)),  # elliptic
        (Mobius.rotation((10, 20), 270), 0.5, Mobius.rotation((10, 20), -45)),  # the short way
        (Mobius.translation((30, 10), 0.2 + 0.3j), 2.5, Mobius.translation((30, 10), 0.5 + 0.75j)),
        (Mobius([[1, 0.5], [0, 1]]), -3, Mobius([[1, -1.5], [0, 1]])),  # parabolic
    ],
)
def test_power_on_each_class(m, t, expected):
    assert_same_map(m**t, expected)
    kind = m.classify()
    assert (m**t).classify() == kind


def test_examples_cover_every_class():
    kinds = {m.classify() for m, _ in EXAMPLES.values()}
    assert kinds == {"identity", "elliptic", "parabolic", "hyperbolic", "loxodromic"}


# -- classification of constructor output ----------------------------------------------------------
@pytest.mark.parametrize(
    ("m", "kind"),
    [
        (Mobius.zoom((30, 40), 1.0), "identity"),
        (Mobius.zoom((30, 40), 1.001), "hyperbolic"),
        (Mobius.zoom((30, 40), 1j), "elliptic"),  # a unit factor is a pure turn
        (Mobius.zoom((30, 40), 1.5j), "loxodromic"),
        (Mobius.translation((30, 40), 0), "identity"),
        (Mobius.translation((30, 40), 1e-3), "parabolic"),
        (Mobius.rotation((30, 40), 0), "identity"),
        (Mobius.rotation((30, 40), 1e-3), "elliptic"),
        (Mobius.from_yaw_pitch_roll(0, 0, 0), "identity"),
        (Mobius.rotation_to((30, 40), (30, 40)), "identity"),
        (Mobius.from_points([0, 1, INF], [0, 1, INF]), "identity"),
        (Mobius.from_points([0, 1, INF], [0, 2, INF]), "hyperbolic"),
        (Mobius.from_points([0, 1, INF], [1, 2, INF]), "parabolic"),
        (Mobius.from_points([0, 1, INF], [0, 1j, INF]), "elliptic"),
    ],
)
def test_classify_constructors(m, kind):
    assert m.classify() == kind


# -- fixed points ----------------------------------------------------------------------------------
@pytest.mark.parametrize("f", NON_IDENTITY)
def test_fixed_points_are_fixed(f):
    m = ex(f)
    fp = m.fixed_points()
    assert fp.shape == ((1, 2) if m.classify() == "parabolic" else (2, 2))
    assert_same_points(m.pull_cp1(fp), fp, tol=1e-9)
    if len(fp) == 2:
        assert chordal(fp[0], fp[1]) > 1e-3


def _iterate(m: Mobius, p: np.ndarray, n: int) -> np.ndarray:
    for _ in range(n):
        p = m.pull_cp1(p)
    return p


@pytest.mark.parametrize(("at", "factor"), [((20, 10), 2.5), ((-60, -40), 3 * np.exp(1j))])
def test_zoom_fixed_point_order(at, factor):
    p = as_cp1_point(at)
    anti = coords.antipode_cp1(p)
    # |factor| > 1: magnifies at `at`, so iterating flows away from it to the antipode,
    # which is attracting and comes first
    fp = Mobius.zoom(at, factor).fixed_points()
    assert_same_points(fp, np.stack([anti, p]), tol=1e-12)
    start = coords.cp1_from_lonlat(np.radians([[100.0, 5.0], [at[0] + 1, at[1] + 1]]))
    assert_same_points(_iterate(Mobius.zoom(at, factor), start, 60), np.stack([anti, anti]), 1e-9)
    # the inverse swaps them
    fp = Mobius.zoom(at, 1 / factor).fixed_points()
    assert_same_points(fp, np.stack([p, anti]), tol=1e-12)
    # local scale at the fixed points
    scale = Mobius.zoom(at, factor).local_scale(np.stack([p, anti]))
    np.testing.assert_allclose(scale, [abs(factor), 1 / abs(factor)], rtol=1e-12)


def test_rotation_fixed_point_order():
    axis = as_cp1_point((40, 25))
    fp = Mobius.rotation((40, 25), 30).fixed_points()
    assert_same_points(fp[0], axis, tol=1e-12)
    fp = Mobius.rotation((40, 25), -30).fixed_points()
    assert_same_points(fp[1], axis, tol=1e-12)


def test_identity_fixed_points():
    fp = Mobius.identity().fixed_points()
    assert_same_points(fp, np.array([[0, 1], [1, 0]]), tol=0)


@pytest.mark.parametrize("f", NON_IDENTITY)
@pytest.mark.parametrize("by", ["random_b", "rotation_generic", "zoom_complex"])
def test_conjugation_moves_fixed_points(f, by):
    m, b = ex(f), ex(by)
    c = m.conjugate(by=b)
    assert isinstance(c, Mobius)
    assert c.classify() == m.classify()
    assert abs(abs(c.trace) - abs(m.trace)) < 1e-9
    fp = m.fixed_points()
    moved = b.pull_cp1(fp)
    assert_same_points(c.pull_cp1(moved), moved, tol=1e-9)
    cfp = c.fixed_points()
    assert len(cfp) == len(fp)
    # same fixed points; in the same order where the order is defined by dynamics
    if m.classify() in ("hyperbolic", "loxodromic"):
        assert_same_points(cfp, moved, tol=1e-8)
    else:
        d = chordal(cfp[:, None], moved[None, :])
        assert np.all(d.min(axis=1) < 1e-8)


# -- three-point maps ------------------------------------------------------------------------------
@PROPERTY
@given(seed=st.integers(0, 2**32 - 1))
def test_from_points_hits_targets(seed):
    r = np.random.default_rng(seed)
    xyz = r.normal(size=(6, 3))
    xyz /= np.linalg.norm(xyz, axis=-1, keepdims=True)
    p, q = xyz[:3], xyz[3:]
    pts_p = coords.cp1_from_xyz(p)
    pts_q = coords.cp1_from_xyz(q)
    sep = min(
        chordal(a, b).min()
        for a, b in ((pts_p[0], pts_p[1:]), (pts_p[1], pts_p[2]), (pts_q[0], pts_q[1:]))
    )
    sep = min(sep, chordal(pts_q[1], pts_q[2]))
    if sep < 0.05:
        return
    m = Mobius.from_points(list(p), list(q))
    assert_same_points(m.pull_cp1(pts_p), pts_q, tol=1e-9)


def test_from_points_with_infinity_and_spellings():
    m = Mobius.from_points([0, 1, INF], [(0, 0), (90, 0), (0, -90)])
    np.testing.assert_allclose(
        m.apply_lonlat([[0, 90], [180, 0]]), [[0, 0], [90, 0]], atol=1e-9
    )  # 0 is the zenith, 1 the back
    assert np.isinf(m(INF))


# -- rotations are exactly the unitary matrices ----------------------------------------------------
ROTATIONS = [
    Mobius.rotation((0, 90), 30),
    Mobius.rotation((37, -21), 123),
    Mobius.rotation((1.0, 2.0, -0.5), -77),
    Mobius.rotation(INF, 10),
    Mobius.rotation(0.3 - 0.4j, 180),
    Mobius.from_yaw_pitch_roll(30, 20, 10),
    Mobius.from_yaw_pitch_roll(-170, 80, 120),
    Mobius.rotation_to((0, 0), (90, 45)),
    Mobius.rotation_to((20, 30), (-160, -30)),
    Mobius.rotation_to((0, 90), (0, -90)),
    Mobius.zoom((45, 30), np.exp(0.7j)),
]
NON_ROTATIONS = [
    ex("zoom_real"),
    ex("translation_paper"),
    ex("random_a"),
    ex("three_points_lonlat"),
]


def _unit_points(n: int = 30, seed: int = 5) -> np.ndarray:
    v = np.random.default_rng(seed).normal(size=(n, 3))
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


@pytest.mark.parametrize("m", ROTATIONS)
def test_rotations_are_unitary_isometries(m):
    a = m.matrix
    np.testing.assert_allclose(a @ a.conj().T, np.eye(2), atol=1e-12)
    assert m.is_rotation()
    v = _unit_points()
    w = m.apply_xyz(v)
    np.testing.assert_allclose(w @ w.T, v @ v.T, atol=1e-12)
    r = m.to_rotation_matrix()
    np.testing.assert_allclose(r @ r.T, np.eye(3), atol=1e-12)
    assert abs(np.linalg.det(r) - 1) < 1e-12
    np.testing.assert_allclose(w, v @ r.T, atol=1e-12)
    np.testing.assert_allclose(m.local_scale(coords.cp1_from_xyz(v)), 1.0, atol=1e-12)


@pytest.mark.parametrize("seed", range(8))
def test_random_unitary_acts_orthogonally(seed):
    m = Mobius(_random_su2(seed))
    assert m.is_rotation()
    v = _unit_points(seed=seed)
    w = m.apply_xyz(v)
    np.testing.assert_allclose(w @ w.T, v @ v.T, atol=1e-12)  # dot products preserved
    # and the action is linear: xyz -> R xyz with R orthogonal, det +1
    r = m.to_rotation_matrix()
    np.testing.assert_allclose(w, v @ r.T, atol=1e-12)
    np.testing.assert_allclose(r.T @ r, np.eye(3), atol=1e-12)
    assert abs(np.linalg.det(r) - 1) < 1e-12


@pytest.mark.parametrize("m", NON_ROTATIONS)
def test_non_unitary_is_not_an_isometry(m):
    assert not m.is_rotation()
    v = _unit_points()
    w = m.apply_xyz(v)
    assert np.abs(w @ w.T - v @ v.T).max() > 1e-2
    with pytest.raises(InvalidValueError):
        m.to_rotation_matrix()


def test_rotation_sign():
    # counter-clockwise seen from the centre looking at the axis
    r = Mobius.rotation((0, 0), 90)
    np.testing.assert_allclose(r.apply_lonlat([10.0, 0.0]), [0.0, 10.0], atol=1e-9)
    r = Mobius.rotation((0, 90), 30)  # about the zenith: longitudes grow
    np.testing.assert_allclose(r.apply_lonlat([[0.0, 0.0], [50.0, 40.0]]), [[30, 0], [80, 40]])
    # the right-hand rule about the axis vector, in the xyz frame of coords
    np.testing.assert_allclose(
        Mobius.rotation((0, 0, 1), 90).to_rotation_matrix(),
        [[0, -1, 0], [1, 0, 0], [0, 0, 1]],
        atol=1e-12,
    )


def test_zoom_with_unit_factor_is_rotation():
    for at, deg in [((30, 40), 50.0), ((-120, -10), -100.0), (INF, 20.0)]:
        assert_same_map(Mobius.zoom(at, np.exp(1j * np.radians(deg))), Mobius.rotation(at, deg))


def test_rotation_to():
    for p, q in [
        ((0, 0), (90, 45)),
        ((20, 30), (-160, -30)),
        ((0, 90), (0, -90)),
        ((1, 2), (1, 2)),
    ]:
        m = Mobius.rotation_to(p, q)
        assert m.is_rotation()
        np.testing.assert_allclose(
            coords.xyz_from_cp1(m.pull_cp1(as_cp1_point(p))),
            coords.xyz_from_cp1(as_cp1_point(q)),
            atol=1e-12,
        )


@PROPERTY
@given(seed=st.integers(0, 2**32 - 1))
def test_rotation_matrix_round_trip(seed):
    from scipy.spatial.transform import Rotation

    r = Rotation.random(random_state=seed).as_matrix()
    m = Mobius.from_rotation_matrix(r)
    assert m.is_rotation()
    np.testing.assert_allclose(m.to_rotation_matrix(), r, atol=1e-12)
    m2 = Mobius(_random_su2(seed % 1000))
    assert_same_map(Mobius.from_rotation_matrix(m2.to_rotation_matrix()), m2, tol=1e-10)


@pytest.mark.parametrize(
    "r",
    [np.eye(3), np.diag([1.0, -1.0, -1.0]), np.diag([-1.0, -1.0, 1.0]), np.diag([-1.0, 1.0, -1.0])],
)
def test_rotation_matrix_round_trip_special(r):
    m = Mobius.from_rotation_matrix(r)
    np.testing.assert_allclose(m.to_rotation_matrix(), r, atol=1e-12)


@pytest.mark.parametrize(
    ("yaw", "pitch", "roll"), [(30, 0, 0), (0, 20, 0), (0, 0, 10), (30, 20, 10)]
)
def test_yaw_pitch_roll_meaning(yaw, pitch, roll):
    m = Mobius.from_yaw_pitch_roll(yaw, pitch, roll)
    # pulled back: the output centre shows the input at (yaw, pitch)
    centre = m.apply_xyz([1.0, 0.0, 0.0])
    y, p = np.radians([yaw, pitch])
    np.testing.assert_allclose(
        centre, [np.cos(p) * np.cos(y), np.cos(p) * np.sin(y), np.sin(p)], atol=1e-12
    )
    if yaw == pitch == 0:  # the right horizon shows latitude -roll
        right = m.apply_lonlat([90.0, 0.0])
        np.testing.assert_allclose(right, [90.0, -roll], atol=1e-9)


# -- local scale -----------------------------------------------------------------------------------
class _PlainPull(SphereMap):
    """Only pull_cp1: reaches the base class's finite-difference local scale."""

    kind = ""

    def __init__(self, m: Mobius):
        self.m = m

    def pull_cp1(self, zw):
        return self.m.pull_cp1(zw)


def _scale_from_formula(m: Mobius, zw: np.ndarray) -> np.ndarray:
    """|S'(z)| (1 + |z|^2) / (1 + |S(z)|^2) in the plane, S' = 1/(cz + d)^2 (det 1)."""
    (a, b), (c, d) = m.matrix
    z = coords.plane_from_cp1(zw)
    s = (a * z + b) / (c * z + d)
    return np.abs(1 / (c * z + d) ** 2) * (1 + np.abs(z) ** 2) / (1 + np.abs(s) ** 2)


@pytest.mark.parametrize("f", NAMES)
def test_local_scale(f):
    m = ex(f)
    p = POINTS_CP1
    exact = m.local_scale(p)
    assert exact.shape == p.shape[:-1] and np.all(exact > 0)
    fd = _PlainPull(m).local_scale(p)
    np.testing.assert_allclose(fd, exact, rtol=FINITE_DIFFERENCE_REL)
    # the plane formula, away from infinity on both sides
    z = coords.plane_from_cp1(p)
    s = m(z)
    ok = (np.abs(z) < 1e3) & (np.abs(s) < 1e3)
    np.testing.assert_allclose(_scale_from_formula(m, p[ok]), exact[ok], rtol=1e-9)
    # a composite with the identity multiplies by 1; chain rule for a composite
    comp = Composite((m, Mobius.identity()))
    np.testing.assert_allclose(comp.local_scale(p), exact, rtol=1e-12)
    g = ex("zoom_complex")
    np.testing.assert_allclose(Composite((m, g)).local_scale(p), (m @ g).local_scale(p), rtol=1e-9)


# -- plain data ------------------------------------------------------------------------------------
@pytest.mark.parametrize("f", NAMES)
def test_dict_and_json_round_trip(f):
    m = ex(f)
    d = m.to_dict()
    assert d["kind"] == "mobius"
    assert json.loads(json.dumps(d)) == d  # JSON-ready plain data
    assert map_from_dict(d) == m
    assert map_from_json(m.to_json()) == m
    assert_same_map(map_from_json(m.to_json()), m, tol=1e-15)


def test_composite_round_trip():
    c = Composite((ex("zoom_complex"), ex("rotation_generic"), ex("random_a")))
    d = c.to_dict()
    assert d["kind"] == "composite" and len(d["maps"]) == 3
    back = map_from_json(json.dumps(d))
    assert isinstance(back, Composite) and back == c
    assert_same_points(back.pull_cp1(POINTS_CP1), c.pull_cp1(POINTS_CP1), tol=1e-14)
    assert_same_map(back.as_mobius(), ex("zoom_complex") @ ex("rotation_generic") @ ex("random_a"))


def test_from_dict_spellings():
    m = map_from_dict({"kind": "MOBIUS", "matrix": [["1", "0.5i"], [0, 1]]})
    assert m == Mobius([[1, 0.5j], [0, 1]])
    m = map_from_dict({"kind": "mobius", "matrix": [[[2, 0], [0, 0]], [[0, 0], [0.5, 0]]]})
    assert m == Mobius([[2, 0], [0, 0.5]])


@pytest.mark.parametrize(
    "data",
    [
        {"kind": "no-such-map"},
        {"matrix": [[1, 0], [0, 1]]},
        [1, 2],
        {"kind": "mobius", "matrix": [[1, 2], [2, 4]]},
        {"kind": "mobius", "matrix": [[1, 0], [0, 1]], "extra": 1},
        {"kind": "mobius"},
        {"kind": "mobius", "matrix": [["1+x", 0], [0, 1]]},
        {"kind": "mobius", "matrix": 5},
    ],
)
def test_from_dict_errors(data):
    with pytest.raises(InvalidValueError):
        map_from_dict(data)


def test_unknown_kind_lists_allowed():
    with pytest.raises(InvalidValueError, match="no-such-map") as info:
        map_from_dict({"kind": "no-such-map"})
    assert "mobius" in str(info.value) and "composite" in str(info.value)
    with pytest.raises(InvalidValueError, match="JSON"):
        map_from_json("{not json")


@pytest.mark.parametrize("f", NAMES)
def test_repr_is_readable(f):
    m = ex(f)
    text = repr(m)
    assert text.startswith("Mobius([[") and "\n" not in text and len(text) < 200
    back = eval(text, {"Mobius": Mobius})  # noqa: S307 - the repr is valid Python
    assert m.isclose(back, atol=1e-5)
    assert "Composite" in repr(Composite((m, ex("zoom_real"))))


def test_immutable():
    m = ex("zoom_real")
    with pytest.raises(ValueError):
        m.matrix[0, 0] = 5
    assert np.isclose(m.trace, np.trace(m.matrix))
