"""The ``spherewarp video`` subcommands made from the still commands.

``droste``, ``lattes`` and ``map`` are generated: each takes the still command's
own options for the fields of its recipe step (:data:`spherewarp.recipe.effects.EFFECTS`;
the same click options, so the same parsing, defaults and help), runs the
still command to build its recipe step (as ``--save-recipe --dry-run`` would,
:func:`~spherewarp.cli.recipe_cmds.capturing_recipe`) and renders the video
through that recipe, as ``spherewarp video IN -o OUT recipe R.json`` does: frame
k equals ``spherewarp render R.json`` of frame k. An effect with a ``phase``
(the Droste flight) also takes ``--loop S``: the phase runs from its value to
one more in S seconds, over and over.

``schottky`` (no recipe step yet) builds its map with the still command's
:func:`~spherewarp.cli.schottky_cmds.schottky_map`; ``project --to NAME``
renders every frame into a view; ``splitscreen`` combines several clips
(:mod:`spherewarp.io.multiclip`).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import click

from ._common import SIZE, RealType
from .video_cmds import _grid, _identity, _Pose, _run, run_recipe, video
from .video_cmds import _outputs as _video_outputs

__all__ = ["GENERATED"]

LOOP = RealType("a duration in seconds", "2.5", metavar="S", gt=0, le=86400)

#: video subcommand -> the still command it is made from ("module:function")
GENERATED = {
    "droste": "droste_cmds:droste",
    "lattes": "elliptic_cmds:lattes",
    "map": "branched_cmds:map_cmd",
}


def _outputs(func: Any) -> Any:
    """-o, --overwrite and --size after the effect too (``video IN droste ... --size WxH``)."""
    func = click.option("--size", "size_", type=SIZE, hidden=True)(func)
    return _video_outputs(func)


def _size_after(ctx: click.Context, size: tuple[int, int] | None) -> None:
    """A --size given after the effect: the output's, as before it."""
    if size is not None:
        ctx.obj["size"] = size


def _still(target: str) -> click.Command:
    import importlib

    module, attr = target.split(":")
    return getattr(importlib.import_module(f"{__package__}.{module}"), attr)


def _loop_option(what: str) -> Any:
    return click.option(
        "--loop",
        type=LOOP,
        help=f"Fly on: the phase runs from --phase to one more in S seconds, over and over "
        f"({what}); without it the map does not change over time.",
    )


def recipe_of_command(ctx: click.Context, still: click.Command, values: dict[str, Any]) -> Any:
    """The recipe data ``still`` (an effect command) builds for the option ``values``, as
    ``--save-recipe R.json --dry-run`` writes it (checked as the command checks them)."""
    from .recipe_cmds import capturing_recipe

    with capturing_recipe() as got:
        ctx.invoke(still, input=(), dry_run=True, save_recipe=None, **values)
    if len(got) != 1:  # pragma: no cover - every generated command saves one recipe
        raise RuntimeError(f"{still.name} built {len(got)} recipes")
    return got[0]


def looped(data: dict[str, Any], effect: str, seconds: float) -> dict[str, Any]:
    """``data`` with the effect's phase running from its value to one more in ``seconds``,
    a loop (the recipe ``spherewarp droste --frames`` saves, stretched to ``seconds``).

    Examples
    --------
    >>> d = {"steps": [{"droste": {"phase": 0.25}}]}
    >>> looped(d, "droste", 2.0)["steps"][0]["droste"]["phase"]
    {'keyframes': [[0, 0.25], [2.0, 1.25]]}
    """
    step = dict(data["steps"][0][effect])
    start = float(step.get("phase", 0.0))
    step["phase"] = {"keyframes": [[0, start], [seconds, start + 1]]}
    return {**data, "duration": seconds, "loop": True, "steps": [{effect: step}]}


#: recipe fields the generated commands do not take as options (Droste's ``images`` comes
#: from its --inside images; its ``view`` and ``periods``, see :data:`WHOLE_PICTURE`)
NOT_ON_VIDEO = frozenset({"view", "periods", "images", "inside"})
#: the still command's options that make a step draw a picture of its own (a flat log
#: plane, several images blended): each frame is rendered through the recipe with its
#: images (:func:`_run_whole`), not through a planned map
WHOLE_PICTURE = {"droste": ("view", "periods", "inside")}


