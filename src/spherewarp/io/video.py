"""360° video: decode, warp every frame, encode, with PyAV (FFmpeg's libraries).

:func:`render_video` reads a video, pulls each frame back through the map that
``frame_map(t)`` gives for the frame's presentation time ``t`` (seconds), and
writes an MP4/MOV file:

* the video is re-encoded (``codec``, ``crf``, ``preset``, ``pix_fmt``); each
  frame keeps its presentation time, so the frame rate, time base, frame count
  and duration are kept, variable frame rates too; a 10-bit input stays 10-bit
  when the codec takes it;
* audio and subtitle packets are copied as they are (no re-encoding) where the
  output's muxer takes their codec (:func:`muxer_takes`), and dropped with a warning
  otherwise (so are data streams);
* equirectangular spherical metadata (V1 and V2, :mod:`spherewarp.io.spherical`)
  is written on the output unless ``spherical=False``;
* a map that ``frame_map`` returns again (the same object) is planned once
  (:class:`~spherewarp.render.WarpMap`) and reused;
* decoding, warping and encoding run in three threads joined by queues of a
  few frames, so memory stays bounded whatever the length;
* the output is written atomically (:func:`spherewarp.io.atomic.atomic_file`):
  an error or an interrupt leaves no file behind.
"""

from __future__ import annotations

import contextlib
import os
import queue
import sys
import threading
import warnings
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from fractions import Fraction
from pathlib import Path
from typing import Any

from .. import _signals
from ..errors import ImageFormatError, InvalidValueError
from ..maps.base import SphereMap
from .atomic import atomic_file
from .planes import PLANAR_FORMATS, frame_plan
from .remote import is_url
from .spherical import Spherical, read_spherical, write_spherical
from .stereo import FramePlan, eye_shape, is_panorama, parse_stereo, resolve_grid

__all__ = [
    "VideoInfo",
    "frames_from",
    "pipeline",
    "probe",
    "render_video",
    "video_encoders",
    "whole",
    "VIDEO_EXTENSIONS",
]

VIDEO_EXTENSIONS = (".mp4", ".mov", ".m4v", ".mkv", ".webm")
#: the muxer of each extension (the others: mp4)
_MUXERS = {".mov": "mov", ".mkv": "matroska", ".webm": "webm"}
#: the video codecs a WebM file holds
_WEBM_VIDEO = ("vp8", "vp9", "av1")
_QUEUE = 4  # frames in flight between two stages
_DEFAULT_CRF = {"libx264": 18, "libx265": 20, "libvpx-vp9": 31, "libsvtav1": 35}
_HIGH_DEPTH_RGB = "rgb48le"
#: the encoders that take their frame rate from their time base, so encode in one of a frame
#: (MPEG-1/2: 1/12288 s read as 12288 fps, refused); the frames are rescaled into it
_FRAME_TIME_BASE = ("mpeg1video", "mpeg2video")
#: the kinds of streams (besides the warped video) copied packet for packet where the
#: output's muxer takes them
_COPIED_KINDS = ("audio", "subtitle")
#: how a warning names the file of each muxer
_CONTAINER_NAMES = {"matroska": "a Matroska", "webm": "a WebM", "mov": "a MOV", "mp4": "an MP4"}


def muxer(output: Path) -> str:
    """The FFmpeg muxer that writes ``output`` (by its extension)."""
    return _MUXERS.get(output.suffix.lower(), "mp4")


def codec_name(stream: Any) -> str:
    """The name of ``stream``'s codec: FFmpeg's name of its codec id (``mp3``, ``subrip``,
    ``mp2``), not its decoder's (``mp3float``, ``srt``, ``mp2float``), which the copy
    decisions and their warnings must not go by; ``"unknown"`` when FFmpeg has none.

    Parameters
    ----------
    stream : av.stream.Stream
        A stream of an open input container.

    Returns
    -------
    str
    """
    cc = stream.codec_context
    if cc is not None:
        return cc.codec.canonical_name or "unknown"
    if stream.type == "data":  # no codec context: the codec id's descriptor names it
        return stream.name or "unknown"
    return "unknown"


def muxer_takes(stream: Any, mux: str) -> bool:
    """Whether the FFmpeg muxer ``mux`` holds a packet-for-packet copy of ``stream``.

    FFmpeg decides, not a table: the stream is added to a throwaway output in memory
    (``avformat_query_codec``: MP4 holds no ADPCM, Matroska no ``adpcm_ima_qt`` nor
    ``mov_text``, WebM only Opus, Vorbis and WebVTT) and its header written (which refuses
    what the codec table allows but the muxer does not: FLAC or Opus in a MOV file).

    Parameters
    ----------
    stream : av.stream.Stream
        A stream of an open input container.
    mux : str
        The muxer's name (``mp4``, ``mov``, ``matroska``, ``webm``: :func:`muxer`).

    Returns
    -------
    bool
    """
    import io

    import av

    try:
        with av.open(io.BytesIO(), "w", format=mux) as trial:
            trial.add_stream_from_template(stream)
            trial.start_encoding()
    except Exception:  # noqa: BLE001 - av raises several kinds (ValueError, FFmpegError...)
        return False
    return True


def encoder_options(enc: Any, crf: float | None, preset: str | None) -> dict[str, str]:
    """The encoder's options: ``crf`` (default: the codec's own, x264 18, x265 20...),
    ``preset``, and the codec's quiet or constant-quality switches.

    Raises
    ------
    InvalidValueError
        For a ``crf`` given to an encoder without a constant rate factor (mpeg4, ffv1...),
        or a ``preset`` to one without presets (mpeg4, libvpx-vp9...), which FFmpeg would
        silently ignore.
    """
    options: dict[str, str] = {}
    if crf is not None and not _has_option(enc, "crf"):
        raise InvalidValueError(
            f"--crf: {enc.name} has no constant rate factor; leave --crf out, or use --codec "
            "libx264, libx265, libvpx-vp9 or libsvtav1"
        )
    if preset is not None and not _has_option(enc, "preset"):
        raise InvalidValueError(
            f"--preset: {enc.name} has no presets; leave --preset out, or use --codec "
            "libx264, libx265 or libsvtav1"
        )
    crf = _DEFAULT_CRF.get(enc.name) if crf is None else crf
    if crf is not None:
        options["crf"] = f"{crf:g}"
    if preset is not None:
        options["preset"] = preset
    if enc.name == "libx265":
        options["x265-params"] = "log-level=error"
    if enc.name in ("libvpx", "libvpx-vp9"):
        options["b"] = "0"  # constant quality: crf alone
    if enc.name == "libsvtav1":
        # SVT-AV1 has no option for it: its library reads SVT_LOG (1: errors) once, when its
        # first encoder opens; without it, a 20-line banner on stderr (x265's: log-level)
        os.environ.setdefault("SVT_LOG", "1")
    return options


