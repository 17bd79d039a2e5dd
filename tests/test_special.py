"""Theta functions, Weierstrass ℘ and ℘', Schwarz–Christoffel maps: against mpmath."""

from __future__ import annotations

import cmath
import math

import numpy as np
import pytest

from spherewarp import special
from spherewarp.errors import InvalidValueError

mp = pytest.importorskip("mpmath")

OMEGA = cmath.exp(1j * math.pi / 3)
TAU = {"square": 1j, "hex": OMEGA}

#: relative error of ℘ and ℘' against mpmath (the issue asks for 1e-10)
WP_REL = 1e-12
#: relative error of SC_n against mpmath away from the vertices
SC_REL = 1e-13


def mp_wp(z: complex, tau: complex) -> tuple[complex, complex]:
    """℘ and ℘' by DLMF 23.6.5 (additive theta formula, not the product we use), 30 digits."""
    with mp.workdps(30):
        q = mp.exp(1j * mp.pi * mp.mpc(tau))
        t2, t3, t4 = (mp.jtheta(k, 0, q) for k in (2, 3, 4))
        e1 = mp.pi**2 / 3 * (t2**4 + 2 * t4**4)

        def f(x):
            v = mp.pi * x
            return e1 + (mp.pi * t3 * t4 * mp.jtheta(2, v, q) / mp.jtheta(1, v, q)) ** 2

        zz = mp.mpc(z)
        return complex(f(zz)), complex(mp.diff(f, zz))


def cell_points(tau: complex, n: int, rng: np.random.Generator) -> np.ndarray:
    """Random points of the fundamental parallelogram, at least 0.05 from the lattice points."""
    s, t = rng.uniform(0, 1, (2, 4 * n))
    z = s + t * tau
    near = np.zeros(z.shape, bool)
    for m in (0, 1):
        for k in (0, 1):
            near |= np.abs(z - m - k * tau) < 0.05
    return z[~near][:n]


# ---------------------------------------------------------------------- theta
@pytest.mark.parametrize("n", [1, 2, 3, 4])
@pytest.mark.parametrize("lattice", ["square", "hex"])
def test_jtheta_matches_mpmath(n, lattice, rng):
    q = cmath.exp(1j * math.pi * TAU[lattice])
    z = rng.uniform(-4, 4, 30) + 1j * rng.uniform(-2, 2, 30)
    got = special.jtheta(n, z, q)
    ref = np.array([complex(mp.jtheta(n, mp.mpc(c), mp.mpc(q))) for c in z])
    scale = np.maximum(np.abs(ref), 1.0)
    assert np.max(np.abs(got - ref) / scale) < 1e-13


def test_jtheta_rejects_bad_nome_and_index():
    with pytest.raises(InvalidValueError):
        special.jtheta(1, 0.1, 1.5)
    with pytest.raises(InvalidValueError):
        special.jtheta(5, 0.1, 0.1)


# ---------------------------------------------------------------------- Weierstrass p
@pytest.mark.parametrize("lattice", ["square", "hex"])
def test_p_and_p_prime_match_mpmath_over_a_fundamental_domain(lattice, rng):
    z = cell_points(TAU[lattice], 60, rng)
    ref = np.array([mp_wp(c, TAU[lattice]) for c in z])
    p = special.weierstrass_p(z, lattice)
    dp = special.weierstrass_p_prime(z, lattice)
    assert np.max(np.abs(p / ref[:, 0] - 1)) < WP_REL
    assert np.max(np.abs(dp / ref[:, 1] - 1)) < 1e-10  # mp.diff is the weaker side here


@pytest.mark.parametrize("lattice", ["square", "hex"])
def test_one_over_p_near_the_poles(lattice, rng):
    tau = TAU[lattice]
    corners = np.array([0, 1, tau, 1 + tau])
    eps = 10.0 ** rng.uniform(-8, -2, 24) * np.exp(2j * np.pi * rng.uniform(0, 1, 24))
    z = corners[np.arange(24) % 4] + eps
    ref = np.array([mp_wp(c, tau)[0] for c in z])
    got = special.weierstrass_p(z, lattice)
    assert np.max(np.abs(1 / got - 1 / ref) / np.abs(1 / ref)) < WP_REL
    # the pair form is exact at the lattice points
    pair = special.weierstrass_p_pair(corners, lattice)
    np.testing.assert_allclose(np.abs(pair[:, 0]), 1.0)
    assert np.all(np.abs(pair[:, 1]) < 1e-15)


