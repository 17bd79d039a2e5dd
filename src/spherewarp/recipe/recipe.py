"""The :class:`Recipe`: a versioned, serialisable render request."""

from __future__ import annotations

import json
import math
import numbers
import os
import stat
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..errors import InvalidValueError
from .effects import EFFECTS, warp_only
from .errors import RecipeError
from .params import Choice, Integer, Real, describe, is_number, suggest
from .tracks import has_track, resolve

__all__ = ["FORMAT_VERSION", "MAX_BYTES", "MAX_DEPTH", "Frame", "Recipe", "Step"]

#: the format version this library writes and reads (``{"spherewarp": 1, ...}``)
FORMAT_VERSION = 1
#: the largest recipe text read, in bytes (checked before parsing)
MAX_BYTES = 1_000_000
#: the deepest nesting of lists and objects accepted
MAX_DEPTH = 32
#: the most steps a recipe may have
MAX_STEPS = 1000

_TOP = ("spherewarp", "inputs", "steps", "duration", "loop", "view", "options")
_VIEW = ("size", "projection", "look_at", "roll", "fov")
_INTERP = Choice(["bilinear", "bicubic", "nearest"], default="bilinear")
_SUPERSAMPLE = Integer(ge=1, le=16)
_DURATION = Real(gt=0, le=86400)
_SIZE_PART = Integer(ge=1, le=1_000_000)
_TONEMAP = Choice(["aces", "reinhard", "clip"], default="aces")  # spherewarp.io.tonemap's
_EXPOSURE = Real(ge=-20, le=20)


@dataclass(frozen=True)
class Step:
    """One step: an effect, its parameters as given, and as parsed (tracks kept)."""

    effect: str
    given: dict[str, Any]
    parsed: dict[str, Any]
    path: str

    def values(self, t: float) -> dict[str, Any]:
        """Every parameter of the effect at time ``t`` (defaults filled in)."""
        spec = EFFECTS[self.effect].params
        out = {name: s.default for name, s in spec.items()}
        out.update({name: resolve(v, t) for name, v in self.parsed.items()})
        return out

    def map_at(self, t: float) -> Any:
        """The map this step pulls the image back by at time ``t``."""
        from ..errors import InvalidTypeError, InvalidValueError

        try:
            return EFFECTS[self.effect].build(self.values(t))
        except RecipeError as exc:
            if exc.path.startswith("steps["):
                raise
            where = f"{self.path}.{self.effect}" + (f".{exc.path}" if exc.path else "")
            raise RecipeError(where, exc.detail) from None
        except (InvalidValueError, InvalidTypeError) as exc:
            when = f" at t = {t:g}" if self.animated else ""
            cli = exc.cli_message + when if exc.cli_message != str(exc) else None
            raise RecipeError(f"{self.path}.{self.effect}", f"{exc}{when}", cli=cli) from None

    @property
    def animated(self) -> bool:
        return any(has_track(v) for v in self.parsed.values())

    def pose_at(self, t: float) -> Any:
        """The turn a recorded camera pose must follow, or None (see :class:`Frame`)."""
        pose = EFFECTS[self.effect].pose
        return None if pose is None else pose(self.values(t))


