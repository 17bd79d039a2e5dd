"""``spherewarp schottky``: a Schottky group image (several Droste effects at once).

Each ``--generator`` names a disk ``D_x`` and where its outside goes: either
the matrix of the Möbius map ``X`` (``LON,LAT,R:a,b,c,d``) or a second disk
``D_X`` (``LON,LAT,R -> LON,LAT,R``, the hyperbolic map of
:func:`spherewarp.maps.schottky.generator_between`). ``--frames N`` renders a
seamless zoom loop through the first generator's disks.
"""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path
from typing import Any

import click

from ._common import ColorType, RealType, RenderOptions, example, input_argument, render_options
from .recipe_cmds import print_options, recipe_options, render_recipe, saving_recipe

__all__ = ["schottky"]


def _disk(text: str) -> tuple[float, float, float]:
    parts = text.strip().split(",")
    if len(parts) != 3:
        raise ValueError(f"expected a disk LON,LAT,R (degrees), got {text.strip()!r}")
    try:
        vals = tuple(float(p) for p in parts)
    except ValueError:
        raise ValueError(f"expected a disk LON,LAT,R of numbers, got {text.strip()!r}") from None
    if not all(math.isfinite(v) for v in vals):
        raise ValueError(f"expected a finite disk LON,LAT,R, got {text.strip()!r}")
    return vals  # type: ignore[return-value]


class GeneratorType(click.ParamType):
    """``LON,LAT,R:a,b,c,d`` (disk and matrix) or ``LON,LAT,R -> LON,LAT,R`` (two disks)."""

    name = "GEN"

    def convert(self, value: Any, param: Any, ctx: Any) -> tuple[str, Any, Any]:
        if isinstance(value, tuple):
            return value
        text = str(value)
        try:
            if "->" in text:
                a, _, b = text.partition("->")
                return ("disks", _disk(a), _disk(b))
            if ":" in text:
                from .mobius_cmds import MatrixType

                a, _, b = text.partition(":")
                return ("matrix", _disk(a), MatrixType().convert(b, param, ctx))
        except ValueError as exc:
            self.fail(str(exc), param, ctx)
        self.fail(
            f"expected LON,LAT,R:a,b,c,d (a disk and the matrix of its generator) or "
            f"'LON,LAT,R -> LON,LAT,R' (two disks), got {text!r}",
            param,
            ctx,
        )


def _output_width(kwargs: dict[str, Any], in_shape: tuple[int, ...]) -> int:
    """The width a Schottky map is sized for (:func:`spherewarp.recipe.recipe.output_width`)."""
    from ..recipe.recipe import output_width

    return output_width(kwargs, in_shape)


GENERATOR = GeneratorType()
DEGREES = RealType("degrees", "30", metavar="DEG")


