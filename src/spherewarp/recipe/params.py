"""Typed parameters of recipe steps: each checks a JSON value at a path.

A spec's :meth:`~Spec.parse` turns the JSON value into the Python value the
effect's builder takes (a float, a ``(lon, lat)`` tuple, ...), with a
:class:`~spherewarp.recipe.tracks.Track` wherever the recipe gives a track;
a bad value raises :class:`~spherewarp.recipe.errors.RecipeError` naming the
path and what was expected.
"""

from __future__ import annotations

import contextlib
import contextvars
import difflib
import math
import os
from collections.abc import Iterable, Iterator, Sequence
from pathlib import Path
from typing import Any

from .errors import RecipeError
from .tracks import EASINGS, Track

__all__ = [
    "Spec",
    "Real",
    "Integer",
    "Flag",
    "Choice",
    "Text",
    "Point",
    "Points",
    "ComplexNumber",
    "Matrix",
    "RealOrAuto",
    "File",
    "Disk",
    "Generators",
    "Targets",
    "FileRefused",
    "allowed_files",
    "base_dir",
    "describe",
    "suggest",
]

#: most keyframes a track may have
MAX_KEYFRAMES = 10000


def describe(value: Any) -> str:
    """A short, bounded rendering of a JSON value for an error message."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if value is None:
        return "null"
    if isinstance(value, dict):
        return "an object" if value else "{}"
    if isinstance(value, list):
        return f"a list of {len(value)}" if value else "[]"
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


def suggest(name: str, choices: Sequence[str]) -> str:
    """`` (did you mean 'x'?)`` for the closest of ``choices``, or ''."""
    close = difflib.get_close_matches(name, list(choices), n=1, cutoff=0.6)
    return f" (did you mean {close[0]!r}?)" if close else ""


def is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


class Spec:
    """One parameter: its JSON type, range, default and whether it may be a track."""

    #: what a value must be, for the messages ("a number > 0")
    expected = "a value"
    trackable = False

    def __init__(self, *, default: Any = None, required: bool = False, help: str = "") -> None:
        self.default = default
        self.required = required
        self.help = help

    def parse(self, value: Any, path: str) -> Any:
        if self.trackable and isinstance(value, dict):
            return self.parse_track(value, path)
        return self.parse_plain(value, path)

    def parse_plain(self, value: Any, path: str) -> Any:  # pragma: no cover - abstract
        raise NotImplementedError

    def fail(self, value: Any, path: str, expected: str | None = None) -> RecipeError:
        return RecipeError(path, f"expected {expected or self.expected}, got {describe(value)}")

    def parse_track(self, value: dict[str, Any], path: str) -> Track:
        unknown = sorted(set(value) - {"keyframes", "easing"})
        if unknown:
            hint = suggest(unknown[0], ["keyframes", "easing"])
            raise RecipeError(
                f"{path}.{unknown[0]}",
                f"unknown track field (expected 'keyframes' and 'easing'){hint}",
            )
        if "keyframes" not in value:
            raise RecipeError(path, "a track needs 'keyframes': [[t, value], ...]")
        easing = value.get("easing", "linear")
        if not isinstance(easing, str) or easing not in EASINGS:
            hint = suggest(easing, list(EASINGS)) if isinstance(easing, str) else ""
            raise RecipeError(
                f"{path}.easing",
                f"expected one of {', '.join(EASINGS)}, got {describe(easing)}{hint}",
            )
        frames = value["keyframes"]
        if not isinstance(frames, list) or not frames:
            raise RecipeError(
                f"{path}.keyframes", f"expected a list of [t, value] pairs, got {describe(frames)}"
            )
        if len(frames) > MAX_KEYFRAMES:
            raise RecipeError(
                f"{path}.keyframes",
                f"expected at most {MAX_KEYFRAMES} keyframes, got {len(frames)}",
            )
        parsed = []
        for k, frame in enumerate(frames):
            where = f"{path}.keyframes[{k}]"
            if not isinstance(frame, list) or len(frame) != 2:
                raise RecipeError(where, f"expected a pair [t, value], got {describe(frame)}")
            t, v = frame
            if not is_number(t) or not math.isfinite(t):
                raise RecipeError(f"{where}[0]", f"expected a time in seconds, got {describe(t)}")
            if parsed and t <= parsed[-1][0]:
                raise RecipeError(
                    f"{where}[0]",
                    f"keyframes out of order: expected a time after {parsed[-1][0]:g}, got {t:g}",
                )
            if isinstance(v, dict):
                raise RecipeError(f"{where}[1]", "expected a value, got a track inside a track")
            pv = self.parse_plain(v, f"{where}[1]")
            if easing == "geometric" and not _all_positive(pv):
                raise RecipeError(
                    f"{where}[1]", f"the geometric easing needs values > 0, got {describe(v)}"
                )
            parsed.append((float(t), pv))
        return Track(parsed, easing)


def _all_positive(value: Any) -> bool:
    if isinstance(value, tuple):
        return all(_all_positive(v) for v in value)
    return is_number(value) and value > 0


class Real(Spec):
    """A finite real number in a range; may be a track."""

    trackable = True

    def __init__(
        self,
        *,
        gt: float | None = None,
        ge: float | None = None,
        lt: float | None = None,
        le: float | None = None,
        **kwargs: Any,
    ) -> None:
        super().__init__(**kwargs)
        self.gt, self.ge, self.lt, self.le = gt, ge, lt, le
        bounds = [
            f"> {gt:g}" if gt is not None else "",
            f">= {ge:g}" if ge is not None else "",
            f"< {lt:g}" if lt is not None else "",
            f"<= {le:g}" if le is not None else "",
        ]
        self.expected = " ".join(["a number"] + [" and ".join(b for b in bounds if b)]).strip()

    def parse_plain(self, value: Any, path: str) -> float:
        if not is_number(value) or not math.isfinite(value):
            raise self.fail(value, path)
        v = float(value)
        if (
            (self.gt is not None and not v > self.gt)
            or (self.ge is not None and not v >= self.ge)
            or (self.lt is not None and not v < self.lt)
            or (self.le is not None and not v <= self.le)
        ):
            raise self.fail(value, path)
        return v


class Integer(Spec):
    """An integer in a range (not a track)."""

    def __init__(self, *, ge: int | None = None, le: int | None = None, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.ge, self.le = ge, le
        if ge is not None and le is not None:
            self.expected = f"an integer from {ge} to {le}"
        elif ge is not None:
            self.expected = f"an integer >= {ge}"
        else:
            self.expected = "an integer"

    def parse_plain(self, value: Any, path: str) -> int:
        if isinstance(value, float) and value.is_integer():
            value = int(value)
        if not isinstance(value, int) or isinstance(value, bool):
            raise self.fail(value, path)
        if (self.ge is not None and value < self.ge) or (self.le is not None and value > self.le):
            raise self.fail(value, path)
        return value


class Flag(Spec):
    """true or false."""

    expected = "true or false"

    def __init__(self, **kwargs: Any) -> None:
        kwargs.setdefault("default", False)
        super().__init__(**kwargs)

    def parse_plain(self, value: Any, path: str) -> bool:
        if not isinstance(value, bool):
            raise self.fail(value, path)
        return value


class Choice(Spec):
    """One of a few strings."""

    def __init__(self, choices: Sequence[str], **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.choices = list(choices)
        self.expected = "one of " + ", ".join(repr(c) for c in self.choices)

    def parse_plain(self, value: Any, path: str) -> str:
        if not isinstance(value, str) or value.lower() not in self.choices:
            hint = suggest(value.lower(), self.choices) if isinstance(value, str) else ""
            raise RecipeError(path, f"expected {self.expected}, got {describe(value)}{hint}")
        return value.lower()


class Text(Spec):
    """A non-empty string of bounded length (a formula: data, parsed, never run as code)."""

    def __init__(self, max_length: int = 2000, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.max_length = max_length
        self.expected = f"a non-empty string of at most {max_length} characters"

    def parse_plain(self, value: Any, path: str) -> str:
        if not isinstance(value, str) or not value.strip() or len(value) > self.max_length:
            raise self.fail(value, path)
        return value


class Point(Spec):
    """A point ``[lon, lat]`` in degrees; the whole point or each coordinate may be a track."""

    expected = "a point [lon, lat] in degrees (lat from -90 to 90)"
    trackable = True
    _lon = Real()
    _lat = Real(ge=-90, le=90)

    def parse_plain(self, value: Any, path: str) -> tuple[Any, Any]:
        if not isinstance(value, list) or len(value) != 2:
            raise self.fail(value, path)
        lon = self._lon.parse(value[0], f"{path}[0]")
        lat = self._lat.parse(value[1], f"{path}[1]")
        return (lon, lat)

    def parse_track(self, value: dict[str, Any], path: str) -> Track:
        track = super().parse_track(value, path)
        for _, v in track.keyframes:
            if any(isinstance(c, Track) for c in v):
                raise RecipeError(path, "expected a value, got a track inside a track")
        return track


class Points(Spec):
    """A list of ``n`` points (or ``n_min`` or more when ``n`` is None)."""

    def __init__(self, n: int | None = None, *, n_min: int = 1, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.n, self.n_min = n, n_min
        count = f"{n}" if n is not None else f"{n_min} or more"
        self.expected = f"a list of {count} points [lon, lat]"
        self._point = Point()

    def parse_plain(self, value: Any, path: str) -> tuple[Any, ...]:
        if not isinstance(value, list):
            raise self.fail(value, path)
        if (self.n is not None and len(value) != self.n) or len(value) < self.n_min:
            raise self.fail(value, path)
        return tuple(self._point.parse(p, f"{path}[{k}]") for k, p in enumerate(value))


class ComplexNumber(Spec):
    """A complex number: a real number or ``[re, im]`` (each part may be a track)."""

    expected = "a number or [re, im]"
    _part = Real()

    def parse_plain(self, value: Any, path: str) -> Any:
        if is_number(value) or isinstance(value, dict):
            return (self._part.parse(value, path), 0.0)
        if isinstance(value, list) and len(value) == 2:
            return (
                self._part.parse(value[0], f"{path}[0]"),
                self._part.parse(value[1], f"{path}[1]"),
            )
        raise self.fail(value, path)


class Matrix(Spec):
    """Four complex entries ``[a, b, c, d]`` of ``[[a, b], [c, d]]``."""

    expected = "four complex entries [a, b, c, d], each a number or [re, im]"
    _entry = ComplexNumber()

    def parse_plain(self, value: Any, path: str) -> tuple[Any, ...]:
        if not isinstance(value, list) or len(value) != 4:
            raise self.fail(value, path)
        return tuple(self._entry.parse(v, f"{path}[{k}]") for k, v in enumerate(value))


class RealOrAuto(Real):
    """``"auto"`` or a number in a range."""

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.expected = f"'auto' or {self.expected}"

    def parse(self, value: Any, path: str) -> Any:
        if value == "auto":
            return "auto"
        return super().parse(value, path)


#: the directory a recipe's relative file names are read from (its own, or the cwd)
_BASE: contextvars.ContextVar[Path | None] = contextvars.ContextVar("recipe_base", default=None)


@contextlib.contextmanager
def base_dir(path: str | os.PathLike[str] | None) -> Iterator[None]:
    """Resolve the :class:`File` parameters parsed inside the block against ``path``."""
    token = _BASE.set(None if path is None else Path(path))
    try:
        yield
    finally:
        _BASE.reset(token)


#: the only files :class:`File` parameters may name (resolved paths), or None: any file
_ALLOWED: contextvars.ContextVar[frozenset[Path] | None] = contextvars.ContextVar(
    "recipe_allowed_files", default=None
)


class FileRefused(RecipeError):
    """A :class:`File` parameter naming a file outside :func:`allowed_files`."""


@contextlib.contextmanager
def allowed_files(paths: Iterable[str | os.PathLike[str]] | None) -> Iterator[None]:
    """Refuse, inside the block, a :class:`File` parameter naming a file not in ``paths``.

    The viewer's server parses the recipes a page sends inside this block: a recipe
    from the network may name only the files the server was started with. The check
    comes before the file is looked at, so the refusal says nothing of other files.

    Examples
    --------
    >>> from spherewarp.recipe import Recipe, RecipeError
    >>> step = {"schottky": {"mask": "/etc/hostname", "targets": []}}
    >>> with allowed_files([]):
    ...     Recipe.from_dict({"spherewarp": 1, "steps": [step]})  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    spherewarp.recipe.params.FileRefused: steps[0].schottky.mask: '/etc/hostname' is not ...
    """
    allowed = None if paths is None else frozenset(Path(p).resolve() for p in paths)
    token = _ALLOWED.set(allowed)
    try:
        yield
    finally:
        _ALLOWED.reset(token)


class File(Spec):
    """A file name (a mask image), relative to the recipe's directory; read, never run."""

    expected = "a file name"

    def parse_plain(self, value: Any, path: str) -> Path:
        if not isinstance(value, str) or not value.strip() or len(value) > 4096 or "\0" in value:
            raise self.fail(value, path)
        p = Path(value).expanduser()
        base = _BASE.get()
        if not p.is_absolute() and base is not None:
            p = base / p
        allowed = _ALLOWED.get()
        if allowed is not None and p.resolve() not in allowed:
            raise FileRefused(
                path,
                f"{value!r} is not a file this viewer was started with (a mask must be "
                "named by its --recipe, or given with --mask)",
            )
        if not p.is_file():
            why = "not a regular file" if p.exists() else "not found"
            raise RecipeError(path, f"expected an image file, got {value!r} ({why}: {p})")
        return p


