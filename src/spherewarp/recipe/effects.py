"""The effect table: one entry per effect a recipe step can name.

Each :class:`Effect` has its parameters (named as the command's options, with
``-`` written ``_``: ``--look-at`` is ``look_at``), a rule for which of them go
together, and a builder that turns their values into the map the renderer
pulls the image back by. The commands build their maps with the same
functions (:func:`rotate_forward`, :func:`zoom_forward`,
:func:`mobius_forward`, ...), so a recipe and its command share one code path.

Examples
--------
>>> from spherewarp.recipe.effects import EFFECTS
>>> sorted(EFFECTS)[:4]
['droste', 'exp', 'lattes', 'map']
>>> EFFECTS["zoom"].build({"at": (10.0, 0.0), "factor": 2.0, "center": False}).classify()
'hyperbolic'
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from .errors import RecipeError
from .params import (
    Choice,
    Flag,
    Integer,
    Matrix,
    Point,
    Points,
    Real,
    RealOrAuto,
    Spec,
    Text,
)

__all__ = [
    "EFFECTS",
    "Effect",
    "rotate_forward",
    "zoom_forward",
    "mobius_forward",
    "with_look_at",
]


# -- the builders the commands share ---------------------------------------------------------
def rotate_forward(
    yaw: float | None = None,
    pitch: float | None = None,
    roll: float | None = None,
    axis: tuple[float, float] | None = None,
    angle: float | None = None,
) -> Any:
    """The rotation that moves the content, for ``spherewarp rotate``.

    Either ``axis`` and ``angle`` (the content turns ``angle`` degrees
    counter-clockwise about ``axis``) or yaw/pitch/roll (the view turns, as in
    ffmpeg's v360; missing ones are 0).

    Examples
    --------
    >>> rotate_forward(yaw=90).apply_lonlat([90.0, 0.0]).round(6)
    array([0., 0.])
    """
    from ..maps import Mobius

    if axis is not None:
        return Mobius.rotation(axis, 0.0 if angle is None else angle)
    y, p, r = (0.0 if v is None else v for v in (yaw, pitch, roll))
    return Mobius.from_yaw_pitch_roll(y, p, r).inverse()


def zoom_forward(at: tuple[float, float], factor: float, center: bool = False) -> tuple[Any, Any]:
    """The zoom that moves the content, and the turn a recorded pose must follow.

    Returns ``(forward, pose_moves)``: the zoom by ``factor`` toward ``at``
    (then, with ``center``, the turn of ``at`` to the image centre), and that
    turn (the identity without ``center``).

    Examples
    --------
    >>> fwd, pose = zoom_forward((0.0, 0.0), 2.0)
    >>> fwd.classify(), pose.is_identity()
    ('hyperbolic', True)
    """
    from ..maps import Mobius

    forward = Mobius.zoom(at, factor)
    pose_moves = Mobius.identity()
    if center:
        pose_moves = Mobius.rotation_to(at, (0.0, 0.0))
        forward = pose_moves @ forward
    return forward, pose_moves


def mobius_forward(
    matrix: tuple[complex, ...] | None = None,
    from_points: Any = None,
    to_points: Any = None,
) -> Any:
    """The Möbius map ``[[a, b], [c, d]]``, or the one sending three points to three.

    Examples
    --------
    >>> mobius_forward((1, 0.5, 0, 1)).classify()
    'parabolic'
    """
    from ..maps import Mobius

    if matrix is not None:
        a, b, c, d = matrix
        return Mobius([[a, b], [c, d]])
    return Mobius.from_points(list(from_points), list(to_points))


def with_look_at(pull_map: Any, look_at: tuple[float, float] | None) -> Any:
    """``pull_map`` followed by the turn of the view to ``look_at`` (LON, LAT), if given."""
    if look_at is None:
        return pull_map
    from ..maps.mobius import Mobius

    return pull_map @ Mobius.from_yaw_pitch_roll(yaw=look_at[0], pitch=look_at[1])


# -- the table --------------------------------------------------------------------------------
@dataclass(frozen=True)
class Effect:
    """One effect: its parameters, which go together, and its map builder.

    ``build(values)`` takes every parameter (defaults filled in, tracks
    resolved) and returns the map to pull the image back by. ``check(given,
    path)`` raises :class:`RecipeError` for parameters that do not go together.
    ``supersample`` is the command's default supersampling, if it has its own.
    """

    name: str
    summary: str
    params: dict[str, Spec]
    build: Callable[[dict[str, Any]], Any]
    check: Callable[[set[str], str], None] = field(default=lambda given, path: None)
    supersample: int | None = None
    #: the turn of the sphere a recorded camera pose must follow (as the command's own GPano
    #: handling), or None for an effect after which no pose holds
    pose: Callable[[dict[str, Any]], Any] | None = None


def _complex(pair: tuple[float, float]) -> complex:
    return complex(pair[0], pair[1])


def _one_of(given: set[str], path: str, *forms: tuple[str, ...]) -> None:
    """Raise unless the given fields belong to exactly one of ``forms``."""
    used = [form for form in forms if given & set(form)]
    names = " or ".join("/".join(form) for form in forms)
    if len(used) != 1:
        what = "both" if used else "neither"
        raise RecipeError(path, f"expected {names}, got {what}")


def _check_rotate(given: set[str], path: str) -> None:
    _one_of(given, path, ("yaw", "pitch", "roll"), ("axis", "angle"))
    if given & {"axis", "angle"} and not {"axis", "angle"} <= given:
        missing = "axis" if "axis" not in given else "angle"
        raise RecipeError(path, f"'axis' and 'angle' go together; '{missing}' is missing")


def _build_rotate(v: dict[str, Any]) -> Any:
    return _forward_rotate(v).inverse()


def _forward_rotate(v: dict[str, Any]) -> Any:
    return rotate_forward(v["yaw"], v["pitch"], v["roll"], v["axis"], v["angle"])


def _pose_zoom(v: dict[str, Any]) -> Any:
    return zoom_forward(v["at"], v["factor"], v["center"])[1]


def _build_zoom(v: dict[str, Any]) -> Any:
    return zoom_forward(v["at"], v["factor"], v["center"])[0].inverse()


def _check_mobius(given: set[str], path: str) -> None:
    _one_of(given, path, ("matrix",), ("from", "to"))
    if given & {"from", "to"} and not {"from", "to"} <= given:
        missing = "from" if "from" not in given else "to"
        raise RecipeError(path, f"'from' and 'to' go together; '{missing}' is missing")


def _forward_mobius(v: dict[str, Any]) -> Any:
    matrix = None if v["matrix"] is None else tuple(_complex(e) for e in v["matrix"])
    forward = mobius_forward(matrix, v["from"], v["to"])
    if v["amount"] != 1.0:
        forward = forward ** v["amount"]
    return forward


def _build_mobius(v: dict[str, Any]) -> Any:
    return _forward_mobius(v).inverse()


def _build_power(v: dict[str, Any]) -> Any:
    from ..maps.branched import Power

    pull = Power(v["n"], branch_points=v["branch_points"], branch=v["branch"], cut=v["cut"])
    return with_look_at(pull, v["look_at"])


def _build_exp(v: dict[str, Any]) -> Any:
    from ..maps.branched import ExpMap

    return with_look_at(ExpMap(v["lam"], branch_points=v["branch_points"]), v["look_at"])


def _build_map(v: dict[str, Any]) -> Any:
    from ..maps.expression import ExpressionMap

    return with_look_at(ExpressionMap(v["expr"], chart=v["chart"]), v["look_at"])


def _build_lattes(v: dict[str, Any]) -> Any:
    from ..maps import Lattes

    return Lattes(v["alpha"], v["lattice"], method="exact" if v["exact"] else "rational")


def _check_droste(given: set[str], path: str) -> None:
    _one_of(given, path, ("frame",), ("inner_radius",))
    if "inner_radius" in given and "center" not in given:
        raise RecipeError(path, "'inner_radius' needs 'center'")
    if given & {"strands", "periodicity"} and "twist" not in given:
        raise RecipeError(path, "'strands' and 'periodicity' go with 'twist': true")


def _build_droste(v: dict[str, Any]) -> Any:
    from ..effects import droste as dr

    if v["frame"] is not None:
        hole = dr.hole_from_corners(list(v["frame"]), v["center"], far=v["far"])
    else:
        hole = dr.hole_from_radius(v["center"], v["inner_radius"], far=v["far"])
    return dr.droste_map(
        hole,
        v["scale"],
        twist=v["twist"],
        strands=v["strands"],
        periodicity=v["periodicity"],
        phase=v["phase"],
        border=v["border"],
        margin=v["margin"],
    )


_ANGLE = Real(help="degrees")
_BRANCH_POINTS = Points(2, help="the branch points P (0 of the chart) and Q (infinity)")
_LOOK_AT = Point(help="then turn the view to look at this point of the result")

EFFECTS: dict[str, Effect] = {
    e.name: e
    for e in (
        Effect(
            "rotate",
            "turn the view (yaw/pitch/roll) or the content about an axis",
            {
                "yaw": _ANGLE,
                "pitch": _ANGLE,
                "roll": _ANGLE,
                "axis": Point(),
                "angle": _ANGLE,
            },
            _build_rotate,
            _check_rotate,
            pose=_forward_rotate,
        ),
        Effect(
            "zoom",
            "zoom toward a point (a hyperbolic Möbius map)",
            {
                "at": Point(required=True),
                "factor": Real(ge=1e-9, le=1e9, required=True),
                "center": Flag(),
            },
            _build_zoom,
            pose=_pose_zoom,
        ),
        Effect(
            "mobius",
            "any Möbius transformation: a matrix, or three points to three points",
            {
                "matrix": Matrix(),
                "from": Points(3),
                "to": Points(3),
                "amount": Real(
                    default=1.0,
                    help="apply M**amount (0: nothing, 1: the map); a linear track moves "
                    "at constant speed along the one-parameter group through M",
                ),
            },
            _build_mobius,
            _check_mobius,
            pose=_forward_mobius,
        ),
        Effect(
            "power",
            "pull back by z**n about two branch points",
            {
                "n": Real(default=2.0),
                "branch_points": _BRANCH_POINTS,
                "branch": Integer(default=0),
                "cut": Real(default=180.0),
                "look_at": _LOOK_AT,
            },
            _build_power,
        ),
        Effect(
            "exp",
            "pull back by the exp variant: infinitely many copies side by side",
            {"lam": Real(gt=0, default=4.0), "branch_points": _BRANCH_POINTS, "look_at": _LOOK_AT},
            _build_exp,
            supersample=3,
        ),
        Effect(
            "map",
            "pull back by a formula in z (parsed, never run as code)",
            {
                "expr": Text(required=True),
                "chart": Choice(["zenith", "front"], default="zenith"),
                "look_at": _LOOK_AT,
            },
            _build_map,
        ),
        Effect(
            "lattes",
            "a Lattès map z -> p(alpha p^-1(z))",
            {
                "alpha": Text(max_length=100, required=True),
                "lattice": Choice(["square", "hex"], default="square"),
                "exact": Flag(),
            },
            _build_lattes,
        ),
        Effect(
            "droste",
            "the room inside its own picture frame (a frame by corners or a round hole)",
            {
                "center": Point(),
                "frame": Points(4),
                "inner_radius": Real(),
                "far": Point(),
                "scale": RealOrAuto(gt=1, default="auto"),
                "border": Real(default=0.0),
                "margin": Real(),
                "twist": Flag(),
                "strands": Integer(default=1),
                "periodicity": Integer(ge=0, le=1000, default=1),
                "phase": Real(default=0.0),
            },
            _build_droste,
            _check_droste,
        ),
    )
}
