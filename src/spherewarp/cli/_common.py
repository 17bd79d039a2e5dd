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
    "output_path",
    "check_size_limit",
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
        if not (1 <= w <= 65536 and 1 <= h <= 32768 and w * h <= 2**30):
            self.fail(
                "expected a size between 1x1 and 65536x32768 of at most 2**30 pixels "
                f"(e.g. 46340x23170), got {value!r}",
                param,
                ctx,
            )
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
    max_pixels: int | None = None

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


def input_argument(func: Callable) -> Callable:
    """The ``INPUT`` image argument."""
    return click.argument(
        "input", type=click.Path(dir_okay=False, path_type=Path), metavar="INPUT"
    )(func)


max_pixels_option = click.option(
    "--max-pixels",
    type=click.IntRange(min=1),
    metavar="N",
    help="Refuse inputs of more pixels than N, counting every EXR part and the canvas a "
    "GPano XMP declares (default: $SPHEREWARP_MAX_PIXELS, else 268435456 = 2**28).",
)
"""The ``--max-pixels`` option: the pixel limit of :func:`spherewarp.io.pixel_limit`."""


def check_size_limit(
    size: tuple[int, int] | None, max_pixels: int | None, *, option: bool = True
) -> None:
    """An output larger than the pixel limit could not be read back: refuse it up front.

    ``option``: the command has ``--max-pixels`` (else only the environment sets the limit).
    """
    from ..io.images import MAX_PIXELS_ENV, pixel_limit

    limit = pixel_limit(max_pixels)
    if size is not None and size[0] * size[1] > limit:
        raise click.BadParameter(
            f"{size[0]}x{size[1]} = {size[0] * size[1]} pixels is more than the pixel limit "
            f"{limit}; choose a smaller --size or raise the limit "
            f"({'--max-pixels or ' if option else ''}{MAX_PIXELS_ENV})",
            param_hint="--size",
        )


def render_options(func: Callable) -> Callable:
    """``-o``, ``--overwrite``, ``--force``, ``--size``, ``--interp``, ``--supersample``,
    ``--antialias``, ``--threads``,
    ``--quality``, ``--max-pixels``; the command receives them as one ``render`` argument."""
    options = [
        click.option(
            "-o",
            "--output",
            type=click.Path(dir_okay=False, path_type=Path),
            help="Output file; its extension picks the format. "
            "Default: INPUT's name with the command appended, in the current directory.",
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
        max_pixels_option,
    ]

    def wrapper(**kwargs: Any) -> Any:
        check_size_limit(kwargs["size"], kwargs["max_pixels"])
        render = RenderOptions(
            output=kwargs.pop("output"),
            overwrite=kwargs.pop("overwrite"),
            force=kwargs.pop("force"),
            size=kwargs.pop("size"),
            interp=kwargs.pop("interp").lower(),
            supersample=kwargs.pop("supersample"),
            quality=kwargs.pop("quality"),
            antialias=kwargs.pop("antialias"),
            threads=kwargs.pop("threads"),
            max_pixels=kwargs.pop("max_pixels"),
        )
        return func(render=render, **kwargs)

    wrapper.__name__ = func.__name__
    wrapper.__doc__ = func.__doc__
    # Keep the options that decorators below this one attached to ``func``.
    wrapper.__click_params__ = list(getattr(func, "__click_params__", []))  # type: ignore[attr-defined]
    for option in reversed(options):
        wrapper = option(wrapper)
    return wrapper


def load_input(path: Path, render: RenderOptions | None = None) -> Any:
    """Read an input image (``ImageData``), refusing a non-2:1 one unless ``--force``."""
    from ..io import read_image
    from ..render.warp import check_equirect

    data = read_image(path, max_pixels=render.max_pixels if render else None)
    check_equirect(data.pixels, force=bool(render and render.force), name=str(path))
    return data


def output_path(render: RenderOptions, input_path: Path | None, command: str) -> Path:
    """Where to write: ``-o``, or ``<input stem>-<command><input suffix>`` in the cwd."""
    if render.output is not None:
        out = render.output
    elif input_path is not None:
        out = Path(f"{input_path.stem}-{command}{input_path.suffix}")
    else:
        out = Path(f"{command}.png")
    if input_path is not None:
        same = out.resolve() == input_path.resolve()
        if not same and out.exists() and input_path.exists():
            same = os.path.samefile(out, input_path)
        if same:
            raise InvalidValueError(
                f"the output {str(out)!r} is the input file; choose another -o (inputs are "
                "never overwritten)"
            )
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
