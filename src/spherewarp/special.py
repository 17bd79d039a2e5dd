"""Special functions: Jacobi theta, Weierstrass ℘ and Schwarz–Christoffel maps.

Everything here is vectorised over complex NumPy arrays and accurate to a few
units in the last place of float64 (checked against mpmath in the tests).

* :func:`jtheta` -- the Jacobi theta functions θ1..θ4 (mpmath's convention,
  ``jtheta(n, z, q)`` with nome ``q``).
* :func:`weierstrass_p`, :func:`weierstrass_p_prime` -- ℘ and ℘' for the
  square lattice ``Z[i]`` (periods 1 and i) and the hexagonal lattice
  ``Z[ω]`` (periods 1 and ω = e^{iπ/3}), computed through theta functions.
  With ``normalized=True`` they return the paper's rescaled ℘̃: ℘/℘(1/2) for
  the square lattice (so ℘̃(1/2) = 1, ℘̃(i/2) = -1, ℘̃((1+i)/2) = 0) and
  ℘/(-√2 ℘(1/2)) for the hexagonal one (so ℘̃(1/2) = -1/√2).
* :func:`schwarz_christoffel` -- SC_n(z) = z ₂F₁(1/n, 2/n; 1+1/n; zⁿ) =
  ∫₀ᶻ dw/(1-wⁿ)^{2/n}, the conformal map of the unit disk onto the regular
  n-gon with vertices SC_n(1)·e^{2πik/n}; accurate on the whole closed disk.

How ℘ is computed: the argument is reduced into the fundamental
parallelogram centred at 0, and ℘ is written as the product

    ℘(u) = -π² θ1'(0)² θ1(π(u+a)) θ1(π(u-a)) / (θ1(πu)² θ1(πa)²)

where ``a`` is a zero of ℘ ((1+i)/2 for Z[i], (1+ω)/3 for Z[ω]); this is the
σ-function identity ℘(u) - ℘(a) = -σ(u+a)σ(u-a)/(σ(u)²σ(a)²) with the
exponential factors cancelled. Being a product, it keeps full relative
accuracy near the zeros of ℘ as well as near its poles. Likewise
℘'(u) = -π³ θ1'(0)³ θ1(2πu)/θ1(πu)⁴ (from ℘' = -σ(2u)/σ(u)⁴).

How SC_n is computed: by its n-fold symmetry the argument is turned into the
sector |arg z| <= π/n; near 0 the hypergeometric series in x = zⁿ is summed;
elsewhere the integral is taken from the vertex 1,
SC_n(z) = SC_n(1) - ∫_z^1 (1-w)^{-2/n} Q(w)^{-2/n} dw with
Q(w) = (1-wⁿ)/(1-w), expanding Q^{-2/n} in powers of 1-w: a series in
(1-z)^{k+1-2/n} that converges geometrically there, including at the vertex
(where the hypergeometric series converges like k^{-(2-2/n)}).
``scipy.special.hyp2f1`` is not used: for complex arguments near |x| = 1 it
loses accuracy (see the tests).

Examples
--------
>>> import numpy as np
>>> from spherewarp import special
>>> print(round(float(special.weierstrass_p(0.5, "square").real), 12))
6.875185818020
>>> special.weierstrass_p(np.array([0.5, 0.5j]), "square", normalized=True).round(12)
array([ 1.+0.j, -1.+0.j])
>>> print(round(float(special.schwarz_christoffel(1.0, 4).real), 12))   # K = Γ(1/4)²/(4√(2π))
1.311028777147
"""

from __future__ import annotations

import cmath
import functools
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .errors import InvalidValueError

__all__ = [
    "LATTICES",
    "jtheta",
    "weierstrass_p",
    "weierstrass_p_prime",
    "weierstrass_p_pair",
    "weierstrass_half_period_value",
    "reduce_to_cell",
    "schwarz_christoffel",
    "schwarz_christoffel_vertex",
    "check_lattice",
]

ComplexArray = NDArray[np.complex128]

