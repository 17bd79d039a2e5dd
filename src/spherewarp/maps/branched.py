"""Branched maps: powers ``z**n``, roots with an explicit branch, the exp variant and its log.

Any conformal map of the sphere that is not Möbius has branch points
(the paper, "Pulling back, pushing forward, and branch points"). Pulling an
image back by ``S(z) = z**n`` shows ``n`` copies of it around two branch
points of order ``n``, at 0 and infinity of the default chart (the zenith
and the nadir: on the ceiling and the floor). Pulling back by the exp variant
``S(z) = -exp(-lam (1 + z)/(1 - z))`` shows infinitely many copies repeating
horizontally; they accumulate at the back point ``z = 1``, where ``S`` has an
essential singularity.

Each map here works in its own chart: a Möbius map ``chart`` taking the
sphere to the chart in which the formula holds, ``S = chart^-1 o f o chart``
(``chart=None`` is the default chart). :func:`chart_for_branch_points` builds
the chart that puts two chosen points at 0 and infinity, which moves the
branch points anywhere.

Convention: points are unit-norm pairs ``(z, w)`` of the default chart (0 at
the zenith, 1 at the back, -1 at the front, infinity at the nadir; see
:mod:`spherewarp.coords`). Every formula is evaluated on the pairs, so 0 and
infinity are exact and no NaN or inf is ever produced.

Possible issues
---------------
* A non-integer power is multi-valued. The branch is explicit: the argument
  of ``z`` (in the map's chart) is taken in ``[c - 2 pi + 2 pi k, c + 2 pi
  k)``, with ``c`` in ``(0, 2 pi]`` the chart argument of the cut meridian
  (its longitude ``cut`` + 180 degrees) and ``k`` the ``branch``; the
  pulled-back image is discontinuous along the cut. ``cut=0, branch=0`` is
  NumPy's principal branch (cut along the negative real axis).
* The exp variant has an essential singularity at the back point (``z = 1``
  in its chart): within :data:`ESSENTIAL_RADIUS` radians of it the map is
  defined as its limit from the upper hemisphere (0) or the lower one
  (infinity), since there the phase cannot be computed in float64. The
  region is far smaller than a pixel of any panorama; near it copies of the
  input shrink below a pixel, so render with supersampling.
* Local scales that are infinite (at the branch point of a root, at the
  essential singularity) are reported as :data:`SCALE_CAP`.

Examples
--------
>>> import numpy as np
>>> from spherewarp.maps import Power, ExpMap
>>> sq = Power(2)
>>> complex(sq(1j))                       # z**2 in the default chart
(-1+0j)
>>> sq.apply_lonlat([[45.0, 0.0]]).round(9)   # the equator doubles its longitudes
array([[-90.,   0.]])
>>> bool(np.isclose(ExpMap(4)(0), -np.exp(-4)))
True
"""

from __future__ import annotations

import math
import numbers
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .. import coords
from ..errors import InvalidTypeError, InvalidValueError
from .base import SphereMap, register_map
from .mobius import Mobius, PointLike, as_cp1_point

__all__ = [
    "ESSENTIAL_RADIUS",
    "SCALE_CAP",
    "ExpMap",
    "LogMap",
    "Power",
    "chart_for_branch_points",
]

ComplexArray = NDArray[np.complex128]
FloatArray = NDArray[np.float64]

#: radius (radians) of the neighbourhood of the exp variant's essential singularity
#: where it is replaced by its limit (see "Possible issues" above)
ESSENTIAL_RADIUS = 1e-9
#: the value reported for an infinite local scale
SCALE_CAP = 1e12

_TWO_PI = 2.0 * math.pi
#: the largest exponent |n| of :class:`Power` (a million copies round a point: far past any
#: output's pixels, and z**n overflows not far beyond), and the largest ``lam`` of
#: :class:`ExpMap` (lam / pi copies side by side)
MAX_EXPONENT = 1e6
_INT_TOL = 1e-12


