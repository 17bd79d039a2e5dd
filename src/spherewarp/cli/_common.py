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

from ..errors import InvalidValueError, OutputExistsError, SpherewarpError

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
    "OutputPlan",
    "plan_output",
    "convert_for_output",
    "check_size_limit",
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


class ColorType(click.ParamType):
    """A colour name (black, white, grey, ...) or hex code ``#RRGGBB``."""

    name = "COLOR"

    def convert(self, value: Any, param: Any, ctx: Any) -> str:
        from ..io.tonemap import parse_color

        try:
            parse_color(value)
        except InvalidValueError as exc:
            self.fail(str(exc), param, ctx)
        return str(value).strip()


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


_NOTES_SHOWN: set[str] = set()


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
    tonemap: str = "aces"
    exposure: float = 0.0
    background: str | None = None
    quiet: bool = False
    max_pixels: int | None = None
    #: ``-o`` names a directory (an existing one, or a path ending in '/'): outputs go into it
    output_dir: bool = False
    #: the output grid (``--projection``, ``--view-at``, ``--view-roll``, ``--fov``)
    projection: str | None = None
    view_at: tuple[float, float] | None = None
    view_roll: float = 0.0
    fov: float | None = None

    def progress(self, desc: str = "rendering") -> Any:
        """A ``progress`` callback for :func:`spherewarp.warp`: a bar on a terminal
        (:mod:`spherewarp.cli._progress`), or None with ``--quiet``."""
        if self.quiet:
            return None
        from ._progress import ProgressBar

        bar = ProgressBar(desc)
        return bar if bar.enabled else None

    def note(self, text: str) -> None:
        """Print ``spherewarp: note: TEXT`` on stderr, unless ``--quiet`` or already printed
        (a command writing many frames says it once)."""
        if not self.quiet and text not in _NOTES_SHOWN:
            _NOTES_SHOWN.add(text)
            click.echo(f"spherewarp: note: {text}", err=True)

    @property
    def panorama(self) -> bool:
        """The output is an equirectangular panorama (it carries GPano)."""
        return self.projection in (None, "equirect")

    def grid(self, in_shape: tuple[int, ...]) -> Any:
        """The output grid for an input of ``in_shape``, or None for the plain panorama."""
        if self.projection is None and self.view_at is None and not self.view_roll:
            if self.fov is not None:
                raise InvalidValueError(
                    "--fov needs a --projection (little-planet, rectilinear, fisheye, ...)"
                )
            return None
        from ..grids import make_grid

        size = None if self.size is None else (self.size[1], self.size[0])
        return make_grid(
            self.projection or "equirect", in_shape[:2], shape=size, look_at=self.view_at,
            roll=self.view_roll, fov=self.fov,
        )  # fmt: skip

    def refuse_view(self, command: str) -> None:
        """For commands with an output of their own (a Peirce square, a torus): refuse the
        output grid options."""
        if self.projection is not None or self.view_at is not None or self.view_roll or self.fov:
            raise InvalidValueError(
                f"{command} makes its own picture: --projection, --view-at, --view-roll and "
                f"--fov do not apply (spherewarp project --to {command} renders it as a grid)"
            )

    def warp_kwargs(self, pixels: Any) -> dict[str, Any]:
        """Keyword arguments for :func:`spherewarp.warp`."""
        kwargs: dict[str, Any] = {
            "interp": self.interp,
            "supersample": self.supersample,
            "antialias": self.antialias,
            "threads": self.threads,
            "force": self.force,
            "progress": self.progress(),
        }
        grid = self.grid(pixels.shape)
        if grid is not None:
            kwargs["grid"] = grid
        elif self.size is not None:
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
            type=click.Path(path_type=Path),  # a folder fails on its own, as a bad file does
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
    from ..errors import ImageFormatError, SpherewarpError
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

    def call(path: Path) -> None:
        if isinstance(path, Path) and path.is_dir():  # said before its output's name is
            raise ImageFormatError(f"cannot read '{path}': is a directory, expected an image file")
        func(input=path, **kwargs)

    if len(inputs) == 1:
        new_job(Job(reads=reads))
        call(inputs[0])
        return
    written: list[tuple[Path, str]] = []
    failed = 0
    for path in inputs:
        job = new_job(Job(reads=reads, writes=tuple(written)))
        try:
            call(path)
        except (SpherewarpError, OSError, MemoryError) as exc:
            if _signals.requested() is not None:
                raise  # interrupted: stop the batch
            click.echo(error_line(exc)[0], err=True)  # type: ignore[index]
            failed += 1
        new = job.written[len(written) :]  # the job was seeded with ``written``
        written += [(p, f"input {str(path)!r}") for p, _ in new]
    if failed:
        raise SpherewarpError(f"{failed} of {len(inputs)} inputs failed (each said why above)")