class Disk(Spec):
    """A disk ``[lon, lat, radius]`` in degrees (the radius from 0 to 90, exclusive of 0)."""

    expected = "a disk [lon, lat, radius] in degrees (lat from -90 to 90, radius > 0)"
    _lon = Real()
    _lat = Real(ge=-90, le=90)
    _radius = Real(gt=0, le=180)

    def parse_plain(self, value: Any, path: str) -> tuple[float, float, float]:
        if not isinstance(value, list) or len(value) != 3:
            raise self.fail(value, path)
        return (
            self._lon.parse_plain(value[0], f"{path}[0]"),
            self._lat.parse_plain(value[1], f"{path}[1]"),
            self._radius.parse_plain(value[2], f"{path}[2]"),
        )


def _object(value: Any, path: str, forms: dict[str, tuple[str, ...]], what: str) -> dict:
    """Check a small JSON object whose fields are one of ``forms`` (name -> fields)."""
    if not isinstance(value, dict):
        raise RecipeError(path, f"expected {what}, got {describe(value)}")
    known = sorted({k for f in forms.values() for k in f})
    for key in value:
        if key not in known:
            raise RecipeError(f"{path}.{key}", f"unknown field{suggest(key, known)} "
                              f"(expected one of {', '.join(known)})")  # fmt: skip
    return value


