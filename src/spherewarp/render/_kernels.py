"""Compiled kernels of the fast renderer (numba).

This module imports numba at import time; only :mod:`spherewarp.render.fast`
imports it, and only when a fast render is requested, so ``import
spherewarp`` stays light. Every kernel is compiled with ``cache=True``: the
machine code is kept on disk (next to this file, or in numba's user cache
directory when the package directory is read-only, or in
``NUMBA_CACHE_DIR``), so a second process pays no compilation.

Layout of the work
------------------
The output is cut into tiles of ``TH x TW`` pixels. The entry points take
``(..., wk, nw)`` and do the share of worker ``wk`` of ``nw`` (tiles dealt
round-robin); the caller runs the ``nw`` shares on its own threads (the
kernels release the GIL), which keeps compilation light (no parallel
accelerator pass) and needs no threading layer. A tile is processed one row
segment (a *chunk*) at a time, in small buffers that stay in the L1/L2
cache:

1. directions of the output pixels: ``(T, X, Y, Z) = (1, cos lat cos lon,
   cos lat sin lon, sin lat)`` from per-row and per-column trig tables (no
   trigonometry per pixel);
2. the *stages* of the map (:func:`run_stages`), in application order, act
   on homogeneous null vectors ``(T, X, Y, Z)`` (the point is ``(X, Y, Z)/T``)
   and keep the running spherical magnification ``G / T``. A Möbius map is a
   Lorentz transformation of these vectors: 16 multiply-adds, no division, no
   trigonometry;
3. vector -> source pixel: ``lon = atan2(Y, X)``, ``lat = atan2(Z, hypot(X,
   Y))`` with a branch-free polynomial arctangent accurate to 3e-16
   (vectorised by LLVM), then ``u = x - 1/2``, ``v = y - 1/2`` (tap space);
4. sampling, with the same rules as :mod:`spherewarp.render.sampling`:
   columns wrap, and taps above the top row or below the bottom row fold over
   the pole (row ``-1 - r``, half a turn in longitude).

Adding a stage kind (a new map family with a compiled kernel)
-------------------------------------------------------------
Write ``_stage_<name>(p, T, X, Y, Z, G, valid, n)`` below (``p`` is the
stage's float64 parameter row; update the point in place, multiply ``G`` by
the map's own magnification where it normalises ``T`` to 1 (see
:func:`_stage_lorentz` for the invariant), clear ``valid[k]`` where the map is
undefined) and add its branch to :func:`run_stages`; its code ``STAGE_<NAME>`` and
the offsets of its fields (``<NAME>_<FIELD>``) come from its entry in the table of
:mod:`spherewarp.render.stages`, whose docstring has the whole recipe.

Keep its loops vectorisable, as the existing stages are: compile it with
``_V`` (numba's ``'numpy'`` error model: no zero-divisor check, which is an
early exit), write branches as selects (``a if c else b``), call
:mod:`._fastmath` instead of ``math.exp``/``log``/``sin``/``cos`` (opaque
calls), index arrays with the loop variable (an offset ``k0 + k`` keeps
numba's negative-index wrap-around: pass slices instead), and read no array
at computed indices in a loop that writes the point arrays (a gather there
needs an overlap check LLVM cannot make; write to a :func:`_stack_block`
instead). :func:`run_stages` is compiled without reference counting
(``_nrt=False``), so a stage may not allocate: its scratch goes on the stack
(:func:`_stack_block`).

Unaligned loads
---------------
The uint8 bilinear path reads two neighbouring pixels at once with one
unaligned 8-byte load: the image's bytes are viewed as ``uint64`` with a
stride of ``C`` bytes (``C`` = channels, 1-4), and results are written with
overlapping unaligned 4-byte stores. x86-64 and AArch64 allow both; the
caller only takes this path on those machines.
"""

from __future__ import annotations

import math

import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.core import cgutils
from numba.core.extending import intrinsic
from numba.np.arrayobj import populate_array

from . import stages as _stages
from ._fastmath import SINCOS_MAX, fexp, flog, fsincos
from .stages import (
    DROSTE_BETA_ABS,
    DROSTE_BETA_IM,
    DROSTE_BETA_RE,
    DROSTE_C_IM,
    DROSTE_C_RE,
    DROSTE_CAP,
    DROSTE_ELL,
    DROSTE_M,
    DROSTE_PIVOT,
    DROSTE_RHO,
    EXP_CAP,
    EXP_LAM,
    EXP_NEAR,
    MOBIUS_L00,
    POWER_M,
    RATIONAL_COEFFICIENTS,
    RATIONAL_DEGREE,
    SCHOTTKY_COUNT,
    SCHOTTKY_DEPTH,
    SCHOTTKY_MASK_COUNT,
    SCHOTTKY_MASK_DATA,
    SCHOTTKY_MASK_DEPTH,
    SCHOTTKY_MASK_HEIGHT,
    SCHOTTKY_MASK_WIDTH,
    SCHOTTKY_MOVES,
    SCHOTTKY_MOVES_COS_R,
    SCHOTTKY_MOVES_L00,
    SCHOTTKY_MOVES_NX,
    SCHOTTKY_MOVES_SIZE,
    STAGE_DROSTE,
    STAGE_EXP,
    STAGE_MOBIUS,
    STAGE_POWER,
    STAGE_RATIONAL,
    STAGE_SCHOTTKY,
    STAGE_SCHOTTKY_MASK,
)

# Only contraction (FMA) and signless zeros: 'reassoc' rewrites (1 - t) a + t b as
# a + t (b - a), which is not exact at t = 1; 'nnan'/'ninf' would break the selects that
# discard NaN lanes; 'afn'/'arcp' may use approximate sqrt/reciprocals.
_FM = {"contract", "nsz"}
_H = {"cache": True, "nogil": True, "fastmath": _FM}  # helpers
_P = {"cache": True, "nogil": True, "fastmath": _FM}  # entry points: (..., wk, nw)
# Vectorised loops (the stages, to_source): numba's default ('python') error model checks
# every float division for a zero divisor and raises ZeroDivisionError, an early exit that
# stops LLVM from vectorising the loop. With 'numpy' a division by zero gives inf/nan,
# which the stages discard with selects where it can happen.
_V = {"cache": True, "nogil": True, "fastmath": _FM, "error_model": "numpy"}

PI = math.pi
HALF_PI = 0.5 * math.pi
TWO_PI = 2.0 * math.pi
INV_TWO_PI = 0.5 / math.pi

# Stage codes and parameter offsets: the table of spherewarp.render.stages (see run_stages).
# numba freezes these globals into the machine code it caches on disk, and its cache only
# looks at this file: a change of the table must touch this file (the fingerprint below).
_TABLE_FINGERPRINT = "f8fc09782162"
if _stages.fingerprint() != _TABLE_FINGERPRINT:  # pragma: no cover - a developer's reminder
    raise ImportError(
        "the stage table (spherewarp.render.stages) changed: update _TABLE_FINGERPRINT in "
        f"{__name__} to {_stages.fingerprint()!r} (this also recompiles the kernels)"
    )

#: interpolation codes
NEAREST = 0
BILINEAR = 1
BICUBIC = 2

#: max subsamples buffered at once in the anti-aliasing pass (>= 32 * 32)
SUB_BATCH = 2048

#: int64 slots between two workers' progress counters (64 bytes: one cache line each)
PROGRESS_STRIDE = 8

# Near-minimax polynomial of atan(a)/a in s = a^2 on [0, 1] (degree 18,
# Chebyshev interpolation in 50-digit arithmetic): |error of atan| < 3e-16.
_A0 = 0.9999999999999998
_A1 = -0.333333333333188
_A2 = 0.19999999998244405
_A3 = -0.14285714201153485
_A4 = 0.11111108947215684
_A5 = -0.09090875100099982
_A6 = 0.07691950418796795
_A7 = -0.06664007607654046
_A8 = 0.05867776001706719
_A9 = -0.052025829246698206
_A10 = 0.045668724719449945
_A11 = -0.03852606834610674
_A12 = 0.02992405293802711
_A13 = -0.02033087003302746
_A14 = 0.011430023675054508
_A15 = -0.0050003664537326496
_A16 = 0.0015739493241755762
_A17 = -0.00031420077366807334
_A18 = 2.969635660165779e-05


# -- geometry --------------------------------------------------------------------------------------
@njit(inline="always", **_H)
def _atan01(a):
    """``atan(a)`` for ``0 <= a <= 1`` (the polynomial of :func:`atan2_poly`), branch-free."""
    s = a * a
    p = _A18
    p = p * s + _A17
    p = p * s + _A16
    p = p * s + _A15
    p = p * s + _A14
    p = p * s + _A13
    p = p * s + _A12
    p = p * s + _A11
    p = p * s + _A10
    p = p * s + _A9
    p = p * s + _A8
    p = p * s + _A7
    p = p * s + _A6
    p = p * s + _A5
    p = p * s + _A4
    p = p * s + _A3
    p = p * s + _A2
    p = p * s + _A1
    p = p * s + _A0
    return p * a


@njit(inline="always", **_H)
def _atan2_ratio(a, y, x):
    """``atan2(y, x)`` from ``a = min(|x|, |y|) / max(|x|, |y|)`` (0 if both are 0)."""
    r = _atan01(a)
    r = HALF_PI - r if abs(y) > abs(x) else r
    r = PI - r if x < 0.0 else r
    return -r if y < 0.0 else r


@njit(inline="always", **_H)
def atan2_poly(y: float, x: float) -> float:
    """``atan2(y, x)`` in ``[-pi, pi]``, branch-free (vectorisable), error < 5e-16."""
    ax = abs(x)
    ay = abs(y)
    mx = max(ax, ay)
    a = min(ax, ay) / mx if mx > 0.0 else 0.0
    return _atan2_ratio(a, y, x)


@njit(**_H)
def _stage_lorentz(p, T, X, Y, Z, n):
    """A Möbius map as the Lorentz matrix at ``p[MOBIUS_L00:]`` (4x4, row-major) on
    ``(T, X, Y, Z)``.

    Linear, so ``T`` is not normalised and the magnification ``G / T`` needs
    no update: for a null vector with ``T = 1`` the sphere map's magnification
    is ``1 / T'``.
    """
    o = MOBIUS_L00  # the matrix, row-major
    l00 = p[o + 0]
    l01 = p[o + 1]
    l02 = p[o + 2]
    l03 = p[o + 3]
    l10 = p[o + 4]
    l11 = p[o + 5]
    l12 = p[o + 6]
    l13 = p[o + 7]
    l20 = p[o + 8]
    l21 = p[o + 9]
    l22 = p[o + 10]
    l23 = p[o + 11]
    l30 = p[o + 12]
    l31 = p[o + 13]
    l32 = p[o + 14]
    l33 = p[o + 15]
    for k in range(n):
        t = T[k]
        x = X[k]
        y = Y[k]
        z = Z[k]
        T[k] = l00 * t + l01 * x + l02 * y + l03 * z
        X[k] = l10 * t + l11 * x + l12 * y + l13 * z
        Y[k] = l20 * t + l21 * x + l22 * y + l23 * z
        Z[k] = l30 * t + l31 * x + l32 * y + l33 * z


# Non-linear stages work in the affine coordinate of modulus <= 1: the point is the pair
# (q, 1) ("upper", the zenith's hemisphere, |z| <= |w|) or (1, q) (the nadir's), so nothing
# overflows and 0 and infinity are ordinary. They normalise T to 1 and multiply the running
# magnification: G <- (G / T) * (the stage's own magnification).
@njit(inline="always", **_H)
def _affine(t, x, y, z):
    """``(sign, Re q, Im q)`` of the null vector ``(t, x, y, z)`` (pair ``(z, w)`` with
    ``z w* = -(x + i y) / 2``, ``|w|^2 - |z|^2 = z``): ``sign = 1`` for ``(q, 1)``,
    ``-1`` for ``(1, q)``. Branch-free (vectorisable)."""
    sg = 1.0 if z >= 0.0 else -1.0
    s = -1.0 / (t + abs(z))
    return sg, x * s, sg * (y * s)


@njit(inline="always", **_H)
def _put_pair(sg, qr, qi, T, X, Y, Z, k):
    """Store the point ``(q, 1)`` (``sg = 1``) or ``(1, q)`` (``sg = -1``) as a null
    vector with ``T = 1``."""
    r2 = qr * qr + qi * qi
    inv = 1.0 / (1.0 + r2)
    T[k] = 1.0
    X[k] = -2.0 * qr * inv
    Y[k] = -2.0 * sg * qi * inv
    Z[k] = sg * (1.0 - r2) * inv


@njit(inline="always", **_H)
def _power_put(sg, am, t, ra, r2, br, bi, T, X, Y, Z, G, k):
    """Store the point ``(b, 1)`` (``sg = 1``) or ``(1, b)`` (``b = q^|m|``) as
    :func:`_put_pair` does, and ``G <- G / t * |m| |a| (1 + |q|^2) / (1 + |b|^2)``
    (``ra = |a|``, ``a = q^(|m| - 1)``, ``r2 = |q|^2``): one division for both."""
    b2 = br * br + bi * bi
    dd = 1.0 / ((1.0 + b2) * t)
    inv = t * dd
    G[k] = G[k] * (am * ra * (1.0 + r2) * dd)
    T[k] = 1.0
    X[k] = -2.0 * br * inv
    Y[k] = -2.0 * sg * bi * inv
    Z[k] = sg * (1.0 - b2) * inv


@njit(**_V)
def _stage_power(p, T, X, Y, Z, G, valid, n):
    """``(z, w) -> (z^m, w^m)`` (``m = p[POWER_M]``, a non-zero integer; ``(w^|m|, z^|m|)`` if
    ``m < 0``); magnification ``|m| |q|^(|m|-1) (1 + |q|^2) / (1 + |q|^(2|m|))``.

    ``|m| = 2, 3`` have their own straight-line loops (vectorised by LLVM)."""
    m = int(p[POWER_M])
    am = abs(m)
    flip = 1.0 if m > 0 else -1.0
    if am == 2:
        for k in range(n):
            t = T[k]
            sg, qr, qi = _affine(t, X[k], Y[k], Z[k])
            r2 = qr * qr + qi * qi
            br = qr * qr - qi * qi
            bi = 2.0 * qr * qi
            _power_put(sg * flip, 2.0, t, math.sqrt(r2), r2, br, bi, T, X, Y, Z, G, k)
    elif am == 3:
        for k in range(n):
            t = T[k]
            sg, qr, qi = _affine(t, X[k], Y[k], Z[k])
            r2 = qr * qr + qi * qi
            ar = qr * qr - qi * qi
            ai = 2.0 * qr * qi
            br = ar * qr - ai * qi
            bi = ar * qi + ai * qr
            _power_put(sg * flip, 3.0, t, r2, r2, br, bi, T, X, Y, Z, G, k)
    else:
        for k in range(n):
            t = T[k]
            sg, qr, qi = _affine(t, X[k], Y[k], Z[k])
            ar = 1.0  # q^(|m| - 1)
            ai = 0.0
            for _ in range(am - 1):
                nr = ar * qr - ai * qi
                ai = ar * qi + ai * qr
                ar = nr
            br = ar * qr - ai * qi  # q^|m|
            bi = ar * qi + ai * qr
            ra = math.sqrt(ar * ar + ai * ai)
            _power_put(sg * flip, float(am), t, ra, qr * qr + qi * qi, br, bi, T, X, Y, Z, G, k)


@njit(**_V)
def _stage_exp(p, T, X, Y, Z, G, valid, n):
    """The exp variant ``S(z) = -exp(-lam (1 + z) / (1 - z))`` (``lam = p[EXP_LAM]``).

    ``u = (1 + z)/(1 - z) = (Z - i Y) / (R + X)`` (``R = |(X, Y, Z)|``, which
    is ``T`` up to rounding; near the singularity ``z = 1``, ``X = -R``, the
    denominator is computed as ``(Y^2 + Z^2) / (R - X)``, without
    cancellation); within ``|w - z|^2 = (R + X)/R < near = 2 sin^2(r / 2)``
    the point goes to its limit (the zenith if ``Z >= 0``, else the nadir)
    with magnification ``cap``; elsewhere the magnification is
    ``lam / (|w - z|^2 cosh(lam Re u))``.

    One branch-free loop (vectorised: :mod:`._fastmath` instead of libm, selects
    instead of ``continue``), with ``T`` for ``R`` (no square root; the two
    differ by the vector's rounding, which ``(Y^2 + Z^2) / (T - X)`` does not
    amplify either; the magnification's ``R / T`` is then 1). The few points with
    ``|lam Im u| > SINCOS_MAX`` (next to the singularity) are left as they are,
    marked with a negative ``T`` (``T`` is positive on the sphere's null cone),
    and redone after the loop with ``math.sin``/``math.cos`` (:func:`_exp_point`).
    """
    lam = p[EXP_LAM]
    near = p[EXP_NEAR]
    cap = p[EXP_CAP]
    nbig = 0
    for k in range(n):
        t = T[k]
        x = X[k]
        y = Y[k]
        z = Z[k]
        g = G[k]
        # 1 / d with d = T + X, for X < 0 as (Y^2 + Z^2) / (T - X): one division
        neg = x < 0.0
        inv_d = (t - x if neg else 1.0) / (y * y + z * z if neg else t + x)
        inside = near * t * inv_d > 1.0  # d < near T (d = 0: inv_d = inf)
        phi = -lam * y * inv_d  # lam Im u (u = (Z - i Y) / d)
        sr = -lam * z * inv_d  # -lam Re u
        e = fexp(-abs(sr))
        sn, c = fsincos(phi)
        # sr <= 0: (-e exp(-i phi), 1); else (-exp(-i phi), e) = (1, -e exp(i phi)); the
        # pair's |q|^2 is e^2 (|exp(i phi)| = 1 to rounding), so 1 / (1 + |q|^2) is also
        # the 1 / cosh(lam Re u) = 2 e / (1 + e^2) of the magnification
        w = 1.0 / (1.0 + e * e)
        gs = g * (lam * inv_d) * (2.0 * e * w)
        zs = (1.0 - e * e) * w
        big = (abs(phi) > SINCOS_MAX) and not inside
        nbig += big
        T[k] = -t if big else 1.0
        G[k] = g if big else (cap if inside else gs)
        X[k] = x if big else (0.0 if inside else 2.0 * e * c * w)
        Y[k] = y if big else (0.0 if inside else -2.0 * e * sn * w)
        zl = 1.0 if z >= 0.0 else -1.0
        Z[k] = z if big else (zl if inside else (zs if sr <= 0.0 else -zs))
    if nbig > 0:
        for k in range(n):
            if T[k] < 0.0:
                _exp_point(lam, T, X, Y, Z, G, k)