def _generate(name: str, target: str) -> click.Command:
    from ..recipe.effects import EFFECTS

    still = _still(target)
    effect = EFFECTS[name]
    # the still command's own options, less those that draw a picture of their own (Droste's
    # log views and its --inside image: a recipe's only step, not yet on video)
    whole = WHOLE_PICTURE.get(name, ())
    fields = (set(effect.params) - NOT_ON_VIDEO) | set(whole)
    params = [p for p in still.params if p.name in fields]
    timed = "phase" in fields

    def callback(
        output_: Any, overwrite_: bool, size_: Any, loop: float | None = None, **values: Any
    ) -> None:
        from .recipe_cmds import command_recipe

        ctx = click.get_current_context()
        _size_after(ctx, size_)
        inside = values.pop("inside", None) or ()
        if "inside" in whole:
            values["inside"] = ()  # the still names its inputs in the recipe; these are ours
        data = recipe_of_command(ctx, still, values)
        if inside:  # the copies cycle through the frame and the --inside images
            data["steps"][0][name]["images"] = 1 + len(inside)
        label: Any = f"video ... {name}"
        if loop is not None:
            data, label = looped(data, name, loop), "--loop"
        recipe = command_recipe(data)  # its errors name the options, as the still's do
        if recipe.at(0.0).renderer is not None:  # a log view, or --inside images
            _run_whole(ctx, recipe, inside, output_, overwrite_)
            return
        run_recipe(ctx, recipe, label, output_, overwrite_)

    summary = (still.help or "").strip().split("\n")[0].rstrip(".")
    help_text = (
        f"{summary}, on every frame: the options of `spherewarp {still.name}`, whose recipe "
        f"step renders each frame (frame k equals `spherewarp {still.name}` of frame k)."
    )
    command = click.Command(
        name, callback=callback, params=params, help=help_text, short_help=effect.summary
    )
    if timed:
        command = _loop_option("the Droste flight, as --frames does for a still")(command)
    return _outputs(command)


for _name, _target in GENERATED.items():
    video.add_command(_generate(_name, _target))


def _like(pixels: Any, frame: Any) -> Any:
    """An --inside image as the frames are: RGB (grey repeated, alpha dropped), their type."""
    import numpy as np

    from ..io.images import convert_dtype

    if pixels.shape[2] in (1, 2):
        pixels = np.repeat(pixels[..., :1], 3, axis=2)
    return np.ascontiguousarray(convert_dtype(pixels[..., :3], frame.dtype))


def _inside_image(path: Path, force: bool) -> Any:
    """The pixels of an --inside image (registered as read), 2:1 unless ``force``."""
    from ..io import read_image
    from ..render.warp import check_equirect
    from ._files import job

    job().reads(path, "--inside image")
    pixels = read_image(path).pixels
    check_equirect(pixels, force=force, name=str(path))
    return pixels