_TONEMAPS = ("aces", "reinhard", "clip")  # spherewarp.io.tonemap.TONEMAPS (not imported here)

max_pixels_option = click.option(
    "--max-pixels",
    type=click.IntRange(min=1),
    metavar="N",
    help="Refuse inputs of more pixels than N, counting every EXR part and the canvas a "
    "GPano XMP declares (default: $SPHEREWARP_MAX_PIXELS, else 268435456 = 2**28).",
)
"""The ``--max-pixels`` option: the pixel limit of :func:`spherewarp.io.pixel_limit`."""


def check_size_limit(
    size: tuple[int, int] | None,
    max_pixels: int | None,
    *,
    option: bool = True,
    hint: str = "--size",
) -> None:
    """An output larger than the pixel limit could not be read back: refuse it up front.

    ``option``: the command has ``--max-pixels`` (else only the environment sets the limit);
    ``hint``: where the size came from (``--size``, or a recipe's ``view.size``).
    """
    from ..io.images import MAX_PIXELS_ENV, pixel_limit

    limit = pixel_limit(max_pixels)
    if size is not None and size[0] * size[1] > limit:
        raise click.BadParameter(
            f"{size[0]}x{size[1]} = {size[0] * size[1]} pixels is more than the pixel limit "
            f"{limit}; choose a smaller --size or raise the limit "
            f"({'--max-pixels or ' if option else ''}{MAX_PIXELS_ENV})",
            param_hint=hint,
        )


#: ``--projection`` names (spherewarp.grids.GRIDS; not imported here, to start fast)
PROJECTIONS = (
    "equirect", "little-planet", "stereographic", "rectilinear", "fisheye", "equisolid",
    "cubemap", "cubemap-6x1", "peirce", "torus",
)  # fmt: skip

view_options = [
    click.option(
        "--projection",
        type=click.Choice(PROJECTIONS, case_sensitive=False),
        help="Output grid: equirect (default), little-planet (= stereographic: the nadir in "
        "the middle, the sky round it), rectilinear (a flat view), fisheye (equidistant), "
        "equisolid, cubemap (v360's 3x2 sheet: right left up / down front back), "
        "cubemap-6x1, peirce (quincuncial: the whole sphere on a square), torus (the "
        "torus cell of the square lattice). Only equirect outputs carry GPano.",
    ),
    click.option(
        "--view-at",
        "view_at",
        type=PointType(),
        help="Point LON,LAT the output grid looks at (its centre; default: the grid's own, "
        "0,-90 for little-planet, 0,90 for peirce and torus, else 0,0).",
    ),
    click.option(
        "--view-roll",
        "view_roll",
        type=RealType("an angle in degrees", "10", metavar="DEG"),
        default=0.0,
        help="Roll the output grid by DEG (as ffmpeg v360's roll).",
    ),
    click.option(
        "--fov",
        type=RealType("a field of view in degrees", "90", metavar="DEG", gt=0, le=360),
        help="Field of view of the output grid (little-planet: 270 across the shorter side; "
        "rectilinear: 90 horizontal; fisheyes: 180).",
    ),
]
"""The options of the output grid, part of :func:`render_options`."""


