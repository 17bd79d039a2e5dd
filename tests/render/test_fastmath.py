"""The branch-free ``exp``, ``log`` and ``sincos`` of the compiled stages, and the stage code
paths they brought.

The functions (:mod:`spherewarp.render._fastmath`) are checked inside numba loops compiled
with the stages' own flags, against NumPy over dense grids of their whole ranges and
against mpmath (40 digits) where the argument reduction is hardest. The stage tests cover
what the map tests of ``test_stages.py`` do not reach: the exp stage's libm fix-up for
huge angles, the Droste stage's round-hole path and the rational stage's symmetric plans.
"""

from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from spherewarp import coords
from spherewarp.maps import Droste, Rational, TwistedDroste
from spherewarp.render import fast

needs_jit = pytest.mark.skipif(not fast.available(), reason="numba is not installed")

#: what the functions reach (the module docstring says < 2 ulp; 2e-16 absolute for sincos)
ULP = 2.0
SINCOS_ABS = 2.5e-16


@pytest.fixture(scope="module")
def fm():
    """Vectorised loops over the functions, compiled as the stages are."""
    from numba import njit

    from spherewarp.render import _fastmath as m

    flags = {"fastmath": {"contract", "nsz"}, "error_model": "numpy", "nogil": True}

    @njit(**flags)
    def vexp(x, out):
        for k in range(x.size):
            out[k] = m.fexp(x[k])

    @njit(**flags)
    def vlog(x, out):
        for k in range(x.size):
            out[k] = m.flog(x[k])

    @njit(**flags)
    def vsincos(x, s, c):
        for k in range(x.size):
            a, b = m.fsincos(x[k])
            s[k] = a
            c[k] = b

    def exp(x):
        x = np.ascontiguousarray(x, np.float64)
        out = np.empty_like(x)
        vexp(x, out)
        return out

    def log(x):
        x = np.ascontiguousarray(x, np.float64)
        out = np.empty_like(x)
        vlog(x, out)
        return out

    def sincos(x):
        x = np.ascontiguousarray(x, np.float64)
        s = np.empty_like(x)
        c = np.empty_like(x)
        vsincos(x, s, c)
        return s, c

    return exp, log, sincos, m.SINCOS_MAX


def _ulps(got: np.ndarray, ref: np.ndarray) -> float:
    """Max error in units of the last place of the reference (finite references)."""
    ok = np.isfinite(ref)
    assert np.array_equal(np.isfinite(got), ok)
    return float(np.max(np.abs(got[ok] - ref[ok]) / np.spacing(np.abs(ref[ok]))))


# -- exp -------------------------------------------------------------------------------------------
@needs_jit
def test_exp_whole_range(fm):
    exp = fm[0]
    rng = np.random.default_rng(1)
    x = np.concatenate(
        [
            np.linspace(-746.0, 710.0, 400_001),
            rng.uniform(-1.0, 1.0, 100_000),
            -np.geomspace(1e-300, 746.0, 20_000),
            np.geomspace(1e-300, 709.7, 20_000),
            np.linspace(-745.2, -708.0, 20_001),  # subnormal results
        ]
    )
    with np.errstate(over="ignore"):
        ref = np.exp(x)
    assert _ulps(exp(x), ref) <= ULP


@needs_jit
def test_exp_special_values(fm):
    exp = fm[0]
    x = np.array([-np.inf, -800.0, -746.0, -0.0, 0.0, 709.78, 709.79, 800.0, np.inf, np.nan])
    got = exp(x)
    assert got[:3].tolist() == [0.0, 0.0, 0.0]
    assert got[3] == got[4] == 1.0
    assert np.isfinite(got[5]) and got[5] > 1.79e308
    assert np.isinf(got[6:9]).all()
    assert np.isnan(got[9])


@needs_jit
def test_exp_against_mpmath(fm):
    exp = fm[0]
    rng = np.random.default_rng(2)
    x = np.concatenate([rng.uniform(-745.0, 709.0, 1500), rng.uniform(-0.5, 0.5, 500)])
    got = exp(x)
    with mpmath.workdps(40):
        ref = np.array([float(mpmath.exp(mpmath.mpf(float(v)))) for v in x])
    assert _ulps(got, ref) <= ULP


@needs_jit
@settings(max_examples=200, deadline=None)
@given(st.lists(st.floats(-745.0, 709.7), min_size=1, max_size=64))
def test_exp_any_argument(fm, xs):
    x = np.array(xs)
    assert _ulps(fm[0](x), np.exp(x)) <= ULP


# -- log -------------------------------------------------------------------------------------------
@needs_jit
def test_log_whole_range(fm):
    log = fm[1]
    rng = np.random.default_rng(3)
    x = np.concatenate(
        [
            np.geomspace(5e-324, 1.7e308, 400_001),  # subnormals included
            rng.uniform(0.5, 2.0, 100_000),
            1.0 + np.linspace(-1e-6, 1e-6, 20_001),  # log(x) ~ x - 1: relative accuracy
            np.geomspace(1e-300, 1.0, 20_000),  # the Droste stage's range
        ]
    )
    assert _ulps(log(x), np.log(x)) <= ULP