def _run_whole(
    ctx: click.Context, recipe: Any, inside: tuple[Path, ...], output_: Any, overwrite_: bool
) -> None:
    """Render the parent's INPUT through ``recipe``, a step that draws its own picture (the
    Droste log plane; the copies cycling through INPUT and the --inside images): frame k is
    ``recipe.render([frame k, *inside], t_k)``, as the still command renders it. A flat
    picture carries no spherical metadata; odd sides are cropped by one pixel (the encoders'
    4:2:0 chroma needs even ones)."""
    from ..io.multiclip import render_clips
    from ..io.sequence import is_frames
    from ..io.spherical import Spherical
    from ._files import job
    from ._video_out import segment_progress
    from .video_cmds import _check_video_output, _take_output

    o = _take_output(ctx.obj, output_, overwrite_)
    if is_frames(o["input"]) or is_frames(o["output"]):
        from ..errors import ImageFormatError

        raise ImageFormatError("--view log and --inside read and write videos, not image sequences")
    _check_video_output(o["output"])
    for name in ("projection", "view_at", "fov", "fps", "dask"):
        if o.get(name) is not None:
            raise click.BadParameter(
                "does not go with --view log or --inside", param_hint=f"--{name.replace('_', '-')}"
            )
    if (o.get("stereo") or "mono").lower() != "mono":
        raise click.BadParameter("--view log and --inside take mono video", param_hint="--stereo")
    for name in ("resume", "jobs", "segment"):
        if o.get(name) not in (None, False, 1):
            raise click.BadParameter(
                "does not go with --view log or --inside (they render in one process)",
                param_hint=f"--{name}",
            )
    job().reads(o["input"], "input")
    job().writes(o["output"], "-o")
    extra = [_inside_image(p, o["force"]) for p in inside]
    frame0 = recipe.at(0.0)
    kwargs: dict[str, Any] = {}
    if o.get("size") is not None:  # WxH: the equirectangular output's; a log plane's height
        kwargs["output_shape"] = (o["size"][1], o["size"][0])
    if o["force"]:
        kwargs["force"] = True

    def combine(frames: list[Any], t: float) -> Any:
        img = frames[0]
        out = recipe.render([img, *(_like(x, img) for x in extra)], t, **kwargs)
        h, w = out.shape[:2]
        return out[: h - h % 2, : w - w % 2]

    bar = segment_progress(o["quiet"], o["progress"])
    try:
        n = render_clips(
            [o["input"]], o["output"], combine, codec=o["codec"], crf=o["crf"],
            preset=o["preset"], pix_fmt=o["pix_fmt"], overwrite=o["overwrite"],
            force=o["force"], spherical=None if frame0.flat else Spherical(), progress=bar,
            timed=True,
        )  # fmt: skip
    finally:
        bar.close()
    if not o["quiet"]:
        click.echo(f"wrote {o['output']} ({n} frames)")


# -- schottky: the still command's options and map --------------------------------------------
def _copied(target: str, names: tuple[str, ...]) -> Any:
    """A decorator adding the options ``names`` of the still command ``target``."""

    def decorate(command: click.Command) -> click.Command:
        have = {p.name: p for p in _still(target).params}
        command.params[:0] = [have[n] for n in names]
        return command

    return decorate


def _eye_width(o: dict[str, Any]) -> int:
    """The width of one eye's equirectangular output for the Schottky map's depth (the
    still command's rule: as fine as the output's finest pixels)."""
    from ..io.sequence import frames_of, is_frames
    from ..io.stereo import eye_shape
    from ..io.video import probe, stereo_layout
    from .schottky_cmds import _output_width

    if is_frames(o["input"]):
        from ..io import read_image

        shape = read_image(frames_of(o["input"])[0]).pixels.shape[:2]
        eye = eye_shape(shape, o["stereo"] or "mono")
    else:
        info = probe(o["input"])
        eye = eye_shape((info.height, info.width), stereo_layout(info, o["stereo"]))
    grid, out_shape = _grid(o, None)
    kwargs = {"grid": grid(eye)} if grid is not None else {"output_shape": out_shape}
    return _output_width(kwargs, eye)


@_copied(
    "schottky_cmds:schottky",
    ("generators", "twists", "depth", "phase", "mask", "targets", "regions"),
)
@click.command("schottky", short_help="a Schottky group image (several Droste effects at once)")
@_loop_option("a zoom through the first generator's disks")
@_outputs
@click.pass_context
def video_schottky(
    ctx: click.Context,
    generators: tuple[tuple[str, Any, Any], ...],
    twists: tuple[float, ...],
    depth: int | None,
    phase: float,
    mask: Path | None,
    targets: tuple[tuple[str, str], ...],
    regions: str,
    loop: float | None,
    output_: Any,
    overwrite_: bool,
    size_: Any,
) -> None:
    """A Schottky group image on every frame, with the options of `spherewarp schottky`
    (frame k equals `spherewarp schottky` of frame k; --loop S: the --frames loop, S seconds
    a turn)."""
    _size_after(ctx, size_)
    from ._files import job
    from .schottky_cmds import check_generators, schottky_map

    check_generators(generators, twists, mask, targets, regions)
    if mask is not None:
        job().reads(mask, "--mask image")
    s, _ = schottky_map(generators, twists, mask, targets, regions, depth, phase)
    s = s.for_output(_eye_width(ctx.obj))
    maps: dict[float, Any] = {}

    def frame_map(t: float) -> tuple[Any, dict[str, Any]]:
        if loop is None:
            return s, {}
        key = round((t / loop) % 1.0, 12)
        if key not in maps:  # a frame's phase: planned once however often it comes round
            maps.clear()
            maps[key] = s.with_phase(phase + key)
        return maps[key], {}

    pose = _Pose(ctx.obj["quiet"])
    pose.see(None)  # no pose holds after a Schottky map
    _run(ctx, None, output_, overwrite_, frame_map=frame_map, pose=pose)