def _has_option(enc: Any, name: str) -> bool:
    """Whether the encoder ``enc`` has its own option ``name`` (``crf``, ``preset``)."""
    import av

    return any(o.name == name for o in av.CodecContext.create(enc).supported_options.private)


def default_codec(output: Path) -> str:
    """libx264, or libvpx-vp9 for a WebM file."""
    return "libvpx-vp9" if muxer(output) == "webm" else "libx264"


def check_container(enc: Any, output: Path) -> None:
    """Refuse a video codec the output's container cannot hold (WebM: VP8, VP9, AV1; MP4 no
    qtrle; none that PyAV writes holds utvideo or huffyuv), naming those that hold it."""
    mux = muxer(output)
    if mux == "webm" and not any(v in enc.name for v in _WEBM_VIDEO + ("vpx",)):
        raise InvalidValueError(
            f"--codec {enc.name}: a WebM file holds VP8, VP9 or AV1 video; use --codec "
            "libvpx-vp9 (or libvpx, libsvtav1), or write .mkv"
        )
    _refuse_unless(enc.name, mux, lambda m: _holds(m, enc.name))


def _refuse_unless(codec: str, mux: str, takes: Callable[[str], bool]) -> None:
    """Refuse ``codec`` in a ``mux`` file unless ``takes(mux)``, naming the extensions whose
    muxers take it (``.mp4``, ``.mov``, ``.mkv``), or saying to choose another codec."""
    if takes(mux):
        return
    others = [
        e for e in (".mp4", ".mov", ".mkv")
        if (m := muxer(Path("x" + e))) != mux and takes(m)
    ]  # fmt: skip
    where = f"write {' or '.join(others)}" if others else "choose another --codec"
    raise InvalidValueError(
        f"--codec {codec}: {_CONTAINER_NAMES[mux]} file cannot hold {codec} video "
        f"(as FFmpeg writes it); {where}"
    )


def _holds(mux: str, codec: str) -> bool:
    """Whether PyAV adds a stream of the encoder ``codec`` to a ``mux`` file (FFmpeg's
    ``avformat_query_codec``: nothing is encoded nor written)."""
    import io

    import av

    container = av.open(io.BytesIO(), "w", format=mux)
    try:
        container.add_stream(codec)
    except ValueError:
        return False
    finally:
        with contextlib.suppress(Exception):  # nothing written: closing may complain
            container.close()
    return True


FrameMap = Callable[[float], tuple[SphereMap, dict[str, Any]]]


@dataclass
class VideoInfo:
    """What :func:`probe` finds in a video file.

    Attributes
    ----------
    width, height : int
    frames : int
        The frame count the container records (0 when unknown).
    rate : Fraction or None
        The average frame rate.
    time_base : Fraction
        The video stream's time base.
    duration : float or None
        Seconds.
    pix_fmt : str
        The decoded pixel format (``yuv420p``, ``yuv420p10le``...).
    codec : str
    bit_depth : int
        8, or more for a high bit depth input.
    spherical : Spherical or None
        The input's spherical metadata (MP4/MOV).
    color_range : int
        The video stream's colour range, as FFmpeg numbers it (``AVColorRange``): 0
        unspecified, 1 limited (MPEG, "tv"), 2 full (JPEG, "pc").
    colors : (int, int, int)
        The video stream's colour primaries, transfer characteristic and YUV matrix, as
        FFmpeg numbers them (``AVColorPrimaries``, ``AVColorTransferCharacteristic``,
        ``AVColorSpace``: 1 BT.709, 9 BT.2020, 18 ``arib-std-b67``...; 2 unspecified).
    display : str or None
        How players turn the frames before showing them (a display matrix, as a phone
        writes: ``"rotated by 90°"``, ``"mirrored"``...); None when they show them as
        stored (:func:`display_transform`).
    """

    width: int
    height: int
    frames: int
    rate: Fraction | None
    time_base: Fraction
    duration: float | None
    pix_fmt: str
    codec: str
    bit_depth: int
    spherical: Spherical | None
    color_range: int = 0
    colors: tuple[int, int, int] = (2, 2, 2)
    display: str | None = None


def _open(path: str | Path) -> Any:
    import av

    if is_url(path):
        return _open_url(path)
    path = Path(path)
    if not path.is_file():
        raise ImageFormatError(f"cannot read '{path}': no such file")
    try:
        return av.open(str(path))
    except av.error.FFmpegError as exc:
        raise ImageFormatError(f"cannot read '{path}': not a video file ({exc.strerror})") from None


def _open_url(url: str) -> Any:
    """A container reading the URL ``url`` through fsspec (:mod:`spherewarp.io.remote`)."""
    import av

    from .remote import open_input

    try:
        return av.open(open_input(url))  # a connection of its own (a worker's threads)
    except FileNotFoundError:
        raise ImageFormatError(f"cannot read '{url}': no such file") from None
    except av.error.FFmpegError as exc:
        raise ImageFormatError(f"cannot read '{url}': not a video file ({exc.strerror})") from None


def _video_stream(container: Any, path: Path) -> Any:
    streams = container.streams.video
    if not streams:
        raise ImageFormatError(f"cannot read '{path}': it has no video stream")
    return streams[0]


def _depth(pix_fmt: str) -> int:
    import av

    try:
        fmt = av.VideoFormat(pix_fmt)
    except (ValueError, av.error.FFmpegError):
        return 8
    return max((c.bits for c in fmt.components), default=8)


#: FFmpeg's colour ranges (``AVColorRange``): unspecified (read as limited) and full
RANGE_UNSPECIFIED, RANGE_FULL = 0, 2
#: FFmpeg's "unspecified" colour primaries, transfer and matrix (``AVCOL_*_UNSPECIFIED``)
COLORS_UNSPECIFIED = (2, 2, 2)


def output_range(out_pix: str, in_pix: str | None = None, in_range: int = 0) -> int:
    """The colour range of the samples an encoder of ``out_pix`` gets, which its stream
    must say (:data:`RANGE_FULL` or :data:`RANGE_UNSPECIFIED`, read as limited).

    Grey and ``yuvj`` samples are full range (swscale converts RGB to them so, whatever
    range is asked); a grey H.264 stream not flagged full range is decoded as limited-range
    YUV, its contrast stretched by 255/219. A frame encoded in its own pixel format
    (``out_pix == in_pix``: warped plane by plane, or through RGB converted back to the
    input's range) keeps the input's range ``in_range``. Other YUV formats are written in
    limited range.

    Parameters
    ----------
    out_pix : str
        The encoder's pixel format.
    in_pix : str, optional
        The input's pixel format.
    in_range : int
        The input's colour range (:attr:`VideoInfo.color_range`).

    Returns
    -------
    int

    Examples
    --------
    >>> output_range("gray"), output_range("yuvj420p"), output_range("gray10le")
    (2, 2, 2)
    >>> output_range("yuv420p", "yuv420p", 2), output_range("yuv420p", "yuv420p", 1)
    (2, 0)
    >>> output_range("yuv444p", "yuv420p", 2)  # through RGB, converted to limited range
    0
    """
    if out_pix.startswith(("gray", "yuvj")):
        return RANGE_FULL
    if out_pix == in_pix and in_range == RANGE_FULL:
        return RANGE_FULL
    return RANGE_UNSPECIFIED


