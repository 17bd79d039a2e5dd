"""The sheeted cover: a branched cover whose sheets show different images.

The map behind split-screen (:mod:`spherewarp.effects.splitscreen`, the
paper's "Pulling back, pushing forward, and branch points"): pull back by a
k-fold branched cover (``z**k``, or the exp variant with its infinitely many
sheets) and let each sheet sample a different input. This module holds the
map (its sheet index, JSON form and registration); finding the seam and
cross-fading the inputs is the effect's work.

Examples
--------
>>> from spherewarp.maps.sheeted import SheetedCover, make_cover
>>> cover = SheetedCover(make_cover("power", n=2), 2, 0.0)
>>> cover.n_sheets, cover.seam
(2, 0.0)
"""

from __future__ import annotations

import math
import numbers
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .. import coords
from ..errors import InvalidTypeError, InvalidValueError
from .base import PullBack, SphereMap, map_from_dict, register_map
from .branched import ExpMap, Power, _u_parts
from .mobius import Mobius, PointLike

__all__ = ["COVERS", "SheetedCover", "make_cover"]

#: the branched covers split-screen can use
COVERS = ("power", "exp")

_TWO_PI = 2.0 * math.pi


def make_cover(
    cover: str | Power | ExpMap = "power",
    *,
    n: int = 2,
    lam: float = 4.0,
    branch_points: tuple[PointLike, PointLike] | None = None,
) -> Power | ExpMap:
    """The branched cover: ``Power(n)`` or ``ExpMap(lam)``, with optional branch points.

    Examples
    --------
    >>> make_cover("power", n=3)
    Power(exponent=3)
    >>> make_cover("EXP", lam=2)
    ExpMap(lam=2)
    """
    if isinstance(cover, Power):
        if not (cover.is_integer and cover.exponent >= 1):
            raise InvalidValueError(f"expected a cover z**n with an integer n >= 1, got {cover!r}")
        return cover
    if isinstance(cover, ExpMap):
        return cover
    if not isinstance(cover, str):
        raise InvalidTypeError(
            f"expected the cover as 'power', 'exp', a Power or an ExpMap, got "
            f"{type(cover).__name__}"
        )
    name = cover.strip().lower()
    if name == "power":
        if isinstance(n, bool) or not isinstance(n, numbers.Integral) or n < 1:
            raise InvalidValueError(f"expected n to be an integer >= 1, got {n!r}")
        return Power(int(n), branch_points=branch_points)
    if name == "exp":
        return ExpMap(lam, branch_points=branch_points)
    raise InvalidValueError(f"unknown cover {cover!r}; expected one of: {', '.join(COVERS)}")


def _seam_angle(seam_lon: float) -> float:
    """Chart argument (radians, in [0, 2 pi)) of the seam meridian at longitude ``seam_lon``."""
    return math.radians(seam_lon + 180.0) % _TWO_PI


