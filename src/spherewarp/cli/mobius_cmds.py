"""``spherewarp rotate``, ``zoom`` and ``mobius``: Möbius transformations of an image.

Each command builds the map that moves the content (the *forward* map), then
renders by pulling the image back through its inverse. ``--print-map`` prints the
forward map as JSON (:meth:`~spherewarp.maps.SphereMap.to_json`) instead of
rendering; :func:`spherewarp.maps.map_from_json` reads it back and
``spherewarp.render.push(image, m)`` renders it.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import click

from ._common import PIXEL, POINT, RealType, RenderOptions, example, input_argument, render_options
from .recipe_cmds import print_options, printed, recipe_options, saving_recipe

__all__ = ["rotate", "zoom", "mobius"]


class MatrixType(click.ParamType):
    """Four complex entries ``a,b,c,d`` of the matrix ``[[a, b], [c, d]]``."""

    name = "a,b,c,d"

    def convert(self, value: Any, param: Any, ctx: Any) -> tuple[complex, ...]:
        if isinstance(value, tuple):
            return value
        parts = str(value).replace(" ", "").split(",")
        if len(parts) != 4:
            self.fail(
                f"expected four complex entries a,b,c,d (e.g. 1,0.5j,0,1), got {value!r} "
                f"({len(parts)} entr{'y' if len(parts) == 1 else 'ies'})",
                param,
                ctx,
            )
        entries = []
        for name, text in zip("abcd", parts, strict=True):
            low = text.lower()
            if "nan" in low or "inf" in low:
                self.fail(f"expected finite matrix entries, got {name} = {text!r}", param, ctx)
            try:
                c = complex(low.replace("i", "j"))
            except ValueError:
                self.fail(
                    f"expected a complex number like 1+2j or 0.5i for entry {name}, got {text!r}",
                    param,
                    ctx,
                )
            if not (math.isfinite(c.real) and math.isfinite(c.imag)):
                self.fail(f"expected finite matrix entries, got {name} = {text!r}", param, ctx)
            entries.append(c)
        return tuple(entries)


ANGLE = RealType("an angle in degrees", "30 or -12.5", metavar="DEG")
# Beyond 1e9 either way the whole image is one pixel and the matrix nears double precision.
FACTOR = RealType("a zoom factor", "2, or 0.5 to zoom out", metavar="F", ge=1e-9, le=1e9)
MATRIX = MatrixType()


def check_output_suffix(path: Path) -> None:
    """Raise unless ``path``'s extension names a format that can be written."""
    from ..errors import ImageFormatError
    from ..io import SUPPORTED_EXTENSIONS

    if path.suffix.lower() not in SUPPORTED_EXTENSIONS:
        allowed = ", ".join(SUPPORTED_EXTENSIONS)
        raise ImageFormatError(
            f"cannot write '{path}': unknown extension {path.suffix or '(none)'!r}; "
            f"use one of {allowed}"
        )


def _view_yaw(moves: Any) -> float | None:
    """How far (degrees) a map turns the view right about the vertical, or None if not a yaw.

    ``moves`` moves the content; a yaw moves the content at longitude ``lon`` to
    ``lon - yaw``, so the centre then shows what was ``yaw`` degrees to the right.
    """
    if not moves.is_rotation():
        return None
    rot = moves.to_rotation_matrix()
    if abs(rot[2, 2] - 1.0) > 1e-9:
        return None
    yaw = -math.degrees(math.atan2(rot[1, 0], rot[0, 0]))
    return 0.0 if abs(yaw) < 1e-9 else yaw


