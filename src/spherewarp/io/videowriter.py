"""Encode frames given as arrays into a video file, with :mod:`spherewarp.io.video`'s options.

:func:`video_writer` is what ``spherewarp animate ... -o OUT.mp4`` and the
split-screen of several clips (:mod:`spherewarp.io.multiclip`) write with: the
same encoders and defaults as ``spherewarp video`` (``codec``, ``crf``,
``preset``, ``pix_fmt``), checked before anything is written; audio packets of
another file copied as they are (optional); spherical metadata
(:mod:`spherewarp.io.spherical`) written at the end; the output written
atomically, so an error or an interrupt leaves no file behind.

Examples
--------
>>> import numpy as np, tempfile, pathlib
>>> from fractions import Fraction
>>> out = pathlib.Path(tempfile.mkdtemp()) / "grey.mp4"
>>> with video_writer(out, (32, 64), Fraction(24)) as w:
...     for k in range(3):
...         w.write(np.full((32, 64, 3), 100, np.uint8))
>>> from spherewarp.io.video import probe
>>> probe(out).frames, probe(out).spherical.projection
(3, 'equirectangular')
"""

from __future__ import annotations

import contextlib
import os
import warnings
from collections.abc import Iterator
from fractions import Fraction
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np

from ..errors import InvalidValueError
from .atomic import atomic_file
from .spherical import Spherical, write_spherical
from .video import (
    _check_encoder,
    _check_even,
    _check_output,
    _depth,
    _encoder,
    _pick_pix_fmt,
    add_video_stream,
    check_container,
    codec_name,
    default_codec,
    encode,
    encoder_options,
    muxer,
    muxer_takes,
    output_range,
)

__all__ = ["VideoWriter", "video_writer", "check_writer", "frame_rate", "EQUIRECT"]

#: mono equirectangular spherical metadata (the default of :func:`video_writer`)
EQUIRECT = Spherical()


def frame_rate(fps: float) -> Fraction:
    """``fps`` as the exact fraction it stands for (29.97 -> 30000/1001).

    Examples
    --------
    >>> frame_rate(24), frame_rate(29.97), frame_rate(23.976)
    (Fraction(24, 1), Fraction(30000, 1001), Fraction(24000, 1001))
    """
    for base in (24, 30, 60, 120, 48):
        ntsc = Fraction(base * 1000, 1001)
        if abs(float(ntsc) - fps) < 5e-4:
            return ntsc
    return Fraction(fps).limit_denominator(1001)


class VideoWriter:
    """The open output of :func:`video_writer`: :meth:`write` one frame after the other."""

    def __init__(self, dst: Any, vout: Any, rgb: str, audio: Any, copies: dict[int, Any]) -> None:
        self._dst, self._vout, self._rgb = dst, vout, rgb
        self._audio, self._copies = audio, copies
        self._pending: Any = None
        self.frames = 0

    def write(self, pixels: np.ndarray, pts: int | None = None, time_base: Any = None) -> None:
        """Encode one frame (H x W x 3 ``uint8``, or ``uint16`` for a high bit depth; grey and
        alpha are converted) at ``pts`` in ``time_base`` (default: frame number / rate)."""
        import av

        frame = av.VideoFrame.from_ndarray(_rgb(pixels, self._rgb), format=self._rgb)
        if pts is None:
            pts, time_base = self.frames, self._vout.codec_context.time_base
        frame.pts, frame.time_base = pts, time_base
        self._mux_audio(float(pts * time_base))
        self._dst.mux(encode(self._vout, frame))
        self.frames += 1

    def _mux_audio(self, until: float | None) -> None:
        """Copy the audio packets up to ``until`` seconds (None: all that are left)."""
        if self._audio is None:
            return
        while True:
            packet = self._pending
            if packet is None:
                packet = next(self._audio, None)
                if packet is None:
                    self._audio = None
                    return
                if packet.dts is None:
                    continue
            t = float(packet.pts * packet.time_base) if packet.pts is not None else 0.0
            if until is not None and t > until:
                self._pending = packet
                return
            self._pending = None
            packet.stream = self._copies[packet.stream_index]
            self._dst.mux(packet)

    def _finish(self, end: float | None) -> None:
        self._dst.mux(encode(self._vout, None))
        if end is None:
            self._mux_audio(None)
        else:  # the audio up to the end of the last frame; the rest is left out
            self._mux_audio(end)


def _rgb(pixels: np.ndarray, fmt: str) -> np.ndarray:
    """``pixels`` as contiguous RGB of ``fmt``'s sample type (rgb24: uint8, rgb48le: uint16)."""
    a = np.asarray(pixels)
    if a.ndim == 2:
        a = a[..., None]
    if a.shape[2] in (2, 4):  # grey or RGB with alpha: over black, as JPEG flattens
        alpha = a[..., -1:].astype(np.float32) / (
            np.iinfo(a.dtype).max if a.dtype.kind in "ui" else 1
        )
        a = (a[..., :-1].astype(np.float32) * alpha).astype(a.dtype)
    if a.shape[2] == 1:
        a = np.repeat(a, 3, axis=2)
    want = np.uint16 if fmt == "rgb48le" else np.uint8
    if a.dtype.kind == "f":
        a = np.clip(a, 0.0, 1.0) * np.iinfo(want).max + 0.5
    elif a.dtype != want:
        a = a.astype(np.float64) * (np.iinfo(want).max / np.iinfo(a.dtype).max) + 0.5
    return np.ascontiguousarray(a.astype(want))