def add_view_aliases(command: click.Command) -> click.Command:
    """Give the grid options the names ``--look-at`` and ``--roll`` too, where ``command``
    has no option of that name of its own (``rotate --roll`` turns the panorama and
    ``power/exp/map/splitscreen --look-at`` turn the result; there only ``--view-roll``
    and ``--view-at`` address the grid)."""
    taken = {o for p in command.params for o in getattr(p, "opts", ())}
    for param in command.params:
        for name, alias in (("view_at", "--look-at"), ("view_roll", "--roll")):
            if param.name == name and alias not in taken and alias not in param.opts:
                param.opts.append(alias)
    return command


def render_options(func: Callable) -> Callable:
    """``-o``, ``--overwrite``, ``--force``, ``--size``, ``--interp``, ``--supersample``,
    ``--antialias``, ``--threads``, ``--quality``, ``--tonemap``, ``--exposure``,
    ``--background``, ``--quiet``, ``--max-pixels`` and the output grid's
    (:data:`view_options`: ``--projection``, ``--view-at``, ``--view-roll``, ``--fov``);
    the command receives them as one
    ``render`` argument."""
    options = [
        click.option(
            "-o",
            "--output",
            type=click.Path(path_type=str),
            help="Output file; its extension picks the format (.jpg .png .tif .webp .exr). "
            "Default: INPUT's name with the command appended (in.jpg -> in-COMMAND.jpg), in "
            "the current directory; -o DIR/ (an existing directory or a name ending in /) puts "
            "that name into DIR. The sample type is kept where the format holds it (8/16-bit "
            "PNG and TIFF, float TIFF and EXR); else it is converted, with a note: HDR (float) "
            "to JPEG/WebP is tone-mapped to 8-bit sRGB and to PNG to 16-bit (--tonemap), "
            "16-bit to JPEG/WebP becomes 8-bit, 8/16-bit (sRGB) to EXR becomes linear-light "
            "float, and transparency (a cropped panorama's "
            "uncovered part) is flattened for JPEG (--background).",
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
            help="Sampling of the input. The area filter (--antialias auto/area) averages "
            "the bilinear surface; with bicubic or nearest, area becomes uniform 4x4 "
            "supersampling.",
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
            "in 1/6 to 1/4 of the time of 4x4 on zooms and Droste images); adaptive: "
            "supersample only where a pixel covers several input pixels (sharper, cheaper); "
            "none; or N for uniform NxN.",
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
        click.option(
            "--tonemap",
            type=click.Choice(list(_TONEMAPS), case_sensitive=False),
            default="aces",
            show_default=True,
            help="How HDR (float, linear light: EXR) becomes 8/16-bit sRGB for JPEG, PNG or "
            "WebP. aces: filmic curve, keeps mid-tone contrast and rolls highlights (lamps, "
            "windows) off instead of cutting them to white; reinhard: x/(1+x), never "
            "clips, flatter; clip: linear, highlights above 1 cut off.",
        ),
        click.option(
            "--exposure",
            type=RealType("an exposure in stops", "1 or -0.5", metavar="EV", ge=-20, le=20),
            default=0.0,
            show_default=True,
            help="Scale HDR values by 2^EV (EV stops) before tone mapping.",
        ),
        click.option(
            "--background",
            type=ColorType(),
            help="Flatten transparency onto this colour (name or #RRGGBB) and drop the alpha "
            "channel. Default: kept where the format has alpha; black for JPEG.",
        ),
        click.option(
            "-q",
            "--quiet",
            is_flag=True,
            help="No progress bar and no notes (the 'wrote ...' line stays). The bar "
            "appears only on a terminal, for renders longer than a second.",
        ),
        max_pixels_option,
        *view_options,
    ]

    def wrapper(**kwargs: Any) -> Any:
        check_size_limit(kwargs["size"], kwargs["max_pixels"])
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
            tonemap=kwargs.pop("tonemap").lower(),
            exposure=kwargs.pop("exposure"),
            background=kwargs.pop("background"),
            quiet=kwargs.pop("quiet"),
            max_pixels=kwargs.pop("max_pixels"),
            projection=kwargs.pop("projection"),
            view_at=kwargs.pop("view_at"),
            view_roll=kwargs.pop("view_roll"),
            fov=kwargs.pop("fov"),
        )
        if render.quiet:
            from .._compile_notice import disable

            disable()  # --quiet: no compile notice either
        return func(render=render, **kwargs)

    wrapper.__name__ = func.__name__
    wrapper.__doc__ = func.__doc__
    # Keep the options that decorators below this one attached to ``func``.
    wrapper.__click_params__ = list(getattr(func, "__click_params__", []))  # type: ignore[attr-defined]
    for option in reversed(options):
        wrapper = option(wrapper)
    return wrapper