#: the lattices that :func:`weierstrass_p` knows, by name
LATTICES = ("square", "hex")

_EPS = 1e-17


def check_lattice(lattice: str) -> str:
    """Normalise a lattice name (case-insensitive), or raise listing the allowed ones.

    ``"hexagonal"`` and ``"hex"`` are the same lattice.

    Examples
    --------
    >>> check_lattice("Square")
    'square'
    """
    name = str(lattice).strip().lower()
    name = {"hexagonal": "hex", "z[w]": "hex", "z[i]": "square"}.get(name, name)
    if name not in LATTICES:
        raise InvalidValueError(
            f"unknown lattice {lattice!r}; expected one of: {', '.join(LATTICES)}"
        )
    return name


# -- theta functions ------------------------------------------------------------
def _theta_terms(kind: int, q: complex, max_im: float) -> int:
    """How many terms the theta series needs for arguments with |Im| <= max_im."""
    aq = abs(q)
    if aq == 0:
        return 1
    lq = math.log(aq)
    off = 0.5 if kind in (1, 2) else 0.0
    logs = []
    for n in range(0, 200):
        logs.append((n + off) ** 2 * lq + (2 * n + 2 * off) * max_im)
        if n > 2 and logs[-1] < max(logs) + math.log(_EPS) and logs[-1] < logs[-2]:
            return n + 1
    return 200


def jtheta(n: int, z: ArrayLike, q: complex) -> ComplexArray:
    """The Jacobi theta function θn(z, q), n = 1..4 (mpmath's ``jtheta`` convention).

    θ1(z) = 2 Σ_{k>=0} (-1)^k q^{(k+1/2)²} sin((2k+1)z), θ2 likewise with cos
    and no sign, θ3(z) = 1 + 2 Σ_{k>=1} q^{k²} cos(2kz), θ4 with (-1)^k.
    Here ``q^{(k+1/2)²}`` means ``exp((k+1/2)² log q)`` with the principal
    logarithm. The number of terms adapts to ``|Im z|``, so the result is
    accurate to a few ulps relative to the largest term.

    Parameters
    ----------
    n : {1, 2, 3, 4}
    z : array_like, complex
    q : complex
        The nome, ``0 < |q| < 1`` (``q = e^{iπτ}``).

    Examples
    --------
    >>> print(round(float(jtheta(3, 0.0, np.exp(-np.pi)).real), 12))
    1.086434811213
    """
    if n not in (1, 2, 3, 4):
        raise InvalidValueError(f"expected n in 1..4, got {n!r}")
    q = complex(q)
    if not 0 < abs(q) < 1:
        raise InvalidValueError(f"expected a nome with 0 < |q| < 1, got {q!r}")
    zz = np.asarray(z, dtype=np.complex128)
    max_im = float(np.max(np.abs(zz.imag))) if zz.size else 0.0
    if not math.isfinite(max_im):
        raise InvalidValueError("expected finite arguments, got NaN or inf")
    nterms = _theta_terms(n, q, max_im)
    lq = cmath.log(q)
    out = np.zeros(zz.shape, np.complex128)
    if n in (1, 2):
        for k in range(nterms):
            coef = 2.0 * cmath.exp((k + 0.5) ** 2 * lq)
            if n == 1:
                out += ((-1) ** k * coef) * np.sin((2 * k + 1) * zz)
            else:
                out += coef * np.cos((2 * k + 1) * zz)
    else:
        out += 1.0
        sign = -1 if n == 4 else 1
        for k in range(1, nterms):
            coef = 2.0 * cmath.exp(k * k * lq) * sign**k
            out += coef * np.cos(2 * k * zz)
    return out


# -- Weierstrass p ----------------------------------------------------------------
@dataclass(frozen=True)
class _Lattice:
    name: str
    tau: complex  # periods 1 and tau
    q: complex  # nome e^{i pi tau}
    zero: complex  # a zero of p
    theta1_prime0: complex  # theta1'(0)
    theta1_at_zero: complex  # theta1(pi * zero)
    e1: float  # p(1/2)
    scale: complex  # p_normalized = p / scale


