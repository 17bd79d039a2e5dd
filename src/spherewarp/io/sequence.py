"""Image sequences as video: ``frames/%05d.png`` in, ``out/%05d.exr`` out, for compositing.

A sequence is named by a pattern with one frame-number field, ``%0Nd`` or
``%d`` (as ffmpeg names them; ``{:0Nd}`` and ``{}`` too). As an input, every
file of the pattern's directory that matches it is a frame, in the order of
its number (numbering may start anywhere; gaps are allowed), shown at ``k /
fps`` seconds for the k-th. As an output, frame k (from 0) is written to the
pattern's name for k, each file atomically (:mod:`spherewarp.io.atomic`),
keeping the sample type (an EXR or 16-bit TIFF/PNG of a 10-bit video holds
16 bits; the values are the decoded, display-referred ones, as the still
commands write them: linearised in an EXR, which holds linear light). An error
or an interrupt removes the frames this run wrote.

:func:`render_sequence` warps a sequence or a video into a sequence or a
video, with the same options as :func:`~spherewarp.io.video.render_video`
(stereo layouts, output grids, encoder options), in three threads (read,
warp, write) joined by queues of a few frames.

Examples
--------
>>> split_pattern("frames/%05d.png")
('frames/', 5, '.png')
>>> frame_path("out/f_%03d.exr", 7).as_posix()
'out/f_007.exr'
>>> is_pattern("clip.mp4"), is_pattern("f%d.tif")
(False, True)
"""

from __future__ import annotations

import dataclasses
import os
import re
import warnings
from collections.abc import Callable, Iterator
from fractions import Fraction
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ImageFormatError, InvalidValueError, OutputExistsError
from .atomic import atomic_file
from .images import _FORMAT_DTYPES, SUPPORTED_EXTENSIONS, convert_dtype, read_image, write_image
from .spherical import write_spherical
from .stereo import FramePlan, is_panorama
from .video import (
    FrameMap,
    VideoInfo,
    _check_encoder,
    _check_even,
    _check_output,
    _depth,
    _encoder,
    _open,
    _pick_pix_fmt,
    add_video_stream,
    check_container,
    default_codec,
    encode,
    encoder_options,
    frame_layout,
    muxer,
    output_range,
    output_spherical,
    pipeline,
    probe,
)

__all__ = [
    "find_frames",
    "frame_path",
    "frames_of",
    "is_frames",
    "is_pattern",
    "render_sequence",
    "split_pattern",
]

_FIELD = re.compile(r"%(?:0([1-9]))?d|\{(?::(?:0([1-9]))?d)?\}")
#: frames a second of a sequence input, unless given
DEFAULT_FPS = 24


def is_pattern(path: str | os.PathLike[str]) -> bool:
    """Whether ``path`` names an image sequence (it holds a frame-number field)."""
    return _FIELD.search(os.fspath(path)) is not None


def is_frames(path: str | os.PathLike[str]) -> bool:
    """Whether ``path`` names images: a sequence pattern, or one image (``.png``, ``.exr``...),
    which :func:`render_sequence` takes as a sequence of one frame (a stereo still, say)."""
    return is_pattern(path) or Path(path).suffix.lower() in SUPPORTED_EXTENSIONS


def frames_of(path: str | os.PathLike[str]) -> list[Path]:
    """The files of a sequence (:func:`find_frames`), or the one image ``path``."""
    if is_pattern(path):
        return find_frames(path)
    if not Path(path).is_file():
        raise ImageFormatError(f"cannot read '{os.fspath(path)}': no such file")
    return [Path(path)]


def _frame_out(output: Path, k: int) -> Path:
    """The file frame ``k`` (from 0) is written to: the pattern's name for ``k``
    (:func:`frame_path`), or ``output`` itself for the one frame of a single image. The
    writer and the check of existing files (:func:`_refuse_existing_frames`) both name the
    frames by it.

    Raises
    ------
    InvalidValueError
        For ``k > 0`` and an ``output`` that is one image, not a pattern.
    """
    if is_pattern(output):
        return frame_path(output, k)
    if k:
        raise InvalidValueError(
            f"-o '{output}' holds one image, and the input has more frames; give a pattern "
            "such as out/%05d.png"
        )
    return output