def load_input(path: Path | str, render: RenderOptions | None = None, label: str = "input") -> Any:
    """Read an input image (``ImageData``), refusing a non-2:1 one unless ``--force``.

    The path is registered as read (``label`` names it in an error), so no output may be it;
    an fsspec URL (a str, :mod:`spherewarp.io.remote`) is downloaded and read, never written.
    """
    from ..io import read_image
    from ..io.remote import is_url, local_copy
    from ..render.warp import as_image, check_equirect
    from ._files import job

    limit = render.max_pixels if render else None
    if is_url(path):
        with local_copy(str(path)) as local:
            try:
                data = read_image(local, max_pixels=limit)
            except SpherewarpError as exc:  # name the URL, not the local copy
                raise type(exc)(exc.cli_message.replace(local, str(path))) from None
    else:
        job().reads(path, label)
        data = read_image(path, max_pixels=limit)
    check_equirect(data.pixels, force=bool(render and render.force), name=str(path))
    as_image(data.pixels, name=str(path))  # its shape, naming the file (in a batch too)
    if render is not None and data.pixels.dtype.kind == "f":
        import numpy as np

        bad = int(data.pixels.size - np.count_nonzero(np.isfinite(data.pixels)))
        if bad:  # a renderer's fireflies: said once, kept as they are (no value is invented)
            render.note(
                f"'{path}' has {bad} NaN or infinite sample(s); they spread to the output "
                "pixels that sample them"
            )
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

    Pixels the format cannot hold are converted first (:func:`convert_for_output`).
    ``source`` is the input's ``ImageData`` (or None). ``gpano=False`` for outputs that
    are not equirectangular panoramas (a Peirce square, a torus texture). Prints the path
    written.
    """
    from ..io import write_image

    out = output_path(render, getattr(source, "path", None), command)
    if not render.panorama:  # a little planet, a flat view, a cube map: no GPano
        gpano = False
    pixels = convert_for_output(pixels, out, render)
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


@dataclass(frozen=True)
class OutputPlan:
    """What :func:`convert_for_output` does to pixels for a format.

    Attributes
    ----------
    format : str
        The format name (``"JPEG"``, ...), ``""`` for an unknown extension.
    dtype : str
        The sample type written (``"uint8"``, ``"uint16"``, ``"float32"``).
    tonemap : bool
        HDR float pixels are tone-mapped to display values first.
    flatten : bool
        The alpha channel is flattened onto the background colour.
    reduce : bool
        16-bit pixels become 8-bit.
    linearize : bool
        Integer (sRGB-encoded) pixels become linear-light float for EXR (done by
        :func:`~spherewarp.io.write_image`; the plan only notes it).
    """

    format: str
    dtype: str
    tonemap: bool = False
    flatten: bool = False
    reduce: bool = False
    linearize: bool = False

    def note(self, render: RenderOptions) -> str | None:
        """One line saying what is done, or None when nothing is."""
        bits = {"uint8": "8-bit", "uint16": "16-bit"}.get(self.dtype, self.dtype)
        parts = []
        if self.tonemap:
            ev = f", --exposure {render.exposure:g}" if render.exposure else ""
            parts.append(
                f"tone-mapped HDR to {bits} sRGB (--tonemap {render.tonemap}{ev}; "
                "choose with --tonemap)"
            )
        if self.reduce:
            parts.append("reduced 16-bit samples to 8-bit")
        if self.linearize:
            parts.append(
                "converted the sRGB-encoded samples to linear-light float (EXR holds linear light)"
            )
        if self.flatten:
            parts.append(
                f"flattened transparency onto {render.background or 'black'} "
                "(choose with --background)"
            )
        return f"{self.format}: " + " and ".join(parts) if parts else None


def plan_output(path: Path, dtype: Any, channels: int, render: RenderOptions) -> OutputPlan:
    """How pixels of ``dtype`` with ``channels`` must change to be written to ``path``.

    Float (HDR) to a format without float: tone-mapped to 16 bits where the
    format has them (PNG), else 8; uint16 to JPEG/WebP: 8 bits; 2 or 4 channels
    to JPEG, or with ``--background``: alpha flattened; integer to EXR: written as
    linear-light float (by :func:`~spherewarp.io.write_image`, noted here). Everything
    else is kept.

    Examples
    --------
    >>> r = RenderOptions(None, False, False, None, "bilinear", 1, 95)
    >>> plan_output(Path("a.jpg"), "float32", 4, r)  # doctest: +NORMALIZE_WHITESPACE
    OutputPlan(format='JPEG', dtype='uint8', tonemap=True, flatten=True, reduce=False,
               linearize=False)
    >>> plan_output(Path("a.png"), "float32", 3, r).dtype
    'uint16'
    >>> plan_output(Path("a.exr"), "float32", 4, r)  # doctest: +NORMALIZE_WHITESPACE
    OutputPlan(format='EXR', dtype='float32', tonemap=False, flatten=False, reduce=False,
               linearize=False)
    >>> plan_output(Path("a.exr"), "uint8", 3, r).linearize
    True
    """
    import numpy as np

    from ..io import SUPPORTED_EXTENSIONS
    from ..io.images import _FORMAT_DTYPES

    dt = np.dtype(dtype)
    fmt = SUPPORTED_EXTENSIONS.get(path.suffix.lower(), "")
    if not fmt:
        return OutputPlan(fmt, dt.name)
    holds = _FORMAT_DTYPES[fmt]
    flatten = channels in (2, 4) and (fmt == "JPEG" or render.background is not None)
    if dt.kind == "f" and np.dtype(np.float32) not in holds:
        target = np.uint16 if np.dtype(np.uint16) in holds else np.uint8
        return OutputPlan(fmt, np.dtype(target).name, tonemap=True, flatten=flatten)
    if dt == np.uint16 and dt not in holds:
        return OutputPlan(fmt, "uint8", flatten=flatten, reduce=True)
    if fmt == "EXR" and dt.kind == "u":  # write_image linearises: EXR holds linear light
        return OutputPlan(fmt, "float32", flatten=flatten, linearize=True)
    return OutputPlan(fmt, dt.name, flatten=flatten)


def convert_for_output(pixels: Any, path: Path, render: RenderOptions) -> Any:
    """``pixels`` as the format of ``path`` can hold them (:func:`plan_output`),
    printing a note of what was done (unless ``--quiet``)."""
    import numpy as np

    from ..io import convert_dtype
    from ..io.tonemap import flatten_alpha, tonemap

    if not isinstance(pixels, np.ndarray) or pixels.ndim != 3:
        return pixels
    plan = plan_output(path, pixels.dtype, pixels.shape[2], render)
    if plan.tonemap:
        pixels = tonemap(pixels, render.tonemap, render.exposure)
    if plan.flatten:
        pixels = flatten_alpha(pixels, render.background or "black")
    if plan.tonemap or plan.reduce:
        pixels = convert_dtype(pixels, np.dtype(plan.dtype))
    note = plan.note(render)
    if note:
        render.note(note)
    return pixels