@njit(**_H)
def _exp_point(lam, T, X, Y, Z, G, k):
    """Point ``k`` of :func:`_stage_exp` (marked ``T[k] = -t``) with libm's sin/cos."""
    t = -T[k]
    x = X[k]
    y = Y[k]
    z = Z[k]
    r = math.sqrt(x * x + y * y + z * z)
    d = (y * y + z * z) / (r - x) if x < 0.0 else r + x
    ur = z / d
    phi = lam * (-y / d)
    sr = -lam * ur
    e = math.exp(-abs(sr))
    G[k] = G[k] / t * (lam * r / d) * (2.0 * e / (1.0 + e * e))
    sg = 1.0 if sr <= 0.0 else -1.0
    _put_pair(sg, -e * math.cos(phi), sg * (e * math.sin(phi)), T, X, Y, Z, k)


@intrinsic
def _stack_block(typingctx, rows, cols):
    """A C-contiguous ``(rows, cols)`` float64 array on the caller's stack (literal sizes).

    Scratch without a heap allocation (nor reference counting: no meminfo), for
    functions compiled with ``_nrt=False``; valid until the caller returns.
    """
    if not (isinstance(rows, types.IntegerLiteral) and isinstance(cols, types.IntegerLiteral)):
        return None
    nr = rows.literal_value
    nc = cols.literal_value
    arrty = types.Array(types.float64, 2, "C")

    def codegen(context, builder, signature, args):
        data = cgutils.alloca_once(builder, ir.ArrayType(ir.DoubleType(), nr * nc))
        data.align = 64
        ary = context.make_array(arrty)(context, builder)
        intp = context.get_value_type(types.intp)
        populate_array(
            ary,
            data=builder.bitcast(data, ary.data.type),
            shape=[ir.Constant(intp, nr), ir.Constant(intp, nc)],
            strides=[ir.Constant(intp, 8 * nc), ir.Constant(intp, 8)],
            itemsize=ir.Constant(intp, 8),
            meminfo=None,
        )
        return ary._getvalue()

    return arrty(rows, cols), codegen


# rows of the rational stage's scratch block (on the stack, see _stack_block; indexed
# [row, k]: row views would each cost an atomic reference-count update)
_R_SG = 0  # chart: 1 for (q, 1), -1 for (1, q)
_R_Q = 1  # q (re, im)
_R_P = 3  # P(s) (re, im), then P'(s)
_R_Q2 = 7  # Q(s), then Q'(s)
_R_S = 11  # s = q^g (g > 1; for g = 1, s is q itself)
_RB = 64  # points a block


@njit(**_H)
def _rational_plan(p):
    """How :func:`_stage_rational` evaluates ``N`` and ``D``: a symmetric map in ``s = q^g``.

    A map with ``N(q) = q^a P(q^g)`` and ``D(q) = q^b Q(q^g)``, ``a + b = 1``, in
    both charts (Lattès maps: ``g = 2`` for the square lattice, 3 for the
    hexagonal one) is evaluated with ``P`` and ``Q``, ``g`` times fewer Horner
    steps. Any other map has the plan ``g = 1``, ``P = N``, ``Q = D``, ``a = b = 0``.

    Returns ``(g, K, jn0, jn1, jd0, jd1, padn, padd, au, bu, al, bl)``: ``K`` the
    degree of ``P`` and ``Q`` (the lower padded with ``padn``/``padd`` leading
    zeros); the non-zero coefficients of ``N`` are at ``jn0, jn0 + g, ..., jn1``
    in its list (highest degree first), those of ``D`` at ``jd0 .. jd1``;
    ``(a, b)`` is ``(au, bu)`` in the chart ``(q, 1)`` and ``(al, bl)`` in ``(1, q)``.
    Costs a few dozen integer operations (once per call, i.e. per chunk).
    """
    d = int(p[RATIONAL_DEGREE])
    on = RATIONAL_COEFFICIENTS
    od = RATIONAL_COEFFICIENTS + 2 * (d + 1)
    generic = (1, d, 0, d, 0, d, 0, 0, 0, 0, 0, 0)
    if d > 62:
        return generic
    # bit j: coefficient j (highest degree first) is non-zero
    mn = 0
    md = 0
    for j in range(d + 1):
        mn |= (1 << j) if (p[on + 2 * j] != 0.0) or (p[on + 2 * j + 1] != 0.0) else 0
        md |= (1 << j) if (p[od + 2 * j] != 0.0) or (p[od + 2 * j + 1] != 0.0) else 0
    if mn == 0 or md == 0:
        return generic
    jn0 = 0
    while not (mn >> jn0) & 1:
        jn0 += 1
    jd0 = 0
    while not (md >> jd0) & 1:
        jd0 += 1
    jn1 = d
    while not (mn >> jn1) & 1:
        jn1 -= 1
    jd1 = d
    while not (md >> jd1) & 1:
        jd1 -= 1
    # lowest powers of q: d - (last index) in the chart (q, 1), the first index in (1, q)
    au = d - jn1
    bu = d - jd1
    al = jn0
    bl = jd0
    if au + bu != 1 or al + bl != 1:
        return generic
    # the largest g whose multiples hold every index (counted from each list's first)
    u = (mn >> jn0) | (md >> jd0)
    g = d
    while g > 1:
        m = 0
        for i in range(0, d + 1, g):
            m |= 1 << i
        if u & ~m == 0:
            break
        g -= 1
    if g < 2:
        return generic
    kn = (jn1 - jn0) // g
    kd = (jd1 - jd0) // g
    kk = max(kn, kd)
    return g, kk, jn0, jn1, jd0, jd1, kk - kn, kk - kd, au, bu, al, bl


@njit(inline="always", **_H)
def _coef(p, base, j, pad, i0, step):
    """``(re, im)`` of coefficient ``j`` (highest degree first, after ``pad`` leading
    zeros) of a polynomial in ``s`` whose coefficients sit at list indices ``i0, i0 +
    step, ...`` of the complex list at ``p[base:]``."""
    z = j < pad
    i = base + 2 * (i0 + step * (0 if z else j - pad))  # in bounds for the padding too
    return (0.0 if z else p[i]), (0.0 if z else p[i + 1])


@njit(inline="always", **_H)
def _rational_block(p, plan, T, X, Y, Z, G, m, buf):
    """The first ``m <= buf.shape[1]`` points of :func:`_stage_rational`."""
    on = RATIONAL_COEFFICIENTS
    od = RATIONAL_COEFFICIENTS + 2 * (int(p[RATIONAL_DEGREE]) + 1)
    g, kk, jn0, jn1, jd0, jd1, pn, pd, au, bu, al, bl = plan
    rs = _R_S if g > 1 else _R_Q
    for k in range(m):
        sg, qr, qi = _affine(T[k], X[k], Y[k], Z[k])
        buf[_R_SG, k] = sg
        buf[_R_Q, k] = qr
        buf[_R_Q + 1, k] = qi
    if g > 1:
        for k in range(m):
            buf[_R_S, k] = buf[_R_Q, k]
            buf[_R_S + 1, k] = buf[_R_Q + 1, k]
        for _ in range(g - 1):
            for k in range(m):
                qr = buf[_R_Q, k]
                qi = buf[_R_Q + 1, k]
                sr = buf[_R_S, k]
                si = buf[_R_S + 1, k]
                buf[_R_S, k] = sr * qr - si * qi
                buf[_R_S + 1, k] = sr * qi + si * qr
    # Horner in s, the derivatives alongside. Leading coefficients (chart (q, 1): a*;
    # (1, q): b*, the lists read backwards); step 0 is folded into step 1.
    an0r, an0i = _coef(p, on, 0, pn, jn0, g)
    bn0r, bn0i = _coef(p, on, 0, pn, jn1, -g)
    ad0r, ad0i = _coef(p, od, 0, pd, jd0, g)
    bd0r, bd0i = _coef(p, od, 0, pd, jd1, -g)
    if kk == 0:
        for k in range(m):
            up = buf[_R_SG, k] > 0.0
            buf[_R_P, k] = an0r if up else bn0r
            buf[_R_P + 1, k] = an0i if up else bn0i
            buf[_R_P + 2, k] = 0.0
            buf[_R_P + 3, k] = 0.0
            buf[_R_Q2, k] = ad0r if up else bd0r
            buf[_R_Q2 + 1, k] = ad0i if up else bd0i
            buf[_R_Q2 + 2, k] = 0.0
            buf[_R_Q2 + 3, k] = 0.0
    for j in range(1, kk + 1):
        anr, ani = _coef(p, on, j, pn, jn0, g)
        bnr, bni = _coef(p, on, j, pn, jn1, -g)
        adr, adi = _coef(p, od, j, pd, jd0, g)
        bdr, bdi = _coef(p, od, j, pd, jd1, -g)
        if j == 1:
            # from the leading coefficients: P = c0 s + c1, P' = c0
            for k in range(m):
                up = buf[_R_SG, k] > 0.0
                tr = buf[rs, k]
                ti = buf[rs + 1, k]
                vr = an0r if up else bn0r
                vi = an0i if up else bn0i
                buf[_R_P, k] = (anr if up else bnr) + vr * tr - vi * ti
                buf[_R_P + 1, k] = (ani if up else bni) + vr * ti + vi * tr
                buf[_R_P + 2, k] = vr
                buf[_R_P + 3, k] = vi
                vr = ad0r if up else bd0r
                vi = ad0i if up else bd0i
                buf[_R_Q2, k] = (adr if up else bdr) + vr * tr - vi * ti
                buf[_R_Q2 + 1, k] = (adi if up else bdi) + vr * ti + vi * tr
                buf[_R_Q2 + 2, k] = vr
                buf[_R_Q2 + 3, k] = vi
            continue
        # complex multiply-adds written c + a b - a' b': two FMAs a part (no reassociation)
        for k in range(m):
            up = buf[_R_SG, k] > 0.0
            tr = buf[rs, k]
            ti = buf[rs + 1, k]
            vr = buf[_R_P, k]
            vi = buf[_R_P + 1, k]
            dr = buf[_R_P + 2, k]
            di = buf[_R_P + 3, k]
            buf[_R_P, k] = (anr if up else bnr) + vr * tr - vi * ti
            buf[_R_P + 1, k] = (ani if up else bni) + vr * ti + vi * tr
            buf[_R_P + 2, k] = vr + dr * tr - di * ti
            buf[_R_P + 3, k] = vi + dr * ti + di * tr
            vr = buf[_R_Q2, k]
            vi = buf[_R_Q2 + 1, k]
            dr = buf[_R_Q2 + 2, k]
            di = buf[_R_Q2 + 3, k]
            buf[_R_Q2, k] = (adr if up else bdr) + vr * tr - vi * ti
            buf[_R_Q2 + 1, k] = (adi if up else bdi) + vr * ti + vi * tr
            buf[_R_Q2 + 2, k] = vr + dr * tr - di * ti
            buf[_R_Q2 + 3, k] = vi + dr * ti + di * tr
    gf = float(g)
    lac = g > 1
    for k in range(m):
        up = buf[_R_SG, k] > 0.0
        a = au if up else al
        b = bu if up else bl
        qr = buf[_R_Q, k]
        qi = buf[_R_Q + 1, k]
        pr = buf[_R_P, k]
        pi = buf[_R_P + 1, k]
        dpr = buf[_R_P + 2, k]
        dpi = buf[_R_P + 3, k]
        cr = buf[_R_Q2, k]
        ci = buf[_R_Q2 + 1, k]
        dcr = buf[_R_Q2 + 2, k]
        dci = buf[_R_Q2 + 3, k]
        # N = q^a P, D = q^b Q (a, b in {0, 1})
        nr = pr * qr - pi * qi if a > 0 else pr
        ni = pr * qi + pi * qr if a > 0 else pi
        dr = cr * qr - ci * qi if b > 0 else cr
        di = cr * qi + ci * qr if b > 0 else ci
        # N' D - N D' (for g = 1: a = b = 0, P' Q - P Q' itself); R = q^(a + b + g - 1) = s
        wr = (dpr * cr - dpi * ci) - (pr * dcr - pi * dci)
        wi = (dpr * ci + dpi * cr) - (pr * dci + pi * dcr)
        rr = buf[_R_S, k] if lac else 1.0
        ri = buf[_R_S + 1, k] if lac else 0.0
        ab = float(a - b)
        jr = ab * (pr * cr - pi * ci) + gf * (rr * wr - ri * wi)
        ji = ab * (pr * ci + pi * cr) + gf * (rr * wi + ri * wr)
        a2 = nr * nr + ni * ni
        b2 = dr * dr + di * di
        tt = a2 + b2
        ok = tt > 0.0
        # one division for 1 / |N|^2 + |D|^2 and the running 1 / T
        t = T[k]
        rinv = 1.0 / (tt * t) if ok else 0.0
        inv = rinv * t
        r2 = qr * qr + qi * qi
        # N = D = 0 (a common root: undefined): the zenith, as normalize_cp1
        G[k] = G[k] * (math.sqrt(jr * jr + ji * ji) * (1.0 + r2) * rinv)
        T[k] = 1.0
        X[k] = -2.0 * (nr * dr + ni * di) * inv  # -2 Re(N conj D)
        Y[k] = -2.0 * (ni * dr - nr * di) * inv  # -2 Im(N conj D)
        Z[k] = (b2 - a2) * inv if ok else 1.0


@njit(_nrt=False, **_V)
def _stage_rational(p, T, X, Y, Z, G, valid, n):
    """``(z, w) -> (N(z, w), D(z, w))``, homogeneous Horner in the affine coordinate ``q``.

    ``p[RATIONAL_DEGREE] = d``, then (from ``RATIONAL_COEFFICIENTS``) the ``d + 1``
    coefficients of ``N`` and of ``D`` (highest degree first, zero-padded to degree
    ``d``) as ``(re, im)`` pairs. For
    ``(1, q)`` the coefficient lists are read backwards. Magnification
    ``|N' D - N D'| (1 + |q|^2) / (|N|^2 + |D|^2)``.

    ``N = q^a P(s)``, ``D = q^b Q(s)`` with ``s = q^g`` (see
    :func:`_rational_plan`; ``g = 1`` for a general map) and ``N' D - N D' = (a -
    b) P Q + g q^(a + b + g - 1) (P' Q - P Q')``. The Horner steps (``P``,
    ``Q`` and their derivatives) run over all points at once, coefficients
    picked per point by a select, so that each step is a vectorisable loop; the
    state lives in a scratch block on the stack, ``_RB`` points at a time.
    """
    plan = _rational_plan(p)
    buf = _stack_block(13, _RB)
    for k0 in range(0, n, _RB):
        # slices, not offset indices (T[k0 + k]): those would keep numba's negative-index
        # wrap-around, which stops LLVM from vectorising (no reference counting here)
        k1 = min(k0 + _RB, n)
        _rational_block(p, plan, T[k0:k1], X[k0:k1], Y[k0:k1], Z[k0:k1], G[k0:k1], k1 - k0, buf)


