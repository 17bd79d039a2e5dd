"""Several clips decoded in lock-step, combined frame by frame into one video.

:func:`render_clips` is the split-screen of two clips (the paper's apartment
video: ``spherewarp video a.mp4 b.mp4 -o out.mp4 splitscreen``): frame k of
every input goes to ``combine`` together; the output keeps the first input's
frame times and audio (packets copied as they are), and is written with
:func:`spherewarp.io.videowriter.video_writer` (the encoder options of
``spherewarp video``, spherical metadata, atomically).

The clips must share a frame rate; when their frame counts differ, the
shortest ends the output (``note`` is told so).
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np

from ..errors import InvalidValueError
from .spherical import Spherical
from .video import VideoInfo, _depth, _encoder, _open, _pick_pix_fmt, default_codec, probe
from .videowriter import EQUIRECT

__all__ = ["render_clips", "check_clips"]


def check_clips(
    inputs: Sequence[Path], force: bool = False
) -> tuple[list[VideoInfo], int, str | None]:
    """Probe the clips: their descriptions, the frame count of the output (the shortest's) and
    a note when they differ in length (None when they agree).

    Raises
    ------
    InvalidValueError
        When the clips differ in frame rate, or one is not 2:1 without ``force``.
    """
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
    counts = [i.frames for i in infos]
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
    timed: bool = False,
) -> int:
    """Combine frame k of every input into frame k of ``output``; return the frames written.

    Parameters
    ----------
    inputs : paths
        Videos with one frame rate (two or more for a split screen).
    output : path
        The video to write (``.mp4``, ``.mov``, ``.m4v``, ``.mkv``, ``.webm``).
    combine : callable
        ``combine([frame_1, frame_2, ...]) -> frame``: RGB arrays (``uint8``, or
        ``uint16`` when the output has more than 8 bits), one from each input.
    codec, crf, preset, pix_fmt, overwrite
        As :func:`spherewarp.io.video.render_video`.
    force : bool
        Accept inputs that are not 2:1.
    spherical : Spherical or None
        The output's spherical metadata (default: mono equirectangular).
    progress : callable, optional
        ``progress(done, total)`` after each frame.
    note : callable, optional
        Told when the inputs differ in length (the shortest ends the output).
    timed : bool
        Call ``combine(frames, t)`` with the first input's frame time ``t`` (seconds).

    Raises
    ------
    ImageFormatError, InvalidValueError, OutputExistsError
        For a bad input, output or option; nothing is written then.
    """
    from .videowriter import video_writer

    inputs = [Path(p) for p in inputs]
    output = Path(output)
    infos, n, differ = check_clips(inputs, force)
    if differ is not None and note is not None:
        note(differ)
    first = infos[0]
    out_pix = _pick_pix_fmt(
        _encoder(default_codec(output) if codec is None else codec), first.pix_fmt, pix_fmt
    )
    rgb = "rgb48le" if _depth(out_pix) > 8 else "rgb24"
    containers = [_open(p) for p in inputs]
    try:
        for c in containers:
            c.streams.video[0].thread_type = "AUTO"
        decoders = [c.decode(video=0) for c in containers]
        vin = containers[0].streams.video[0]
        rate = first.rate or vin.guessed_rate
        writer_cm = None
        done = 0
        while n == 0 or done < n:
            frames = [next(d, None) for d in decoders]
            if any(f is None for f in frames):
                break
            lead = frames[0]
            arrays = [f.to_ndarray(format=rgb) for f in frames]
            if timed:
                t = lead.pts * lead.time_base if lead.pts is not None else done / rate
                out = combine(arrays, float(t))  # type: ignore[call-arg]
            else:
                out = combine(arrays)
            if writer_cm is None:  # the size is the first combined frame's
                writer_cm = video_writer(
                    output, out.shape[:2], rate, time_base=vin.time_base, codec=codec, crf=crf,
                    preset=preset, pix_fmt=pix_fmt, in_pix=first.pix_fmt, overwrite=overwrite,
                    spherical=spherical, audio_from=inputs[0],
                    end=None if differ is None else float(n / rate),
                )  # fmt: skip
                writer = writer_cm.__enter__()
            writer.write(out, lead.pts, lead.time_base)
            done += 1
            if progress is not None:
                progress(done, n)
        if writer_cm is None:
            raise InvalidValueError(f"'{inputs[0]}' has no frames to combine")
    except BaseException as exc:
        if writer_cm is not None:
            writer_cm.__exit__(type(exc), exc, exc.__traceback__)
        raise
    finally:
        for c in containers:
            c.close()
    writer_cm.__exit__(None, None, None)
    return done