@click.command(
    epilog=example(
        "spherewarp schottky interior.png -o schottky.png "
        "--generator '-163,5,12 -> 17,-5,25' --generator '-75,10,15 -> 105,0,20'",
        "spherewarp schottky room.jpg -o s.png --generator '0,90,20:30,0,0,1'",
        "spherewarp schottky room.jpg -o loop.png --generator '-163,5,12 -> 17,-5,25' --frames 48",
    )
)
@input_argument
@click.option(
    "--generator",
    "generators",
    type=GENERATOR,
    multiple=True,
    help="A generator (repeatable): 'LON,LAT,R:a,b,c,d' is the disk D_x (centre and "
    "angular radius, degrees) and the matrix of X (complex entries as in mobius "
    "--matrix), which takes the outside of D_x onto D_X; 'LON,LAT,R -> LON,LAT,R' gives "
    "D_x and D_X, and X is the hyperbolic map fixing the two points symmetric in both "
    "circles (see --twist).",
)
@click.option(
    "--twist",
    "twists",
    type=DEGREES,
    multiple=True,
    help="With 'D_x -> D_X' generators: also turn by DEG about the fixed points "
    "(a loxodromic map); once for all, or once per generator in order.",
)
@click.option(
    "--depth",
    type=click.IntRange(1, 10000),
    help="The most reduction steps; pixels not reduced by then get the background "
    "(default: enough for the copies left to be below a pixel of the output).",
)
@click.option(
    "--phase",
    type=RealType("a zoom phase", "0.25", metavar="T"),
    default=0.0,
    show_default=True,
    help="Zoom phase t through the first generator's disks: 0 and 1 give the same image.",
)
@click.option(
    "--frames",
    type=click.IntRange(1, 100000),
    help="Render N frames of a seamless zoom loop: OUT_0000.png ... (or a pattern "
    "with one field %0Nd or {:0Nd}, N = 1..9, such as frames/%04d.png).",
)
@click.option(
    "--mask",
    type=click.Path(dir_okay=False, path_type=Path),
    help="An equirectangular mask image, one colour per disk D_x (the paper's workflow: "
    "the window red, the mirror green; black is the fundamental region). Name where each "
    "goes with --target; see --regions.",
)
@click.option(
    "--regions",
    type=click.Choice(["exact", "round"], case_sensitive=False),
    default="exact",
    show_default=True,
    help="With --mask: 'exact' takes each disk D_x as the pixels of its colour and D_X = "
    "X(outside of D_x) (the paper's rule), with X built from the largest round disk "
    "inside the region, so that D_X lies in its --target disk; 'round' takes the smallest "
    "round disk about each colour as D_x.",
)
@click.option(
    "--target",
    "targets",
    type=(ColorType(), str),
    multiple=True,
    metavar="COLOUR WHERE",
    help="With --mask (repeatable): the disk of COLOUR (a name such as red, or #RRGGBB) "
    "and where its outside goes: a disk LON,LAT,R (as after '->' in --generator), or a "
    "zoom factor F > 1 (X zooms by F about the disk's centre, fixing its antipode: a "
    "Droste portal there).",
)
@print_options
@recipe_options
@render_options
def schottky(
    input: Path,
    render: RenderOptions,
    generators: tuple[tuple[str, Any, Any], ...],
    twists: tuple[float, ...],
    mask: Path | None,
    targets: tuple[tuple[str, str], ...],
    regions: str,
    depth: int | None,
    phase: float,
    frames: int | None,
    print_recipe: bool = False,
    print_map: bool = False,
    save_recipe: Path | None = None,
    dry_run: bool = False,
) -> None:
    """Schottky group: each disk shows the whole picture again, in each other disk, forever.

    Each --generator pairs a disk D_x with a disk D_X: looking into D_X you see
    the picture outside D_x, shrunk; looking into D_x you see it from outside
    D_X. With one generator this is the straight Droste effect.
    """
    from ._common import load_input, output_name, output_path, save_output
    from .droste_cmds import _check_suffix, frame_paths

    printing = print_map or print_recipe
    check_generators(generators, twists, mask, targets, regions)
    if mask is not None:
        from ._files import job

        job().reads(mask, "--mask image")
    if not (printing or dry_run):  # every file written, checked before any work
        if frames is None:
            _check_suffix(output_path(render, input, "schottky"))
        else:
            pattern = output_name(render, input, "schottky")
            paths = frame_paths(pattern, frames)
            for p in paths:
                one = replace(render, output=p, output_dir=False)
                _check_suffix(output_path(one, input, "schottky", given=str(pattern)))

    s, n_gens, step = _schottky_parts(
        generators, twists, mask, targets, regions, depth, phase, render.max_pixels
    )
    if print_map:
        click.echo(s.to_json())
        return
    if not step["generators"]:
        del step["generators"]
    top: dict[str, Any] = {}
    if frames is not None:  # a loop: 'spherewarp animate R.json IN --fps FRAMES' replays it
        step["phase"] = {"keyframes": [[0, phase], [1, phase + 1]]}
        top = {"duration": 1, "loop": True}
    if print_recipe:
        from .recipe_cmds import print_recipe as show

        show({"schottky": step}, render, input, top)
        return
    with saving_recipe({"schottky": step}, render, input, save_recipe, dry_run, top) as dry:
        if dry:
            return
        src_img = load_input(input, render)
        kwargs = render.warp_kwargs(src_img.pixels)
        depth_shown = s.for_output(_output_width(kwargs, src_img.pixels.shape)).depth
        if frames is None:
            if not render.quiet:  # a note: --quiet hides it
                click.echo(f"schottky: {n_gens} generator(s), depth {depth_shown}")
            out = render_recipe({"schottky": step}, render, src_img, "schottky")[0]
            save_output(out, src_img, render, command="schottky")
            return
        for p in {p.parent for p in paths}:
            p.mkdir(parents=True, exist_ok=True)
        if not render.quiet:
            click.echo(f"schottky: {n_gens} generator(s), depth {depth_shown}, {frames} frames")
        for k, p in enumerate(paths):  # frame k at t = k / N s of the loop recipe
            r = replace(render, output=p, output_dir=False)
            out = render_recipe({"schottky": step}, r, src_img, "schottky", top, k / frames)[0]
            save_output(out, src_img, r, command="schottky")