@njit(inline="always", **_H)
def _droste_block(p, T, X, Y, Z, G, n, buf):
    """The first ``n <= buf.shape[1]`` points of :func:`_stage_droste`.

    Two branch-free loops, vectorised (``._fastmath`` instead of libm, selects
    instead of branches), and between them a scalar one that reads the rho
    samples (vector gathers are slow on some machines; skipped when all the
    samples are equal, a round hole). The first loop leaves ``(Re Ls, theta_s,
    rho table position, 2 |beta| T (inf at the fixed points), rxy (T there),
    T)`` in ``buf``; the last finishes with one division a point.
    """
    m = int(p[DROSTE_M])
    ell = p[DROSTE_ELL]
    br = p[DROSTE_BETA_RE]
    bi = p[DROSTE_BETA_IM]
    l0 = p[DROSTE_PIVOT]
    cr = p[DROSTE_C_RE]
    ci = p[DROSTE_C_IM]
    cap = p[DROSTE_CAP]
    ab = p[DROSTE_BETA_ABS]
    tiny = 1e-300
    mf = float(m)
    inv_ell = 1.0 / ell
    rho0 = p[DROSTE_RHO]
    round_hole = True
    for j in range(1, m):
        round_hole &= p[DROSTE_RHO + j] == rho0
    for k in range(n):
        t = T[k]
        x = X[k]
        y = Y[k]
        z = Z[k]
        rxy = math.sqrt(x * x + y * y)
        # |zeta| = |a| / |b| = sqrt((R - z) / (R + z)) (unit pair: |a|^2 = (R - z) / 2R)
        # is rxy / (R + |z|) <= 1 or its inverse (no cancellation; T for R = |(x, y, z)|
        # as in _stage_exp), and theta = arg(a conj b) = atan2(-y, -x) needs min / max of
        # |x|, |y|: one division for both ratios. max is clamped at 1e-300, so that the
        # product does not underflow (the angle is then wrong, but only within 1e-300 of
        # a fixed point, where it has no limit)
        ax = abs(x)
        ay = abs(y)
        mx = max(max(ax, ay), tiny)
        rz = t + abs(z)
        dd = 1.0 / (rz * mx)
        # clamped at 1e-300 (the fixed points) as the reference
        lq = flog(max(rxy * mx * dd, tiny))
        u = lq if z >= 0.0 else -lq
        th = _atan2_ratio(min(ax, ay) * rz * dd, -y, -x)
        ur = u - l0
        li = br * th + bi * ur + ci
        # theta into [-pi, pi) (floor, not fmod: cheaper, same to rounding)
        ths = li - TWO_PI * np.floor((li + PI) * INV_TWO_PI)
        buf[0, k] = br * ur - bi * th + cr
        buf[1, k] = ths
        buf[2, k] = rho0 if round_hole else (ths + PI) * (mf * INV_TWO_PI)
        # the magnification |beta| (e / (1 + e^2)) 2R / rxy: cap at the fixed points
        # (rxy / 2R <= 1e-150), marked by an infinite numerator
        fixed = not (rxy > 2e-150 * t)
        buf[3, k] = math.inf if fixed else 2.0 * ab * t
        buf[4, k] = t if fixed else rxy
        buf[5, k] = t
    if not round_hole:
        for k in range(n):
            xi = buf[2, k]
            i0f = min(max(np.floor(xi), 0.0), mf - 1.0)
            f = xi - i0f
            i0 = int(i0f)
            i1 = i0 + 1 if i0 + 1 < m else 0
            buf[2, k] = p[DROSTE_RHO + i0] * (1.0 - f) + p[DROSTE_RHO + i1] * f
    for k in range(n):
        lr = buf[0, k]
        ths = buf[1, k]
        rho = buf[2, k]
        # rounding can leave us a hair outside the strip: clamped (reciprocal of ell:
        # the same to rounding)
        us = lr - np.floor((lr - rho) * inv_ell) * ell
        us = min(max(us, rho), rho + ell)
        e = fexp(-abs(us))
        sn, c = fsincos(ths)
        # one division: 1 / ((1 + e^2) t rxy) gives w = 1 / (1 + e^2) (the pair below
        # has |q|^2 = e^2, |exp(i ths)| = 1 to rounding), the magnification over t, and
        # the cap over t; the cap where the magnification is larger or NaN
        e2 = e * e
        rq = buf[4, k]
        t = buf[5, k]
        h = (1.0 + e2) * rq
        inv = 1.0 / (h * t)
        w = t * rq * inv
        sct = e * buf[3, k] * inv
        capt = cap * h * inv
        G[k] = G[k] * (sct if sct < capt else capt)
        # (zeta_s, 1) (us <= 0) or (1, 1 / zeta_s): _put_pair with that |q|^2
        zs = (1.0 - e2) * w
        T[k] = 1.0
        X[k] = -2.0 * e * c * w
        Y[k] = -2.0 * e * sn * w
        Z[k] = zs if us <= 0.0 else -zs


@njit(_nrt=False, **_V)
def _stage_droste(p, T, X, Y, Z, G, valid, n):
    """A straight or twisted Droste map in its own chart (0 and infinity the fixed points).

    ``p``: the fields of the ``droste`` stage (:mod:`.stages`: ``m, ell, Re beta, Im beta,
    L0, Re C, Im C, cap, |beta|``, then ``rho_0 .. rho_(m-1)``):
    ``L = log zeta``, ``Ls = beta (L - L0) + C``, then ``Ls`` is reduced into the
    strip ``rho(theta) <= Re < rho(theta) + ell``, ``|Im| <= pi`` (``rho`` the
    periodic linear interpolation of the ``m`` samples at ``theta = -pi + 2 pi
    j / m``) and the point is ``exp(Ls)``. Magnification ``|beta| |zeta_s| (1 +
    |zeta|^2) / (|zeta| (1 + |zeta_s|^2))``, ``cap`` at the fixed points.

    ``_RB`` points at a time through a scratch block on the stack
    (:func:`_droste_block`).
    """
    buf = _stack_block(6, _RB)
    for k0 in range(0, n, _RB):
        # slices, not offset indices (see _stage_rational)
        k1 = min(k0 + _RB, n)
        _droste_block(p, T[k0:k1], X[k0:k1], Y[k0:k1], Z[k0:k1], G[k0:k1], k1 - k0, buf)


@njit(_nrt=False, **_V)
def _stage_schottky(p, T, X, Y, Z, G, valid, n):
    """The Schottky reduction (:class:`spherewarp.maps.Schottky`), at most ``depth`` moves.

    ``p``: the fields of the ``schottky`` stage (:mod:`.stages`): ``count`` generators,
    ``depth``, then ``2 count`` moves of ``SCHOTTKY_MOVES_SIZE`` floats: the open disk
    ``n . v > cos_r`` (``v`` the unit point) and the Lorentz matrix applied there (move
    ``2 i``: ``D_x`` and ``X``; ``2 i + 1``: ``D_X`` and ``X^-1``). While the point lies in
    the disk of a move, that move is applied (the first in order; never the one undoing
    the last move, so a point on a boundary does not bounce); a point still in a disk
    after ``depth`` moves is invalid. The disk test is ``n . (X, Y, Z) > cos_r T`` on the
    homogeneous vector; a move normalises ``T`` to 1 and divides ``G`` by the ``T`` it
    gave (the magnification stays ``G / T``). A point of the fundamental region is left
    as it is. Scalar: the number of moves differs from point to point.
    """
    nm = 2 * int(p[SCHOTTKY_COUNT])
    depth = int(p[SCHOTTKY_DEPTH])
    for k in range(n):
        t = T[k]
        x = X[k]
        y = Y[k]
        z = Z[k]
        g = G[k]
        last = -1
        free = False
        moved = False
        for it in range(depth + 1):
            move = -1
            for j in range(nm):
                b = SCHOTTKY_MOVES + j * SCHOTTKY_MOVES_SIZE
                d = p[b + SCHOTTKY_MOVES_NX] * x + p[b + SCHOTTKY_MOVES_NX + 1] * y
                d += p[b + SCHOTTKY_MOVES_NX + 2] * z
                if j != (last ^ 1) and d > p[b + SCHOTTKY_MOVES_COS_R] * t:
                    move = j
                    break
            if move < 0:
                free = True
                break
            if it == depth:
                break
            o = SCHOTTKY_MOVES + move * SCHOTTKY_MOVES_SIZE + SCHOTTKY_MOVES_L00
            t2 = p[o] * t + p[o + 1] * x + p[o + 2] * y + p[o + 3] * z
            x2 = p[o + 4] * t + p[o + 5] * x + p[o + 6] * y + p[o + 7] * z
            y2 = p[o + 8] * t + p[o + 9] * x + p[o + 10] * y + p[o + 11] * z
            z2 = p[o + 12] * t + p[o + 13] * x + p[o + 14] * y + p[o + 15] * z
            inv = 1.0 / t2
            g = g * inv
            t = 1.0
            x = x2 * inv
            y = y2 * inv
            z = z2 * inv
            last = move
            moved = True
        if moved:
            T[k] = t
            X[k] = x
            Y[k] = y
            Z[k] = z
            G[k] = g
        if not free:
            valid[k] = 0


@njit(_nrt=False, **_H)
def _mask_label(p, lab0, w, h, t, x, y, z):
    """The mask's label at the homogeneous point ``(t, x, y, z)``: that of the pixel it
    falls in (as :meth:`spherewarp.maps.schottky.MaskRegions.label`)."""
    inv = 1.0 / t
    x = x * inv
    y = y * inv
    z = z * inv
    lon = atan2_poly(y, x)
    lat = atan2_poly(z, math.sqrt(x * x + y * y))
    ix = int(math.floor((lon + PI) * (w * INV_TWO_PI))) % w
    iy = int(math.floor((HALF_PI - lat) * (h / PI)))
    iy = min(max(iy, 0), h - 1)
    return int(p[lab0 + iy * w + ix])


@njit(_nrt=False, **_H)
def _stage_schottky_mask(p, T, X, Y, Z, G, valid, n):
    """The Schottky reduction with the exact disks of a mask (``schottky_mask`` stage).

    As :func:`_stage_schottky`, with the disk tests of
    :meth:`spherewarp.maps.Schottky.with_mask_regions`: move ``2 i`` (``D_x``) when the
    point's mask label is ``i``, then ``X``; move ``2 i + 1`` (``D_X = X(C - D_x)``) when
    the label of ``X^-1`` of the point is not ``i``, which is then the new point. The
    matrices of ``X`` and ``X^-1`` (16 floats each) start at ``SCHOTTKY_MASK_DATA``,
    the labels (row-major) follow them.
    """
    nm = 2 * int(p[SCHOTTKY_MASK_COUNT])
    depth = int(p[SCHOTTKY_MASK_DEPTH])
    w = int(p[SCHOTTKY_MASK_WIDTH])
    h = int(p[SCHOTTKY_MASK_HEIGHT])
    lab0 = SCHOTTKY_MASK_DATA + 16 * nm
    for k in range(n):
        t = T[k]
        x = X[k]
        y = Y[k]
        z = Z[k]
        g = G[k]
        last = -1
        free = False
        moved = False
        for it in range(depth + 1):
            move = -1
            t2 = t
            x2 = x
            y2 = y
            z2 = z
            here = _mask_label(p, lab0, w, h, t, x, y, z)
            for j in range(nm):
                if j == (last ^ 1):
                    continue
                i = j >> 1
                if (j & 1) == 0 and here != i:
                    continue
                o = SCHOTTKY_MASK_DATA + 16 * j
                t2 = p[o] * t + p[o + 1] * x + p[o + 2] * y + p[o + 3] * z
                x2 = p[o + 4] * t + p[o + 5] * x + p[o + 6] * y + p[o + 7] * z
                y2 = p[o + 8] * t + p[o + 9] * x + p[o + 10] * y + p[o + 11] * z
                z2 = p[o + 12] * t + p[o + 13] * x + p[o + 14] * y + p[o + 15] * z
                if (j & 1) == 0 or _mask_label(p, lab0, w, h, t2, x2, y2, z2) != i:
                    move = j
                    break
            if move < 0:
                free = True
                break
            if it == depth:
                break
            inv = 1.0 / t2
            g = g * inv
            t = 1.0
            x = x2 * inv
            y = y2 * inv
            z = z2 * inv
            last = move
            moved = True
        if moved:
            T[k] = t
            X[k] = x
            Y[k] = y
            Z[k] = z
            G[k] = g
        if not free:
            valid[k] = 0


@njit(_nrt=False, **_H)
def run_stages(codes, params, T, X, Y, Z, G, valid, n):
    """Apply the stages of a map, in order, to the first ``n`` points.

    Compiled without reference counting (``_nrt=False``: it allocates nothing): the
    stages are inlined here, and numba's atomic reference-count updates of the
    arrays passed to them cost about 50 ns a call, one call a chunk of 64 points.
    """
    for s in range(codes.shape[0]):
        code = codes[s]
        if code == STAGE_MOBIUS:
            _stage_lorentz(params[s], T, X, Y, Z, n)
        elif code == STAGE_POWER:
            _stage_power(params[s], T, X, Y, Z, G, valid, n)
        elif code == STAGE_EXP:
            _stage_exp(params[s], T, X, Y, Z, G, valid, n)
        elif code == STAGE_RATIONAL:
            _stage_rational(params[s], T, X, Y, Z, G, valid, n)
        elif code == STAGE_DROSTE:
            _stage_droste(params[s], T, X, Y, Z, G, valid, n)
        elif code == STAGE_SCHOTTKY:
            _stage_schottky(params[s], T, X, Y, Z, G, valid, n)
        elif code == STAGE_SCHOTTKY_MASK:
            _stage_schottky_mask(params[s], T, X, Y, Z, G, valid, n)
        # New kinds: elif code == STAGE_<NAME>: _stage_<name>(params[s], T, X, Y, Z, G, valid, n)


@njit(**_V)
def to_source(X, Y, Z, n, kx, ky, u, v):
    """Tap-space source coordinates ``u = x - 1/2``, ``v = y - 1/2`` of the points."""
    for k in range(n):
        x = X[k]
        y = Y[k]
        z = Z[k]
        lon = atan2_poly(y, x)
        lat = atan2_poly(z, math.sqrt(x * x + y * y))
        u[k] = (lon + PI) * kx - 0.5
        v[k] = (HALF_PI - lat) * ky - 0.5


@njit(**_H)
def mobius_to_source(cl, sl, cc, cs, p, n, kx, ky, T, u, v):
    """The common case fused: one Lorentz stage, from the row's and columns' trig
    tables straight to tap-space source coordinates (and ``T``; the
    magnification is ``1 / T``)."""
    o = MOBIUS_L00  # the Lorentz matrix, row-major
    sl0 = p[o + 0] + p[o + 3] * sl
    sl1 = p[o + 4] + p[o + 7] * sl
    sl2 = p[o + 8] + p[o + 11] * sl
    sl3 = p[o + 12] + p[o + 15] * sl
    c01 = p[o + 1] * cl
    c02 = p[o + 2] * cl
    c11 = p[o + 5] * cl
    c12 = p[o + 6] * cl
    c21 = p[o + 9] * cl
    c22 = p[o + 10] * cl
    c31 = p[o + 13] * cl
    c32 = p[o + 14] * cl
    for k in range(n):
        x = cc[k]
        y = cs[k]
        T[k] = sl0 + c01 * x + c02 * y
        X = sl1 + c11 * x + c12 * y
        Y = sl2 + c21 * x + c22 * y
        Z = sl3 + c31 * x + c32 * y
        lon = atan2_poly(Y, X)
        lat = atan2_poly(Z, math.sqrt(X * X + Y * Y))
        u[k] = (lon + PI) * kx - 0.5
        v[k] = (HALF_PI - lat) * ky - 0.5


@njit(**_H)
def _edge_source(cl, sl, ecc, ecs, codes, params, mob1, kx, ky, EF, evalid):
    """Tap-space source points ``EF[5:7]`` of the two columns ``ecc, ecs`` (cos/sin of
    their longitudes) of the row at ``cl, sl`` (``EF``: ``T, X, Y, Z, G, u, v`` rows)."""
    if mob1:
        mobius_to_source(cl, sl, ecc, ecs, params[0], 2, kx, ky, EF[0], EF[5], EF[6])
        return
    _directions(cl, sl, ecc, ecs, 2, EF[0], EF[1], EF[2], EF[3], EF[4], evalid)
    run_stages(codes, params, EF[0], EF[1], EF[2], EF[3], EF[4], evalid, 2)
    to_source(EF[1], EF[2], EF[3], 2, kx, ky, EF[5], EF[6])


@njit(**_H)
def _directions(cl, sl, cc, cs, n, T, X, Y, Z, G, valid):
    for k in range(n):
        T[k] = 1.0
        X[k] = cl * cc[k]
        Y[k] = cl * cs[k]
        Z[k] = sl
        G[k] = 1.0
        valid[k] = 1


@njit(**_H)
def _counts(T, G, valid, n, cl, aa_kx, aa_ky, tol, cap, uniform, nx, ny, special):
    """Samples per output pixel (``nx x ny``) from the magnification ``G / T``."""
    nsp = 0
    for k in range(n):
        if uniform > 0:
            a = uniform
            b = uniform
        else:
            # T > 0 on the sphere's null cone, but a nearly singular Möbius matrix can
            # round it to 0 (or NaN): count such a pixel as shrunk as can be
            t = T[k]
            s = min(G[k] / t, 1e9) if t > 0.0 else 1e9
            a = math.ceil(s * aa_kx * cl - tol)
            b = math.ceil(s * aa_ky - tol)
        nsp += _set_count(a, b, cap, valid[k], nx, ny, special, k)
    return nsp


@njit(inline="always", **_H)
def _set_count(fa, fb, cap, ok, nx, ny, special, k):
    """``nx[k] x ny[k]`` samples (``fa x fb`` clamped to ``1..cap``); returns whether the
    pixel is special (several samples, or undefined)."""
    a = int(min(max(fa, 1), cap))
    b = int(min(max(fb, 1), cap))
    nx[k] = a
    ny[k] = b
    sp = (a * b > 1) or (ok == 0)
    special[k] = sp
    return sp


# -- jumps (maps with seams: Droste, the exp variant's spiral) -------------------------------------
@njit(**_H)
def _geom_row(i, ho, jc, js, n, codes, params, T, G, geo, vals, slot):
    """Pull back the ``n`` pixel centres of output row ``i`` (columns' trig tables ``jc``,
    ``js``) into slot ``slot``: unit source vectors ``geo[slot, 0:3]``, magnification
    ``geo[slot, 3]``, validity ``vals[slot]`` (``T``, ``G``: scratch)."""
    X = geo[slot, 0]
    Y = geo[slot, 1]
    Z = geo[slot, 2]
    S = geo[slot, 3]
    valid = vals[slot]
    lat = HALF_PI - PI * (i + 0.5) / ho
    cl = math.cos(lat)
    sl = math.sin(lat)
    _directions(cl, sl, jc, js, n, T, X, Y, Z, G, valid)
    run_stages(codes, params, T, X, Y, Z, G, valid, n)
    for k in range(n):
        t = T[k]
        it = 1.0 / t if t > 0.0 else 0.0  # t > 0, but a nearly singular matrix can round it
        X[k] = X[k] * it
        Y[k] = Y[k] * it
        Z[k] = Z[k] * it
        S[k] = min(G[k] * it, 1e9) if t > 0.0 else 1e9


@njit(inline="always", **_H)
def _is_jump(xa, ya, za, sa, va, xb, yb, zb, sb, vb, step, rho):
    """Whether neighbouring source points are further apart than the magnification allows
    (as :func:`spherewarp.render.antialias.jump_mask`)."""
    dx = xa - xb
    dy = ya - yb
    dz = za - zb
    d = math.sqrt(dx * dx + dy * dy + dz * dz)
    allow = 2.0 * max(sa, sb) * step + 2.0 * rho
    return (va != 0) and (vb != 0) and d > allow


