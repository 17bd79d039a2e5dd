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
    File,
    Flag,
    Generators,
    Integer,
    Matrix,
    Point,
    Points,
    Real,
    RealOrAuto,
    Spec,
    Targets,
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
    #: an effect that renders its own picture (several inputs blended, a flat panel):
    #: ``render(images, values, map, warp_kwargs)``; such a step is the recipe's only step
    render: Callable[[list[Any], dict[str, Any], Any, dict[str, Any]], Any] | None = None
    #: whether a step with these values renders its own picture (then it is the only step)
    whole: Callable[[dict[str, Any]], bool] = field(default=lambda values: True)
    #: how many input images a step needs (``values -> n``)
    inputs: Callable[[dict[str, Any]], int] = field(default=lambda values: 1)
    #: whether the picture is flat (no GPano; no output grid), from the values
    flat: Callable[[dict[str, Any]], bool] = field(default=lambda values: False)


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
    _one_of(given, path, ("frame",), ("inner_radius",), ("mask",))
    if "periods" in given and "view" not in given:
        raise RecipeError(path, "'periods' goes with 'view': 'log' or 'log-output'")
    if "inner_radius" in given and "center" not in given:
        raise RecipeError(path, "'inner_radius' needs 'center'")
    if given & {"strands", "periodicity"} and "twist" not in given:
        raise RecipeError(path, "'strands' and 'periodicity' go with 'twist': true")


def _build_droste(v: dict[str, Any]) -> Any:
    from ..effects import droste as dr

    if v["frame"] is not None:
        hole = dr.hole_from_corners(list(v["frame"]), v["center"], far=v["far"])
    elif v["mask"] is not None:
        hole = dr.hole_from_mask(read_mask(v["mask"]), v["center"], far=v["far"])
    else:
        from ..errors import InvalidValueError

        try:
            hole = dr.hole_from_radius(v["center"], v["inner_radius"], far=v["far"])
        except InvalidValueError as exc:  # the function's 'radius' is the step's inner_radius
            field, _, detail = str(exc).partition(": ")
            if field != "radius":
                raise
            raise RecipeError("inner_radius", detail) from None
    return dr.droste_map(
        hole,
        v["scale"],
        twist=v["twist"],
        strands=v["strands"],
        periodicity=v["periodicity"],
        phase=v["phase"],
        n_images=v["images"],
        border=v["border"],
        margin=v["margin"],
    )


def warp_only(kw: dict[str, Any]) -> dict[str, Any]:
    """A renderer's keyword arguments less those that are not :func:`~spherewarp.render.warp`'s
    (``max_pixels``, for a picture of its own)."""
    return {k: v for k, v in kw.items() if k != "max_pixels"}


def _render_droste_log(images: list[Any], v: dict[str, Any], m: Any, kw: dict[str, Any]) -> Any:
    """The log plane of a Droste step (``view``: 'log' or 'log-output'), or the image."""
    from ..effects import droste as dr
    from ..render import warp

    if v["view"] == "equirect":
        return warp(images if len(images) > 1 else images[0], m, **warp_only(kw))
    shape = kw.get("output_shape")
    return dr.log_view(
        images,
        m,
        height=None if shape is None else int(shape[0]),
        periods=v["periods"],
        plane="input" if v["view"] == "log" else "output",
        interp=kw.get("interp", "bilinear"),
        supersample=kw.get("supersample", 1),
    )


#: mask images read by recipes: (path, size, mtime) -> pixels
_MASKS: dict[tuple[str, int, int], Any] = {}


def read_mask(path: Any) -> Any:
    """The pixels of a mask image a recipe names (read once per process and file version)."""
    import os

    from ..io import read_image

    st = os.stat(path)
    key = (str(path), st.st_size, st.st_mtime_ns)
    if key not in _MASKS:
        if len(_MASKS) > 8:
            _MASKS.clear()
        _MASKS[key] = read_image(path).pixels
    return _MASKS[key]


# -- schottky ---------------------------------------------------------------------------------
def _check_schottky(given: set[str], path: str) -> None:
    if "mask" in given and "targets" not in given:
        raise RecipeError(f"{path}.targets", "missing: 'mask' needs a target for each colour")
    if "targets" in given and "mask" not in given:
        raise RecipeError(f"{path}.mask", "missing: 'targets' go with a 'mask'")
    if not given & {"generators", "mask"}:
        raise RecipeError(path, "expected 'generators' or 'mask' with 'targets'")
    if "regions" in given and "mask" not in given:
        raise RecipeError(f"{path}.regions", "'regions' goes with 'mask'")


