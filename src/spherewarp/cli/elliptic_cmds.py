"""``spherewarp lattes``, ``fit-rational``, ``peirce`` and ``torus``: elliptic functions.

The paper's section "Weierstrass and Schwarz–Christoffel": Lattès twists
(rational maps from lattice multiplications), the SVD fit of rational maps,
Peirce's quincuncial projection and toroidal images.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import click

from ._common import RenderOptions, example, input_argument, render_options, save_output
from .recipe_cmds import (
    print_options,
    recipe_options,
    render_recipe,
    saving_recipe,
)
from .recipe_cmds import print_recipe as show_recipe

__all__ = ["lattes", "fit_rational_cmd", "peirce", "torus"]

_LATTICE = click.Choice(["square", "hex"], case_sensitive=False)


def _check_suffix(path: Path) -> None:
    from ..errors import ImageFormatError
    from ..io import SUPPORTED_EXTENSIONS

    if path.suffix.lower() not in SUPPORTED_EXTENSIONS:
        raise ImageFormatError(
            f"cannot write '{path}': unknown extension {path.suffix or '(none)'!r}; "
            f"use one of {', '.join(SUPPORTED_EXTENSIONS)}"
        )


def _json_of_fit(data: dict[str, Any]) -> str:
    return json.dumps(data)


# -- lattes ----------------------------------------------------------------------------
@click.command(
    epilog=example(
        "spherewarp lattes room.jpg --lattice square --alpha 1+1j -o twist.jpg",
        "spherewarp lattes room.jpg --lattice hex --alpha 1+w -o triple.jpg",
        "spherewarp lattes --lattice square --alpha 2+1j --print-map",
    )
)
@input_argument(required=False)
@click.option(
    "--lattice",
    type=_LATTICE,
    default="square",
    show_default=True,
    help="Square torus Z[i] or hexagonal torus Z[w], w = exp(i pi/3).",
)
@click.option(
    "--alpha",
    required=True,
    help="The lattice element: a Gaussian integer a+bj for --lattice square (1+1j, 2, 2+1j), "
    "an Eisenstein integer a+bw for hex (1+w, 2, 2-w). The map has degree |alpha|^2 <= 49 "
    "(<= 64 with --exact).",
)
@click.option(
    "--exact",
    is_flag=True,
    help="Render through the composition p(alpha p^-1(z)) instead of the fitted rational "
    "map (same image, slower).",
)
@click.option(
    "--print-map",
    "print_map",
    is_flag=True,
    help="Print the fitted rational map as JSON (coefficients [re, im], highest degree "
    "first) instead of rendering; INPUT is not needed.",
)
@click.option(
    "--print",
    "print_recipe_",
    is_flag=True,
    help="Print the recipe of this render as JSON instead of rendering; INPUT is not needed.",
)
@recipe_options
@render_options
def lattes(
    input: Path | None,
    render: RenderOptions,
    lattice: str,
    alpha: str,
    exact: bool,
    print_map: bool = False,
    print_recipe_: bool = False,
    save_recipe: Path | None = None,
    dry_run: bool = False,
) -> None:
    """Twist a 360° image by a Lattès map: z -> p(alpha p^-1(z)).

    The panorama is pulled back to the torus by the Weierstrass function p,
    multiplied by the lattice element alpha and pushed down again (the
    Schwarz-Christoffel map): a rational map of degree |alpha|^2 in the
    default chart (0 at the zenith, 1 at the back). The output shows
    |alpha|^2 copies of the input around branch points.
    """
    from ..errors import InvalidValueError
    from ..maps import Lattes

    try:
        lmap = Lattes(alpha, lattice.lower(), method="exact" if exact else "rational")
    except InvalidValueError as exc:
        raise InvalidValueError(f"--alpha: {exc.cli_message}") from None
    if print_map:
        from ..maps.elliptic import MAX_FITTED_DEGREE

        if lmap.degree > MAX_FITTED_DEGREE:
            raise InvalidValueError(
                f"--print-map shows the fitted rational map, which holds for |alpha|^2 <= "
                f"{MAX_FITTED_DEGREE}; alpha = {alpha} has degree {lmap.degree}"
            )
        data = {**lmap.rational().to_dict(), "degree": lmap.degree}
        data["residual"] = lmap.fit_residual()
        click.echo(_json_of_fit(data))
        return
    step = {"lattes": {"alpha": alpha, "lattice": lattice.lower(), "exact": exact}}
    if print_recipe_:
        show_recipe(step, render, input)
        return
    if input is None and not dry_run:
        raise click.UsageError(
            "missing INPUT (only --print, --print-map and --dry-run work without an image)"
        )
    from ..render import warp
    from ._common import load_input, output_path

    with saving_recipe(step, render, input, save_recipe, dry_run) as dry:
        if dry:
            return
        _check_suffix(output_path(render, input, "lattes"))
        src = load_input(input, render)
        out = warp(src.pixels, lmap, **render.warp_kwargs(src.pixels))
        save_output(out, src, render, command="lattes")


# -- fit-rational ------------------------------------------------------------------------
@click.command(
    "fit-rational",
    epilog=example(
        "spherewarp fit-rational --expr '(z**2 + 1)**2 / (4*z*(z**2 - 1))'",
        "spherewarp fit-rational --expr 'z**3 + 1/z' --degree 4",
    ),
)
@click.option(
    "--expr",
    required=True,
    help="A formula in z (the default chart: 0 at the zenith); see spherewarp.maps.expression.",
)
@click.option(
    "--degree",
    type=click.IntRange(1, 256),
    help="The degree of the rational map (default: detected, up to --max-degree).",
)
@click.option(
    "--max-degree",
    type=click.IntRange(1, 256),
    default=32,
    show_default=True,
    help="Largest degree tried when detecting it.",
)
def fit_rational_cmd(expr: str, degree: int | None, max_degree: int) -> None:
    """Fit a rational map to a formula by the SVD and print it as JSON.

    Samples the formula at points spread over the sphere and finds the
    numerator and denominator coefficients (highest degree first, complex
    numbers as [re, im], leading denominator coefficient 1), with the degree
    and the residual (the largest chordal distance to the samples). A formula
    that is not a rational map of that degree is refused.
    """
    from ..maps import fit_rational
    from ..maps.expression import ExpressionMap

    fmap = ExpressionMap(expr)
    fit = fit_rational(fmap, degree, max_degree=max_degree)
    click.echo(_json_of_fit(fit.to_dict()))


# -- peirce -----------------------------------------------------------------------------
@click.command(
    epilog=example(
        "spherewarp peirce room.jpg -o square.png --size 1024",
        "spherewarp peirce square.png --inverse -o room-again.png --size 2048x1024",
    )
)
@input_argument
@click.option(
    "--inverse",
    is_flag=True,
    help="INPUT is a Peirce quincuncial square: turn it back into an equirectangular image.",
)
@click.option(
    "--lon0",
    type=float,
    default=0.0,
    show_default=True,
    help="Central meridian in degrees (PROJ's +lon_0): it runs to the bottom-left corner.",
)
@print_options
@recipe_options
@render_options
def peirce(
    input: Path,
    render: RenderOptions,
    inverse: bool,
    lon0: float,
    print_recipe: bool = False,
    print_map: bool = False,
    save_recipe: Path | None = None,
    dry_run: bool = False,
) -> None:
    """Peirce's quincuncial projection: the whole sphere in a square.

    The zenith is at the centre, the nadir at the four corners; conformal
    except at four points of the equator (the midpoints of the sides). --size N
    sets the side of the square (default 1.5 x the input's height); with
    --inverse, --size WxH sets the equirectangular output.
    """
    import math

    from ..errors import InvalidValueError
    from ..grids.peirce import peirce_to_equirect
    from ._common import output_path

    render.refuse_view("peirce")

    if not math.isfinite(lon0):
        raise click.BadParameter(f"expected a finite longitude, got {lon0!r}", param_hint="--lon0")
    if inverse and (save_recipe or dry_run or print_recipe or print_map):
        raise click.UsageError(
            "--inverse takes a Peirce square back to the sphere: it has no recipe or map "
            "(a recipe renders panoramas)"
        )
    if print_map:
        raise click.UsageError("peirce renders a picture of its own, not a map: use --print")
    step = {"peirce": {"lon0": lon0}}
    if print_recipe:
        show_recipe(step, render, input)
        return
    if inverse:
        from ..io import read_image

        _check_suffix(output_path(render, input, "peirce"))
        src = read_image(input, max_pixels=render.max_pixels)
        h, w = src.pixels.shape[:2]
        if h != w:
            raise InvalidValueError(
                f"{input}: expected a square Peirce quincuncial image, got {w}x{h}"
            )
        if render.size is not None and render.size[0] != 2 * render.size[1]:
            raise click.BadParameter(
                f"expected a 2:1 size for the panorama, got {render.size[0]}x{render.size[1]}",
                param_hint="--size",
            )
        shape = (render.size[1], render.size[0]) if render.size else None
        n = render.supersample  # --antialias N: N x N samples a pixel, as project --from
        if not isinstance(render.antialias, str):
            n = int(render.antialias)
        out = peirce_to_equirect(
            src.pixels,
            shape,
            lon0=lon0,
            interp=render.interp,
            supersample=n,
            progress=render.progress(),
        )
        save_output(out, src, render, command="peirce")
        return
    from ._common import load_input

    if render.size is not None:  # a square picture: --size N (read as N x N/2) or N x N
        w, h = render.size
        if h not in (w, w // 2) or not 2 <= w <= 32768:
            raise click.BadParameter(
                f"expected a square of 2 to 32768 pixels a side (--size N), got {w}x{h}",
                param_hint="--size",
            )
    with saving_recipe(step, render, input, save_recipe, dry_run) as dry:
        if dry:
            return
        _check_suffix(output_path(render, input, "peirce"))
        src = load_input(input, render)
        out = render_recipe(step, render, src, "peirce")[0]
        save_output(out, src, render, "peirce", gpano=False)


# -- torus -------------------------------------------------------------------------------
@click.command(
    epilog=example(
        "spherewarp torus room.jpg -o torus.png --lattice square --cells 2x2",
        "spherewarp torus room.jpg -o hex.png --lattice hex --mesh torus.obj",
    )
)
@input_argument
@click.option(
    "--lattice",
    type=_LATTICE,
    default="square",
    show_default=True,
    help="Square torus Z[i] or hexagonal torus Z[w].",
)
@click.option(
    "--cells",
    default="1x1",
    show_default=True,
    metavar="CXxCY",
    help="How many cells across and down (each holds two copies of the panorama).",
)
@click.option(
    "--mesh",
    type=click.Path(dir_okay=False, path_type=Path),
    metavar="OUT.obj",
    help="Also write a textured torus: OUT.obj, OUT.mtl and OUT_texture.png (not part of "
    "the recipe).",
)
@print_options
@recipe_options
@render_options
def torus(
    input: Path,
    render: RenderOptions,
    lattice: str,
    cells: str,
    mesh: Path | None,
    print_recipe: bool = False,
    print_map: bool = False,
    save_recipe: Path | None = None,
    dry_run: bool = False,
) -> None:
    """Toroidal image: pull a 360° image back to the torus by Weierstrass p.

    The unit cell holds two copies of the panorama and four branch points
    (the square cell: nadir at the corners, zenith at the centre, back at the
    middle of the top and bottom sides, front at the middle of the left and
    right sides). The image tiles the plane. --size W
    sets the width (the height follows from the cells); default: the input's
    width.
    """
    from ..effects.torus import parse_cells
    from ..errors import InvalidValueError

    render.refuse_view("torus")

    try:
        cxy = parse_cells(cells)
    except InvalidValueError as exc:
        raise click.BadParameter(str(exc), param_hint="--cells") from None
    if print_map:
        raise click.UsageError("torus renders a picture of its own, not a map: use --print")
    lat = lattice.lower()
    step = {"torus": {"lattice": lat, "cells": list(cxy)}}
    if print_recipe:
        show_recipe(step, render, input)
        return
    if mesh is not None:
        from ..effects.torus import check_obj_name

        try:
            check_obj_name(mesh)
        except InvalidValueError as exc:
            raise click.BadParameter(str(exc), param_hint="--mesh") from None
    with saving_recipe(step, render, input, save_recipe, dry_run) as dry:
        if not dry:
            _torus(input, render, step, mesh, cxy)


def _torus(
    input: Path, render: RenderOptions, step: dict[str, Any], mesh: Path | None, cxy: Any
) -> None:
    from ..effects.torus import render_torus_texture, write_torus_obj
    from ..errors import OutputExistsError
    from ._common import load_input, output_path
    from ._files import job

    _check_suffix(output_path(render, input, "torus"))
    lat = step["torus"]["lattice"]
    if mesh is not None:
        for p in (mesh, mesh.with_suffix(".mtl"), mesh.with_name(mesh.stem + "_texture.png")):
            job().writes(p, "--mesh", str(mesh))
            if p.exists() and not render.overwrite:
                raise OutputExistsError(f"{str(p)!r} exists; pass --overwrite to replace it")
        from ..io.atomic import check_writable

        check_writable(mesh)  # before the picture is written, not after
    src = load_input(input, render)
    kw = {"interp": render.interp, "supersample": render.supersample, "force": render.force}
    out = render_recipe(step, render, src, "torus")[0]
    save_output(out, src, render, "torus", gpano=False)
    if mesh is not None:
        texture = render_torus_texture(src.pixels, lat, cells=cxy, **kw)
        if texture.dtype.kind == "f":  # the PNG texture: 16-bit
            import numpy as np

            texture = np.clip(np.rint(texture * 65535.0), 0, 65535).astype(np.uint16)
        for p in write_torus_obj(mesh, texture, cells=cxy, lattice=lat, overwrite=render.overwrite):
            click.echo(f"wrote {p}")
