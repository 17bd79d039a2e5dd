"""``spherewarp video IN -o OUT EFFECT [effect options]``: warp every frame of a 360° video.

The effect is a subcommand with the options of the still command of the same
name (``rotate``, ``zoom``, ``mobius``); its map does not change over time, so
it is planned once and reused for every frame. See :mod:`spherewarp.io.video`
for what is kept (timing, audio, spherical metadata).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import click

from ._common import POINT, SIZE, example, view_options
from ._video_out import (
    PathOrURL,
    refuse_segment_options,
    register_paths,
    segment_options,
    segment_progress,
)
from .branched_cmds import _LOOK_AT_HELP, EXP_SUPERSAMPLE, EXPONENT, POSITIVE
from .mobius_cmds import ANGLE, FACTOR, MATRIX

__all__ = ["video"]


def _view_options(func: Any) -> Any:
    for option in reversed(view_options):
        func = option(func)
    return func


class _EffectGroup(click.Group):
    """A group whose own options may follow INPUT: ``video IN -o OUT EFFECT ...`` (a plain group
    stops reading its options at the first argument)."""

    def parse_args(self, ctx: click.Context, args: list[str]) -> list[str]:
        i = next((k for k, a in enumerate(args) if a in self.commands), len(args))
        if i == len(args):
            self._refuse_misspelt_effect(ctx, args)
        ctx.allow_interspersed_args = True
        rest = click.Command.parse_args(self, ctx, args[:i]) + args[i:]
        ctx.allow_interspersed_args = False
        if "_protected_args" in vars(ctx):  # click >= 8.2
            ctx._protected_args, ctx.args = rest[:1], rest[1:]
        else:
            ctx.protected_args, ctx.args = rest[:1], rest[1:]
        return ctx.args

    def _refuse_misspelt_effect(self, ctx: click.Context, args: list[str]) -> None:
        """No effect named: a later INPUT that is no file and reads like an effect name is a
        misspelt effect (``rotat``), said as such, not taken for an input clip."""
        import difflib
        import os

        takes_value = {
            name
            for p in self.get_params(ctx)
            if isinstance(p, click.Option) and not p.is_flag and not p.count
            for name in p.opts
        }
        positionals = 0
        after_option = None
        for a in args:
            if a == "--":
                return
            if a.startswith("-") and len(a) > 1:
                after_option = a if "=" not in a else None
                continue
            if after_option in takes_value:  # the option's value
                after_option = None
                continue
            after_option = None
            positionals += 1
            if positionals == 1 or os.path.exists(a):
                continue
            close = difflib.get_close_matches(a.lower(), sorted(self.commands), n=1)
            if close:
                raise click.UsageError(f"no such effect {a!r} (did you mean {close[0]!r}?)")


@click.group(
    cls=_EffectGroup,
    epilog=example(
        "spherewarp video tour.mp4 -o tour-zoomed.mp4 zoom --at 0,0 --factor 2",
        "spherewarp video tour.mp4 -o tour-right.mp4 --codec libx265 --crf 22 rotate --yaw 90",
        "spherewarp video tour.mp4 -o flight.mp4 recipe flight.json",
        "spherewarp video stereo-tb.mp4 -o planet.mkv --projection little-planet rotate",
        "spherewarp video 'in/%05d.png' --fps 30 -o 'out/%05d.exr' zoom --at 0,0 --factor 2",
        "spherewarp video still-tb.jpg --stereo tb -o turned.jpg rotate --yaw 90",
    ),
)
@click.argument("input", nargs=-1, required=True, type=PathOrURL())
@click.option(
    "-o",
    "--output",
    type=PathOrURL(),
    help="The video to write (.mp4, .mov, .m4v, .mkv or .webm), or an image sequence "
    "(out/%05d.exr, frames numbered from 0; PNG, TIFF, EXR...); may also follow the effect. "
    "A video (INPUT too) may be an fsspec URL (ftp://host/out.mp4).",
)
@click.option(
    "--codec",
    help="The video encoder (default libx264; libvpx-vp9 for .webm): libx264, libx265, "
    "libvpx-vp9, libsvtav1, or another this build offers.",
)
@click.option(
    "--crf",
    type=click.FloatRange(0, 63),
    help="Constant rate factor: lower is better and bigger (default: 18 for x264, 20 for x265, "
    "31 for VP9).",
)
@click.option("--preset", help="The encoder's speed preset (x264/x265: ultrafast ... veryslow).")
@click.option(
    "--pix-fmt",
    help="The encoded pixel format (default: the input's when the encoder takes it, "
    "so a 10-bit input stays 10-bit; else yuv420p).",
)
@click.option(
    "--stereo",
    type=click.Choice(["tb", "sbs", "mono"], case_sensitive=False),
    help="The input's stereo layout: tb (top-bottom, left eye on top), sbs (side by side, "
    "left eye left) or mono (default: its metadata's, st3d or Matroska StereoMode, else "
    "mono). Each eye is warped on its own and the output keeps the layout.",
)
@click.option(
    "--size",
    type=SIZE,
    help="Output size WxH of each eye (default: the input eye's, or the --projection's).",
)
@_view_options
@click.option(
    "--fps",
    type=click.FloatRange(min=0, max=1000, min_open=True),
    help="Frames a second of an image sequence input (default 24).",
)
@click.option(
    "--tonemap",
    type=click.Choice(["aces", "reinhard", "clip"], case_sensitive=False),
    default="aces",
    show_default=True,
    help="How HDR frames of an EXR/TIFF sequence become video (or 8/16-bit image) values.",
)
@click.option(
    "--force",
    is_flag=True,
    help="Warp a video whose frame (eye) is not 2:1, or that players show rotated (its frames "
    "as stored; the rotation is dropped).",
)
@click.option("--overwrite", is_flag=True, help="Replace an existing output.")
@click.option(
    "-q",
    "--quiet",
    is_flag=True,
    help="No progress bar, no notes (but one: split-screen clips of different lengths, which "
    "cut the output short).",
)
@segment_options
@click.pass_context
def video(ctx: click.Context, input: tuple[Path, ...], output: Path, **options: Any) -> None:
    """Apply an effect to every frame of a 360° video.

    Decodes and encodes with FFmpeg's libraries (PyAV). Each frame keeps its
    time (frame rate, frame count and duration are kept, variable frame rates
    too), audio is copied as it is, and the output carries the 360° metadata
    (Spherical Video V1 and V2; Matroska's elements in .mkv/.webm) that
    YouTube and players look for. An interrupted render leaves no file behind.

    A stereo input (top-bottom or side by side: its metadata, or --stereo) is
    warped eye by eye and keeps its layout. --projection and the other grid
    options (or a recipe's view) render every frame into that grid. INPUT and
    -o may be image sequences (frames/%05d.png, TIFF, EXR; --fps for an
    input sequence), or one image (a stereo still: --stereo tb).
    """
    if len(input) > 1 and ctx.invoked_subcommand not in _SEVERAL_INPUTS:
        raise click.UsageError(
            f"{ctx.invoked_subcommand or 'the effect'} takes one INPUT, got {len(input)} "
            f"(several clips go with {' or '.join(sorted(_SEVERAL_INPUTS))})"
        )
    ctx.obj = {"input": input[0], "inputs": input, "output": output, **options}


#: the subcommands that take several input clips (spherewarp.cli.video_effects)
_SEVERAL_INPUTS = {"splitscreen"}


#: the output grid's options, named as RenderOptions names them
_GRID_KEYS = ("projection", "view_at", "view_roll", "fov")


def _grid(o: dict[str, Any], view: dict[str, Any] | None) -> tuple[Any, tuple[int, int] | None]:
    """``(grid, out_shape)`` for :func:`spherewarp.io.video.render_video`: the command line's
    grid options, else the recipe's ``view``; a grid's default size rounded down to even sides
    (the encoders' 4:2:0 chroma needs them)."""
    chosen = {k: o.get(k) for k in _GRID_KEYS}
    size = None if o.get("size") is None else (o["size"][1], o["size"][0])
    if not any(chosen.values()) and view:
        chosen = {
            "projection": view.get("projection"),
            "view_at": view.get("look_at"),
            "view_roll": view.get("roll") or 0.0,
            "fov": view.get("fov"),
        }
        if size is None and view.get("size") is not None:
            size = (view["size"][1], view["size"][0])
    if not any(chosen.values()):
        return None, size
    if chosen["fov"] is not None and chosen["projection"] is None:
        from ..errors import InvalidValueError

        raise InvalidValueError(
            "--fov needs a --projection (little-planet, rectilinear, fisheye, ...)"
        )
    name = chosen["projection"] or "equirect"

    return _GridFor(name, size, chosen), None


class _GridFor:
    """``grid(eye_shape) -> Grid``: a picklable grid maker (segments render elsewhere)."""

    def __init__(self, name: str, size: Any, chosen: dict[str, Any]) -> None:
        self.name, self.size, self.chosen = name, size, chosen

    def __call__(self, eye: tuple[int, int]) -> Any:
        from ..grids import default_shape, make_grid

        shape = self.size
        if shape is None:
            h, w = default_shape(self.name, eye)
            shape = (max(2, h - h % 2), max(2, w - w % 2))
        look = self.chosen["view_at"]
        return make_grid(
            self.name, eye, shape=shape, look_at=None if look is None else tuple(look),
            roll=float(self.chosen["view_roll"] or 0.0), fov=self.chosen["fov"],
        )  # fmt: skip


class _Static:
    """``frame_map(t)`` of a map that does not change (picklable)."""

    def __init__(self, inverse: Any, build: dict[str, Any]) -> None:
        self.inverse, self.build = inverse, build

    def __call__(self, t: float) -> tuple[Any, dict[str, Any]]:
        return self.inverse, self.build


class _Timed:
    """``frame_map(t)`` of a timed recipe; tells ``pose`` what each frame's map does to the
    directions (in this process; :meth:`on_client` for frames rendered elsewhere)."""

    def __init__(self, recipe: Any, build: dict[str, Any], pose: _Pose | None) -> None:
        self.recipe, self.build, self.pose = recipe, build, pose

    def __call__(self, t: float) -> tuple[Any, dict[str, Any]]:
        if self.pose is not None:
            self.pose.see(self.recipe.pose_at(t))
        return self.recipe.map_at(t), self.build

    def on_client(self, times: list[float]) -> None:
        for t in times:
            self.pose.see(self.recipe.pose_at(t))

    def __getstate__(self) -> dict[str, Any]:
        return {**vars(self), "pose": None}


def _outputs(func: Any) -> Any:
    """-o and --overwrite after the effect too (``video IN zoom ... -o OUT``)."""
    func = click.option("--overwrite", "overwrite_", is_flag=True, hidden=True)(func)
    return click.option("-o", "--output", "output_", type=PathOrURL(), hidden=True)(func)


def _take_output(o: dict[str, Any], output: Path | None, overwrite: bool) -> dict[str, Any]:
    """The parent's options ``o`` with -o and --overwrite given after the effect; refuses
    a render without -o."""
    if output is not None:
        o["output"] = output
    o["overwrite"] = o["overwrite"] or overwrite
    if o["output"] is None:
        raise click.UsageError("give the video to write with -o OUT.mp4")
    return o


def _check_video_output(output: Path) -> None:
    """Refuse an output whose extension names no video container."""
    from ..io.video import _check_output

    _check_output(output, " with -o")


def _run(
    ctx: click.Context,
    forward: Any,
    output: Path | None,
    overwrite: bool,
    pull: Any = None,
    build: dict[str, Any] | None = None,
    frame_map: Any = None,
    view: dict[str, Any] | None = None,
    pose: _Pose | None = None,
) -> None:
    """Render the parent's INPUT to its -o with the map that moves the content by ``forward``
    (or pulls it back by ``pull``; ``build``: WarpMap.build's options; or ``frame_map(t)``,
    as :func:`spherewarp.io.video.render_video` takes it); ``view``: a recipe's, used
    unless the command line names an output grid; ``pose``: what the input's spherical pose
    must follow (default: ``forward``, a turn it follows; with ``pull``, none)."""
    o = _take_output(ctx.obj, output, overwrite)
    from ..io.sequence import is_frames, is_pattern

    sequence = is_frames(o["input"]) or is_frames(o["output"])
    if sequence:
        _register_sequence(o["input"], o["output"])
    else:
        register_paths([(o["input"], "input")], o["output"])
    if o["fps"] is not None and not is_frames(o["input"]):
        raise click.BadParameter(
            "applies to an image sequence input (a video keeps its frame times)",
            param_hint="--fps",
        )
    if not is_frames(o["output"]):
        _check_video_output(o["output"])
    if pose is None:
        pose = _Pose(o["quiet"])
        pose.see(forward if pull is None else None)
    if frame_map is None:
        frame_map = _Static(forward.inverse() if pull is None else pull, build or {})
    grid, out_shape = _grid(o, view)
    if sequence:
        refuse_segment_options(o, "an image sequence is written frame by frame")
    bar = segment_progress(o["quiet"], o["progress"])
    options = dict(
        codec=o["codec"], crf=o["crf"], preset=o["preset"], pix_fmt=o["pix_fmt"],
        overwrite=o["overwrite"], force=o["force"], progress=bar, stereo=o["stereo"],
        grid=grid, out_shape=out_shape, spherical=pose,
    )  # fmt: skip
    try:
        if sequence:
            from ..io.sequence import render_sequence

            n = render_sequence(
                o["input"], o["output"], frame_map, fps=o["fps"], tonemap=o["tonemap"], **options
            )
            bar.close()
            one = n == 1 and not is_pattern(o["output"])
            click.echo(f"wrote {o['output']}" if one else f"wrote {n} frames to {o['output']}")
        else:
            from ..io.segments import DEFAULT_SEGMENT_SECONDS, render_segmented

            render_segmented(
                o["input"], o["output"], frame_map, identity=_identity(ctx, o),
                resume=o["resume"], jobs=o["jobs"], dask=o["dask"],
                segment_seconds=o["segment"] or DEFAULT_SEGMENT_SECONDS,
                on_client=getattr(frame_map, "on_client", None), **options,
            )  # fmt: skip
            bar.close()
            click.echo(f"wrote {o['output']}")  # as every command does (--quiet keeps it)
    finally:
        bar.close()


#: the options of ``video`` that do not change the pixels (left out of a render's identity)
_NOT_PIXELS = ("input", "output", "overwrite", "quiet", "progress", "resume", "jobs", "dask")


def _identity(ctx: click.Context, o: dict[str, Any]) -> str:
    """Everything that decides the output's pixels, as text: the effect and its options,
    the recipe file's contents, the ``video`` options (a resumed render must match it)."""
    import hashlib
    import json

    params = {k: v for k, v in ctx.params.items() if k not in ("output_", "overwrite_")}
    recipe = params.get("recipe")
    if recipe is not None:
        params["recipe"] = hashlib.sha256(Path(recipe).read_bytes()).hexdigest()
    group = {k: v for k, v in o.items() if k not in _NOT_PIXELS}
    return json.dumps(
        {"effect": ctx.info_name, "params": params, "video": group}, sort_keys=True, default=str
    )


def _file_key(path: Path) -> Any:
    """What names one file whatever the path (a link, a hard link): its device and inode, or
    its real path when it does not exist."""
    import os

    try:
        st = os.stat(path)
    except OSError:
        return os.path.realpath(path)
    return (st.st_dev, st.st_ino)


def _register_sequence(input: Path, output: Path) -> None:
    """Register a sequence's frames as read (and a video as read or written), refusing an
    output frame that would be an input frame."""

    from ..errors import InvalidValueError
    from ..io.sequence import _frame_out, frames_of, is_frames, is_pattern, split_pattern
    from ._files import job

    inputs = frames_of(input) if is_frames(input) else [job().reads(input, "input")]
    if is_frames(output):
        if is_pattern(output):
            split_pattern(output)
        ours = {_file_key(p): p for p in inputs}
        for k in range(len(inputs) if is_pattern(output) else 1):
            p = _frame_out(output, k)
            same = ours.get(_file_key(p))
            if same is not None:
                raise InvalidValueError(
                    f"-o {str(output)!r} would write {str(p)!r}, which is the input frame "
                    f"{str(same)!r}; choose another -o (an input is never overwritten, not "
                    "even with --overwrite)"
                )
    else:
        for p in inputs:
            job().reads(p, "input frame")
        job().writes(output, "-o")


class _Pose:
    """The output's spherical pose (``sv3d``/``prhd`` yaw, pitch, roll): the input's, turned
    with the map as the still commands turn a GPano pose, kept when the map leaves the
    directions in place, else dropped with a note.

    :meth:`see` is told the turn of the sphere the pose must follow, once for a static map
    or at every frame (None: no pose holds, as after a branched map); called with the
    metadata to write, it puts the pose in (a
    :func:`~spherewarp.io.video.render_video` ``spherical`` callable).
    """

    def __init__(self, quiet: bool) -> None:
        self.quiet = quiet
        self.yaws: set[float] = set()
        self.lost = False

    def see(self, moves: Any) -> None:
        from .mobius_cmds import _view_yaw

        yaw = None if moves is None else (0.0 if moves.is_identity() else _view_yaw(moves))
        if yaw is None:
            self.lost = True
        else:
            self.yaws.add(round(yaw, 9) % 360.0)

    def __call__(self, meta: Any) -> Any:
        if not (meta.yaw or meta.pitch or meta.roll):
            return meta
        if not self.lost and len(self.yaws) == 1:
            (turn,) = self.yaws
            if turn == 0.0:
                return meta
            if not (meta.pitch or meta.roll):  # a level pose follows a turn about the vertical
                meta.yaw = (meta.yaw - turn + 180.0) % 360.0 - 180.0  # sv3d: counter-clockwise
                return meta
        if not self.quiet:
            click.echo(
                "spherewarp: note: the input's spherical pose (sv3d yaw "
                f"{meta.yaw:g}, pitch {meta.pitch:g}, roll {meta.roll:g}) does not describe the "
                "output; it is left out",
                err=True,
            )
        meta.yaw = meta.pitch = meta.roll = 0.0
        return meta


@video.command("rotate")
@click.option("--yaw", type=ANGLE, default=0.0, help="Turn the view right by DEG.")
@click.option("--pitch", type=ANGLE, default=0.0, help="Turn the view up by DEG.")
@click.option("--roll", type=ANGLE, default=0.0, help="Roll the view clockwise by DEG.")
@_outputs
@click.pass_context
def video_rotate(
    ctx: click.Context, yaw: float, pitch: float, roll: float, output_: Any, overwrite_: bool
) -> None:
    """Turn the view, as the rotate command and ffmpeg's v360 filter do."""
    from ..maps import Mobius

    _run(ctx, Mobius.from_yaw_pitch_roll(yaw, pitch, roll).inverse(), output_, overwrite_)


@video.command("zoom")
@click.option("--at", type=POINT, required=True, help="The point to zoom toward, LON,LAT.")
@click.option("--factor", type=FACTOR, required=True, help="Magnification at the point.")
@click.option("--center", is_flag=True, help="Also turn the zoom point to the image centre.")
@_outputs
@click.pass_context
def video_zoom(
    ctx: click.Context,
    at: tuple[float, float],
    factor: float,
    center: bool,
    output_: Any,
    overwrite_: bool,
) -> None:
    """Zoom toward a point, as the zoom command does."""
    from ..recipe.effects import zoom_forward

    forward, moves = zoom_forward(at, factor, center)
    pose = _Pose(ctx.obj["quiet"])
    pose.see(moves)  # the zoomed point stays where the pose places it; --center turns it
    _run(ctx, forward, output_, overwrite_, pose=pose)


@video.command("mobius")
@click.option("--matrix", type=MATRIX, required=True, help="Entries a,b,c,d (as `mobius`).")
@_outputs
@click.pass_context
def video_mobius(
    ctx: click.Context, matrix: tuple[complex, ...], output_: Any, overwrite_: bool
) -> None:
    """Push the content forward by z -> (az+b)/(cz+d), as the mobius command does."""
    from ..errors import InvalidValueError
    from ..maps import Mobius

    a, b, c, d = matrix
    try:
        forward = Mobius([[a, b], [c, d]])
    except InvalidValueError as exc:
        raise InvalidValueError(f"--matrix: {exc.cli_message}") from None
    _run(ctx, forward, output_, overwrite_)


@video.command("power")
@click.option(
    "--n", "exponent", type=EXPONENT, default="2", show_default=True, help="The exponent."
)
@click.option("--look-at", type=POINT, default=None, help=_LOOK_AT_HELP)
@_outputs
@click.pass_context
def video_power(
    ctx: click.Context, exponent: float, look_at: Any, output_: Any, overwrite_: bool
) -> None:
    """Pull back by z**n, as the power command does (default branch points)."""
    from ..maps.branched import Power
    from ..recipe.effects import with_look_at

    _run(ctx, None, output_, overwrite_, pull=with_look_at(Power(exponent), look_at))


@video.command("exp")
@click.option("--lam", type=POSITIVE, default=4.0, show_default=True, help="Scale lambda.")
@click.option("--look-at", type=POINT, default=None, help=_LOOK_AT_HELP)
@_outputs
@click.pass_context
def video_exp(ctx: click.Context, lam: float, look_at: Any, output_: Any, overwrite_: bool) -> None:
    """Pull back by the exp variant, as the exp command does (supersampled 3x3)."""
    from ..maps.branched import ExpMap
    from ..recipe.effects import with_look_at

    pull = with_look_at(ExpMap(lam), look_at)
    _run(ctx, None, output_, overwrite_, pull=pull, build={"supersample": EXP_SUPERSAMPLE})


@video.command("recipe")
@click.argument("recipe", type=click.Path(dir_okay=False, path_type=Path), metavar="R.json")
@_outputs
@click.pass_context
def video_recipe(ctx: click.Context, recipe: Path, output_: Any, overwrite_: bool) -> None:
    """Apply a recipe (``--save-recipe``, see ``spherewarp render``): a timed one is evaluated
    at every frame's presentation time (a loop wraps round its duration), a static one is
    planned once for the whole video."""
    from ._files import job
    from .recipe_cmds import load_recipe

    job().reads(recipe, "the recipe")
    run_recipe(ctx, load_recipe(recipe), recipe, output_, overwrite_)


def run_recipe(ctx: click.Context, r: Any, path: Any, output_: Any, overwrite_: bool) -> None:
    """Render the parent's INPUT through the recipe ``r`` (read from ``path``, or what names
    it in messages), as ``video ... recipe R.json`` does."""
    _check_recipe_fits(r, path, ctx.obj)
    if r.n_inputs > 1:
        from ..errors import InvalidValueError

        raise InvalidValueError(
            f"{path}: the recipe renders from {r.n_inputs} images (a split screen's, or "
            "Droste's --inside images) but video renders one clip through a recipe; use "
            "'spherewarp video A.mp4 B.mp4 -o OUT splitscreen ...' for clips on the sheets, "
            "or 'spherewarp video IN -o OUT droste ... --inside IMAGE'"
        )
    if r.at(0.0).renderer is not None:  # a step that draws its own picture (a log view)
        from .video_effects import _run_whole

        _run_whole(ctx, r, (), output_, overwrite_)
        return
    keys = ("interp", "antialias", "supersample")
    build = {k: v for k, v in r.at(0.0).warp_kwargs.items() if k in keys}
    if build.get("supersample") == 1:
        build.pop("supersample")
    static = None if r.animated else r.map_at(0.0)
    pose = _Pose(ctx.obj["quiet"])
    if static is not None:
        pose.see(r.pose_at(0.0))

    frame_map = _Static(static, build) if static is not None else _Timed(r, build, pose)
    _run(ctx, None, output_, overwrite_, frame_map=frame_map, view=r.at(0.0).view, pose=pose)


def _check_recipe_fits(r: Any, path: Path, o: dict[str, Any]) -> None:
    """Refuse a timed recipe that runs longer than the clip (its end would never be shown)."""
    from ..errors import InvalidValueError
    from ..io.sequence import DEFAULT_FPS, frames_of, is_frames, is_pattern
    from ..io.video import probe

    if r.duration is None or not r.animated:
        return
    if is_frames(o["input"]) and not is_pattern(o["input"]):
        return  # one image: the recipe at time 0
    if is_frames(o["input"]):
        rate = o["fps"] or DEFAULT_FPS
        seconds, step = len(frames_of(o["input"])) / rate, 1 / rate
    else:
        info = probe(o["input"])
        if info.duration is None:
            return
        seconds, step = info.duration, 1 / float(info.rate or 24)
    if r.duration > seconds + step / 2:
        what = "loop" if r.loop else "recipe"
        raise InvalidValueError(
            f"{path}: the {what} runs {r.duration:g} s but '{o['input']}' lasts {seconds:g} s, "
            'so its end would never be shown; shorten its "duration" (or its keyframes) '
            "to the clip's"
        )


from . import video_effects  # noqa: E402, F401 - the effects generated from the still commands