@dataclass(frozen=True)
class Frame:
    """What a recipe renders at one time: the map and the keyword arguments of ``warp``.

    ``background`` is the colour transparency is flattened onto when written
    (``--background``), or None. ``pose`` is the turn of the sphere that a
    camera pose recorded with the input (GPano) must follow, as the effect
    commands carry it (a zoom keeps it, a rotation turns it), or None when a
    step is not a Möbius map (the pose no longer describes the pixels).
    """

    map: Any
    warp_kwargs: dict[str, Any]
    background: str | None = None
    view: dict[str, Any] = field(default_factory=dict)
    pose: Any = None
    #: for a step that renders its own picture: ``render(images, warp_kwargs)``
    renderer: Any = None
    #: the picture is flat (a Peirce square, a torus, a log plane): no GPano, no grid
    flat: bool = False
    #: how many input images the frame takes
    n_inputs: int = 1
    #: how HDR pixels are written to an 8- or 16-bit file (``--tonemap``, ``--exposure``),
    #: or None for the default
    tonemap: str | None = None
    exposure: float | None = None

    def sized_map(self, warp_kwargs: dict[str, Any], in_shape: tuple[int, ...]) -> Any:
        """The map, its depth sized for the output (a Schottky map's ``for_output``)."""
        m = self.map
        if hasattr(m, "for_output"):
            m = m.for_output(output_width(warp_kwargs, in_shape))
        return m

    def render_pixels(self, images: Any, warp_kwargs: dict[str, Any]) -> Any:
        """The pixels of this frame from ``images`` (one, or a list of :attr:`n_inputs`).

        ``warp_kwargs`` are :func:`~spherewarp.render.warp`'s, and may also hold
        ``max_pixels``: the most pixels a picture of its own (a torus, whose height
        follows from its cells) may have.
        """
        from ..render import warp

        imgs = list(images) if isinstance(images, (list, tuple)) else [images]
        if len(imgs) != self.n_inputs:
            raise RecipeError("inputs", f"expected {self.n_inputs} input image(s), got {len(imgs)}")
        if self.renderer is not None:
            return self.renderer(imgs, warp_kwargs)
        kwargs = warp_only(warp_kwargs)
        return warp(imgs[0], self.sized_map(kwargs, imgs[0].shape), **kwargs)


def output_width(kwargs: dict[str, Any], in_shape: tuple[int, ...]) -> int:
    """The width of an equirectangular output with pixels as fine as the output's finest.

    For a grid, from the angle between neighbouring pixel centres (the larger of the
    two axes', at the smallest over a lattice of pixels).
    """
    grid = kwargs.get("grid")
    if grid is None:
        shape = kwargs.get("output_shape") or in_shape[:2]
        return int(shape[1])
    import numpy as np

    h, w = grid.shape
    y, x = np.meshgrid(np.linspace(0.5, h - 1.5, 17), np.linspace(0.5, w - 1.5, 17))
    c, ok = grid.directions_at(x, y)
    steps = []
    for dx, dy in ((1.0, 0.0), (0.0, 1.0)):
        n, ok2 = grid.directions_at(x, y, dx, dy)
        steps.append(np.arccos(np.clip((c * n).sum(-1), -1.0, 1.0)))
        ok = ok & ok2
    step = np.maximum(*steps)[ok & (np.maximum(*steps) > 0)]
    if step.size == 0:
        return max(h, w)
    return int(min(2**20, math.ceil(2 * math.pi / float(step.min()))))