@functools.cache
def _lattice(name: str) -> _Lattice:
    if name == "square":
        tau = 1j
        zero = (1 + 1j) / 2
    else:
        tau = cmath.exp(1j * math.pi / 3)
        zero = (1 + tau) / 3
    q = cmath.exp(1j * math.pi * tau)
    lq = cmath.log(q)
    t1p = sum(2.0 * (-1) ** k * (2 * k + 1) * cmath.exp((k + 0.5) ** 2 * lq) for k in range(30))
    t1a = complex(jtheta(1, math.pi * zero, q))
    lat = _Lattice(name, tau, q, zero, t1p, t1a, 1.0, 1.0)
    num, den = _p_num_den(np.array([0.5 + 0j]), lat)
    e1 = float((num[0] / den[0]).real)
    scale = e1 if name == "square" else -math.sqrt(2.0) * e1
    return _Lattice(name, tau, q, zero, t1p, t1a, e1, scale)


def reduce_to_cell(z: ArrayLike, lattice: str = "square") -> ComplexArray:
    """Reduce points modulo the lattice into the parallelogram ``x + yτ``, |x|, |y| <= 1/2.

    τ is i for the square lattice and ω = e^{iπ/3} for the hexagonal one.

    Examples
    --------
    >>> reduce_to_cell(np.array([1.25 + 2.5j]), "square")
    array([0.25+0.5j])
    """
    lat = _lattice(check_lattice(lattice))
    zz = np.asarray(z, dtype=np.complex128)
    tau = lat.tau
    y = zz.imag / tau.imag
    x = zz.real - y * tau.real
    return zz - np.round(x) - np.round(y) * tau


def _p_num_den(u: ComplexArray, lat: _Lattice) -> tuple[ComplexArray, ComplexArray]:
    """℘(u) as numerator / denominator, both finite (u already reduced)."""
    a = lat.zero
    pi = math.pi
    num = (-(pi**2) * lat.theta1_prime0**2 / lat.theta1_at_zero**2) * (
        jtheta(1, pi * (u + a), lat.q) * jtheta(1, pi * (u - a), lat.q)
    )
    den = jtheta(1, pi * u, lat.q) ** 2
    return num, den


def _as_points(z: ArrayLike) -> ComplexArray:
    zz = np.asarray(z, dtype=np.complex128)
    if not np.all(np.isfinite(zz)):
        raise InvalidValueError("expected finite points of the plane, got NaN or inf")
    return zz


def weierstrass_p_pair(
    z: ArrayLike, lattice: str = "square", normalized: bool = True
) -> ComplexArray:
    """℘(z) as unit-norm homogeneous pairs ``(..., 2)``: exact at the poles.

    The lattice points give ``(1, 0)``, the point at infinity, with no
    division by zero. See :func:`weierstrass_p` for the parameters.

    Examples
    --------
    >>> weierstrass_p_pair(np.array([0.0, 1 + 1j]), "square").round(12) + 0
    array([[1.+0.j, 0.+0.j],
           [1.+0.j, 0.+0.j]])
    """
    lat = _lattice(check_lattice(lattice))
    u = reduce_to_cell(_as_points(z), lat.name)
    num, den = _p_num_den(u, lat)
    if normalized:
        num = num / lat.scale
    pair = np.stack([num, den], axis=-1)
    n = np.sqrt(np.abs(num) ** 2 + np.abs(den) ** 2)
    return pair / n[..., None]