video.add_command(video_schottky)


# -- project --to: every frame into a view -----------------------------------------------------
@_copied("views_cmds:project", ("to", "look_at", "roll"))
@click.command("project", short_help="every frame into another grid (a little planet, a view)")
@_outputs
@click.pass_context
def video_project(
    ctx: click.Context,
    to: str | None,
    look_at: tuple[float, float] | None,
    roll: float,
    output_: Any,
    overwrite_: bool,
    size_: Any,
) -> None:
    """Reproject every frame into another grid, as `spherewarp project --to NAME` does
    (bicubic): little-planet, rectilinear, fisheye, cubemap, ... (--size: the view's size)."""
    _size_after(ctx, size_)
    from ..maps import Mobius

    o = ctx.obj
    if to is None:
        raise click.UsageError("give the grid to project into with --to NAME")
    if o.get("projection") is not None:
        raise click.UsageError("project takes --to, not --projection")
    if look_at is not None and o.get("view_at") is not None:
        raise click.UsageError("give --look-at or --view-at, not both")
    o["projection"] = to.lower()
    o["view_at"] = look_at if look_at is not None else o.get("view_at")
    o["view_roll"] = roll + (o.get("view_roll") or 0.0)
    _run(ctx, Mobius.identity(), output_, overwrite_, build={"interp": "bicubic"})


video.add_command(video_project)


