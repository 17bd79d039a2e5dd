"""Options and helpers shared by the subcommands.

A subcommand that renders one image looks like this::

    @click.command(epilog=example("spherewarp rotate in.jpg --yaw 30 -o out.jpg"))
    @input_argument
    @render_options
    @click.option("--yaw", type=float, default=0.0)
    def rotate(input, render, yaw):
        src = load_input(input, render)
        out = warp(src.pixels, inverse_map, **render.warp_kwargs(src.pixels))
        save_output(out, src, render, command="rotate")

Values are parsed by click types that raise one-line errors naming the option.
"""

from __future__ import annotations

import functools
import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import click

from ..errors import InvalidValueError, OutputExistsError

__all__ = [
    "POINT",
    "PIXEL",
    "COMPLEX",
    "SIZE",
    "RealType",
    "RenderOptions",
    "example",
    "input_argument",
    "render_options",
    "load_input",
    "save_output",
    "output_name",
    "output_path",
    "run_inputs",
]


def example(*lines: str) -> str:
    """An epilog for ``--help`` showing example command lines."""
    body = "\n".join(f"  {line}" for line in lines)
    return f"\b\nExample{'s' if len(lines) > 1 else ''}:\n{body}"


class PointType(click.ParamType):
    """``LON,LAT`` in degrees."""

    name = "LON,LAT"

    def convert(self, value: Any, param: Any, ctx: Any) -> tuple[float, float]:
        if isinstance(value, tuple):
            return value
        from ..coords import parse_lonlat

        try:
            return parse_lonlat(value)
        except InvalidValueError as exc:
            self.fail(str(exc), param, ctx)


class PixelType(click.ParamType):
    """``X,Y`` in pixels of the input image."""

    name = "X,Y"

    def convert(self, value: Any, param: Any, ctx: Any) -> tuple[float, float]:
        if isinstance(value, tuple):
            return value
        try:
            x, y = (float(v) for v in str(value).replace(" ", "").split(","))
        except ValueError:
            self.fail(f"expected a pixel position X,Y (e.g. 512,256), got {value!r}", param, ctx)
        return x, y


class ComplexType(click.ParamType):
    """A complex number such as ``2``, ``-0.5j``, ``1+2j`` or ``1+2i``."""

    name = "COMPLEX"

    def convert(self, value: Any, param: Any, ctx: Any) -> complex:
        if isinstance(value, complex):
            return value
        text = str(value).strip().replace(" ", "").replace("i", "j").replace("J", "j")
        try:
            c = complex(text)
        except ValueError:
            self.fail(f"expected a complex number like 1+2j, got {value!r}", param, ctx)
        if c != c or abs(c) == float("inf"):
            self.fail(f"expected a finite complex number, got {value!r}", param, ctx)
        return c


class SizeType(click.ParamType):
    """``WxH`` in pixels, or ``W`` alone for a 2:1 image of that width."""

    name = "WxH"

    def convert(self, value: Any, param: Any, ctx: Any) -> tuple[int, int]:
        if isinstance(value, tuple):
            return value
        text = str(value).lower().replace(" ", "")
        try:
            if "x" in text:
                w, h = (int(v) for v in text.split("x"))
            else:
                w = int(text)
                h = w // 2
        except ValueError:
            self.fail(f"expected a size WxH like 2048x1024, got {value!r}", param, ctx)
        if not (1 <= w <= 65536 and 1 <= h <= 32768):
            self.fail(f"expected a size between 1x1 and 65536x32768, got {value!r}", param, ctx)
        return w, h


class AntialiasType(click.ParamType):
    """``auto``, ``area``, ``adaptive``, ``none`` or an integer N (uniform NxN supersampling)."""

    name = "auto|area|adaptive|none|N"

    def convert(self, value: Any, param: Any, ctx: Any) -> str | int:
        if isinstance(value, int) and not isinstance(value, bool):
            return value
        text = str(value).strip().lower()
        if text in ("auto", "area", "adaptive", "none"):
            return text
        try:
            n = int(text)
        except ValueError:
            n = 0
        if not 1 <= n <= 16:
            self.fail(
                f"expected auto, area, adaptive, none or an integer 1..16, got {value!r}",
                param,
                ctx,
            )
        return n


class RealType(click.ParamType):
    """A finite real number, optionally bounded: ``RealType("a zoom factor", "2", gt=0)``.

    Errors read "expected <what> <bounds> (e.g. <example>), got '<value>'".
    """

    def __init__(
        self,
        what: str,
        example: str,
        *,
        metavar: str = "X",
        gt: float | None = None,
        ge: float | None = None,
        le: float | None = None,
        hint: str = "",
    ):
        self.what, self.example, self.name = what, example, metavar
        self.gt, self.ge, self.le, self.hint = gt, ge, le, hint

    def _bounds(self) -> str:
        if self.ge is not None and self.le is not None:
            return f" from {self.ge:g} to {self.le:g}"
        parts = []
        if self.gt is not None:
            parts.append(f"> {self.gt:g}")
        if self.ge is not None:
            parts.append(f">= {self.ge:g}")
        if self.le is not None:
            parts.append(f"<= {self.le:g}")
        return (" " + " and ".join(parts)) if parts else ""

    def convert(self, value: Any, param: Any, ctx: Any) -> float:
        if isinstance(value, float):
            return value
        expected = f"expected {self.what}{self._bounds()} (e.g. {self.example}{self.hint})"
        try:
            v = float(str(value).strip())
        except ValueError:
            self.fail(f"{expected}, got {value!r}", param, ctx)
        if v != v or abs(v) == float("inf"):
            self.fail(f"expected a finite value: {expected[9:]}, got {value!r}", param, ctx)
        ok = (self.gt is None or v > self.gt) and (self.ge is None or v >= self.ge)
        if not ok or (self.le is not None and v > self.le):
            self.fail(f"{expected}, got {value!r}", param, ctx)
        return v