def split_pattern(pattern: str | os.PathLike[str]) -> tuple[str, int, str]:
    """``(head, width, tail)`` of a pattern: the text before the field, its zero-padded
    width (0: not padded) and the text after; InvalidValueError unless exactly one field."""
    text = os.fspath(pattern)
    fields = list(_FIELD.finditer(text))
    rest = _FIELD.sub("", text)
    if len(fields) != 1 or any(c in rest for c in "%{}"):
        raise InvalidValueError(
            "expected an image sequence pattern with one field %0Nd (N = 1..9) or %d, like "
            f"frames/%05d.png, and no other '%', '{{' or '}}'; got {text!r}"
        )
    m = fields[0]
    return text[: m.start()], int(m.group(1) or m.group(2) or 0), text[m.end() :]


def frame_path(pattern: str | os.PathLike[str], k: int) -> Path:
    """The file of frame ``k`` of ``pattern``."""
    head, width, tail = split_pattern(pattern)
    return Path(f"{head}{k:0{width}d}{tail}")


def find_frames(pattern: str | os.PathLike[str]) -> list[Path]:
    """The files of a sequence, in the order of their numbers.

    Raises
    ------
    ImageFormatError
        When no file matches.
    """
    head, width, tail = split_pattern(pattern)
    cut = max(head.rfind("/"), head.rfind(os.sep)) + 1
    directory, prefix = Path(head[:cut] or "."), head[cut:]
    digits = r"\d+" if width == 0 else rf"\d{{{width},}}"
    name = re.compile(re.escape(prefix) + f"({digits})" + re.escape(tail))
    found = []
    if directory.is_dir():
        for p in directory.iterdir():
            m = name.fullmatch(p.name)
            if m and p.is_file():
                found.append((int(m.group(1)), p))
    if not found:
        raise ImageFormatError(f"cannot read '{os.fspath(pattern)}': no file matches the pattern")
    return [p for _, p in sorted(found)]


def _check_image_output(pattern: Path, overwrite: bool) -> None:
    """Refuse an image output that names no image format or holds no one pattern, and an
    existing single image unless ``overwrite`` (a pattern's frames: see
    :func:`_refuse_existing_frames`, once their count is known)."""
    if is_pattern(pattern):
        split_pattern(pattern)
    elif pattern.exists() and not overwrite:
        raise OutputExistsError(f"'{pattern}' exists; pass --overwrite to replace it")
    if pattern.suffix.lower() not in SUPPORTED_EXTENSIONS:
        raise ImageFormatError(
            f"cannot write '{pattern}': unknown image extension {pattern.suffix or '(none)'!r}; "
            f"use one of {', '.join(SUPPORTED_EXTENSIONS)}"
        )


def _refuse_existing_frames(pattern: Path, frames: int, overwrite: bool) -> None:
    """Refuse, unless ``overwrite``, to write ``frames`` frames to ``pattern`` when a file they
    would be written to exists: the names the writer gives them (:func:`_frame_out`, from 0),
    not every file the pattern matches (``%d`` matches ``00001.png``, which it never writes).

    Raises
    ------
    OutputExistsError
        Naming the first such file and how many there are.
    """
    if overwrite or not is_pattern(pattern):
        return
    existing = [p for p in (_frame_out(pattern, k) for k in range(frames)) if p.exists()]
    if existing:
        raise OutputExistsError(
            f"'{existing[0]}' exists ({len(existing)} of the {frames} frames of '{pattern}'); "
            "pass --overwrite to replace them"
        )


def _to_rgb(pixels: np.ndarray, dtype: Any, tonemap: str) -> np.ndarray:
    """An image of a sequence as the encoder's RGB: 3 channels of ``dtype`` (alpha over black,
    grey repeated, HDR float tone-mapped)."""
    from .tonemap import flatten_alpha
    from .tonemap import tonemap as _tonemap

    img = pixels if pixels.ndim == 3 else pixels[..., None]
    if img.dtype.kind == "f":
        img = _tonemap(img, tonemap)
    if img.shape[2] in (2, 4):
        img = flatten_alpha(img, "black")
    if img.shape[2] == 1:
        img = np.repeat(img, 3, axis=2)
    return np.ascontiguousarray(convert_dtype(img, dtype))


def _for_format(pixels: np.ndarray, path: Path, tonemap: str) -> np.ndarray:
    """``pixels`` as the format of ``path`` holds them (float tone-mapped, 16 bits to 8)."""
    fmt = SUPPORTED_EXTENSIONS[path.suffix.lower()]
    holds = _FORMAT_DTYPES[fmt]
    if pixels.dtype in holds:
        return pixels
    from .tonemap import tonemap as _tonemap

    if pixels.dtype.kind == "f":
        pixels = _tonemap(pixels, tonemap)
    target = np.uint16 if np.dtype(np.uint16) in holds else np.uint8
    return convert_dtype(pixels, target)