def _build_schottky(v: dict[str, Any]) -> Any:
    """The Schottky map of a step (generators by disks or matrices, a mask with targets)."""
    import math

    from ..errors import InvalidValueError
    from ..maps.mobius import Mobius
    from ..maps.schottky import Cap, MaskRegions, Schottky, cap_from_mask, generator_between

    gens = []
    for i, g in enumerate(v["generators"] or ()):
        try:
            src = Cap(*g["disk"])
            if "to" in g:
                m = generator_between(src, Cap(*g["to"]), g["twist"])
            else:
                a, b, c, d = (_complex(e) for e in g["matrix"])
                m = Mobius([[a, b], [c, d]])
        except InvalidValueError as exc:
            raise RecipeError(f"generators[{i}]", str(exc)) from None
        gens.append((src, m))
    exact = v["regions"] == "exact"
    if v["mask"] is not None:
        from ..io.tonemap import parse_color

        if v["generators"] and exact:
            raise RecipeError(
                "regions", "'exact' (the default with a mask) takes every disk from the mask: "
                "leave out 'generators', or give 'regions': 'round'"
            )  # fmt: skip
        pixels = read_mask(v["mask"])
        colours = []
        for i, tg in enumerate(v["targets"]):
            try:
                colours.append(parse_color(tg["colour"]))
                cap = cap_from_mask(pixels, colours[-1], inside=exact)
                if "to" in tg:
                    m = generator_between(cap, Cap(*tg["to"]))
                else:
                    if not math.isfinite(tg["zoom"]):  # pragma: no cover - checked
                        raise InvalidValueError("expected a zoom factor > 1")
                    m = Mobius.zoom((cap.lon, cap.lat), tg["zoom"])
            except InvalidValueError as exc:
                raise RecipeError(f"targets[{i}]", str(exc)) from None
            gens.append((cap, m))
    s = Schottky(gens, depth=v["depth"], phase=v["phase"])
    if v["mask"] is not None and exact:
        s = s.with_mask_regions(MaskRegions(pixels, colours, path=str(v["mask"])))
    return s


# -- splitscreen ------------------------------------------------------------------------------
def _check_splitscreen(given: set[str], path: str) -> None:
    pass


def _build_splitscreen(v: dict[str, Any]) -> Any:
    from ..errors import InvalidValueError
    from ..maps.branched import ExpMap, Power

    if v["n"] is not None and v["cover"] != "power":
        raise RecipeError("n", "applies to 'cover': 'power' only")
    if v["n"] is not None and v["n"] % v["images"]:
        raise RecipeError("n", f"expected a multiple of 'images' ({v['images']}), got {v['n']}")
    bp = v["branch_points"]
    try:
        if v["cover"] == "exp":
            cover = ExpMap(v["lam"], branch_points=bp)
        else:
            cover = Power(v["n"] or v["images"], branch_points=bp)
    except InvalidValueError as exc:
        raise RecipeError("", str(exc)) from None
    return with_look_at(cover, v["look_at"])


def splitscreen_seam(images: list[Any], v: dict[str, Any], force: bool = False) -> float:
    """The seam longitude of a split-screen step: its own, or the auto one for ``images``."""
    from ..effects import splitscreen as ss

    if v["seam"] != "auto":
        return float(v["seam"])
    return float(
        ss.auto_seam(images, feather_deg=v["feather"], **_splitscreen_cover(v), force=force)
    )


def _splitscreen_cover(v: dict[str, Any]) -> dict[str, Any]:
    return {"cover": v["cover"], "n": v["n"], "lam": v["lam"], "branch_points": v["branch_points"]}


def _render_splitscreen(images: list[Any], v: dict[str, Any], m: Any, kw: dict[str, Any]) -> Any:
    from ..effects import splitscreen as ss

    kw = warp_only(kw)
    force = bool(kw.pop("force", False))
    look = v["look_at"]
    view = None
    if look is not None:
        from ..maps.mobius import Mobius

        view = Mobius.from_yaw_pitch_roll(yaw=look[0], pitch=look[1])
    return ss.splitscreen(
        images,
        seam=splitscreen_seam(images, v, force),
        feather_deg=v["feather"],
        view=view,
        **_splitscreen_cover(v),
        force=force,
        **kw,
    )


# -- peirce and torus: pictures of their own ----------------------------------------------------
def _build_none(v: dict[str, Any]) -> Any:
    return None