POINT = PointType()
PIXEL = PixelType()
COMPLEX = ComplexType()
SIZE = SizeType()


@dataclass(frozen=True)
class RenderOptions:
    """The options every rendering command shares."""

    output: Path | None
    overwrite: bool
    force: bool
    size: tuple[int, int] | None
    interp: str
    supersample: int
    quality: int
    antialias: str | int = "auto"
    threads: int | None = None
    #: ``-o`` names a directory (an existing one, or a path ending in '/'): outputs go into it
    output_dir: bool = False

    def warp_kwargs(self, pixels: Any) -> dict[str, Any]:
        """Keyword arguments for :func:`spherewarp.warp`."""
        kwargs: dict[str, Any] = {
            "interp": self.interp,
            "supersample": self.supersample,
            "antialias": self.antialias,
            "threads": self.threads,
            "force": self.force,
        }
        if self.size is not None:
            kwargs["output_shape"] = (self.size[1], self.size[0])
        return kwargs


def input_argument(func: Callable | None = None, *, required: bool = True) -> Callable:
    """The ``INPUT...`` argument: one image, or several processed one after the other.

    The command function still receives one ``input`` (None when the argument
    is optional and missing) and is called once for each. With several inputs,
    ``-o`` must name a directory (or be left out); each input's output gets the
    name it would get on its own. An input that fails (unreadable, its output
    exists, ...) reports its one error line and the batch goes on; the command
    then exits with status 2. A usage error stops the batch.
    """

    def decorate(func: Callable) -> Callable:
        @functools.wraps(func)
        def each_input(input: tuple[Path, ...], **kwargs: Any) -> None:
            run_inputs(func, input, kwargs)

        each_input.__doc__ = (func.__doc__ or "").rstrip() + _BATCH_HELP
        return click.argument(
            "input",
            nargs=-1,
            required=required,
            type=click.Path(dir_okay=False, path_type=Path),
            metavar="INPUT..." if required else "[INPUT...]",
        )(each_input)

    return decorate if func is None else decorate(func)


_BATCH_HELP = """

    Several INPUTs are processed one after the other in one run: -o DIR/ puts
    each output into DIR under the name it would get on its own;
    an input that fails says why in one line, the others go on, and the exit
    status is then 2. No output may be an input (checked before any work).
    """


def _names_directory(output: str | None) -> bool:
    return output is not None and (output.endswith(("/", os.sep)) or os.path.isdir(output))


def run_inputs(func: Callable, inputs: tuple[Path, ...], kwargs: dict[str, Any]) -> None:
    """Call ``func(input=..., **kwargs)`` for each input, each with a fresh
    :class:`~spherewarp.cli._files.Job` that also knows the batch's other inputs and the
    outputs written so far (so no input is overwritten and no output written twice)."""
    from .. import _signals
    from ..errors import SpherewarpError
    from . import error_line
    from ._files import Job, new_job

    if not inputs:
        new_job()
        func(input=None, **kwargs)
        return
    output = kwargs.get("output")
    if len(inputs) > 1 and output is not None and not _names_directory(output):
        raise click.UsageError(
            f"-o {output!r}: several inputs need -o DIR/ (a directory, made if missing) or no -o"
        )
    reads = tuple((p, "input") for p in inputs)
    if len(inputs) == 1:
        new_job(Job(reads=reads))
        func(input=inputs[0], **kwargs)
        return
    written: list[tuple[Path, str]] = []
    failed = 0
    for path in inputs:
        job = new_job(Job(reads=reads, writes=tuple(written)))
        try:
            func(input=path, **kwargs)
        except (SpherewarpError, OSError, MemoryError) as exc:
            if _signals.requested() is not None:
                raise  # interrupted: stop the batch
            click.echo(error_line(exc)[0], err=True)  # type: ignore[index]
            failed += 1
        written += [(p, f"input {str(path)!r}") for p, _ in job.written]
    if failed:
        raise SpherewarpError(f"{failed} of {len(inputs)} inputs failed (each said why above)")


