"""Several clips decoded in lock-step, combined frame by frame into one video.

:func:`render_clips` is the split-screen of two clips (the paper's apartment
video: ``spherewarp video a.mp4 b.mp4 -o out.mp4 splitscreen``): frame k of
every input goes to ``combine`` together; the output keeps the first input's
frame times and audio (packets copied as they are). It renders in segments as
every other video does (:func:`spherewarp.io.segments.run_segments`: GOP-aligned
segments in ``OUT.parts/``, cut at the first clip's frame times, ``resume``,
``jobs``, ``dask``): each segment (a :class:`ClipsJob`, rendered by
:func:`render_clips_segment`) decodes every clip for its frame range, in lock-step,
and the joined output carries the spherical metadata.

The clips must share a frame rate; when their frame counts differ, the
shortest ends the output (``note`` is told so).
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from fractions import Fraction
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import InvalidValueError
from .spherical import Spherical
from .video import (
    VideoInfo,
    _depth,
    _encoder,
    _open,
    _pick_pix_fmt,
    default_codec,
    frames_from,
    probe,
)
from .videowriter import EQUIRECT

__all__ = ["ClipsJob", "check_clips", "render_clips", "render_clips_segment"]


def check_clips(
    inputs: Sequence[Path], force: bool = False, counts: Sequence[int] | None = None
) -> tuple[list[VideoInfo], int, str | None]:
    """Probe the clips: their descriptions, the frame count of the output (the shortest's) and
    a note when they differ in length (None when they agree).

    Parameters
    ----------
    inputs : sequence of Path
        The clips.
    force : bool
        Accept clips that are not 2:1.
    counts : sequence of int, optional
        Each clip's frame count, when the caller has counted them; by default they are
        counted from the clips' packets (:func:`~spherewarp.io.segments.frame_times`, as a
        single video's render counts them), never taken from the container's header, which
        Matroska and WebM do not hold (:attr:`VideoInfo.frames` is 0 there).

    Returns
    -------
    (list of VideoInfo, int, str or None)

    Raises
    ------
    InvalidValueError
        When the clips differ in frame rate, or one is not 2:1 without ``force``.
    """
    from .segments import frame_times

    infos = [probe(p) for p in inputs]
    first = infos[0]
    for path, info in zip(inputs, infos, strict=True):
        if info.rate != first.rate:
            raise InvalidValueError(
                f"'{path}' runs at {float(info.rate or 0):g} frames a second but "
                f"'{inputs[0]}' at {float(first.rate or 0):g}; the clips are combined frame by "
                "frame, so they need one frame rate (re-time one first, e.g. ffmpeg -r)"
            )
        if info.width != 2 * info.height and not force:
            raise InvalidValueError(
                f"'{path}' is {info.width}x{info.height}, not 2:1 (equirectangular); "
                "pass --force to combine it anyway"
            )
    if counts is None:
        counts = [len(frame_times(p)[0]) for p in inputs]
    counts = list(counts)
    n = min(counts)
    note = None
    if len(set(counts)) > 1:
        shortest = inputs[counts.index(n)]
        listed = ", ".join(f"'{p}' {c}" for p, c in zip(inputs, counts, strict=True))
        note = (
            f"the clips differ in length ({listed} frames): the output ends with the "
            f"shortest, '{shortest}', after {n} frames"
        )
    return infos, n, note


@dataclass
class ClipsJob:
    """One segment of a split-screen of clips: frames ``[start, start + frames)`` of every
    clip, combined and encoded into ``part`` (picklable: sent to a process pool or a Dask
    worker; ``combine`` must pickle too)."""

    index: int
    part: str
    inputs: list[str]
    starts: list[int]  # each clip's presentation time of the segment's first frame
    frames: int
    combine: Any
    rgb: str
    size: tuple[int, int]
    rate: Fraction
    time_base: Fraction
    encoding: dict[str, Any]
    in_pix: str
    threads: int | None = None
    timed: bool = False  # combine(frames, t): t the first clip's frame time in seconds


def _decoders(
    containers: list[Any], starts: list[int], seek: bool, paths: list[str] | None = None
) -> list[Iterator[Any]]:
    """Each clip's frames from its frame at ``starts[k]`` on (``seek``: from the keyframe
    before it, else from the clip's start; :func:`~spherewarp.io.video.frames_from`). A clip
    decoded afresh after a seek that landed too late is opened again from ``paths`` (its
    container added to ``containers``, for the caller to close)."""
    out = []
    for k, (c, start) in enumerate(zip(list(containers), starts, strict=True)):

        def reopen(k: int = k) -> Any:
            containers.append(_open(paths[k]))
            return containers[-1]

        out.append(frames_from(c, start, seek, reopen if paths is not None else None))
    return out


def _time(frame: Any, job: ClipsJob, k: int) -> float:
    """The time in seconds of ``frame``, the ``k``-th of ``job``'s segment."""
    if frame.pts is not None:
        return float(frame.pts * frame.time_base)
    return float(job.starts[0] * job.time_base + Fraction(k) / job.rate)


def render_clips_segment(
    job: ClipsJob, progress: Callable[[int], None] | None = None
) -> tuple[int, int, int]:
    """Render one :class:`ClipsJob` to ``job.part`` atomically; return ``(index, frames,
    bytes)`` (a :func:`spherewarp.io.segments.run_segments` ``render``); ``progress(k)``
    after each frame."""
    from .segments import _dask_threads, _set_threads, writing_part
    from .videowriter import video_writer

    _set_threads(job.threads if job.threads is not None else _dask_threads())
    containers = [_open(p) for p in job.inputs]
    done = 0
    try:
        decoders = _decoders(containers, job.starts, job.index > 0, job.inputs)
        with writing_part(job.part) as tmp:
            with video_writer(
                tmp, job.size, job.rate, time_base=job.time_base, in_pix=job.in_pix,
                overwrite=True, spherical=None, **job.encoding,
            ) as writer:  # fmt: skip
                while done < job.frames:
                    frames = [next(d, None) for d in decoders]
                    if any(f is None for f in frames):
                        break
                    arrays = [f.to_ndarray(format=job.rgb) for f in frames]
                    if job.timed:
                        out = job.combine(arrays, _time(frames[0], job, done))
                    else:
                        out = job.combine(arrays)
                    writer.write(out, frames[0].pts, frames[0].time_base)
                    done += 1
                    if progress is not None:
                        progress(done)
                if done != job.frames:
                    raise RuntimeError(
                        f"segment {job.index} of '{job.inputs[0]}' gave {done} frames, "
                        f"expected {job.frames}"
                    )
            size = os.path.getsize(tmp)
    finally:
        for c in containers:
            c.close()
    return job.index, done, size


def render_clips(
    inputs: Sequence[str | os.PathLike[str]],
    output: str | os.PathLike[str],
    combine: Callable[[list[np.ndarray]], np.ndarray],
    *,
    codec: str | None = None,
    crf: float | None = None,
    preset: str | None = None,
    pix_fmt: str | None = None,
    overwrite: bool = False,
    force: bool = False,
    spherical: Spherical | None = EQUIRECT,
    progress: Callable[[int, int], None] | None = None,
    note: Callable[[str], None] | None = None,
    identity: str = "",
    resume: bool = False,
    jobs: int = 1,
    dask: str | Any | None = None,
    segment_seconds: float | None = None,
    timed: bool = False,
) -> int:
    """Combine frame k of every input into frame k of ``output``, in segments; return the
    frames written.

    Parameters
    ----------
    inputs : paths
        Two or more videos with one frame rate.
    output : path
        The video to write (``.mp4``, ``.mov``, ``.m4v``, ``.mkv``, ``.webm``).
    combine : callable
        ``combine([frame_1, frame_2, ...]) -> frame``: RGB arrays (``uint8``, or
        ``uint16`` when the output has more than 8 bits), one from each input. It is first
        called here on the first frames (it may settle what it chooses from them, e.g. an
        automatic seam), then (pickled, with ``jobs > 1`` or ``dask``) for every frame.
    codec, crf, preset, pix_fmt, overwrite
        As :func:`spherewarp.io.video.render_video`.
    force : bool
        Accept inputs that are not 2:1.
    spherical : Spherical or None
        The output's spherical metadata (default: mono equirectangular).
    progress : callable, optional
        ``progress(done, total)`` as frames are done.
    note : callable, optional
        Told when the inputs differ in length (the shortest ends the output).
    identity, resume, jobs, dask, segment_seconds
        As :func:`spherewarp.io.segments.render_segmented` (``identity``: what decides
        ``combine``'s pixels).
    timed : bool
        Call ``combine(frames, t)`` with the first input's frame time ``t`` (seconds).

    Raises
    ------
    ImageFormatError, InvalidValueError, OutputExistsError
        For a bad input, output or option; nothing is written then.
    """
    import json

    from .atomic import exists_error
    from .segments import (
        Segmented,
        _input_identity,
        check_times,
        frame_times,
        join,
        plan_segments,
        run_segments,
        segment_frames,
    )
    from .spherical import write_spherical
    from .video import muxer
    from .videowriter import check_writer

    paths = [os.path.abspath(p) for p in inputs]
    output = Path(output)
    if not overwrite and os.path.lexists(output):
        raise exists_error(output)
    times = [frame_times(p) for p in inputs]  # a bad clip is named as given
    counts = [len(pts) for pts, _ in times]
    infos, n, differ = check_clips([Path(p) for p in inputs], force, counts)
    if n == 0:
        raise InvalidValueError(f"'{inputs[0]}' has no frames to combine")
    if differ is not None and note is not None:
        note(differ)
    first = infos[0]
    rate, tb = first.rate or Fraction(24), times[0][1]
    out_pix = _pick_pix_fmt(
        _encoder(default_codec(output) if codec is None else codec), first.pix_fmt, pix_fmt
    )
    rgb = "rgb48le" if _depth(out_pix) > 8 else "rgb24"
    containers = [_open(p) for p in paths]
    try:  # the first frames: the size (and whatever combine settles on them)
        lead = [next(d) for d in _decoders(containers, [pts[0] for pts, _ in times], False)]
        arrays = [f.to_ndarray(format=rgb) for f in lead]
        t0 = float(lead[0].pts * lead[0].time_base) if lead[0].pts is not None else 0.0
        size = (combine(arrays, t0) if timed else combine(arrays)).shape[:2]
    finally:
        for c in containers:
            c.close()
    enc, out_pix, _, _ = check_writer(
        output, size, rate, time_base=tb, codec=codec, crf=crf, preset=preset, pix_fmt=pix_fmt,
        in_pix=first.pix_fmt,
    )  # fmt: skip
    encoding = {"codec": enc.name, "crf": crf, "preset": preset, "pix_fmt": out_pix}
    lead_pts = times[0][0]
    check_times(lead_pts[:n], tb, inputs[0])
    step = segment_frames(segment_seconds, float(rate))
    ranges = plan_segments(lead_pts[:n], step)

    def job(i: int, part: str) -> ClipsJob:
        a, b = ranges[i]
        return ClipsJob(
            index=i, part=part, inputs=paths, starts=[pts[a] for pts, _ in times],
            frames=b - a, combine=combine, rgb=rgb, size=size, rate=rate, time_base=tb,
            encoding=encoding, in_pix=first.pix_fmt, timed=timed,
        )  # fmt: skip

    end = None if differ is None else float(n / rate)

    def join_parts(parts: list[Path], tmp: Path) -> None:
        join(parts, Path(paths[0]), tmp, muxer(output), end=end, times=lead_pts[:n], time_base=tb)
        write_spherical(tmp, spherical)

    full = json.dumps(
        {"identity": identity, "encoding": encoding, "in_pix": first.pix_fmt, "size": size,
         "frames": n, "spherical": repr(spherical)},
        sort_keys=True, default=str,
    )  # fmt: skip
    segments = [
        {"index": i, "start": a, "end": b, "start_pts": [pts[a] for pts, _ in times]}
        for i, (a, b) in enumerate(ranges)
    ]
    plan = Segmented(
        output=output, source=[_input_identity(p) for p in paths],
        name=", ".join(str(p) for p in inputs), identity=full, segments=segments, job=job,
        render=render_clips_segment, join=join_parts, reads=paths,
    )  # fmt: skip
    run_segments(plan, resume=resume, jobs=jobs, dask=dask, overwrite=overwrite,
                 progress=progress)  # fmt: skip
    return n