def _video_format(pix_fmt: str) -> Any:
    """PyAV's ``VideoFormat`` of ``pix_fmt``, or None for a name FFmpeg does not know."""
    import av

    try:
        return av.VideoFormat(pix_fmt)
    except (ValueError, av.error.FFmpegError):
        return None


def _is_rgb(pix_fmt: str) -> bool:
    f = _video_format(pix_fmt)
    return f is not None and bool(f.is_rgb)


def output_colors(out_pix: str, in_pix: str, colors: tuple[int, int, int]) -> tuple[int, int, int]:
    """The colour primaries, transfer and matrix an output of ``out_pix`` says, from the
    input's ``colors`` (:attr:`VideoInfo.colors`).

    A warp moves pixels and leaves their colours as they are, so the primaries and the
    transfer (HLG, PQ, BT.709...) are the input's. The YUV matrix is the input's too where
    both are YUV: frames warped through RGB are converted back with it (:func:`encode`), as
    the decoder converted them to RGB with the input's. An RGB output has no matrix to say,
    and a YUV output of an RGB input (whose matrix says RGB) keeps the encoder's default
    (unspecified).

    Examples
    --------
    >>> output_colors("yuv420p10le", "yuv420p10le", (9, 18, 9))
    (9, 18, 9)
    >>> output_colors("gbrp", "yuv420p", (1, 1, 1)), output_colors("yuv420p", "rgba", (2, 2, 0))
    ((1, 1, 2), (2, 2, 2))
    """
    primaries, trc, matrix = colors
    if _is_rgb(out_pix) or _is_rgb(in_pix) or matrix == 0:  # AVCOL_SPC_RGB
        matrix = COLORS_UNSPECIFIED[2]
    return primaries, trc, matrix


def add_video_stream(
    dst: Any,
    codec: str,
    rate: Fraction,
    options: dict[str, str],
    size: tuple[int, int],
    pix_fmt: str,
    time_base: Fraction,
    color_range: int = RANGE_UNSPECIFIED,
    colors: tuple[int, int, int] = COLORS_UNSPECIFIED,
) -> Any:
    """Add the encoder's stream to the output container ``dst``.

    Parameters
    ----------
    dst : av.container.OutputContainer
    codec : str
        The encoder.
    rate : Fraction
        The frame rate.
    options : dict
        The encoder's options (:func:`encoder_options`).
    size : (height, width)
    pix_fmt : str
        The encoder's pixel format.
    time_base : Fraction
        The stream's and the encoder's time base.
    color_range : int
        The range of its samples (:func:`output_range`), written in the stream; frames
        given in another pixel format are converted into it (:func:`encode`).
    colors : (int, int, int)
        The colour primaries, transfer and YUV matrix written in the stream
        (:func:`output_colors`; unspecified ones are left out); RGB frames are converted
        with that matrix (:func:`encode`).

    HEVC in an MP4/MOV file is tagged ``hvc1`` (parameter sets in the sample entry), as
    ``ffmpeg -tag:v hvc1`` writes it: Apple's players refuse FFmpeg's default ``hev1``.

    Returns
    -------
    av.video.stream.VideoStream
    """
    vout = dst.add_stream(codec, rate=rate, options=options)
    vout.height, vout.width = size
    vout.pix_fmt = pix_fmt
    vout.time_base = time_base
    vout.codec_context.time_base = encoder_time_base(codec, time_base, rate)
    vout.thread_type = "AUTO"
    if color_range != RANGE_UNSPECIFIED:
        vout.codec_context.color_range = color_range
    cc = vout.codec_context
    for tag, value, unset in zip(
        ("color_primaries", "color_trc", "colorspace"), colors, COLORS_UNSPECIFIED, strict=True
    ):
        if value != unset:
            setattr(cc, tag, value)
    if dst.format.name in ("mp4", "mov") and vout.codec_context.codec.canonical_name == "hevc":
        vout.codec_context.codec_tag = "hvc1"  # FFmpeg's default, hev1, Apple's players refuse
    return vout


def encoder_time_base(codec: str, time_base: Fraction, rate: Fraction | None) -> Fraction:
    """The encoder's time base: the stream's, or one frame (``1 / rate``) for an encoder that
    reads its frame rate from it (MPEG-1/2, :data:`_FRAME_TIME_BASE`).

    Examples
    --------
    >>> encoder_time_base("mpeg2video", Fraction(1, 12288), Fraction(12))
    Fraction(1, 12)
    >>> encoder_time_base("libx264", Fraction(1, 12288), Fraction(12))
    Fraction(1, 12288)
    """
    if codec in _FRAME_TIME_BASE and rate:
        return 1 / Fraction(rate)
    return time_base


def encode(vout: Any, frame: Any) -> list[Any]:
    """``vout.encode(frame)`` (None: flush), an RGB frame first tagged with the stream's colour
    range and YUV matrix: the encoder converts it to its pixel format in that range and with
    that matrix, the ones its stream says (RGB samples are full range whatever the tag; an
    untagged frame is converted with BT.601's matrix, which an untagged stream is read with)."""
    if frame is not None and frame.format.is_rgb:
        frame.color_range = vout.codec_context.color_range
        if vout.codec_context.colorspace != COLORS_UNSPECIFIED[2]:
            frame.colorspace = vout.codec_context.colorspace
    return vout.encode(frame)


def probe(path: str | os.PathLike[str]) -> VideoInfo:
    """Describe the first video stream of ``path``.

    Raises
    ------
    ImageFormatError
        When ``path`` is not a video file or has no video stream.
    """
    path = path if is_url(path) else Path(path)
    with _open(path) as c:
        s = _video_stream(c, path)
        cc = s.codec_context
        pix = cc.pix_fmt or "yuv420p"
        duration = None
        if s.duration is not None:
            duration = float(s.duration * s.time_base)
        elif c.duration is not None:
            duration = c.duration / 1_000_000
        try:
            sph = None if is_url(path) else read_spherical(path)  # a URL's: not read
        except ImageFormatError:
            sph = None
        return VideoInfo(
            width=cc.width,
            height=cc.height,
            frames=int(s.frames or 0),
            rate=s.average_rate,
            time_base=s.time_base,
            duration=duration,
            pix_fmt=pix,
            codec=cc.codec.canonical_name,
            bit_depth=_depth(pix),
            spherical=sph,
            color_range=int(cc.color_range or 0),
            colors=(int(cc.color_primaries), int(cc.color_trc), int(cc.colorspace)),
            display=_display(c, s),
        )