@njit(**_H)
def _jump_flags(geo, vals, above, cur, below, has_above, has_below, w, cl, wo, ho, rho,
                jmin, nx, ny, special, area, J):  # fmt: skip
    """Give the pixels of the current row that sit on a jump ``jmin x jmin`` samples at
    least; returns how many pixels became special.

    ``geo[slot]`` holds ``(X, Y, Z, S)`` rows of ``w + 2`` columns (one either side of the
    chunk) and ``vals[slot]`` their validity, for the rows above, current and below.
    With ``area``, the footprint ``J`` of a pixel on a jump (meaningless there) is
    cleared: its samples are plain bilinear taps.
    """
    hstep = TWO_PI / wo * cl
    vstep = PI / ho
    gc = geo[cur]
    vc = vals[cur]
    ga = geo[above]
    va = vals[above]
    gb = geo[below]
    vb = vals[below]
    added = 0
    for k in range(w):
        j = k + 1
        jump = _is_jump(gc[0, j], gc[1, j], gc[2, j], gc[3, j], vc[j],
                        gc[0, j - 1], gc[1, j - 1], gc[2, j - 1], gc[3, j - 1], vc[j - 1],
                        hstep, rho) or \
            _is_jump(gc[0, j], gc[1, j], gc[2, j], gc[3, j], vc[j],
                     gc[0, j + 1], gc[1, j + 1], gc[2, j + 1], gc[3, j + 1], vc[j + 1],
                     hstep, rho)  # fmt: skip
        if not jump and has_above:
            jump = _is_jump(gc[0, j], gc[1, j], gc[2, j], gc[3, j], vc[j],
                            ga[0, j], ga[1, j], ga[2, j], ga[3, j], va[j], vstep, rho)  # fmt: skip
        if not jump and has_below:
            jump = _is_jump(gc[0, j], gc[1, j], gc[2, j], gc[3, j], vc[j],
                            gb[0, j], gb[1, j], gb[2, j], gb[3, j], vb[j], vstep, rho)  # fmt: skip
        if jump:
            if not special[k]:
                added += 1
            nx[k] = max(nx[k], jmin)
            ny[k] = max(ny[k], jmin)
            special[k] = 1
            if area:
                J[0, k] = 0.0
                J[1, k] = 0.0
                J[2, k] = 0.0
                J[3, k] = 0.0
    return added


# -- sampling, any dtype (float32 arithmetic, as spherewarp.render.sampling) -----------------------
@njit(**_H)
def _fold(iy, ix, h, w):
    if iy < 0:
        iy = -1 - iy
        ix += w // 2
    elif iy >= h:
        iy = 2 * h - 1 - iy
        ix += w // 2
    iy = min(max(iy, 0), h - 1)
    return iy, ix % w


@njit(**_H)
def _cubic(t):
    a = np.float32(-0.5)
    t2 = t * t
    t3 = t2 * t
    w0 = a * (t3 - 2 * t2 + t)
    w1 = (a + 2) * t3 - (a + 3) * t2 + 1
    w2 = -(a + 2) * t3 + (2 * a + 3) * t2 - a * t
    w3 = a * (t2 - t3)
    return w0, w1, w2, w3


#: fixed-point bicubic of uint8 images: fractions and weights in 1/2**CUBIC_BITS; a weighted
#: sum of 16 pixels, in 1/2**(2 * CUBIC_BITS), stays within int32 (|255 * 1.25**2 * 2**22|)
CUBIC_BITS = 11
_CUBIC_ONE = np.int32(1 << CUBIC_BITS)
_CUBIC_SCALE = np.float32(1.0 / (1 << (2 * CUBIC_BITS)))


@njit(inline="always", **_H)
def _cubic_tap(u):
    """The fixed-point bicubic tap of a tap-space coordinate.

    Parameters
    ----------
    u : float
        Tap-space coordinate (NaN or ``|u| >= 1e6`` count as 0, as :func:`taps_u8`).

    Returns
    -------
    x0 : int64
        The pixel at or before ``u`` rounded to 1/2**CUBIC_BITS (the second of the 4 taps).
    q : int32
        The rounded fraction past ``x0``, in ``[0, 2**CUBIC_BITS)``.
    """
    uk = u if abs(u) < 1e6 else 0.0
    xi = np.int64(math.floor(np.float64(uk) * np.float64(1 << CUBIC_BITS) + 0.5))
    return xi >> np.int64(CUBIC_BITS), np.int32(xi & np.int64((1 << CUBIC_BITS) - 1))


@njit(inline="always", **_H)
def _cubic_q(q):
    """Keys' cubic weights (``a = -0.5``) in 1/2**CUBIC_BITS of the fraction ``q / 2**CUBIC_BITS``.

    The outer weights are the exact ones rounded to nearest
    (``-q (1 - q)**2 / 2`` and ``-q**2 (1 - q) / 2``, in int32: at most
    ``4/27 * 2**33``); the inner two follow from the two sums Keys' weights keep,
    ``w0 + w1 + w2 + w3 = 1`` and ``-w0 + w2 + 2 w3 = q``, so that the four sum to
    exactly ``2**CUBIC_BITS`` and a linear ramp is reproduced exactly. Each is
    within 1.5 / 2**CUBIC_BITS of the exact weight; symmetric in ``q <-> 1 - q``.

    Parameters
    ----------
    q : int32
        The fraction, in ``[0, 2**CUBIC_BITS]``.

    Returns
    -------
    w0, w1, w2, w3 : int32
        The weights of the taps at ``-1, 0, 1, 2`` pixels from the first.
    """
    i32 = np.int32
    r = _CUBIC_ONE - q
    half = i32(1 << (2 * CUBIC_BITS))  # rounding term of the shift by 2 * CUBIC_BITS + 1
    sh = i32(2 * CUBIC_BITS + 1)
    w0 = -i32(i32(i32(i32(q * r) * r) + half) >> sh)
    w3 = -i32(i32(i32(i32(q * q) * r) + half) >> sh)
    w2 = i32(q + w0 - i32(2 * w3))
    w1 = i32(_CUBIC_ONE - w0 - w3 - w2)
    return w0, w1, w2, w3


@njit(**_H)
def _get(img, iy, ix, ch):
    """Pixel value of the image bundle ``img`` as float32 (see ``fast._image_bundle``)."""
    dt = img[4]
    if dt == 0:
        return np.float32(img[0][iy, ix, ch])
    if dt == 1:
        return np.float32(img[1][iy, ix, ch])
    if dt == 2:
        return img[2][iy, ix, ch]
    return np.float32(img[3][iy, ix, ch])


@njit(**_H)
def _put(dst, i, r):
    """Store element ``i`` of the flat output bundle ``dst`` (``r`` already rounded)."""
    dt = dst[4]
    if dt == 0:
        dst[0][i] = r
    elif dt == 1:
        dst[1][i] = r
    elif dt == 2:
        dst[2][i] = r
    else:
        dst[3][i] = r


@njit(**_H)
def acc_sample(img, u, v, interp, acc, j):
    """``acc[j, :] += sample of the image at tap-space (u, v)`` (float32).

    Bicubic taps of a uint8 image are in fixed point (:func:`_cubic_u8_sample`, as
    :func:`cubic_u8`); the other taps and types in float32.
    """
    h = img[5]
    w = img[6]
    c = img[7]
    if interp == BICUBIC and img[4] == 0:
        _cubic_u8_sample(img[0], h, w, c, u, v, acc, j)
        return
    if interp == NEAREST:
        iy, ix = _fold(int(math.floor(v + 0.5)), int(math.floor(u + 0.5)), h, w)
        for ch in range(c):
            acc[j, ch] += _get(img, iy, ix, ch)
        return
    x0f = math.floor(u)
    y0f = math.floor(v)
    tx = np.float32(u - x0f)
    ty = np.float32(v - y0f)
    x0 = int(x0f)
    y0 = int(y0f)
    if interp == BILINEAR:
        one = np.float32(1.0)
        for dy in range(2):
            wy = one - ty if dy == 0 else ty
            iya, ixa = _fold(y0 + dy, x0, h, w)
            iyb, ixb = _fold(y0 + dy, x0 + 1, h, w)
            for ch in range(c):
                row = (one - tx) * _get(img, iya, ixa, ch) + tx * _get(img, iyb, ixb, ch)
                acc[j, ch] += wy * row
        return
    if img[4] >= 2:  # float samples (HDR): clamped to the four nearest, no ringing
        _cubic_float_sample(img, h, w, c, x0, y0, tx, ty, acc, j)
        return
    wx0, wx1, wx2, wx3 = _cubic(tx)
    wy0, wy1, wy2, wy3 = _cubic(ty)
    for dy in range(4):
        wy = wy0 if dy == 0 else (wy1 if dy == 1 else (wy2 if dy == 2 else wy3))
        iy0, ix0 = _fold(y0 + dy - 1, x0 - 1, h, w)
        iy1, ix1 = _fold(y0 + dy - 1, x0, h, w)
        iy2, ix2 = _fold(y0 + dy - 1, x0 + 1, h, w)
        iy3, ix3 = _fold(y0 + dy - 1, x0 + 2, h, w)
        for ch in range(c):
            row = (
                wx0 * _get(img, iy0, ix0, ch)
                + wx1 * _get(img, iy1, ix1, ch)
                + wx2 * _get(img, iy2, ix2, ch)
                + wx3 * _get(img, iy3, ix3, ch)
            )
            acc[j, ch] += wy * row


@njit(**_H)
def _cubic_float_sample(img, h, w, c, x0, y0, tx, ty, acc, j):
    """``acc[j, :] +=`` the bicubic sample of a float image, clamped to the range of its
    four nearest samples (``tx, ty`` the fraction past ``x0, y0``).

    Keys' cubic overshoots an edge by up to 7% of its step on either side. An HDR image's
    steps are unbounded (a sun of 50,000 beside a sky of 1 rang to -2,269: black specks
    once tone-mapped), and no clamp to a sample range follows as for integer types; so no
    value leaves the range of the four samples around it (``sampling.sample`` does the
    same). Away from such steps the clamp changes nothing.
    """
    wx0, wx1, wx2, wx3 = _cubic(tx)
    wy0, wy1, wy2, wy3 = _cubic(ty)
    for ch in range(c):
        val = np.float32(0.0)
        lo = np.float32(np.inf)
        hi = np.float32(-np.inf)
        for dy in range(4):
            wy = wy0 if dy == 0 else (wy1 if dy == 1 else (wy2 if dy == 2 else wy3))
            iy0, ix0 = _fold(y0 + dy - 1, x0 - 1, h, w)
            iy1, ix1 = _fold(y0 + dy - 1, x0, h, w)
            iy2, ix2 = _fold(y0 + dy - 1, x0 + 1, h, w)
            iy3, ix3 = _fold(y0 + dy - 1, x0 + 2, h, w)
            a0 = _get(img, iy0, ix0, ch)
            a1 = _get(img, iy1, ix1, ch)
            a2 = _get(img, iy2, ix2, ch)
            a3 = _get(img, iy3, ix3, ch)
            row = wx0 * a0 + wx1 * a1 + wx2 * a2 + wx3 * a3
            val += wy * row
            if dy == 1 or dy == 2:
                lo = min(lo, a1, a2)
                hi = max(hi, a1, a2)
        if val < lo:  # NaN stays NaN
            val = lo
        elif val > hi:
            val = hi
        acc[j, ch] += val


@njit(**_H)
def _cubic_u8_sample(a, h, w, c, u, v, acc, j):
    """``acc[j, :] +=`` the fixed-point bicubic sample of the uint8 image ``a`` at
    tap-space ``(u, v)``.

    Weights of :func:`_cubic_q` along each axis (fractions rounded to
    1/2**CUBIC_BITS, :func:`_cubic_tap`); each row's 4 pixels times the column
    weights, then the 4 rows times the row weights, summed in int32; the sum times
    2**(-2 CUBIC_BITS) as float32. Taps fold over the poles and wrap as the float
    path's. :func:`cubic_u8` does the same operations (so the same pixels).

    Parameters
    ----------
    a : ndarray of uint8, shape (h, w, c)
        The image.
    h, w, c : int
        Its shape.
    u, v : float
        Tap-space coordinates of the sample.
    acc : ndarray of float32, shape (m, c)
        Accumulator; row ``j`` is added to.
    j : int
        The row of ``acc``.
    """
    i32 = np.int32
    x0, qx = _cubic_tap(u)
    y0, qy = _cubic_tap(v)
    wx0, wx1, wx2, wx3 = _cubic_q(qx)
    wy0, wy1, wy2, wy3 = _cubic_q(qy)
    for ch in range(c):
        s = i32(0)
        for dy in range(4):
            wy = wy0 if dy == 0 else (wy1 if dy == 1 else (wy2 if dy == 2 else wy3))
            iy0, ix0 = _fold(y0 + dy - 1, x0 - 1, h, w)
            iy1, ix1 = _fold(y0 + dy - 1, x0, h, w)
            iy2, ix2 = _fold(y0 + dy - 1, x0 + 1, h, w)
            iy3, ix3 = _fold(y0 + dy - 1, x0 + 2, h, w)
            row = i32(
                wx0 * i32(a[iy0, ix0, ch])
                + wx1 * i32(a[iy1, ix1, ch])
                + wx2 * i32(a[iy2, ix2, ch])
                + wx3 * i32(a[iy3, ix3, ch])
            )
            s = i32(s + wy * row)
        acc[j, ch] += np.float32(s) * _CUBIC_SCALE


@njit(inline="always", **_H)
def finish_pixel(acc, j, cover, count, bg, dst, q, c, co, is_int, maxval, full):
    """Write pixel ``q`` of the flat output ``dst`` (``co`` values a pixel) from ``acc[j]``.

    ``count`` samples were taken, ``cover`` of them defined; the rest are
    background. With ``co == c + 1`` the last channel is the coverage (alpha).
    The output's type is picked once (:func:`_finish_typed`): a dispatch per
    value cost more than the rest of the pixel.
    """
    dt = dst[4]
    if dt == 0:
        _finish_typed(acc, j, cover, count, bg, dst[0], q, c, co, is_int, maxval, full)
    elif dt == 1:
        _finish_typed(acc, j, cover, count, bg, dst[1], q, c, co, is_int, maxval, full)
    elif dt == 2:
        _finish_typed(acc, j, cover, count, bg, dst[2], q, c, co, is_int, maxval, full)
    else:
        _finish_typed(acc, j, cover, count, bg, dst[3], q, c, co, is_int, maxval, full)


@njit(inline="always", **_H)
def _finish_typed(acc, j, cover, count, bg, out, q, c, co, is_int, maxval, full):
    inv = np.float32(1.0) / np.float32(count)
    miss = np.float32(count - cover)
    for ch in range(c):
        r = (acc[j, ch] + miss * bg[ch]) * inv
        if is_int:
            r = min(max(np.rint(r), np.float32(0.0)), maxval)
        out[q * co + ch] = r
    if co > c:
        r = np.float32(cover) * inv * full
        if is_int:
            r = min(max(np.rint(r), np.float32(0.0)), maxval)
        out[q * co + c] = r


@njit(inline="always", **_H)
def _tent_integral(s):
    """``int_-inf^s tent``: the antiderivative of the bilinear (tent) kernel (branch-free)."""
    s = min(max(s, -1.0), 1.0)
    a = 1.0 - abs(s)
    h2 = 0.5 * a * a
    return 1.0 - h2 if s >= 0.0 else h2


@njit(inline="always", **_H)
def _fold_row(iy, h, half):
    """Input row ``iy`` folded over the poles (row ``-1 - iy``, half a turn round: the
    columns shift by ``half``), clamped: ``(row, shift)``."""
    sh = 0
    if iy < 0:
        iy = -1 - iy
        sh = half
    elif iy >= h:
        iy = 2 * h - 1 - iy
        sh = half
    return min(max(iy, 0), h - 1), sh


@njit(**_V)
def _area_weights(U, V, BX, BY, n, WS, X0, Y0):
    """Phase 1 of :func:`area_batch` (vectorised): the first tap ``X0, Y0`` and the
    weights ``WS[0:4]`` (columns), ``WS[4:8]`` (rows) of each sample: the tent
    averaged over a box of width ``b`` (at most 2 input pixels, so 4 taps a side)
    at distances ``t .. t + 3``, ``(F(t + b/2) - F(t - b/2)) / b`` with ``F`` the
    tent's antiderivative."""
    for k in range(n):
        u = U[k]
        v = V[k]
        bx = min(max(BX[k], 1e-3), 2.0)
        by = min(max(BY[k], 1e-3), 2.0)
        xf = math.floor(u) - 1.0
        yf = math.floor(v) - 1.0
        X0[k] = np.int64(xf)
        Y0[k] = np.int64(yf)
        tx = xf - u
        ty = yf - v
        hx = 0.5 * bx
        hy = 0.5 * by
        ix = 1.0 / bx
        iy = 1.0 / by
        for d in range(4):
            WS[d, k] = (_tent_integral(tx + d + hx) - _tent_integral(tx + d - hx)) * ix
            WS[4 + d, k] = (_tent_integral(ty + d + hy) - _tent_integral(ty + d - hy)) * iy


