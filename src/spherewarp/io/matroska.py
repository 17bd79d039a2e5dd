"""Spherical metadata in Matroska/WebM files (``.mkv``, ``.webm``): read it, and write it.

Matroska keeps what MP4's ``st3d``/``sv3d`` boxes say in the video track's
``Video`` element: ``StereoMode`` (1: side by side, left eye first; 3: top
and bottom, left eye first; 2 and 11 the same with the right eye first) and
``Projection`` holding ``ProjectionType`` (1: equirectangular),
``ProjectionPrivate`` (for equirectangular, the body of an ``equi`` box:
version and flags, then the bounds top, bottom, left, right in 0.32 fixed
point) and ``ProjectionPoseYaw``/``Pitch``/``Roll`` (floats, degrees, written
as FFmpeg writes and reads them: the values of ``sv3d``'s pose).

PyAV cannot hand the muxer the stream side data FFmpeg would write these
from, so :func:`write_matroska_spherical` edits the file FFmpeg wrote: it
rebuilds the ``Tracks`` element and takes the bytes it gains from the
``Void`` element FFmpeg reserves before it (after the ``SeekHead``), so that
nothing after ``Tracks`` moves; the ``SeekHead`` entries of what moved
(``Info``, ``Tracks``) and the EBML CRC-32 elements of the rebuilt elements
are rewritten.

Examples
--------
>>> element(0x53B8, uint(3)).hex()   # StereoMode 3: top-bottom
'53b88103'
>>> read_vint(bytes.fromhex("4123"), 0)
(291, 2)
"""

from __future__ import annotations

import os
import struct
import zlib
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from ..errors import ImageFormatError

if TYPE_CHECKING:  # spherical imports this module
    from .spherical import Spherical

__all__ = ["element", "is_matroska", "read_matroska_spherical", "uint", "write_matroska_spherical"]

MAGIC = bytes.fromhex("1a45dfa3")
SEGMENT, SEEKHEAD, SEEK, SEEKID, SEEKPOS = 0x18538067, 0x114D9B74, 0x4DBB, 0x53AB, 0x53AC
INFO, TRACKS, TRACKENTRY, TRACKTYPE, VIDEO, CLUSTER = (
    0x1549A966, 0x1654AE6B, 0xAE, 0x83, 0xE0, 0x1F43B675,
)  # fmt: skip
VOID, CRC32 = 0xEC, 0xBF
STEREOMODE, PROJECTION, PROJ_TYPE, PROJ_PRIVATE = 0x53B8, 0x7670, 0x7671, 0x7672
POSE_YAW, POSE_PITCH, POSE_ROLL = 0x7673, 0x7674, 0x7675
_STEREO_OUT = {"left-right": 1, "top-bottom": 3}
_STEREO_IN = {1: "left-right", 11: "left-right", 2: "top-bottom", 3: "top-bottom"}


@dataclass
class _El:
    """An element: its ID, where it starts, its header length and its data length."""

    id: int
    start: int
    head: int
    size: int

    @property
    def data(self) -> int:
        return self.start + self.head

    @property
    def end(self) -> int:
        return self.start + self.head + self.size


def read_vint(data: bytes, pos: int, keep_marker: bool = False) -> tuple[int, int]:
    """An EBML variable-length integer at ``pos``: (value, length); ``keep_marker`` for IDs."""
    if pos >= len(data):
        raise ImageFormatError("a truncated Matroska element")
    first = data[pos]
    n = 1
    while n <= 8 and not first & (0x80 >> (n - 1)):
        n += 1
    if n > 8 or pos + n > len(data):
        raise ImageFormatError("a bad Matroska element header")
    value = first if keep_marker else first & ((0x80 >> (n - 1)) - 1)
    for b in data[pos + 1 : pos + n]:
        value = (value << 8) | b
    return value, n