class Recipe:
    """A render request: the steps (effects with their own parameters), the view, the
    options, and time.

    The steps compose in order: step 1 is applied to the image, then step 2 to
    the result, and so on (the pull-back maps compose as ``S1 @ S2 @ ...``). Any
    number parameter, or a point's coordinates, may be a track
    (:mod:`spherewarp.recipe.tracks`). The recipe is data: loading one never
    runs code (``map`` formulas are parsed by a safe parser).

    Parameters
    ----------
    data : dict
        The recipe as JSON data (see :meth:`from_dict`); it is validated.
    base : path, optional
        The directory that relative file names in the recipe (a mask) are read
        from: the recipe file's own (:meth:`load`), else the current directory.

    Examples
    --------
    >>> import numpy as np
    >>> r = Recipe.loads('''{"spherewarp": 1, "duration": 2,
    ...     "steps": [{"zoom": {"at": [0, 0], "factor": {"keyframes": [[0, 1], [2, 4]]}}}]}''')
    >>> r.step_values(0, t=1)["factor"]
    2.5
    >>> r.render(np.zeros((32, 64, 3), np.uint8), t=1).shape
    (32, 64, 3)
    >>> Recipe.loads('{"spherewarp": 1, "steps": [{"zooom": {}}]}')
    Traceback (most recent call last):
    ...
    spherewarp.recipe.errors.RecipeError: steps[0]: unknown effect 'zooom' (did you mean 'zoom'?)
    """

    def __init__(self, data: dict[str, Any], base: str | os.PathLike[str] | None = None) -> None:
        from .params import base_dir

        self._data = data
        self.base = None if base is None else Path(base)
        with base_dir(self.base):
            self._parse(data)

    # -- reading ------------------------------------------------------------------------------
    @classmethod
    def from_dict(cls, data: Any, base: str | os.PathLike[str] | None = None) -> Recipe:
        """Validate recipe JSON data (already parsed) and return the recipe.

        Raises :class:`RecipeError` naming the first bad field.
        """
        _check_depth(data)
        return cls(_loads(_json_text(data)), base)  # a copy: the caller's data may change

    @classmethod
    def loads(cls, text: str | bytes, base: str | os.PathLike[str] | None = None) -> Recipe:
        """Parse and validate recipe JSON text (at most :data:`MAX_BYTES`, as UTF-8)."""
        size = len(text)
        if isinstance(text, str) and MAX_BYTES < size * 4 and size <= MAX_BYTES:
            size = len(text.encode("utf-8", "surrogatepass"))  # up to 4 bytes a character
        if size > MAX_BYTES:
            raise RecipeError(
                "", f"expected a recipe of at most {MAX_BYTES} bytes, got {size} bytes"
            )
        if isinstance(text, bytes):
            try:
                text = text.decode("utf-8")
            except UnicodeDecodeError as exc:
                raise RecipeError(
                    "", f"expected UTF-8 JSON text, got a byte that is not UTF-8 at {exc.start}"
                ) from None
        try:
            data = _loads(text)
        except RecursionError:
            raise RecipeError("", f"expected JSON nested at most {MAX_DEPTH} deep") from None
        except json.JSONDecodeError as exc:
            raise RecipeError(
                "", f"not JSON: {exc.msg} (line {exc.lineno}, column {exc.colno})"
            ) from None
        _check_depth(data)
        return cls(data, base)

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> Recipe:
        """Read and validate a recipe file (at most :data:`MAX_BYTES`)."""
        from ..errors import ImageFormatError

        p = Path(path)
        try:
            st = p.stat()
            if not stat.S_ISREG(st.st_mode) and not stat.S_ISDIR(st.st_mode):
                # a FIFO would block, a device never end
                raise OSError(0, "not a regular file (a device, FIFO or socket)")
            size = st.st_size
            if size > MAX_BYTES:
                raise RecipeError(
                    "", f"expected a recipe of at most {MAX_BYTES} bytes, got {size} bytes"
                )
            with p.open("rb") as fh:
                text = fh.read(MAX_BYTES + 1)
        except IsADirectoryError:
            raise ImageFormatError(f"cannot read recipe '{p}': it is a directory") from None
        except OSError as exc:
            raise ImageFormatError(f"cannot read recipe '{p}': {exc.strerror or exc}") from None
        return cls.loads(text, base=p.resolve().parent)

    @staticmethod
    def validate(data: Any) -> None:
        """Raise :class:`RecipeError` unless ``data`` is a valid recipe."""
        Recipe.from_dict(data)

    # -- writing ------------------------------------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        """The recipe as JSON data (as given: the parameters, the tracks)."""
        return json.loads(json.dumps(self._data))

    def dumps(self) -> str:
        """The recipe as JSON text."""
        return json.dumps(self._data, indent=2, allow_nan=False) + "\n"

    def save(self, path: str | os.PathLike[str], *, overwrite: bool = False) -> Path:
        """Write the recipe as JSON, atomically; refuse to replace a file unless ``overwrite``."""
        from ..io.atomic import write_text

        return write_text(path, self.dumps(), overwrite=overwrite)

    # -- evaluating ---------------------------------------------------------------------------
    @property
    def steps(self) -> tuple[Step, ...]:
        return self._steps

    @property
    def duration(self) -> float | None:
        """The length in seconds, or None for a still."""
        return self._duration

    @property
    def loop(self) -> bool:
        return self._loop

    @property
    def animated(self) -> bool:
        """Whether some parameter is a track."""
        return any(s.animated for s in self._steps)

    def time(self, t: float) -> float:
        """The time the tracks are evaluated at: ``t`` modulo the duration for a loop."""
        if isinstance(t, bool) or not isinstance(t, numbers.Real) or not math.isfinite(t):
            raise RecipeError("time", f"expected a finite time in seconds, got {t!r}")
        if self._loop and self._duration:
            return math.fmod(t, self._duration) % self._duration
        return float(t)

    def step_values(self, index: int, t: float = 0.0) -> dict[str, Any]:
        """The parameters of step ``index`` at time ``t``."""
        return self._steps[index].values(self.time(t))

    def map_at(self, t: float = 0.0) -> Any:
        """The map to pull the image back by at time ``t``: the steps composed in order."""
        from ..maps import Mobius

        tt = self.time(t)
        maps = [m for m in (s.map_at(tt) for s in self._steps) if m is not None]
        if not maps:
            return Mobius.identity()
        total = maps[0]
        for k, m in enumerate(maps[1:], 1):
            try:
                total = total @ m
            except InvalidValueError as exc:  # each step fine, together out of range
                raise RecipeError("steps", f"steps 0 to {k} together: {exc}") from None
        return total

    @property
    def n_inputs(self) -> int:
        """How many input images the recipe renders from (a split screen's, Droste's
        ``images``); 1 for most."""
        return self._n_inputs

    @property
    def files(self) -> tuple[tuple[str, Path], ...]:
        """The files the recipe's steps read (a Droste or Schottky ``mask``), as
        (field, path) pairs: ``("steps[0].schottky.mask", Path(...))``.

        A command that renders the recipe registers them as inputs, so that no output
        of it overwrites one.

        Examples
        --------
        >>> from spherewarp.demo import sample_path
        >>> step = {"schottky": {"mask": str(sample_path("interior-mask.png")),
        ...                      "targets": [{"colour": "red", "zoom": 40}]}}
        >>> [(k, p.name) for k, p in Recipe.from_dict({"spherewarp": 1, "steps": [step]}).files]
        [('steps[0].schottky.mask', 'interior-mask.png')]
        """
        from .params import File

        found = []
        for s in self._steps:
            for name, spec in EFFECTS[s.effect].params.items():
                if isinstance(spec, File) and s.parsed.get(name) is not None:
                    found.append((f"{s.path}.{s.effect}.{name}", Path(s.parsed[name])))
        return tuple(found)

    def at(self, t: float = 0.0) -> Frame:
        """The map and the render options at time ``t``."""
        renderer, flat = None, False
        m = self.map_at(t)
        if self._steps:
            step = self._steps[0]
            effect = EFFECTS[step.effect]
            values = step.values(self.time(t))
            flat = effect.flat(values)
            if effect.render is not None and effect.whole(values):
                draw = effect.render

                def renderer(images: list[Any], kwargs: dict[str, Any]) -> Any:
                    return draw(images, values, m, kwargs)

        return Frame(
            m,
            dict(self._warp_kwargs),
            self._background,
            dict(self._view),
            None if flat or renderer is not None else self.pose_at(t),
            renderer,
            flat,
            self._n_inputs,
            self._tonemap,
            self._exposure,
        )

    def pose_at(self, t: float = 0.0) -> Any:
        """The turn a recorded camera pose must follow at time ``t`` (see :class:`Frame`)."""
        from ..maps import Mobius

        tt = self.time(t)
        total = Mobius.identity()
        for s in self._steps:  # step 1 moves the content first
            pose = s.pose_at(tt)
            if pose is None:
                return None
            total = pose @ total
        return total

    def render(self, image: Any, t: float = 0.0, **warp_kwargs: Any) -> Any:
        """Render the recipe on ``image`` at time ``t`` with :func:`spherewarp.warp`.

        ``warp_kwargs`` override the recipe's options (``threads=``, ``progress=``, ...).
        """
        frame = self.at(t)
        kwargs = dict(frame.warp_kwargs)
        images = list(image) if isinstance(image, (list, tuple)) else [image]
        images = [getattr(i, "pixels", i) for i in images]
        grid = view_grid(frame.view, images[0].shape)
        if grid is not None:
            kwargs.pop("output_shape", None)
            kwargs["grid"] = grid
        return frame.render_pixels(images, {**kwargs, **warp_kwargs})

    def frame_times(self, fps: float, duration: float | None = None) -> list[float]:
        """The times of the frames of an animation at ``fps`` frames a second.

        ``duration`` defaults to the recipe's. A loop's frames stop one frame
        short of the duration (the frame after the last is the first).
        """
        d = self._duration if duration is None else duration
        if d is None:
            raise RecipeError("duration", "expected a duration in seconds for an animation")
        n = max(1, round(d * fps))
        return [k / fps for k in range(n if self._loop else n + 1)]

    def _check_whole(self, data: dict[str, Any]) -> None:
        _check_whole_steps(self, data)

    def __repr__(self) -> str:
        names = ", ".join(s.effect for s in self._steps)
        return f"Recipe([{names}], duration={self._duration}, loop={self._loop})"

    # -- parsing ------------------------------------------------------------------------------
    def _parse(self, data: Any) -> None:
        if not isinstance(data, dict):
            raise RecipeError("", f"expected a JSON object, got {describe(data)}")
        for key in data:
            if key not in _TOP:
                raise RecipeError(key, f"unknown field{suggest(key, _TOP)}")
        if "spherewarp" not in data:
            raise RecipeError(
                "spherewarp", f'missing: a recipe starts {{"spherewarp": {FORMAT_VERSION}, ...}}'
            )
        version = data["spherewarp"]
        if not isinstance(version, int) or isinstance(version, bool) or version < 1:
            raise RecipeError(
                "spherewarp",
                f"expected the format version {FORMAT_VERSION}, got {describe(version)}",
            )
        if version > FORMAT_VERSION:
            raise RecipeError(
                "spherewarp",
                f"format version {version} is newer than this spherewarp reads "
                f"({FORMAT_VERSION}); upgrade spherewarp",
            )
        inputs = data.get("inputs", [])
        if not isinstance(inputs, list) or not all(isinstance(i, str) for i in inputs):
            raise RecipeError("inputs", f"expected a list of file names, got {describe(inputs)}")
        self._duration = (
            None
            if data.get("duration") is None
            else _DURATION.parse_plain(data["duration"], "duration")
        )
        loop = data.get("loop", False)
        if not isinstance(loop, bool):
            raise RecipeError("loop", f"expected true or false, got {describe(loop)}")
        if loop and self._duration is None:
            raise RecipeError("loop", "a loop needs a 'duration'")
        self._loop = loop
        steps = data.get("steps")
        if not isinstance(steps, list):
            raise RecipeError("steps", f"expected a list of steps, got {describe(steps)}")
        if len(steps) > MAX_STEPS:
            raise RecipeError("steps", f"expected at most {MAX_STEPS} steps, got {len(steps)}")
        self._steps = tuple(_parse_step(s, f"steps[{k}]") for k, s in enumerate(steps))
        self._view = _parse_view(data.get("view", {}))
        try:  # the grid's own checks (a field of view its projection can show), at the start
            view_grid(self._view, (512, 1024))
        except InvalidValueError as exc:
            err = RecipeError("view", str(exc))
            err.cli_detail = exc.cli_message  # what a command's own --fov, --size got wrong
            raise err from None
        self._warp_kwargs, writing = _parse_options(data.get("options", {}), self._steps)
        self._background, self._tonemap, self._exposure = writing
        if self._view.get("size") is not None:
            w, h = self._view["size"]
            self._warp_kwargs["output_shape"] = (h, w)
        for s in self._steps:  # every builder's own checks, at the start
            s.map_at(0.0)
        self._check_whole(data)
        if len(self._steps) > 1:
            self.map_at(0.0)  # and the steps composed