@needs_jit
def test_log_special_values(fm):
    log = fm[1]
    got = log(np.array([0.0, -0.0, -1.0, -np.inf, np.inf, np.nan, 1.0, 5e-324]))
    assert got[0] == got[1] == -np.inf
    assert np.isnan(got[2:4]).all()
    assert got[4] == np.inf
    assert np.isnan(got[5])
    assert got[6] == 0.0
    assert got[7] == np.log(5e-324)


@needs_jit
def test_log_against_mpmath(fm):
    log = fm[1]
    rng = np.random.default_rng(4)
    x = np.concatenate([10.0 ** rng.uniform(-307, 307, 1500), 1 + rng.uniform(-0.3, 0.4, 500)])
    got = log(x)
    with mpmath.workdps(40):
        ref = np.array([float(mpmath.log(mpmath.mpf(float(v)))) for v in x])
    assert _ulps(got, ref) <= ULP


@needs_jit
@settings(max_examples=200, deadline=None)
@given(st.lists(st.floats(5e-324, 1.7e308), min_size=1, max_size=64))
def test_log_any_argument(fm, xs):
    x = np.array(xs)
    assert _ulps(fm[1](x), np.log(x)) <= ULP


# -- sincos ----------------------------------------------------------------------------------------
@needs_jit
@pytest.mark.parametrize("bound", [4.0, 1e3, 1e6, "max"])
def test_sincos_dense(fm, bound):
    sincos, smax = fm[2], fm[3]
    bound = smax if bound == "max" else bound
    rng = np.random.default_rng(5)
    x = np.concatenate([np.linspace(-bound, bound, 400_001), rng.uniform(-bound, bound, 100_000)])
    s, c = sincos(x)
    assert np.abs(s - np.sin(x)).max() <= SINCOS_ABS
    assert np.abs(c - np.cos(x)).max() <= SINCOS_ABS


@needs_jit
def test_sincos_near_multiples_of_half_pi(fm):
    """Where the reduced argument is smallest (the hardest cases of the reduction)."""
    sincos, smax = fm[2], fm[3]
    k = np.unique(np.concatenate([np.arange(1, 200), np.geomspace(200, smax / 1.6, 300)]))
    k = np.floor(k)
    x = np.concatenate([k * (np.pi / 2), -k * (np.pi / 2), np.nextafter(k * (np.pi / 2), 0)])
    x = x[np.abs(x) <= smax]
    s, c = sincos(x)
    with mpmath.workdps(60):
        rs = np.array([float(mpmath.sin(mpmath.mpf(float(v)))) for v in x])
        rc = np.array([float(mpmath.cos(mpmath.mpf(float(v)))) for v in x])
    assert np.abs(s - rs).max() <= SINCOS_ABS
    assert np.abs(c - rc).max() <= SINCOS_ABS


@needs_jit
def test_sincos_beyond_its_range_is_bounded(fm):
    """Past SINCOS_MAX the values mean nothing (callers redo those points), but stay finite."""
    sincos, smax = fm[2], fm[3]
    x = np.concatenate([np.geomspace(smax, 1e300, 2000), -np.geomspace(smax, 1e300, 2000)])
    s, c = sincos(np.append(x, [np.inf, -np.inf]))
    assert np.isfinite(s).all() and np.isfinite(c).all()
    assert np.abs(s).max() <= 1.0 and np.abs(c).max() <= 1.0
    s, c = sincos(np.array([np.nan]))
    assert np.isnan(s[0]) and np.isnan(c[0])


@needs_jit
@settings(max_examples=200, deadline=None)
@given(st.lists(st.floats(-1.6e6, 1.6e6), min_size=1, max_size=64))
def test_sincos_any_argument(fm, xs):
    x = np.array(xs)
    s, c = fm[2](x)
    assert np.abs(s - np.sin(x)).max() <= SINCOS_ABS
    assert np.abs(c - np.cos(x)).max() <= SINCOS_ABS


# -- the stage paths -------------------------------------------------------------------------------
IN_SHAPE = (64, 128)
OUT_SHAPE = (48, 96)


def _pixel_centres_error(m) -> tuple[float, float, float]:
    """Max |dx| (wrapped; not at the source's poles), |dy| in source pixels and the max
    relative error of the magnification, compiled stages against ``pull_cp1``."""
    spec = fast.kernel_spec(m, opt_in="all")
    x, y, s, ok = fast.source_coords(spec, IN_SHAPE, OUT_SHAPE)
    assert ok.all()
    (h_in, w_in), (h, w) = IN_SHAPE, OUT_SHAPE
    grid = np.stack(np.meshgrid(np.arange(w) + 0.5, np.arange(h) + 0.5), -1)
    zw = coords.cp1_from_lonlat(coords.lonlat_from_pixel(grid, w, h))
    ll = coords.lonlat_from_cp1(m.pull_cp1(zw))
    ref = coords.pixel_from_lonlat(ll, w_in, h_in)
    dx = np.abs((x - ref[..., 0] + w_in / 2) % w_in - w_in / 2)
    at_pole = np.abs(ll[..., 1]) > np.pi / 2 - 1e-7
    rs = m.local_scale(zw)
    big = rs > 1e-12
    rel = np.abs(s[big] - rs[big]) / rs[big]
    return (
        float(dx[~at_pole].max(initial=0.0)),
        float(np.abs(y - ref[..., 1]).max()),
        float(rel.max(initial=0.0)),
    )


