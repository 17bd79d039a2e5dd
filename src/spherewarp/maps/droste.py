"""Straight and twisted Droste maps of the sphere.

A Droste image contains a scaled copy of itself. On the sphere (paper,
"The Droste effect") the copies live in a chart ``zeta`` with 0 at the centre
``c`` of a frame and infinity at a second point ``a`` (by default the antipode
of ``c``). The *hole* ``H`` is the inside of the frame, a region star-shaped
about ``c``: in the chart its boundary is ``|zeta| = r(theta)``. The *annulus*
``A`` is the part of the sphere outside ``H`` and inside ``lambda H``, and
copies ``lambda**k A`` of it tile the sphere minus ``c`` and ``a``.

Everything is easiest in log coordinates ``L = log zeta = u + i theta``: the
annulus is the strip ``rho(theta) <= u < rho(theta) + log(lambda)`` with
``rho = log r``, and the straight Droste image is periodic under the lattice
``Lambda`` spanned by ``log(lambda)`` and ``2 pi i``.

* Straight: an output point ``L`` is pulled back to ``L - k log(lambda)``, the
  one translate that lies in the strip.
* Twisted (De Smit and Lenstra, Escher's *Print Gallery*): a primitive period
  ``P = s log(lambda) + p 2 pi i`` of ``Lambda`` (``s`` strands, periodicity
  ``p``) is turned and scaled to ``2 pi i``: the output point ``L`` is first
  sent to ``beta (L - L0) + L0`` with ``beta = P / (2 pi i)``, then reduced as
  for the straight map. Since ``2 pi i beta = P`` lies in ``Lambda`` the result
  is single-valued on the sphere. ``L0 = mean(rho)`` (the hole's mean
  log-radius) only fixes where the output matches the input best: along the
  hole's edge in the direction ``theta = 0``.

Both are invariant under a similarity of the chart (:meth:`Droste.symmetry`):
the zoom by ``lambda`` about ``c`` for the straight map, a spiral similarity
for the twisted one. The zoom phase ``t`` (:attr:`Droste.phase`) pre-composes
the map with the ``t``-th power of that similarity, so phase 1 is phase 0 and
``N`` phases ``k/N`` make a seamless loop, zooming *into* the frame.

Building a hole from the corners of a real frame, a mask or a radius, and
choosing ``lambda``, is in :mod:`spherewarp.effects.droste`; this module holds the maps
(the hole enters as samples of ``rho``, see :func:`droste_chart`).

Convention: points are unit-norm pairs in the default chart
(:mod:`spherewarp.coords`); angles of the Droste chart are measured so that
the direction "up" (towards the zenith) at the centre is ``theta = +90``
degrees, counter-clockwise as seen from inside the sphere.

Examples
--------
>>> import numpy as np
>>> from spherewarp.maps import Droste
>>> rho = np.full(64, np.log(np.tan(np.radians(10) / 2)))   # a round hole, radius 10 deg
>>> d = Droste((0, 0), rho, scale=4.0)
>>> d.apply_lonlat([[0.0, 15.0], [0.0, 5.0]]).round(6) + 0.0   # annulus: fixed; hole: scaled
array([[ 0.      , 15.      ],
       [ 0.      , 19.812881]])
"""

from __future__ import annotations

import cmath
import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import coords
from ..errors import InvalidTypeError, InvalidValueError
from .base import PullBack, SphereMap, register_map
from .mobius import Mobius, PointLike, as_cp1_point

__all__ = ["Droste", "TwistedDroste", "droste_chart"]

ComplexArray = NDArray[np.complex128]

#: log|zeta| at the fixed points themselves (instead of -inf / +inf)
_LOG_TINY = math.log(1e-300)
#: local scale reported at the two fixed points, where it is unbounded
SCALE_CAP = 1e8