def weierstrass_p(z: ArrayLike, lattice: str = "square", normalized: bool = False) -> ComplexArray:
    """The Weierstrass ℘ function of the square or hexagonal lattice.

    Parameters
    ----------
    z : array_like, complex
        Finite points of the plane.
    lattice : {"square", "hex"}
        ``Z[i]`` (periods 1, i) or ``Z[ω]`` (periods 1, ω = e^{iπ/3}).
    normalized : bool
        Return the paper's ℘̃ instead: ℘/℘(1/2) for the square lattice and
        ℘/(-√2 ℘(1/2)) for the hexagonal one.

    Returns
    -------
    ndarray, complex
        ``inf`` (``inf+0j``) at the lattice points, finite elsewhere.

    Examples
    --------
    >>> z = np.array([0.3 + 0.2j])
    >>> bool(np.allclose(weierstrass_p(z + 1j), weierstrass_p(z), rtol=1e-13))
    True
    >>> weierstrass_p(np.array([0.5]), "hex", normalized=True).round(12)   # -1/sqrt(2)
    array([-0.70710678+0.j])
    """
    lat = _lattice(check_lattice(lattice))
    u = reduce_to_cell(_as_points(z), lat.name)
    num, den = _p_num_den(u, lat)
    if normalized:
        num = num / lat.scale
    pole = den == 0
    with np.errstate(divide="ignore", invalid="ignore"):
        out = num / np.where(pole, 1.0, den)
    return np.where(pole, complex(np.inf, 0.0), out)


def weierstrass_p_prime(
    z: ArrayLike, lattice: str = "square", normalized: bool = False
) -> ComplexArray:
    """The derivative ℘'(z) (of ℘̃ with ``normalized=True``); ``inf`` at lattice points.

    Examples
    --------
    >>> weierstrass_p_prime(np.array([0.5, 0.5j, 0.5 + 0.5j]), "square").round(9) + 0
    array([0.+0.j, 0.+0.j, 0.+0.j])
    """
    lat = _lattice(check_lattice(lattice))
    u = reduce_to_cell(_as_points(z), lat.name)
    pi = math.pi
    num = (-(pi**3) * lat.theta1_prime0**3) * jtheta(1, 2 * pi * u, lat.q)
    den = jtheta(1, pi * u, lat.q) ** 4
    if normalized:
        num = num / lat.scale
    pole = den == 0
    with np.errstate(divide="ignore", invalid="ignore"):
        out = num / np.where(pole, 1.0, den)
    return np.where(pole, complex(np.inf, 0.0), out)


def weierstrass_half_period_value(lattice: str = "square") -> float:
    """℘(1/2) of the lattice (real and positive for both lattices).

    Examples
    --------
    >>> round(weierstrass_half_period_value("square"), 10)
    6.875185818
    """
    return _lattice(check_lattice(lattice)).e1


# -- Schwarz-Christoffel maps of the disk onto regular polygons ---------------------------
_SERIES_TERMS = 72


@functools.cache
def _sc_tables(n: int) -> tuple[float, float, NDArray[np.float64], NDArray[np.float64], float]:
    """Radius of the direct series, SC_n(1), Maclaurin and vertex coefficients."""
    a, b, c = 1.0 / n, 2.0 / n, 1.0 + 1.0 / n
    # Maclaurin coefficients of 2F1(a, b; c; x)
    mac = np.empty(_SERIES_TERMS)
    t = 1.0
    for k in range(_SERIES_TERMS):
        mac[k] = t
        t *= (a + k) * (b + k) / ((c + k) * (k + 1))
    # Q(1 - t) = (1 - (1-t)^n)/t as a polynomial in t, and the series of Q^beta
    beta = -2.0 / n
    qc = [math.comb(n, j + 1) * (-1) ** j for j in range(n)]
    f = np.empty(_SERIES_TERMS)
    f[0] = qc[0] ** beta
    for k in range(1, _SERIES_TERMS):
        s = 0.0
        for j in range(1, min(k, n - 1) + 1):
            s += ((beta + 1) * j - k) * qc[j] * f[k - j]
        f[k] = s / (k * qc[0])
    expo = np.arange(_SERIES_TERMS) + 1.0 + beta
    vertex = f / expo
    sc1 = math.gamma(1.0 / n) * math.gamma(1.0 - 2.0 / n) / (n * math.gamma(1.0 - 1.0 / n))
    # Switch to the vertex series where |z|^n > r0; r0 balances both series' convergence.
    r0 = {3: 0.4, 4: 0.35}.get(n, 0.3)
    return r0, sc1, mac, vertex, 1.0 + beta