def test_p_of_the_square_lattice_against_jacobi_sn():
    # an independent route: p(z) = e3 + (e1 - e3)/sn^2(sqrt(e1 - e3) z | m), m = 1/2,
    # with e1 = -e3 = Gamma(1/4)^4/(8 pi) and e2 = 0 for Z[i]
    e1 = math.gamma(0.25) ** 4 / (8 * math.pi)
    z = np.array([0.1 + 0.2j, 0.37 - 0.05j, 0.5 + 0.5j, 0.25 + 0.4j, -0.3 + 0.11j])
    ref = []
    with mp.workdps(30):
        r = mp.sqrt(2 * e1)
        for c in z:
            sn = mp.ellipfun("sn", r * mp.mpc(c), m=mp.mpf(1) / 2)
            ref.append(complex(-e1 + 2 * e1 / sn**2))
    got = special.weierstrass_p(z, "square")
    assert np.max(np.abs(got - np.array(ref)) / np.maximum(np.abs(ref), 1)) < WP_REL
    assert special.weierstrass_half_period_value("square") == pytest.approx(e1, rel=1e-14)


@pytest.mark.parametrize("lattice", ["square", "hex"])
def test_p_is_doubly_periodic_and_even(lattice, rng):
    tau = TAU[lattice]
    z = cell_points(tau, 200, rng) - (1 + tau) / 2
    p = special.weierstrass_p(z, lattice)
    for shift in (1, tau, 3 - 2 * tau, -5 + 7 * tau):
        np.testing.assert_allclose(special.weierstrass_p(z + shift, lattice), p, rtol=1e-10)
    np.testing.assert_allclose(special.weierstrass_p(-z, lattice), p, rtol=1e-10)
    np.testing.assert_allclose(
        special.weierstrass_p_prime(-z, lattice),
        -special.weierstrass_p_prime(z, lattice),
        rtol=1e-10,
    )


@pytest.mark.parametrize("lattice", ["square", "hex"])
def test_p_satisfies_its_differential_equation(lattice, rng):
    tau = TAU[lattice]
    e = special.weierstrass_p(np.array([0.5, tau / 2, (1 + tau) / 2]), lattice)
    g2 = -4 * (e[0] * e[1] + e[0] * e[2] + e[1] * e[2])
    g3 = 4 * e[0] * e[1] * e[2]
    z = cell_points(tau, 100, rng)
    p = special.weierstrass_p(z, lattice)
    dp = special.weierstrass_p_prime(z, lattice)
    rhs = 4 * p**3 - g2 * p - g3
    scale = np.abs(4 * p**3) + np.abs(g2 * p) + np.abs(g3)
    assert np.max(np.abs(dp**2 - rhs) / scale) < 1e-12
    assert abs(np.sum(e)) < 1e-12 * abs(e[0])


def test_normalisations_of_the_paper():
    sq = special.weierstrass_p(np.array([0.5, 0.5j, 0.5 + 0.5j]), "square", normalized=True)
    np.testing.assert_allclose(sq, [1, -1, 0], atol=1e-14)
    hx = special.weierstrass_p(np.array([0.5, (1 + OMEGA) / 3]), "hex", normalized=True)
    np.testing.assert_allclose(hx, [-1 / math.sqrt(2), 0], atol=1e-14)


def test_p_rejects_bad_input():
    with pytest.raises(InvalidValueError, match="lattice"):
        special.weierstrass_p(0.3, "triangular")
    with pytest.raises(InvalidValueError, match="finite"):
        special.weierstrass_p(np.array([np.nan]))


# ---------------------------------------------------------------------- Schwarz-Christoffel
def mp_sc(z: complex, n: int) -> complex:
    with mp.workdps(30):
        zz = mp.mpc(z)
        return complex(zz * mp.hyp2f1(mp.mpf(1) / n, mp.mpf(2) / n, 1 + mp.mpf(1) / n, zz**n))