def _output_gpano(
    src: Any, shape: tuple[int, ...], pose_moves: Any, command: str, quiet: bool = False
) -> Any:
    """The output's GPano: the input's pose turned with the view, kept, or dropped.

    ``pose_moves`` is the turn of the sphere that the recorded pose must follow
    (identity: the pose still holds; None: it no longer describes the pixels).
    A pose that cannot follow is dropped with a note on stderr (unless ``quiet``).
    """
    gpano = getattr(src, "gpano", None)
    if gpano is None or not gpano.has_pose:
        return True  # a plain full-sphere GPano
    full = gpano.as_full_sphere(int(shape[1]), int(shape[0]))
    yaw = None if pose_moves is None else _view_yaw(pose_moves)
    turned = None if yaw is None else full.turned(yaw)
    if turned is None:
        if quiet:
            return full.without_pose()
        click.echo(
            f"note: the input's GPano pose (PoseHeadingDegrees/PitchDegrees/RollDegrees) "
            f"does not describe the {command} output; it is left out",
            err=True,
        )
        return full.without_pose()
    return turned


def _render(
    input: Path,
    render: RenderOptions,
    forward: Any,
    command: str,
    src: Any = None,
    pose_moves: Any = None,
) -> None:
    """Read INPUT (unless ``src`` has it), push it forward by ``forward``, write the result.

    ``pose_moves``: see :func:`_output_gpano`.
    """
    from ..render import warp
    from ._common import load_input, output_path, save_output

    check_output_suffix(output_path(render, input, command))  # refuse a bad output early
    if src is None:
        src = load_input(input, render)
    out = warp(src.pixels, forward.inverse(), **render.warp_kwargs(src.pixels))
    gpano = _output_gpano(src, out.shape, pose_moves, command, render.quiet)
    save_output(out, src, render, command=command, gpano=gpano)


@click.command(
    epilog=example(
        "spherewarp rotate room.jpg --yaw 90 -o room-right.jpg",
        "spherewarp rotate room.jpg --yaw 30 --pitch -10 --roll 5 -o tilted.jpg",
        "spherewarp rotate room.jpg --axis -163,5 --angle 45 -o turned.png",
    )
)
@input_argument
@click.option("--yaw", type=ANGLE, help="Turn the view right by DEG (ffmpeg v360 yaw).")
@click.option("--pitch", type=ANGLE, help="Turn the view up by DEG (ffmpeg v360 pitch).")
@click.option("--roll", type=ANGLE, help="Roll the view clockwise by DEG (ffmpeg v360 roll).")
@click.option(
    "--axis",
    type=POINT,
    help="Rotate the content about this point LON,LAT (degrees); use with --angle.",
)
@click.option(
    "--angle",
    type=ANGLE,
    help="With --axis: turn the content DEG counter-clockwise about the axis, "
    "as seen from the centre of the sphere looking at it.",
)
@print_options
@recipe_options
@render_options
def rotate(
    input: Path,
    render: RenderOptions,
    yaw: float | None,
    pitch: float | None,
    roll: float | None,
    axis: tuple[float, float] | None,
    angle: float | None,
    print_map: bool = False,
    print_recipe: bool = False,
    save_recipe: Path | None = None,
    dry_run: bool = False,
) -> None:
    """Rotate a 360° image: turn the view (yaw/pitch/roll) or the content about an axis.

    --yaw/--pitch/--roll turn the view the way ffmpeg's v360 filter does
    (yaw, then pitch, then roll): --yaw 90 brings what was at longitude +90
    (the right) to the centre. --axis/--angle turn the content about a point
    instead. Give one form or the other.

    360° metadata: a GPano pose recorded in INPUT (PoseHeadingDegrees, ...)
    follows a turn about the vertical (--yaw alone, or an --axis at a pole):
    the heading becomes heading + yaw. Any other rotation tilts the image away
    from the recorded pose, which is then left out (a note says so).
    """
    from ..recipe.effects import rotate_forward

    ypr = (yaw, pitch, roll)
    uses_ypr = any(v is not None for v in ypr)
    uses_axis = axis is not None or angle is not None
    if uses_ypr and uses_axis:
        raise click.UsageError("give either --yaw/--pitch/--roll or --axis with --angle, not both")
    if not (uses_ypr or uses_axis):
        raise click.UsageError("nothing to do: give --yaw/--pitch/--roll, or --axis and --angle")
    if uses_axis:
        if axis is None or angle is None:
            missing = "--axis" if axis is None else "--angle"
            raise click.UsageError(f"--axis and --angle go together; {missing} is missing")
        step = {"axis": list(axis), "angle": angle}
    else:
        step = {k: v for k, v in zip(("yaw", "pitch", "roll"), ypr, strict=True) if v is not None}
    forward = rotate_forward(yaw, pitch, roll, axis, angle)
    if printed({"rotate": step}, forward, render, input, print_recipe, print_map):
        return
    with saving_recipe({"rotate": step}, render, input, save_recipe, dry_run) as dry:
        if not dry:
            _render(input, render, forward, "rotate", pose_moves=forward)