@njit(**_H)
def _area_apply(a, h, w, c, n, WS, X0, Y0, BX, BY, keep, own, acc, cover):
    """Phase 2 of :func:`area_batch` on the typed image ``a``: the 4 x 4 taps of each
    kept sample into ``acc[own[k]]``; taps fold over the poles and wrap as in
    :func:`acc_sample`."""
    half = w // 2
    for k in range(n):
        if not keep[k] or BX[k] > AREA_BOX or BY[k] > AREA_BOX:  # (wide: _area_wide)
            continue
        j = own[k]
        x0 = X0[k]
        y0 = Y0[k]
        wx0 = WS[0, k]
        wx1 = WS[1, k]
        wx2 = WS[2, k]
        wx3 = WS[3, k]
        for dy in range(4):
            wgy = WS[4 + dy, k]
            if wgy == 0.0:
                continue
            iy, sh = _fold_row(y0 + dy, h, half)
            ix0 = (x0 + sh) % w
            ix1 = ix0 + 1 if ix0 + 1 < w else 0
            ix2 = ix1 + 1 if ix1 + 1 < w else 0
            ix3 = ix2 + 1 if ix2 + 1 < w else 0
            w0 = wgy * wx0
            w1 = wgy * wx1
            w2 = wgy * wx2
            w3 = wgy * wx3
            for ch in range(c):
                acc[j, ch] += (
                    w0 * np.float32(a[iy, ix0, ch])
                    + w1 * np.float32(a[iy, ix1, ch])
                    + w2 * np.float32(a[iy, ix2, ch])
                    + w3 * np.float32(a[iy, ix3, ch])
                )
        cover[j] += 1


#: The widest box (input pixels a side) of the 4 x 4 area taps. A wider one is a wide tap
#: (:func:`_wide_weights`), exact up to :data:`AREA_BOX_MAX`: a box is the lengths of the rows
#: of the footprint's Jacobian, split along its columns into parts of at most ``AREA_SPLIT *
#: (1 + tol)`` (sqrt 2 * 1.1) input pixels, so that a turned part's box can be up to 2.2 a
#: side; the parts of footprints split into ``AUTO_MAX`` parts (the exp variant's) can be far
#: wider: exact up to 4, clamped beyond (the 4 x 4 taps clamped every box to 2).
AREA_BOX = 2.0
AREA_BOX_MAX = 4.0
_WIDE_TAPS = 7  # taps a side of a box of AREA_BOX_MAX: 4 + 2 + 1


@njit(inline="always", **_H)
def _wide_weights(u, b, W):
    """The weights of the tent averaged over a box of width ``b`` (clamped to
    ``[1e-3, AREA_BOX_MAX]``) centred on ``u``, along one axis: ``W[0:m]`` for the input
    pixels ``i0 .. i0 + m - 1`` (every pixel the tent * box touches), the exact
    ``(F(i - u + b/2) - F(i - u - b/2)) / b`` of :func:`_area_weights`. Returns ``i0, m``."""
    b = min(max(b, 1e-3), AREA_BOX_MAX)
    hb = 0.5 * b
    i0 = np.int64(math.floor(u - hb - 1.0)) + 1
    i1 = np.int64(math.ceil(u + hb + 1.0)) - 1
    m = min(i1 - i0 + 1, _WIDE_TAPS)
    ib = 1.0 / b
    for d in range(m):
        t = (i0 + d) - u
        W[d] = (_tent_integral(t + hb) - _tent_integral(t - hb)) * ib
    return i0, m


@njit(inline="always", **_H)
def _wide_sum(a, h, w, c, u, v, bx, by, WX, WY, out):
    """``out[0:c]``: the bilinear image ``a`` (typed, ``(h, w, c)``) averaged over the box
    ``bx x by`` at tap-space ``(u, v)``, a box wider than :data:`AREA_BOX` (float64 sums;
    rows fold over the poles and columns wrap, as :func:`_area_apply`)."""
    x0, mx = _wide_weights(u, bx, WX)
    y0, my = _wide_weights(v, by, WY)
    half = w // 2
    for ch in range(c):
        out[ch] = 0.0
    for dy in range(my):
        wgy = WY[dy]
        if wgy == 0.0:
            continue
        iy, sh = _fold_row(y0 + dy, h, half)
        ix = (x0 + sh) % w
        for dx in range(mx):
            wg = wgy * WX[dx]
            for ch in range(c):
                out[ch] += wg * np.float64(a[iy, ix, ch])
            ix = ix + 1 if ix + 1 < w else 0


@njit(**_H)
def _area_wide(a, h, w, c, U, V, BX, BY, n, keep, own, acc, cover):
    """The kept samples of :func:`area_batch` whose box is wider than :data:`AREA_BOX`
    (which :func:`_area_apply` leaves out): wide taps (:func:`_wide_sum`)."""
    WX = np.empty(_WIDE_TAPS)
    WY = np.empty(_WIDE_TAPS)
    out = np.empty(c)
    for k in range(n):
        if not keep[k] or not (BX[k] > AREA_BOX or BY[k] > AREA_BOX):
            continue
        u = U[k] if abs(U[k]) < 1e6 else 0.0
        v = V[k] if abs(V[k]) < 1e6 else 0.0
        _wide_sum(a, h, w, c, u, v, BX[k], BY[k], WX, WY, out)
        j = own[k]
        for ch in range(c):
            acc[j, ch] += np.float32(out[ch])
        cover[j] += 1


@njit(**_H)
def area_batch(img, U, V, BX, BY, n, keep, own, acc, cover, WS, X0, Y0):
    """Area taps of ``n`` samples: ``acc[own[k]] +=`` the bilinear image averaged over
    the box ``BX[k] x BY[k]`` (input pixels, at most 2 each) centred on tap-space
    ``(U[k], V[k])``, and ``cover[own[k]] += 1``, for the samples with ``keep[k]``.

    The area filter of ``antialias="area"``: what supersampling a pixel converges
    to where the map is smooth over it, as 4 x 4 taps of ``tent * box`` in closed
    form. ``WS`` (float32, ``(8, >= n)``), ``X0``, ``Y0`` (int64) are scratch.
    """
    _area_weights(U, V, BX, BY, n, WS, X0, Y0)
    h = img[5]
    w = img[6]
    c = img[7]
    dt = img[4]
    nwide = 0
    for k in range(n):
        nwide += keep[k] != 0 and (BX[k] > AREA_BOX or BY[k] > AREA_BOX)
    if dt == 0:
        _area_apply(img[0], h, w, c, n, WS, X0, Y0, BX, BY, keep, own, acc, cover)
        if nwide > 0:
            _area_wide(img[0], h, w, c, U, V, BX, BY, n, keep, own, acc, cover)
    elif dt == 1:
        _area_apply(img[1], h, w, c, n, WS, X0, Y0, BX, BY, keep, own, acc, cover)
        if nwide > 0:
            _area_wide(img[1], h, w, c, U, V, BX, BY, n, keep, own, acc, cover)
    elif dt == 2:
        _area_apply(img[2], h, w, c, n, WS, X0, Y0, BX, BY, keep, own, acc, cover)
        if nwide > 0:
            _area_wide(img[2], h, w, c, U, V, BX, BY, n, keep, own, acc, cover)
    else:
        _area_apply(img[3], h, w, c, n, WS, X0, Y0, BX, BY, keep, own, acc, cover)
        if nwide > 0:
            _area_wide(img[3], h, w, c, U, V, BX, BY, n, keep, own, acc, cover)


@njit(**_V)
def _area_counts(U, V, valid, n, cl, wi, ho, wo, tol, cap, nx, ny, special, J, BX, BY, S, E,
                 T, G, aa_kx, aa_ky, jmin, split):  # fmt: skip
    """Footprints (``J``, boxes ``BX x BY``) and samples per pixel of
    ``antialias="area"``; returns the number of special pixels.

    The footprint of pixel ``k`` in the input's chart is the Jacobian ``J[:, k] =
    (du/dx, du/dy, dv/dx, dv/dy)`` (input pixels per output pixel). Its first
    column is a difference of the source coordinates along the row: the mean of
    the left and right ones where they agree, else the shorter (so that a jump
    next door does not count); the second follows from it because the map is
    conformal (``E``: the tap-space source points ``(u, v)`` of the columns just
    left and right of the chunk, round the seam, ``E[0:2, 0]`` and ``E[0:2, 1]``):
    on the sphere the image of the output's north step is the image of
    its east step turned by a right angle and scaled by their ratio ``q``
    (``cos(lat_src)`` converts between the chart and the sphere). The footprint's
    box in the input is ``BX x BY``, the lengths of the rows of ``J`` (a box with
    the footprint's second moments): one area tap (:func:`area_u8`,
    :func:`area_batch`) where each side is at most 2 input pixels. A pixel whose
    footprint is longer gets ``ceil(L / sqrt 2)`` samples along each of its axes
    (``L`` the length of that column of ``J``, at most ``cap``), each pulled back
    through the map and an area tap over its share of the footprint
    (:func:`_subsamples`): it is ``special``, as an undefined pixel is.
    ``S``: scratch, ``(3, >= n + 1)``, its first row the sources' cos(latitude)
    (:func:`source_cos`).

    Neighbour differences can miss a footprint that the magnification ``G / T``
    says is large: where the map repeats itself at the pixel's scale (a Droste
    map's fixed point, where neighbours land in the same place of other copies)
    or where neighbours are half the input apart (tiny outputs). A pixel whose
    footprint on the sphere is under half of what the magnification says (and
    that is over 2 input pixels) is treated as on a jump: ``J`` cleared, plain
    taps, as many as :func:`_counts` gives, at least ``jmin`` a side.
    """
    q = wo / (2.0 * ho * cl)
    half = 0.5 * wi
    CS = S[0]
    DU = S[1]
    DV = S[2]
    # vectorised passes: the differences to the left
    # neighbour (wrapped round the seam), then per pixel (in float32: 5 square roots
    # a pixel, twice the lanes of float64)
    for k in range(1, n):
        d = U[k] - U[k - 1]
        d = d - wi if d > half else d
        DU[k] = d + wi if d < -half else d
        DV[k] = V[k] - V[k - 1]
    d = U[0] - E[0, 0]
    d = d - wi if d > half else d
    DU[0] = d + wi if d < -half else d
    DV[0] = V[0] - E[1, 0]
    d = E[0, 1] - U[n - 1]
    d = d - wi if d > half else d
    DU[n] = d + wi if d < -half else d
    DV[n] = E[1, 1] - V[n - 1]
    nsp = 0
    f = np.float32
    q32 = f(q)
    r2 = f(1.0 / split)
    tol32 = f(tol)
    fcap = f(cap)
    one = f(1.0)
    half32 = f(0.5)
    for k in range(n):
        dul = f(DU[k])
        dvl = f(DV[k])
        dur = f(DU[k + 1])
        dvr = f(DV[k + 1])
        ll = dul * dul + dvl * dvl
        lr = dur * dur + dvr * dvr
        left = ll <= lr
        du = dul if left else dur
        dv = dvl if left else dvr
        near = f(4.0) * min(ll, lr) >= max(ll, lr)  # no jump next door: the centre's
        du = half32 * (dul + dur) if near else du
        dv = half32 * (dvl + dvr) if near else dv
        cs = f(max(CS[k], 1e-9))
        j01 = -q32 * dv / cs
        j21 = q32 * du * cs
        J[0, k] = du
        J[1, k] = j01
        J[2, k] = dv
        J[3, k] = j21
        BX[k] = math.sqrt(du * du + j01 * j01)
        BY[k] = math.sqrt(dv * dv + j21 * j21)
        a = min(max(np.ceil(math.sqrt(du * du + dv * dv) * r2 - tol32), one), fcap)
        b = min(max(np.ceil(math.sqrt(j01 * j01 + j21 * j21) * r2 - tol32), one), fcap)
        # the footprint's east step on the sphere against what the magnification says
        t = T[k]
        sc = f(min(G[k] / t, 1e9) if t > 0.0 else 1e9)
        ex = sc * f(aa_kx * cl)
        dus = du * cs
        if ex > f(2.0) and f(4.0) * (dus * dus + dv * dv) < ex * ex:
            J[0, k] = f(0.0)
            J[1, k] = f(0.0)
            J[2, k] = f(0.0)
            J[3, k] = f(0.0)
            a = min(max(np.ceil(ex - tol32), f(jmin)), fcap)
            b = min(max(np.ceil(sc * f(aa_ky) - tol32), f(jmin)), fcap)
        nx[k] = np.int64(a)
        ny[k] = np.int64(b)
        sp = np.int64((valid[k] == 0) or (a * b > one))
        special[k] = sp
        nsp += sp
    return nsp


@njit(**_H)
def _subsamples(
    k0, n, special, nx, ny, cl, sl, cc, cs, tabs,
    codes, params, kx, ky, img, interp, acc, cover, bufs, own, sv, u8, area, J, ascr, asc,
):  # fmt: skip
    """Supersample the special pixels of a chunk into ``acc``/``cover``.

    Subsample directions come from the pixel centre's by angle addition with
    the tables ``tabs[0..3][n, m]`` (cos/sin of the column and row offsets of
    subsample ``m`` of ``n``), so no trigonometry per subsample either.
    ``u8`` bundles the uint8 fast path's views and batch buffers (its first
    item says whether to use it). With ``area``, each subsample is an area tap
    over its share of the pixel's footprint ``J[:, k]``: :func:`area_u8` for uint8
    images (scratch ``asc``), else :func:`area_batch` (scratch ``ascr``).
    """
    ST = bufs[0]
    SX = bufs[1]
    SY = bufs[2]
    SZ = bufs[3]
    SG = bufs[4]
    SBX = bufs[7]
    SBY = bufs[8]
    xc = tabs[0]
    xs = tabs[1]
    yc = tabs[2]
    ys = tabs[3]
    nb = 0
    for k in range(k0, n):
        if not special[k]:
            continue
        a = nx[k]
        b = ny[k]
        if nb + a * b > SUB_BATCH:
            _flush(nb, codes, params, kx, ky, img, interp, acc, cover, bufs, own, sv, u8, area,
                   ascr, asc)  # fmt: skip
            nb = 0
        bxs = 0.0
        bys = 0.0
        if area:
            bxs = math.sqrt((J[0, k] / a) ** 2 + (J[1, k] / b) ** 2)
            bys = math.sqrt((J[2, k] / a) ** 2 + (J[3, k] / b) ** 2)
        for jb in range(b):
            dc = yc[b, jb]
            ds = ys[b, jb]
            cls = cl * dc + sl * ds
            sls = sl * dc - cl * ds
            for ja in range(a):
                ec = xc[a, ja]
                es = xs[a, ja]
                ST[nb] = 1.0
                SX[nb] = cls * (cc[k] * ec - cs[k] * es)
                SY[nb] = cls * (cs[k] * ec + cc[k] * es)
                SZ[nb] = sls
                SG[nb] = 1.0
                sv[nb] = 1
                own[nb] = k
                SBX[nb] = bxs
                SBY[nb] = bys
                nb += 1
    if nb > 0:
        _flush(nb, codes, params, kx, ky, img, interp, acc, cover, bufs, own, sv, u8, area, ascr,
               asc)  # fmt: skip


@njit(**_H)
def _flush(nb, codes, params, kx, ky, img, interp, acc, cover, bufs, own, sv, u8, area, ascr,
           asc):  # fmt: skip
    ST = bufs[0]
    SX = bufs[1]
    SY = bufs[2]
    SZ = bufs[3]
    SG = bufs[4]
    SU = bufs[5]
    SV = bufs[6]
    run_stages(codes, params, ST, SX, SY, SZ, SG, sv, nb)
    to_source(SX, SY, SZ, nb, kx, ky, SU, SV)
    if area and u8[0]:
        c = img[7]
        area_u8(u8[1], u8[2], u8[3], img[0], img[6], img[5], c, SU, SV, bufs[7], bufs[8], nb,
                asc[5], asc, False, sv, 1)  # fmt: skip
        F = asc[6]
        for q in range(nb):
            if sv[q]:
                j = own[q]
                for ch in range(c):
                    acc[j, ch] += F[ch, q]
                cover[j] += 1
        return
    if area:
        WS, X0, Y0 = ascr
        area_batch(img, SU, SV, bufs[7], bufs[8], nb, sv, own, acc, cover, WS, X0, Y0)
        return
    if u8[0]:
        _, p64, tail, big, big_w, shift, lom, boa, bob, bwt, bqa, bqb, bres = u8
        hi = img[5]
        wi = img[6]
        c = img[7]
        taps_u8(SU, SV, nb, wi, hi, big, boa, bob, bwt)
        gather_u8(p64, tail, big, big_w, shift, lom, boa, bob, bqa, bqb, nb)
        blend_u8(bqa, bqb, bwt, bres, nb, c)
        for q in range(nb):
            if sv[q]:
                j = own[q]
                r = bres[q]
                for ch in range(c):
                    acc[j, ch] += np.float32((r >> np.uint32(8 * ch)) & np.uint32(255))
                cover[j] += 1
        return
    for q in range(nb):
        if sv[q]:
            acc_sample(img, SU[q], SV[q], interp, acc, own[q])
            cover[own[q]] += 1


# -- uint8 bilinear: two taps a load, fixed-point weights -----------------------------------------
_SEAM = np.int32(-2147483648)
_LOW31 = np.int32(0x7FFFFFFF)


@njit(**_H)
def taps_u8(u, v, n, w_in, h_in, big, oa, ob, wt):
    """Fixed-point taps of tap-space ``(u, v)``: top-left pixel index of the top
    row (``oa``) and of the bottom row (``ob``), weights ``tx | ty << 8`` in
    1/256 pixel (rounded to nearest). The sign bit marks a pair that is not two
    neighbours in memory (seam, or a pixel past ``big``): the slow path loads it.
    """
    W = np.int32(w_in)
    H = np.int32(h_in)
    half = W // np.int32(2)
    one = np.int32(1)
    zero = np.int32(0)
    bigi = np.int32(big)
    for k in range(n):
        # NaN or huge coordinates (none from the stages; a safety net against reads
        # outside the image) count as 0
        uk = u[k] if abs(u[k]) < 1e6 else 0.0
        vk = v[k] if abs(v[k]) < 1e6 else 0.0
        xi = np.int32(uk * 256.0 + 1024.5)
        yi = np.int32(vk * 256.0 + 1024.5)
        x0 = (xi >> np.int32(8)) - np.int32(4)
        y0 = (yi >> np.int32(8)) - np.int32(4)
        tx = xi & np.int32(255)
        ty = yi & np.int32(255)
        x0 = x0 + W if x0 < zero else x0
        x0 = x0 - W if x0 >= W else x0
        xs = x0 + half
        xs = xs - W if xs >= W else xs
        top = y0 < zero
        bot = y0 + one >= H
        ya = zero if top else y0
        ya = H - one if ya >= H else ya
        yb = H - one if bot else y0 + one
        xa = xs if top else x0
        xb = xs if bot else x0
        ia = ya * W + xa
        ib = yb * W + xb
        oa[k] = ia | _SEAM if (xa == W - one) or (ia >= bigi) else ia
        ob[k] = ib | _SEAM if (xb == W - one) or (ib >= bigi) else ib
        wt[k] = np.uint16(tx | (ty << np.int32(8)))


