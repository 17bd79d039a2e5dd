"""``spherewarp power``, ``exp``, ``map`` and ``splitscreen``: branched maps.

Each command builds the map that the renderer pulls the image back by
(:mod:`spherewarp.maps.branched`, :mod:`spherewarp.maps.expression`,
:mod:`spherewarp.effects.splitscreen`): the forward maps are multi-valued (roots,
logarithms), so these commands say "pull back by S" where the Möbius commands
say "move the content by T". ``--look-at LON,LAT`` then turns the view of the
result, e.g. ``--look-at 0,90`` shows the branch point on the ceiling at the
centre, as in the paper's figure.
"""

from __future__ import annotations

import math
from fractions import Fraction
from pathlib import Path
from typing import Any

import click

from ._common import POINT, RealType, RenderOptions, example, input_argument, render_options
from .recipe_cmds import print_options, printed, recipe_options, render_recipe, saving_recipe
from .recipe_cmds import print_recipe as show_recipe

__all__ = ["power", "exp", "map_cmd", "splitscreen"]

#: supersampling used when --supersample is not given, for maps whose copies shrink to points
EXP_SUPERSAMPLE = 3


class ExponentType(click.ParamType):
    """A non-zero real exponent: ``2``, ``-1``, ``0.5`` or a fraction ``1/3``."""

    name = "N"

    def convert(self, value: Any, param: Any, ctx: Any) -> float:
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            v = float(value)
        else:
            text = str(value).strip()
            try:
                v = float(Fraction(text))
            except (ValueError, ZeroDivisionError):
                self.fail(
                    f"expected an exponent such as 2, 3, -1, 0.5 or 1/3, got {value!r}", param, ctx
                )
        if not math.isfinite(v) or v == 0:
            self.fail(f"expected a finite non-zero exponent, got {value!r}", param, ctx)
        return v


class SeamType(click.ParamType):
    """``auto`` or a longitude in degrees."""

    name = "auto|LON"

    def convert(self, value: Any, param: Any, ctx: Any) -> str | float:
        if isinstance(value, float) or value == "auto":
            return value
        text = str(value).strip().lower()
        if text == "auto":
            return "auto"
        parts = [p for p in text.replace(" ", ",").split(",") if p]
        if len(parts) > 1:
            self.fail(
                f"expected one seam longitude (the seams are the lifts of one input meridian, "
                f"so they are equally spaced), got {value!r}",
                param,
                ctx,
            )
        try:
            v = float(text)
        except ValueError:
            self.fail(f"expected 'auto' or a longitude in degrees, got {value!r}", param, ctx)
        if not math.isfinite(v):
            self.fail(f"expected a finite longitude, got {value!r}", param, ctx)
        return v


EXPONENT = ExponentType()
POSITIVE = RealType("a number", "4", gt=0)
FEATHER = RealType("a feather width in degrees", "10", metavar="DEG", ge=0, le=180)
SEAM = SeamType()

_BRANCH_POINTS_HELP = (
    "Put the branch points at P (0 of the chart) and Q (infinity), LON,LAT each "
    "(default: the zenith and the nadir)."
)
_LOOK_AT_HELP = (
    "Then turn the view (yaw, pitch) to look at this point LON,LAT of the result; "
    "0,90 puts the branch point on the ceiling at the centre."
)


def _look_at(point: tuple[float, float] | None) -> Any:
    if point is None:
        return None
    from ..maps.mobius import Mobius

    return Mobius.from_yaw_pitch_roll(yaw=point[0], pitch=point[1])


def _supersample(render: RenderOptions, default: int) -> RenderOptions:
    """``render`` with ``default`` supersampling unless --supersample or --antialias was
    given (either one chooses the filter: the default must not override it)."""
    from dataclasses import replace

    ctx = click.get_current_context()
    given = (ctx.get_parameter_source(k) for k in ("supersample", "antialias"))
    if all(s in (None, click.core.ParameterSource.DEFAULT) for s in given):
        return replace(render, supersample=default)
    return render