@click.command(
    epilog=example(
        "spherewarp zoom room.jpg --at -163,5 --factor 3 -o picture.jpg",
        "spherewarp zoom room.jpg --at-pixel 47,243 --factor 3 --center -o picture-centred.jpg",
    )
)
@input_argument
@click.option("--at", type=POINT, help="The point to zoom toward, LON,LAT in degrees.")
@click.option(
    "--at-pixel",
    type=PIXEL,
    help="The point to zoom toward as a pixel X,Y of INPUT (origin at the top-left "
    "corner; 512,256 is the centre of a 1024x512 image).",
)
@click.option(
    "--factor",
    type=FACTOR,
    required=True,
    help="Magnification at the point (1e-9 to 1e9); its antipode shrinks by the same factor.",
)
@click.option("--center", is_flag=True, help="Also turn the zoom point to the image centre.")
@print_options
@recipe_options
@render_options
def zoom(
    input: Path,
    render: RenderOptions,
    at: tuple[float, float] | None,
    at_pixel: tuple[float, float] | None,
    factor: float,
    center: bool,
    print_map: bool = False,
    print_recipe: bool = False,
    save_recipe: Path | None = None,
    dry_run: bool = False,
) -> None:
    """Zoom into a 360° image toward a point (a hyperbolic Möbius map).

    The content at the point is magnified FACTOR times and the content at the
    opposite point shrinks FACTOR times; both points stay where they are
    (unless --center). The map is conformal: shapes stay undistorted in the
    small.

    360° metadata: a GPano pose recorded in INPUT is kept: the point zoomed
    toward and its opposite stay where they were, neither moved nor turned, so
    the pose still places them. With --center it follows the turn to the
    centre when that is a turn about the vertical (a point on the horizon) and
    is left out otherwise.
    """
    from ..recipe.effects import zoom_forward

    if (at is None) == (at_pixel is None):
        raise click.UsageError("give exactly one of --at LON,LAT and --at-pixel X,Y")
    src = None
    if at_pixel is not None:
        import numpy as np

        from .. import coords
        from ._common import load_input, output_path

        if not (print_map or print_recipe or dry_run):
            check_output_suffix(output_path(render, input, "zoom"))  # refuse a bad output early
        src = load_input(input, render)
        h, w = src.pixels.shape[:2]
        x, y = at_pixel
        if not (0 <= x <= w and 0 <= y <= h):
            raise click.BadParameter(
                f"expected a pixel inside the {w}x{h} input (0..{w}, 0..{h}), got {x:g},{y:g}",
                param_hint="'--at-pixel'",
            )
        lon, lat = coords.lonlat_deg_from_pixel(np.array([x, y]), w, h)
        at = (float(lon), float(lat))
    forward, pose_moves = zoom_forward(at, factor, center)
    step = {"at": list(at), "factor": factor, "center": center}
    if printed({"zoom": step}, forward, render, input, print_recipe, print_map):
        return
    with saving_recipe({"zoom": step}, render, input, save_recipe, dry_run) as dry:
        if not dry:
            _render(input, render, forward, "zoom", src, pose_moves=pose_moves)