def render_sequence(
    input: str | os.PathLike[str],
    output: str | os.PathLike[str],
    frame_map: FrameMap,
    *,
    fps: float | None = None,
    codec: str | None = None,
    crf: float | None = None,
    preset: str | None = None,
    pix_fmt: str | None = None,
    overwrite: bool = False,
    force: bool = False,
    spherical: Any = True,
    progress: Callable[[int, int], None] | None = None,
    stereo: str | None = None,
    grid: Any = None,
    out_shape: tuple[int, int] | None = None,
    tonemap: str = "aces",
) -> int:
    """Warp every frame of a sequence or video ``input`` into a sequence or video ``output``.

    One of the two at least is images (:func:`is_frames`: a pattern, or one
    image, a sequence of one frame); for video to video, use
    :func:`~spherewarp.io.video.render_video` (it copies the audio).

    Parameters
    ----------
    input, output : path or pattern
        A video (``.mp4``...) or an image sequence (``frames/%05d.png``; PNG,
        TIFF, EXR, JPEG, WebP).
    frame_map : callable
        As :func:`~spherewarp.io.video.render_video` takes it.
    fps : float, optional
        The frame rate of a sequence input (default 24); a video input's
        frames keep their times, and a video output of a sequence gets this
        rate.
    tonemap : {"aces", "reinhard", "clip"}
        How HDR (float) frames become a video's or an 8/16-bit image's values.
    codec, crf, preset, pix_fmt, overwrite, force, spherical, progress, stereo, grid, out_shape
        As for :func:`~spherewarp.io.video.render_video`; ``spherical`` and the
        encoder options apply to a video output, and an image output carries
        GPano when it is a panorama.

    Returns
    -------
    int
        The number of frames written.

    Raises
    ------
    ImageFormatError, InvalidValueError, OutputExistsError
        For a bad input, output or option; nothing is written then.
    """
    input_seq, output_seq = is_frames(input), is_frames(output)
    input, output = Path(input), Path(output)
    if not (input_seq or output_seq):
        raise InvalidValueError("render_sequence: expected images (a pattern, an image) in or out")
    if output_seq:
        _check_image_output(output, overwrite)
    else:
        _check_output(output)
    if fps is not None and not (0 < fps <= 1000):
        raise InvalidValueError(f"--fps: expected frames a second in (0, 1000], got {fps:g}")
    if input_seq:
        files = frames_of(input)
        first = read_image(files[0])
        h, w = first.pixels.shape[:2]
        rate = Fraction(fps if fps is not None else DEFAULT_FPS).limit_denominator(1001)
        depth = 16 if first.pixels.dtype != np.uint8 else 8
        pix = "rgb48le" if depth > 8 else "rgb24"
        info = VideoInfo(
            w, h, len(files), rate, 1 / rate, len(files) / rate, pix, "image", depth, None
        )  # fmt: skip
    else:
        files = []
        info = probe(input)
        if fps is not None:
            raise InvalidValueError(
                "--fps applies to an image sequence input; a video keeps its frame times"
            )
        if output_seq:  # counted from the packets, as a video render does (MKV records none)
            from .segments import frame_times

            info = dataclasses.replace(info, frames=len(frame_times(input)[0]))
    layout, grid, size = frame_layout(info, input, stereo, grid, out_shape, force)
    if output_seq and info.frames > 1:
        _frame_out(output, info.frames - 1)  # one image cannot hold them
    if output_seq:
        _refuse_existing_frames(output, info.frames, overwrite)
    gpano = is_panorama(grid) and layout == "mono"

    def frames() -> Iterator[tuple[float, np.ndarray]]:
        if input_seq:
            for k, p in enumerate(files):
                img = read_image(p).pixels
                if img.shape[:2] != (h, w):
                    raise ImageFormatError(
                        f"cannot read '{p}': {img.shape[1]}x{img.shape[0]}, but the sequence's "
                        f"first frame is {w}x{h}"
                    )
                yield float(k / rate), img
            return
        fmt = "rgb48le" if info.bit_depth > 8 else "rgb24"
        with _open(input) as c:
            others = [f"#{s.index} ({s.type})" for s in c.streams if s.type != "video"]
            if others:
                warnings.warn(
                    f"stream {', '.join(others)} is dropped: an image sequence holds the video "
                    "alone",
                    stacklevel=4,
                )
            vin = c.streams.video[0]
            vin.thread_type = "AUTO"
            for k, frame in enumerate(c.decode(vin)):
                t = float(frame.pts * frame.time_base) if frame.pts is not None else k / 24
                yield t, frame.to_ndarray(format=fmt)

    def make_plan(inverse: Any, opts: dict[str, Any]) -> FramePlan:
        return FramePlan(
            inverse, (info.height, info.width), stereo=layout, grid=grid, out_shape=out_shape,
            **{"force": force, **opts},
        )  # fmt: skip

    if output_seq:
        written: list[Path] = []

        def sink(k: int, t: float, pixels: np.ndarray) -> None:
            p = _frame_out(output, k)
            if k == 0:
                p.parent.mkdir(parents=True, exist_ok=True)
            write_image(p, _for_format(pixels, p, tonemap), gpano=gpano, overwrite=overwrite)
            written.append(p)

        try:
            return _pipeline(frames(), frame_map, make_plan, sink, progress, info.frames)
        except BaseException:
            for p in written:
                p.unlink(missing_ok=True)
            raise
    return _encode_sequence(
        output, info, size, layout, grid, frames(), frame_map, make_plan, progress, codec, crf,
        preset, pix_fmt, overwrite, spherical, tonemap,
    )  # fmt: skip