def droste_chart(center: PointLike, far: PointLike | None = None) -> Mobius:
    """The chart ``zeta`` of a Droste map: 0 at ``center``, infinity at ``far``.

    For ``far=None`` (the antipode of ``center``) the chart is a rotation of
    the sphere, so ``|zeta| = tan(d/2)`` at angular distance ``d`` from the
    centre. It is turned so that the direction towards the zenith at the
    centre is ``arg zeta = +90`` degrees (at a pole: towards longitude 180 at
    the north pole, 0 at the south pole).

    Parameters
    ----------
    center, far : point
        Any point form of :func:`~spherewarp.maps.as_cp1_point`.

    Returns
    -------
    Mobius
        The map from default-chart points to ``zeta``.

    Raises
    ------
    InvalidValueError
        If ``far`` is (numerically) the centre.

    Examples
    --------
    >>> ch = droste_chart((30, 10))
    >>> complex(ch(coords.plane_from_lonlat(np.radians([30, 10])))).__abs__() < 1e-12
    True
    >>> ch.is_rotation()
    True
    """
    c = as_cp1_point(center, "center")
    a = coords.antipode_cp1(c) if far is None else as_cp1_point(far, "far")
    if abs(complex(c[0] * a[1] - c[1] * a[0])) < 1e-9:
        raise InvalidValueError("the far fixed point must differ from the centre")
    m = Mobius([[c[1], -c[0]], [a[1], -a[0]]])
    xyz = coords.xyz_from_cp1(c)
    lon, lat = coords.lonlat_from_xyz(xyz)
    up = np.array([-np.sin(lat) * np.cos(lon), -np.sin(lat) * np.sin(lon), np.cos(lat)])
    p = xyz + 1e-6 * up
    zeta = complex(coords.plane_from_cp1(m.pull_cp1(coords.cp1_from_xyz(p / np.linalg.norm(p)))))
    half = (0.5 * math.pi - cmath.phase(zeta)) / 2
    turn = Mobius([[cmath.exp(1j * half), 0], [0, cmath.exp(-1j * half)]])
    out = turn @ m
    assert isinstance(out, Mobius)
    return out


def _lonlat_deg(zw: NDArray[np.complex128]) -> list[float]:
    lon, lat = np.degrees(coords.lonlat_from_cp1(zw))
    return [float(lon), float(lat)]


def _check_int(value: Any, name: str) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        if isinstance(value, float) and value.is_integer():
            return int(value)
        raise InvalidTypeError(f"{name}: expected an integer, got {value!r}")
    return int(value)


def check_phase(phase: Any) -> float:
    """A zoom phase as a finite float (:class:`InvalidValueError` otherwise)."""
    try:
        t = float(phase)
    except (TypeError, ValueError):
        raise InvalidValueError(f"phase: expected a number, got {phase!r}") from None
    if not math.isfinite(t):
        raise InvalidValueError(f"phase: expected a finite number, got {phase!r}")
    return t


def _coefficients(strands: int, periodicity: int) -> tuple[int, int]:
    """Integers ``(c, d)`` with ``periodicity * c - strands * d == 1``."""
    # extended Euclid on (periodicity, -strands)
    old_r, r = periodicity, -strands
    old_s, s = 1, 0
    old_t, t = 0, 1
    while r != 0:
        q = old_r // r
        old_r, r = r, old_r - q * r
        old_s, s = s, old_s - q * s
        old_t, t = t, old_t - q * t
    if old_r < 0:
        old_r, old_s, old_t = -old_r, -old_s, -old_t
    # periodicity * old_s + (-strands) * old_t == old_r == 1
    return old_s, old_t