def _exp_stage_numpy(lam, near, cap, t, x, y, z, g):
    """The exp stage as it was before the branch-free rewrite (libm, scalar formulas)."""
    r = np.sqrt(x * x + y * y + z * z)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        d = np.where(x < 0, (y * y + z * z) / (r - x), r + x)
        inside = d < near * r
        phi = lam * (-y / d)
        sr = -lam * (z / d)
        e = np.exp(-np.abs(sr))
        gs = g / t * (lam * r / d) * (2 * e / (1 + e * e))
        sg = np.where(sr <= 0, 1.0, -1.0)
        qr = -e * np.cos(phi)
        qi = sg * (e * np.sin(phi))
        r2 = qr * qr + qi * qi
        inv = 1 / (1 + r2)
        out = np.stack([-2 * qr * inv, -2 * sg * qi * inv, sg * (1 - r2) * inv])
    out[:, inside] = 0.0
    out[2, inside] = np.where(z[inside] >= 0, 1.0, -1.0)
    return out, np.where(inside, cap, gs), phi


@needs_jit
def test_exp_stage_huge_angles_use_libm():
    """Next to the singularity |lam Im u| passes SINCOS_MAX: those points are redone with
    math.sin/cos after the vectorised loop; every point matches the libm formulas."""
    from spherewarp.render import _kernels as k

    lam, near, cap = 4.0, 5e-19, 1e12
    # points at angular distance delta from the singularity (-1, 0, 0), many directions
    delta = np.geomspace(1e-12, 1.0, 40)
    ang = np.linspace(0, 2 * np.pi, 16, endpoint=False) + 0.1
    dd, aa = np.meshgrid(delta, ang)
    dd, aa = dd.ravel(), aa.ravel()
    x = -np.cos(dd)
    y = np.sin(dd) * np.cos(aa)
    z = np.sin(dd) * np.sin(aa)
    t = np.ones_like(x)
    g = np.ones_like(x)
    ref, gref, phi = _exp_stage_numpy(lam, near, cap, t, x, y, z, g)
    assert (np.abs(phi) > k.SINCOS_MAX).sum() > 20  # the fix-up path is exercised
    T, X, Y, Z, G = (a.copy() for a in (t, x, y, z, g))
    k._stage_exp(np.array([lam, near, cap]), T, X, Y, Z, G, np.ones(x.size, np.uint8), x.size)
    assert (T == 1.0).all()
    # errors of the order of |phi| times the rounding of phi itself
    tol = 1e-14 * np.maximum(1.0, np.abs(phi))
    for got, want in zip((X, Y, Z), ref, strict=True):
        assert np.all(np.abs(got - want) <= tol)
    assert np.allclose(G, gref, rtol=1e-12, atol=0)


@needs_jit
@pytest.mark.parametrize(
    "m",
    [
        Droste((0, 0), np.full(64, math.log(0.3)), 4.0),
        Droste((30, 20), np.full(16, math.log(0.5)), 3.0, phase=0.3, far=(-100, -40)),
        TwistedDroste((20, -10), np.full(64, math.log(0.3)), 5.0),
    ],
    ids=["straight", "far_phase", "twisted"],
)
def test_droste_round_hole(m):
    """All rho samples equal (a round hole): the stage skips the table lookup."""
    ex, ey, es = _pixel_centres_error(m)
    assert ex <= 1e-6 and ey <= 1e-6
    assert es <= 1e-6


@needs_jit
@pytest.mark.parametrize(
    ("num", "den", "g"),
    [
        ([1, 0, 0.3j, 0, 0.5], [0, 0.7, 0, 1.2 - 0.4j, 0], 2),  # D padded: one step fewer
        ([0.3, 0, 0, 1, 0], [0, 0.5j, 0, 0, 2], 3),
        ([0.2, 0, 0, 0, -1j, 0], [0, 0.6, 0, 0, 0, 1 + 0.3j], 4),
        ([2], [1 + 1j], 1),  # degree 0: a constant map
    ],
)
def test_rational_symmetric_plans(num, den, g):
    """Maps N = q^a P(q^g), D = q^b Q(q^g) (a + b = 1 in both charts) are evaluated in q^g."""
    from spherewarp.render import _kernels as k

    m = Rational(num, den)
    spec = fast.kernel_spec(m)
    assert k._rational_plan(spec.params[0])[0] == g
    ex, ey, es = _pixel_centres_error(m)
    assert ex <= 1e-6 and ey <= 1e-6
    assert es <= 1e-6