@njit(**_H)
def _pair_slow(p64, tail, big, w_in, shift, lom, code):
    i = np.int64(code & _LOW31)
    lo = p64[i] if i < big else tail[i - big]
    if i % w_in == w_in - 1:
        j = i - w_in + 1
        hi = p64[j] if j < big else tail[j - big]
        lo = (lo & lom) | (hi << shift)
    return lo


@njit(**_H)
def gather_u8(p64, tail, big, w_in, shift, lom, oa, ob, qa, qb, n):
    for k in range(n):
        a = oa[k]
        b = ob[k]
        if (a | b) >= 0:
            qa[k] = p64[np.uint32(a)]
            qb[k] = p64[np.uint32(b)]
        else:
            qa[k] = _pair_slow(p64, tail, big, w_in, shift, lom, a)
            qb[k] = _pair_slow(p64, tail, big, w_in, shift, lom, b)


@njit(**_H)
def gather_u8_cached(p64, tail, big, w_in, shift, lom, oa, qa, qb, n):
    """Like :func:`gather_u8` with the lower pair ``w_in`` pixels after the upper one."""
    for k in range(n):
        a = oa[k]
        if a >= 0:
            qa[k] = p64[np.uint32(a)]
            qb[k] = p64[np.uint32(a) + np.uint32(w_in)]
        else:
            b = (a & _LOW31) + np.int32(w_in)
            qa[k] = _pair_slow(p64, tail, big, w_in, shift, lom, a)
            qb[k] = _pair_slow(p64, tail, big, w_in, shift, lom, b | _SEAM)


@njit(inline="always", **_H)
def _blend_c(qa, qb, wt, res, n, c):
    sh = np.uint64(8 * c)
    for k in range(n):
        ww = np.uint32(wt[k])
        tx = ww & np.uint32(255)
        ty = ww >> np.uint32(8)
        ux = np.uint32(256) - tx
        uy = np.uint32(256) - ty
        q0 = qa[k]
        q1 = qb[k]
        r = np.uint32(0)
        for ch in range(c):
            s0 = np.uint64(8 * ch)
            s1 = s0 + sh
            top = (
                np.uint32((q0 >> s0) & np.uint64(255)) * ux
                + np.uint32((q0 >> s1) & np.uint64(255)) * tx
            )
            bot = (
                np.uint32((q1 >> s0) & np.uint64(255)) * ux
                + np.uint32((q1 >> s1) & np.uint64(255)) * tx
            )
            val = (top * uy + bot * ty + np.uint32(32768)) >> np.uint32(16)
            r |= val << np.uint32(8 * ch)
        res[k] = r


@njit(**_H)
def blend_u8(qa, qb, wt, res, n, c):
    """Bilinear blend of the pairs in 8.8 fixed point, rounded; packed result.

    One branch per channel count, so that the channel loop is unrolled.
    """
    if c == 3:
        _blend_c(qa, qb, wt, res, n, 3)
    elif c == 4:
        _blend_c(qa, qb, wt, res, n, 4)
    elif c == 1:
        _blend_c(qa, qb, wt, res, n, 1)
    else:
        _blend_c(qa, qb, wt, res, n, 2)


@njit(**_H)
def store_u8(res, o32, p0, obytes, b0, n, c, spill):
    """Write ``n`` packed pixels from pixel ``p0`` (byte ``b0``): overlapping
    4-byte stores, then the last ``spill`` pixels byte by byte (their 4-byte
    store would run into the next tile or row)."""
    m = n - spill if n > spill else 0
    o = o32[p0 : p0 + m]
    for k in range(m):
        o[k, 0] = res[k]
    for k in range(m, n):
        r = res[k]
        for ch in range(c):
            obytes[b0 + k * c + ch] = np.uint8((r >> np.uint32(8 * ch)) & np.uint32(255))


# -- float32 bilinear: vectorised taps and blend ------------------------------------------------
@njit(**_V)
def taps_f32(u, v, n, w_in, h_in, I, TX, TY):
    """Bilinear taps of tap-space ``(u, v)`` for a float32 image (vectorised): the flat
    pixel indices ``I[0:4]`` (top-left, top-right, bottom-left, bottom-right; wrapped
    round the seam, folded over the poles as :func:`acc_sample`) and the weights
    ``TX, TY`` of the right and lower taps."""
    W = np.int64(w_in)
    H = np.int64(h_in)
    half = W // 2
    for k in range(n):
        uk = u[k] if abs(u[k]) < 1e6 else 0.0  # NaN or huge: 0 (as taps_u8)
        vk = v[k] if abs(v[k]) < 1e6 else 0.0
        xf = math.floor(uk)
        yf = math.floor(vk)
        TX[k] = np.float32(uk - xf)
        TY[k] = np.float32(vk - yf)
        x0 = np.int64(xf)
        y0 = np.int64(yf)
        x0 = x0 + W if x0 < 0 else x0
        x0 = x0 - W if x0 >= W else x0
        x1 = x0 + 1
        x1 = x1 - W if x1 >= W else x1
        top = y0 < 0  # row -1: row 0, half a turn round
        bot = y0 + 1 >= H  # row H: row H - 1, half a turn round
        ya = 0 if top else min(y0, H - 1)
        yb = H - 1 if bot else y0 + 1
        sa = half if top else 0
        sb = half if bot else 0
        xa0 = x0 + sa
        xa0 = xa0 - W if xa0 >= W else xa0
        xa1 = x1 + sa
        xa1 = xa1 - W if xa1 >= W else xa1
        xb0 = x0 + sb
        xb0 = xb0 - W if xb0 >= W else xb0
        xb1 = x1 + sb
        xb1 = xb1 - W if xb1 >= W else xb1
        I[0, k] = ya * W + xa0
        I[1, k] = ya * W + xa1
        I[2, k] = yb * W + xb0
        I[3, k] = yb * W + xb1


@njit(**_V)
def cached_taps_f32(oa, wt, n, w_in, I, TX, TY):
    """:func:`taps_f32` from a cached map's top-left taps and 8.8 weights (see
    :func:`taps_u8`; pixels whose taps fold over a pole are not among them)."""
    W = np.int64(w_in)
    inv = np.float32(1.0 / 256.0)
    for k in range(n):
        a = np.int64(oa[k] & _LOW31)
        x = a % W
        r = np.int64(1) if x != W - 1 else np.int64(1) - W  # the right neighbour, or wrapped
        I[0, k] = a
        I[1, k] = a + r
        I[2, k] = a + W
        I[3, k] = a + W + r
        ww = np.int32(wt[k])
        TX[k] = np.float32(ww & 255) * inv
        TY[k] = np.float32(ww >> 8) * inv


@njit(inline="always", **_H)
def _blend_f32_c(f, I, TX, TY, out, o0, n, c):
    one = np.float32(1.0)
    for k in range(n):
        tx = TX[k]
        ty = TY[k]
        i0 = I[0, k] * c
        i1 = I[1, k] * c
        i2 = I[2, k] * c
        i3 = I[3, k] * c
        q = o0 + k * c
        for ch in range(c):
            top = (one - tx) * f[i0 + ch] + tx * f[i1 + ch]
            bot = (one - tx) * f[i2 + ch] + tx * f[i3 + ch]
            out[q + ch] = (one - ty) * top + ty * bot


@njit(**_H)
def blend_f32(f, I, TX, TY, out, o0, n, c):
    """The bilinear blend of :func:`taps_f32` from the flat float32 image ``f`` into the
    flat float32 output ``out`` from value ``o0`` (one branch per channel count)."""
    if c == 3:
        _blend_f32_c(f, I, TX, TY, out, o0, n, 3)
    elif c == 4:
        _blend_f32_c(f, I, TX, TY, out, o0, n, 4)
    elif c == 1:
        _blend_f32_c(f, I, TX, TY, out, o0, n, 1)
    else:
        _blend_f32_c(f, I, TX, TY, out, o0, n, c)


# -- uint8 area taps: 4 x 4 fixed-point weights of tent * box ------------------------------------
@njit(inline="always", **_H)
def _ramp_integral(t):
    """``int_0^t clamp(1 - s, 0, 1) ds`` (branch-free): the antiderivative of the sum of
    the tents at or left of 0 (a ramp from 1 down to 0 over ``[0, 1]``)."""
    tc = min(t, np.float32(1.0))
    p = max(tc, np.float32(0.0))
    return tc - np.float32(0.5) * p * p


@njit(inline="always", **_V)
def _box_weights(F, B, n, W):
    """``W[0:4, k]``: the 4 fixed-point weights (1/4096) along one axis of each tap ``k``
    at fraction ``F[k]`` past its second pixel, box width ``B[k]`` (clamped to ``[1e-3,
    2]``): rounded cumulative sums (the ramp's integral over the box), so that they sum
    to exactly 4096. One vectorised pass (four output rows: few enough for LLVM's
    run-time alias checks)."""
    lo = np.float32(1e-3)
    hi = np.float32(2.0)
    half = np.float32(0.5)
    one = np.float32(1.0)
    W0 = W[0]
    W1 = W[1]
    W2 = W[2]
    W3 = W[3]
    for k in range(n):
        f = F[k]
        b = min(max(np.float32(B[k]), lo), hi)
        h = half * b
        s = np.float32(4096.0) / b
        a = f + one
        c0 = np.int32((_ramp_integral(a + h) - _ramp_integral(a - h)) * s + half)
        c1 = np.int32((_ramp_integral(f + h) - _ramp_integral(f - h)) * s + half)
        a = f - one
        c2 = np.int32((_ramp_integral(a + h) - _ramp_integral(a - h)) * s + half)
        W0[k] = c0
        W1[k] = c1 - c0
        W2[k] = c2 - c1
        W3[k] = np.int32(4096) - c2


@njit(inline="always", **_V)
def _first_taps(U, n, X0, FX):
    """``X0[k]``: the first of the 4 taps along one axis of tap-space coordinate
    ``U[k]`` (NaN or huge: 0, as :func:`taps_u8`); ``FX[k]``: its fraction past the
    second, float32."""
    for k in range(n):
        uk = U[k] if abs(U[k]) < 1e6 else 0.0
        fu = math.floor(uk)
        X0[k] = np.int32(fu) - np.int32(1)
        FX[k] = np.float32(uk - fu)


@njit(**_V)
def area_taps_u8(U, V, BX, BY, n, WX, WY, X0, Y0, FX, FY):
    """Fixed-point area taps (vectorised): the first tap ``X0, Y0`` and the weights
    ``WX[0:4]`` (columns), ``WY[0:4]`` (rows) of each sample, in 1/4096, each set
    summing to exactly 4096 (so that a weighted sum of 255s, 255 * 4096 * 4096, still
    fits in 32 bits). ``FX``, ``FY``: float32 scratch for the fractions.

    The weights are those of :func:`_area_weights` (the tent averaged over a box
    of width ``b``, clamped to ``[1e-3, 2]``), taken as differences of rounded
    cumulative sums; the cumulative weight of the taps up to ``d`` is the ramp's
    integral over the box. Four passes, each with few output arrays: one loop
    writing all ten was not vectorised (2.5x the time).
    """
    _first_taps(U, n, X0, FX)
    _first_taps(V, n, Y0, FY)
    _box_weights(FX, BX, n, WX)
    _box_weights(FY, BY, n, WY)


@njit(**_H)
def _area_gather_slow(p64, tail, big, w_in, h_in, c, x0, y0, Q, k):
    """:func:`area_gather_u8` for a sample whose 4 x 4 taps cross the seam, a pole or
    the end of ``p64``: pixel by pixel, folding and wrapping as :func:`acc_sample`."""
    shift = np.uint64(8 * c)
    lom = (np.uint64(1) << shift) - np.uint64(1)
    for j in range(4):
        iy, xs = _fold(y0 + j, np.int64(x0), h_in, w_in)  # the row's first tap
        base = iy * w_in
        if xs + 3 < w_in and base + xs + 2 < big:  # this row is four neighbours
            Q[2 * j, k] = p64[base + xs]
            Q[2 * j + 1, k] = p64[base + xs + 2]
            continue
        for m in range(2):
            q = np.uint64(0)
            for t in range(2):
                i = base + (xs + 2 * m + t) % w_in  # (round more than once: 1 to 3 pixels)
                px = (p64[i] if i < big else tail[i - big]) & lom
                q |= px << (shift * np.uint64(t))
            Q[2 * j + m, k] = q


@njit(**_H)
def area_gather_u8(p64, tail, big, w_in, h_in, c, X0, Y0, n, Q):
    """The 4 x 4 pixels of each sample as 8 loads of two pixels: ``Q[2 j]`` holds
    columns 0, 1 and ``Q[2 j + 1]`` columns 2, 3 of row ``j``."""
    lim = big - 2 - 3 * w_in
    for k in range(n):
        x0 = X0[k]
        y0 = Y0[k]
        i = y0 * w_in + x0
        if y0 >= 0 and y0 + 3 < h_in and x0 >= 0 and x0 + 3 < w_in and i < lim:
            a = np.uint32(i)
            b = a + np.uint32(w_in)
            d = b + np.uint32(w_in)
            e = d + np.uint32(w_in)
            two = np.uint32(2)
            Q[0, k] = p64[a]
            Q[1, k] = p64[a + two]
            Q[2, k] = p64[b]
            Q[3, k] = p64[b + two]
            Q[4, k] = p64[d]
            Q[5, k] = p64[d + two]
            Q[6, k] = p64[e]
            Q[7, k] = p64[e + two]
        else:
            _area_gather_slow(p64, tail, big, w_in, h_in, c, x0, y0, Q, k)


@njit(inline="always", **_H)
def _area_blend_c(Q, WX, WY, res, F, n, c, packed):
    sh = np.uint64(8 * c)
    m = np.uint64(255)
    for k in range(n):
        w0 = np.uint32(WX[0, k])
        w1 = np.uint32(WX[1, k])
        w2 = np.uint32(WX[2, k])
        w3 = np.uint32(WX[3, k])
        r = np.uint32(0)
        for ch in range(c):
            s0 = np.uint64(8 * ch)
            s1 = s0 + sh
            acc = np.uint32(0)
            for j in range(4):
                qa = Q[2 * j, k]
                qb = Q[2 * j + 1, k]
                row = (
                    np.uint32((qa >> s0) & m) * w0
                    + np.uint32((qa >> s1) & m) * w1
                    + np.uint32((qb >> s0) & m) * w2
                    + np.uint32((qb >> s1) & m) * w3
                )
                acc += row * np.uint32(WY[j, k])
            if packed:
                r |= ((acc + np.uint32(1 << 23)) >> np.uint32(24)) << np.uint32(8 * ch)
            else:
                F[ch, k] = np.float32(acc) * np.float32(1.0 / (1 << 24))
        if packed:
            res[k] = r


@njit(**_H)
def area_blend_u8(Q, WX, WY, res, F, n, c, packed):
    """The 4 x 4 weighted sums in 8.24 fixed point: rounded and packed into ``res``, or
    (not ``packed``) as float32 ``F[channel, sample]``, for sums of several taps. One
    branch per channel count, so that the channel loop is unrolled."""
    if c == 3:
        _area_blend_c(Q, WX, WY, res, F, n, 3, packed)
    elif c == 4:
        _area_blend_c(Q, WX, WY, res, F, n, 4, packed)
    elif c == 1:
        _area_blend_c(Q, WX, WY, res, F, n, 1, packed)
    else:
        _area_blend_c(Q, WX, WY, res, F, n, 2, packed)


@njit(**_H)
def area_u8(p64, tail, big, a8, w_in, h_in, c, U, V, BX, BY, n, res, sc, packed, mask, want):
    """Area taps of ``n`` samples of a uint8 image into packed ``res`` or (not
    ``packed``) ``sc[6]`` (``sc``: the scratch ``WX, WY, X0, Y0, Q``, results)."""
    WX, WY, X0, Y0, Q, _, F = sc
    area_taps_u8(U, V, BX, BY, n, WX, WY, X0, Y0, F[0], F[1])  # (F: scratch until the blend)
    area_gather_u8(p64, tail, big, w_in, h_in, c, X0, Y0, n, Q)
    area_blend_u8(Q, WX, WY, res, F, n, c, packed)
    nwide = 0
    for k in range(n):
        nwide += mask[k] == want and (BX[k] > AREA_BOX or BY[k] > AREA_BOX)
    if nwide > 0:
        _area_wide_u8(a8, h_in, w_in, c, U, V, BX, BY, n, res, F, packed, mask, want)


@njit(**_H)
def _area_wide_u8(a, h, w, c, U, V, BX, BY, n, res, F, packed, mask, want):
    """The samples of :func:`area_u8` whose box is wider than :data:`AREA_BOX`: wide
    taps (:func:`_wide_sum`) over the 4 x 4 taps' result, rounded to nearest."""
    WX = np.empty(_WIDE_TAPS)
    WY = np.empty(_WIDE_TAPS)
    out = np.empty(c)
    for k in range(n):
        if mask[k] != want or not (BX[k] > AREA_BOX or BY[k] > AREA_BOX):
            continue
        u = U[k] if abs(U[k]) < 1e6 else 0.0  # NaN or huge: 0 (as taps_u8)
        v = V[k] if abs(V[k]) < 1e6 else 0.0
        _wide_sum(a, h, w, c, u, v, BX[k], BY[k], WX, WY, out)
        if packed:
            r = np.uint32(0)
            for ch in range(c):
                val = min(max(math.floor(out[ch] + 0.5), 0.0), 255.0)
                r |= np.uint32(val) << np.uint32(8 * ch)
            res[k] = r
        else:
            for ch in range(c):
                F[ch, k] = np.float32(out[ch])