def _render(input: Path, render: RenderOptions, pull_map: Any, command: str) -> None:
    """Read INPUT, pull it back by ``pull_map`` (then the view), write the result."""
    from ..render import warp
    from ._common import load_input, output_path, save_output

    output_path(render, input, command)  # refuse a bad output before the work
    src = load_input(input, render)
    out = warp(src.pixels, pull_map, **render.warp_kwargs(src.pixels))
    save_output(out, src, render, command=command)


def _points(value: Any) -> Any:
    """A point (or a tuple of points) as recipe JSON lists; None stays None."""
    if not value:
        return None
    if isinstance(value[0], tuple):
        return [list(p) for p in value]
    return list(value)


@click.command(
    epilog=example(
        "spherewarp power room.jpg --n 2 -o two-rooms.jpg",
        "spherewarp power room.jpg --n 2 --look-at 0,90 -o branch-point.jpg",
        "spherewarp power room.jpg --n 3 --branch-points 0,0 180,0 -o front-back.jpg",
        "spherewarp power room.jpg --n 1/2 --cut 0 -o half-room.jpg",
    )
)
@input_argument
@click.option(
    "--n",
    "exponent",
    type=EXPONENT,
    default="2",
    show_default=True,
    help="The exponent: 2, 3, ... show that many copies around the branch points; "
    "1/k (or 0.5) spreads one k-th of the image over the sphere; -1 inverts.",
)
@click.option(
    "--branch-points", type=POINT, nargs=2, metavar="P Q", default=None, help=_BRANCH_POINTS_HELP
)
@click.option(
    "--branch",
    type=int,
    default=0,
    show_default=True,
    help="For a non-integer exponent: which branch of the root.",
)
@click.option(
    "--cut",
    type=RealType("a longitude in degrees", "180", metavar="LON"),
    default=180.0,
    show_default=True,
    help="For a non-integer exponent: longitude of the meridian along which the root is cut "
    "(in the frame of the branch points); 0 is NumPy's principal branch.",
)
@click.option("--look-at", type=POINT, default=None, help=_LOOK_AT_HELP)
@print_options
@recipe_options
@render_options
def power(
    input: Path,
    render: RenderOptions,
    exponent: float,
    branch_points: tuple[tuple[float, float], tuple[float, float]] | None,
    branch: int,
    cut: float,
    look_at: tuple[float, float] | None,
    print_recipe: bool = False,
    print_map: bool = False,
    save_recipe: Path | None = None,
    dry_run: bool = False,
) -> None:
    """Pull back by z**n: n copies of the image around two branch points.

    With the default chart the branch points are the zenith and the nadir (on
    the ceiling and the floor), and the copies sit side by side.
    """
    from ..recipe.effects import EFFECTS

    step = {
        "n": exponent,
        "branch_points": _points(branch_points),
        "branch": branch,
        "cut": cut,
        "look_at": _points(look_at),
    }
    pull = EFFECTS["power"].build({**step, "branch_points": branch_points or None})
    if printed({"power": step}, pull, render, input, print_recipe, print_map):
        return
    with saving_recipe({"power": step}, render, input, save_recipe, dry_run) as dry:
        if not dry:
            _render(input, render, pull, "power")