class Generators(Spec):
    """Schottky generators: ``{"disk": D, "to": D, "twist": DEG}`` or ``{"disk": D,
    "matrix": [a, b, c, d]}`` each (``D`` a :class:`Disk`)."""

    expected = "a list of generators {disk, to[, twist]} or {disk, matrix}"
    _disk = Disk()
    _twist = Real()

    def parse_plain(self, value: Any, path: str) -> tuple[dict[str, Any], ...]:
        if not isinstance(value, list) or len(value) > 64:
            raise self.fail(value, path, "a list of at most 64 generators")
        out = []
        forms = {"disks": ("disk", "to", "twist"), "matrix": ("disk", "matrix")}
        for k, g in enumerate(value):
            where = f"{path}[{k}]"
            g = _object(g, where, forms, "a generator {disk, to} or {disk, matrix}")
            if "disk" not in g:
                raise RecipeError(f"{where}.disk", f"missing: expected {Disk.expected}")
            if ("to" in g) == ("matrix" in g):
                raise RecipeError(where, "expected 'to' (a second disk) or 'matrix', not "
                                  + ("both" if "to" in g else "neither"))  # fmt: skip
            item: dict[str, Any] = {"disk": self._disk.parse(g["disk"], f"{where}.disk")}
            if "to" in g:
                item["to"] = self._disk.parse(g["to"], f"{where}.to")
                item["twist"] = self._twist.parse(g.get("twist", 0.0), f"{where}.twist")
            else:
                if "twist" in g:
                    raise RecipeError(f"{where}.twist", "a twist goes with 'to', not 'matrix'")
                item["matrix"] = Matrix().parse(g["matrix"], f"{where}.matrix")
            out.append(item)
        return tuple(out)