@register_map
class Droste(SphereMap):
    """The straight Droste map: copies of an annulus, scaled by powers of ``scale``.

    Output point ``zeta`` (in the chart of :func:`droste_chart`) is pulled back
    to ``zeta / scale**k``, the one copy that lies in the annulus between the
    hole and the hole scaled by ``scale``. The tile index ``k``
    (:meth:`tile_index`) is 0 on the annulus itself (where the map is the
    identity), negative inside the frame and positive towards ``far``.

    Usually built by :func:`spherewarp.effects.droste.droste_map` from a frame.

    Parameters
    ----------
    center : point
        The centre of the hole (any form of :func:`~spherewarp.maps.as_cp1_point`,
        e.g. ``(lon, lat)`` in degrees): the fixed point inside the frame.
    rho : array_like, shape (n,)
        The hole: ``log r(theta)`` at ``theta = -pi + 2 pi j / n`` in the chart
        ``droste_chart(center, far)``; linear interpolation in between.
        At least 8 finite samples.
    scale : float
        ``lambda > 1``: the annulus runs from the hole to the hole scaled by it.
    far : point, optional
        The second fixed point (default: the antipode of ``center``).
    phase : float
        Zoom phase ``t``: the image is pushed by ``symmetry() ** t``
        (``t = 1`` is the same image as ``t = 0``, and with ``n_images``
        images ``t = n_images`` is; growing ``t`` flies into the frame).
    n_images : int
        Copy at depth ``d`` (``d = -k``; 1 is the first copy inside the frame)
        takes its content from input image ``d mod n_images``
        (:attr:`~spherewarp.maps.PullBack.sheet`).

    Raises
    ------
    InvalidValueError
        For a scale <= 1, bad ``rho``, coincident fixed points, a bad phase or
        ``n_images < 1``.

    Examples
    --------
    >>> rho = np.full(64, np.log(0.2))
    >>> d = Droste((0, 0), rho, 3.0)
    >>> z = d.chart.inverse()(np.array([0.5, 0.1, 0.03]))   # chart points -> default chart
    >>> (d.chart(d(z)) ).round(9)                         # ... their copies in the annulus
    array([0.5 +0.j, 0.3 +0.j, 0.27+0.j])
    >>> d.tile_index(coords.cp1_from_plane(z))
    array([ 0, -1, -2])
    """

    kind = "droste"
    _strands = 0
    _periodicity = 1

    def __init__(
        self,
        center: PointLike,
        rho: ArrayLike,
        scale: float,
        *,
        far: PointLike | None = None,
        phase: float = 0.0,
        n_images: int = 1,
    ):
        self._center = as_cp1_point(center, "center")
        self._far = None if far is None else as_cp1_point(far, "far")
        self._chart = droste_chart(self._center, self._far)
        self._chart_inv = self._chart.inverse()
        try:
            r = np.array(rho, dtype=np.float64)
        except (TypeError, ValueError):
            raise InvalidValueError(f"rho: expected an array of numbers, got {rho!r:.80}") from None
        if r.ndim != 1 or r.size < 8 or not np.all(np.isfinite(r)) or np.abs(r).max() > 300:
            raise InvalidValueError(
                f"rho: expected at least 8 finite log-radii of moderate size, got shape {r.shape}"
            )
        r.flags.writeable = False
        self._rho = r
        try:
            lam = float(scale)
        except (TypeError, ValueError):
            raise InvalidValueError(f"scale: expected a number > 1, got {scale!r}") from None
        if not (math.isfinite(lam) and lam > 1.0):
            raise InvalidValueError(
                f"scale: expected a Droste scale > 1 (the annulus runs from the hole to the "
                f"hole scaled by it), got {scale!r}"
            )
        if lam > 1e100:
            raise InvalidValueError(f"scale: expected a scale below 1e100, got {scale!r}")
        self._scale = lam
        self._ell = math.log(lam)
        self._phase = check_phase(phase)
        n = _check_int(n_images, "n_images")
        if n < 1:
            raise InvalidValueError(f"n_images: expected an integer >= 1, got {n_images!r}")
        self._n_images = n
        #: the phase the map uses: the same image, reduced by its period (``n_images`` whole
        #: zooms), so that a phase of 1e12 is not 1e12 log(lambda) away in the log plane
        self._shift = math.fmod(self._phase, float(self._n_images))
        self._setup_twist()

    def _setup_twist(self) -> None:
        s, p = self._strands, self._periodicity
        ell = self._ell
        self._period = complex(s * ell, p * 2 * math.pi)  # P, made vertical of height 2 pi
        self._beta = self._period / (2j * math.pi)
        c, d = _coefficients(s, p)
        self._q = complex(c * ell, d * 2 * math.pi)  # the other generator of the lattice
        self._pivot = float(self._rho.mean())  # L0: the hole

    # -- properties -------------------------------------------------------------
    @property
    def center(self) -> NDArray[np.complex128]:
        """The fixed point inside the frame (unit-norm pair)."""
        return self._center.copy()

    @property
    def far(self) -> NDArray[np.complex128]:
        """The other fixed point (unit-norm pair): the antipode unless one was given."""
        return coords.antipode_cp1(self._center) if self._far is None else self._far.copy()

    @property
    def chart(self) -> Mobius:
        """The chart ``zeta`` (:func:`droste_chart`)."""
        return self._chart

    @property
    def rho(self) -> NDArray[np.float64]:
        """The samples of ``log r(theta)`` (read-only)."""
        return self._rho

    @property
    def scale(self) -> float:
        """``lambda``."""
        return self._scale

    @property
    def phase(self) -> float:
        """The zoom phase ``t``."""
        return self._phase

    @property
    def n_images(self) -> int:
        """How many input images the copies cycle through."""
        return self._n_images

    @property
    def n_sheets(self) -> int:  # type: ignore[override]
        return self._n_images

    @property
    def beta(self) -> complex:
        """The factor of the twist in log coordinates (1 for the straight map)."""
        return self._beta

    @property
    def period(self) -> complex:
        """The period ``P = s log(lambda) + p 2 pi i`` of the input log plane made vertical."""
        return self._period

    @property
    def second_period(self) -> complex:
        """``Q``: the lattice vector that makes ``(P, Q)`` a positive basis.

        ``Q = log(lambda)`` for the straight map. The phase moves the input log
        plane by ``-phase * Q``.
        """
        return self._q

    @property
    def pivot(self) -> float:
        """``L0``: the log-radius the twist turns about (the hole's mean log-radius)."""
        return self._pivot

    @property
    def symmetry_factor(self) -> complex:
        """The factor ``q`` with ``D(q zeta) == D(zeta)``: ``lambda`` for the straight map.

        For the twisted map it is ``exp(2 pi i Q / P)``, ``Q`` the lattice vector
        that completes ``P`` to a positive basis: a spiral similarity.
        """
        return cmath.exp(self._q / self._beta)

    def symmetry(self, power: float = 1.0) -> Mobius:
        """The Möbius map ``zeta -> q**power zeta`` that leaves the image unchanged.

        The rendered image ``out`` satisfies ``warp(out, d.symmetry()) == out``
        (up to interpolation). For the straight map it is the zoom by ``lambda``
        about the centre; ``power`` gives the path of the animation.

        Examples
        --------
        >>> d = Droste((0, 0), np.full(16, np.log(0.2)), 3.0)
        >>> d.symmetry() == Mobius.zoom_between(d.far, d.center, 3.0)
        True
        """
        f = cmath.exp(float(power) * self._q / self._beta)
        m = Mobius([[f**0.5, 0], [0, f**-0.5]])
        out = self._chart_inv @ m @ self._chart
        assert isinstance(out, Mobius)
        return out

    # -- the maths in log coordinates -------------------------------------------------
    def log_radius(self, theta: ArrayLike) -> NDArray[np.float64]:
        """``rho(theta) = log r(theta)``, periodic linear interpolation of the samples.

        Examples
        --------
        >>> d = Droste((0, 0), np.linspace(0, 1, 8, endpoint=False), 2.0)
        >>> d.log_radius([-np.pi, -np.pi + np.pi / 8, np.pi]).round(12)
        array([0.    , 0.0625, 0.    ])
        """
        th = np.asarray(theta, dtype=np.float64)
        n = self._rho.size
        x = np.mod(th + math.pi, 2 * math.pi) * (n / (2 * math.pi))
        i0 = np.floor(x)
        f = x - i0
        i0 = i0.astype(np.intp) % n
        i1 = (i0 + 1) % n
        return self._rho[i0] * (1.0 - f) + self._rho[i1] * f

    def log_chart(self, zw: ComplexArray) -> NDArray[np.complex128]:
        """``log zeta`` of points (finite: the fixed points get ``log|zeta| = -+690``)."""
        zeta = self._chart.pull_cp1(np.asarray(zw, dtype=np.complex128))
        a, b = zeta[..., 0], zeta[..., 1]
        aa, ab = np.abs(a), np.abs(b)
        with np.errstate(divide="ignore"):
            u = np.log(np.maximum(aa, 1e-300)) - np.log(np.maximum(ab, 1e-300))
        theta = np.angle(a * np.conj(b))
        return u + 1j * theta

    def source_log(self, log_zeta: ArrayLike) -> NDArray[np.complex128]:
        """The twist and phase: ``beta (L - L0) + L0 - phase Q`` (before reduction)."""
        L = np.asarray(log_zeta, dtype=np.complex128)
        return self._beta * (L - self._pivot) + (self._pivot - self._shift * self._q)

    def output_log(self, log_zeta: ArrayLike) -> NDArray[np.complex128]:
        """The inverse of :meth:`source_log`: input log plane -> output log plane."""
        L = np.asarray(log_zeta, dtype=np.complex128)
        return (L - self._pivot + self._shift * self._q) / self._beta + self._pivot

    def reduce_log(self, log_zeta: ArrayLike) -> tuple[NDArray[np.complex128], NDArray[np.int64]]:
        """The translate of ``L`` in the strip, and its tile index ``k``.

        Returns ``(L - k log(lambda) - 2 pi i j, k)`` with imaginary part in
        ``[-pi, pi)`` and real part in ``[rho, rho + log(lambda))``.
        """
        L = np.asarray(log_zeta, dtype=np.complex128)
        theta = np.mod(L.imag + math.pi, 2 * math.pi) - math.pi
        rho = self.log_radius(theta)
        k = np.floor((L.real - rho) / self._ell)
        u = L.real - k * self._ell
        # rounding can leave u a hair outside [rho, rho + ell)
        u = np.clip(u, rho, rho + self._ell)
        return u + 1j * theta, k.astype(np.int64)

    def tile_index(self, zw: ComplexArray) -> NDArray[np.int64]:
        """Index ``k`` of the copy of the annulus each point is in (0: the annulus).

        For a twisted map it depends on the branch of ``log zeta`` (``theta``
        in ``[-pi, pi]``), see :class:`TwistedDroste`.
        """
        return self.reduce_log(self.source_log(self.log_chart(zw)))[1]

    # -- the map protocol ------------------------------------------------------------
    def _pull(self, zw: ComplexArray) -> tuple[ComplexArray, NDArray[np.int64], ComplexArray]:
        zw = np.asarray(zw, dtype=np.complex128)
        Ls, k = self.reduce_log(self.source_log(self.log_chart(zw)))
        zeta_s = coords.cp1_from_plane(np.exp(Ls))
        return self._chart_inv.pull_cp1(zeta_s), k, zeta_s

    def pull_cp1(self, zw: ComplexArray) -> ComplexArray:
        return self._pull(zw)[0]

    def pull(self, zw: ComplexArray) -> PullBack:
        points, k, _ = self._pull(zw)
        if self._n_images == 1:
            return PullBack(points)
        return PullBack(points, sheet=np.mod(-k, self._n_images).astype(np.intp))

    def kernel_stages(self) -> tuple[tuple[str, NDArray[np.float64]], ...] | None:
        """``chart``, ``("droste", ...)``, ``chart^-1`` (compiled renderer; one image only)."""
        if self._n_images != 1:
            return None
        from ..render.stages import DROSTE

        c = self._pivot - self._shift * self._q
        b = self._beta
        p = DROSTE.pack(
            m=self._rho.size, ell=self._ell, beta_re=b.real, beta_im=b.imag, pivot=self._pivot,
            c_re=c.real, c_im=c.imag, cap=SCALE_CAP, beta_abs=abs(b), rho=self._rho,
        )  # fmt: skip
        core = (("droste", p),)
        return self._chart.kernel_stages() + core + self._chart_inv.kernel_stages()

    def local_scale(self, zw: ComplexArray) -> NDArray[np.float64]:
        """Exact spherical magnification (chain rule through the chart).

        In the chart the map is ``zeta -> exp(beta log zeta + const)``, whose
        derivative is ``beta zeta_s / zeta``. At the two fixed points, where it
        is unbounded, :data:`SCALE_CAP` is returned.
        """
        zw = coords.normalize_cp1(np.asarray(zw, dtype=np.complex128))
        _, _, zs = self._pull(zw)
        zeta = self._chart.pull_cp1(zw)
        den = np.abs(zeta[..., 0]) * np.abs(zeta[..., 1])
        num = np.abs(zs[..., 0]) * np.abs(zs[..., 1])
        s_chart = self._chart.local_scale(zw) * self._chart_inv.local_scale(zs)
        with np.errstate(divide="ignore", invalid="ignore"):
            s = abs(self._beta) * s_chart * num / den
        return np.where((den > 1e-150) & np.isfinite(s), np.minimum(s, SCALE_CAP), SCALE_CAP)

    # -- plain data ------------------------------------------------------------------
    def params(self) -> dict[str, Any]:
        out: dict[str, Any] = {
            "center": _lonlat_deg(self._center),
            "rho": [float(v) for v in self._rho],
            "scale": self._scale,
        }
        if self._far is not None:
            out["far"] = _lonlat_deg(self._far)
        if self._phase:
            out["phase"] = self._phase
        if self._n_images != 1:
            out["n_images"] = self._n_images
        return out

    @classmethod
    def _from_params(cls, params: dict[str, Any]) -> SphereMap:
        params = dict(params)
        center = params.pop("center")
        rho = params.pop("rho")
        scale = params.pop("scale")
        if "far" in params and params["far"] is not None:
            params["far"] = tuple(params["far"])
        return cls(tuple(center), rho, scale, **params)

    def with_phase(self, phase: float) -> Droste:
        """The same map at another zoom phase."""
        return type(self)._from_params({**self.params(), "phase": float(phase)})  # type: ignore[return-value]

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Droste):
            return NotImplemented
        return type(self) is type(other) and self.params() == other.params()

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        lon, lat = (v + 0.0 for v in np.round(_lonlat_deg(self._center), 9))
        extra = ""
        if self._strands or self._periodicity != 1:
            extra = f", strands={self._strands}, periodicity={self._periodicity}"
        return (
            f"{type(self).__name__}(center=({lon:.6g}, {lat:.6g}), scale={self._scale:.6g}"
            f"{extra}, phase={self._phase:.6g}, n={self._rho.size})"
        )


