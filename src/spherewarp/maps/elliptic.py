"""Elliptic maps: the ℘ pull-back (toroidal images) and Lattès maps.

The paper's section "Weierstrass and Schwarz–Christoffel". The rescaled
Weierstrass function ℘̃ of the square lattice ``Z[i]`` (℘̃(1/2) = 1) or of the
hexagonal lattice ``Z[ω]`` (℘/(-√2 ℘(1/2))) maps the plane onto the Riemann
sphere; it is doubly periodic, so it is a map from a torus, a branched double
cover (:func:`sphere_from_plane`). The four branch points of the square
torus go to the nadir (∞), the zenith (0), the back (1) and the front (-1);
those of the hexagonal torus to the nadir and three points at latitude
arcsin(1/3) ≈ 19.47° (longitudes 0 and ±120°): the vertices of a regular
tetrahedron.

A lattice element α (a Gaussian integer for the square lattice, an
Eisenstein integer ``a + bω`` for the hexagonal one) gives the Lattès map
``L(z) = ℘̃(α ℘̃⁻¹(z))``, a rational map of degree |α|², well defined because
℘̃ is even and ``αΛ ⊂ Λ``. ℘̃⁻¹ is computed with the Schwarz–Christoffel maps
(:func:`weierstrass_inverse`). In the default chart (0 at the zenith, 1 at
the back) these are exactly the paper's formulas:

=========  =======================  ============================================
lattice    α                        L(z)
=========  =======================  ============================================
square     1+i                      (i/2)(-z + 1/z)
square     2                        (z²+1)²/(4z(z²-1))
square     2+i                      z((-1+2i)+z²)²/(-i+(2+i)z²)²
hex        1+ω                      (z³+√2)/(3ωz²)
=========  =======================  ============================================

:class:`Lattes` renders through the rational map fitted by the SVD
(:func:`~spherewarp.maps.fit_rational`), which is much faster than the
composition ℘̃ ∘ α ∘ ℘̃⁻¹ (``method="exact"``).

Examples
--------
>>> import numpy as np
>>> from spherewarp.maps import Lattes
>>> L = Lattes("1+i")
>>> z = np.array([0.3 + 0.4j])
>>> bool(np.allclose(L(z), 0.5j * (-z + 1 / z), rtol=1e-12))
True
>>> Lattes("1+w", lattice="hex").degree
3
"""

from __future__ import annotations

import cmath
import functools
import math
import re
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .. import coords, special
from ..errors import InvalidValueError
from .base import SphereMap, register_map
from .rational import Rational, fit_rational

__all__ = [
    "Lattes",
    "lattice_integer",
    "parse_lattice_integer",
    "sphere_from_plane",
    "weierstrass_inverse",
    "MAX_LATTES_DEGREE",
]

ComplexArray = NDArray[np.complex128]

OMEGA = cmath.exp(1j * math.pi / 3)
#: largest |α|² a Lattès map may have
MAX_LATTES_DEGREE = 64
#: largest |α|² whose rational map the SVD fit recovers in double precision (measured on
#: every α of both lattices: all fit up to 49, none of degree 57 and above, some of 50-52)
MAX_FITTED_DEGREE = 49


# -- lattice integers ----------------------------------------------------------------
def lattice_integer(a: int, b: int, lattice: str = "square") -> complex:
    """The lattice element ``a + b i`` (square) or ``a + b ω`` (hex) as a complex number.

    Examples
    --------
    >>> lattice_integer(1, 1, "hex")
    (1.5+0.8660254037844386j)
    """
    unit = 1j if special.check_lattice(lattice) == "square" else OMEGA
    return complex(a) + b * unit


_TERM = re.compile(r"([+-]?)(\d*)\*?([ijw]?)")