@click.command(
    epilog=example(
        "spherewarp exp room.jpg --lam 4 -o corridor.jpg",
        "spherewarp exp room.jpg --lam 2 --look-at 180,0 --supersample 4 -o vanishing.jpg",
    )
)
@input_argument
@click.option(
    "--lam",
    type=POSITIVE,
    default=4.0,
    show_default=True,
    help="Scale lambda of S(z) = -exp(-lambda (1+z)/(1-z)): larger gives more, smaller copies.",
)
@click.option(
    "--branch-points", type=POINT, nargs=2, metavar="P Q", default=None, help=_BRANCH_POINTS_HELP
)
@click.option("--look-at", type=POINT, default=None, help=_LOOK_AT_HELP)
@print_options
@recipe_options
@render_options
def exp(
    input: Path,
    render: RenderOptions,
    lam: float,
    branch_points: tuple[tuple[float, float], tuple[float, float]] | None,
    look_at: tuple[float, float] | None,
    print_recipe: bool = False,
    print_map: bool = False,
    save_recipe: Path | None = None,
    dry_run: bool = False,
) -> None:
    """Pull back by the exp variant: the image repeats infinitely often horizontally.

    The copies shrink toward the back point, where infinitely many of them
    meet; --supersample defaults to 3 here to keep that clean (unless --antialias
    is given).
    """
    from ..recipe.effects import EFFECTS

    render = _supersample(render, EXP_SUPERSAMPLE)
    step = {"lam": lam, "branch_points": _points(branch_points), "look_at": _points(look_at)}
    pull = EFFECTS["exp"].build({**step, "branch_points": branch_points or None})
    if printed({"exp": step}, pull, render, input, print_recipe, print_map):
        return
    with saving_recipe({"exp": step}, render, input, save_recipe, dry_run) as dry:
        if not dry:
            _render(input, render, pull, "exp")


@click.command(
    "map",
    epilog=example(
        "spherewarp map room.jpg --expr 'z**2' -o two-rooms.jpg",
        "spherewarp map room.jpg --expr '(z-1)/(z+1)' --chart front -o turned.jpg",
        "spherewarp map room.jpg --expr 'z**3 + 0.5*z' -o three.jpg",
    ),
)
@input_argument
@click.option(
    "--expr",
    required=True,
    help="Complex expression in z to pull back by: numbers, z, i (or j), pi, e, "
    "+ - * / **, exp log sqrt sin cos tan sinh cosh tanh abs conj.",
)
@click.option(
    "--chart",
    type=click.Choice(["zenith", "front"], case_sensitive=False),
    default="zenith",
    show_default=True,
    help="Where z = 0 and infinity are: zenith (0 up, inf down, -1 at the front) or "
    "front (0 at the front, inf at the back, 1 on the right, i up).",
)
@click.option("--look-at", type=POINT, default=None, help=_LOOK_AT_HELP)
@print_options
@recipe_options
@render_options
def map_cmd(
    input: Path,
    render: RenderOptions,
    expr: str,
    chart: str,
    look_at: tuple[float, float] | None,
    print_recipe: bool = False,
    print_map: bool = False,
    save_recipe: Path | None = None,
    dry_run: bool = False,
) -> None:
    """Pull back by a formula in z, parsed safely (no Python eval)."""
    from ..recipe.effects import EFFECTS

    step = {"expr": expr, "chart": chart.lower(), "look_at": _points(look_at)}
    pull = EFFECTS["map"].build({**step, "look_at": look_at})
    if printed({"map": step}, pull, render, input, print_recipe, print_map):
        return
    with saving_recipe({"map": step}, render, input, save_recipe, dry_run) as dry:
        if not dry:
            _render(input, render, pull, "map")