def schwarz_christoffel_vertex(n: int) -> float:
    """SC_n(1) = Γ(1/n)Γ(1-2/n)/(n Γ(1-1/n)): the distance from the centre to a vertex.

    Examples
    --------
    >>> round(schwarz_christoffel_vertex(4), 12)
    1.311028777147
    """
    _check_n(n)
    return _sc_tables(int(n))[1]


def _check_n(n: object) -> None:
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or not 3 <= int(n) <= 64:
        raise InvalidValueError(f"expected the number of sides n as an integer 3..64, got {n!r}")


def schwarz_christoffel(z: ArrayLike, n: int = 4) -> ComplexArray:
    """The Schwarz–Christoffel map of the unit disk onto the regular n-gon.

    SC_n(z) = ∫₀ᶻ dw/(1-wⁿ)^{2/n} = z ₂F₁(1/n, 2/n; 1+1/n; zⁿ), with the
    principal branch on the closed disk. The polygon is centred at 0 with its
    vertices at ``SC_n(1) e^{2πik/n}`` (the images of the n-th roots of
    unity); the unit circle goes onto its boundary.

    Parameters
    ----------
    z : array_like, complex
        Points of the closed unit disk (|z| <= 1; a rounding excess of 1e-12
        is accepted).
    n : int
        Number of sides, 3..64.

    Returns
    -------
    ndarray, complex

    Raises
    ------
    InvalidValueError
        For points outside the closed disk or non-finite points.

    Examples
    --------
    >>> z = np.exp(1j * np.pi / 4)                   # middle of an arc: middle of an edge
    >>> k = schwarz_christoffel_vertex(4)
    >>> w = schwarz_christoffel(z, 4)
    >>> print(round(float(abs(w.real) + abs(w.imag)) / k, 12))
    1.0
    """
    _check_n(n)
    n = int(n)
    zz = np.asarray(z, dtype=np.complex128)
    if not np.all(np.isfinite(zz)):
        raise InvalidValueError("expected finite points of the closed unit disk, got NaN or inf")
    mod = np.abs(zz)
    if zz.size and float(mod.max()) > 1.0 + 1e-12:
        raise InvalidValueError(
            f"expected points of the closed unit disk, got |z| up to {float(mod.max()):.6g}"
        )
    r0, sc1, mac, vertex, expo0 = _sc_tables(n)
    # Turn into the sector |arg z| <= pi/n (by the n-fold symmetry SC(rz) = r SC(z)).
    k = np.round(np.angle(zz) * (n / (2.0 * np.pi))) % n
    rot = np.exp(2j * np.pi * k / n)
    quarter = (4 * k) % n == 0  # quarter turns are exact: keep vertices like i and -1 exact
    units = np.array([1.0, 1j, -1.0, -1j])
    rot = np.where(quarter, units[((4 * k) // n).astype(np.intp) % 4], rot)
    zs = zz * np.conj(rot)
    zs = np.where(np.abs(zs) > 1.0, zs / np.abs(np.where(zs == 0, 1.0, zs)), zs)
    out = np.empty(zz.shape, np.complex128)
    near = np.abs(zs) ** n <= r0
    if np.any(near):
        x = zs[near] ** n
        acc = np.full(x.shape, mac[-1], np.complex128)
        for coef in mac[-2::-1]:
            acc = acc * x + coef
        out[near] = zs[near] * acc
    far = ~near
    if np.any(far):
        t = 1.0 - zs[far]
        acc = np.full(t.shape, vertex[-1], np.complex128)
        for coef in vertex[-2::-1]:
            acc = acc * t + coef
        # t**expo0 with the principal branch (Re t >= 0 in the sector); t = 0 is the vertex
        with np.errstate(divide="ignore", invalid="ignore"):
            tp = np.where(t == 0, 0.0, np.exp(expo0 * np.log(np.where(t == 0, 1.0, t))))
        out[far] = sc1 - tp * acc
    return out * rot