@click.command(
    epilog=example(
        "spherewarp mobius room.jpg --matrix 1,0.5,0,1 -o shifted.jpg",
        "spherewarp mobius room.jpg --matrix '1+1j,0,0,1-1j' -o spiral.jpg",
        "spherewarp mobius room.jpg --from 0,0 90,0 0,90 --to 0,0 60,0 0,60 -o squeezed.jpg",
    )
)
@input_argument
@click.option(
    "--matrix",
    type=MATRIX,
    help="Push the content forward by z -> (az+b)/(cz+d) in the default chart "
    "(0 at the zenith, -1 at the front, 1 at the back, inf at the nadir); entries like "
    "1+2j or 0.5i.",
)
@click.option(
    "--from",
    "from_points",
    type=POINT,
    nargs=3,
    metavar="P1 P2 P3",
    help="Three distinct points LON,LAT; with --to: the content at each moves to the "
    "matching --to point.",
)
@click.option(
    "--to", "to_points", type=POINT, nargs=3, metavar="Q1 Q2 Q3", help="Three distinct points."
)
@print_options
@recipe_options
@render_options
def mobius(
    input: Path,
    render: RenderOptions,
    matrix: tuple[complex, ...] | None,
    from_points: tuple[tuple[float, float], ...] | None,
    to_points: tuple[tuple[float, float], ...] | None,
    print_map: bool = False,
    print_recipe: bool = False,
    save_recipe: Path | None = None,
    dry_run: bool = False,
) -> None:
    """Apply any Möbius transformation: a matrix, or three points to three points.

    Content at p moves to M(p). With --from/--to the map is the unique
    Möbius transformation sending each --from point to its --to point.

    360° metadata: a GPano pose recorded in INPUT follows a map that turns the
    sphere about the vertical, and is left out otherwise (a note says so).
    """
    from ..errors import InvalidValueError
    from ..recipe.effects import mobius_forward

    from_points = from_points or None
    to_points = to_points or None
    uses_points = from_points is not None or to_points is not None
    if matrix is not None and uses_points:
        raise click.UsageError("give either --matrix or --from/--to, not both")
    if matrix is None and not uses_points:
        raise click.UsageError(
            "nothing to do: give --matrix a,b,c,d or --from P1 P2 P3 --to Q1 Q2 Q3"
        )
    if matrix is not None:
        try:
            forward = mobius_forward(matrix)
        except InvalidValueError as exc:
            raise InvalidValueError(f"--matrix: {exc.cli_message}") from None
        step: dict[str, Any] = {"matrix": [[c.real, c.imag] for c in matrix]}
    else:
        if from_points is None or to_points is None:
            missing = "--from" if from_points is None else "--to"
            raise click.UsageError(f"--from and --to go together; {missing} is missing")
        _check_distinct(from_points, "--from")
        _check_distinct(to_points, "--to")
        forward = mobius_forward(None, from_points, to_points)
        step = {"from": [list(p) for p in from_points], "to": [list(p) for p in to_points]}
    if printed({"mobius": step}, forward, render, input, print_recipe, print_map):
        return
    with saving_recipe({"mobius": step}, render, input, save_recipe, dry_run) as dry:
        if not dry:
            _render(input, render, forward, "mobius", pose_moves=forward)


def _check_distinct(points: tuple[tuple[float, float], ...], option: str) -> None:
    """Raise unless the three LON,LAT points are distinct points of the sphere."""
    import numpy as np

    from .. import coords
    from ..errors import InvalidValueError

    xyz = coords.xyz_from_lonlat(np.radians(np.asarray(points, dtype=np.float64)))
    for i, j in ((0, 1), (0, 2), (1, 2)):
        if np.linalg.norm(xyz[i] - xyz[j]) < 1e-9:
            p, q = points[i], points[j]
            raise InvalidValueError(
                f"{option}: expected three distinct points, got the same point twice "
                f"(point {i + 1} = {p[0]:g},{p[1]:g} and point {j + 1} = {q[0]:g},{q[1]:g})"
            )
