"""``spherewarp render``: replay a recipe; ``--save-recipe``: write one.

Every effect command that takes ``--save-recipe R.json`` builds the recipe step
of what it does (its own options, by name) and hands it to
:func:`saving_recipe`; ``spherewarp render R.json IN -o OUT`` builds the same map
from the step (:mod:`spherewarp.recipe.effects`) and renders it with the same
options, so the pixels are the command's own.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import click

from ._common import RealType, RenderOptions, check_size_limit, example, render_options
from ._video_out import (
    PathOrURL,
    encoding_options,
    is_video_output,
    refuse_segment_options,
    segment_options,
)

__all__ = [
    "render",
    "animate",
    "recipe_options",
    "print_options",
    "saving_recipe",
    "recipe_of",
    "capturing_recipe",
    "print_recipe",
    "printed",
    "render_recipe",
]

TIME = RealType("a time in seconds", "1.5", metavar="T")

#: recipe files this process wrote (path -> data): a batch writes one recipe, naming its inputs
_WRITTEN: dict[str, dict[str, Any]] = {}
#: while :func:`capturing_recipe` runs: the recipes the effect commands would save
_CAPTURED: list[dict[str, Any]] | None = None


@contextlib.contextmanager
def capturing_recipe() -> Iterator[list[dict[str, Any]]]:
    """Collect the recipe an effect command builds instead of rendering or saving it.

    Inside the block, :func:`saving_recipe` appends the recipe data of its step to the
    list yielded and tells the command to render nothing (as ``--dry-run``); so
    ``spherewarp video ... droste`` builds the very step ``spherewarp droste`` would.
    """
    global _CAPTURED
    saved, _CAPTURED = _CAPTURED, []
    try:
        yield _CAPTURED
    finally:
        _CAPTURED = saved


def _print_or_save(ctx: click.Context, param: click.Parameter, value: Any) -> Any:
    """Refuse ``--print`` (or ``--print-map``) with ``--save-recipe``: printing writes nothing.

    Each of the three options calls this as it is parsed, so the one parsed last sees the
    other in ``ctx.params``, whatever the order on the command line.
    """
    given = {n for n in ("print_recipe", "print_map", "save_recipe") if ctx.params.get(n)}
    if value and param.name is not None:
        given.add(param.name)
    if "save_recipe" in given and given & {"print_recipe", "print_map"}:
        flag = "--print" if "print_recipe" in given else "--print-map"
        raise click.UsageError(
            f"{flag} prints instead of rendering and writes no file; leave out --save-recipe, "
            "or write the recipe without rendering with --save-recipe R.json --dry-run"
        )
    return value


def recipe_options(func: Callable) -> Callable:
    """The ``--save-recipe R.json`` and ``--dry-run`` options of an effect command."""
    func = click.option(
        "--dry-run",
        is_flag=True,
        help="With --save-recipe: write the recipe and render nothing (INPUT is still read "
        "where the recipe needs it, as for --at-pixel).",
    )(func)
    return click.option(
        "--save-recipe",
        type=click.Path(dir_okay=False, path_type=Path),
        metavar="R.json",
        callback=_print_or_save,
        help="Also write the recipe of this render as JSON; 'spherewarp render R.json IN' "
        "replays it on any panorama.",
    )(func)


def command_recipe(data: dict[str, Any], base: Path | None = None) -> Any:
    """The :class:`~spherewarp.recipe.Recipe` of a command's own options; its errors name
    the options (``steps[0].droste.inner_radius: ...`` reads ``--inner-radius: ...``)."""
    import re

    from ..errors import InvalidValueError
    from ..recipe import Recipe, RecipeError

    try:
        return Recipe.from_dict(data, base=base)
    except RecipeError as exc:
        if exc.path == "view" or exc.path.startswith("view."):  # the command's view options
            raise InvalidValueError(exc.cli_detail) from None
        m = re.match(r"steps\[0\]\.[a-z]+(?:\.([a-z_]+))?(.*)$", exc.path)
        if m is None:
            raise
        where = "" if m.group(1) is None else "--" + m.group(1).replace("_", "-") + m.group(2)
        detail = exc.cli_detail  # the message naming CLI options, where it has one
        raise InvalidValueError(f"{where}: {detail}" if where else detail) from None


def load_recipe(path: Path | str) -> Any:
    """:meth:`Recipe.load <spherewarp.recipe.Recipe.load>`, its errors naming the file
    (``recipe 'R.json': not JSON: ...``)."""
    from ..errors import InvalidValueError
    from ..recipe import Recipe, RecipeError

    try:
        return Recipe.load(path)
    except RecipeError as exc:
        raise InvalidValueError(f"recipe {str(path)!r}: {exc.cli_message}") from None


def print_options(func: Callable) -> Callable:
    """``--print`` (the recipe as JSON, render nothing) and ``--print-map`` (the map)."""
    func = click.option(
        "--print-map",
        "print_map",
        is_flag=True,
        callback=_print_or_save,
        help="Print the map as JSON (spherewarp.maps.map_from_json reads it) instead of rendering.",
    )(func)
    return click.option(
        "--print",
        "print_recipe",
        is_flag=True,
        callback=_print_or_save,
        help="Print the recipe of this render as JSON ('spherewarp render' replays it) "
        "instead of rendering.",
    )(func)


def _json_value(value: Any, base: Path | None) -> Any:
    """A step value as JSON: file names relative to ``base`` (the recipe's directory)."""
    if isinstance(value, Path):
        p = value.resolve()
        if base is None:
            return str(p)
        try:  # inside the recipe's directory: relative, so the two move together
            return p.relative_to(base.resolve()).as_posix()
        except ValueError:
            return str(p)
    if isinstance(value, (list, tuple)):
        return [_json_value(v, base) for v in value]
    if isinstance(value, dict):
        return {k: _json_value(v, base) for k, v in value.items() if v is not None}
    return value


def recipe_of(
    step: dict[str, Any],
    render: RenderOptions,
    input: Path | list[Path] | None = None,
    top: dict[str, Any] | None = None,
    base: Path | None = None,
) -> dict[str, Any]:
    """The recipe data of one step rendered with ``render``'s options (``top``: more
    top-level fields, such as ``duration`` and ``loop``; ``input``: the input, or the
    inputs of a split screen; ``base``: the directory file names are written relative to).
    """
    options: dict[str, Any] = {
        "interp": render.interp,
        "supersample": render.supersample,
        "antialias": render.antialias,
    }
    if render.background is not None:
        options["background"] = render.background
    if render.tonemap != "aces":  # how HDR is written (the default is left out)
        options["tonemap"] = render.tonemap
    if render.exposure:
        options["exposure"] = render.exposure
    data: dict[str, Any] = {"spherewarp": 1}
    if isinstance(input, (list, tuple)):
        data["inputs"] = [i.name for i in input]
    elif input is not None:
        data["inputs"] = [input.name]
    data.update(top or {})
    data["steps"] = [{k: _json_value(p, base)} for k, p in step.items()]
    view: dict[str, Any] = {}
    if render.size is not None:
        view["size"] = list(render.size)
    if render.projection is not None:
        view["projection"] = render.projection
    if render.view_at is not None:
        view["look_at"] = list(render.view_at)
    if render.view_roll:
        view["roll"] = render.view_roll
    if render.fov is not None:
        view["fov"] = render.fov
    if view:
        data["view"] = view
    data["options"] = options
    return data


@contextlib.contextmanager
def saving_recipe(
    step: dict[str, Any],
    render: RenderOptions,
    input: Path | list[Path] | None,
    path: Path | None,
    dry_run: bool,
    top: dict[str, Any] | None = None,
) -> Iterator[bool]:
    """Check, then write the recipe of ``step`` to ``path`` (if given) once the render in the
    ``with`` block has succeeded; the block gets True for ``--dry-run`` (render nothing).

    The recipe is validated first, so a written recipe always reads back. An
    existing file is refused before any work without ``--overwrite``; a batch
    writes it once.
    """
    if _CAPTURED is not None:  # capturing_recipe: hand the step over, render nothing
        _CAPTURED.append(recipe_of(step, render, input, top))
        yield True
        return
    if path is None:
        if dry_run:
            raise click.UsageError("--dry-run goes with --save-recipe R.json")
        yield False
        return
    from ..errors import InvalidValueError, OutputExistsError
    from ..io.atomic import write_text
    from ._files import job

    key = str(path.resolve())
    earlier = _WRITTEN.get(key)
    p = path
    if earlier is None:  # (a later input of a batch adds itself to the recipe written)
        p = job().writes(path, "--save-recipe")  # never an input, nor another output
    if path.suffix.lower() != ".json":
        raise click.BadParameter(
            f"expected a file name ending in .json, got {str(path)!r}",
            param_hint="'--save-recipe'",
        )
    data = recipe_of(step, render, input, top, base=p.resolve().parent)
    if earlier is not None:  # an earlier input of this batch wrote it: add this input
        if {**earlier, "inputs": None} != {**data, "inputs": None}:
            raise InvalidValueError(
                f"--save-recipe {str(p)!r}: this input gives another recipe than the "
                "earlier inputs of the batch (e.g. --at-pixel on another size); save one "
                "input's recipe at a time"
            )
        data["inputs"] = earlier.get("inputs", []) + data.get("inputs", [])
    text = command_recipe(data, base=p.resolve().parent).dumps()
    if p.exists() and not render.overwrite and earlier is None:
        raise OutputExistsError(f"{str(p)!r} exists; pass --overwrite to replace it")
    from ..io.atomic import check_writable

    check_writable(p)  # refused now, not after the render (a missing folder, no permission)
    yield dry_run
    if earlier != data:
        write_text(p, text, overwrite=True)
        _WRITTEN[key] = data
        click.echo(f"wrote {p}")


def _chosen(ctx: click.Context, name: str) -> bool:
    """Whether the option ``name`` was given on the command line (not its default)."""
    source = ctx.get_parameter_source(name)
    return source not in (None, click.core.ParameterSource.DEFAULT)


def _with_recipe_options(ctx: click.Context, render: RenderOptions, frame: Any) -> Any:
    """``render`` with the recipe's interp, supersample, antialias, size, background,
    tonemap and exposure, except those given on the command line."""
    from dataclasses import replace

    kwargs = dict(frame.warp_kwargs)
    changes: dict[str, Any] = {}
    for name in ("interp", "supersample", "antialias"):
        if not _chosen(ctx, name):
            changes[name] = kwargs[name]
    if not _chosen(ctx, "size") and "output_shape" in kwargs:
        h, w = kwargs["output_shape"]
        changes["size"] = (w, h)
        check_size_limit((w, h), render.max_pixels, hint="the recipe's view.size")
    for name in ("background", "tonemap", "exposure"):
        if not _chosen(ctx, name) and getattr(frame, name) is not None:
            changes[name] = getattr(frame, name)
    if not any(_chosen(ctx, n) for n in ("projection", "view_at", "view_roll", "fov")):
        view = frame.view  # the recipe's output grid, unless the command line names one
        changes["projection"] = view.get("projection")
        changes["view_at"] = None if view.get("look_at") is None else tuple(view["look_at"])
        changes["view_roll"] = float(view.get("roll") or 0.0)
        changes["fov"] = view.get("fov")
    return replace(render, **changes)


def print_recipe(
    step: dict[str, Any],
    render: RenderOptions,
    input: Path | list[Path] | None,
    top: dict[str, Any] | None = None,
) -> None:
    """``--print``: the recipe of ``step`` on stdout (validated; file names absolute)."""
    click.echo(command_recipe(recipe_of(step, render, input, top)).dumps(), nl=False)


def printed(
    step: dict[str, Any],
    the_map: Any,
    render: RenderOptions,
    input: Path | list[Path] | None,
    recipe: bool,
    map: bool,
) -> bool:
    """``--print-map`` (``the_map`` as JSON) or ``--print`` (the recipe of ``step``) on
    stdout, as asked; True if it printed (the command then renders nothing)."""
    if map:
        click.echo(the_map.to_json())
    elif recipe:
        print_recipe(step, render, input)
    return map or recipe


def render_recipe(
    step: dict[str, Any],
    render: RenderOptions,
    srcs: Any,
    command: str,
    top: dict[str, Any] | None = None,
    t: float = 0.0,
) -> tuple[Any, Any, Any]:
    """Render ``step`` (one recipe step, as the command names it) through :class:`Recipe`,
    as ``spherewarp render`` replays it: ``(pixels, gpano, frame)``."""
    frame = command_recipe(recipe_of(step, render, None, top)).at(t)
    out, gpano = _render_frame(srcs, frame, render, command)
    return out, gpano, frame


def _render_frame(srcs: Any, frame: Any, render: RenderOptions, command: str) -> tuple[Any, Any]:
    """The pixels of one frame (from one input, or a list) and the GPano to write with them."""
    from .mobius_cmds import _output_gpano

    srcs = list(srcs) if isinstance(srcs, (list, tuple)) else [srcs]
    pixels = [s.pixels for s in srcs]
    if frame.flat:
        render.refuse_view(command)
    kwargs = {**render.warp_kwargs(pixels[0]), "max_pixels": render.max_pixels}
    out = frame.render_pixels(pixels, kwargs)
    gpano: Any = True  # after a branched map no pose holds, as with those commands
    if frame.flat:
        gpano = False
    elif frame.pose is not None:
        gpano = _output_gpano(srcs[0], out.shape, frame.pose, command, render.quiet)
    return out, gpano


def _groups(recipe: Any, name: Path, inputs: tuple[Path, ...]) -> list[tuple[Path, ...]] | None:
    """The inputs as one group of a several-input recipe, or None (one render an input)."""
    n = recipe.n_inputs
    if n == 1:
        return None
    if len(inputs) != n:
        from ..errors import InvalidValueError

        raise InvalidValueError(
            f"{name}: the recipe renders from {n} inputs ({recipe.steps[0].effect}), got "
            f"{len(inputs)} (give INPUT1 ... INPUT{n})"
        )
    return [inputs]


def _load_all(inputs: tuple[Path, ...], render: RenderOptions) -> list[Any]:
    from ._common import load_input

    return [load_input(p, render, f"input {k + 1}") for k, p in enumerate(inputs)]


def _inputs_argument(func: Callable, kind: click.ParamType | None = None) -> Callable:
    return click.argument(
        "inputs",
        nargs=-1,
        required=True,
        type=kind or click.Path(dir_okay=False, path_type=Path),
        metavar="INPUT...",
    )(func)


def _inputs_or_urls(func: Callable) -> Callable:
    """INPUT... as paths or fsspec URLs (:class:`~spherewarp.cli._video_out.PathOrURL`)."""
    return _inputs_argument(func, PathOrURL())


@click.command(
    epilog=example(
        "spherewarp zoom room.jpg --at -163,5 --factor 3 --save-recipe zoom.json -o a.jpg",
        "spherewarp render zoom.json other-room.jpg -o b.jpg",
        "spherewarp render flight.json room.jpg --time 1.5 -o frame.png",
    )
)
@click.argument("recipe", type=click.Path(dir_okay=False, path_type=Path), metavar="R.json")
@_inputs_or_urls
@click.option(
    "--time",
    "time",
    type=TIME,
    default=0.0,
    show_default=True,
    help="The time in seconds at which to evaluate the recipe's tracks.",
)
@click.option(
    "--dask",
    metavar="ADDRESS",
    help="Render the INPUTs on the workers of this Dask scheduler (tcp://host:8786), which "
    "read them (and R.json) by the same path or URL; the files are written here.",
)
@render_options
def render(
    inputs: tuple[Path | str, ...],
    render: RenderOptions,
    recipe: Path,
    time: float,
    dask: str | None,
) -> None:
    """Render a recipe (R.json, as --save-recipe writes it) on INPUT.

    The recipe's options (--interp, --supersample, --antialias, --size,
    --background, --tonemap, --exposure) apply unless given here. A recipe made
    from several inputs (a split screen, Droste's --inside images) takes them all,
    in order, as one render; otherwise each INPUT is rendered in turn. With --dask
    the images are warped on a Dask cluster's workers, all at once, and written
    here as without it.
    INPUT may be an fsspec URL (ftp://host/room.jpg), read as `spherewarp
    animate` reads its still (by each worker with --dask); the output is a local
    file, named from the URL's file name (room-render.jpg).
    """
    from ..io.remote import is_url
    from ._common import run_inputs
    from ._files import Job, job, new_job

    if is_url(click.get_current_context().params.get("output")):
        raise click.BadParameter(
            "render writes local files only; give a local -o (OUT.jpg or DIR/)", param_hint="-o"
        )
    job().reads(recipe, "recipe")
    r = load_recipe(recipe)
    _reads_files(r)
    frame = r.at(time)
    render = _with_recipe_options(click.get_current_context(), render, frame)
    groups = _groups(r, recipe, inputs)
    if groups is None:
        kwargs = {"render": render, "recipe": recipe, "r": r, "frame": frame, "time": time,
                  "dask": dask}  # fmt: skip
        run_inputs(_render_one, inputs, kwargs)
        return
    if dask is not None:
        raise click.UsageError("--dask renders recipes of one input each, not this one's group")
    new_job(Job(reads=((recipe, "recipe"),)))
    _render_one(groups[0], render, recipe, r, frame, time, None)


def _reads_files(r: Any) -> None:
    """Register the files the recipe's steps read (a ``mask``) as inputs of this job."""
    from ._files import job

    for name, path in r.files:
        job().reads(path, f"recipe's {name}")


def _render_one(
    input: Any,
    render: RenderOptions,
    recipe: Path,
    r: Any,
    frame: Any,
    time: float,
    dask: str | None,
) -> None:
    from ._common import output_path, save_output
    from ._files import job
    from ._video_out import register_paths
    from .mobius_cmds import check_output_suffix

    group = tuple(input) if isinstance(input, tuple) else (input,)
    job().reads(recipe, "recipe")
    _reads_files(r)
    register_paths([(p, f"input {k + 1}" if len(group) > 1 else "input")
                    for k, p in enumerate(group)])  # fmt: skip
    # refuse a bad output early (a URL's file name names it, as a local file's does)
    check_output_suffix(output_path(render, Path(group[0]), "render"))
    srcs = _load_all(group, render)
    if dask is None:
        out, gpano = _render_frame(srcs, frame, render, "render")
    else:
        ctx = click.get_current_context()
        out, gpano = _dask_batch(ctx, dask, recipe, render, time).result(group[0])
    save_output(out, srcs[0], render, command="render", gpano=gpano)


class _DaskBatch:
    """The INPUTs of one ``render --dask`` run, all sent to the workers at the first one
    (each then waits for its own result, so the batch renders in parallel)."""

    def __init__(self, address: str, recipe: Path, inputs: list[Path | str], render: RenderOptions,
                 time: float) -> None:  # fmt: skip
        import os

        from ..io.remote import is_url
        from ..io.segments import check_workers, dask_client

        self.client = dask_client(address)
        paths = [p if is_url(p) else os.path.abspath(p) for p in (recipe, *inputs)]
        check_workers(self.client, paths)
        self.futures = {
            p: self.client.submit(_remote_still, a, paths[0], render, time, pure=False)
            for p, a in zip(inputs, paths[1:], strict=True)
        }

    def result(self, input: Path | str) -> tuple[Any, Any]:
        return self.futures[input].result()


_BATCHES: dict[int, _DaskBatch] = {}


def _dask_batch(
    ctx: click.Context, address: str, recipe: Path, render: RenderOptions, time: float
) -> _DaskBatch:
    key = id(ctx)
    if key not in _BATCHES:
        ctx.call_on_close(lambda: _BATCHES.pop(key).client.close())
        inputs = list(dict.fromkeys(ctx.params["inputs"]))
        _BATCHES[key] = _DaskBatch(address, recipe, inputs, render, time)
    return _BATCHES[key]


def _remote_still(input: str, recipe: str, render: RenderOptions, time: float) -> tuple[Any, Any]:
    """On a Dask worker: the pixels of ``recipe`` at ``time`` on ``input`` (a path or a URL),
    and the GPano."""
    from ..io.remote import is_url
    from ..io.segments import _dask_threads, _set_threads
    from ._common import load_input
    from ._files import new_job

    _set_threads(_dask_threads())
    new_job()
    src = load_input(input if is_url(input) else Path(input), render)
    return _render_frame(src, load_recipe(recipe).at(time), render, "render")


FPS = RealType("frames per second", "24 or 29.97", metavar="F", gt=0, le=1000)
DURATION = RealType("a duration in seconds", "2.5", metavar="S", gt=0, le=86400)
#: the most frames one animate run writes
MAX_FRAMES = 100000


@click.command(
    epilog=example(
        "spherewarp animate spin.json room.jpg --fps 24 -o frames/",
        "spherewarp animate flight.json room.jpg --fps 30 --duration 4 -o frames/%04d.png",
        "spherewarp animate loop.json room.jpg --fps 24 -o loop.mp4 --crf 20",
    )
)
@click.argument("recipe", type=click.Path(dir_okay=False, path_type=Path), metavar="R.json")
@_inputs_or_urls
@click.option("--fps", type=FPS, required=True, help="Frames per second.")
@click.option(
    "--duration",
    type=DURATION,
    help="Seconds to render (default: the recipe's duration).",
)
@encoding_options
@segment_options
@render_options
def animate(
    inputs: tuple[Path, ...],
    render: RenderOptions,
    recipe: Path,
    fps: float,
    duration: float | None,
    progress: str,
    segment: float | None,
    resume: bool,
    jobs: int,
    dask: str | None,
    **encoding: Any,
) -> None:
    """Render the frames of a timed recipe (R.json) on INPUT, as numbered images.

    Frame k shows the recipe at time k / FPS, from 0 to the duration; a
    looping recipe ("loop": true) stops one frame short, so the frame after
    the last is the first. -o names the frames: OUT.png gives OUT_0000.png,
    OUT_0001.png, ...; a pattern such as frames/%04d.png, or a directory
    (-o frames/: frames/INPUT-animate_0000.png, ...). PNG, TIFF, EXR, JPEG or
    WebP, by the extension (default: INPUT's). -o OUT.mp4 (.mov, .m4v, .mkv,
    .webm) encodes the frames into one video instead, with the encoder
    options of `spherewarp video` (--codec, --crf, --preset, --pix-fmt); an
    equirectangular one carries the 360° metadata. A video is rendered in
    segments as `spherewarp video` renders one (--segment, --resume, --jobs,
    --dask, --progress). INPUT and a video -o may be fsspec URLs
    (ftp://host/room.jpg, -o ftp://host/out/loop.mp4), read and written as
    `spherewarp video` reads and writes them. The recipe's options apply
    unless given here.
    """
    from dataclasses import replace

    from ..io.remote import is_url
    from ._common import run_inputs
    from ._files import Job, job, new_job

    given = click.get_current_context().params.get("output")  # -o as typed (a URL stays one)
    if is_url(given):
        render = replace(render, output=given)
    job().reads(recipe, "recipe")
    r = load_recipe(recipe)
    _reads_files(r)
    groups = _groups(r, recipe, inputs)
    kwargs = {"render": render, "recipe": recipe, "r": r, "fps": fps, "duration": duration}
    kwargs["encoding"] = encoding
    kwargs["segments"] = {"progress": progress, "segment": segment, "resume": resume,
                          "jobs": jobs, "dask": dask}  # fmt: skip
    if groups is None:
        run_inputs(_animate_one, inputs, kwargs)
        return
    new_job(Job(reads=((recipe, "recipe"),)))
    _animate_one(groups[0], **kwargs)


def _animate_one(
    input: Any,
    render: RenderOptions,
    recipe: Path,
    r: Any,
    fps: float,
    duration: float | None,
    encoding: dict[str, Any],
    segments: dict[str, Any],
) -> None:
    from dataclasses import replace

    from ..errors import InvalidValueError
    from ..io.remote import is_url
    from ._common import output_name, output_path, save_output
    from ._files import job
    from ._video_out import register_paths
    from .droste_cmds import frame_paths
    from .mobius_cmds import check_output_suffix

    group = tuple(input) if isinstance(input, tuple) else (input,)
    input = Path(group[0])  # a URL's name names the frames
    job().reads(recipe, "recipe")
    _reads_files(r)
    inputs = [(p, f"input {k + 1}" if len(group) > 1 else "input") for k, p in enumerate(group)]
    if duration is None and r.duration is None:
        raise click.UsageError(f"{recipe} has no duration; give --duration S")
    seconds = r.duration if duration is None else duration
    if round(seconds * fps) > MAX_FRAMES:
        raise InvalidValueError(
            f"--fps {fps:g} for {seconds:g} s is {round(seconds * fps)} frames; "
            f"expected at most {MAX_FRAMES}"
        )
    times = r.frame_times(fps, seconds)
    ctx = click.get_current_context()
    render = _with_recipe_options(ctx, render, r.at(0.0))
    if is_video_output(render.output):
        register_paths(inputs, render.output)
        return _animate_video(group, render, r, times, fps, encoding, segments)
    register_paths(inputs)
    if is_url(render.output):
        raise click.BadParameter(
            "numbered images are written to local files only; give a local -o (frames/ or "
            "frames/%04d.png), or a video (-o ftp://host/out.mp4) to write to a URL",
            param_hint="-o",
        )
    refuse_segment_options(segments, "numbered images are written one by one")
    if any(v is not None for v in encoding.values()):
        given = next(k for k, v in encoding.items() if v is not None).replace("_", "-")
        raise click.BadParameter("goes with a video -o (OUT.mp4 ...)", param_hint=f"--{given}")
    pattern = output_name(render, input, "animate")
    paths = frame_paths(pattern, len(times))
    per_frame = [replace(render, output=p, output_dir=False) for p in paths]
    for one in per_frame:  # refuse inputs, existing files and bad names before any work
        check_output_suffix(output_path(one, input, "animate", given=str(pattern)))
    srcs = _load_all(group, render)
    for p in {p.parent for p in paths}:
        p.mkdir(parents=True, exist_ok=True)
    for t, one in zip(times, per_frame, strict=True):
        out, gpano = _render_frame(srcs, r.at(t), one, "animate")
        save_output(out, srcs[0], one, command="animate", gpano=gpano)


def _animate_video(
    group: tuple[Path, ...],
    render: RenderOptions,
    r: Any,
    times: list[float],
    fps: float,
    encoding: dict[str, Any],
    segments: dict[str, Any],
) -> None:
    """``animate ... -o OUT.mp4``: the frames encoded into one video, in segments."""
    from ..io.segments import refuse_existing
    from ._video_out import animate_video

    if render.output_dir:
        raise click.BadParameter("names a directory; give a video file", param_hint="-o")
    refuse_existing(render.output, render.overwrite)
    srcs = _load_all(group, render)
    animate_video(group, srcs, render, r, times, fps, encoding, segments)