def parse_lattice_integer(value: Any, lattice: str = "square") -> tuple[int, int]:
    """Parse a Gaussian integer ``a+bj`` / ``a+bi`` or an Eisenstein integer ``a+bw``.

    Returns the integer coordinates ``(a, b)`` in the basis 1, i (square) or
    1, ω (hex). A complex number is accepted when it is a lattice element (to
    1e-9). Zero is refused.

    Examples
    --------
    >>> parse_lattice_integer("2-w", "hex")
    (2, -1)
    >>> parse_lattice_integer("1+1j", "square")
    (1, 1)
    >>> parse_lattice_integer("1+1j", "hex")   # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    spherewarp.errors.InvalidValueError: expected an Eisenstein integer a+bw...
    """
    lat = special.check_lattice(lattice)
    what = (
        "a Gaussian integer a+bj (e.g. 1+1j, 2, 2-1j)"
        if lat == "square"
        else "an Eisenstein integer a+bw, w = exp(i pi/3) (e.g. 1+w, 2, 2-w)"
    )
    if isinstance(value, (list, tuple)) and len(value) == 2:
        try:
            a, b = (int(v) for v in value)
            if float(value[0]) != a or float(value[1]) != b:
                raise ValueError
        except (TypeError, ValueError):
            raise InvalidValueError(f"expected {what}, got {value!r}") from None
    elif isinstance(value, str):
        text = value.strip().lower().replace(" ", "").replace("ω", "w").replace("j", "i")
        if lat == "square":
            text = text.replace("i", "j")
        allowed = "j" if lat == "square" else "w"
        a = b = 0
        pos = 0
        ok = bool(text)
        while ok and pos < len(text):
            m = _TERM.match(text, pos)
            if m is None or m.end() == pos or (not m.group(2) and not m.group(3)):
                ok = False
                break
            if pos > 0 and not m.group(1):
                ok = False
                break
            sign = -1 if m.group(1) == "-" else 1
            coef = int(m.group(2)) if m.group(2) else 1
            if m.group(3) == "":
                a += sign * coef
            elif m.group(3) == allowed:
                b += sign * coef
            else:
                ok = False
            pos = m.end()
        if not ok:
            raise InvalidValueError(f"expected {what}, got {value!r}")
    elif isinstance(value, (int, float, complex, np.number)):
        c = complex(value)
        if not cmath.isfinite(c):
            raise InvalidValueError(f"expected {what}, got {value!r}")
        if lat == "square":
            fa, fb = c.real, c.imag
        else:
            fb = c.imag / OMEGA.imag
            fa = c.real - fb * OMEGA.real
        a, b = round(fa), round(fb)
        if abs(fa - a) > 1e-9 or abs(fb - b) > 1e-9:
            raise InvalidValueError(f"expected {what}, got {value!r}, not a lattice element")
    else:
        raise InvalidValueError(f"expected {what}, got {value!r}")
    if a == 0 and b == 0:
        raise InvalidValueError(f"expected a nonzero lattice element ({what}), got 0")
    return int(a), int(b)


def _norm(a: int, b: int, lattice: str) -> int:
    return a * a + b * b if lattice == "square" else a * a + a * b + b * b


# -- the p pull-back and its inverse ----------------------------------------------------
def sphere_from_plane(u: Any, lattice: str = "square") -> ComplexArray:
    """℘̃(u) as unit-norm pairs: the point of the sphere over ``u`` (default chart).

    This is the pull-back that makes toroidal images: the colour at ``u`` of
    the plane is the panorama's colour at ``sphere_from_plane(u)``. The unit
    cell contains two copies of the sphere.

    Examples
    --------
    >>> coords.plane_from_cp1(sphere_from_plane(np.array([0.5, 0.5j, 0.5 + 0.5j]))).round(12)
    array([ 1.+0.j, -1.+0.j,  0.+0.j])
    """
    return special.weierstrass_p_pair(u, special.check_lattice(lattice), normalized=True)


@functools.cache
def _inverse_constants(lattice: str) -> tuple[complex, ...]:
    e1 = special.weierstrass_half_period_value(lattice)
    if lattice == "square":
        # p~(u) = 1/sl(sqrt(e1) u)^2 and sl^-1 = SC_4
        return (math.sqrt(e1),)
    # hex: p(k SC_6(w)) = A (1 - w^6)^(2/3) / w^2 with A^3 = -g3/16 = -e1^3/4, k = A^(-1/2)
    a_const = -e1 / 4.0 ** (1.0 / 3.0)
    scale = -math.sqrt(2.0) * e1  # p = scale * p~
    return (a_const, 1.0 / cmath.sqrt(a_const), scale)


def _principal_pow(x: ComplexArray, e: float) -> ComplexArray:
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(x == 0, 0.0, np.exp(e * np.log(np.where(x == 0, 1.0, x))))