@register_map
class TwistedDroste(Droste):
    """The twisted Droste map of De Smit and Lenstra (Escher's *Print Gallery*).

    The period ``P = strands * log(lambda) + periodicity * 2 pi i`` of the
    straight image's log plane is turned and scaled to ``2 pi i``. Going once
    round the centre of the output then crosses ``strands`` copies of the
    frame (the number of spiral arms) and goes ``periodicity`` times round the
    input. ``strands=0, periodicity=1`` is the straight map; a negative
    ``strands`` twists the other way.

    Parameters
    ----------
    center, rho, scale, far, phase, n_images
        As for :class:`Droste`.
    strands : int
        The coefficient of ``log(lambda)`` in ``P``.
    periodicity : int
        The coefficient of ``2 pi i`` in ``P``, >= 0; ``gcd(strands,
        periodicity)`` must be 1 so that ``P`` is a primitive period.

    Notes
    -----
    The copies of the annulus join up into ``|strands|`` spiral bands, so the
    tile index ``k`` is not a function on the sphere: it jumps by ``strands``
    across the ray ``theta = +-pi`` of the chart. Several input images
    (``n_images = K``) are therefore allowed only when ``K`` divides
    ``strands``: strand ``j`` then shows image ``j mod K`` throughout.

    Examples
    --------
    >>> rho = np.full(64, np.log(0.2))
    >>> d = TwistedDroste((0, 0), rho, 4.0)
    >>> bool(np.isclose(d.beta, 1 - 1j * np.log(4) / (2 * np.pi)))
    True
    >>> abs(d.symmetry_factor) < 4   # a spiral similarity: less zoom, some turn
    True
    """

    kind = "twisted_droste"

    def __init__(
        self,
        center: PointLike,
        rho: ArrayLike,
        scale: float,
        *,
        strands: int = 1,
        periodicity: int = 1,
        far: PointLike | None = None,
        phase: float = 0.0,
        n_images: int = 1,
    ):
        s = _check_int(strands, "strands")
        p = _check_int(periodicity, "periodicity")
        if p < 0:
            raise InvalidValueError(f"periodicity: expected an integer >= 0, got {periodicity!r}")
        if math.gcd(s, p) != 1:
            raise InvalidValueError(
                "expected strands and periodicity with no common factor (a primitive period "
                f"strands*log(scale) + periodicity*2*pi*i), got strands={s}, periodicity={p}"
            )
        n = _check_int(n_images, "n_images")
        if n > 1 and s % n:
            raise InvalidValueError(
                f"a twisted Droste cycles {n} images only if they divide the strands (one "
                f"spiral strand runs through every copy), got strands={s}"
            )
        if abs(s) > 1000 or p > 1000:
            raise InvalidValueError(
                f"expected strands and periodicity of at most 1000, got {s} and {p}"
            )
        self._strands = s
        self._periodicity = p
        super().__init__(center, rho, scale, far=far, phase=phase, n_images=n_images)

    @property
    def strands(self) -> int:
        """The number of spiral arms (coefficient of ``log(lambda)`` in the period)."""
        return self._strands

    @property
    def periodicity(self) -> int:
        """How often the output goes round the input per turn (coefficient of ``2 pi i``)."""
        return self._periodicity

    def params(self) -> dict[str, Any]:
        out = super().params()
        out["strands"] = self._strands
        out["periodicity"] = self._periodicity
        return out
