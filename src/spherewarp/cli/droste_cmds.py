"""``spherewarp droste``: straight and twisted Droste images from a picture frame.

The command names the frame (its corners, a mask or a round radius), builds
the Droste map with :mod:`spherewarp.effects.droste` and renders it with the one
pull-back renderer. ``--frames N`` renders a seamless zoom loop as numbered
images; ``--view log`` writes the log-plane picture instead, with the period
rectangle drawn.
"""

from __future__ import annotations

import math
import re
from dataclasses import replace
from pathlib import Path
from typing import Any

import click

from ._common import POINT, RealType, RenderOptions, example, input_argument, render_options
from .recipe_cmds import (
    print_options,
    recipe_options,
    render_recipe,
    saving_recipe,
)
from .recipe_cmds import print_recipe as show_recipe

__all__ = ["droste", "frame_paths"]


class ScaleType(click.ParamType):
    """``auto`` or a number > 1."""

    name = "LAMBDA|auto"

    def convert(self, value: Any, param: Any, ctx: Any) -> float | str:
        if isinstance(value, float) or value == "auto":
            return value
        text = str(value).strip().lower()
        if text == "auto":
            return "auto"
        try:
            v = float(text)
        except ValueError:
            self.fail(f"expected a scale > 1 (e.g. 8) or 'auto', got {value!r}", param, ctx)
        if not (math.isfinite(v) and v > 1):
            self.fail(
                f"expected a Droste scale > 1 (the annulus runs from the frame to the frame "
                f"scaled by it), got {value!r}",
                param,
                ctx,
            )
        return v


SCALE = ScaleType()
DEGREES = RealType("degrees", "12.5", metavar="DEG")


#: the one frame-number field of a --frames pattern: %d, %0Nd, {} or {:0Nd}, N = 1..9
_FRAME_FIELD = re.compile(r"%(?:0([1-9]))?d|\{(?::(?:0([1-9]))?d)?\}")


def frame_paths(output: Path, n: int) -> list[Path]:
    """The file names of ``n`` frames for ``-o OUTPUT``.

    ``OUT.png`` gives ``OUT_0000.png``, ``OUT_0001.png`` ...; a pattern holds
    one frame-number field, zero-padded to width N (1..9) or not padded,
    written ``%0Nd`` / ``%d`` or ``{:0Nd}`` / ``{}``, and no other ``%``,
    ``{`` or ``}`` (``frames/%04d.png`` puts them into a directory, created if
    missing). Nothing else is interpreted: the pattern is never passed to
    ``%`` or ``str.format``.

    Examples
    --------
    >>> [p.as_posix() for p in frame_paths(Path("loop.png"), 2)]
    ['loop_0000.png', 'loop_0001.png']
    >>> frame_paths(Path("f/x-%03d.exr"), 1)[0].as_posix()
    'f/x-000.exr'
    """
    from ..errors import InvalidValueError

    text = str(output)
    if not any(c in text for c in "%{}"):
        return [output.with_name(f"{output.stem}_{k:04d}{output.suffix}") for k in range(n)]
    fields = list(_FRAME_FIELD.finditer(text))
    rest = _FRAME_FIELD.sub("", text)
    if len(fields) != 1 or any(c in rest for c in "%{}"):
        shown = repr(text) if len(text) <= 80 else repr(text[:80] + "...")
        raise InvalidValueError(
            "expected a frame pattern with one field %0Nd or {:0Nd} (N = 1..9, or %d, {}), "
            f"like out_%04d.png, and no other '%', '{{' or '}}'; got {shown}"
        )
    width = int(fields[0].group(1) or fields[0].group(2) or 0)
    head, tail = text[: fields[0].start()], text[fields[0].end() :]
    return [Path(f"{head}{k:0{width}d}{tail}") for k in range(n)]


def _check_suffix(path: Path) -> None:
    from ..errors import ImageFormatError
    from ..io import SUPPORTED_EXTENSIONS

    if path.suffix.lower() not in SUPPORTED_EXTENSIONS:
        raise ImageFormatError(
            f"cannot write '{path}': unknown extension {path.suffix or '(none)'!r}; "
            f"use one of {', '.join(SUPPORTED_EXTENSIONS)}"
        )