def check_writer(
    output: Path,
    size: tuple[int, int],
    rate: Fraction,
    *,
    time_base: Fraction | None = None,
    codec: str | None = None,
    crf: float | None = None,
    preset: str | None = None,
    pix_fmt: str | None = None,
    in_pix: str = "yuv420p",
) -> tuple[Any, str, dict[str, str], Fraction]:
    """Settle :func:`video_writer`'s encoder for these options, refusing a bad one (the
    encoder is opened once): ``(encoder, pix_fmt, encoder options, time base)``.

    Examples
    --------
    >>> enc, pix, options, tb = check_writer(Path("a.mp4"), (32, 64), Fraction(24))
    >>> enc.name, pix, options, tb
    ('libx264', 'yuv420p', {'crf': '18'}, Fraction(1, 24))
    """
    _check_output(output)
    enc = _encoder(default_codec(output) if codec is None else codec)
    out_pix = _pick_pix_fmt(enc, in_pix, pix_fmt)
    _check_even(size, out_pix)
    check_container(enc, output)
    options = encoder_options(enc, crf, preset)
    tb = time_base or 1 / Fraction(rate)
    _check_encoder(
        enc, out_pix, options, SimpleNamespace(time_base=tb, rate=rate), size,
        output_range(out_pix),
    )  # fmt: skip
    return enc, out_pix, options, tb


@contextlib.contextmanager
def video_writer(
    output: str | os.PathLike[str],
    size: tuple[int, int],
    rate: Fraction,
    *,
    time_base: Fraction | None = None,
    codec: str | None = None,
    crf: float | None = None,
    preset: str | None = None,
    pix_fmt: str | None = None,
    in_pix: str = "yuv420p",
    overwrite: bool = False,
    spherical: Spherical | None = EQUIRECT,
    audio_from: str | os.PathLike[str] | None = None,
    end: float | None = None,
) -> Iterator[VideoWriter]:
    """Open ``output`` to encode frames of ``size`` (height, width) at ``rate`` frames a second.

    Parameters
    ----------
    output : path
        ``.mp4``, ``.mov``, ``.m4v``, ``.mkv`` or ``.webm``.
    size : (height, width)
    rate : Fraction
        The frame rate; frames are numbered in ``time_base`` (default ``1 / rate``).
    codec, crf, preset, pix_fmt
        As :func:`spherewarp.io.video.render_video`; ``in_pix`` stands for the input's
        pixel format when choosing the default ``pix_fmt`` (a 10-bit input stays 10-bit).
    overwrite : bool
        Replace an existing ``output``.
    spherical : Spherical or None
        The spherical metadata written on the output (default: mono equirectangular);
        None for none.
    audio_from : path, optional
        A video whose audio streams are copied (packets as they are), up to ``end``
        seconds when given.

    Raises
    ------
    ImageFormatError, InvalidValueError, OutputExistsError
        For a bad output or option, before anything is written.
    """
    import av

    output = Path(output)
    enc, out_pix, options, tb = check_writer(
        output, size, rate, time_base=time_base, codec=codec, crf=crf, preset=preset,
        pix_fmt=pix_fmt, in_pix=in_pix,
    )  # fmt: skip
    rgb = "rgb48le" if _depth(out_pix) > 8 else "rgb24"
    with atomic_file(output, overwrite=overwrite) as tmp, contextlib.ExitStack() as stack:
        dst = stack.enter_context(av.open(str(tmp), "w", format=muxer(output)))
        vout = add_video_stream(
            dst, enc.name, rate, options, size, out_pix, tb, output_range(out_pix)
        )  # fmt: skip
        audio, copies = None, {}
        if audio_from is not None:
            src = stack.enter_context(av.open(str(audio_from)))
            for s in src.streams:
                name = codec_name(s)
                if s.type == "audio" and muxer_takes(s, dst.format.name):
                    copies[s.index] = dst.add_stream_from_template(s)
                elif s.type == "audio":
                    warnings.warn(
                        f"stream #{s.index} (audio, {name}) of '{audio_from}' is dropped: "
                        f"'{output.name}' cannot hold audio in {name}",
                        stacklevel=3,
                    )
                elif s.type != "video":
                    warnings.warn(
                        f"stream #{s.index} ({s.type}, {name}) of '{audio_from}' is dropped: "
                        "only its audio is copied",
                        stacklevel=3,
                    )
            if copies:
                audio = src.demux([s for s in src.streams if s.index in copies])
        writer = VideoWriter(dst, vout, rgb, audio, copies)
        yield writer
        if writer.frames == 0:
            raise InvalidValueError(f"no frames to write to '{output}'")
        writer._finish(end)
        stack.close()
        write_spherical(tmp, spherical)
