"""Branch-free ``exp``, ``log`` and ``sincos`` for the compiled stages (numba).

The libm functions (``math.exp``, ``math.sin``, ...) are opaque calls to LLVM:
a loop that calls them runs one point at a time. These are written with
arithmetic, selects (``a if c else b``) and bit reinterpretations only, so
that the loops of :mod:`spherewarp.render._kernels` that inline them
(``inline="always"``) are vectorised by LLVM.

Each function is the classic scheme: reduce the argument exactly (Cody--Waite,
split constants whose products with the reduction integer are exact), then a
polynomial on the small remainder, then undo the reduction with exact
operations (a power of two built in the exponent bits, a quadrant swap).
Accuracy (against ``mpmath`` and NumPy; ``tests/render/test_fastmath.py``
asserts 2 ulp and 2.5e-16):

* :func:`fexp`: at most 1 ulp (relative error 2.2e-16) on the whole double
  range, subnormal results and ``0``/``inf`` at the ends included;
* :func:`flog`: at most 1 ulp (relative 2.2e-16) for all positive doubles,
  subnormals included;
* :func:`fsincos`: absolute error at most 2.2e-16 for ``|x| <= SINCOS_MAX``
  (about 1.6e6; 1.1e-16 for ``|x| <= 1e4``). Larger arguments give bounded
  values (``|sin|, |cos| <= 1``) without meaning: the caller detects them
  (``abs(x) > SINCOS_MAX``) and recomputes those points with
  ``math.sin``/``math.cos`` outside its vectorised loop.

NaN arguments give NaN. The callers compile these with their own flags: no
``reassoc`` (it would fold away the ``(t + MAGIC) - MAGIC`` rounding) and no
``nnan``/``ninf``.
"""

from __future__ import annotations

import math

from llvmlite import ir
from numba import njit, types
from numba.core.extending import intrinsic

_FM = {"contract", "nsz"}
_H = {"cache": True, "nogil": True, "fastmath": _FM, "error_model": "numpy"}

#: 1.5 * 2^52: ``(x + MAGIC) - MAGIC`` rounds ``x`` (``|x| < 2^51``) to the nearest
#: integer, and the low bits of ``x + MAGIC`` hold that integer (two's complement)
MAGIC = 6755399441055744.0

#: arguments of :func:`fsincos` up to this size are reduced exactly (2^20 pi / 2)
SINCOS_MAX = 1647099.3291652855

_LOG2E = 1.4426950408889634
# ln 2 split: the high part has 32 significant bits, so k * _LN2_HI is exact for |k| < 2^21
_LN2_HI = 6.93147180369123816490e-01
_LN2_LO = 1.90821492927058770002e-10
_SQRT2 = 1.4142135623730951
_TWO_54 = 18014398509481984.0
_MIN_NORMAL = 2.2250738585072014e-308
_INF = math.inf

# exp(r) on |r| <= ln(2)/2: Taylor to degree 13 (remainder < 5e-18 relative)
_E2 = 1.0 / 2.0
_E3 = 1.0 / 6.0
_E4 = 1.0 / 24.0
_E5 = 1.0 / 120.0
_E6 = 1.0 / 720.0
_E7 = 1.0 / 5040.0
_E8 = 1.0 / 40320.0
_E9 = 1.0 / 362880.0
_E10 = 1.0 / 3628800.0
_E11 = 1.0 / 39916800.0
_E12 = 1.0 / 479001600.0
_E13 = 1.0 / 6227020800.0

# log(1 + f) = f - f^2/2 + s (f^2/2 + R(s^2)), s = f / (2 + f), |s| <= 0.1716 (fdlibm's
# e_log.c: the remez polynomial R, error < 2^-58.45)
_LG1 = 6.666666666666735130e-01
_LG2 = 3.999999999940941908e-01
_LG3 = 2.857142874366239149e-01
_LG4 = 2.222219843214978396e-01
_LG5 = 1.818357216161805012e-01
_LG6 = 1.531383769920937332e-01
_LG7 = 1.479819860511658591e-01

# pi/2 in three parts of 33 significant bits (fdlibm's pio2_1, pio2_2, pio2_3): k * _PIO2_1
# and k * _PIO2_2 are exact for |k| < 2^20, the third product's rounding is below 1e-31
_TWO_OVER_PI = 0.6366197723675814
_PIO2_1 = 1.57079632673412561417e00
_PIO2_2 = 6.07710050630396597660e-11
_PIO2_3 = 2.02226624871116645580e-21

# sin(r) = r + r^3 S(r^2), cos(r) = 1 - r^2/2 + r^4 C(r^2) on |r| <= pi/4 (fdlibm's
# k_sin.c and k_cos.c: errors < 2^-58)
_S1 = -1.66666666666666324348e-01
_S2 = 8.33333333332248946124e-03
_S3 = -1.98412698298579493134e-04
_S4 = 2.75573137070700676789e-06
_S5 = -2.50507602534068634195e-08
_S6 = 1.58969099521155010221e-10
_C1 = 4.16666666666666019037e-02
_C2 = -1.38888888888741095749e-03
_C3 = 2.48015872894767294178e-05
_C4 = -2.75573143513906633035e-07
_C5 = 2.08757232129817482790e-09
_C6 = -1.13596475577881948265e-11


# -- bit reinterpretation (LLVM bitcast: one register move, vectorisable) -----------------------
@intrinsic
def f64_bits(typingctx, x):
    """The IEEE-754 bits of the float64 ``x`` as an int64."""
    if not isinstance(x, types.Float):
        return None

    def codegen(context, builder, signature, args):
        return builder.bitcast(args[0], ir.IntType(64))

    return types.int64(types.float64), codegen