def weierstrass_inverse(zw: ComplexArray, lattice: str = "square") -> ComplexArray:
    """A point ``u`` of the plane with ℘̃(u) = z, for unit pairs ``zw`` (default chart).

    Computed with the Schwarz–Christoffel maps on the closed unit disk:

    * square: ``u = SC_4(z^{-1/2})/√e1`` for |z| >= 1 and
      ``u = (1+i)/2 + SC_4((-z)^{1/2})/√e1`` for |z| < 1 (℘̃(u + (1+i)/2) = -1/℘̃(u));
    * hex: ``℘(κ SC_6(w)) = A (1-w⁶)^{2/3}/w²`` with ``A³ = -g3/16``,
      ``κ = A^{-1/2}``; ``w⁶`` solves a quadratic (a Joukowski map) and the
      branch comes from the equation itself; near the zenith (a vertex of the
      hexagon, where SC_6 amplifies rounding) one Newton step on ℘̃ follows.

    ℘̃ is 2:1 (on the torus), so ``u`` is one of the preimages: ``-u`` and
    the lattice translates are the others.

    Examples
    --------
    >>> z = np.array([0.3 - 2j, 0.1j, np.inf])
    >>> u = weierstrass_inverse(coords.cp1_from_plane(z), "hex")
    >>> coords.plane_from_cp1(sphere_from_plane(u, "hex")).round(12)
    array([0.3-2.j , 0. +0.1j, inf+0.j ])
    """
    lat = special.check_lattice(lattice)
    zw = coords.normalize_cp1(zw)
    z, w = zw[..., 0], zw[..., 1]
    out = np.empty(z.shape, np.complex128)
    big = np.abs(z) >= np.abs(w)  # |p~| >= 1 (includes infinity)
    consts = _inverse_constants(lat)
    if lat == "square":
        (r,) = consts
        if np.any(big):
            out[big] = special.schwarz_christoffel(np.sqrt(w[big] / z[big]), 4) / r
        small = ~big
        if np.any(small):
            out[small] = (1 + 1j) / 2 + special.schwarz_christoffel(
                np.sqrt(-z[small] / w[small]), 4
            ) / r
        return out
    a_const, kappa, scale = consts
    s = np.empty(z.shape, np.complex128)
    small = ~big
    if np.any(small):
        p = scale * z[small] / w[small]
        cube = (p / a_const) ** 3
        root = np.sqrt(cube * (cube + 4.0))
        d1, d2 = 2.0 + cube + root, 2.0 + cube - root
        first = np.abs(d1) >= np.abs(d2)
        den = np.where(first, d1, d2)
        one_minus_t = (cube + np.where(first, root, -root)) / den
        with np.errstate(divide="ignore", invalid="ignore"):
            ss = a_const * _principal_pow(one_minus_t, 2.0 / 3.0) / p
        s[small] = np.where(p == 0, 1.0, ss)
    if np.any(big):
        q = w[big] / (scale * z[big])  # 1/p
        rr = (a_const * q) ** 3  # 1/P
        root = np.sqrt(4.0 * rr + 1.0)
        root = np.where(np.abs(2 * rr + 1 + root) >= np.abs(2 * rr + 1 - root), root, -root)
        den = 2.0 * rr + 1.0 + root
        one_minus_t = (1.0 + root) / den
        s[big] = a_const * _principal_pow(one_minus_t, 2.0 / 3.0) * q
    wdisk = np.sqrt(s)
    mod = np.abs(wdisk)
    wdisk = np.where(mod > 1.0, wdisk / np.where(mod > 0, mod, 1.0), wdisk)
    out = kappa * special.schwarz_christoffel(wdisk, 6)
    # Near the zeros of p~ (the zenith) u is near a vertex of the hexagon, where SC_6 amplifies
    # rounding (error ~ eps^(2/3)); p~ is regular there, so one Newton step restores it.
    near = np.abs(z) < 0.25 * np.abs(w)
    if np.any(near):
        un = out[near]
        target = z[near] / w[near]
        step = (special.weierstrass_p(un, "hex", normalized=True) - target) / (
            special.weierstrass_p_prime(un, "hex", normalized=True)
        )
        ok = np.isfinite(step) & (np.abs(step) < 1e-3)
        out[near] = np.where(ok, un - np.where(ok, step, 0.0), un)
    return out


# -- Lattes maps ------------------------------------------------------------------------
@functools.cache
def _fitted(lattice: str, a: int, b: int) -> tuple[Rational, float]:
    exact = Lattes((a, b), lattice, method="exact")
    fit = fit_rational(exact, exact.degree)
    return fit.map, fit.residual