def _check_whole_steps(recipe: Recipe, data: dict[str, Any]) -> None:
    """A step that renders its own picture is the only step; the inputs it needs are named."""
    n = 1
    for k, s in enumerate(recipe.steps):
        effect = EFFECTS[s.effect]
        values = s.values(0.0)
        if effect.render is not None and effect.whole(values) and len(recipe.steps) > 1:
            raise RecipeError(
                f"steps[{k}].{s.effect}",
                "renders a picture of its own (several inputs, a flat panel): it must be the "
                f"recipe's only step, got {len(recipe.steps)} steps",
            )
        n = max(n, effect.inputs(values))
        size = recipe._view.get("size")
        if s.effect == "droste" and values.get("view", "equirect") != "equirect" and size:
            if not 8 <= size[1] <= 16384:  # log_view's own bounds, checked at the start
                msg = f"a Droste log view is 8 to 16384 pixels high, got {size[1]}"
                err = RecipeError("view.size", msg)
                err.cli_detail = f"--size: {msg}"  # a command's own --size
                raise err
        if effect.flat(values) and any(
            recipe._view.get(v) for v in ("projection", "look_at", "roll", "fov")
        ):
            raise RecipeError(
                "view", f"{s.effect} makes a flat picture of its own: no projection, look_at, "
                "roll or fov"
            )  # fmt: skip
    inputs = data.get("inputs")
    if n > 1 and inputs is not None and len(inputs) < n:
        raise RecipeError(
            "inputs", f"expected {n} input names for {recipe.steps[0].effect}, got {len(inputs)}"
        )
    recipe._n_inputs = n


