"""Rational maps in homogeneous form, and the SVD fit with degree detection."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from spherewarp import coords
from spherewarp.errors import InvalidTypeError, InvalidValueError
from spherewarp.maps import Mobius, Rational, fit_rational, map_from_dict, map_from_json
from spherewarp.maps.base import SphereMap
from spherewarp.maps.rational import fibonacci_cp1

#: chordal distance of two evaluations of the same map
POINTS = 1e-12
#: coefficients of a fitted map against the true ones, after fixing the scale
COEF = 1e-9


def chordal(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    a, b = coords.normalize_cp1(a), coords.normalize_cp1(b)
    return np.abs(a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0])


def random_rational(rng: np.random.Generator, dn: int, dd: int) -> Rational:
    num = rng.normal(size=dn + 1) + 1j * rng.normal(size=dn + 1)
    den = rng.normal(size=dd + 1) + 1j * rng.normal(size=dd + 1)
    return Rational(num, den)


def same_up_to_scale(a: np.ndarray, b: np.ndarray) -> float:
    """Largest coefficient difference after scaling b onto a (relative to a's largest)."""
    k = int(np.argmax(np.abs(a)))
    b = b * (a[k] / b[k])
    return float(np.max(np.abs(a - b)) / np.max(np.abs(a)))


def padded(r: Rational) -> np.ndarray:
    d = r.degree
    n = np.concatenate([np.zeros(d + 1 - r.numerator.size), r.numerator])
    m = np.concatenate([np.zeros(d + 1 - r.denominator.size), r.denominator])
    return np.concatenate([n, m])


# ---------------------------------------------------------------------- evaluation
def test_evaluation_matches_the_formula_and_is_exact_at_infinity_and_poles(rng):
    r = Rational([1, 0, 1], [2, 0])  # (z^2 + 1)/(2z)
    z = rng.normal(size=50) + 1j * rng.normal(size=50)
    np.testing.assert_allclose(r(z), (z**2 + 1) / (2 * z), rtol=1e-14)
    special = r(np.array([0, np.inf, 1j, -1j]))
    assert np.isinf(special[0]) and np.isinf(special[1])
    np.testing.assert_allclose(special[2:], [0, 0], atol=1e-16)
    # huge and tiny inputs: no overflow, no NaN
    zw = coords.cp1_from_plane(np.array([1e300, 1e-300, 1e200j]))
    out = r.pull_cp1(zw)
    assert np.all(np.isfinite(out))
    np.testing.assert_allclose(np.abs(out[..., 0]) ** 2 + np.abs(out[..., 1]) ** 2, 1.0)


def test_never_nan_on_random_pairs(rng):
    r = random_rational(rng, 5, 3)
    zw = coords.normalize_cp1(rng.normal(size=(1000, 2)) + 1j * rng.normal(size=(1000, 2)))
    zw[:3] = [[1, 0], [0, 1], [1, 1]]
    out = r.pull_cp1(zw)
    assert np.all(np.isfinite(out))
    assert np.all(np.isfinite(r.local_scale(zw)))


@pytest.mark.parametrize("degrees", [(2, 1), (1, 3), (4, 4), (0, 2)])
def test_local_scale_is_the_spherical_derivative(degrees, rng):
    r = random_rational(rng, *degrees)
    zw = fibonacci_cp1(200)
    exact = r.local_scale(zw)
    approx = SphereMap.local_scale(r, zw)  # finite differences of the base class
    np.testing.assert_allclose(exact, approx, rtol=1e-5, atol=1e-9)
    # and the holomorphic formula |R'(z)| (1 + |z|^2)/(1 + |R(z)|^2) at finite points
    z = coords.plane_from_cp1(zw)
    n, d = np.poly1d(r.numerator), np.poly1d(r.denominator)
    deriv = (n.deriv()(z) * d(z) - n(z) * d.deriv()(z)) / d(z) ** 2
    formula = np.abs(deriv) * (1 + np.abs(z) ** 2) / (1 + np.abs(n(z) / d(z)) ** 2)
    np.testing.assert_allclose(exact, formula, rtol=1e-10)


def test_degree_one_is_a_mobius_map():
    r = Rational([1, 2j], [3, 1])
    m = r.as_mobius()
    assert isinstance(m, Mobius)
    zw = fibonacci_cp1(50)
    assert np.max(chordal(m.pull_cp1(zw), r.pull_cp1(zw))) < POINTS
    inv = r.inverse()
    assert np.max(chordal(inv.pull_cp1(r.pull_cp1(zw)), zw)) < POINTS
    with pytest.raises(InvalidValueError, match="single-valued inverse"):
        Rational([1, 0, 0], [1]).inverse()
    assert Rational([1, 0, 0], [1]).as_mobius() is None


def test_plain_data_round_trip():
    r = Rational([[0, -0.5], 0, "0.5j"], [1, 0])
    data = json.loads(r.to_json())
    assert data == {
        "kind": "rational",
        "numerator": [[0.0, -0.5], [0.0, 0.0], [0.0, 0.5]],
        "denominator": [[1.0, 0.0], [0.0, 0.0]],
    }
    assert map_from_json(r.to_json()) == r
    assert map_from_dict({**data, "degree": 2, "residual": 1e-15}) == r
    assert r == Rational([0.5j, 0, -0.5j], [-1, 0])  # the same map, scaled by -1
    assert Rational([1, 0, 1], [2, 0]).isclose(Rational([2, 0, 2], [4, 0]))


def test_bad_coefficients_are_refused():
    with pytest.raises(InvalidValueError, match="nonzero"):
        Rational([0, 0], [1])
    with pytest.raises(InvalidValueError, match="finite"):
        Rational([1, np.nan], [1])
    with pytest.raises(InvalidValueError, match="coefficients"):
        Rational("z**2", [1])
    with pytest.raises(InvalidValueError, match="complex coefficients"):
        Rational([1, "abc"], [1])


# ---------------------------------------------------------------------- fitting
@pytest.mark.parametrize("degrees", [(1, 1), (2, 1), (3, 3), (5, 2), (0, 4), (8, 8)])
def test_fit_recovers_random_maps_and_their_degree(degrees, rng):
    true = random_rational(rng, *degrees)
    fit = fit_rational(true)
    assert fit.degree == max(degrees)
    assert fit.residual < 1e-12
    assert same_up_to_scale(padded(true), padded(fit.map)) < COEF
    assert fit.map.denominator[0] == 1  # leading denominator coefficient


def test_fit_from_a_plane_function_and_from_samples(rng):
    def f(z):
        return (z**3 - 2j) / (z**2 + 0.5)

    fit = fit_rational(f)
    assert fit.degree == 3
    np.testing.assert_allclose(fit.map.numerator, [1, 0, 0, -2j], atol=1e-12)
    np.testing.assert_allclose(fit.map.denominator, [1, 0, 0.5], atol=1e-12)
    z = rng.normal(size=40) + 1j * rng.normal(size=40)
    from_samples = fit_rational((z, f(z)))
    assert from_samples.map.isclose(fit.map, 1e-9)
    pairs = fit_rational((coords.cp1_from_plane(z), coords.cp1_from_plane(f(z))), 3)
    assert pairs.map.isclose(fit.map, 1e-9)


def test_fit_handles_poles_and_infinity_among_the_samples():
    # samples exactly at the poles, at infinity and at 0
    z = np.array([0, np.inf, 1, -1, 1j, -1j, 2, 0.5, 3j, -0.25 + 0.5j, 5 - 1j, 0.1j])
    with np.errstate(divide="ignore", invalid="ignore"):
        w = (z**2 + 1) ** 2 / (4 * z * (z**2 - 1))
    w[0], w[1] = np.inf, np.inf
    fit = fit_rational((z, w), 4)
    np.testing.assert_allclose(fit.map.numerator * 4, [1, 0, 2, 0, 1], atol=1e-10)


def test_fit_of_a_mobius_map_is_that_map():
    m = Mobius.zoom((30, 10), 3) @ Mobius.rotation((0, 90), 40)
    fit = fit_rational(m)
    assert fit.degree == 1
    assert fit.map.as_mobius() == m


@pytest.mark.parametrize(
    "func",
    [np.exp, np.sqrt, lambda z: np.abs(z) ** 2, lambda z: np.conj(z)],
    ids=["exp", "sqrt", "abs2", "conj"],
)
def test_fit_refuses_maps_that_are_not_rational(func):
    with pytest.raises(InvalidValueError, match="not a rational map"):
        fit_rational(func, max_degree=12)


def test_fit_refuses_the_wrong_degree():
    with pytest.raises(InvalidValueError, match="degree 2"):  # a degree-3 map
        fit_rational(lambda z: z**3 + 1, degree=2)
    with pytest.raises(InvalidValueError, match=r"lower than 5 \(it looks like degree 3\):"):
        fit_rational(lambda z: z**3 + 1, degree=5)
    with pytest.raises(InvalidValueError, match="more than double precision tells apart"):
        fit_rational(lambda z: z**57, degree=57)  # the monomial basis's limit, said as such


def test_fit_input_errors():
    with pytest.raises(InvalidValueError, match="degree"):
        fit_rational(np.exp, degree=0)
    with pytest.raises(InvalidValueError, match="at least"):
        fit_rational((np.arange(5.0), np.arange(5.0)), 4)
    with pytest.raises(InvalidTypeError):
        fit_rational("z**2")
    with pytest.raises(InvalidValueError, match="samples"):
        fit_rational((np.arange(5.0), np.arange(6.0)))


def test_fit_to_dict_is_the_json_the_cli_prints():
    fit = fit_rational(lambda z: 1j / z)
    data = fit.to_dict()
    assert data["kind"] == "rational" and data["degree"] == 1
    assert data["denominator"] == [[1.0, 0.0], [0.0, 0.0]]
    np.testing.assert_allclose(data["numerator"], [[0.0, 1.0]], atol=1e-14)
    assert math.isfinite(data["residual"])
    json.dumps(data)
