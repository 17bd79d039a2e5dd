"""Rational maps of the Riemann sphere, and fitting them to samples by SVD.

A rational map ``R(z) = N(z)/D(z)`` of degree ``d`` is evaluated in
homogeneous form on unit-norm pairs ``(z, w)``:
``N(z, w) = Σ a_k z^k w^{d-k}`` and likewise ``D``, so infinity and the poles
are ordinary points (no NaN, no overflow). Each point is evaluated in the
affine variable of modulus at most 1 (``z/w`` or ``w/z``), by Horner's rule.

:func:`fit_rational` is the paper's numerical method ("Weierstrass and
Schwarz–Christoffel"): sample a map at points ``z_j``, write
``N(z_j) - w_j D(z_j) = 0`` as one row of a matrix per sample and take the
kernel by the singular value decomposition. Here the rows are the
homogeneous form of the paper's rows ``(z_j^n ... 1, -w_j z_j^n ... -w_j)``
(multiplied by ``s_j q_j^n`` for unit-norm pairs ``(p_j, q_j)`` and
``(r_j, s_j)``), the monomials are scaled by ``sqrt(binomial(n, k))`` (the
unitarily invariant basis) and the samples are spread evenly over the sphere
(a Fibonacci sphere), which keeps the matrix well conditioned up to high
degrees.

Convention: coefficients are listed highest degree first, in the default
chart (see :mod:`spherewarp.coords`).

Examples
--------
>>> import numpy as np
>>> from spherewarp.maps import Rational, fit_rational
>>> r = Rational([1, 0, 1], [2, 0])          # (z^2 + 1)/(2z)
>>> complex(r(2.0))
(1.25+0j)
>>> fit = fit_rational(lambda z: (z**2 + 1) / (2 * z))
>>> fit.degree, fit.map.denominator.round(12).tolist()
(2, [(1+0j), 0j])
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .. import coords
from ..errors import InvalidTypeError, InvalidValueError
from .base import SphereMap, register_map

__all__ = ["Rational", "RationalFit", "fit_rational", "fibonacci_cp1"]

ComplexArray = NDArray[np.complex128]

#: coefficients below this, relative to the largest, are set to zero in fitted maps
CLEAN_REL = 1e-11
#: largest degree :func:`fit_rational` looks for when none is given
MAX_DEGREE = 32
#: relative smallest singular value below which a kernel is found
KERNEL_REL = 1e-9
#: largest chordal residual of an accepted fit
RESIDUAL_TOL = 1e-8


def _coef(v: Any) -> complex:
    if isinstance(v, (list, tuple)) and len(v) == 2:
        return complex(float(v[0]), float(v[1]))
    if isinstance(v, str):
        return complex(v.replace(" ", "").replace("i", "j"))
    return complex(v)


def _as_coefficients(values: Any, name: str) -> ComplexArray:
    if isinstance(values, np.ndarray):
        seq = list(values.ravel()) if values.ndim <= 1 else None
    elif isinstance(values, (list, tuple)):
        seq = list(values)
    else:
        seq = None
    if seq is None:
        raise InvalidValueError(
            f"{name}: expected a list of coefficients (highest degree first), got {values!r:.80}"
        )
    try:
        arr = np.array([_coef(v) for v in seq], dtype=np.complex128)
    except (TypeError, ValueError):
        raise InvalidValueError(
            f"{name}: expected complex coefficients (numbers, [re, im] pairs or strings like "
            f"'1+2j'), got {values!r:.80}"
        ) from None
    if arr.size == 0 or not np.all(np.isfinite(arr)):
        raise InvalidValueError(f"{name}: expected finite coefficients, got {values!r:.80}")
    nz = np.flatnonzero(arr)
    if nz.size == 0:
        raise InvalidValueError(f"{name}: expected a nonzero polynomial, got all zeros")
    return arr[nz[0] :]


def _horner(coefs: ComplexArray, t: ComplexArray) -> tuple[ComplexArray, ComplexArray]:
    """Value and derivative of ``Σ coefs[j] t^(len-1-j)`` (highest first)."""
    p = np.full(t.shape, coefs[0], np.complex128)
    dp = np.zeros(t.shape, np.complex128)
    for c in coefs[1:]:
        dp = dp * t + p
        p = p * t + c
    return p, dp


@register_map
class Rational(SphereMap):
    """A rational map ``z -> N(z)/D(z)`` of the Riemann sphere.

    Parameters
    ----------
    numerator, denominator : sequence
        Coefficients, highest degree first: numbers, ``[re, im]`` pairs or
        strings like ``"1+2j"``. Leading zeros are dropped; neither may be
        all zero. Common factors are not cancelled.

    Notes
    -----
    The degree is ``max(deg N, deg D)``; the map takes ∞ to ``a_d / b_d``
    (∞ if ``deg N > deg D``). ``local_scale`` is exact:
    ``|R'(z)| (1 + |z|²)/(1 + |R(z)|²)``.

    Examples
    --------
    >>> r = Rational([[0, -0.5], 0, [0, 0.5]], [1, 0])      # (i/2)(-z + 1/z)
    >>> r.degree
    2
    >>> r(np.array([0, np.inf, 1j])).round(12)
    array([inf+0.j, inf+0.j, 0.+1.j])
    """

    kind = "rational"

    def __init__(self, numerator: Sequence[Any], denominator: Sequence[Any]):
        num = _as_coefficients(numerator, "numerator")
        den = _as_coefficients(denominator, "denominator")
        d = max(num.size, den.size) - 1
        self._num = num
        self._den = den
        padded_n = np.concatenate([np.zeros(d + 1 - num.size, np.complex128), num])
        padded_d = np.concatenate([np.zeros(d + 1 - den.size, np.complex128), den])
        for arr in (num, den, padded_n, padded_d):
            arr.flags.writeable = False
        self._pn = padded_n
        self._pd = padded_d
        self._degree = d

    # -- access ---------------------------------------------------------------
    @property
    def numerator(self) -> ComplexArray:
        """Numerator coefficients, highest degree first (read-only)."""
        return self._num

    @property
    def denominator(self) -> ComplexArray:
        """Denominator coefficients, highest degree first (read-only)."""
        return self._den

    @property
    def degree(self) -> int:
        """``max(deg N, deg D)`` (the topological degree when there is no common factor)."""
        return self._degree

    def params(self) -> dict[str, Any]:
        return {
            "numerator": [[float(c.real), float(c.imag)] for c in self._num],
            "denominator": [[float(c.real), float(c.imag)] for c in self._den],
        }

    @classmethod
    def _from_params(cls, params: dict[str, Any]) -> Rational:
        extra = set(params) - {"numerator", "denominator", "degree", "residual"}
        if extra:
            raise TypeError(f"unexpected keys {sorted(extra)}")
        return cls(params["numerator"], params["denominator"])

    def __repr__(self) -> str:
        def fmt(arr: ComplexArray) -> str:
            return "[" + ", ".join(f"{c.real:.6g}{c.imag:+.6g}j" for c in arr) + "]"

        return f"Rational({fmt(self._num)}, {fmt(self._den)})"

    def isclose(self, other: Rational, rtol: float = 1e-9) -> bool:
        """True if both are the same map up to a common scale of the coefficients."""
        a = np.concatenate([self._pn, self._pd])
        b = np.concatenate([other._pn, other._pd])
        if a.size != b.size:
            return False
        k = int(np.argmax(np.abs(a)))
        if b[k] == 0:
            return False
        b = b * (a[k] / b[k])
        return bool(np.max(np.abs(a - b)) <= rtol * np.max(np.abs(a)))

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Rational):
            return NotImplemented
        return self.isclose(other, 1e-12)

    __hash__ = None  # type: ignore[assignment]

    # -- the map protocol -------------------------------------------------------
    def _eval(self, zw: ComplexArray, deriv: bool) -> tuple[ComplexArray, ...]:
        zw = np.asarray(zw, dtype=np.complex128)
        z, w = zw[..., 0], zw[..., 1]
        low = np.abs(z) <= np.abs(w)
        n = np.empty(z.shape, np.complex128)
        d = np.empty(z.shape, np.complex128)
        dn = np.empty(z.shape, np.complex128) if deriv else None
        dd = np.empty(z.shape, np.complex128) if deriv else None
        t = np.empty(z.shape, np.complex128)
        for sel, flip in ((low, False), (~low, True)):
            if not np.any(sel):
                continue
            if flip:  # t = w/z: N = z^d * sum a_k t^(d-k), coefficients reversed
                ts = w[sel] / z[sel]
                coefs_n, coefs_d = self._pn[::-1], self._pd[::-1]
            else:
                ts = z[sel] / w[sel]
                coefs_n, coefs_d = self._pn, self._pd
            t[sel] = ts
            n[sel], dns = _horner(coefs_n, ts)
            d[sel], dds = _horner(coefs_d, ts)
            if deriv:
                dn[sel] = dns
                dd[sel] = dds
        return n, d, t, dn, dd

    def pull_cp1(self, zw: ComplexArray) -> ComplexArray:
        n, d, _, _, _ = self._eval(zw, False)
        return coords.normalize_cp1(np.stack([n, d], axis=-1))

    def local_scale(self, zw: ComplexArray) -> NDArray[np.float64]:
        """Exact spherical magnification ``|N'D - ND'| (1 + |t|²)/(|N|² + |D|²)``.

        ``t`` is the affine coordinate of modulus <= 1 (``z/w`` or ``w/z``;
        ``t -> 1/t`` is an isometry of the sphere).
        """
        n, d, t, dn, dd = self._eval(zw, True)
        num = np.abs(dn * d - n * dd) * (1.0 + np.abs(t) ** 2)
        den = np.abs(n) ** 2 + np.abs(d) ** 2
        with np.errstate(divide="ignore", invalid="ignore"):
            out = num / den
        return np.where(den > 0, out, 0.0)

    def kernel_stages(self) -> tuple[tuple[str, NDArray[np.float64]], ...]:
        """One ``"rational"`` stage: ``[d, N, D]`` (zero-padded, ``(re, im)`` pairs)."""
        from ..render.stages import RATIONAL

        coefs = np.concatenate([self._pn, self._pd])
        return (("rational", RATIONAL.pack(degree=self._degree, coefficients=coefs)),)

    def as_mobius(self) -> Any:
        if self._degree != 1:
            return None
        from .mobius import Mobius

        m = np.array([[self._pn[0], self._pn[1]], [self._pd[0], self._pd[1]]])
        if abs(m[0, 0] * m[1, 1] - m[0, 1] * m[1, 0]) < 1e-13 * np.abs(m).max() ** 2:
            return None
        return Mobius(m)

    def inverse(self) -> SphereMap:
        mob = self.as_mobius()
        if mob is None:
            raise InvalidValueError(
                f"a rational map of degree {self._degree} has no single-valued inverse"
            )
        return mob.inverse()


# -- fitting ------------------------------------------------------------------------
@dataclass(frozen=True)
class RationalFit:
    """The result of :func:`fit_rational`.

    Attributes
    ----------
    map : Rational
        The fitted map, scaled so that the leading denominator coefficient is 1.
    degree : int
        Its degree.
    residual : float
        Largest chordal distance (``|z1 w2 - z2 w1|`` of unit pairs, half
        the Euclidean distance on the unit sphere) between the map and the
        samples; for a map or a function, also over as many points that the
        fit did not use.
    singular_values : ndarray
        The singular values of the (scaled) matrix at the fitted degree,
        largest first; the last one, relative to the first, says how exact
        the kernel is.
    """

    map: Rational
    degree: int
    residual: float
    singular_values: NDArray[np.float64]

    def to_dict(self) -> dict[str, Any]:
        """``{"kind": "rational", "numerator": ..., "denominator": ..., "degree", "residual"}``."""
        return {**self.map.to_dict(), "degree": self.degree, "residual": self.residual}


def fibonacci_cp1(n: int, phase: float = 0.1234) -> ComplexArray:
    """``n`` points spread evenly over the sphere (a Fibonacci sphere), as unit pairs.

    The points avoid both poles and the real axis of the default chart
    (where many maps have special values).

    Examples
    --------
    >>> fibonacci_cp1(100).shape
    (100, 2)
    """
    k = np.arange(n) + 0.5
    zc = 1.0 - 2.0 * k / n
    r = np.sqrt(1.0 - zc**2)
    phi = k * math.pi * (3.0 - math.sqrt(5.0)) + phase
    xyz = np.stack([r * np.cos(phi), r * np.sin(phi), zc], axis=-1)
    return coords.cp1_from_xyz(xyz)


def _undefined(v: ComplexArray) -> NDArray[np.bool_]:
    """NaN with no infinite part (an infinite part, as in inf+nanj from z/0, is infinity)."""
    return np.isnan(v) & ~(np.isinf(v.real) | np.isinf(v.imag))


def _samples(
    func_or_samples: Any, count: int, phase: float = 0.1234
) -> tuple[ComplexArray, ComplexArray]:
    """Unit pairs (inputs, outputs) from a map, a plane function or given samples."""
    if isinstance(func_or_samples, SphereMap):
        zin = fibonacci_cp1(count, phase)
        return zin, coords.normalize_cp1(func_or_samples.pull_cp1(zin))
    if callable(func_or_samples):
        zin = fibonacci_cp1(count, phase)
        zp = coords.plane_from_cp1(zin)
        try:
            with np.errstate(all="ignore"):
                out = np.asarray(func_or_samples(zp), dtype=np.complex128)
        except (TypeError, ValueError) as exc:
            raise InvalidValueError(
                f"the function failed on an array of complex points: {exc}"
            ) from None
        if out.shape != zp.shape:
            out = np.broadcast_to(out, zp.shape)
        keep = ~_undefined(out)
        return zin[keep], coords.cp1_from_plane(out[keep])
    if isinstance(func_or_samples, (tuple, list)) and len(func_or_samples) == 2:
        a, b = (np.asarray(v, dtype=np.complex128) for v in func_or_samples)
        if a.ndim == 2 and a.shape[-1] == 2 and b.shape == a.shape:
            zin, zout = coords.normalize_cp1(a), coords.normalize_cp1(b)
        elif a.ndim == 1 and b.shape == a.shape:
            keep = ~(_undefined(a) | _undefined(b))
            zin, zout = coords.cp1_from_plane(a[keep]), coords.cp1_from_plane(b[keep])
        else:
            raise InvalidValueError(
                "expected samples as (z, w) with z and w 1-D arrays of plane points of one "
                f"length, or (m, 2) arrays of pairs; got shapes {a.shape} and {b.shape}"
            )
        return zin, zout
    raise InvalidTypeError(
        "expected a SphereMap, a function of complex arrays or samples (z, w), got "
        f"{type(func_or_samples).__name__}"
    )


def _matrix(zin: ComplexArray, zout: ComplexArray, n: int) -> tuple[ComplexArray, NDArray]:
    p, q = zin[:, 0], zin[:, 1]
    r, s = zout[:, 0], zout[:, 1]
    k = np.arange(n, -1, -1)
    scale = np.sqrt(np.array([math.comb(n, int(j)) for j in k], dtype=np.float64))
    mono = p[:, None] ** k * q[:, None] ** (n - k) * scale
    m = np.concatenate([s[:, None] * mono, -r[:, None] * mono], axis=1)
    return m, scale


def _residual(fitted: Rational, zin: ComplexArray, zout: ComplexArray) -> float:
    got = fitted.pull_cp1(zin)
    return float(np.max(np.abs(got[:, 0] * zout[:, 1] - got[:, 1] * zout[:, 0])))


def _smallest_rel(zin: ComplexArray, zout: ComplexArray, n: int) -> float:
    sv = np.linalg.svd(_matrix(zin, zout, n)[0], compute_uv=False)
    return float(sv[-1] / sv[0])


def _clean(c: ComplexArray, tiny: float) -> ComplexArray:
    """Real and imaginary parts below ``tiny`` set to zero (and -0.0 to 0.0)."""
    re = np.where(np.abs(c.real) < tiny, 0.0, c.real) + 0.0
    im = np.where(np.abs(c.imag) < tiny, 0.0, c.imag) + 0.0
    return re + 1j * im


def fit_rational(
    func_or_samples: SphereMap | Callable[[ComplexArray], ComplexArray] | tuple[Any, Any],
    degree: int | None = None,
    *,
    max_degree: int = MAX_DEGREE,
    n_samples: int | None = None,
    tol: float = RESIDUAL_TOL,
) -> RationalFit:
    """Fit a rational map to a map of the sphere by the SVD (the paper's method).

    Parameters
    ----------
    func_or_samples : SphereMap, callable or (z, w)
        A map (sampled in homogeneous form: poles and ∞ are fine), a
        function of complex arrays of plane points (``inf`` results are the
        point at infinity, NaN samples are dropped), or samples ``(z, w)``
        with ``w_j = f(z_j)``: 1-D arrays of plane points or ``(m, 2)``
        arrays of homogeneous pairs.
    degree : int, optional
        The degree. Default: the smallest degree whose matrix has a kernel
        (smallest singular value below ``1e-9`` of the largest), up to
        ``max_degree``.
    max_degree : int
        Largest degree tried when detecting it.
    n_samples : int, optional
        Points sampled for a map or function (default: enough for the degree,
        at least 64).
    tol : float
        Largest accepted residual (chordal distance, see :class:`RationalFit`).

    Returns
    -------
    RationalFit
        The map (leading denominator coefficient 1, coefficients below
        ``1e-11`` of the largest set to zero), its degree and residual.

    Raises
    ------
    InvalidValueError
        If the map is not rational of the given degree (or of any degree up
        to ``max_degree``), if its degree is lower than the one given, or if
        there are too few samples.

    Examples
    --------
    >>> fit = fit_rational(lambda z: (z**2 + 1)**2 / (4 * z * (z**2 - 1)))
    >>> fit.degree, bool(fit.residual < 1e-12)
    (4, True)
    >>> (fit.map.numerator * 4).round(12).tolist()
    [(1+0j), 0j, (2+0j), 0j, (1+0j)]
    >>> fit_rational(np.exp, max_degree=6)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    spherewarp.errors.InvalidValueError: not a rational map of degree 1..6: ...
    """
    if degree is not None and (
        isinstance(degree, bool) or not isinstance(degree, (int, np.integer)) or degree < 1
    ):
        raise InvalidValueError(f"expected a degree >= 1, got {degree!r}")
    if isinstance(max_degree, bool) or not isinstance(max_degree, (int, np.integer)):
        raise InvalidValueError(f"expected an integer max_degree, got {max_degree!r}")
    top = int(degree) if degree is not None else int(max_degree)
    if top < 1 or top > 256:
        raise InvalidValueError(f"expected a degree between 1 and 256, got {top}")
    count = int(n_samples) if n_samples is not None else max(64, 6 * (top + 1))
    zin, zout = _samples(func_or_samples, count)
    sampled = isinstance(func_or_samples, SphereMap) or callable(func_or_samples)
    check = _samples(func_or_samples, count, phase=2.0) if sampled else None
    need = 2 * top + 3
    if degree is None and not sampled:  # given samples: look as high as they allow
        top = max(1, min(top, (zin.shape[0] - 3) // 2))
        need = 2 * top + 3
    if zin.shape[0] < need:
        raise InvalidValueError(
            f"expected at least {need} samples for degree {top}, got {zin.shape[0]}"
        )
    degrees = [top] if degree is not None else range(1, top + 1)
    best = None
    worst = None
    for n in degrees:
        m, scale = _matrix(zin, zout, n)
        _, sv, vh = np.linalg.svd(m, full_matrices=False)
        rel = sv[-1] / sv[0]
        if degree is None and rel > KERNEL_REL:
            best = rel if best is None else min(best, rel)
            continue
        if sv.size > 1 and sv[-2] / sv[0] < KERNEL_REL:
            if degree is None:  # not one-dimensional: no rational map of this degree
                continue
            lower = next((k for k in range(1, n) if _smallest_rel(zin, zout, k) < KERNEL_REL), None)
            where = f" (it looks like degree {lower})" if lower else ""
            # the monomial basis in double precision: from about degree 50, a map of the
            # full degree can look lower (z**57 looked like degree 56)
            maybe = (
                f", or degree {n} is more than double precision tells apart on these samples"
                if n > 40 else ""
            )  # fmt: skip
            raise InvalidValueError(
                f"the map has a degree lower than {n}{where}{maybe}: the kernel is not "
                "one-dimensional; give a smaller degree or none to detect it"
            )
        x = np.conj(vh[-1])
        num, den = x[: n + 1] * scale, x[n + 1 :] * scale
        big = max(np.abs(num).max(), np.abs(den).max())
        nzd = np.flatnonzero(np.abs(den) > CLEAN_REL * big)
        if nzd.size == 0 or not np.any(np.abs(num) > CLEAN_REL * big):
            raise InvalidValueError(
                "the fit gave a degenerate map (a zero numerator or denominator)"
            )
        lead = den[nzd[0]]
        num, den = num / lead, den / lead
        den[nzd[0]] = 1.0
        tiny = CLEAN_REL * max(np.abs(num).max(), np.abs(den).max())
        fitted = Rational(_clean(num, tiny), _clean(den, tiny))
        residual = _residual(fitted, zin, zout)
        if residual <= tol and check is not None:  # and on points the fit has not seen
            residual = max(residual, _residual(fitted, *check))
        if residual > tol:
            if degree is None:  # a near-kernel of a map that is not rational: keep looking
                worst = residual if worst is None else min(worst, residual)
                continue
            raise InvalidValueError(
                f"not a rational map of degree {n}: the best fit misses the samples by "
                f"{residual:.3g} (chordal), more than the tolerance {tol:.3g}"
            )
        return RationalFit(fitted, n, residual, sv)
    if worst is not None:
        raise InvalidValueError(
            f"not a rational map of degree 1..{top}: the best fit misses the samples by "
            f"{worst:.3g} (chordal), more than the tolerance {tol:.3g}; give the degree "
            "(--degree) if it is higher"
        )
    detail = f" (smallest relative singular value {best:.3g})" if best is not None else ""
    raise InvalidValueError(
        f"not a rational map of degree 1..{top}: no one-dimensional kernel found{detail}; "
        "give the degree (--degree) if it is higher"
    )