def chart_for_branch_points(p: PointLike, q: PointLike) -> Mobius:
    """The chart (a Möbius map) that sends ``p`` to 0 and ``q`` to infinity.

    It is the rotation taking ``p`` to the zenith along a great circle,
    followed (when ``p`` and ``q`` are not antipodal) by the Möbius map that
    fixes 0 with derivative 1 and sends the image of ``q`` to infinity. For
    the zenith and the nadir it is the identity; for antipodal points it is a
    rotation.

    Parameters
    ----------
    p, q : point
        Two different points: ``(lon, lat)`` in degrees, an ``(x, y, z)``
        vector, a complex number of the default chart, or a pair.

    Raises
    ------
    InvalidValueError
        If the points coincide.

    Examples
    --------
    >>> m = chart_for_branch_points((0, 0), (180, 0))   # front and back
    >>> m.is_rotation(), m.apply_lonlat([[0.0, 0.0], [180.0, 0.0]])[:, 1].round(9)
    (True, array([ 90., -90.]))
    >>> chart_for_branch_points((0, 90), (0, -90)).is_identity()
    True
    """
    pp = as_cp1_point(p, "first branch point")
    qq = as_cp1_point(q, "second branch point")
    if abs(pp[0] * qq[1] - pp[1] * qq[0]) < 1e-9:
        raise InvalidValueError("the two branch points must be different points")
    rot = Mobius.rotation_to(coords.xyz_from_cp1(pp), (0.0, 0.0, 1.0))
    a, b = rot.pull_cp1(qq)
    if abs(b) < 1e-15:
        return rot
    out = Mobius([[a, 0.0], [-b, a]]) @ rot
    assert isinstance(out, Mobius)
    return out


def _as_chart(chart: Any, branch_points: Any) -> Mobius | None:
    if branch_points is not None:
        if chart is not None:
            raise InvalidValueError("give either chart or branch_points, not both")
        try:
            p, q = branch_points
        except (TypeError, ValueError):
            raise InvalidValueError(
                f"expected branch_points as two points (p, q), got {branch_points!r:.80}"
            ) from None
        chart = chart_for_branch_points(p, q)
    if chart is None:
        return None
    if isinstance(chart, dict):
        chart = Mobius._from_params(chart)
    elif not isinstance(chart, Mobius):
        try:
            chart = Mobius(chart)
        except InvalidValueError:
            raise InvalidTypeError(
                f"expected the chart as a Mobius map or a 2x2 matrix, got {chart!r:.80}"
            ) from None
    return None if chart.is_identity(1e-15) else chart


def _charts_equal(a: Mobius | None, b: Mobius | None) -> bool:
    if a is None or b is None:
        return a is None and b is None
    return a.isclose(b)


def _unit(zw: ComplexArray) -> ComplexArray:
    return coords.normalize_cp1(np.asarray(zw, dtype=np.complex128))


class _ChartedMap(SphereMap):
    """A map ``chart^-1 o core o chart``; subclasses give ``_core`` and ``_core_scale``."""

    _chart: Mobius | None

    @property
    def chart(self) -> Mobius:
        """The Möbius map into the chart where the formula holds (identity by default)."""
        return Mobius.identity() if self._chart is None else self._chart

    def _core(self, zw: ComplexArray) -> ComplexArray:  # pragma: no cover - abstract
        raise NotImplementedError

    def _core_scale(self, zw: ComplexArray) -> FloatArray:  # pragma: no cover - abstract
        raise NotImplementedError

    def pull_cp1(self, zw: ComplexArray) -> ComplexArray:
        zw = _unit(zw)
        if self._chart is None:
            return self._core(zw)
        return self._chart.inverse().pull_cp1(self._core(self._chart.pull_cp1(zw)))

    def local_scale(self, zw: ComplexArray) -> FloatArray:
        zw = _unit(zw)
        if self._chart is None:
            return np.minimum(self._core_scale(zw), SCALE_CAP)
        m = self._chart
        inner = m.pull_cp1(zw)
        core = self._core(inner)
        scale = m.local_scale(zw) * self._core_scale(inner) * m.inverse().local_scale(core)
        return np.minimum(scale, SCALE_CAP)

    def _chart_params(self) -> dict[str, Any]:
        return {"chart": None if self._chart is None else self._chart.params()}

    def _chart_repr(self) -> str:
        return "" if self._chart is None else f", chart={self._chart!r}"


