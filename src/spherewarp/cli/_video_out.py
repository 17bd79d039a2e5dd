"""``spherewarp animate R.json STILL -o OUT.mp4``: the frames of a recipe encoded as a video.

The encoder options are ``spherewarp video``'s (``--codec``, ``--crf``,
``--preset``, ``--pix-fmt``; :func:`spherewarp.io.videowriter.video_writer`);
an equirectangular output carries the spherical metadata (V1 and V2, or
Matroska's), another view none.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass
from fractions import Fraction
from pathlib import Path
from typing import Any

import click

from ._common import RealType

__all__ = [
    "encoding_options",
    "is_video_output",
    "register_paths",
    "animate_video",
    "segment_options",
    "segment_progress",
    "refuse_segment_options",
    "FramesJob",
    "PathOrURL",
    "render_frames",
]


def encoding_options(func: Callable) -> Callable:
    """``--codec``, ``--crf``, ``--preset``, ``--pix-fmt`` (for a video output)."""
    options = [
        click.option(
            "--codec",
            help="With a video -o: the video encoder (default libx264; libvpx-vp9 for .webm): "
            "libx264, libx265, libvpx-vp9, libsvtav1, or another this build offers.",
        ),
        click.option(
            "--crf",
            type=click.FloatRange(0, 63),
            help="With a video -o: constant rate factor, lower is better and bigger "
            "(default: 18 for x264, 20 for x265, 31 for VP9).",
        ),
        click.option(
            "--preset", help="With a video -o: the encoder's speed preset (ultrafast ... veryslow)."
        ),
        click.option(
            "--pix-fmt",
            help="With a video -o: the encoded pixel format (default: yuv420p; 10-bit "
            "yuv420p10le for a 16-bit or HDR still when the encoder takes it).",
        ),
    ]
    for option in reversed(options):
        func = option(func)
    return func


def is_video_output(output: Path | str | None) -> bool:
    """Whether ``-o`` (a path or an fsspec URL) names a video file (by its extension)."""
    from ..io.segments import local_name
    from ..io.video import VIDEO_EXTENSIONS

    return output is not None and local_name(output).suffix.lower() in VIDEO_EXTENSIONS


def register_paths(inputs: list[tuple[Any, str]], output: Any = None) -> None:
    """Register the local ``inputs`` (``(path, label)``) as read and a local ``output`` (if
    any) as written, so that no input is overwritten (:mod:`spherewarp.cli._files`); URLs are
    read and written through fsspec, and an output URL that names an input is refused."""
    from ..io.remote import is_url
    from ._files import job

    for path, label in inputs:
        if not is_url(path):
            job().reads(path, label)
    if output is None:
        return
    if not is_url(output):
        job().writes(output, "-o")
    elif any(output == path for path, _ in inputs):
        raise click.BadParameter("names the input; an input is never overwritten", param_hint="-o")


class PathOrURL(click.Path):
    """A file's path (a ``Path``), or an fsspec URL kept as it is (``ftp://host/in.mp4``: a
    ``str``; see :mod:`spherewarp.io.remote`).

    Examples
    --------
    >>> kind = PathOrURL()
    >>> kind.convert("ftp://host/in.mp4", None, None), kind.convert("a.mp4", None, None)
    ('ftp://host/in.mp4', PosixPath('a.mp4'))
    """

    def __init__(self) -> None:
        super().__init__(path_type=Path, dir_okay=False)

    def convert(self, value: Any, param: Any, ctx: Any) -> Any:
        from ..io.remote import is_url

        if is_url(value):
            return value
        return super().convert(value, param, ctx)


#: ``--segment S``: a finite number of seconds above 0 (click's FloatRange lets nan and inf
#: through, which then broke the segment plan's ``round(S * rate)``)
SEGMENT_SECONDS = RealType("a segment length in seconds", "10", metavar="S", gt=0)


def segment_options(func: Callable) -> Callable:
    """``--progress``, ``--segment``, ``--resume``, ``--jobs`` and ``--dask``: a video output
    rendered in segments (:func:`spherewarp.io.segments.run_segments`), as ``video`` and
    ``animate`` share them."""
    options = [
        click.option(
            "--progress",
            type=click.Choice(["bar", "json", "none"], case_sensitive=False),
            default="bar",
            show_default=True,
            help="bar: a progress bar on a terminal; json: one JSON object a line on stderr "
            "(frames, total, fps, eta), for scripts; none.",
        ),
        click.option(
            "--segment",
            type=SEGMENT_SECONDS,
            default=None,
            metavar="S",
            help="Seconds of video in each segment (default 10): a video is rendered in "
            "segments, each starting on a keyframe, in OUT.parts/ beside the output, then "
            "joined.",
        ),
        click.option(
            "--resume",
            is_flag=True,
            help="Continue an interrupted render from the finished segments in OUT.parts/.",
        ),
        click.option(
            "-j",
            "--jobs",
            type=click.IntRange(min=1),
            default=1,
            show_default=True,
            help="Segments rendered at once by local processes (each with its share of the cores).",
        ),
        click.option(
            "--dask",
            metavar="ADDRESS",
            help="Render the segments on the workers of this Dask scheduler (tcp://host:8786); "
            "the inputs and the output's folder must be at the same path (or URL) on every "
            "worker.",
        ),
    ]
    for option in reversed(options):
        func = option(func)
    return func


#: the options of :func:`segment_options`, with the values that mean "not given"
SEGMENT_DEFAULTS = {"resume": False, "jobs": 1, "dask": None, "segment": None}


def refuse_segment_options(options: dict[str, Any], why: str) -> None:
    """Refuse ``--resume``, ``--jobs``, ``--dask`` or ``--segment`` where no video is written
    in segments (``why`` says what is written instead).

    Examples
    --------
    >>> refuse_segment_options({"jobs": 1, "resume": False}, "images")  # the defaults: fine
    >>> refuse_segment_options({"jobs": 2}, "images")
    Traceback (most recent call last):
    ...
    click.exceptions.BadParameter: applies to a video output (images)
    """
    for name, default in SEGMENT_DEFAULTS.items():
        if options.get(name, default) != default:
            raise click.BadParameter(f"applies to a video output ({why})", param_hint=f"--{name}")


def segment_progress(quiet: bool, mode: str) -> Any:
    """The ``progress(done, total)`` callback of ``--progress MODE`` (none with ``--quiet``)."""
    import sys

    mode = "none" if quiet else mode.lower()
    if mode == "json":
        from ._progress import JsonProgress

        return JsonProgress()
    from ._progress import FrameBar

    return FrameBar(enabled=mode == "bar" and sys.stderr.isatty())


@dataclass
class FramesJob:
    """One segment of ``animate ... -o OUT.mp4``: frames ``first ...`` of a timed recipe on a
    still, encoded into ``part`` (picklable: sent to a process pool or a Dask worker)."""

    index: int
    part: str
    first: int
    times: list[float]
    inputs: list[str]
    recipe: Any
    render: Any
    size: tuple[int, int]
    rate: Fraction
    encoding: dict[str, Any]
    in_pix: str
    threads: int | None = None

    @property
    def frames(self) -> int:
        return len(self.times)


def render_frames(
    job: FramesJob, progress: Callable[[int], None] | None = None
) -> tuple[int, int, int]:
    """Render one :class:`FramesJob` to ``job.part`` atomically; return ``(index, frames,
    bytes)`` (a :func:`spherewarp.io.segments.run_segments` ``render``).

    Frame ``job.first + k`` shows the recipe at ``job.times[k]``, at presentation time
    ``(job.first + k) / job.rate``; ``progress(k + 1)`` after each.
    """
    from ..io.segments import release_memory

    try:
        return _render_frames(job, progress)
    finally:
        release_memory()  # what the segment's encoder and frames freed


def _render_frames(
    job: FramesJob, progress: Callable[[int], None] | None = None
) -> tuple[int, int, int]:
    from ..io.remote import is_url
    from ..io.segments import _dask_threads, _set_threads, writing_part
    from ..io.videowriter import video_writer
    from ._files import new_job
    from .recipe_cmds import _load_all

    _set_threads(job.threads if job.threads is not None else _dask_threads())
    new_job()
    srcs = _load_all(tuple(p if is_url(p) else Path(p) for p in job.inputs), job.render)
    tb = 1 / job.rate
    with writing_part(job.part) as tmp:
        with video_writer(
            tmp, job.size, job.rate, in_pix=job.in_pix, overwrite=True, spherical=None,
            **job.encoding,
        ) as writer:  # fmt: skip
            for k, t in enumerate(job.times):
                pixels = animate_frame(srcs, job.recipe.at(t), job.render)
                writer.write(pixels, pts=job.first + k, time_base=tb)
                if progress is not None:
                    progress(k + 1)
        size = os.path.getsize(tmp)
    return job.index, len(job.times), size


def animate_frame(srcs: Any, frame: Any, render: Any) -> Any:
    """The pixels of one frame of ``animate ... -o OUT.mp4`` (HDR tone-mapped as for a 16-bit
    PNG)."""
    from ._common import convert_for_output
    from .recipe_cmds import _render_frame

    out, _ = _render_frame(srcs, frame, render, "animate")
    if out.dtype.kind == "f":
        out = convert_for_output(out, Path("frame.png"), render)
    return out


def animate_video(
    inputs: tuple[Path, ...],
    srcs: Any,
    render: Any,
    recipe: Any,
    times: list[float],
    fps: float,
    encoding: dict[str, Any],
    segments: dict[str, Any],
) -> int:
    """Render ``recipe`` at ``times`` on the stills ``inputs`` (read: ``srcs``) and encode the
    frames into ``render.output`` at ``fps`` (``encoding``: codec, crf, preset, pix_fmt), in
    segments (``segments``: :func:`segment_options`' values, and ``quiet``); return the
    frames written."""
    import hashlib
    import json
    from dataclasses import asdict, replace

    import numpy as np

    from ..io.remote import is_url
    from ..io.segments import Segmented, join, local_name, run_segments, segment_frames
    from ..io.segments import _input_identity as identity_of
    from ..io.spherical import write_spherical
    from ..io.video import muxer
    from ..io.videowriter import EQUIRECT, check_writer, frame_rate

    output = render.output if is_url(render.output) else Path(render.output)
    named = local_name(output)  # its extension picks the container (a URL's too)
    rate = frame_rate(fps)
    first = animate_frame(srcs, recipe.at(times[0]), render)  # the frame's size and depth
    in_pix = "yuv420p" if first.dtype == np.uint8 else "yuv420p10le"
    size = first.shape[:2]
    enc, out_pix, _, _ = check_writer(named, size, rate, in_pix=in_pix, **encoding)
    encoding = {**encoding, "codec": enc.name, "pix_fmt": out_pix}  # parts are MP4 files
    quiet = replace(render, quiet=True)  # workers draw no bars
    step = segment_frames(segments["segment"], float(rate))
    ranges = [(a, min(a + step, len(times))) for a in range(0, len(times), step)]
    paths = [p if is_url(p) else os.path.abspath(p) for p in inputs]  # as workers reach them

    def job(i: int, part: str) -> FramesJob:
        a, b = ranges[i]
        return FramesJob(
            index=i, part=part, first=a, times=times[a:b], inputs=paths, recipe=recipe,
            render=quiet, size=size, rate=rate, encoding=encoding, in_pix=in_pix,
        )  # fmt: skip

    panorama = render.projection in (None, "equirect")

    def join_parts(parts: list[Path], tmp: Path) -> None:
        join(parts, None, tmp, muxer(named), times=list(range(len(times))), time_base=1 / rate)
        write_spherical(tmp, EQUIRECT if panorama else None)

    pixels = {k: v for k, v in asdict(quiet).items() if k not in ("output", "overwrite")}
    identity = json.dumps(
        {"recipe": hashlib.sha256(recipe.dumps().encode()).hexdigest(), "times": times,
         "fps": str(rate), "render": pixels, "encoding": encoding, "in_pix": in_pix},
        sort_keys=True, default=str,
    )  # fmt: skip
    plan = Segmented(
        output=output, source=[identity_of(p) for p in paths],
        name=", ".join(str(p) for p in inputs), identity=identity,
        segments=[{"index": i, "start": a, "end": b} for i, (a, b) in enumerate(ranges)],
        job=job, render=render_frames, join=join_parts, reads=paths,
    )  # fmt: skip
    bar = segment_progress(render.quiet, segments["progress"])
    try:
        run_segments(plan, resume=segments["resume"], jobs=segments["jobs"],
                     dask=segments["dask"], overwrite=render.overwrite, progress=bar)  # fmt: skip
    finally:
        bar.close()
    click.echo(f"wrote {output} ({len(times)} frames at {fps:g} fps)")
    return len(times)