@register_map
class SheetedCover(SphereMap):
    """A branched cover whose sheets show different images.

    ``warp(images, SheetedCover(cover, len(images), seam))`` renders a hard
    split-screen: the output point ``q`` samples ``images[k]`` at
    ``cover(q)``, where ``k`` counts the sheets of the cover from the seam
    (modulo the number of images). :func:`splitscreen` adds the feathered
    blend.

    Parameters
    ----------
    cover : Power or ExpMap
        ``Power(n)`` with an integer ``n >= 1`` (a multiple of ``n_images``)
        or ``ExpMap(lam)``, in any chart.
    n_images : int
        How many images the sheets cycle through.
    seam : float
        Longitude (degrees, in the cover's chart frame) of the input meridian
        along which the sheets are cut.
    view : Mobius, optional
        Applied to output points first (e.g. a rotation that brings a branch
        point to the centre of the result).
    halves : bool
        Split each sheet at the meridian opposite the seam, giving ``2 *
        n_images`` sheet indices (``2 k`` for the first half of image ``k``'s
        sheet, ``2 k + 1`` for the second); :func:`splitscreen` uses it.

    Examples
    --------
    >>> s = SheetedCover(Power(2), 2, seam=0.0)
    >>> zw = coords.cp1_from_lonlat(np.radians([[0.0, 10.0], [180.0, -10.0]]))
    >>> s.pull(zw).sheet.tolist()
    [0, 1]
    """

    kind = "sheeted_cover"

    def __init__(
        self,
        cover: Power | ExpMap,
        n_images: int,
        seam: float = 0.0,
        *,
        view: Mobius | None = None,
        halves: bool = False,
    ):
        if isinstance(cover, dict):
            cover = map_from_dict(cover)  # type: ignore[assignment]
        cover = make_cover(cover)
        if isinstance(n_images, bool) or not isinstance(n_images, numbers.Integral):
            raise InvalidTypeError(f"expected n_images to be an integer, got {n_images!r}")
        if n_images < 1:
            raise InvalidValueError(f"expected at least one image, got n_images={n_images}")
        if isinstance(cover, Power) and int(cover.exponent) % n_images:
            raise InvalidValueError(
                f"the {int(cover.exponent)} sheets of z**{int(cover.exponent)} cannot cycle "
                f"through {n_images} images; expected n to be a multiple of {n_images}"
            )
        if isinstance(seam, bool) or not isinstance(seam, numbers.Real):
            raise InvalidTypeError(f"expected the seam as a longitude in degrees, got {seam!r}")
        if not math.isfinite(seam):
            raise InvalidValueError(f"expected a finite seam longitude, got {seam!r}")
        if isinstance(view, dict):
            view = Mobius._from_params(view)
        if view is not None and not isinstance(view, Mobius):
            raise InvalidTypeError(f"expected view to be a Mobius map, got {type(view).__name__}")
        self._cover = cover
        self._m = int(n_images)
        self._seam = float(seam)
        self._view = None if view is None or view.is_identity(1e-15) else view
        self._halves = bool(halves)

    @property
    def cover(self) -> Power | ExpMap:
        """The branched cover."""
        return self._cover

    @property
    def seam(self) -> float:
        """Longitude (degrees, chart frame) of the seam meridian of the inputs."""
        return self._seam

    @property
    def n_sheets(self) -> int:  # type: ignore[override]
        return self._m * (2 if self._halves else 1)

    def _viewed(self, zw: NDArray[np.complex128]) -> NDArray[np.complex128]:
        zw = coords.normalize_cp1(np.asarray(zw, dtype=np.complex128))
        return zw if self._view is None else self._view.pull_cp1(zw)

    def sheet_coordinate(self, zw: NDArray[np.complex128]) -> NDArray[np.float64]:
        """Real sheet coordinate ``s``: sheet ``floor(s)``, seams at the integers.

        The fractional part is the chart angle of the pulled-back point from
        the seam meridian, in turns.
        """
        return self._sheet_coordinate(self._viewed(zw))

    def _sheet_coordinate(self, q: NDArray[np.complex128]) -> NDArray[np.float64]:
        chart = self._cover._chart
        zc = q if chart is None else chart.pull_cp1(q)
        phi = _seam_angle(self._seam)
        if isinstance(self._cover, Power):
            n = int(self._cover.exponent)
            theta = np.angle(zc[..., 0] * np.conj(zc[..., 1]))
            # The sheet with the chart's front (theta = pi) is sheet 0.
            offset = -math.floor(n * ((math.pi - phi / n) % _TWO_PI) / _TWO_PI)
            return n * np.mod(theta - phi / n, _TWO_PI) / _TWO_PI + offset
        lam = self._cover.lam
        _, im_u, _, _ = _u_parts(zc)
        offset = -math.floor((math.pi - phi) / _TWO_PI)  # the chart's front is on sheet 0
        return (math.pi - lam * im_u - phi) / _TWO_PI + offset

    def pull_cp1(self, zw: NDArray[np.complex128]) -> NDArray[np.complex128]:
        return self._cover.pull_cp1(self._viewed(zw))

    def pull(self, zw: NDArray[np.complex128]) -> PullBack:
        q = self._viewed(zw)
        s = self._sheet_coordinate(q)
        whole = np.floor(s)
        sheet = np.mod(whole, self._m).astype(np.intp)
        if self._halves:
            sheet = 2 * sheet + (s - whole >= 0.5)
        return PullBack(self._cover.pull_cp1(q), sheet=sheet)

    def local_scale(self, zw: NDArray[np.complex128]) -> NDArray[np.float64]:
        zw = coords.normalize_cp1(np.asarray(zw, dtype=np.complex128))
        if self._view is None:
            return self._cover.local_scale(zw)
        return self._view.local_scale(zw) * self._cover.local_scale(self._view.pull_cp1(zw))

    def params(self) -> dict[str, Any]:
        return {
            "cover": self._cover.to_dict(),
            "n_images": self._m,
            "seam": self._seam,
            "view": None if self._view is None else self._view.params(),
            "halves": self._halves,
        }