@click.command(
    epilog=example(
        "spherewarp splitscreen empty.jpg person.jpg -o together.jpg",
        "spherewarp splitscreen a.jpg b.jpg c.jpg --seam 40 --feather 20 -o three.jpg",
        "spherewarp splitscreen a.jpg b.jpg --cover exp --lam 3 -o corridor.jpg",
    )
)
@click.argument(
    "inputs",
    nargs=-1,
    required=True,
    type=click.Path(dir_okay=False, path_type=Path),
    metavar="INPUT1 INPUT2 [INPUT3 ...]",
)
@click.option(
    "--cover",
    type=click.Choice(["power", "exp"], case_sensitive=False),
    default="power",
    show_default=True,
    help="The branched cover: z**n (n sheets around the branch points) or the exp variant "
    "(infinitely many sheets side by side).",
)
@click.option(
    "--n",
    type=click.IntRange(1, 1000),
    default=None,
    help="Sheets of the power cover (default: the number of inputs; a multiple of it).",
)
@click.option(
    "--lam", type=POSITIVE, default=4.0, show_default=True, help="Scale of the exp cover."
)
@click.option(
    "--branch-points", type=POINT, nargs=2, metavar="P Q", default=None, help=_BRANCH_POINTS_HELP
)
@click.option(
    "--seam",
    type=SEAM,
    default="auto",
    show_default=True,
    help="Longitude of the input meridian along which the sheets are cut; auto picks the one "
    "where the inputs agree best.",
)
@click.option(
    "--feather",
    type=FEATHER,
    default=10.0,
    show_default=True,
    help="Width in degrees of input longitude of the cross-fade across each seam (0: hard cut).",
)
@click.option("--look-at", type=POINT, default=None, help=_LOOK_AT_HELP)
@print_options
@recipe_options
@render_options
def splitscreen(
    inputs: tuple[Path, ...],
    render: RenderOptions,
    cover: str,
    n: int | None,
    lam: float,
    branch_points: tuple[tuple[float, float], tuple[float, float]] | None,
    seam: str | float,
    feather: float,
    look_at: tuple[float, float] | None,
    print_recipe: bool = False,
    print_map: bool = False,
    save_recipe: Path | None = None,
    dry_run: bool = False,
) -> None:
    """Combine panoramas taken from one spot on the sheets of a branched cover.

    Each sheet shows a different input (INPUT1 on the sheet at the front, then
    the others in turn); the seams run between the branch points, along the
    input meridian where the inputs agree, and are cross-faded. Inputs may
    differ in size (resampled to the largest) and channels. With --cover exp,
    --supersample defaults to 3 (unless --antialias is given).
    """
    import spherewarp.effects.splitscreen as ss

    from ._common import load_input, output_path, save_output
    from ._files import job

    cover = cover.lower()
    if len(inputs) < 2:
        raise click.UsageError("expected at least two inputs to combine")
    if n is not None and cover != "power":
        raise click.UsageError("--n applies to --cover power only")
    if n is not None and n % len(inputs):
        raise click.BadParameter(
            f"expected a multiple of the number of inputs ({len(inputs)}), got {n}",
            param_hint="'--n'",
        )
    if cover == "exp":
        render = _supersample(render, EXP_SUPERSAMPLE)
    labels = [f"input {k + 1}" for k in range(len(inputs))]
    for path, label in zip(inputs, labels, strict=True):
        job().reads(path, label)
    step: dict[str, Any] = {
        "images": len(inputs),
        "cover": cover,
        "n": n,
        "lam": lam,
        "branch_points": _points(branch_points),
        "seam": seam,
        "feather": feather,
        "look_at": _points(look_at),
    }
    if print_map:  # each sheet shows another input: no one map to pull back by
        raise click.UsageError(
            "splitscreen blends its inputs on the sheets of a cover, not one map: use --print"
        )
    if print_recipe:
        show_recipe({"splitscreen": step}, render, list(inputs))
        return
    with saving_recipe({"splitscreen": step}, render, list(inputs), save_recipe, dry_run) as dry:
        if dry:
            return
        output_path(render, inputs[0], "splitscreen")  # refuse a bad output first
        sources = [load_input(p, render, label) for p, label in zip(inputs, labels, strict=True)]
        if seam == "auto":  # the seam the recipe's 'auto' finds, said once
            pixels = [s.pixels for s in sources]
            options = {"cover": cover, "n": n, "lam": lam, "branch_points": branch_points or None}
            found = ss.auto_seam(pixels, feather_deg=feather, **options, force=render.force)
            if not render.quiet:  # a note: --quiet hides it
                click.echo(f"seam: input meridian at longitude {found:.1f} (auto)")
            step = {**step, "seam": float(found)}
        out = render_recipe({"splitscreen": step}, render, sources, "splitscreen")[0]
        save_output(out, sources[0], render, command="splitscreen")
