"""Tracks: a parameter that changes over time.

A track is ``{"keyframes": [[t, value], ...], "easing": NAME}`` with ``t`` in
seconds, strictly increasing; ``value`` is a number (or a list of numbers, e.g.
a point). Before the first keyframe the track holds its first value, after the
last its last value. Between two keyframes ``u = (t - t0) / (t1 - t0)`` is
eased and the value is ``v0 + easing(u) (v1 - v0)``:

=================  ============================================================
easing             ``easing(u)``
=================  ============================================================
``linear``         ``u`` (the default)
``hold``           ``0``: the value jumps at each keyframe
``ease-in``        ``u^3``
``ease-out``       ``1 - (1 - u)^3``
``ease-in-out``    cubic: ``4u^3`` below 1/2, ``1 - (2 - 2u)^3 / 2`` above
``smoothstep``     ``3u^2 - 2u^3``
``geometric``      linear in ``log(value)``: ``v0^(1-u) v1^u`` (positive values
                   only); a zoom factor on this easing flies at constant speed
=================  ============================================================

Examples
--------
>>> tr = Track([(0.0, 1.0), (2.0, 4.0)])
>>> tr(1.0), tr(-1.0), tr(5.0)
(2.5, 1.0, 4.0)
>>> Track([(0, 1.0), (2, 4.0)], "geometric")(1.0)
2.0
>>> Track([(0, 0.0), (1, 1.0)], "ease-in-out")(0.25)
0.0625
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

__all__ = ["EASINGS", "Track"]


def _ease_in_out(u: float) -> float:
    return 4.0 * u**3 if u < 0.5 else 1.0 - (2.0 - 2.0 * u) ** 3 / 2.0


#: easing name -> the curve u -> eased u on [0, 1] ("geometric" is linear in log(value))
EASINGS: dict[str, Callable[[float], float]] = {
    "linear": lambda u: u,
    "hold": lambda u: 0.0,
    "ease-in": lambda u: u**3,
    "ease-out": lambda u: 1.0 - (1.0 - u) ** 3,
    "ease-in-out": _ease_in_out,
    "smoothstep": lambda u: u * u * (3.0 - 2.0 * u),
    "geometric": lambda u: u,
}


class Track:
    """A value over time: keyframes and an easing (see the module documentation).

    Parameters
    ----------
    keyframes : sequence of (t, value)
        ``t`` in seconds, strictly increasing; ``value`` a float or a tuple of
        floats (all of one length).
    easing : str
        One of :data:`EASINGS`.
    """

    def __init__(self, keyframes: Sequence[tuple[float, Any]], easing: str = "linear") -> None:
        if easing not in EASINGS:
            raise ValueError(f"unknown easing {easing!r}")
        self.keyframes = [(float(t), v) for t, v in keyframes]
        self.easing = easing

    def __call__(self, t: float) -> Any:
        kf = self.keyframes
        if t <= kf[0][0]:
            return kf[0][1]
        if t >= kf[-1][0]:
            return kf[-1][1]
        for (t0, v0), (t1, v1) in zip(kf, kf[1:], strict=False):
            if t0 <= t < t1:
                return self._between(v0, v1, (t - t0) / (t1 - t0))
        return kf[-1][1]  # pragma: no cover - t is inside [t0, t_last)

    def _between(self, v0: Any, v1: Any, u: float) -> Any:
        if isinstance(v0, tuple):
            return tuple(self._between(a, b, u) for a, b in zip(v0, v1, strict=True))
        if self.easing == "geometric":
            return math.exp(math.log(v0) + u * (math.log(v1) - math.log(v0)))
        e = EASINGS[self.easing](u)
        return v0 + e * (v1 - v0)

    def to_json(self) -> dict[str, Any]:
        """The track as recipe JSON."""
        frames = [[t, list(v) if isinstance(v, tuple) else v] for t, v in self.keyframes]
        return {"keyframes": frames, "easing": self.easing}

    def __repr__(self) -> str:
        return f"Track({self.keyframes!r}, {self.easing!r})"


def resolve(value: Any, t: float) -> Any:
    """``value`` with every :class:`Track` in it replaced by its value at time ``t``."""
    if isinstance(value, Track):
        return value(t)
    if isinstance(value, tuple):
        return tuple(resolve(v, t) for v in value)
    if isinstance(value, list):
        return [resolve(v, t) for v in value]
    if isinstance(value, dict):
        return {k: resolve(v, t) for k, v in value.items()}
    return value


def has_track(value: Any) -> bool:
    """Whether ``value`` holds a :class:`Track` anywhere."""
    if isinstance(value, Track):
        return True
    if isinstance(value, (tuple, list)):
        return any(has_track(v) for v in value)
    if isinstance(value, dict):
        return any(has_track(v) for v in value.values())
    return False