def display_transform(matrix: Any) -> str | None:
    """What a display matrix (``AV_FRAME_DATA_DISPLAYMATRIX``: 9 int32, 16.16 fixed point)
    does to a frame, in words (the rotation counterclockwise, in (-180, 180], as ffprobe's
    ``rotation``); None for the identity.

    Examples
    --------
    >>> display_transform([-65536, 0, 0, 0, -65536, 0, 0, 0, 1 << 30])
    'rotated by 180°'
    >>> display_transform([0, -65536, 0, 65536, 0, 0, 0, 0, 1 << 30])
    'rotated by 90°'
    >>> display_transform([-65536, 0, 0, 0, 65536, 0, 0, 0, 1 << 30])
    'mirrored'
    >>> display_transform([65536, 0, 0, 0, 65536, 0, 0, 0, 1 << 30]) is None
    True
    """
    import math

    a, b, _, c, d, _, _, _, _ = (int(v) for v in matrix)
    if (a, b, c, d) == (65536, 0, 0, 65536):
        return None
    mirrored = a * d - b * c < 0
    if mirrored:  # undo the flip (of the x axis) to read the rotation
        a, c = -a, -c
    degrees = -round(math.degrees(math.atan2(b, a)))  # counterclockwise, as ffprobe says it
    degrees = 180 if degrees == -180 else degrees
    turned = f"rotated by {degrees}°" if degrees else ""
    return " and ".join(w for w in (turned, "mirrored" if mirrored else "") if w) or None


def _display(container: Any, stream: Any) -> str | None:
    """:func:`display_transform` of the display matrix of ``stream``'s first frame (FFmpeg
    gives the stream's to its frames), None when it has none or it cannot be decoded."""
    import av
    import numpy as np

    try:
        frame = next(container.decode(stream), None)
    except av.error.FFmpegError:
        return None
    sd = frame.side_data if frame is not None else None
    if sd is None:
        return None
    for key in sd.keys():
        if "DISPLAYMATRIX" in str(key):
            return display_transform(np.frombuffer(bytes(sd[key]), "<i4")[:9])
    return None


def video_encoders() -> list[str]:
    """The names of the video encoders this PyAV build offers.

    Examples
    --------
    >>> "libx264" in video_encoders()
    True
    """
    import av

    names = []
    for name in sorted(av.codecs_available):
        try:
            codec = av.Codec(name, "w")
        except Exception:  # noqa: BLE001 - not an encoder
            continue
        if codec.type == "video":
            names.append(name)
    return names


def _encoder(codec: str) -> Any:
    import av

    try:
        enc = av.Codec(codec, "w")
    except Exception:  # noqa: BLE001 - av raises several kinds for an unknown name
        enc = None
    if enc is None or enc.type != "video":
        raise InvalidValueError(
            f"--codec {codec!r}: this build has no such video encoder; "
            f"use one of {', '.join(video_encoders())}"
        )
    return enc


def _pick_pix_fmt(enc: Any, in_pix: str, wanted: str | None) -> str:
    offered = [f.name for f in (enc.video_formats or [])]
    if wanted is not None:
        if offered and wanted not in offered:
            raise InvalidValueError(
                f"--pix-fmt {wanted!r}: {enc.name} does not take it; "
                f"use one of {', '.join(offered)}"
            )
        return wanted
    if not offered:
        return in_pix
    if in_pix in offered:
        return in_pix
    if _depth(in_pix) > 8:
        for f in ("yuv420p10le", "yuv422p10le", "yuv444p10le", "p010le"):
            if f in offered:
                return f
    return "yuv420p" if "yuv420p" in offered else offered[0]


@contextlib.contextmanager
def _quiet_stderr() -> Iterator[None]:
    """Silence file descriptor 2 (libx264 prints a bad preset there itself, past FFmpeg's log).

    Only in the main thread: fd 2 is the whole process's, and swapping it under the other
    threads of a Dask worker would hide (or lose) what they print; elsewhere it does nothing.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    try:
        sys.stderr.flush()
        saved = os.dup(2)
    except (OSError, ValueError):
        yield
        return
    try:
        with open(os.devnull, "wb") as null:
            os.dup2(null.fileno(), 2)
            yield
    finally:
        os.dup2(saved, 2)
        os.close(saved)


def _check_encoder(
    enc: Any,
    pix: str,
    options: dict[str, str],
    info: Any,
    size: tuple[int, int],
    color_range: int = RANGE_UNSPECIFIED,
) -> None:
    """Open the encoder once with its options (and colour range), so a bad preset fails
    before anything is written."""
    import av

    cc = av.CodecContext.create(enc.name, "w")
    cc.height, cc.width = size
    cc.pix_fmt = pix
    if color_range != RANGE_UNSPECIFIED:
        cc.color_range = color_range
    cc.framerate = info.rate or Fraction(24)
    cc.time_base = encoder_time_base(enc.name, info.time_base, cc.framerate)
    cc.options = dict(options)
    level = av.logging.get_level()
    av.logging.set_level(av.logging.ERROR)  # PyAV's handler, so that Capture sees the messages
    try:
        with av.logging.Capture() as logs, _quiet_stderr():
            cc.open()
    except av.error.FFmpegError as exc:
        said = "; ".join(str(m[2]).strip() for m in logs if m[0] <= av.logging.ERROR)
        if enc.name in _FRAME_TIME_BASE and "fps" in said:  # the input's rate, not an option
            raise InvalidValueError(
                f"--codec {enc.name}: it does not take the input's {cc.framerate} fps (MPEG-1 "
                "takes 23.976, 24, 25, 29.97, 30, 50, 59.94 and 60 fps, MPEG-2 also some "
                "fractions of them); choose another --codec, e.g. libx264"
            ) from None
        raise InvalidValueError(
            f"{enc.name} refused its options ({said or exc.strerror}); "
            "check --preset, --crf and --pix-fmt"
        ) from None
    finally:
        av.logging.set_level(level)


def _starts(mux: str, enc: Any, pix: str, options: dict[str, str], info: Any,
            size: tuple[int, int]) -> bool:  # fmt: skip
    """Whether a ``mux`` file in memory with a stream of the encoder ``enc`` (as it will be
    set up) writes its header: the muxer's own check of the codec."""
    import io

    import av

    try:
        with _quiet_stderr(), av.open(io.BytesIO(), "w", format=mux) as trial:
            rate = info.rate or Fraction(24)
            add_video_stream(trial, enc.name, rate, options, size, pix, info.time_base)
            trial.start_encoding()
    except Exception:  # noqa: BLE001 - av raises several kinds (ValueError, FFmpegError...)
        return False
    return True