@intrinsic
def f64_from_bits(typingctx, b):
    """The float64 whose IEEE-754 bits are the int64 ``b``."""
    if not isinstance(b, types.Integer):
        return None

    def codegen(context, builder, signature, args):
        return builder.bitcast(args[0], ir.DoubleType())

    return types.float64(types.int64), codegen


@njit(inline="always", **_H)
def _pow2(kf):
    """``2.0 ** kf`` for an integral float ``-1022 <= kf <= 1023``, from the exponent bits.

    Integer work is add/subtract/left shift only: no 64-bit arithmetic right shift or
    int64 -> float64 conversion, which AVX2 has no vector instructions for."""
    return f64_from_bits((f64_bits(kf + MAGIC) - f64_bits(MAGIC) + 1023) << 52)


# -- functions ---------------------------------------------------------------------------------
@njit(inline="always", **_H)
def fexp(x):
    """``exp(x)``, branch-free; error at most 1 ulp (see the module docstring)."""
    # clamp so that 2^k stays representable in two factors; exp(-746) = 0, exp(710) = inf
    # (NaN fails both comparisons and stays NaN)
    x = -746.0 if x < -746.0 else x
    x = 710.0 if x > 710.0 else x
    kf = (x * _LOG2E + MAGIC) - MAGIC  # k = round(x / ln 2), |k| <= 1077
    r = (x - kf * _LN2_HI) - kf * _LN2_LO
    p = _E13
    p = p * r + _E12
    p = p * r + _E11
    p = p * r + _E10
    p = p * r + _E9
    p = p * r + _E8
    p = p * r + _E7
    p = p * r + _E6
    p = p * r + _E5
    p = p * r + _E4
    p = p * r + _E3
    p = p * r + _E2
    p = p * (r * r) + r  # exp(r) - 1, accurate for small r
    # 2^k in two factors: k alone may fall outside the normal exponents (subnormal results,
    # overflow to inf); the first product is exact, the second rounds once
    k1 = (kf * 0.5 + MAGIC) - MAGIC
    return ((p + 1.0) * _pow2(k1)) * _pow2(kf - k1)


@njit(inline="always", **_H)
def flog(x):
    """Natural logarithm, branch-free; error at most 1 ulp (see the module docstring).

    ``log(0) = -inf``, ``log(x < 0) = nan``, ``log(inf) = inf``.
    """
    sub = x < _MIN_NORMAL  # subnormal (or 0, negative): scale into the normal range first
    xs = x * _TWO_54 if sub else x
    b = f64_bits(xs)
    # the biased exponent as a float: its 11 bits under the exponent of 2^52 (the mask lets
    # LLVM shift logically; no int64 -> float64 conversion)
    eb = f64_from_bits(((b & 0x7FF0000000000000) >> 52) | 0x4330000000000000)
    ef = eb - (4503599627370496.0 + 1023.0)
    m = f64_from_bits((b & 0x000FFFFFFFFFFFFF) | 0x3FF0000000000000)  # in [1, 2)
    hi = m > _SQRT2  # m into [sqrt(2)/2, sqrt(2)]: log(1 + f) with |f| <= 0.414
    m = 0.5 * m if hi else m
    ef = ef + 1.0 if hi else ef
    ef = ef - 54.0 if sub else ef
    f = m - 1.0
    s = f / (2.0 + f)
    z = s * s
    w = z * z
    # fdlibm's split of R into even and odd powers (shorter dependency chains)
    t1 = w * (_LG2 + w * (_LG4 + w * _LG6))
    t2 = z * (_LG1 + w * (_LG3 + w * (_LG5 + w * _LG7)))
    rr = t2 + t1
    hfsq = 0.5 * f * f
    res = ef * _LN2_HI - ((hfsq - (s * (hfsq + rr) + ef * _LN2_LO)) - f)
    res = x + x if not (x < _INF) else res  # inf -> inf, nan -> nan
    res = -_INF if x == 0.0 else res
    return math.nan if x < 0.0 else res


@njit(inline="always", **_H)
def fsincos(x):
    """``(sin x, cos x)``, branch-free; absolute error <= 2.2e-16 for ``|x| <= SINCOS_MAX``.

    Beyond, the reduction is not exact (the values are bounded but meaningless): callers
    recompute those points with ``math.sin``/``math.cos``.
    """
    xc = -SINCOS_MAX if x < -SINCOS_MAX else x
    xc = SINCOS_MAX if xc > SINCOS_MAX else xc
    t = xc * _TWO_OVER_PI + MAGIC
    kf = t - MAGIC
    q = f64_bits(t) & 3  # quadrant: k mod 4 (the integer sits in the low bits)
    # the first subtraction is exact (Sterbenz), the second rounds once at |r| <= pi/4
    r = ((xc - kf * _PIO2_1) - kf * _PIO2_2) - kf * _PIO2_3
    z = r * r
    sp = _S6
    sp = sp * z + _S5
    sp = sp * z + _S4
    sp = sp * z + _S3
    sp = sp * z + _S2
    sp = sp * z + _S1
    s = r + (r * z) * sp
    cp = _C6
    cp = cp * z + _C5
    cp = cp * z + _C4
    cp = cp * z + _C3
    cp = cp * z + _C2
    cp = cp * z + _C1
    c = 1.0 - (0.5 * z - (z * z) * cp)
    # sin, cos of k pi/2 + r
    odd = (q & 1) == 1
    sn = c if odd else s
    cs = s if odd else c
    sn = -sn if q >= 2 else sn
    cs = -cs if (q == 1) or (q == 2) else cs
    return sn, cs