def _render_peirce(images: list[Any], v: dict[str, Any], m: Any, kw: dict[str, Any]) -> Any:
    from ..grids.peirce import render_peirce

    shape = kw.get("output_shape")
    return render_peirce(
        images[0],
        None if shape is None else int(shape[1]),
        lon0=v["lon0"],
        interp=kw.get("interp", "bilinear"),
        supersample=kw.get("supersample", 1),
        force=bool(kw.get("force", False)),
        progress=kw.get("progress"),
    )


def _build_torus(v: dict[str, Any]) -> Any:
    from ..effects.torus import parse_cells
    from ..errors import InvalidValueError

    try:
        parse_cells(f"{v['cells'][0]}x{v['cells'][1]}")
    except InvalidValueError as exc:
        raise RecipeError("cells", str(exc)) from None
    return None


def _render_torus(images: list[Any], v: dict[str, Any], m: Any, kw: dict[str, Any]) -> Any:
    from ..effects.torus import render_torus

    shape = kw.get("output_shape")
    return render_torus(
        images[0],
        v["lattice"],
        cells=tuple(v["cells"]),
        width=None if shape is None else int(shape[1]),
        interp=kw.get("interp", "bilinear"),
        supersample=kw.get("supersample", 1),
        force=bool(kw.get("force", False)),
        progress=kw.get("progress"),
        max_pixels=kw.get("max_pixels"),
    )


class _Cells(Spec):
    """``[CX, CY]``: cells across and down."""

    expected = "[cells across, cells down], integers from 1 to 64"
    _n = Integer(ge=1, le=64)

    def parse_plain(self, value: Any, path: str) -> tuple[int, int]:
        if not isinstance(value, list) or len(value) != 2:
            raise self.fail(value, path)
        return (self._n.parse(value[0], f"{path}[0]"), self._n.parse(value[1], f"{path}[1]"))


class _Seam(Real):
    """'auto' or a longitude."""

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.expected = "'auto' or a longitude in degrees"
        self.trackable = False

    def parse(self, value: Any, path: str) -> Any:
        return "auto" if value == "auto" else self.parse_plain(value, path)


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
                "phase": Real(default=0.0, help="zoom phase: 0 and 1 give the same image"),
                "mask": File(help="a mask image, white = the hole inside the frame"),
                "images": Integer(
                    ge=1,
                    le=64,
                    default=1,
                    help="how many inputs the copies cycle through (INPUT, then --inside ones)",
                ),
                "view": Choice(["equirect", "log", "log-output"], default="equirect"),
                "periods": Real(ge=0.1, le=100, default=3.0),
            },
            _build_droste,
            _check_droste,
            render=_render_droste_log,
            whole=lambda v: v["view"] != "equirect" or v["images"] > 1,
            inputs=lambda v: v["images"],
            flat=lambda v: v["view"] != "equirect",
        ),
        Effect(
            "schottky",
            "a Schottky group: each disk shows the whole picture again, forever",
            {
                "generators": Generators(),
                "mask": File(help="one colour per disk D_x"),
                "targets": Targets(),
                "regions": Choice(["exact", "round"], default="exact"),
                "depth": Integer(ge=1, le=10000),
                "phase": Real(default=0.0, help="zoom phase through the first generator"),
            },
            _build_schottky,
            _check_schottky,
        ),
        Effect(
            "splitscreen",
            "several panoramas on the sheets of a branched cover",
            {
                "images": Integer(ge=2, le=64, default=2, help="how many inputs it combines"),
                "cover": Choice(["power", "exp"], default="power"),
                "n": Integer(ge=1, le=1000),
                "lam": Real(gt=0, default=4.0),
                "branch_points": _BRANCH_POINTS,
                "seam": _Seam(default="auto"),
                "feather": Real(ge=0, le=180, default=10.0),
                "look_at": _LOOK_AT,
            },
            _build_splitscreen,
            _check_splitscreen,
            render=_render_splitscreen,
            inputs=lambda v: v["images"],
        ),
        Effect(
            "peirce",
            "Peirce's quincuncial projection: the whole sphere in a square (a flat picture)",
            {"lon0": Real(default=0.0, help="central meridian, degrees")},
            _build_none,
            render=_render_peirce,
            flat=lambda v: True,
        ),
        Effect(
            "torus",
            "the toroidal image: the panorama pulled back to the torus (a flat picture)",
            {
                "lattice": Choice(["square", "hex"], default="square"),
                "cells": _Cells(default=(1, 1)),
            },
            _build_torus,
            render=_render_torus,
            flat=lambda v: True,
        ),
    )
}