def _check_header(
    enc: Any, pix: str, options: dict[str, str], info: Any, size: tuple[int, int], output: Path
) -> None:
    """Refuse a codec whose stream the output's muxer refuses when it writes its header (VP9
    or AV1 in a MOV file: the codec table allows them, the muxer does not), before any frame
    is rendered; the encoder itself opened (:func:`_check_encoder`)."""
    _refuse_unless(enc.name, muxer(output), lambda m: _starts(m, enc, pix, options, info, size))


class _Stop(Exception):
    """Another stage failed or was stopped."""


def _put(q: queue.Queue, item: Any, stop: threading.Event) -> None:
    while True:
        if stop.is_set():
            raise _Stop
        try:
            q.put(item, timeout=0.1)
            return
        except queue.Full:
            continue


def _get(q: queue.Queue, stop: threading.Event) -> Any:
    while True:
        if stop.is_set():
            raise _Stop
        try:
            return q.get(timeout=0.1)
        except queue.Empty:
            continue


_END = object()


def pipeline(
    produce: Iterator[Any],
    work: Callable[[Any], Any],
    consume: Callable[[Any], None],
    finish: Callable[[], None] | None = None,
    size: int = _QUEUE,
) -> int:
    """Run ``consume(work(item))`` for each item of ``produce`` as three stages: ``produce`` in
    a thread (decoding), ``work`` in the calling thread (warping: a Ctrl-C reaches it there),
    ``consume`` in a thread (encoding), then ``finish()`` in that thread; queues of ``size``
    items join them, so memory holds a few items whatever the length. The first error (or
    an interrupt) stops all three and is raised; returns the number of items.

    Examples
    --------
    >>> got = []
    >>> pipeline(iter(range(5)), lambda x: 10 * x, got.append)
    5
    >>> got
    [0, 10, 20, 30, 40]
    """
    stop = threading.Event()
    todo: queue.Queue = queue.Queue(size)
    done: queue.Queue = queue.Queue(size)
    errors: list[BaseException] = []

    def run(f: Callable[[], None]) -> Callable[[], None]:
        def body() -> None:
            try:
                f()
            except _Stop:
                pass
            except BaseException as exc:  # noqa: BLE001 - carried to the calling thread
                errors.append(exc)
                stop.set()

        return body

    def source() -> None:
        for item in produce:
            _put(todo, item, stop)
        _put(todo, _END, stop)

    def sink() -> None:
        while (item := _get(done, stop)) is not _END:
            consume(item)
        if finish is not None:
            finish()

    threads = [threading.Thread(target=run(f), daemon=True) for f in (source, sink)]
    n = 0
    finished = False
    try:
        with _signals.held():  # both threads or neither (see _signals.held)
            for t in threads:
                t.start()
        while (item := _get(todo, stop)) is not _END:
            _put(done, work(item), stop)
            n += 1
        _put(done, _END, stop)
        threads[1].join()
        finished = True
    except _Stop:
        pass
    finally:
        with _signals.held():  # no thread outlives the call, whatever arrives meanwhile
            if errors or not finished:
                stop.set()
            for t in threads:
                if t.is_alive():
                    t.join()
    if errors:
        raise errors[0]
    if stop.is_set():
        raise RuntimeError("the video pipeline stopped early")
    return n


#: how far before a segment's first frame (seconds) a seek that landed after it is tried again,
#: in turn, before the file is decoded from its start
SEEK_BACK_S = (1.0, 4.0, 16.0, 64.0)


class _Overshot(Exception):
    """A seek landed after the frame wanted: its first keyframe, or the first frame decoded
    from it, comes later."""


def frames_from(
    container: Any, start: int, seek: bool = True, reopen: Callable[[], Any] | None = None
) -> Iterator[Any]:
    """The decoded frames of ``container``'s first video stream from presentation time ``start``
    on (in the stream's time base), each as decoding the whole file gives it.

    ``seek``: seek to a keyframe at or before ``start`` rather than decode from the file's
    start. A seek may land after that keyframe: MPEG-TS has no index, so FFmpeg seeks it by
    byte position, and lands on the packet nearest ``start``, a keyframe or not (the decoder
    then drops every frame up to the next keyframe, past the segment). So the packets before
    the first keyframe are dropped, and when that keyframe, or the first frame decoded from
    it, comes after ``start``, the seek is tried again further back (:data:`SEEK_BACK_S`),
    and at last the file is decoded from its start: ``reopen()`` (a fresh container of the
    file, which the caller closes), else ``container`` sought to its start.
    """
    import av

    vin = container.streams.video[0]
    vin.thread_type = "AUTO"
    if seek:
        first = vin.start_time
        targets = [start] + [start - round(Fraction(s) / vin.time_base) for s in SEEK_BACK_S]
        for target in targets:
            if target != start and first is not None and target <= first:
                break  # before the file's start: decode it from there
            try:
                container.seek(target, stream=vin, backward=True, any_frame=False)
            except av.error.FFmpegError:
                continue
            frames = _from_keyframe(container, vin, start)
            try:
                head = next(frames)
            except (_Overshot, StopIteration):
                continue
            yield head
            yield from frames
            return
        if reopen is not None:
            container = reopen()
            vin = container.streams.video[0]
            vin.thread_type = "AUTO"
        else:
            container.seek(0, backward=True, any_frame=False)  # the file's start, in AV_TIME_BASE
    for packet in whole(container.demux(vin)):
        for frame in packet.decode():
            if frame.pts is not None and frame.pts >= start:
                yield frame


def whole(packets: Iterator[Any]) -> Iterator[Any]:
    """``packets`` but those FFmpeg reads short (``is_corrupt``: a truncated file's last one),
    which no frame comes from: decoded, one stopped the decoder ('Invalid data'), or its frame
    threads dropped the frames before it. :func:`~spherewarp.io.segments.frame_times` counts
    the frames so too."""
    for packet in packets:
        if not (packet.is_corrupt and packet.size):
            yield packet


def _from_keyframe(container: Any, vin: Any, start: int) -> Iterator[Any]:
    """After a seek: the frames from ``start`` on, decoded from the first keyframe packet
    (those before it are dropped); :class:`_Overshot`, before any frame, when that keyframe or
    the first frame decoded comes after ``start`` (or no keyframe comes)."""
    keyed = checked = False
    for packet in whole(container.demux(vin)):
        if not keyed:
            if not packet.size:  # the end, and no keyframe
                raise _Overshot
            if not packet.is_keyframe:
                continue
            when = packet.pts if packet.pts is not None else packet.dts
            if when is not None and when > start:
                raise _Overshot
            keyed = True
        for frame in packet.decode():
            if frame.pts is None:
                continue
            if not checked:
                if frame.pts > start:
                    raise _Overshot
                checked = True
            if frame.pts >= start:
                yield frame
    if not keyed:
        raise _Overshot