def _check_real(value: Any, name: str) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise InvalidTypeError(f"expected {name} to be a real number, got {value!r}")
    v = float(value)
    if not math.isfinite(v):
        raise InvalidValueError(f"expected a finite {name}, got {value!r}")
    return v


def _round_int(t: float) -> float:
    r = round(t)
    return float(r) if abs(t - r) <= _INT_TOL * max(1.0, abs(t)) else t


@register_map
class Power(_ChartedMap):
    """Pull back by ``S(z) = z**exponent`` in a chart with the branch points at 0 and infinity.

    For an integer ``n >= 2`` the pulled-back image shows ``n`` copies of the
    input around two branch points of order ``n``; for a root ``1/k`` one
    ``k``-th of the input is spread over the whole sphere (the push forward
    by ``z**k``). Negative exponents include the inversion ``z -> 1/z``.

    Parameters
    ----------
    exponent : real, non-zero
        The power; integers give single-valued maps.
    branch_points : (point, point), optional
        Where the branch points are: the first goes to 0, the second to
        infinity (see :func:`chart_for_branch_points`). Default: the zenith
        and the nadir.
    chart : Mobius, optional
        Instead of ``branch_points``: the Möbius map into the chart in which
        the map is ``z**exponent``.
    branch : int
        For a non-integer exponent, which branch (``arg z`` taken in
        ``[c - 2 pi + 2 pi branch, c + 2 pi branch)``, ``c`` the cut's chart
        angle in ``(0, 2 pi]``).
    cut : float
        For a non-integer exponent, the longitude (degrees, in the chart's
        frame) of the meridian along which the branch is cut: ``c = cut +
        180`` degrees. Default 180, the back; 0 gives NumPy's principal
        branch.

    Notes
    -----
    On pairs, ``(z, w) -> (z**n, w**n)`` (renormalised), exact at 0 and
    infinity. The spherical magnification is
    ``|n| (|z| |w|)**(|n| - 1) / (|z|**(2|n|) + |w|**(2|n|))`` for unit pairs.
    ``Power(a) @ Power(b)`` with integer exponents and the same chart is
    ``Power(a * b)``.

    Examples
    --------
    >>> p = Power(2)
    >>> np.round(p([0, 2j, np.inf]), 12)
    array([ 0.+0.j, -4.+0.j, inf+0.j])
    >>> Power(2) @ Power(3)
    Power(exponent=6)
    >>> r = Power(0.5, cut=0)               # principal square root
    >>> bool(np.allclose(r([4j, -4j]), np.sqrt([4j, -4j])))
    True
    >>> float(Power(3).local_scale(coords.cp1_from_plane(1.0)))   # 3 on the equator
    3.0
    """

    kind = "power"

    def __init__(
        self,
        exponent: float,
        *,
        branch_points: tuple[PointLike, PointLike] | None = None,
        chart: Mobius | None = None,
        branch: int = 0,
        cut: float = 180.0,
    ):
        t = _round_int(_check_real(exponent, "exponent"))
        if t == 0:
            raise InvalidValueError(
                f"expected a non-zero exponent, got {exponent!r} (a constant map)"
            )
        if abs(t) > MAX_EXPONENT:  # z**n overflows; and n copies round a point are noise
            raise InvalidValueError(
                f"expected an exponent of at most {MAX_EXPONENT:g} in size (that many copies "
                f"of the image round each branch point), got {t:g}"
            )
        if isinstance(branch, bool) or not isinstance(branch, numbers.Integral):
            raise InvalidTypeError(f"expected branch to be an integer, got {branch!r}")
        self._t = t
        self._is_int = float(t).is_integer()
        self._branch = int(branch)
        self._cut = _check_real(cut, "cut")
        self._chart = _as_chart(chart, branch_points)

    @property
    def exponent(self) -> float:
        """The exponent (a float; integral for integer powers)."""
        return self._t

    @property
    def is_integer(self) -> bool:
        """True for integer exponents (single-valued maps)."""
        return self._is_int

    @property
    def branch(self) -> int:
        """The branch index of a non-integer power."""
        return self._branch

    @property
    def cut(self) -> float:
        """Longitude (degrees, chart frame) of the branch cut of a non-integer power."""
        return self._cut

    def _arg_start(self) -> float:
        """Start of the range of arg z (radians) of a non-integer power's branch."""
        c = math.radians(self._cut + 180.0) % _TWO_PI
        c = c if c > 0 else _TWO_PI  # the cut's chart angle, in (0, 2 pi]
        return c - _TWO_PI + _TWO_PI * self._branch

    def _core(self, zw: ComplexArray) -> ComplexArray:
        a, b = zw[..., 0], zw[..., 1]
        ra, rb = np.abs(a), np.abs(b)
        big = np.maximum(ra, rb)
        big = np.where(big > 0, big, 1.0)
        t = self._t
        if self._is_int:
            n = int(t)
            with np.errstate(under="ignore"):
                if n > 0:
                    out = np.stack([(a / big) ** n, (b / big) ** n], axis=-1)
                else:
                    out = np.stack([(b / big) ** -n, (a / big) ** -n], axis=-1)
            return coords.normalize_cp1(out)
        ra, rb = ra / big, rb / big
        low = self._arg_start()
        theta = np.angle(a * np.conj(b))
        theta = low + np.mod(theta - low, _TWO_PI)
        phase = np.exp(1j * (t * theta))
        if t > 0:
            out = np.stack([ra**t * phase, (rb**t).astype(np.complex128)], axis=-1)
        else:
            out = np.stack([rb ** (-t) * phase, (ra ** (-t)).astype(np.complex128)], axis=-1)
        return coords.normalize_cp1(out)

    def _core_scale(self, zw: ComplexArray) -> FloatArray:
        t = abs(self._t)
        a, b = np.abs(zw[..., 0]), np.abs(zw[..., 1])
        with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
            s = t * (a * b) ** (t - 1) / (a ** (2 * t) + b ** (2 * t))
        return np.where(np.isnan(s), SCALE_CAP, s)

    def kernel_stages(self) -> tuple[tuple[str, NDArray[np.float64]], ...] | None:
        """Integer exponents: ``chart``, ``("power", [n])``, ``chart^-1`` (compiled renderer)."""
        if not self._is_int:
            return None
        from ..render.stages import POWER

        core = (("power", POWER.pack(m=self._t)),)
        if self._chart is None:
            return core
        return self._chart.kernel_stages() + core + self._chart.inverse().kernel_stages()

    def inverse(self, branch: int = 0) -> SphereMap:
        """The inverse map: a root (branch ``branch``) of an integer power, else the power 1/t.

        ``p @ p.inverse()`` is the identity for every power; for roots and
        other injective powers (``|t| <= 1``) ``p.inverse() @ p`` is too (off
        the cut). For a non-integer power the inverse's cut is placed so that
        this holds.

        Examples
        --------
        >>> p = Power(3)
        >>> z = np.array([0.3 + 0.2j, -2 + 1j])
        >>> bool(np.allclose(p(p.inverse(branch=1)(z)), z))
        True
        >>> Power(0.5).inverse()
        Power(exponent=2)
        """
        s = _round_int(1.0 / self._t)
        if self._is_int:
            c_new = self._cut
        else:
            start = self._t * self._arg_start() - (0.0 if self._t > 0 else _TWO_PI)
            # The same start of the argument range as a cut and a branch.
            branch = math.ceil(start / _TWO_PI)
            c_new = math.degrees(start - _TWO_PI * (branch - 1)) - 180.0
        return Power(s, chart=self._chart, branch=branch, cut=c_new)

    def __matmul__(self, other: object) -> SphereMap:
        if (
            isinstance(other, Power)
            and self._is_int
            and other._is_int
            and _charts_equal(self._chart, other._chart)
        ):
            return Power(self._t * other._t, chart=self._chart)
        return super().__matmul__(other)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Power):
            return NotImplemented
        if self._t != other._t or not _charts_equal(self._chart, other._chart):
            return False
        return self._is_int or (self._branch == other._branch and self._cut == other._cut)

    __hash__ = None  # type: ignore[assignment]

    def params(self) -> dict[str, Any]:
        t: float | int = int(self._t) if self._is_int else self._t
        out: dict[str, Any] = {"exponent": t}
        if not self._is_int:
            out.update(branch=self._branch, cut=self._cut)
        out.update(self._chart_params())
        return out

    @classmethod
    def _from_params(cls, params: dict[str, Any]) -> Power:
        params = dict(params)
        chart = params.pop("chart", None)
        return cls(chart=None if chart is None else Mobius._from_params(chart), **params)

    def __repr__(self) -> str:
        t = int(self._t) if self._is_int else self._t
        extra = "" if self._is_int else f", branch={self._branch}, cut={self._cut:g}"
        return f"Power(exponent={t}{extra}{self._chart_repr()})"