@click.command(
    epilog=example(
        "spherewarp droste interior.png -o droste.png "
        "--frame -173,23.6 -153.8,24.5 -153.8,-14.8 -173,-14.2",
        "spherewarp droste interior.png -o twisted.png --twist "
        "--frame -173,23.6 -153.8,24.5 -153.8,-14.8 -173,-14.2",
        "spherewarp droste room.jpg -o loop.png --center -163,5 --inner-radius 12 --frames 48",
        "spherewarp droste room.jpg -o log.png --mask hole.png --view log",
    )
)
@input_argument
@click.option(
    "--center",
    type=POINT,
    help="The point inside the frame that the copies shrink toward, LON,LAT "
    "(default with --frame: the middle of the corners; with --mask: the centroid).",
)
@click.option(
    "--frame",
    type=POINT,
    nargs=4,
    metavar="P1 P2 P3 P4",
    help="The four corners of the picture frame, LON,LAT each, in order round it.",
)
@click.option(
    "--mask",
    type=click.Path(dir_okay=False, path_type=Path),
    help="An equirectangular mask image, white = the hole inside the frame.",
)
@click.option("--inner-radius", type=DEGREES, help="A round hole of this radius (degrees).")
@click.option(
    "--far",
    type=POINT,
    help="The second fixed point, LON,LAT (default: the antipode of the centre).",
)
@click.option(
    "--scale",
    type=SCALE,
    default="auto",
    show_default=True,
    help="λ > 1: each copy is the previous one scaled by λ. 'auto' makes the portal "
    "round the far point as large as the hole (and fits the frame plus a margin).",
)
@click.option(
    "--border",
    type=DEGREES,
    default=0.0,
    help="With --scale auto: width of the frame's moulding round the hole, degrees.",
)
@click.option(
    "--margin", type=DEGREES, help="With --scale auto: wall kept round the frame, degrees."
)
@click.option("--twist", is_flag=True, help="Twisted Droste (De Smit-Lenstra, Escher).")
@click.option(
    "--strands",
    type=int,
    default=1,
    show_default=True,
    help="With --twist: the number of spiral arms (negative: twist the other way).",
)
@click.option(
    "--periodicity",
    type=click.IntRange(0, 1000),
    default=1,
    show_default=True,
    help="With --twist: how often the picture goes round per turn.",
)
@click.option(
    "--phase",
    type=RealType("a zoom phase", "0.25", metavar="T"),
    default=0.0,
    show_default=True,
    help="Zoom phase t: 0 and 1 give the same image; growing t flies into the frame.",
)
@click.option(
    "--frames",
    type=click.IntRange(1, 100000),
    help="Render N frames of a seamless zoom loop: OUT_0000.png ... (or a pattern "
    "with one field %0Nd or {:0Nd}, N = 1..9, such as frames/%04d.png; missing "
    "directories are created).",
)
@click.option(
    "--view",
    type=click.Choice(["equirect", "log", "log-output"], case_sensitive=False),
    default="equirect",
    show_default=True,
    help="'log': the input in log coordinates (the annulus strip, its copies dimmed, the "
    "period rectangle drawn); 'log-output': the log of the result. A flat picture: "
    "--size sets its height, --periods its width.",
)
@click.option(
    "--periods",
    type=click.FloatRange(0.1, 100),
    default=3.0,
    show_default=True,
    help="With --view log: how many periods log(λ) fit across.",
)
@click.option(
    "--inside",
    type=click.Path(dir_okay=False, path_type=Path),
    multiple=True,
    metavar="IMG",
    help="Another image for the copies inside the frame (repeatable: copy d shows "
    "image d mod K of INPUT, IMG1, ...).",
)
@print_options
@recipe_options
@render_options
def droste(
    input: Path,
    render: RenderOptions,
    center: tuple[float, float] | None,
    frame: tuple[tuple[float, float], ...] | None,
    mask: Path | None,
    inner_radius: float | None,
    far: tuple[float, float] | None,
    scale: float | str,
    border: float,
    margin: float | None,
    twist: bool,
    strands: int,
    periodicity: int,
    phase: float,
    frames: int | None,
    view: str,
    periods: float,
    inside: tuple[Path, ...],
    print_recipe: bool = False,
    print_map: bool = False,
    save_recipe: Path | None = None,
    dry_run: bool = False,
) -> None:
    """Droste effect: the room inside its own picture frame, forever.

    Name the frame with --frame (its four corners), --mask (white = hole) or
    --inner-radius (with --center). Looking into the frame you see the room
    again, scaled by 1/λ, and again; looking away you see a flower-shaped
    portal round the far point. --twist turns the copies into Escher's spiral.
    """
    from ._common import convert_for_output, load_input, output_name, output_path, save_output
    from ._files import job

    frame = frame or None
    given = [name for name, v in (("--frame", frame), ("--mask", mask)) if v is not None]
    if inner_radius is not None:
        given.append("--inner-radius")
    if len(given) != 1:
        raise click.UsageError(
            "name the frame with exactly one of --frame, --mask or --inner-radius"
            + (f" (got {', '.join(given)})" if given else "")
        )
    if inner_radius is not None and center is None:
        raise click.UsageError("--inner-radius needs --center")
    if not twist and (strands != 1 or periodicity != 1):
        raise click.UsageError("--strands and --periodicity go with --twist")
    view = view.lower()
    if view != "equirect" and frames is not None:
        raise click.UsageError("--frames renders the equirectangular loop; drop --view")
    printing = print_map or print_recipe
    if mask is not None:
        job().reads(mask, "--mask image")
    if not (printing or dry_run):  # every file read and written, checked before any work
        for path in inside:
            job().reads(path, "--inside image")
        if view != "equirect":
            _check_suffix(output_path(render, input, "droste-log"))
        elif frames is None:
            _check_suffix(output_path(render, input, "droste"))
        else:
            pattern = output_name(render, input, "droste")
            paths = frame_paths(pattern, frames)
            for p in paths:  # refuse inputs, existing files and bad names before any work
                one = replace(render, output=p, output_dir=False)
                _check_suffix(output_path(one, input, "droste", given=str(pattern)))

    step: dict[str, Any] = {
        "center": None if center is None else list(center),
        "frame": None if frame is None else [list(p) for p in frame],
        "inner_radius": inner_radius,
        "far": None if far is None else list(far),
        "scale": scale,
        "border": border,
        "margin": margin,
        "twist": twist,
        "phase": phase,
        "mask": mask,
    }
    if inside:
        step["images"] = 1 + len(inside)
    if view != "equirect":
        step.update(view=view, periods=periods)
    top: dict[str, Any] = {}
    if twist:
        step.update(strands=strands, periodicity=periodicity)
    if frames is not None:  # a loop: 'spherewarp animate R.json IN --fps FRAMES' replays it
        step["phase"] = {"keyframes": [[0, phase], [1, phase + 1]]}
        top = {"duration": 1, "loop": True}
    inputs = [input, *inside] if inside else input
    if print_map:
        from .recipe_cmds import command_recipe, recipe_of

        click.echo(command_recipe(recipe_of({"droste": step}, render)).map_at(0.0).to_json())
        return
    if print_recipe:
        show_recipe({"droste": step}, render, inputs, top)
        return
    with saving_recipe({"droste": step}, render, inputs, save_recipe, dry_run, top) as dry:
        if dry:
            return
        src = load_input(input, render)
        images = [src]
        for path in inside:
            extra = load_input(path, render, "--inside image")
            if (
                extra.pixels.dtype != src.pixels.dtype
                or extra.pixels.shape[2] != src.pixels.shape[2]
            ):
                from ..errors import InvalidValueError

                raise InvalidValueError(
                    f"--inside {path}: expected the input's sample type and channels "
                    f"({src.pixels.dtype}, {src.pixels.shape[2]}), got {extra.pixels.dtype}, "
                    f"{extra.pixels.shape[2]}"
                )
            images.append(extra)

        if view != "equirect":
            from ..io import write_image

            out = output_path(render, input, "droste-log")
            pixels = render_recipe({"droste": step}, render, images, "droste")[0]
            pixels = convert_for_output(pixels, out, render)
            written = write_image(
                out,
                pixels,
                icc_profile=src.icc_profile,
                exif=src.exif,
                gpano=False,
                quality=render.quality,
                overwrite=render.overwrite,
            )
            click.echo(f"wrote {written} ({pixels.shape[1]}x{pixels.shape[0]} log plane)")
            return

        if frames is None:
            pixels, _, fr = render_recipe({"droste": step}, render, images, "droste")
            if not render.quiet:  # a note: --quiet hides it
                auto = " (auto)" if scale == "auto" else ""
                click.echo(f"droste: scale {fr.map.scale:.4g}{auto}")
            save_output(pixels, src, render, command="droste")
            return

        per_frame = [replace(render, output=p, output_dir=False) for p in paths]
        for p in {p.parent for p in paths}:
            p.mkdir(parents=True, exist_ok=True)
        for k, r in enumerate(per_frame):  # frame k at t = k / N s of the loop recipe
            pixels, _, fr = render_recipe({"droste": step}, r, images, "droste", top, k / frames)
            if k == 0 and not render.quiet:
                click.echo(f"droste: scale {fr.map.scale:.4g}, {frames} frames")
            save_output(pixels, src, r, command="droste")  # atomic, as every image written