def _check_output(output: Path | str, hint: str = "") -> None:
    """Refuse an output (a path or a URL) whose extension names no video container
    (``hint`` ends the line)."""
    suffix = Path(str(output).split("?", 1)[0]).suffix
    if suffix.lower() not in VIDEO_EXTENSIONS:
        raise ImageFormatError(
            f"cannot write '{output}': unknown video extension {suffix or '(none)'!r}; "
            f"use one of {', '.join(VIDEO_EXTENSIONS)}{hint}"
        )


def render_video(
    input: str | os.PathLike[str],
    output: str | os.PathLike[str],
    frame_map: FrameMap,
    *,
    codec: str | None = None,
    crf: float | None = None,
    preset: str | None = None,
    pix_fmt: str | None = None,
    overwrite: bool = False,
    force: bool = False,
    spherical: bool | Callable[[Spherical], Spherical | None] = True,
    progress: Callable[[int, int], None] | None = None,
    stereo: str | None = None,
    grid: Any = None,
    out_shape: tuple[int, int] | None = None,
    planar: bool = True,
) -> VideoInfo:
    """Warp every frame of ``input`` and write ``output`` (see the module documentation).

    Parameters
    ----------
    input, output : path
        The video to read; the file to write (``.mp4``, ``.mov``, ``.m4v``, or Matroska
        ``.mkv``, WebM ``.webm``).
    frame_map : callable
        ``frame_map(t) -> (inverse_map, options)``: the map from output points
        to input points for the frame shown at ``t`` seconds, and the keyword
        arguments of :meth:`~spherewarp.render.WarpMap.build` (``interp``,
        ``antialias``...). Returning the same map object again reuses its plan.
    codec, crf, preset, pix_fmt
        The encoder and its options; default ``libx264`` (WebM: ``libvpx-vp9``), CRF 18
        (x265: 20, VP9: 31),
        the encoder's preset, and the input's pixel format when the encoder
        takes it (a 10-bit input stays 10-bit), else ``yuv420p``.
    overwrite : bool
        Replace an existing ``output``.
    force : bool
        Accept a frame (an eye, for stereo) that is not 2:1.
    spherical : bool or callable
        Write spherical metadata: equirectangular (V1 and V2) with the stereo
        layout on a panorama, the layout alone (``st3d``) on another view of a
        stereo input, none else. A callable gets the metadata to write (the
        layout, and the input's pose) and returns what to write instead (None:
        nothing), e.g. the pose turned with the map.
    progress : callable, optional
        ``progress(done, total)`` after each frame (``total`` 0 when unknown).
    stereo : {"mono", "tb", "sbs"}, optional
        The input's stereo layout (default: its ``st3d`` metadata, else mono):
        the map is planned for one eye and applied to each eye's half, and the
        output keeps the layout (:class:`~spherewarp.io.stereo.FramePlan`).
    grid : Grid or callable, optional
        Each eye's output grid (a little planet, a flat view...), or
        ``grid(eye_shape) -> Grid``; default: the equirectangular panorama.
    out_shape : (height, width), optional
        One eye's output size without a grid (default: the input's).
    planar : bool
        Warp a 4:2:0 frame's planes as they are when the encoder writes the
        same pixel format (:mod:`spherewarp.io.planes`); False: always through RGB.

    Returns
    -------
    VideoInfo
        The input's description.

    Raises
    ------
    ImageFormatError, InvalidValueError, OutputExistsError
        For a bad input, output or option; nothing is written then.
    """
    input, output = Path(input), Path(output)
    _check_output(output)
    s = prepare(input, output, codec, crf, preset, pix_fmt, stereo, grid, out_shape, force)
    import av

    with atomic_file(output, overwrite=overwrite) as tmp:
        src = _open(input)
        try:
            from .segments import mux_options  # the frames' times exactly, not in 1/1000 s

            fmt = muxer(output)
            options = mux_options(fmt, Fraction(src.streams.video[0].time_base))
            dst = av.open(str(tmp), "w", format=fmt, options=options)
            try:
                _transcode(
                    src, dst, s.info, s.codec, s.out_pix, s.rgb, s.options, frame_map, progress,
                    s.plan_maker(planar), s.size, s.color_range, s.colors,
                )  # fmt: skip
            finally:
                dst.close()
        finally:
            src.close()
        write_spherical(tmp, output_spherical(s.info, s.layout, s.grid, spherical))
    return s.info


@dataclass
class Settings:
    """What :func:`prepare` settles before any frame is read: the input, its layout and
    grid, the encoder and its options (all picklable, for segment workers)."""

    info: VideoInfo
    layout: str
    grid: Any
    size: tuple[int, int]
    codec: str
    out_pix: str
    rgb: str
    options: dict[str, str]
    out_shape: tuple[int, int] | None
    force: bool
    color_range: int = RANGE_UNSPECIFIED
    colors: tuple[int, int, int] = COLORS_UNSPECIFIED

    def plan_maker(self, planar: bool) -> Callable[[SphereMap, dict[str, Any], str], Any]:
        """``make_plan(inverse, build_options, in_pix)``: the frame plan of one map."""
        info, layout, grid, out_shape, force = (
            self.info, self.layout, self.grid, self.out_shape, self.force
        )  # fmt: skip

        def make_plan(inverse: SphereMap, opts: dict[str, Any], in_pix: str) -> Any:
            # planes warped by PlaneTaps need only the render plan, not a WarpMap
            lazy = planar and in_pix == self.out_pix and in_pix in PLANAR_FORMATS[:2]

            def make(shape: tuple[int, int], eye_out: tuple[int, int] | None) -> FramePlan:
                return FramePlan(
                    inverse, shape, stereo=layout, grid=grid, out_shape=eye_out or out_shape,
                    lazy=lazy, **{"force": force, **opts},
                )  # fmt: skip

            return frame_plan(
                make, (info.height, info.width), in_pix, self.out_pix, self.rgb, planar
            )

        return make_plan