@register_map
class Lattes(SphereMap):
    """The Lattès map ``z -> ℘̃(α ℘̃⁻¹(z))`` of the square or hexagonal lattice.

    A rational map of degree |α|² (see the module docstring for the paper's
    formulas). Used as a pull-back it "twists" a panorama: the output is
    tiled by |α|² copies of the input, with branch points.

    Parameters
    ----------
    alpha : str, complex or (a, b)
        A nonzero lattice element: a Gaussian integer (``"1+1j"``, ``"2"``,
        ``2+1j``) for the square lattice, an Eisenstein integer
        (``"1+w"``, ``"2-w"``, ``(1, 1)`` = 1 + ω) for the hexagonal one.
        |α|² <= 64; with ``method="rational"`` |α|² <= 49, the degrees the fit
        recovers (:data:`MAX_FITTED_DEGREE`).
    lattice : {"square", "hex"}
    method : {"rational", "exact"}
        ``"rational"`` (default) evaluates the rational map fitted by the
        SVD (:meth:`rational`, computed once per α and cached); ``"exact"``
        the composition ℘̃ ∘ α ∘ ℘̃⁻¹ through theta functions and
        Schwarz–Christoffel maps (the same map, several times slower).

    Examples
    --------
    >>> L = Lattes(2)
    >>> z = np.array([0.2 + 0.7j])
    >>> bool(np.allclose(L(z), (z**2 + 1) ** 2 / (4 * z * (z**2 - 1)), rtol=1e-12))
    True
    >>> Lattes("2+w", lattice="hex").degree      # |2 + w|^2 = 4 + 2 + 1
    7
    """

    kind = "lattes"

    def __init__(self, alpha: Any = (1, 1), lattice: str = "square", method: str = "rational"):
        lat = special.check_lattice(lattice)
        a, b = parse_lattice_integer(alpha, lat)
        deg = _norm(a, b, lat)
        if deg > MAX_LATTES_DEGREE:
            raise InvalidValueError(
                f"expected |alpha|^2 <= {MAX_LATTES_DEGREE}, got {deg} for alpha = "
                f"{_format_alpha(a, b, lat)}"
            )
        meth = str(method).strip().lower()
        if meth not in ("rational", "exact"):
            raise InvalidValueError(f"unknown method {method!r}; expected one of: rational, exact")
        if meth == "rational" and deg > MAX_FITTED_DEGREE:
            why = (
                f"the fitted rational map holds for |alpha|^2 <= {MAX_FITTED_DEGREE}, got {deg} "
                f"for alpha = {_format_alpha(a, b, lat)}; use "
            )
            more = f" for degrees up to {MAX_LATTES_DEGREE}"
            raise InvalidValueError(why + "method='exact'" + more, cli=why + "--exact" + more)
        self._lattice = lat
        self._ab = (a, b)
        self._alpha = lattice_integer(a, b, lat)
        self._degree = deg
        self._method = meth

    @property
    def alpha(self) -> complex:
        """α as a complex number."""
        return self._alpha

    @property
    def lattice(self) -> str:
        return self._lattice

    @property
    def degree(self) -> int:
        """|α|²."""
        return self._degree

    @property
    def method(self) -> str:
        return self._method

    def params(self) -> dict[str, Any]:
        return {
            "alpha": _format_alpha(*self._ab, self._lattice),
            "lattice": self._lattice,
            "method": self._method,
        }

    def __repr__(self) -> str:
        return (
            f"Lattes({_format_alpha(*self._ab, self._lattice)!r}, lattice={self._lattice!r}, "
            f"method={self._method!r})"
        )

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Lattes):
            return NotImplemented
        return (self._lattice, self._ab, self._method) == (
            other._lattice,
            other._ab,
            other._method,
        )

    __hash__ = None  # type: ignore[assignment]

    def rational(self) -> Rational:
        """The map as a :class:`Rational`, fitted by the SVD (cached per α)."""
        return _fitted(self._lattice, *self._ab)[0]

    def fit_residual(self) -> float:
        """Largest chordal distance between the fitted rational map and the composition."""
        return _fitted(self._lattice, *self._ab)[1]

    def pull_cp1(self, zw: ComplexArray) -> ComplexArray:
        if self._method == "rational":
            return self.rational().pull_cp1(zw)
        return self.exact_pull_cp1(zw)

    def exact_pull_cp1(self, zw: ComplexArray) -> ComplexArray:
        """The composition ℘̃(α ℘̃⁻¹(z)) through theta and Schwarz–Christoffel functions."""
        zw = np.asarray(zw, dtype=np.complex128)
        u = weierstrass_inverse(zw, self._lattice)
        return sphere_from_plane(self._alpha * u, self._lattice)

    def local_scale(self, zw: ComplexArray) -> NDArray[np.float64]:
        if self._degree > MAX_FITTED_DEGREE:  # no fit to differentiate: finite differences
            return super().local_scale(zw)
        return self.rational().local_scale(zw)

    def kernel_stages(self) -> tuple[tuple[str, NDArray[np.float64]], ...] | None:
        """With ``method="rational"``, the fitted rational map's stage (compiled renderer)."""
        return self.rational().kernel_stages() if self._method == "rational" else None

    def as_mobius(self) -> Any:
        return self.rational().as_mobius() if self._degree == 1 else None

    def inverse(self) -> SphereMap:
        if self._degree == 1:
            return self.rational().inverse()
        return super().inverse()


def _format_alpha(a: int, b: int, lattice: str) -> str:
    unit = "j" if lattice == "square" else "w"
    if b == 0:
        return str(a)
    bs = {1: "", -1: "-"}.get(b, str(b))
    if a == 0:
        return f"{bs}{unit}"
    sign = "+" if b > 0 else ""
    return f"{a}{sign}{bs}{unit}"