def _u_parts(zw: ComplexArray) -> tuple[FloatArray, FloatArray, FloatArray, NDArray[np.bool_]]:
    """``u = (1 + z)/(1 - z)`` of unit pairs: (Re u, Im u, |w - z|^2, near the singularity)."""
    a, b = zw[..., 0], zw[..., 1]
    d2 = np.abs(b - a) ** 2
    near = d2 < 2.0 * math.sin(ESSENTIAL_RADIUS / 2) ** 2
    d2s = np.where(near, 1.0, d2)
    re_u = (np.abs(b) ** 2 - np.abs(a) ** 2) / d2s
    im_u = 2.0 * np.imag(a * np.conj(b)) / d2s
    return re_u, im_u, d2, near


def _check_lam(lam: Any) -> float:
    v = _check_real(lam, "lam")
    if v <= 0:
        raise InvalidValueError(f"expected lam > 0, got {lam!r}")
    if v > MAX_EXPONENT:  # about lam / pi copies between front and back: far past any output
        raise InvalidValueError(f"expected lam of at most {MAX_EXPONENT:g}, got {v:g}")
    return v


@register_map
class ExpMap(_ChartedMap):
    """Pull back by the exp variant ``S(z) = -exp(-lam (1 + z)/(1 - z))``.

    The Möbius map ``(1 + z)/(1 - z)`` turns the sphere a quarter turn about
    ``+-i`` so that the copies of the input repeat horizontally; ``lam``
    scales them (the paper uses 4). The forward map is a logarithm, with
    branch points of infinite order at 0 and infinity of the input; the
    output has an essential singularity at the back point (``z = 1``).

    Parameters
    ----------
    lam : float > 0
        The scale: about ``lam / pi`` copies fit between the front and
        45 degrees from the back.
    branch_points : (point, point), optional
        Where the input's 0 and infinity are taken from (see
        :func:`chart_for_branch_points`); moves the singularity with them.
    chart : Mobius, optional
        Instead of ``branch_points``: the chart of the formula.

    Notes
    -----
    ``S`` keeps the hemispheres: ``|S| = exp(-lam Re u) < 1`` exactly where
    ``|z| < 1``. Within :data:`ESSENTIAL_RADIUS` of the back point the map is
    replaced by its limit, 0 above the equator and infinity below it. The
    spherical magnification is ``lam / (|w - z|**2 cosh(lam Re u))`` for unit
    pairs: infinite along the equator toward the back point, vanishing fast
    off it.

    Examples
    --------
    >>> e = ExpMap(4)
    >>> bool(np.isclose(e(0.5j), -np.exp(-4 * (1 + 0.5j) / (1 - 0.5j))))
    True
    >>> np.round(e([1.0, -1.0, 0.0]), 12)    # the singularity, the front, the zenith
    array([ 0.        +0.j, -1.        +0.j, -0.01831564+0.j])
    >>> float(e.local_scale(coords.cp1_from_plane(-1.0)))   # lam/2 at the front
    2.0
    """

    kind = "exp"

    def __init__(
        self,
        lam: float = 4.0,
        *,
        branch_points: tuple[PointLike, PointLike] | None = None,
        chart: Mobius | None = None,
    ):
        self._lam = _check_lam(lam)
        self._chart = _as_chart(chart, branch_points)

    @property
    def lam(self) -> float:
        """The scale parameter lambda."""
        return self._lam

    def _core(self, zw: ComplexArray) -> ComplexArray:
        re_u, im_u, _, near = _u_parts(zw)
        lam = self._lam
        sr = -lam * re_u
        with np.errstate(over="ignore", under="ignore"):
            mag_z = np.exp(np.minimum(sr, 0.0))
            mag_w = np.exp(-np.maximum(sr, 0.0))
        out = np.stack([-mag_z * np.exp(-1j * lam * im_u), mag_w.astype(np.complex128)], axis=-1)
        if np.any(near):
            upper = np.abs(zw[..., 1]) >= np.abs(zw[..., 0])
            limit = np.where(upper[..., None], [0.0, 1.0], [1.0, 0.0]).astype(np.complex128)
            out = np.where(near[..., None], limit, out)
        return coords.normalize_cp1(out)

    def _core_scale(self, zw: ComplexArray) -> FloatArray:
        re_u, _, d2, near = _u_parts(zw)
        with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
            s = self._lam / (d2 * np.cosh(self._lam * re_u))
        s = np.where(np.isnan(s), 0.0, s)
        return np.where(near, SCALE_CAP, s)

    def kernel_stages(self) -> tuple[tuple[str, NDArray[np.float64]], ...]:
        """``chart``, ``("exp", [lam, 2 sin^2(r/2), cap])``, ``chart^-1`` (compiled renderer)."""
        from ..render.stages import EXP

        near = 2.0 * math.sin(ESSENTIAL_RADIUS / 2) ** 2
        core = (("exp", EXP.pack(lam=self._lam, near=near, cap=SCALE_CAP)),)
        if self._chart is None:
            return core
        return self._chart.kernel_stages() + core + self._chart.inverse().kernel_stages()

    def inverse(self, branch: int = 0) -> LogMap:
        """The log variant with branch ``branch``: ``e @ e.inverse(k)`` is the identity.

        Examples
        --------
        >>> e = ExpMap(4)
        >>> z = np.array([0.3 + 0.2j, -2 + 1j])
        >>> bool(np.allclose(e(e.inverse(branch=2)(z)), z))
        True
        """
        return LogMap(self._lam, branch=branch, chart=self._chart)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, ExpMap):
            return NotImplemented
        return self._lam == other._lam and _charts_equal(self._chart, other._chart)

    __hash__ = None  # type: ignore[assignment]

    def params(self) -> dict[str, Any]:
        return {"lam": self._lam, **self._chart_params()}

    @classmethod
    def _from_params(cls, params: dict[str, Any]) -> ExpMap:
        params = dict(params)
        chart = params.pop("chart", None)
        return cls(chart=None if chart is None else Mobius._from_params(chart), **params)

    def __repr__(self) -> str:
        return f"ExpMap(lam={self._lam:g}{self._chart_repr()})"