def prepare(
    input: Path,
    output: Path,
    codec: str | None,
    crf: float | None,
    preset: str | None,
    pix_fmt: str | None,
    stereo: str | None,
    grid: Any,
    out_shape: tuple[int, int] | None,
    force: bool,
    check: bool = True,
) -> Settings:
    """Probe ``input`` and settle the encoder for ``output``, refusing a bad option before
    anything is written (``check``: also open the encoder once with its options)."""
    info = probe(input)
    layout, grid, size = frame_layout(info, input, stereo, grid, out_shape, force)
    enc = _encoder(default_codec(output) if codec is None else codec)
    out_pix = _pick_pix_fmt(enc, info.pix_fmt, pix_fmt)
    _check_even(size, out_pix)
    rgb = _rgb_format(enc, info.pix_fmt, out_pix)
    check_container(enc, output)
    options = encoder_options(enc, crf, preset)
    color_range = output_range(out_pix, info.pix_fmt, info.color_range)
    if check:
        _check_encoder(enc, out_pix, options, info, size, color_range)
        _check_header(enc, out_pix, options, info, size, output)
    colors = output_colors(out_pix, info.pix_fmt, info.colors)
    return Settings(
        info, layout, grid, size, enc.name, out_pix, rgb, options, out_shape, force, color_range,
        colors,
    )  # fmt: skip


def _has_alpha(pix_fmt: str) -> bool:
    f = _video_format(pix_fmt)
    return f is not None and any(c.is_alpha for c in f.components)


def _rgb_format(enc: Any, in_pix: str, out_pix: str) -> str:
    """The RGB format frames are warped in when not plane by plane: ``rgb24`` (``rgb48le``
    for more than 8 bits), with alpha (``rgba``, ``rgba64le``) when both the input and the
    encoder's ``out_pix`` have it; warns that an input's alpha is dropped when ``out_pix``
    has none. Refuses alpha for VP8/VP9, which write it beside the frames (in WebM's block
    additions), where spherewarp's segments and joins do not carry it."""
    deep = _depth(out_pix) > 8
    if _has_alpha(out_pix) and enc.name in ("libvpx", "libvpx-vp9"):
        raise InvalidValueError(
            f"--pix-fmt {out_pix}: spherewarp cannot write {enc.name}'s alpha (kept beside "
            "the frames); for alpha use --codec png, prores_ks or ffv1 (.mov or .mkv), or "
            "choose a --pix-fmt without alpha"
        )
    if _has_alpha(in_pix):
        if _has_alpha(out_pix):
            return "rgba64le" if deep else "rgba"
        warnings.warn(
            f"the input's alpha channel is dropped: {out_pix} has none (for alpha use e.g. "
            "--codec png --pix-fmt rgba, in .mov or .mkv)",
            stacklevel=4,
        )
    return _HIGH_DEPTH_RGB if deep else "rgb24"


def frame_layout(
    info: VideoInfo,
    input: Path,
    stereo: str | None,
    grid: Any,
    out_shape: tuple[int, int] | None,
    force: bool,
) -> tuple[str, Any, tuple[int, int]]:
    """The stereo layout, the output grid (resolved for an eye) and the output frame's size;
    refuses an eye that is not 2:1 unless ``force``, and frames that players show turned (a
    display matrix: :attr:`VideoInfo.display`) unless ``force``.

    A panorama is what players show: a phone's rotation tag on an equirectangular video is
    a mistake or a portrait clip, and a map applied to the stored frames would turn another
    sphere than the one seen (the output's yaw would be the input's pitch, or its opposite);
    writing the matrix on the output would show the warped panorama turned. So such an
    input is refused, unless ``force`` (warp the frames as stored, the rotation dropped
    with a warning)."""
    _check_projection(info, input)
    if info.display is not None:
        if not force:
            raise InvalidValueError(
                f"'{input}' is shown {info.display} (a display matrix), but its frames are "
                "warped as stored: make it upright first (ffmpeg -i IN OUT applies it), or "
                "pass --force to warp the frames as stored (the rotation is dropped)"
            )
        warnings.warn(
            f"'{input}' is shown {info.display} (a display matrix): its frames are warped "
            "as stored and the output has no display rotation",
            stacklevel=3,
        )
    layout = stereo_layout(info, stereo)
    eye_h, eye_w = eye_shape((info.height, info.width), layout)
    if eye_w != 2 * eye_h and not force:
        what = "" if layout == "mono" else f" each eye ({layout} stereo) is {eye_w}x{eye_h},"
        raise InvalidValueError(
            f"'{input}' is {info.width}x{info.height},{what} not 2:1 (equirectangular); "
            "pass --force to warp it anyway",
        )
    grid = resolve_grid(grid, (eye_h, eye_w))
    return layout, grid, FramePlan.output_shape((eye_h, eye_w), layout, grid, out_shape)


def _check_projection(info: VideoInfo, input: Path) -> None:
    """Refuse an input whose spherical metadata says its frame is not the whole sphere in
    equirectangular: cropped equirectangular (non-zero ``equi`` bounds: VR180 and others), a
    cubemap or a mesh. Warping the frame as a full panorama and calling the output one (as
    was done) gives a wrong picture and wrong metadata; --force does not change that."""
    sph = info.spherical
    if sph is None:
        return
    if sph.projection in ("cubemap", "mesh"):
        raise InvalidValueError(
            f"'{input}' is a {sph.projection} 360° video (its spherical metadata), which "
            "spherewarp does not map: convert it to equirectangular first"
        )
    if sph.projection == "equirectangular" and any(b > 0 for b in sph.bounds):
        top, bottom, left, right = sph.bounds
        what = "a VR180 (half-sphere)" if abs(left + right - 0.5) < 1e-3 else "a cropped"
        raise InvalidValueError(
            f"'{input}' is {what} equirectangular video (its spherical metadata's bounds crop "
            f"off top {top:.4g}, bottom {bottom:.4g}, left {left:.4g}, right {right:.4g} of "
            "the sphere), which spherewarp does not map yet: pad it to the full 360x180 "
            "sphere first"
        )


def stereo_layout(info: VideoInfo, stereo: str | None) -> str:
    """The stereo layout to warp by: ``stereo`` when given, else the input's metadata's."""
    if stereo is not None:
        return parse_stereo(stereo)
    return info.spherical.stereo if info.spherical is not None else "mono"


def output_spherical(
    info: VideoInfo,
    layout: str,
    grid: Any,
    spherical: bool | Callable[[Spherical], Spherical | None],
) -> Spherical | None:
    """The spherical metadata of an output (see :func:`render_video`'s ``spherical``)."""
    if not spherical:
        return None
    if not is_panorama(grid):
        return Spherical(projection="", stereo=layout) if layout != "mono" else None
    meta = Spherical(stereo=layout)
    if info.spherical is not None:
        sph = info.spherical
        meta.yaw, meta.pitch, meta.roll = sph.yaw, sph.pitch, sph.roll
    return spherical(meta) if callable(spherical) else Spherical(stereo=layout)


def _check_even(size: tuple[int, int], pix: str) -> None:
    """Refuse odd sides that ``pix``'s subsampled chroma cannot hold."""
    h, w = size
    both = pix.startswith(("yuv420", "yuvj420", "yuva420", "nv12", "nv21", "p010", "p016"))
    wide = pix.startswith(("yuv422", "yuvj422", "yuva422", "nv16"))
    if (both and (h % 2 or w % 2)) or (wide and w % 2):
        raise InvalidValueError(
            f"the output is {w}x{h}; {pix} needs even sides: choose a --size with even sides"
        )