# -- uint8 nearest (the scalar sampler's arithmetic) and bicubic (fixed point), by 8-byte loads ----
@njit(**_H)
def nearest_u8(p64, tail, big, w_in, h_in, c, U, V, n, res):
    """Nearest taps of a uint8 image into packed ``res``: one unaligned load a pixel,
    folded and wrapped as :func:`acc_sample` (so the same pixels as its ``NEAREST``)."""
    lom = (np.uint64(1) << np.uint64(8 * c)) - np.uint64(1)
    W = np.int64(w_in)
    H = np.int64(h_in)
    for k in range(n):
        uk = U[k] if abs(U[k]) < 1e6 else 0.0  # NaN or huge: 0 (as taps_u8)
        vk = V[k] if abs(V[k]) < 1e6 else 0.0
        ix = np.int64(math.floor(uk + 0.5))
        iy = np.int64(math.floor(vk + 0.5))
        if iy < 0 or iy >= H or ix < 0 or ix >= W:  # (inside, _fold is the identity)
            iy, ix = _fold(iy, ix, h_in, w_in)
        i = iy * W + ix
        q = p64[i] if i < big else tail[i - big]
        res[k] = np.uint32(q & lom)


@njit(inline="always", **_H)
def _cubic_blend_c(Q, QF, res, n, c):
    sh = np.uint64(8 * c)
    m = np.uint64(255)
    lo = np.float32(0.0)
    hi = np.float32(255.0)
    i32 = np.int32
    for k in range(n):
        wx0, wx1, wx2, wx3 = _cubic_q(QF[0, k])
        wy0, wy1, wy2, wy3 = _cubic_q(QF[1, k])
        r = np.uint32(0)
        for ch in range(c):
            s0 = np.uint64(8 * ch)
            s1 = s0 + sh
            acc = i32(0)
            for dy in range(4):
                # the operations of _cubic_u8_sample, in int32 (the casts keep LLVM's
                # lanes 32 bits wide: numba widens int32 arithmetic to int64)
                wy = wy0 if dy == 0 else (wy1 if dy == 1 else (wy2 if dy == 2 else wy3))
                qa = Q[2 * dy, k]
                qb = Q[2 * dy + 1, k]
                row = i32(
                    wx0 * i32((qa >> s0) & m)
                    + wx1 * i32((qa >> s1) & m)
                    + wx2 * i32((qb >> s0) & m)
                    + wx3 * i32((qb >> s1) & m)
                )
                acc = i32(acc + wy * row)
            val = min(max(np.rint(np.float32(acc) * _CUBIC_SCALE), lo), hi)
            r |= np.uint32(val) << np.uint32(8 * ch)
        res[k] = r


@njit(**_H)
def cubic_u8(p64, tail, big, w_in, h_in, c, U, V, n, res, sc):
    """Bicubic taps of a uint8 image into packed ``res``, in fixed point.

    The taps and rounded fractions of :func:`_cubic_tap`, the 4 x 4 pixels as 8
    loads of two (:func:`area_gather_u8`), then the int32 blend of
    :func:`_cubic_u8_sample` with the weights of :func:`_cubic_q`, rounded as
    :func:`finish_pixel` (so the same pixels as :func:`acc_sample`).

    Parameters
    ----------
    p64, tail, big : ndarray of uint64, ndarray of uint64, int
        The image as unaligned 8-byte loads (see :func:`gather_u8`).
    w_in, h_in, c : int
        The image's shape.
    U, V : ndarray of float64
        Tap-space coordinates of the ``n`` samples.
    n : int
        Number of samples.
    res : ndarray of uint32
        Packed result, ``c`` bytes a sample.
    sc : tuple
        The area scratch of :func:`area_u8`: ``X0``, ``Y0``, ``Q`` and its first
        int32 array (``WX``) for the fractions.
    """
    QF, _, X0, Y0, Q, _, _ = sc
    for k in range(n):
        x0, qx = _cubic_tap(U[k])
        y0, qy = _cubic_tap(V[k])
        X0[k] = np.int32(x0) - np.int32(1)
        Y0[k] = np.int32(y0) - np.int32(1)
        QF[0, k] = qx
        QF[1, k] = qy
    area_gather_u8(p64, tail, big, w_in, h_in, c, X0, Y0, n, Q)
    if c == 3:
        _cubic_blend_c(Q, QF, res, n, 3)
    elif c == 4:
        _cubic_blend_c(Q, QF, res, n, 4)
    elif c == 1:
        _cubic_blend_c(Q, QF, res, n, 1)
    else:
        _cubic_blend_c(Q, QF, res, n, 2)


@njit(**_V)
def source_cos(V, n, hi, CS):
    """``CS[k]``: cos(latitude) of the source point at tap-space row ``V[k]`` of an input
    ``hi`` rows high (NaN or huge: row 0, as :func:`taps_u8`); vectorised, computed once
    a chunk for :func:`_one_tap_px` and :func:`_area_counts`."""
    kv = PI / hi
    for k in range(n):
        vk = V[k] if abs(V[k]) < 1e6 else 0.0
        CS[k] = fsincos(kv * (vk + 0.5))[0]


@njit(**_V)
def _one_tap_px(T, G, CS, valid, n, cl, aa_kx, aa_ky, thr, small):
    """Which pixels of the area filter take one bilinear tap: ``small[k]`` where the
    footprint's box in the input's chart is at most ``thr`` input pixels a side,
    bounded from the magnification ``s = G / T``: the footprint's axes on the sphere
    are ``s * kx * cos(lat)`` and ``s * ky`` equatorial input pixels, and the chart
    stretches the east one by ``1 / cos(lat_src)`` (``CS``, :func:`source_cos`).
    Returns how many."""
    ext = max(aa_kx * cl, aa_ky)
    cnt = 0
    for k in range(n):
        t = T[k]
        s = min(G[k] / t, 1e9) if t > 0.0 else 1e9
        ok = (valid[k] != 0) and (s * ext <= thr * CS[k])
        small[k] = ok
        cnt += ok
    return cnt


@njit(inline="always", **_H)
def _row_integral(P, ti, ch, x, w):
    """``int_0^x`` of row ``ti``'s linear interpolant (samples at integers, periodic in
    ``w``) from its prefix sums ``P[ti, k, ch] = sum of the first k samples`` (``k = 0 ..
    w + 1``, the last past the seam)."""
    wf = np.float64(w)
    q = math.floor(x / wf)
    x0 = x - q * wf
    n = min(max(np.int64(x0), 0), w - 1)
    t = x0 - n
    a = P[ti, n, ch]
    b = P[ti, n + 1, ch]
    d = P[ti, n + 2, ch]
    return (
        q * P[ti, w, ch]
        + 0.5 * (a + b - P[ti, 1, ch])
        + t * (b - a)
        + (0.5 * t * t) * (d - 2.0 * b + a)
    )


@njit(inline="always", **_H)
def _row_integral2(P, Q, ti, ch, x, w):
    """``int_0^x int_0^s`` of row ``ti``'s linear interpolant (periodic in ``w``): its
    second antiderivative, from the prefix sums ``P`` (:func:`_row_integral`) and
    ``Q[ti, k, ch]``, the second antiderivative at the integers ``k = 0 .. w``."""
    wf = np.float64(w)
    q = math.floor(x / wf)
    x0 = x - q * wf
    n = min(max(np.int64(x0), 0), w - 1)
    t = x0 - n
    a = P[ti, n, ch]
    b = P[ti, n + 1, ch]
    d = P[ti, n + 2, ch]
    g = 0.5 * (a + b - P[ti, 1, ch])  # the first antiderivative at n
    pn = b - a
    f2 = Q[ti, n, ch] + t * g + (0.5 * t * t) * pn + (t * t * t / 6.0) * (d - b - pn)
    return q * Q[ti, w, ch] + P[ti, w, ch] * (wf * q * (q - 1.0) * 0.5 + q * x0) + f2


@njit(**_H)
def _slivers(U, V, BX, BY, J, special, valid, n, h, w, c, PQ, tindex, limit, bend, slv, SL):
    """The sliver taps of :data:`~spherewarp.render.antialias.AREA_SLIVER_BOX`: each
    special pixel with a footprint (``J`` not cleared) whose box is at most ``limit``
    input pixels high and whose 4 rows have prefix sums (``tindex``: an input row's
    row of ``P``, or -1) is the bilinear surface averaged over its whole box ``BX x
    BY`` exactly, the tent-times-box weights of :func:`_area_weights` across the rows
    and along them the footprint's own spread: the convolution of boxes as wide as its
    two steps' ``u`` components (a trapezoid, as the parallelogram's shadow on the
    row), from the rows' second antiderivatives (:func:`_row_integral2`; a box where
    one step is negligible, :func:`_row_integral`), into ``SL[ch, k]``; it is no longer
    special (``slv[k] = 1``). ``PQ``: the prefix sums and the second ones. Only where
    the chart keeps the footprint straight: a straight piece of the sphere at ``d`` rows
    from a pole, ``dl`` radians of longitude either side of its centre, bends by about
    ``d dl^2 / 2`` rows in the chart, which must be at most ``bend``. Returns how many."""
    P = PQ[0]
    Q = PQ[1]
    half = w // 2
    cnt = 0
    for k in range(n):
        slv[k] = 0
        if not special[k] or valid[k] == 0 or BY[k] > limit:
            continue
        if J[0, k] == 0.0 and J[1, k] == 0.0 and J[2, k] == 0.0 and J[3, k] == 0.0:
            continue  # on a jump: plain taps
        u = U[k]
        v = V[k]
        by = min(max(BY[k], 1e-3), 2.0)
        yf = math.floor(v) - 1.0
        y0 = np.int64(yf)
        ty = yf - v
        hy = 0.5 * by
        ok = True
        for d in range(4):
            iy = y0 + d
            iy = -1 - iy if iy < 0 else (2 * h - 1 - iy if iy >= h else iy)
            iy = min(max(iy, 0), h - 1)
            if tindex[iy] < 0:
                ok = False
        if not ok:
            continue
        ea = abs(J[0, k])
        eb = abs(J[1, k])
        lo = min(ea, eb)
        hi = max(max(ea, eb), 1e-3)
        box = lo < 1e-2 * hi  # one step along the row: a box
        hx = 0.5 * hi
        dp = min(v + 0.5, h - (v + 0.5))  # rows to the nearest pole
        dl = (0.5 * (ea + eb)) * (TWO_PI / w)
        if dp * dl * dl * 0.5 > bend:
            continue
        s1 = 0.5 * (ea + eb)
        s2 = 0.5 * abs(ea - eb)
        iab = 1.0 / (ea * eb) if not box else 0.0
        for ch in range(c):
            SL[ch, k] = 0.0
        for d in range(4):
            wy = (_tent_integral(ty + d + hy) - _tent_integral(ty + d - hy)) / by
            if wy == 0.0:
                continue
            iy = y0 + d
            sh = 0.0
            if iy < 0:  # fold over the pole: row -1 - iy, half a turn round
                iy = -1 - iy
                sh = np.float64(half)
            elif iy >= h:
                iy = 2 * h - 1 - iy
                sh = np.float64(half)
            ti = tindex[min(max(iy, 0), h - 1)]
            x = u + sh
            for ch in range(c):
                if box:
                    a = _row_integral(P, ti, ch, x - hx, w)
                    b = _row_integral(P, ti, ch, x + hx, w)
                    SL[ch, k] += wy * (b - a) / hi
                else:
                    f = (
                        _row_integral2(P, Q, ti, ch, x + s1, w)
                        - _row_integral2(P, Q, ti, ch, x + s2, w)
                        - _row_integral2(P, Q, ti, ch, x - s2, w)
                        + _row_integral2(P, Q, ti, ch, x - s1, w)
                    )
                    SL[ch, k] += wy * f * iab
        slv[k] = 1
        special[k] = 0
        cnt += 1
    return cnt


