"""Spherical video metadata in MP4/MOV files: read it, and write it on an equirectangular video.

Two forms are read and written, as YouTube, players and headsets look for them:

* Spherical Video V2 (the ``sv3d``/``st3d`` boxes inside the video track's sample
  entry, ``avc1``/``hvc1``...): ``st3d`` (stereo mode), ``sv3d`` holding ``svhd``
  (the writing tool's name; ffprobe ignores ``sv3d`` without it) and ``proj``
  holding ``prhd`` (pose: yaw, pitch, roll in 16.16 fixed point) and ``equi``
  (the projection bounds top, bottom, left, right in 0.32 fixed point).
* Spherical Video V1: a ``uuid`` box (``ffcc8263-f855-4a93-8814-587a02521fdd``) in
  the video ``trak`` holding the ``GSpherical`` XML.

Writing rewrites the ``moov`` box with the new boxes and every enclosing box's
size fixed; when ``moov`` comes before the media data, the chunk offsets
(``stco``/``co64``) are moved by the growth.

Examples
--------
>>> st3d = box(b"st3d", b"\\0\\0\\0\\0" + bytes([0]))
>>> st3d.hex()
'0000000d737433640000000000'
>>> [(b.kind, len(b.payload)) for b in parse_boxes(st3d + st3d)]
[(b'st3d', 5), (b'st3d', 5)]
"""

from __future__ import annotations

import os
import struct
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import ImageFormatError

__all__ = [
    "Box",
    "Spherical",
    "box",
    "parse_boxes",
    "read_spherical",
    "write_spherical",
    "V1_UUID",
]

V1_UUID = bytes.fromhex("ffcc8263f8554a938814587a02521fdd")
#: boxes that hold other boxes (and nothing else) on the way to the sample entries and chunk offsets
_CONTAINERS = {b"moov", b"trak", b"mdia", b"minf", b"stbl", b"edts", b"udta"}
#: sample entries of video codecs: 78 bytes of fields, then child boxes
_VIDEO_ENTRIES = {b"avc1", b"avc3", b"hvc1", b"hev1", b"vp09", b"av01", b"mp4v", b"encv"}
_VISUAL_FIELDS = 78
_TOOL = "spherewarp"


@dataclass
class Box:
    """One ISO base media box: its four-character ``kind`` and ``payload`` (after the header)."""

    kind: bytes
    payload: bytes
    children: list[Box] | None = None

    def to_bytes(self) -> bytes:
        """The box with a header (children, when parsed, replace the payload)."""
        return box(self.kind, self.payload)


def box(kind: bytes, payload: bytes) -> bytes:
    """A box: a 32-bit size (64-bit when needed), the kind, the payload.

    Examples
    --------
    >>> box(b"free", b"ab")
    b'\\x00\\x00\\x00\\nfreeab'
    """
    size = 8 + len(payload)
    if size < 2**32:
        return struct.pack(">I4s", size, kind) + payload
    return struct.pack(">I4sQ", 1, kind, size + 8) + payload


def _full(version: int, flags: int, body: bytes) -> bytes:
    return struct.pack(">I", (version << 24) | flags) + body


def parse_boxes(data: bytes) -> list[Box]:
    """Split ``data`` into boxes (not recursing); raise ImageFormatError on a bad size.

    Examples
    --------
    >>> parse_boxes(box(b"free", b""))
    [Box(kind=b'free', payload=b'', children=None)]
    """
    out = []
    pos = 0
    while pos + 8 <= len(data):
        size, kind = struct.unpack_from(">I4s", data, pos)
        head = 8
        if size == 1:
            if pos + 16 > len(data):
                raise ImageFormatError("a truncated MP4 box")
            size = struct.unpack_from(">Q", data, pos + 8)[0]
            head = 16
        elif size == 0:
            size = len(data) - pos
        if size < head or pos + size > len(data):
            raise ImageFormatError(f"a bad MP4 box size ({kind!r})")
        out.append(Box(kind, data[pos + head : pos + size]))
        pos += size
    return out


@dataclass
class Spherical:
    """The spherical metadata of a video track.

    Attributes
    ----------
    projection : str
        ``"equirectangular"`` (the only one written with V1/V2 spherical boxes; any
        other value writes the stereo layout alone, ``st3d``, for a view that is
        not a panorama).
    stereo : str
        ``"mono"``, ``"top-bottom"`` or ``"left-right"``.
    yaw, pitch, roll : float
        The pose in degrees.
    bounds : (top, bottom, left, right)
        The equirectangular projection bounds, fractions of the frame cropped off.
    versions : set of str
        Where it was found: ``"v1"`` and/or ``"v2"``; ``"mkv"`` in a Matroska file.
    """

    projection: str = "equirectangular"
    stereo: str = "mono"
    yaw: float = 0.0
    pitch: float = 0.0
    roll: float = 0.0
    bounds: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)
    versions: set[str] = field(default_factory=set)


_STEREO = {0: "mono", 1: "top-bottom", 2: "left-right"}