#: tags the muxer writes itself (or that describe the input file, not the output's streams)
_OWN_TAGS = {
    "encoder", "major_brand", "minor_version", "compatible_brands", "duration", "vendor_id",
    "bps", "number_of_frames", "number_of_bytes",
}  # fmt: skip


def _tags(metadata: dict[str, str]) -> dict[str, str]:
    """``metadata`` less the tags the muxer writes itself (:data:`_OWN_TAGS`, Matroska's
    statistics: ``DURATION``, ``BPS-eng``, ``_STATISTICS_*``)."""
    keep = {}
    for key, value in metadata.items():
        low = key.lower()
        if low.split("-", 1)[0] in _OWN_TAGS or low.startswith("_statistics"):
            continue
        keep[key] = value
    return keep


def is_chapter_track(container: Any, stream: Any) -> bool:
    """Whether ``stream`` is an MP4/MOV chapter track (a text track FFmpeg reads as
    ``container.chapters()``, and shows as a ``bin_data`` data stream)."""
    return stream.type == "data" and codec_name(stream) == "bin_data" and bool(container.chapters())


def is_timecode_track(stream: Any) -> bool:
    """Whether ``stream`` is a MOV/MP4 timecode (``tmcd``) track: FFmpeg reads it as a data
    stream with a ``timecode`` tag, which it also puts on the video stream."""
    return stream.type == "data" and "timecode" in stream.metadata


def keep_metadata(
    src: Any, dst: Any, vin: Any, vout: Any, copies: dict[int, Any], end: float | None = None
) -> None:
    """Give the output ``dst`` the input ``src``'s container tags (title, artist...), its
    chapters (those that start before ``end`` seconds, when given), and each stream's tags
    (language, title, handler; the video's ``timecode``, from which a MOV/MP4 muxer writes
    a timecode track) and disposition (which audio track is the default): ``vout`` gets
    ``vin``'s, each copy of ``copies`` (:func:`copy_streams`) its stream's. Call it before
    the first packet is muxed.
    """
    dst.metadata.update(_tags(src.metadata))
    chapters = [
        c for c in src.chapters() if end is None or c["start"] * c["time_base"] < end
    ]  # fmt: skip
    if chapters:
        dst.set_chapters(chapters)
    pairs = [(vin, vout)] + [(s, copies[s.index]) for s in src.streams if s.index in copies]
    for s, out in pairs:
        tags = _tags(s.metadata)
        if "name" in tags and "title" not in tags:  # an MP4 track's title reads as its 'name'
            tags["title"] = tags.pop("name")
        out.metadata.update(tags)
        out.disposition = int(s.disposition)
    timecodes = [s.metadata["timecode"] for s in src.streams if is_timecode_track(s)]
    if timecodes and "timecode" not in vout.metadata:
        vout.metadata["timecode"] = timecodes[0]
    cc = vout.codec_context
    rate = vin.average_rate or vin.guessed_rate
    if "timecode" in vout.metadata and cc is not None and rate:
        # the timecode track counts frames at the input's rate (a joined part's says another)
        cc.framerate = rate


def copy_streams(src: Any, dst: Any, vin: Any) -> dict[int, Any]:
    """Add to ``dst`` a copy of each stream of ``src`` but ``vin`` that its container holds
    (``{input stream index: output stream}``), warning of each one dropped."""
    copies: dict[int, Any] = {}
    mux = dst.format.name
    for s in src.streams:
        if s is vin:
            continue
        name = codec_name(s)
        if is_chapter_track(src, s) or (is_timecode_track(s) and mux in ("mov", "mp4")):
            continue  # made anew from the chapters, the video's timecode (keep_metadata)
        if is_timecode_track(s):
            warnings.warn(
                f"stream #{s.index} (timecode track) is dropped: "
                f"{_CONTAINER_NAMES.get(mux, 'the output')} file holds no timecode track (the "
                f"video keeps its timecode tag, {s.metadata['timecode']})",
                stacklevel=4,
            )
            continue
        if s.type == "video":
            why = "only the first video stream is warped"
        elif s.type not in _COPIED_KINDS:
            why = "only audio and subtitle streams are copied"
        elif not muxer_takes(s, mux):
            why = f"{_CONTAINER_NAMES.get(mux, 'the output')} file cannot hold {s.type} in {name}"
        else:
            copies[s.index] = dst.add_stream_from_template(s)
            continue
        warnings.warn(f"stream #{s.index} ({s.type}, {name}) is dropped: {why}", stacklevel=4)
    return copies


def _transcode(
    src: Any,
    dst: Any,
    info: VideoInfo,
    codec: str,
    out_pix: str,
    rgb: str,
    options: dict[str, str],
    frame_map: FrameMap,
    progress: Callable[[int, int], None] | None,
    make_plan: Callable[[SphereMap, dict[str, Any], str], Any],
    size: tuple[int, int],
    color_range: int = RANGE_UNSPECIFIED,
    colors: tuple[int, int, int] = COLORS_UNSPECIFIED,
) -> None:
    import av

    vin = src.streams.video[0]
    vin.thread_type = "AUTO"
    rate = vin.average_rate or vin.guessed_rate or Fraction(24)
    vout = add_video_stream(
        dst, codec, rate, options, size, out_pix, vin.time_base, color_range, colors
    )  # fmt: skip
    copies = copy_streams(src, dst, vin)
    keep_metadata(src, dst, vin, vout, copies)
    total = info.frames
    plan: tuple[Any, Any] | None = None
    done = 0

    def items() -> Iterator[Any]:
        wanted = [vin, *(s for s in src.streams if s.index in copies)]
        for packet in src.demux(wanted):
            if packet.stream is vin:
                if not (packet.is_corrupt and packet.size):  # cut short (:func:`whole`)
                    yield from packet.decode()
            elif packet.dts is not None:
                yield packet

    def warp(item: Any) -> Any:
        nonlocal plan, done
        if isinstance(item, av.Packet):
            return item
        t = float(item.pts * item.time_base) if item.pts is not None else done / rate
        inverse, opts = frame_map(t)
        if plan is None or plan[0] is not inverse:
            plan = (inverse, make_plan(inverse, opts, item.format.name))
        frame = plan[1].apply(item)
        frame.pts, frame.time_base = item.pts, item.time_base
        done += 1
        if progress is not None:
            progress(done, max(total, done))
        return frame

    def write(item: Any) -> None:
        if isinstance(item, av.Packet):
            item.stream = copies[item.stream_index]
            dst.mux(item)
        else:
            dst.mux(encode(vout, item))

    pipeline(items(), warp, write, lambda: dst.mux(encode(vout, None)))