def disk_points(rng: np.random.Generator, count: int) -> np.ndarray:
    r = np.sqrt(rng.uniform(0, 1, count))
    inner = r * np.exp(2j * np.pi * rng.uniform(0, 1, count))
    circle = np.exp(2j * np.pi * rng.uniform(0, 1, count // 2))
    ring = (1 - 10.0 ** rng.uniform(-6, -1, count // 2)) * np.exp(
        2j * np.pi * rng.uniform(0, 1, count // 2)
    )
    return np.concatenate([inner, circle, ring])


@pytest.mark.parametrize("n", [3, 4, 6])
def test_schwarz_christoffel_matches_mpmath_on_the_closed_disk(n, rng):
    z = disk_points(rng, 120)
    got = special.schwarz_christoffel(z, n)
    ref = np.array([mp_sc(c, n) for c in z])
    # rounding the argument by 2e-16 moves SC by |SC'| 2e-16 = |1 - z^n|^(-2/n) 2e-16
    cond = np.abs(1 - z.astype(np.complex128) ** n) ** (-2.0 / n) * 4e-16
    err = np.abs(got - ref)
    assert np.all(err <= SC_REL * np.abs(ref) + cond)
    far = np.abs(1 - z**n) > 1e-3
    assert np.max(err[far] / np.abs(ref[far])) < SC_REL


@pytest.mark.parametrize("n", [3, 4, 6])
def test_schwarz_christoffel_near_the_vertex_one(n):
    # on the real axis no rounding happens before the vertex series: full accuracy
    z = 1 - np.logspace(-15, -1, 15)
    ref = np.array([mp_sc(c, n) for c in z])
    np.testing.assert_allclose(special.schwarz_christoffel(z, n), ref, rtol=1e-14)
    sc1 = special.schwarz_christoffel_vertex(n)
    assert special.schwarz_christoffel(1.0, n) == pytest.approx(sc1, rel=1e-15)
    assert sc1 == pytest.approx(mp_sc(1.0, n).real, rel=1e-14)


def test_sc4_maps_the_unit_circle_onto_the_square():
    k = special.schwarz_christoffel_vertex(4)
    assert k == pytest.approx(math.gamma(0.25) ** 2 / (4 * math.sqrt(2 * math.pi)), rel=1e-15)
    # vertices where the paper puts them: the images of 1, i, -1, -i
    np.testing.assert_allclose(
        special.schwarz_christoffel(np.array([1, 1j, -1, -1j]), 4), k * np.array([1, 1j, -1, -1j])
    )
    theta = np.linspace(0, 2 * np.pi, 1001)
    w = special.schwarz_christoffel(np.exp(1j * theta), 4)
    np.testing.assert_allclose(np.abs(w.real) + np.abs(w.imag), k, rtol=1e-12)
    # the boundary is traversed once, counter-clockwise
    turn = np.sum(np.angle(np.roll(w, -1)[:-1] / w[:-1]))
    assert turn == pytest.approx(2 * np.pi, rel=1e-6)  # the vertex at 1 is ill-conditioned
    # interior points go inside
    z = 0.999 * np.exp(1j * theta)
    w = special.schwarz_christoffel(z, 4)
    assert np.all(np.abs(w.real) + np.abs(w.imag) < k)


def test_sc4_inverts_the_normalised_p():
    # p~(SC_4(w)/sqrt(e1)) = 1/w^2: SC_4 is the inverse of the square lattice's p, and the
    # diamond SC_4(disk) has half-diagonal exactly 1/2 in lattice units
    e1 = special.weierstrass_half_period_value("square")
    assert special.schwarz_christoffel_vertex(4) / math.sqrt(e1) == pytest.approx(0.5, rel=1e-14)
    w = np.array([0.3 + 0.1j, -0.5j, 0.9 * np.exp(0.3j), 0.05])
    u = special.schwarz_christoffel(w, 4) / math.sqrt(e1)
    np.testing.assert_allclose(special.weierstrass_p(u, normalized=True), 1 / w**2, rtol=1e-12)


@pytest.mark.parametrize("n", [3, 4, 6])
def test_schwarz_christoffel_has_n_fold_symmetry(n, rng):
    z = disk_points(rng, 50)
    rot = np.exp(2j * np.pi / n)
    np.testing.assert_allclose(
        special.schwarz_christoffel(z * rot, n),
        rot * special.schwarz_christoffel(z, n),
        rtol=1e-7,  # near the vertices the rounding of z * rot is amplified
        atol=1e-7,
    )


def test_schwarz_christoffel_rejects_points_outside_the_disk():
    with pytest.raises(InvalidValueError, match="closed unit disk"):
        special.schwarz_christoffel(np.array([0.5, 1.01]), 4)
    with pytest.raises(InvalidValueError, match="number of sides"):
        special.schwarz_christoffel(0.5, 2)
    with pytest.raises(InvalidValueError, match="finite"):
        special.schwarz_christoffel(np.array([np.nan]), 4)