def _v2_boxes(meta: Spherical) -> bytes:
    mode = {v: k for k, v in _STEREO.items()}[meta.stereo]
    st3d = box(b"st3d", _full(0, 0, bytes([mode])))
    if meta.projection != "equirectangular":  # a stereo view that is no panorama: st3d alone
        return st3d
    svhd = box(b"svhd", _full(0, 0, _TOOL.encode() + b"\0"))
    pose = (round(a * 65536) for a in (meta.yaw, meta.pitch, meta.roll))
    prhd = box(b"prhd", _full(0, 0, struct.pack(">iii", *pose)))
    fixed = (min(2**32 - 1, round(b * 2**32)) for b in meta.bounds)
    equi = box(b"equi", _full(0, 0, struct.pack(">IIII", *fixed)))
    return st3d + box(b"sv3d", svhd + box(b"proj", prhd + equi))


def _v1_box(meta: Spherical) -> bytes:
    if meta.projection != "equirectangular":
        return b""
    stereo = {"mono": "", "top-bottom": "top-bottom", "left-right": "left-right"}[meta.stereo]
    extra = f"<GSpherical:StereoMode>{stereo}</GSpherical:StereoMode>" if stereo else ""
    xml = (
        '<?xml version="1.0"?><rdf:SphericalVideo\n'
        'xmlns:rdf="http://www.w3.org/1999/02/22-rdf-syntax-ns#"\n'
        'xmlns:GSpherical="http://ns.google.com/videos/1.0/spherical/">'
        "<GSpherical:Spherical>true</GSpherical:Spherical>"
        "<GSpherical:Stitched>true</GSpherical:Stitched>"
        f"<GSpherical:StitchingSoftware>{_TOOL}</GSpherical:StitchingSoftware>"
        "<GSpherical:ProjectionType>equirectangular</GSpherical:ProjectionType>"
        f"{extra}</rdf:SphericalVideo>"
    )
    return box(b"uuid", V1_UUID + xml.encode())


def _top_level(path: Path) -> list[tuple[bytes, int, int]]:
    """(kind, offset, size) of each top-level box, read from the file without loading it."""
    out = []
    total = os.path.getsize(path)
    with open(path, "rb") as f:
        pos = 0
        while pos + 8 <= total:
            f.seek(pos)
            size, kind = struct.unpack(">I4s", f.read(8))
            if size == 1:
                size = struct.unpack(">Q", f.read(8))[0]
            elif size == 0:
                size = total - pos
            if size < 8 or pos + size > total:
                raise ImageFormatError(f"'{path}' is not a well-formed MP4 file")
            out.append((kind, pos, size))
            pos += size
    return out


def _read_moov(path: Path) -> tuple[Box, int, int, list[tuple[bytes, int, int]]]:
    boxes = _top_level(path)
    for kind, pos, size in boxes:
        if kind == b"moov":
            with open(path, "rb") as f:
                f.seek(pos)
                (moov,) = parse_boxes(f.read(size))
            return moov, pos, size, boxes
    raise ImageFormatError(f"'{path}' has no moov box (not an MP4/MOV file)")


def _is_video_trak(trak: Box) -> bool:
    for mdia in parse_boxes(trak.payload):
        if mdia.kind == b"mdia":
            for hdlr in parse_boxes(mdia.payload):
                if hdlr.kind == b"hdlr":
                    return hdlr.payload[8:12] == b"vide"
    return False


def _sample_entries(stsd: bytes) -> tuple[bytes, list[Box]]:
    return stsd[:8], parse_boxes(stsd[8:])


def _rebuild(
    b: Box, trak_hook: object, entry_hook: object, shift: int, in_video: bool = False
) -> bytes:
    """``b`` rebuilt: sample entries through ``entry_hook``, video traks through ``trak_hook``,
    chunk offsets moved by ``shift``."""
    if b.kind in _CONTAINERS:
        video = in_video or (b.kind == b"trak" and _is_video_trak(b))
        kids = [_rebuild(c, trak_hook, entry_hook, shift, video) for c in parse_boxes(b.payload)]
        if b.kind == b"trak" and video:
            kids = trak_hook(kids)  # type: ignore[operator]
        return box(b.kind, b"".join(kids))
    if b.kind == b"stsd" and in_video:
        head, entries = _sample_entries(b.payload)
        return box(b"stsd", head + b"".join(entry_hook(e) for e in entries))  # type: ignore[operator]
    if b.kind in (b"stco", b"co64") and shift:
        fmt = ">I" if b.kind == b"stco" else ">Q"
        n = struct.unpack_from(">I", b.payload, 4)[0]
        step = struct.calcsize(fmt)
        offsets = [struct.unpack_from(fmt, b.payload, 8 + i * step)[0] + shift for i in range(n)]
        if b.kind == b"stco" and offsets and max(offsets) >= 2**32:
            raise ImageFormatError("the chunk offsets overflow 32 bits; keep moov at the end")
        return box(b.kind, b.payload[:8] + b"".join(struct.pack(fmt, o) for o in offsets))
    return b.to_bytes()


_DROP_V2 = {b"st3d", b"sv3d"}