def _encode_sequence(
    output: Path,
    info: VideoInfo,
    size: tuple[int, int],
    layout: str,
    grid: Any,
    frames: Iterator[tuple[float, np.ndarray]],
    frame_map: FrameMap,
    make_plan: Callable[..., FramePlan],
    progress: Callable[[int, int], None] | None,
    codec: str | None,
    crf: float | None,
    preset: str | None,
    pix_fmt: str | None,
    overwrite: bool,
    spherical: Any,
    tonemap: str,
) -> int:
    """A sequence's frames, warped, encoded into the video ``output``."""
    import av

    enc = _encoder(default_codec(output) if codec is None else codec)
    check_container(enc, output)
    in_pix = "yuv420p10le" if info.bit_depth > 8 else "yuv420p"
    out_pix = _pick_pix_fmt(enc, in_pix, pix_fmt)
    _check_even(size, out_pix)
    high = _depth(out_pix) > 8
    rgb, dtype = ("rgb48le", np.uint16) if high else ("rgb24", np.uint8)
    options = encoder_options(enc, crf, preset)
    color_range = output_range(out_pix)  # RGB frames: grey and yuvj are full range
    _check_encoder(enc, out_pix, options, info, size, color_range)
    rate = info.rate or Fraction(DEFAULT_FPS)
    with atomic_file(output, overwrite=overwrite) as tmp:
        dst = av.open(str(tmp), "w", format=muxer(output))
        try:
            vout = add_video_stream(
                dst, enc.name, rate, options, size, out_pix, 1 / rate, color_range
            )  # fmt: skip

            def sink(k: int, t: float, pixels: np.ndarray) -> None:
                frame = av.VideoFrame.from_ndarray(_to_rgb(pixels, dtype, tonemap), format=rgb)
                frame.pts, frame.time_base = k, 1 / rate
                dst.mux(encode(vout, frame))

            n = _pipeline(frames, frame_map, make_plan, sink, progress, info.frames)
            dst.mux(encode(vout, None))
        finally:
            dst.close()
        write_spherical(tmp, output_spherical(info, layout, grid, spherical))
    return n


def _pipeline(
    frames: Iterator[tuple[float, np.ndarray]],
    frame_map: FrameMap,
    make_plan: Callable[..., FramePlan],
    sink: Callable[[int, float, np.ndarray], None],
    progress: Callable[[int, int], None] | None,
    total: int,
) -> int:
    """Read (a thread), warp (here) and write (a thread) every frame; the number written
    (:func:`spherewarp.io.video.pipeline`)."""
    plan: tuple[Any, FramePlan] | None = None
    done = 0

    def warp(item: tuple[float, np.ndarray]) -> tuple[float, np.ndarray]:
        nonlocal plan, done
        t, pixels = item
        inverse, opts = frame_map(t)
        if plan is None or plan[0] is not inverse:
            plan = (inverse, make_plan(inverse, opts))
        out = (t, plan[1].apply(pixels))
        done += 1
        if progress is not None:
            progress(done, max(total, done))
        return out

    written = 0

    def write(item: tuple[float, np.ndarray]) -> None:
        nonlocal written
        sink(written, *item)
        written += 1

    return pipeline(frames, warp, write)