# -- splitscreen: several clips ------------------------------------------------------------------
@_copied(
    "branched_cmds:splitscreen",
    ("cover", "n", "lam", "branch_points", "seam", "feather", "look_at"),
)
@click.command(
    "splitscreen", short_help="several clips on the sheets of a branched cover (INPUT1 INPUT2 ...)"
)
@_outputs
@click.pass_context
def video_splitscreen(
    ctx: click.Context,
    cover: str,
    n: int | None,
    lam: float,
    branch_points: Any,
    seam: str | float,
    feather: float,
    look_at: tuple[float, float] | None,
    output_: Any,
    overwrite_: bool,
    size_: Any,
) -> None:
    """Combine clips filmed from one spot, frame by frame, on the sheets of a branched cover,
    as `spherewarp splitscreen` combines stills: `spherewarp video a.mp4 b.mp4 -o out.mp4
    splitscreen`. The clips are decoded in lock-step and need one frame rate; the shortest
    ends the output (a note says so). The first clip's frame times and audio are kept. An
    --seam auto is chosen on the first frames and kept for the whole video. It renders in
    segments as every video does (--segment, --resume, --jobs, --dask), cut at the first
    clip's frame times."""
    _size_after(ctx, size_)
    from ..io.multiclip import render_clips
    from ..io.sequence import is_frames
    from ..io.spherical import Spherical
    from ..io.stereo import is_panorama, resolve_grid
    from ..io.video import VIDEO_EXTENSIONS
    from ._files import job
    from ._video_out import segment_progress
    from .branched_cmds import EXP_SUPERSAMPLE, _look_at

    o = ctx.obj
    if output_ is not None:
        o["output"] = output_
    o["overwrite"] = o["overwrite"] or overwrite_
    inputs = list(o["inputs"])
    cover = cover.lower()
    if len(inputs) < 2:
        raise click.UsageError("splitscreen combines several clips: video A.mp4 B.mp4 -o OUT ...")
    if o["output"] is None:
        raise click.UsageError("give the video to write with -o OUT.mp4")
    if n is not None and cover != "power":
        raise click.UsageError("--n applies to --cover power only")
    if n is not None and n % len(inputs):
        raise click.BadParameter(
            f"expected a multiple of the number of inputs ({len(inputs)}), got {n}",
            param_hint="'--n'",
        )
    for name in ("fps",):
        if o.get(name) is not None:
            raise click.BadParameter("applies to an image sequence input", param_hint="--fps")
    if (o.get("stereo") or "mono").lower() != "mono":
        raise click.BadParameter("splitscreen takes mono clips", param_hint="--stereo")
    if any(is_frames(p) for p in [*inputs, o["output"]]):
        from ..errors import ImageFormatError

        raise ImageFormatError("splitscreen reads and writes videos, not image sequences")
    if o["output"].suffix.lower() not in VIDEO_EXTENSIONS:
        from ..errors import ImageFormatError

        raise ImageFormatError(
            f"cannot write '{o['output']}': unknown video extension "
            f"{o['output'].suffix or '(none)'!r}; use one of {', '.join(VIDEO_EXTENSIONS)} with -o"
        )
    for k, path in enumerate(inputs):
        job().reads(path, f"input {k + 1}")
    job().writes(o["output"], "-o")
    options: dict[str, Any] = {
        "cover": cover, "n": n, "lam": lam, "branch_points": branch_points or None,
        "force": o["force"],
    }  # fmt: skip
    grid_of, out_shape = _grid(o, None)
    combine = _Combine(
        options, seam, feather, _look_at(look_at), out_shape, grid_of,
        EXP_SUPERSAMPLE if cover == "exp" else 1, o["quiet"],
    )  # fmt: skip
    if grid_of is None:
        panorama = True
    else:
        from ..io.video import probe

        first = probe(inputs[0])
        panorama = is_panorama(resolve_grid(grid_of, (first.height, first.width)))
    bar = segment_progress(o["quiet"], o["progress"])
    try:
        n_done = render_clips(
            inputs, o["output"], combine, codec=o["codec"], crf=o["crf"], preset=o["preset"],
            pix_fmt=o["pix_fmt"], overwrite=o["overwrite"], force=o["force"],
            spherical=Spherical() if panorama else None, progress=bar,
            note=_note,  # the clips' lengths differ: the output is cut short, even with -q
            identity=_identity(ctx, {k: v for k, v in o.items() if k != "inputs"}),
            resume=o["resume"], jobs=o["jobs"], dask=o["dask"], segment_seconds=o["segment"],
        )  # fmt: skip
    finally:
        bar.close()
    click.echo(f"wrote {o['output']} ({n_done} frames)")


def _note(text: str) -> None:
    click.echo(f"spherewarp: note: {text}", err=True)


class _Combine:
    """``combine(frames)`` of ``video ... splitscreen``: the clips' frames on the sheets
    (picklable: segments render elsewhere). An automatic seam is chosen on the first frames
    it is given (in the client, before any segment) and kept."""

    def __init__(
        self,
        options: dict[str, Any],
        seam: str | float,
        feather: float,
        view: Any,
        out_shape: Any,
        grid_of: Any,
        supersample: int,
        quiet: bool,
    ) -> None:
        self.options, self.seam, self.feather, self.view = options, seam, feather, view
        self.out_shape, self.grid_of, self.supersample = out_shape, grid_of, supersample
        self.quiet = quiet

    def __call__(self, frames: list[Any]) -> Any:
        import spherewarp.effects.splitscreen as ss
        from spherewarp.io.stereo import resolve_grid

        if self.seam == "auto":
            self.seam = ss.auto_seam(frames, feather_deg=self.feather, **self.options)
            if not self.quiet:
                click.echo(f"seam: input meridian at longitude {self.seam:.1f} (auto)")
        eye = frames[0].shape[:2]
        return ss.splitscreen(
            frames,
            seam=float(self.seam),
            feather_deg=self.feather,
            view=self.view,
            output_shape=self.out_shape,
            grid=resolve_grid(self.grid_of, eye) if self.grid_of is not None else None,
            supersample=self.supersample,
            **self.options,
        )


video.add_command(video_splitscreen)