@register_map
class LogMap(_ChartedMap):
    """The log variant, inverse of :class:`ExpMap`: ``z = (u - 1)/(u + 1)``, ``u = -log(-w)/lam``.

    ``log`` is taken with ``arg(-w)`` in ``(-pi, pi]`` plus ``2 pi branch``.
    Pulling back by it pushes an image forward by the exp variant: the whole
    output is one of the copies (number ``branch``) of :class:`ExpMap`'s
    output, spread over the sphere. 0 and infinity go to the back point.

    Examples
    --------
    >>> lg = LogMap(4)
    >>> np.round(lg([0.0, np.inf, -np.exp(-4)]), 12)
    array([1.+0.j, 1.+0.j, 0.+0.j])
    """

    kind = "log"

    def __init__(
        self,
        lam: float = 4.0,
        *,
        branch: int = 0,
        branch_points: tuple[PointLike, PointLike] | None = None,
        chart: Mobius | None = None,
    ):
        if isinstance(branch, bool) or not isinstance(branch, numbers.Integral):
            raise InvalidTypeError(f"expected branch to be an integer, got {branch!r}")
        self._lam = _check_lam(lam)
        self._branch = int(branch)
        self._chart = _as_chart(chart, branch_points)

    @property
    def lam(self) -> float:
        """The scale parameter lambda."""
        return self._lam

    @property
    def branch(self) -> int:
        """Which branch of the logarithm."""
        return self._branch

    def _core(self, zw: ComplexArray) -> ComplexArray:
        c, d = zw[..., 0], zw[..., 1]
        with np.errstate(divide="ignore"):
            log_abs = np.log(np.abs(c)) - np.log(np.abs(d))
        arg = np.angle(-c * np.conj(d)) + _TWO_PI * self._branch
        inf = np.isinf(log_abs)
        u = -(np.where(inf, 0.0, log_abs) + 1j * arg) / self._lam
        big = np.abs(u) > 1.0
        with np.errstate(divide="ignore", invalid="ignore"):
            r = np.where(big, 1.0 / np.where(big, u, 1.0), 0.0)
        pair_big = np.stack([1.0 - r, 1.0 + r], axis=-1)
        pair_small = np.stack([u - 1.0, u + 1.0], axis=-1)
        out = np.where(big[..., None], pair_big, pair_small)
        out = np.where(inf[..., None], np.array([1.0, 1.0], np.complex128), out)
        return coords.normalize_cp1(out)

    def _core_scale(self, zw: ComplexArray) -> FloatArray:
        z = self._core(zw)
        fwd = ExpMap(self._lam)._core_scale(z)
        with np.errstate(divide="ignore"):
            return np.where(fwd > 0, 1.0 / np.maximum(fwd, 1.0 / SCALE_CAP), SCALE_CAP)

    def inverse(self) -> ExpMap:
        """The exp variant (single-valued)."""
        return ExpMap(self._lam, chart=self._chart)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, LogMap):
            return NotImplemented
        return (
            self._lam == other._lam
            and self._branch == other._branch
            and _charts_equal(self._chart, other._chart)
        )

    __hash__ = None  # type: ignore[assignment]

    def params(self) -> dict[str, Any]:
        return {"lam": self._lam, "branch": self._branch, **self._chart_params()}

    @classmethod
    def _from_params(cls, params: dict[str, Any]) -> LogMap:
        params = dict(params)
        chart = params.pop("chart", None)
        return cls(chart=None if chart is None else Mobius._from_params(chart), **params)

    def __repr__(self) -> str:
        return f"LogMap(lam={self._lam:g}, branch={self._branch}{self._chart_repr()})"