def _parse_step(step: Any, path: str) -> Step:
    if not isinstance(step, dict) or len(step) != 1:
        raise RecipeError(
            path, f'expected one effect {{"NAME": {{parameters}}}}, got {describe(step)}'
        )
    ((name, params),) = step.items()
    if name not in EFFECTS:
        raise RecipeError(path, f"unknown effect {name!r}{suggest(name, list(EFFECTS))}")
    effect = EFFECTS[name]
    where = f"{path}.{name}"
    if not isinstance(params, dict):
        raise RecipeError(where, f"expected an object of parameters, got {describe(params)}")
    parsed: dict[str, Any] = {}
    for key, value in params.items():
        if key not in effect.params:
            raise RecipeError(
                f"{where}.{key}",
                f"unknown parameter of {name}{suggest(key, list(effect.params))} "
                f"(expected one of {', '.join(effect.params)})",
            )
        if value is None:
            continue
        parsed[key] = effect.params[key].parse(value, f"{where}.{key}")
    for key, spec in effect.params.items():
        if spec.required and key not in parsed:
            raise RecipeError(f"{where}.{key}", f"missing: expected {spec.expected}")
    effect.check(set(parsed), where)
    return Step(name, params, parsed, path)


def _parse_view(view: Any) -> dict[str, Any]:
    """The output view: ``size`` [W, H] is used; the grid fields are checked loosely for now."""
    if not isinstance(view, dict):
        raise RecipeError("view", f"expected an object, got {describe(view)}")
    out: dict[str, Any] = {}
    for key, value in view.items():
        if key not in _VIEW:
            raise RecipeError(f"view.{key}", f"unknown field{suggest(key, _VIEW)}")
        if value is None:
            continue
        if key == "size":
            if not isinstance(value, list) or len(value) != 2:
                raise RecipeError("view.size", f"expected [width, height], got {describe(value)}")
            out[key] = tuple(_SIZE_PART.parse(v, f"view.size[{k}]") for k, v in enumerate(value))
        elif key == "projection":
            from ..grids import GRIDS

            name = value.strip().lower() if isinstance(value, str) else None
            if name not in GRIDS:
                raise RecipeError(
                    "view.projection",
                    f"expected one of {', '.join(GRIDS)}, got {describe(value)}"
                    + (suggest(value, list(GRIDS)) if isinstance(value, str) else ""),
                )
            out[key] = name
        elif key == "look_at":
            from .params import Point

            out[key] = Point().parse_plain(value, "view.look_at")
        elif key == "roll":
            out[key] = Real(ge=-360, le=360).parse_plain(value, "view.roll")
        else:
            out[key] = Real(gt=0, le=360).parse_plain(value, "view.fov")
    return out