def check_generators(
    generators: tuple[tuple[str, Any, Any], ...],
    twists: tuple[float, ...],
    mask: Path | None,
    targets: tuple[tuple[str, str], ...],
    regions: str,
) -> None:
    """Refuse options of ``schottky`` (and ``video ... schottky``) that do not go together."""
    if mask is not None and not targets:
        raise click.UsageError("--mask needs --target COLOUR WHERE for each disk it holds")
    if targets and mask is None:
        raise click.UsageError("--target goes with --mask")
    if not generators and mask is None:
        raise click.UsageError("name at least one --generator (or --mask with --target)")
    if mask is not None and generators and regions.lower() == "exact":
        raise click.UsageError(
            "--regions exact (the default with --mask) takes every disk from the mask: "
            "leave out --generator, or give --regions round"
        )
    n_pairs = sum(1 for g in generators if g[0] == "disks")
    if twists and len(twists) not in (1, n_pairs):
        raise click.UsageError(
            f"give --twist once, or once per 'D_x -> D_X' generator ({n_pairs}), got {len(twists)}"
        )
    if twists and not n_pairs:
        raise click.UsageError("--twist goes with 'LON,LAT,R -> LON,LAT,R' generators")


def schottky_map(
    generators: tuple[tuple[str, Any, Any], ...],
    twists: tuple[float, ...],
    mask: Path | None,
    targets: tuple[tuple[str, str], ...],
    regions: str,
    depth: int | None,
    phase: float,
    max_pixels: int | None = None,
) -> tuple[Any, int]:
    """The Schottky map of ``schottky``'s options (checked by :func:`check_generators`) and
    its number of generators; not yet fitted to an output width (``for_output``)."""
    s, n_gens, _ = _schottky_parts(
        generators, twists, mask, targets, regions, depth, phase, max_pixels
    )
    return s, n_gens


def _schottky_parts(
    generators: tuple[tuple[str, Any, Any], ...],
    twists: tuple[float, ...],
    mask: Path | None,
    targets: tuple[tuple[str, str], ...],
    regions: str,
    depth: int | None,
    phase: float,
    max_pixels: int | None,
) -> tuple[Any, int, dict[str, Any]]:
    """The map, its number of generators and its recipe step (the options, by name)."""
    from ..errors import InvalidValueError
    from ..maps.mobius import Mobius
    from ..maps.schottky import Cap, Schottky, generator_between

    n_pairs = sum(1 for g in generators if g[0] == "disks")
    tw = list(twists) * n_pairs if len(twists) == 1 else list(twists) or [0.0] * n_pairs
    gens = []
    k = 0
    step: dict[str, Any] = {"generators": [], "depth": depth, "phase": phase}
    for i, (form, disk, other) in enumerate(generators):
        if form == "disks":
            g = {"disk": list(disk), "to": list(other)}
            if twists:
                g["twist"] = tw[k]
        else:
            g = {"disk": list(disk), "matrix": [[c.real, c.imag] for c in other]}
        step["generators"].append(g)
        try:
            src = Cap(*disk)
            if form == "disks":
                m = generator_between(src, Cap(*other), tw[k])
                k += 1
            else:
                a, b, c, d = other
                m = Mobius([[a, b], [c, d]])
        except InvalidValueError as exc:
            raise InvalidValueError(f"--generator {i + 1}: {exc}") from None
        gens.append((src, m))
    if mask is not None:
        from ..io import read_image
        from ..io.tonemap import parse_color
        from ..maps.schottky import cap_from_mask

        pixels = read_image(mask, max_pixels=max_pixels).pixels
        colours = []
        step.update(mask=mask, targets=[], regions=regions.lower())
        for colour, where in targets:
            try:
                colours.append(parse_color(colour))
                # exact regions: the disk inside the region, so that X takes the region's
                # outside into the target disk; round: the disk round the region
                cap = cap_from_mask(pixels, colours[-1], inside=regions.lower() == "exact")
                if "," in where:
                    m = generator_between(cap, Cap(*_disk(where)))
                    step["targets"].append({"colour": colour, "to": list(_disk(where))})
                else:
                    f = float(where)
                    if not (math.isfinite(f) and f > 1):
                        raise ValueError(f"expected a zoom factor > 1 or LON,LAT,R, got {where!r}")
                    m = Mobius.zoom((cap.lon, cap.lat), f)
                    step["targets"].append({"colour": colour, "zoom": f})
            except (InvalidValueError, ValueError) as exc:
                msg = str(exc)
                if msg.startswith("could not convert"):
                    msg = f"expected a zoom factor > 1 or a disk LON,LAT,R, got {where!r}"
                raise InvalidValueError(f"--target {colour}: {msg}") from None
            gens.append((cap, m))
    try:
        s = Schottky(gens, depth=depth, phase=phase)
    except InvalidValueError as exc:
        opts = "/".join(o for o, v in (("--generator", generators), ("--target", targets)) if v)
        raise InvalidValueError(f"{opts}: {exc}") from None
    if mask is not None and regions.lower() == "exact":
        from ..maps.schottky import MaskRegions

        try:
            s = s.with_mask_regions(MaskRegions(pixels, colours, path=str(mask)))
        except InvalidValueError as exc:
            hint = " (a larger zoom, or --regions round)" if "disjoint" in str(exc) else ""
            raise InvalidValueError(f"--mask/--target: {exc}{hint}") from None
    return s, len(gens), step