def render_options(func: Callable) -> Callable:
    """``-o``, ``--overwrite``, ``--force``, ``--size``, ``--interp``, ``--supersample``,
    ``--antialias``, ``--threads``,
    ``--quality``; the command receives them as one ``render`` argument."""
    options = [
        click.option(
            "-o",
            "--output",
            type=click.Path(path_type=str),
            help="Output file; its extension picks the format. Default: INPUT's name with the "
            "command appended (in.jpg -> in-COMMAND.jpg), in the current directory; -o DIR/ "
            "(an existing directory or a name ending in /) puts that name into DIR.",
        ),
        click.option("--overwrite", is_flag=True, help="Replace an existing output file."),
        click.option(
            "--force", is_flag=True, help="Treat an input that is not 2:1 as equirectangular."
        ),
        click.option("--size", type=SIZE, help="Output size WxH (default: the input's size)."),
        click.option(
            "--interp",
            type=click.Choice(["bilinear", "bicubic", "nearest"], case_sensitive=False),
            default="bilinear",
            show_default=True,
            help="Sampling of the input.",
        ),
        click.option(
            "--supersample",
            type=click.IntRange(1, 16),
            default=1,
            show_default=True,
            help="Average NxN samples in every output pixel (uniform; overrides --antialias).",
        ),
        click.option(
            "--antialias",
            type=AntialiasType(),
            default="auto",
            show_default=True,
            help="auto: 'area' for a map that shrinks the input somewhere, else one bilinear "
            "tap a pixel; area: average every pixel's footprint (as heavy supersampling does, "
            "in about 1/5 of the time of 4x4); adaptive: supersample only where a pixel covers "
            "several input pixels (sharper, cheaper); none; or N for uniform NxN.",
        ),
        click.option(
            "--threads",
            type=click.IntRange(1, 1024),
            help="Threads for rendering (default: all cores).",
        ),
        click.option(
            "--quality",
            type=click.IntRange(1, 100),
            default=95,
            show_default=True,
            help="JPEG/WebP quality.",
        ),
    ]

    def wrapper(**kwargs: Any) -> Any:
        output = kwargs.pop("output")
        render = RenderOptions(
            output=None if output is None else Path(output),
            output_dir=_names_directory(output),
            overwrite=kwargs.pop("overwrite"),
            force=kwargs.pop("force"),
            size=kwargs.pop("size"),
            interp=kwargs.pop("interp").lower(),
            supersample=kwargs.pop("supersample"),
            quality=kwargs.pop("quality"),
            antialias=kwargs.pop("antialias"),
            threads=kwargs.pop("threads"),
        )
        return func(render=render, **kwargs)

    wrapper.__name__ = func.__name__
    wrapper.__doc__ = func.__doc__
    # Keep the options that decorators below this one attached to ``func``.
    wrapper.__click_params__ = list(getattr(func, "__click_params__", []))  # type: ignore[attr-defined]
    for option in reversed(options):
        wrapper = option(wrapper)
    return wrapper


def load_input(path: Path, render: RenderOptions | None = None, label: str = "input") -> Any:
    """Read an input image (``ImageData``), refusing a non-2:1 one unless ``--force``.

    The path is registered as read (``label`` names it in an error), so no output may be it.
    """
    from ..io import read_image
    from ..render.warp import check_equirect
    from ._files import job

    job().reads(path, label)
    data = read_image(path)
    check_equirect(data.pixels, force=bool(render and render.force), name=str(path))
    return data


def output_name(render: RenderOptions, input_path: Path | None, command: str) -> Path:
    """The output's name: ``-o``, else ``<input stem>-<command><input suffix>``, in the cwd or
    in the ``-o DIR/`` directory."""
    if render.output is not None and not render.output_dir:
        return render.output
    if input_path is not None:
        name = f"{input_path.stem}-{command}{input_path.suffix}"
    else:
        name = f"{command}.png"
    return render.output / name if render.output is not None else Path(name)


def output_path(
    render: RenderOptions,
    input_path: Path | None,
    command: str,
    option: str = "-o",
    given: str | None = None,
) -> Path:
    """Where to write (:func:`output_name`), registered as written; refuses an input (any link
    to one included, even with ``--overwrite``) and an existing file without ``--overwrite``.

    ``option`` and ``given`` (what the user typed, e.g. a frame pattern) name it in an error.
    """
    from ._files import job

    out = job().writes(output_name(render, input_path, command), option, given)
    if render.output_dir and render.output is not None:
        render.output.mkdir(parents=True, exist_ok=True)
    if out.exists() and not render.overwrite:
        raise OutputExistsError(f"{str(out)!r} exists; pass --overwrite to replace it")
    return out


def save_output(
    pixels: Any,
    source: Any,
    render: RenderOptions,
    command: str,
    *,
    gpano: bool = True,
) -> Path:
    """Write the result atomically, carrying ICC profile and EXIF over from ``source``.

    ``source`` is the input's ``ImageData`` (or None). ``gpano=False`` for outputs that
    are not equirectangular panoramas (a Peirce square, a torus texture). Prints the path
    written.
    """
    from ..io import write_image

    out = output_path(render, getattr(source, "path", None), command)
    written = write_image(
        out,
        pixels,
        icc_profile=getattr(source, "icc_profile", None),
        exif=getattr(source, "exif", None),
        gpano=gpano,
        quality=render.quality,
        overwrite=render.overwrite,
    )
    click.echo(f"wrote {written}")
    return Path(written)