def view_grid(view: dict[str, Any], in_shape: tuple[int, ...]) -> Any:
    """The output grid a recipe's ``view`` names for an input of ``in_shape``, or None for
    the plain panorama (then ``view.size`` alone sets the output size)."""
    if not any(view.get(k) for k in ("projection", "look_at", "roll", "fov")):
        return None
    from ..grids import make_grid

    size = view.get("size")
    return make_grid(
        view.get("projection") or "equirect",
        tuple(in_shape[:2]),
        shape=None if size is None else (size[1], size[0]),
        look_at=view.get("look_at"),
        roll=view.get("roll") or 0.0,
        fov=view.get("fov"),
    )


def _parse_options(
    options: Any, steps: tuple[Step, ...]
) -> tuple[dict[str, Any], tuple[str | None, str | None, float | None]]:
    """``warp``'s keyword arguments, and how the file is written: ``(background, tonemap,
    exposure)``, each None where the recipe leaves it to the command."""
    if not isinstance(options, dict):
        raise RecipeError("options", f"expected an object, got {describe(options)}")
    known = ("interp", "supersample", "antialias", "background", "tonemap", "exposure")
    for key in options:
        if key not in known:
            raise RecipeError(f"options.{key}", f"unknown option{suggest(key, known)}")
    kwargs: dict[str, Any] = {"interp": "bilinear", "supersample": 1, "antialias": "auto"}
    own = [EFFECTS[s.effect].supersample for s in steps if EFFECTS[s.effect].supersample]
    if own and options.get("antialias") is None:  # as the command does without --supersample
        kwargs["supersample"] = max(own)  # or --antialias (either one chooses the filter)
    if options.get("interp") is not None:
        kwargs["interp"] = _INTERP.parse_plain(options["interp"], "options.interp")
    if options.get("supersample") is not None:
        kwargs["supersample"] = _SUPERSAMPLE.parse_plain(
            options["supersample"], "options.supersample"
        )
    aa = options.get("antialias")
    if aa is not None:
        names = ("auto", "area", "adaptive", "none")
        if isinstance(aa, str) and aa.lower() in names:
            kwargs["antialias"] = aa.lower()
        elif is_number(aa) and float(aa).is_integer() and 1 <= aa <= 16:
            kwargs["antialias"] = int(aa)
        else:
            hint = suggest(aa.lower(), names) if isinstance(aa, str) else ""
            raise RecipeError(
                "options.antialias",
                f"expected auto, area, adaptive, none or an integer 1 to 16, got "
                f"{describe(aa)}{hint}",
            )
    background = options.get("background")
    if background is not None and (not isinstance(background, str) or len(background) > 40):
        raise RecipeError(
            "options.background",
            f"expected a colour name or #RRGGBB, got {describe(background)}",
        )
    if background is not None:  # checked now, not when a transparent input meets it
        from ..io.tonemap import parse_color

        try:
            parse_color(background)
        except InvalidValueError as exc:
            raise RecipeError("options.background", str(exc)) from None
    tonemap, exposure = options.get("tonemap"), options.get("exposure")
    if tonemap is not None:
        tonemap = _TONEMAP.parse_plain(tonemap, "options.tonemap")
    if exposure is not None:
        exposure = _EXPOSURE.parse_plain(exposure, "options.exposure")
    return kwargs, (background, tonemap, exposure)


