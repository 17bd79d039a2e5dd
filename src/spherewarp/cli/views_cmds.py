"""``spherewarp project``: reprojection between the panorama and the other grids."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Any

import click
import numpy as np

from ..errors import InvalidValueError
from ._common import (
    PROJECTIONS,
    PointType,
    RealType,
    RenderOptions,
    example,
    input_argument,
    output_path,
    render_options,
    save_output,
)
from .recipe_cmds import print_options, recipe_options, saving_recipe


@click.command(
    epilog=example(
        "spherewarp project room.jpg --to little-planet -o planet.jpg",
        "spherewarp project room.jpg --to rectilinear --look-at 90,10 --fov 70 -o view.jpg",
        "spherewarp project room.jpg --to cubemap -o cube.png",
        "spherewarp project cube.png --from cubemap -o room-again.png",
    )
)
@input_argument
@click.option(
    "--to",
    "to",
    type=click.Choice(PROJECTIONS, case_sensitive=False),
    help="Reproject the panorama INPUT into this grid (as --projection).",
)
@click.option(
    "--from",
    "from_",
    type=click.Choice(PROJECTIONS, case_sensitive=False),
    help="INPUT is a picture in this grid (a cube map, a little planet, a fisheye): take "
    "it back to an equirectangular panorama, transparent where the picture does not reach "
    "(--look-at, --roll, --fov: those it was made with; --size: the panorama's, default "
    "twice as wide as INPUT is high, or as a cube map's face).",
)
@click.option(
    "--look-at",
    "look_at",
    type=PointType(),
    help="Point LON,LAT the grid looks at (default: the grid's own: 0,-90 for a little "
    "planet, 0,90 for peirce and torus, else 0,0).",
)
@click.option(
    "--roll",
    type=RealType("an angle in degrees", "10", metavar="DEG"),
    default=0.0,
    help="Roll of the grid, DEG (as ffmpeg v360's roll).",
)
@print_options
@recipe_options
@render_options
def project(
    input: Path,
    render: RenderOptions,
    to: str | None,
    from_: str | None,
    look_at: tuple[float, float] | None,
    roll: float,
    print_recipe: bool = False,
    print_map: bool = False,
    save_recipe: Path | None = None,
    dry_run: bool = False,
) -> None:
    """Reproject the panorama INPUT into another grid (--to), or back (--from).

    The same grids as every effect's --projection: little-planet (stereographic),
    rectilinear, fisheye, equisolid, cubemap (3x2, as ffmpeg v360's c3x2), cubemap-6x1,
    peirce (quincuncial), torus (the torus cell; --to only). Default sizes: a square of
    the input's height for little-planet and the fisheyes, faces of its height for the
    cube maps (--size 3072x2048 for v360's default from a 4096x2048 panorama). A plain
    reprojection samples bicubically by default, both ways, so that a round trip keeps
    the detail (a cube map and back: 37.6 dB on a forest photograph, 34.0 bilinear).
    """
    if (to is None) == (from_ is None):
        raise click.UsageError("give one of --to NAME or --from NAME")
    if render.projection is not None:
        raise click.UsageError("project takes --to or --from, not --projection")
    if look_at is not None and render.view_at is not None:
        raise click.UsageError("give --look-at or --view-at, not both")
    if roll and render.view_roll:  # (they were added together)
        raise click.UsageError("give --roll or --view-roll, not both")
    render = replace(
        render,
        view_at=look_at if look_at is not None else render.view_at,
        view_roll=roll + render.view_roll,
    )
    if from_ is not None and (save_recipe or dry_run or print_recipe or print_map):
        raise click.UsageError(
            "--from takes a picture back to the sphere: it has no recipe or map (a recipe "
            "renders panoramas; --to has one)"
        )
    if to is None:
        _project_from(input, render, from_.lower())
        return
    render = replace(render, projection=to.lower())
    if print_map:
        from ..maps import Mobius

        click.echo(Mobius.identity().to_json())  # a reprojection moves nothing
        return
    if print_recipe:  # no steps: the view alone
        from .recipe_cmds import print_recipe as show

        show({}, render, input)
        return
    with saving_recipe({}, render, input, save_recipe, dry_run) as dry:
        if not dry:
            _project_to(input, render)


def _project_to(input: Path, render: RenderOptions) -> None:
    from ._common import load_input
    from .recipe_cmds import render_recipe

    src = load_input(input, render)
    output_path(render, input, render.projection or "project")  # refuse a bad -o first
    out = render_recipe({}, render, src, "project")[0]
    save_output(out, src, render, command=render.projection or "project")


def _project_from(input: Path, render: RenderOptions, name: str) -> None:
    from ..grids import from_grid, make_grid
    from ..io import read_image
    from ._files import job

    job().reads(input, "input")
    output_path(render, input, "equirect")  # refuse a bad -o before reading
    src = read_image(input, max_pixels=render.max_pixels)
    h, w = src.pixels.shape[:2]
    view = {"look_at": render.view_at, "roll": render.view_roll, "fov": render.fov}
    make_grid(name, (1024, 2048), **view)  # the options' own checks, naming the options
    try:
        grid = make_grid(name, shape=(h, w), **view)
    except InvalidValueError as exc:  # then the input is not such a picture: name it
        raise InvalidValueError(f"'{input}': {exc}") from None
    face = getattr(grid, "face", None)  # a cube map: a panorama as tall as a face
    size = (2 * h, h) if face is None else (2 * face, face)
    size = size if render.size is None else render.size
    if size[0] != 2 * size[1]:
        raise InvalidValueError(f"expected a 2:1 --size for the panorama, got {size[0]}x{size[1]}")
    n = None if render.supersample == 1 else render.supersample
    if not isinstance(render.antialias, str):
        n = int(render.antialias)
    if render.interp == "nearest":
        raise click.BadParameter(
            "--from takes bilinear or bicubic (a grid's picture is resampled smoothly)",
            param_hint="'--interp'",
        )
    out: Any = from_grid(
        src.pixels, grid, (size[1], size[0]), supersample=n, alpha=True, interp=render.interp
    )
    channels = src.pixels.shape[2] if src.pixels.ndim == 3 else 1
    if out.shape[2] > channels and np.all(out[..., -1] == out[..., -1].max()):
        out = out[..., :channels]  # the picture covers the whole sphere: no alpha needed
    save_output(
        out,
        src,
        replace(render, projection=None, view_at=None, view_roll=0.0, fov=None),
        command="equirect",
    )


# a plain reprojection keeps detail: bicubic unless --interp says otherwise (shown in --help)
for _param in project.params:
    if _param.name == "interp":
        _param.default = "bicubic"