# -- tiles -----------------------------------------------------------------------------------------
@njit(**_H)
def _layout(img, dst, ho, wo, th, tw):
    """What the tiled entry points share: input width and channels, the output's bytes,
    tiles per row and in all, and the uint8 pair path's row length, shift, low-pixel
    mask and spill (pixels whose 4-byte store would run past the row)."""
    wi = img[6]
    c = img[7]
    ntx = (wo + tw - 1) // tw
    ntiles = ((ho + th - 1) // th) * ntx
    shift = np.uint64(8 * c)
    lom = (np.uint64(1) << shift) - np.uint64(1)
    spill = (4 - c + c - 1) // c
    return wi, c, dst[0], ntx, ntiles, np.int64(wi), shift, lom, spill


@njit(**_H)
def _tile(t, ntx, th, tw, ho, wo):
    ty0 = (t // ntx) * th
    tx0 = (t % ntx) * tw
    return ty0, tx0, min(th, ho - ty0), min(tw, wo - tx0)


@njit(**_P)
def render_spec(
    img, p64, tail, big, o32, dst, ho, wo, co, fast_u8, fast_f32, fimg,
    codes, params, ccos, csin, tabs, kx, ky,
    do_aa, aa_kx, aa_ky, tol, cap, uniform, jumps, rho, jmin, area, split, one_tap,
    sl_p, sl_index, sl_box, sl_bend, interp, bg, is_int, maxval, full, th, tw, prog, wk, nw,
):  # fmt: skip
    """Render an equirectangular output through the stages of a map.

    ``img``, ``dst``: input and flat output bundles (one array per sample
    type, so that one compiled kernel serves them all; see
    ``fast._image_bundle``). ``fast_u8``: a uint8 image whose one-tap pixels go
    through the whole-pixel loads (``p64``, ``tail``, ``o32`` are the unaligned
    views): bilinear two taps a load, nearest one load, bicubic 8 loads of two;
    ``fast_f32``: float32 bilinear through vectorised taps (``fimg``: the image,
    flat); otherwise the scalar float32 sampler. ``do_aa``: compute samples per pixel
    (``uniform > 0``: that many per axis; else adaptive from the magnification).
    ``jumps``: in adaptive mode, also give pixels on a jump of the map (a seam
    between neighbouring pixels' source points, see :func:`_jump_flags`; ``rho``
    the angular size of an input pixel) ``jmin x jmin`` samples at least. The
    rows are then pulled back one ahead, with one column more on either side.
    ``area`` (with ``do_aa``, ``uniform = 0``): every pixel is an area tap over
    its footprint, split into parts where an axis of the footprint is over about
    1.5 input pixels (:func:`_area_counts`; the taps: :func:`area_u8` in fixed
    point for uint8, :func:`area_batch` otherwise), except that a pixel whose
    footprint's box is at most ``one_tap`` input pixels a side (bounded from the
    magnification, :func:`_one_tap_px`) takes one bilinear tap; a chunk made of
    such pixels skips the footprints. A footprint to split that is a sliver (its box
    at most ``sl_box`` high, ``sl_box > 0``) is one exact tap of its whole box from the
    rows' prefix sums ``sl_p`` (``sl_index``: the row of ``sl_p`` of each input row, or
    -1; :func:`_slivers`). ``prog``: int64 progress
    counters, ``PROGRESS_STRIDE`` apart (a cache line each); worker ``wk`` adds
    one to ``prog[wk * PROGRESS_STRIDE]`` per tile finished (no atomics: one
    writer per slot), which the caller may read while the kernel runs; the
    caller cancels the render by setting the last slot, ``prog[-1]``, to non-zero
    (each worker stops before its next tile).
    """
    hi = img[5]
    wi, c, obytes, ntx, ntiles, big_w, shift, lom, spill = _layout(img, dst, ho, wo, th, tw)
    # without anti-aliasing the special pixels (undefined ones: valid = 0) still go through
    # _subsamples, one sample each: room for a whole chunk
    nsb = SUB_BATCH if do_aa else tw
    # Worker wk of nw (threads of the caller): scratch is allocated once; rows of tiles
    # are dealt out round-robin, and each row is walked left to right (cache locality).
    f64s = np.empty((7, tw))
    T = f64s[0]
    X = f64s[1]
    Y = f64s[2]
    Z = f64s[3]
    G = f64s[4]
    U = f64s[5]
    V = f64s[6]
    u8s = np.empty((2, tw), np.uint8)
    valid = u8s[0]
    special = u8s[1]
    i64s = np.empty((3, tw), np.int64)
    nx = i64s[0]
    ny = i64s[1]
    cover = i64s[2]
    acc = np.empty((tw, c), np.float32)
    i32s = np.empty((2, tw), np.int32)
    oa = i32s[0]
    ob = i32s[1]
    wt = np.empty(tw, np.uint16)
    qs = np.empty((2, tw), np.uint64)
    qa = qs[0]
    qb = qs[1]
    res = np.empty(tw, np.uint32)
    bufs = np.zeros((9, nsb))
    J = np.zeros((4, tw if area else 1))
    na = max(nsb, tw) if area else 1
    ascr = (np.empty((8, na), np.float32), np.empty(na, np.int64), np.empty(na, np.int64))
    ident = np.arange(tw)
    BXc = np.empty(tw)
    BYc = np.empty(tw)
    keep = np.empty(tw, np.uint8)
    AS = np.empty((3, tw + 1 if area else 1))
    fast_bl = fast_u8 and interp == BILINEAR  # uint8 bilinear, two taps a load
    area_px = area and fast_bl  # area taps in fixed point (uint8)
    nn_px = fast_u8 and interp == NEAREST and not area  # uint8 nearest, a load a pixel
    cu_px = fast_u8 and interp == BICUBIC and not area  # uint8 bicubic, 8 loads a pixel
    nau = na if area_px else (tw if cu_px else 1)
    small = np.zeros(tw, np.uint8)
    res2 = np.empty(tw, np.uint32)
    slv = np.zeros(tw, np.uint8)
    SL = np.empty((c, tw))
    asc = (np.empty((4, nau), np.int32), np.empty((4, nau), np.int32), np.empty(nau, np.int32),
          np.empty(nau, np.int32), np.empty((8, nau), np.uint64), np.empty(nau, np.uint32),
          np.empty((4, nau), np.float32))  # fmt: skip
    own = np.empty(nsb, np.int64)
    sv = np.empty(nsb, np.uint8)
    mob1 = codes.shape[0] == 1 and codes[0] == STAGE_MOBIUS  # the common case, fused
    ecc = np.empty(2)
    ecs = np.empty(2)
    EF = np.ones((7, 2))
    evalid = np.ones(2, np.uint8)
    G[:] = 1.0
    valid[:] = 1
    # jump mode: rows above / current / below (slots rotate), each w + 2 columns
    jm = jumps and do_aa and uniform == 0 and not mob1
    fast_px = fast_bl and not area  # centre taps through the uint8 bilinear path
    fast_fpx = fast_f32 and not area  # centre taps through the float32 bilinear path
    direct = fast_px or fast_fpx or nn_px or cu_px  # centre taps written straight out
    nf = tw if fast_f32 else 1
    fI = np.empty((4, nf), np.int64)
    fT = np.empty((2, nf), np.float32)
    tw2 = tw + 2 if jm else 1
    geo = np.empty((3, 4, tw2))
    vals = np.empty((3, tw2), np.uint8)
    jtmp = np.empty((4, tw2))
    jc = jtmp[0]
    js = jtmp[1]
    jT = jtmp[2]
    jG = jtmp[3]
    nu8 = nsb if fast_bl else 1
    bi32 = np.empty((2, nu8), np.int32)
    bq = np.empty((2, nu8), np.uint64)
    u8 = (
        fast_bl, p64, tail, big, big_w, shift, lom, bi32[0], bi32[1],
        np.empty(nu8, np.uint16), bq[0], bq[1], np.empty(nu8, np.uint32),
    )  # fmt: skip
    stop = prog.shape[0] - 1  # the caller sets this slot to cancel (Ctrl-C)
    for tt in range(ntiles):
        if (tt // ntx) % nw != wk:
            continue
        if prog[stop] != 0:
            return
        ty0, tx0, h, w = _tile(tt, ntx, th, tw, ho, wo)
        cc = ccos[tx0 : tx0 + w]
        cs = csin[tx0 : tx0 + w]
        ecc[0] = ccos[(tx0 - 1) % wo]  # the columns either side of the chunk
        ecc[1] = ccos[(tx0 + w) % wo]
        ecs[0] = csin[(tx0 - 1) % wo]
        ecs[1] = csin[(tx0 + w) % wo]
        sa = 0
        sc = 1
        sn = 2
        if jm:
            for j in range(w + 2):
                q = (tx0 - 1 + j) % wo
                jc[j] = ccos[q]
                js[j] = csin[q]
        for r in range(h):
            i = ty0 + r
            lat = HALF_PI - PI * (i + 0.5) / ho
            cl = math.cos(lat)
            sl = math.sin(lat)
            if mob1:
                mobius_to_source(cl, sl, cc, cs, params[0], w, kx, ky, T, U, V)
            elif jm:
                if r == 0:
                    if i > 0:
                        _geom_row(i - 1, ho, jc, js, w + 2, codes, params, jT, jG, geo, vals, sa)
                    _geom_row(i, ho, jc, js, w + 2, codes, params, jT, jG, geo, vals, sc)
                else:
                    sa, sc, sn = sc, sn, sa
                if i + 1 < ho:
                    _geom_row(i + 1, ho, jc, js, w + 2, codes, params, jT, jG, geo, vals, sn)
                g = geo[sc]
                to_source(g[0, 1:], g[1, 1:], g[2, 1:], w, kx, ky, U, V)
                for k in range(w):
                    T[k] = 1.0
                    G[k] = g[3, k + 1]
                    valid[k] = vals[sc, k + 1]
            else:
                _directions(cl, sl, cc, cs, w, T, X, Y, Z, G, valid)
                run_stages(codes, params, T, X, Y, Z, G, valid, w)
                to_source(X, Y, Z, w, kx, ky, U, V)
            nsp = 0
            nsmall = 0
            if area:
                source_cos(V, w, hi, AS[0])  # (read by _area_counts too)
                nsmall = _one_tap_px(T, G, AS[0], valid, w, cl, aa_kx, aa_ky, one_tap, small)
            if area and nsmall == w:  # one tap a pixel: no footprints
                for k in range(w):
                    nx[k] = 1
                    ny[k] = 1
                    special[k] = 0
            elif area:
                _edge_source(cl, sl, ecc, ecs, codes, params, mob1, kx, ky, EF, evalid)
                nsp = _area_counts(
                    U, V, valid, w, cl, wi, ho, wo, tol, cap, nx, ny, special, J, BXc, BYc, AS,
                    EF[5:7], T, G, aa_kx, aa_ky, jmin, split,
                )  # fmt: skip
            elif do_aa:
                nsp = _counts(T, G, valid, w, cl, aa_kx, aa_ky, tol, cap, uniform, nx, ny, special)
            if do_aa:
                if jm:
                    nsp += _jump_flags(geo, vals, sa, sc, sn, i > 0, i + 1 < ho, w, cl, wo, ho,
                                       rho, jmin, nx, ny, special, area, J)  # fmt: skip
            else:
                for k in range(w):
                    special[k] = valid[k] == 0
                    nsp += special[k]
                    nx[k] = 1
                    ny[k] = 1
            nsl = 0
            if area and nsp > 0 and sl_box > 0.0:
                nsl = _slivers(U, V, BXc, BYc, J, special, valid, w, hi, wi, c, sl_p, sl_index,
                               sl_box, sl_bend, slv, SL)  # fmt: skip
                nsp -= nsl
                if nsl > 0:
                    for k in range(w):
                        if slv[k]:
                            nx[k] = 1
                            ny[k] = 1
            p0 = i * wo + tx0
            if fast_px:
                taps_u8(U, V, w, wi, hi, big, oa, ob, wt)
                gather_u8(p64, tail, big, big_w, shift, lom, oa, ob, qa, qb, w)
                blend_u8(qa, qb, wt, res, w, c)
                store_u8(res, o32, p0, obytes, p0 * c, w, c, spill)
                if nsp == 0:
                    continue
            elif fast_fpx:
                taps_f32(U, V, w, wi, hi, fI, fT[0], fT[1])
                blend_f32(fimg, fI, fT[0], fT[1], dst[2], p0 * c, w, c)
                if nsp == 0:
                    continue
            elif nn_px:
                nearest_u8(p64, tail, big, wi, hi, c, U, V, w, res)
                store_u8(res, o32, p0, obytes, p0 * c, w, c, spill)
                if nsp == 0:
                    continue
            elif cu_px:
                cubic_u8(p64, tail, big, wi, hi, c, U, V, w, res, asc)
                store_u8(res, o32, p0, obytes, p0 * c, w, c, spill)
                if nsp == 0:
                    continue
            elif area_px:
                if nsmall < w:
                    area_u8(p64, tail, big, img[0], wi, hi, c, U, V, BXc, BYc, w, res, asc, True,
                            special, 0)  # fmt: skip
                if nsmall > 0:  # one bilinear tap where the footprint is under a pixel
                    taps_u8(U, V, w, wi, hi, big, oa, ob, wt)
                    gather_u8(p64, tail, big, big_w, shift, lom, oa, ob, qa, qb, w)
                    blend_u8(qa, qb, wt, res2 if nsmall < w else res, w, c)
                    if nsmall < w:
                        for k in range(w):
                            res[k] = res2[k] if small[k] else res[k]
                if nsl > 0:
                    for k in range(w):
                        if slv[k]:
                            r = np.uint32(0)
                            for ch in range(c):
                                val = min(max(np.rint(SL[ch, k]), 0.0), 255.0)
                                r |= np.uint32(val) << np.uint32(8 * ch)
                            res[k] = r
                store_u8(res, o32, p0, obytes, p0 * c, w, c, spill)
                if nsp == 0:
                    continue
            acc[:w] = 0.0
            cover[:w] = 0
            if area and not area_px:
                for k in range(w):
                    keep[k] = special[k] == 0
                    if small[k]:  # a box of (nearly) nothing: the bilinear tap
                        BXc[k] = 0.0
                        BYc[k] = 0.0
                    if nsl > 0 and slv[k]:  # its tap is taken
                        keep[k] = 0
                WS, X0, Y0 = ascr
                area_batch(img, U, V, BXc, BYc, w, keep, ident, acc, cover, WS, X0, Y0)
                if nsl > 0:
                    for k in range(w):
                        if slv[k]:
                            for ch in range(c):
                                acc[k, ch] = np.float32(SL[ch, k])
                            cover[k] = 1
            elif not direct and not area:
                for k in range(w):
                    if not special[k]:
                        acc_sample(img, U[k], V[k], interp, acc, k)
                        cover[k] = 1
            if nsp > 0:
                _subsamples(
                    0, w, special, nx, ny, cl, sl, cc, cs, tabs,
                    codes, params, kx, ky, img, interp, acc, cover, bufs, own, sv, u8, area, J,
                    ascr, asc,
                )  # fmt: skip
            for k in range(w):
                if special[k] or not (direct or area_px):
                    finish_pixel(
                        acc, k, cover[k], nx[k] * ny[k], bg, dst, p0 + k, c, co,
                        is_int, maxval, full,
                    )  # fmt: skip
        prog[wk * PROGRESS_STRIDE] += 1


@njit(**_P)
def spec_coords(codes, params, ccos, csin, r0, ho, kx, ky, u, v, scale, valid, wk, nw):
    """Tap-space source coordinates, magnification and validity of rows
    ``r0 .. r0 + len(u)`` of an equirectangular output (for caches and tests)."""
    nr, wo = u.shape
    for r in range(wk, nr, nw):
        i = r0 + r
        lat = HALF_PI - PI * (i + 0.5) / ho
        cl = math.cos(lat)
        sl = math.sin(lat)
        T = np.empty(wo)
        X = np.empty(wo)
        Y = np.empty(wo)
        Z = np.empty(wo)
        G = np.empty(wo)
        vr = valid[r]
        _directions(cl, sl, ccos, csin, wo, T, X, Y, Z, G, vr)
        run_stages(codes, params, T, X, Y, Z, G, vr, wo)
        to_source(X, Y, Z, wo, kx, ky, u[r], v[r])
        sr = scale[r]
        for k in range(wo):
            t = T[k]  # > 0, but a nearly singular Möbius matrix can round it to 0
            sr[k] = min(G[k] / t, 1e9) if t > 0.0 else 1e9


@njit(**_P)
def spec_subsample_coords(codes, params, ho, wo, kx, ky, py, px, oy, ox, u, v, valid, wk, nw):
    """Source coordinates of subsamples at output ``(px + ox, py + oy)`` (pixel
    index plus offset in [0, 1)); direct trigonometry (used when building caches)."""
    n = py.shape[0]
    nchunk = (n + 1023) // 1024
    for ci in range(wk, nchunk, nw):
        a = ci * 1024
        m = min(1024, n - a)
        T = np.empty(m)
        X = np.empty(m)
        Y = np.empty(m)
        Z = np.empty(m)
        G = np.empty(m)
        vv = valid[a : a + m]
        for k in range(m):
            lat = HALF_PI - PI * (py[a + k] + oy[a + k]) / ho
            lon = 2.0 * PI * (px[a + k] + ox[a + k]) / wo - PI
            cl = math.cos(lat)
            T[k] = 1.0
            X[k] = cl * math.cos(lon)
            Y[k] = cl * math.sin(lon)
            Z[k] = math.sin(lat)
            G[k] = 1.0
            vv[k] = 1
        run_stages(codes, params, T, X, Y, Z, G, vv, m)
        to_source(X, Y, Z, m, kx, ky, u[a : a + m], v[a : a + m])


# -- samples given as coordinates (any map), and cached maps ---------------------------------------
@njit(**_P)
def sample_csr(img, u, v, valid, start, interp, bg, dst, co, p0, is_int, maxval, full, wk, nw):
    """Pixels ``p0 + j`` of ``dst`` (flat, ``co`` values a pixel) = mean of the
    samples ``start[j]:start[j+1]``.

    ``u, v``: tap-space coordinates of the samples; ``valid``: 0 for samples
    where the map is undefined (they count as background).
    """
    c = img[7]
    npx = start.shape[0] - 1
    nblk = (npx + 255) // 256
    for bi in range(wk, nblk, nw):
        j0 = bi * 256
        m = min(256, npx - j0)
        acc = np.zeros((m, c), np.float32)
        for j in range(m):
            cov = 0
            for s in range(start[j0 + j], start[j0 + j + 1]):
                if valid[s]:
                    acc_sample(img, u[s], v[s], interp, acc, j)
                    cov += 1
            finish_pixel(
                acc, j, cov, start[j0 + j + 1] - start[j0 + j], bg, dst, p0 + j0 + j,
                c, co, is_int, maxval, full,
            )  # fmt: skip


@njit(**_P)
def apply_cache(
    img, p64, tail, big, o32, dst, ho, wo, co, fast_u8, fast_f32, fimg, oa, wt, th, tw,
    sp_pix, sp_start, sp_u, sp_v, sp_valid, sp_tile, interp, bg, is_int, maxval, full, wk, nw,
):  # fmt: skip
    """Apply a cached map: the top-left tap and weights of each pixel (tile-major,
    see :func:`taps_u8`; the lower taps are ``wi`` pixels further on; none for a
    map whose pixels are all special), then the special pixels (anti-aliased,
    partly undefined, folded over a pole, or not bilinear) from their sample
    lists. ``fast_f32``: a float32 image (``fimg``, flat) through vectorised taps."""
    wi, c, obytes, ntx, ntiles, big_w, shift, lom, spill = _layout(img, dst, ho, wo, th, tw)
    nf = tw if fast_f32 else 1
    fI = np.empty((4, nf), np.int64)
    fT = np.empty((2, nf), np.float32)
    one = np.float32(1.0)
    inv = one / np.float32(256.0)
    qs = np.empty((2, tw), np.uint64)
    qa = qs[0]
    qb = qs[1]
    res = np.empty(tw, np.uint32)
    acc = np.empty((1, c), np.float32)
    for t in range(ntiles):
        if (t // ntx) % nw != wk:
            continue
        ty0, tx0, h, w = _tile(t, ntx, th, tw, ho, wo)
        base = ty0 * wo + tx0 * h
        for r in range(h):
            o = base + r * w
            p0 = (ty0 + r) * wo + tx0
            if fast_u8:
                gather_u8_cached(p64, tail, big, big_w, shift, lom, oa[o : o + w], qa, qb, w)
                blend_u8(qa, qb, wt[o : o + w], res, w, c)
                store_u8(res, o32, p0, obytes, p0 * c, w, c, spill)
            elif fast_f32 and oa.shape[0] > 0:
                cached_taps_f32(oa[o : o + w], wt[o : o + w], w, wi, fI, fT[0], fT[1])
                blend_f32(fimg, fI, fT[0], fT[1], dst[2], p0 * c, w, c)
            elif oa.shape[0] > 0:
                for k in range(w):
                    a = np.int64(oa[o + k] & _LOW31)
                    b = a + big_w
                    a1 = a + 1 if (a % big_w) != big_w - 1 else a - big_w + 1
                    b1 = b + 1 if (b % big_w) != big_w - 1 else b - big_w + 1
                    ww = wt[o + k]
                    tx = np.float32(ww & 255) * inv
                    ty = np.float32(ww >> 8) * inv
                    ya = a // big_w
                    ya1 = a1 // big_w
                    yb = b // big_w
                    yb1 = b1 // big_w
                    xa = a - ya * big_w
                    xa1 = a1 - ya1 * big_w
                    xb = b - yb * big_w
                    xb1 = b1 - yb1 * big_w
                    for ch in range(c):
                        top = (one - tx) * _get(img, ya, xa, ch) + tx * _get(img, ya1, xa1, ch)
                        bot = (one - tx) * _get(img, yb, xb, ch) + tx * _get(img, yb1, xb1, ch)
                        acc[0, ch] = (one - ty) * top + ty * bot
                    finish_pixel(acc, 0, 1, 1, bg, dst, p0 + k, c, co, is_int, maxval, full)
        for q in range(sp_tile[t], sp_tile[t + 1]):
            acc[0, :] = 0.0
            cov = 0
            for s in range(sp_start[q], sp_start[q + 1]):
                if sp_valid[s]:
                    acc_sample(img, np.float64(sp_u[s]), np.float64(sp_v[s]), interp, acc, 0)
                    cov += 1
            finish_pixel(
                acc, 0, cov, sp_start[q + 1] - sp_start[q], bg, dst, sp_pix[q],
                c, co, is_int, maxval, full,
            )  # fmt: skip


@njit(**_P)
def build_taps(u, v, w_in, h_in, big, oa, ob, wt, wk, nw):
    """Fixed-point taps (see :func:`taps_u8`) of rows of tap-space coordinates,
    written in order to the flat ``oa``, ``ob``, ``wt``."""
    nr, n = u.shape
    for r in range(wk, nr, nw):
        taps_u8(u[r], v[r], n, w_in, h_in, big, oa[r * n : (r + 1) * n],
                ob[r * n : (r + 1) * n], wt[r * n : (r + 1) * n])  # fmt: skip