def _size_vint(size: int, length: int | None = None) -> bytes:
    """``size`` as an EBML size of ``length`` bytes (default: the shortest)."""
    n = length or next(k for k in range(1, 9) if size < (1 << (7 * k)) - 1)
    if size >= (1 << (7 * n)) - 1:
        raise ImageFormatError(f"a Matroska size {size} does not fit {n} bytes")
    return ((1 << (7 * n)) | size).to_bytes(n, "big")


def _id_bytes(eid: int) -> bytes:
    return eid.to_bytes((eid.bit_length() + 7) // 8, "big")


def element(eid: int, payload: bytes, size_length: int | None = None) -> bytes:
    """An element: its ID, the size of ``payload``, ``payload``."""
    return _id_bytes(eid) + _size_vint(len(payload), size_length) + payload


def uint(value: int, length: int | None = None) -> bytes:
    """An unsigned integer payload (the shortest, or ``length`` bytes)."""
    n = length or max(1, (value.bit_length() + 7) // 8)
    return value.to_bytes(n, "big")


def _children(data: bytes, start: int, end: int) -> list[_El]:
    out = []
    pos = start
    while pos < end:
        eid, n = read_vint(data, pos, keep_marker=True)
        size, m = read_vint(data, pos + n)
        if size == (1 << (7 * m)) - 1:  # unknown size: to the end of the parent
            size = end - pos - n - m
        el = _El(eid, pos, n + m, size)
        if el.end > end:
            raise ImageFormatError("a Matroska element runs past its parent")
        out.append(el)
        pos = el.end
    return out


def _uint_of(data: bytes, el: _El) -> int:
    return int.from_bytes(data[el.data : el.end], "big")


def _float_of(data: bytes, el: _El) -> float:
    raw = data[el.data : el.end]
    if len(raw) == 4:
        return struct.unpack(">f", raw)[0]
    if len(raw) == 8:
        return struct.unpack(">d", raw)[0]
    return 0.0


def is_matroska(path: str | os.PathLike[str]) -> bool:
    """Whether ``path`` starts with the EBML header of a Matroska/WebM file."""
    try:
        with open(path, "rb") as f:
            return f.read(4) == MAGIC
    except OSError:
        return False


def _segment(data: bytes, path: Path) -> _El:
    """The Segment element (after the EBML header), read from its header alone."""
    try:
        if data[:4] != MAGIC:
            raise ImageFormatError("no EBML header")
        pos = _header_and_size(data, 0)
        eid, n = read_vint(data, pos, keep_marker=True)
        size, m = read_vint(data, pos + n)
    except ImageFormatError:
        raise ImageFormatError(f"'{path}' is not a Matroska file") from None
    if eid != SEGMENT:
        raise ImageFormatError(f"'{path}' is not a Matroska file")
    if size == (1 << (7 * m)) - 1:
        size = 2**62  # unknown size (a live stream): to the end
    return _El(eid, pos, n + m, size)


def _read_head(path: Path) -> bytes:
    """The file up to its first cluster's header (all the metadata before the media)."""
    size = 1 << 16
    total = os.path.getsize(path)
    while True:
        with open(path, "rb") as f:
            data = f.read(size)
        try:
            seg = _segment(data, path)
            level1 = _level1(data, seg)
            if level1 and (level1[-1].id == CLUSTER or level1[-1].end >= min(seg.end, total)):
                return data
        except ImageFormatError:
            if size >= total:
                raise
        if size >= total:
            return data
        size *= 4


def _level1(data: bytes, seg: _El) -> list[_El]:
    """The segment's children up to the first cluster (all that may hold the tracks)."""
    out = []
    pos = seg.data
    while pos < min(seg.end, len(data)):
        eid, n = read_vint(data, pos, keep_marker=True)
        size, m = read_vint(data, pos + n)
        el = _El(eid, pos, n + m, size)
        if el.id != CLUSTER and el.end > len(data):
            raise ImageFormatError("a truncated Matroska element")
        out.append(el)
        if el.id == CLUSTER:
            break
        pos = el.end
    return out


def _header_and_size(data: bytes, pos: int) -> int:
    _, n = read_vint(data, pos, keep_marker=True)
    size, m = read_vint(data, pos + n)
    return n + m + size


def _video_track(data: bytes, tracks: _El) -> tuple[_El, _El] | None:
    """The first video TrackEntry and its Video element."""
    for entry in _children(data, tracks.data, tracks.end):
        if entry.id != TRACKENTRY:
            continue
        kids = _children(data, entry.data, entry.end)
        kind = next((k for k in kids if k.id == TRACKTYPE), None)
        video = next((k for k in kids if k.id == VIDEO), None)
        if kind is not None and _uint_of(data, kind) == 1 and video is not None:
            return entry, video
    return None


def read_matroska_spherical(path: str | os.PathLike[str]) -> Spherical | None:
    """The spherical metadata (a :class:`~spherewarp.io.spherical.Spherical`, ``versions``
    ``{"mkv"}``) of the first video track of a Matroska file, or None when it has none."""
    from .spherical import Spherical

    path = Path(path)
    data = _read_head(path)
    seg = _segment(data, path)
    tracks = next((e for e in _level1(data, seg) if e.id == TRACKS), None)
    found = None if tracks is None else _video_track(data, tracks)
    if found is None:
        return None
    meta = Spherical(versions={"mkv"})
    seen = False
    for k in _children(data, found[1].data, found[1].end):
        if k.id == STEREOMODE:
            meta.stereo = _STEREO_IN.get(_uint_of(data, k), "mono")
            seen = seen or meta.stereo != "mono"
        elif k.id == PROJECTION:
            for p in _children(data, k.data, k.end):
                if p.id == PROJ_TYPE:
                    kind = _uint_of(data, p)
                    meta.projection = {1: "equirectangular", 2: "cubemap", 3: "mesh"}.get(
                        kind, "rectangular"
                    )
                    seen = seen or kind != 0
                elif p.id == PROJ_PRIVATE and p.size >= 20:
                    vals = struct.unpack_from(">IIII", data, p.data + 4)
                    meta.bounds = tuple(v / 2**32 for v in vals)  # type: ignore[assignment]
                elif p.id in (POSE_YAW, POSE_PITCH, POSE_ROLL):
                    name = {POSE_YAW: "yaw", POSE_PITCH: "pitch", POSE_ROLL: "roll"}[p.id]
                    setattr(meta, name, _float_of(data, p))
    return meta if seen else None


def _projection(meta: Spherical) -> bytes:
    fixed = (min(2**32 - 1, round(b * 2**32)) for b in meta.bounds)
    private = struct.pack(">I", 0) + struct.pack(">IIII", *fixed)
    body = element(PROJ_TYPE, uint(1)) + element(PROJ_PRIVATE, private)
    for eid, value in ((POSE_YAW, meta.yaw), (POSE_PITCH, meta.pitch), (POSE_ROLL, meta.roll)):
        if value:
            body += element(eid, struct.pack(">f", float(value)))
    return element(PROJECTION, body)


def _with_crc(eid: int, kids: bytes, had_crc: bool) -> bytes:
    """A level-1 element of ``kids``, led by a CRC-32 of them when the original had one."""
    if had_crc:
        kids = element(CRC32, struct.pack("<I", zlib.crc32(kids))) + kids
    return element(eid, kids)


def write_matroska_spherical(path: str | os.PathLike[str], meta: Spherical | None = None) -> None:
    """Put spherical metadata on the first video track of the Matroska file ``path``, in
    place: StereoMode for a stereo layout, Projection for an equirectangular panorama (a
    :class:`~spherewarp.io.spherical.Spherical` whose ``projection`` is another
    writes the layout alone); ``meta=None`` removes both.

    Raises
    ------
    ImageFormatError
        When the file is not Matroska, has no video track, or has no ``Void`` room
        before its tracks (FFmpeg's muxer always leaves some).
    """
    path = Path(path)
    data = _read_head(path)
    seg = _segment(data, path)
    level1 = _level1(data, seg)
    tracks = next((e for e in level1 if e.id == TRACKS), None)
    found = None if tracks is None else _video_track(data, tracks)
    if tracks is None or found is None:
        raise ImageFormatError(f"'{path}' has no video track to mark")
    entry, video = found
    added = b""
    if meta is not None and meta.stereo in _STEREO_OUT:
        added += element(STEREOMODE, uint(_STEREO_OUT[meta.stereo]))
    if meta is not None and meta.projection == "equirectangular":
        added += _projection(meta)
    kept = b"".join(
        data[k.start : k.end]
        for k in _children(data, video.data, video.end)
        if k.id not in (STEREOMODE, PROJECTION)
    )
    new_video = element(VIDEO, kept + added)
    entry_kids = b"".join(
        new_video if k.id == VIDEO else data[k.start : k.end]
        for k in _children(data, entry.data, entry.end)
    )
    new_entry = element(TRACKENTRY, entry_kids)
    kids = _children(data, tracks.data, tracks.end)
    had_crc = bool(kids) and kids[0].id == CRC32
    body = b"".join(
        new_entry if k.start == entry.start else data[k.start : k.end]
        for k in kids
        if k.id != CRC32
    )
    new_tracks = _with_crc(TRACKS, body, had_crc)
    grow = len(new_tracks) - (tracks.end - tracks.start)
    # the room: a Void before the tracks, shrunk (or grown) by as much
    voids = [e for e in level1 if e.id == VOID and e.end <= tracks.start]
    if not voids:
        raise ImageFormatError(f"'{path}' has no room before its tracks for the metadata")
    void = voids[-1]
    room = void.end - void.start - grow
    if room < 2:
        raise ImageFormatError(f"'{path}' has too little room before its tracks for the metadata")
    filler = room - 9 if room >= 9 else room - 2
    new_void = element(VOID, bytes(filler), 8 if room >= 9 else 1)
    moved = [e for e in level1 if void.end <= e.start <= tracks.start]
    head = data[: void.start]
    heads = [e for e in level1 if e.id == SEEKHEAD and e.end <= void.start]
    if heads:  # the seek entries of what moved: rel. to the segment's data, grow bytes back
        sh = heads[0]
        shifted = {e.start - seg.data: e.start - seg.data - grow for e in moved}
        head = head[: sh.start] + _seekhead(data, sh, shifted) + head[sh.end :]
        if len(head) != void.start:
            raise ImageFormatError(f"'{path}': rewriting its seek head changed its size")
    middle = b"".join(data[e.start : e.end] for e in moved if e.id != TRACKS)
    out = head + new_void + middle + new_tracks
    if len(out) != tracks.end:
        raise ImageFormatError(f"'{path}': the Matroska rewrite would move the clusters")
    with open(path, "r+b") as f:
        f.write(out)


def _seekhead(data: bytes, sh: _El, shifted: dict[int, int]) -> bytes:
    """The SeekHead with the positions in ``shifted`` changed (each in as many bytes)."""
    kids = _children(data, sh.data, sh.end)
    had_crc = bool(kids) and kids[0].id == CRC32
    parts = []
    for k in kids:
        if k.id == CRC32:
            continue
        if k.id != SEEK:
            parts.append(data[k.start : k.end])
            continue
        inner = []
        for s in _children(data, k.data, k.end):
            raw = data[s.start : s.end]
            if s.id == SEEKPOS:
                old = _uint_of(data, s)
                if old in shifted:
                    raw = element(SEEKPOS, uint(shifted[old], s.size), s.head - 2)
            inner.append(raw)
        parts.append(element(SEEK, b"".join(inner), k.head - 2))
    body = b"".join(parts)
    if had_crc:
        body = element(CRC32, struct.pack("<I", zlib.crc32(body))) + body
    return _id_bytes(SEEKHEAD) + _size_vint(len(body), sh.head - 4) + body