class Targets(Spec):
    """Where each mask colour's outside goes: ``{"colour": C, "to": D}`` or
    ``{"colour": C, "zoom": F}`` (F > 1)."""

    expected = "a list of targets {colour, to} or {colour, zoom}"
    _disk = Disk()
    _zoom = Real(gt=1, le=1e9)

    def parse_plain(self, value: Any, path: str) -> tuple[dict[str, Any], ...]:
        if not isinstance(value, list) or not value or len(value) > 64:
            raise self.fail(value, path, "a list of 1 to 64 targets")
        forms = {"disk": ("colour", "to"), "zoom": ("colour", "zoom")}
        out = []
        for k, g in enumerate(value):
            where = f"{path}[{k}]"
            g = _object(g, where, forms, "a target {colour, to} or {colour, zoom}")
            colour = g.get("colour")
            if not isinstance(colour, str) or not colour.strip() or len(colour) > 40:
                raise RecipeError(f"{where}.colour", "expected a colour name or #RRGGBB, got "
                                  + describe(colour))  # fmt: skip
            if ("to" in g) == ("zoom" in g):
                raise RecipeError(where, "expected 'to' (a disk) or 'zoom' (a factor > 1), not "
                                  + ("both" if "to" in g else "neither"))  # fmt: skip
            item: dict[str, Any] = {"colour": colour.strip()}
            if "to" in g:
                item["to"] = self._disk.parse(g["to"], f"{where}.to")
            else:
                item["zoom"] = self._zoom.parse(g["zoom"], f"{where}.zoom")
            out.append(item)
        return tuple(out)