def _refuse_constant(name: str) -> Any:
    raise RecipeError("", f"expected finite numbers, got {name} (JSON has no NaN or Infinity)")


def _no_dupes(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for key, value in pairs:
        if key in out:
            raise RecipeError(key, "given twice")
        out[key] = value
    return out


def _check_depth(data: Any) -> None:
    """Raise unless lists and objects nest at most :data:`MAX_DEPTH` deep (no recursion)."""
    stack = [(data, 1)]
    while stack:
        value, depth = stack.pop()
        if isinstance(value, (list, dict)):
            if depth > MAX_DEPTH:
                raise RecipeError("", f"expected JSON nested at most {MAX_DEPTH} deep")
            items = value.values() if isinstance(value, dict) else value
            stack.extend((v, depth + 1) for v in items)


#: the most digits of an integer in a recipe (more is beyond a float's range)
MAX_DIGITS = 308


def _parse_int(text: str) -> int:
    digits = len(text.lstrip("-"))
    if digits > MAX_DIGITS:
        raise RecipeError("", f"expected numbers of at most {MAX_DIGITS} digits, got an integer "
                          f"of {digits} digits")  # fmt: skip
    return int(text)


def _loads(text: str) -> Any:
    return json.loads(
        text, parse_constant=_refuse_constant, object_pairs_hook=_no_dupes, parse_int=_parse_int
    )


def _json_text(data: Any) -> str:
    """Python data as JSON text; refuse NaN, infinities and what JSON cannot hold."""
    try:
        return json.dumps(data, allow_nan=False)
    except ValueError as exc:
        if "integer string conversion" in str(exc):  # an int of over 4300 digits
            raise RecipeError("", f"expected numbers of at most {MAX_DIGITS} digits") from None
        raise RecipeError("", "expected finite numbers (JSON has no NaN or Infinity)") from None
    except TypeError as exc:
        raise RecipeError("", f"expected JSON data: {exc}") from None