def _is_v1(b: bytes) -> bool:
    return b[4:8] == b"uuid" and b[8:24] == V1_UUID


def write_spherical(path: str | os.PathLike[str], meta: Spherical | None = None) -> None:
    """Put equirectangular spherical metadata (V1 and V2) on the video track of ``path``, in place
    (a Matroska/WebM file gets its own elements: :mod:`spherewarp.io.matroska`).

    Any spherical metadata already there is replaced; ``meta=None`` removes it.
    Meant for a file just written (a temporary file, before it is put in place).

    Examples
    --------
    See ``tests/io/test_spherical.py`` (it needs an MP4 file).
    """
    path = Path(path)
    from .matroska import is_matroska, write_matroska_spherical

    if is_matroska(path):
        write_matroska_spherical(path, meta)
        return
    moov, pos, size, boxes = _read_moov(path)
    v2 = b"" if meta is None else _v2_boxes(meta)
    v1 = b"" if meta is None else _v1_box(meta)

    def entry_hook(e: Box) -> bytes:
        if e.kind not in _VIDEO_ENTRIES:
            return e.to_bytes()
        fields, kids = e.payload[:_VISUAL_FIELDS], parse_boxes(e.payload[_VISUAL_FIELDS:])
        kept = b"".join(k.to_bytes() for k in kids if k.kind not in _DROP_V2)
        return box(e.kind, fields + kept + v2)

    def trak_hook(kids: list[bytes]) -> list[bytes]:
        return [k for k in kids if not _is_v1(k)] + ([v1] if v1 else [])

    media_after = any(k == b"mdat" and p > pos for k, p, _ in boxes)
    new = _rebuild(moov, trak_hook, entry_hook, 0)
    if media_after:  # the media moves by the growth of moov: move the chunk offsets too
        new = _rebuild(moov, trak_hook, entry_hook, len(new) - size)
    last = pos + size == os.path.getsize(path)
    if last:
        with open(path, "r+b") as f:
            f.truncate(pos)
            f.seek(pos)
            f.write(new)
        return
    with open(path, "rb") as f:
        data = f.read()
    with open(path, "wb") as f:
        f.write(data[:pos] + new + data[pos + size :])


def _parse_v2(entry_kids: list[Box], meta: Spherical) -> bool:
    found = False
    for k in entry_kids:
        if k.kind == b"st3d" and len(k.payload) >= 5:
            meta.stereo = _STEREO.get(k.payload[4], "mono")
        elif k.kind == b"sv3d":
            for p in parse_boxes(k.payload):
                if p.kind != b"proj":
                    continue
                for q in parse_boxes(p.payload):
                    if q.kind == b"prhd" and len(q.payload) >= 16:
                        y, pi, r = struct.unpack_from(">iii", q.payload, 4)
                        meta.yaw, meta.pitch, meta.roll = y / 65536, pi / 65536, r / 65536
                    elif q.kind == b"equi" and len(q.payload) >= 20:
                        vals = struct.unpack_from(">IIII", q.payload, 4)
                        meta.bounds = tuple(v / 2**32 for v in vals)  # type: ignore[assignment]
                        meta.projection = "equirectangular"
                        found = True
                    elif q.kind in (b"cbmp", b"mshp"):
                        meta.projection = "cubemap" if q.kind == b"cbmp" else "mesh"
                        found = True
    return found


def read_spherical(path: str | os.PathLike[str]) -> Spherical | None:
    """The spherical metadata of ``path``'s first video track, or None when it has none
    (MP4/MOV boxes, or a Matroska/WebM file's elements: :mod:`spherewarp.io.matroska`).

    Raises
    ------
    ImageFormatError
        When ``path`` is not an MP4/MOV file.
    """
    from .matroska import is_matroska, read_matroska_spherical

    if is_matroska(path):
        return read_matroska_spherical(path)
    moov, *_ = _read_moov(Path(path))
    for trak in parse_boxes(moov.payload):
        if trak.kind != b"trak" or not _is_video_trak(trak):
            continue
        meta = Spherical()
        for k in parse_boxes(trak.payload):
            if k.kind == b"uuid" and k.payload[:16] == V1_UUID:
                xml = k.payload[16:].decode("utf-8", "replace")
                if "<GSpherical:Spherical>true" in xml:
                    meta.versions.add("v1")
                    if "StereoMode>top-bottom" in xml:
                        meta.stereo = "top-bottom"
                    elif "StereoMode>left-right" in xml:
                        meta.stereo = "left-right"
        stbl = _find(trak, [b"mdia", b"minf", b"stbl", b"stsd"])
        if stbl is not None:
            for e in _sample_entries(stbl.payload)[1]:
                if e.kind in _VIDEO_ENTRIES:
                    if _parse_v2(parse_boxes(e.payload[_VISUAL_FIELDS:]), meta):
                        meta.versions.add("v2")
        return meta if meta.versions else None
    return None


def _find(b: Box, chain: list[bytes]) -> Box | None:
    for name in chain:
        nxt = next((k for k in parse_boxes(b.payload) if k.kind == name), None)
        if nxt is None:
            return None
        b = nxt
    return b
