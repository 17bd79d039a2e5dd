"""GPano (Google Photo Sphere) XMP metadata: the :class:`GPano` record, writing and parsing.

Panorama viewers recognise a 360° equirectangular image by the XMP properties of
the ``GPano`` namespace (``http://ns.google.com/photos/1.0/panorama/``). The ones
this module reads and writes are:

================================  =======================================
``ProjectionType``                ``equirectangular`` for spherewarp
``UsePanoramaViewer``             written as ``True``
``FullPanoWidthPixels``           width of the full sphere
``FullPanoHeightPixels``          height of the full sphere
``CroppedAreaImageWidthPixels``   width of the part stored in the file
``CroppedAreaImageHeightPixels``  height of the part stored in the file
``CroppedAreaLeftPixels``         column of the stored part in the full sphere
``CroppedAreaTopPixels``          row of the stored part in the full sphere
``PoseHeadingDegrees``            compass heading of the image centre
``PosePitchDegrees``              pitch of the camera (0: level)
``PoseRollDegrees``               roll of the camera (0: level)
================================  =======================================

The pose properties are optional: read when present, written when set. They
hold for the pixels as captured; an edit that turns the image updates them
(:meth:`GPano.turned`) or drops them (:meth:`GPano.without_pose`).

:func:`parse_gpano` accepts the two forms that XMP writers use, properties as
attributes of ``rdf:Description`` or as child elements, and parses with
:mod:`xml.etree.ElementTree`. A packet is decoded first (UTF-8, UTF-16 or
UTF-32, by its byte-order mark, its first bytes or its XML declaration) and a
packet with a DTD (``<!DOCTYPE``, ``<!ENTITY``) is refused in every encoding,
so no entity is ever expanded; the parser then sees exactly the text that was
checked, re-encoded as UTF-8. GPano numbers must be integers from 0 to
``2**31 - 1``.

Examples
--------
>>> from spherewarp.io.xmp import GPano, gpano_xmp, parse_gpano
>>> g = GPano.full_sphere(2048, 1024)
>>> packet = gpano_xmp(g)
>>> packet.startswith("<?xpacket")
True
>>> parse_gpano(packet) == g
True
"""

from __future__ import annotations

import codecs
import math
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass, replace

from ..errors import InvalidTypeError, InvalidValueError

__all__ = ["GPANO_NAMESPACE", "GPano", "gpano_xmp", "parse_gpano"]

GPANO_NAMESPACE = "http://ns.google.com/photos/1.0/panorama/"
"""XML namespace of the GPano properties."""

_RDF_NS = "http://www.w3.org/1999/02/22-rdf-syntax-ns#"

# XMP property name -> GPano field name, for the integer properties.
_INT_PROPERTIES = {
    "FullPanoWidthPixels": "full_width",
    "FullPanoHeightPixels": "full_height",
    "CroppedAreaImageWidthPixels": "cropped_width",
    "CroppedAreaImageHeightPixels": "cropped_height",
    "CroppedAreaLeftPixels": "cropped_left",
    "CroppedAreaTopPixels": "cropped_top",
}

# XMP property name -> GPano field name, for the (optional) pose in degrees.
_POSE_PROPERTIES = {
    "PoseHeadingDegrees": "pose_heading",
    "PosePitchDegrees": "pose_pitch",
    "PoseRollDegrees": "pose_roll",
}


def _check_angle(name: str, value: object) -> float | None:
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise InvalidTypeError(f"GPano {name} must be a number, got {type(value).__name__}")
    if not math.isfinite(value):
        raise InvalidValueError(f"GPano {name} must be finite, got {value}")
    return float(value)


def _check_int(name: str, value: object, minimum: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int):
        raise InvalidTypeError(f"GPano {name} must be an int, got {type(value).__name__}")
    if value < minimum:
        raise InvalidValueError(f"GPano {name} must be >= {minimum}, got {value}")
    return int(value)


@dataclass(frozen=True, kw_only=True)
class GPano:
    """Where the pixels of a file lie on the full 360° x 180° panorama.

    All fields are keyword-only. ``cropped_width`` and ``cropped_height``
    default to the full size (the file holds the whole sphere).

    Parameters
    ----------
    projection_type : str
        GPano ``ProjectionType``; spherewarp only places ``"equirectangular"``.
    full_width, full_height : int
        Size in pixels of the full panorama (``FullPanoWidthPixels``,
        ``FullPanoHeightPixels``).
    cropped_width, cropped_height : int or None
        Size of the part stored in the file; ``None`` means the full size.
    cropped_left, cropped_top : int
        Position of the stored part's top-left pixel in the full panorama.
    pose_heading, pose_pitch, pose_roll : float or None
        The camera's pose in degrees (``PoseHeadingDegrees``: compass heading
        of the centre of the full panorama, kept in [0, 360);
        ``PosePitchDegrees`` in [-90, 90]; ``PoseRollDegrees``, kept in
        (-180, 180]); None when the file does not say.

    Raises
    ------
    InvalidTypeError
        If a size or offset is not an int.
    InvalidValueError
        If a size is not positive, an offset is negative, or the stored part
        does not fit in the full panorama (it may wrap horizontally across the
        seam, never vertically), or a pose angle is not finite or the pitch is
        outside [-90, 90].

    Examples
    --------
    >>> g = GPano(full_width=4000, full_height=2000, cropped_width=4000,
    ...           cropped_height=1000, cropped_top=500)
    >>> g.is_cropped
    True
    >>> GPano.full_sphere(4000, 2000).is_cropped
    False
    """

    projection_type: str = "equirectangular"
    full_width: int
    full_height: int
    cropped_width: int | None = None
    cropped_height: int | None = None
    cropped_left: int = 0
    cropped_top: int = 0
    pose_heading: float | None = None
    pose_pitch: float | None = None
    pose_roll: float | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.projection_type, str):
            raise InvalidTypeError(
                f"GPano projection_type must be a str, got {type(self.projection_type).__name__}"
            )
        fw = _check_int("full_width", self.full_width, 1)
        fh = _check_int("full_height", self.full_height, 1)
        cw = fw if self.cropped_width is None else self.cropped_width
        ch = fh if self.cropped_height is None else self.cropped_height
        cw = _check_int("cropped_width", cw, 1)
        ch = _check_int("cropped_height", ch, 1)
        left = _check_int("cropped_left", self.cropped_left, 0)
        top = _check_int("cropped_top", self.cropped_top, 0)
        if cw > fw:
            raise InvalidValueError(f"GPano cropped_width ({cw}) must not exceed full_width ({fw})")
        if left >= fw:
            raise InvalidValueError(f"GPano cropped_left must be < full_width ({fw}), got {left}")
        if top + ch > fh:
            raise InvalidValueError(
                f"GPano cropped area (top {top} + height {ch} = {top + ch}) "
                f"does not fit in full_height ({fh})"
            )
        object.__setattr__(self, "cropped_width", cw)
        object.__setattr__(self, "cropped_height", ch)
        heading = _check_angle("pose_heading", self.pose_heading)
        pitch = _check_angle("pose_pitch", self.pose_pitch)
        roll = _check_angle("pose_roll", self.pose_roll)
        if pitch is not None and not -90.0 <= pitch <= 90.0:
            raise InvalidValueError(f"GPano pose_pitch must be in [-90, 90], got {pitch}")
        if heading is not None:
            heading %= 360.0
        if roll is not None:
            roll = 180.0 - (180.0 - roll) % 360.0
        object.__setattr__(self, "pose_heading", heading)
        object.__setattr__(self, "pose_pitch", pitch)
        object.__setattr__(self, "pose_roll", roll)

    @classmethod
    def full_sphere(cls, width: int, height: int) -> GPano:
        """Return the GPano of an uncropped equirectangular image of ``width`` x ``height``.

        Examples
        --------
        >>> GPano.full_sphere(8, 4)  # doctest: +NORMALIZE_WHITESPACE
        GPano(projection_type='equirectangular', full_width=8, full_height=4,
              cropped_width=8, cropped_height=4, cropped_left=0, cropped_top=0,
              pose_heading=None, pose_pitch=None, pose_roll=None)
        """
        return cls(full_width=width, full_height=height)

    @property
    def has_pose(self) -> bool:
        """True when any of the pose angles is set."""
        return any(v is not None for v in (self.pose_heading, self.pose_pitch, self.pose_roll))

    @property
    def is_level(self) -> bool:
        """True when the pose has no pitch and no roll (absent or 0)."""
        return not self.pose_pitch and not self.pose_roll

    def as_full_sphere(self, width: int, height: int) -> GPano:
        """An uncropped equirectangular ``width`` x ``height`` sphere with this pose.

        Examples
        --------
        >>> g = GPano(full_width=400, full_height=200, cropped_height=100, pose_heading=30)
        >>> g.as_full_sphere(800, 400).is_cropped, g.as_full_sphere(800, 400).pose_heading
        (False, 30.0)
        """
        return replace(
            GPano.full_sphere(width, height),
            pose_heading=self.pose_heading,
            pose_pitch=self.pose_pitch,
            pose_roll=self.pose_roll,
        )

    def without_pose(self) -> GPano:
        """This GPano with no pose (for pixels the recorded pose no longer describes)."""
        return replace(self, pose_heading=None, pose_pitch=None, pose_roll=None)

    def turned(self, yaw: float) -> GPano | None:
        """The GPano of the image turned by ``yaw`` degrees about the vertical, or None.

        After ``spherewarp rotate --yaw YAW`` the centre shows what was ``YAW``
        degrees to its right, so the heading becomes ``heading + yaw``. That
        holds for a level pose only (pitch and roll absent or 0): for a tilted
        one no heading/pitch/roll of the turned image is known here, and None
        is returned (drop the pose).

        Examples
        --------
        >>> GPano(full_width=8, full_height=4, pose_heading=350.0).turned(30).pose_heading
        20.0
        >>> GPano(full_width=8, full_height=4, pose_pitch=5.0).turned(30) is None
        True
        """
        if float(yaw) % 360.0 == 0.0:
            return self
        if not self.is_level:
            return None
        if self.pose_heading is None:
            return self
        return replace(self, pose_heading=self.pose_heading + float(yaw))

    @property
    def is_cropped(self) -> bool:
        """True when the file holds only part of the full panorama, or holds it shifted."""
        return (
            self.cropped_width != self.full_width
            or self.cropped_height != self.full_height
            or self.cropped_left != 0
            or self.cropped_top != 0
        )


def _quoteattr(text: str) -> str:
    """``xml.sax.saxutils.quoteattr`` (same output) without importing it: that module
    imports ``urllib.request`` (with ``http``, ``email``, ``ssl``), 15 ms of every command."""
    for raw, ent in (("&", "&amp;"), (">", "&gt;"), ("<", "&lt;")):
        text = text.replace(raw, ent)
    for raw, ent in (("\n", "&#10;"), ("\r", "&#13;"), ("\t", "&#9;")):
        text = text.replace(raw, ent)
    if '"' not in text:
        return f'"{text}"'
    if "'" not in text:
        return f"'{text}'"
    return '"{}"'.format(text.replace('"', "&quot;"))


def gpano_xmp(gpano: GPano) -> str:
    """Return a complete XMP packet (``<x:xmpmeta>`` in ``<?xpacket?>``) describing ``gpano``.

    The packet holds ``ProjectionType``, ``UsePanoramaViewer="True"``, the full
    size, the cropped size and the cropped offsets, and the pose angles that
    are set, as attributes of one ``rdf:Description``. It is plain ASCII apart from the BOM in the
    ``xpacket`` header that the XMP specification asks for; encode it as UTF-8.

    Parameters
    ----------
    gpano : GPano
        The panorama description to write.

    Returns
    -------
    str
        The XMP packet.

    Raises
    ------
    InvalidTypeError
        If ``gpano`` is not a :class:`GPano`.

    Examples
    --------
    >>> xmp = gpano_xmp(GPano.full_sphere(64, 32))
    >>> 'GPano:FullPanoWidthPixels="64"' in xmp and 'GPano:CroppedAreaTopPixels="0"' in xmp
    True
    """
    if not isinstance(gpano, GPano):
        raise InvalidTypeError(f"gpano must be a GPano, got {type(gpano).__name__}")
    props = [
        ("ProjectionType", gpano.projection_type),
        ("UsePanoramaViewer", "True"),
        ("FullPanoWidthPixels", gpano.full_width),
        ("FullPanoHeightPixels", gpano.full_height),
        ("CroppedAreaImageWidthPixels", gpano.cropped_width),
        ("CroppedAreaImageHeightPixels", gpano.cropped_height),
        ("CroppedAreaLeftPixels", gpano.cropped_left),
        ("CroppedAreaTopPixels", gpano.cropped_top),
    ]
    for name, field in _POSE_PROPERTIES.items():
        value = getattr(gpano, field)
        if value is not None:
            props.append((name, f"{value:.10g}"))
    attrs = "".join(f"\n    GPano:{name}={_quoteattr(str(value))}" for name, value in props)
    return (
        '<?xpacket begin="\ufeff" id="W5M0MpCehiHzreSzNTczkc9d"?>\n'
        '<x:xmpmeta xmlns:x="adobe:ns:meta/" x:xmptk="spherewarp">\n'
        f' <rdf:RDF xmlns:rdf="{_RDF_NS}">\n'
        '  <rdf:Description rdf:about=""\n'
        f'    xmlns:GPano="{GPANO_NAMESPACE}"{attrs}/>\n'
        " </rdf:RDF>\n"
        "</x:xmpmeta>\n"
        '<?xpacket end="w"?>'
    )


_MAX_GPANO_VALUE = 2**31 - 1
_MAX_NUMBER_TEXT = 40
_BOMS = (
    (codecs.BOM_UTF32_BE, "utf-32-be"),
    (codecs.BOM_UTF32_LE, "utf-32-le"),
    (codecs.BOM_UTF8, "utf-8"),
    (codecs.BOM_UTF16_BE, "utf-16-be"),
    (codecs.BOM_UTF16_LE, "utf-16-le"),
)
# How a packet that starts with "<" begins in each encoding without a BOM.
_FIRST_BYTES = (
    (b"\x00\x00\x00<", "utf-32-be"),
    (b"<\x00\x00\x00", "utf-32-le"),
    (b"\x00<", "utf-16-be"),
    (b"<\x00", "utf-16-le"),
)
_DECLARATION = re.compile(r"^\s*<\?xml\b[^>]*\?>")
_DECLARED_ENCODING = re.compile(rb"^\s*<\?xml\b[^>]*?encoding\s*=\s*[\"']([A-Za-z0-9._-]{1,40})")


def _encoding_of(data: bytes) -> tuple[str, int]:
    """The encoding of an XMP packet and the length of its byte-order mark."""
    for bom, name in _BOMS:
        if data.startswith(bom):
            return name, len(bom)
    for first, name in _FIRST_BYTES:
        if data.startswith(first):
            return name, 0
    head = data[:64]
    if len(head) >= 4 and b"\x00" in head:  # UTF-16 after leading blanks: NULs in every pair
        even, odd = head[0::2].count(0), head[1::2].count(0)
        if even >= 2 * odd + 2:
            return "utf-16-be", 0
        if odd >= 2 * even + 2:
            return "utf-16-le", 0
    declared = _DECLARED_ENCODING.match(data[:200])
    if declared:
        name = declared.group(1).decode("ascii")
        try:
            codec = codecs.lookup(name).name
        except LookupError:
            raise InvalidValueError(f"XMP packet declares an unknown encoding {name!r}") from None
        # The declaration was read as ASCII, so the bytes are not UTF-16/32 whatever it says.
        return ("utf-8" if codec.startswith(("utf-16", "utf-32")) else codec), 0
    return "utf-8", 0


def _decode_packet(data: bytes | str) -> str:
    """The text of an XMP packet, without BOM, XML declaration or NUL/blank padding."""
    if isinstance(data, str):
        text = data
    else:
        encoding, skip = _encoding_of(data)
        data = data[skip:]
        unit = 4 if "32" in encoding else 2 if "16" in encoding else 1
        if unit > 1:  # drop NUL padding without cutting the last character
            data = data.rstrip(b"\x00")
            data += b"\x00" * (-len(data) % unit)
        try:
            text = data.decode(encoding)
        except (UnicodeDecodeError, LookupError) as exc:
            raise InvalidValueError(f"XMP packet is not valid {encoding} text: {exc}") from None
    text = text.strip("\x00 \t\r\n\ufeff")
    return _DECLARATION.sub("", text, count=1).strip()


def _fromstring(data: bytes) -> ET.Element:
    """Parse UTF-8 bytes as UTF-8, whatever encoding a declaration in them names."""
    parser = ET.XMLParser(encoding="utf-8")
    parser.feed(data)
    return parser.close()


def _parse_xml(data: bytes) -> ET.Element:
    try:
        return _fromstring(data)
    except ET.ParseError as first_error:
        # Some writers pad the packet or put bytes around it: retry on the
        # <x:xmpmeta> ... </x:xmpmeta> element alone.
        start = data.find(b"<x:xmpmeta")
        end = data.rfind(b"</x:xmpmeta>")
        if start >= 0 and end > start:
            try:
                return _fromstring(data[start : end + len(b"</x:xmpmeta>")])
            except ET.ParseError:
                pass
        raise InvalidValueError(f"XMP packet is not well-formed XML: {first_error}") from None


def _parse_int(name: str, text: str) -> int:
    text = text.strip()
    shown = repr(text) if len(text) <= _MAX_NUMBER_TEXT else f"a {len(text)}-character value"
    value: int | float = math.nan
    if len(text) <= _MAX_NUMBER_TEXT:
        try:
            value = int(text)
        except ValueError:
            try:
                value = float(text)
            except ValueError:
                pass
    if not math.isfinite(value) or value != int(value):
        raise InvalidValueError(f"GPano:{name} must be an integer, got {shown}")
    if not 0 <= value <= _MAX_GPANO_VALUE:
        raise InvalidValueError(
            f"GPano:{name} must be an integer from 0 to {_MAX_GPANO_VALUE}, got {shown}"
        )
    return int(value)


def _parse_angle(name: str, text: str) -> float:
    try:
        value = float(text.strip())
    except ValueError:
        value = float("nan")
    if not math.isfinite(value):
        raise InvalidValueError(f"GPano:{name} must be a number of degrees, got {text!r}")
    return value


def parse_gpano(xmp: bytes | str) -> GPano | None:
    """Parse the GPano properties of an XMP packet.

    Parameters
    ----------
    xmp : bytes or str
        An XMP packet (with or without the ``<?xpacket?>`` wrapper), as found
        in a PNG ``iTXt`` chunk, a JPEG APP1 segment, a WebP ``XMP`` chunk or
        TIFF tag 700. Bytes are taken as UTF-8 unless the packet declares
        another encoding (or starts with a UTF-16/UTF-32 byte-order mark or
        its first bytes are UTF-16/UTF-32); NUL padding is ignored.

    Returns
    -------
    GPano or None
        ``None`` when the packet has no GPano properties that give the
        panorama size (``FullPano*Pixels``, or else ``CroppedAreaImage*Pixels``).
        Missing cropped sizes default to the full size, missing offsets to 0.

    Raises
    ------
    InvalidTypeError
        If ``xmp`` is neither bytes nor str.
    InvalidValueError
        If the packet is not text in its encoding, not well-formed XML,
        contains a DTD (in any encoding), or has GPano values that are not
        integers from 0 to ``2**31 - 1`` or do not describe a valid placement.

    Examples
    --------
    Attribute form and element form give the same result:

    >>> a = '''<x:xmpmeta xmlns:x="adobe:ns:meta/"><rdf:RDF
    ...   xmlns:rdf="http://www.w3.org/1999/02/22-rdf-syntax-ns#">
    ...   <rdf:Description xmlns:GPano="http://ns.google.com/photos/1.0/panorama/"
    ...     GPano:FullPanoWidthPixels="400" GPano:FullPanoHeightPixels="200"
    ...     GPano:CroppedAreaImageHeightPixels="100" GPano:CroppedAreaTopPixels="50"/>
    ... </rdf:RDF></x:xmpmeta>'''
    >>> e = '''<x:xmpmeta xmlns:x="adobe:ns:meta/"><rdf:RDF
    ...   xmlns:rdf="http://www.w3.org/1999/02/22-rdf-syntax-ns#">
    ...   <rdf:Description xmlns:GPano="http://ns.google.com/photos/1.0/panorama/">
    ...     <GPano:FullPanoWidthPixels>400</GPano:FullPanoWidthPixels>
    ...     <GPano:FullPanoHeightPixels>200</GPano:FullPanoHeightPixels>
    ...     <GPano:CroppedAreaImageHeightPixels>100</GPano:CroppedAreaImageHeightPixels>
    ...     <GPano:CroppedAreaTopPixels>50</GPano:CroppedAreaTopPixels>
    ...   </rdf:Description></rdf:RDF></x:xmpmeta>'''
    >>> parse_gpano(a) == parse_gpano(e.encode())
    True
    >>> parse_gpano(a).cropped_height, parse_gpano(a).cropped_width
    (100, 400)
    >>> parse_gpano('<x:xmpmeta xmlns:x="adobe:ns:meta/"/>') is None
    True
    """
    if isinstance(xmp, (bytes, bytearray, memoryview)):
        xmp = bytes(xmp)
    elif not isinstance(xmp, str):
        raise InvalidTypeError(f"xmp must be bytes or str, got {type(xmp).__name__}")
    text = _decode_packet(xmp)
    if not text:
        return None
    if "<!DOCTYPE" in text or "<!ENTITY" in text:
        raise InvalidValueError("XMP packet contains a DTD (<!DOCTYPE or <!ENTITY), refused")
    root = _parse_xml(text.encode("utf-8"))

    prefix = "{" + GPANO_NAMESPACE + "}"
    found: dict[str, str] = {}
    for elem in root.iter():
        for key, value in elem.attrib.items():
            if key.startswith(prefix):
                found.setdefault(key[len(prefix) :], value)
        if isinstance(elem.tag, str) and elem.tag.startswith(prefix):
            found.setdefault(elem.tag[len(prefix) :], (elem.text or "").strip())

    values: dict[str, int] = {}
    for name, field in _INT_PROPERTIES.items():
        if name in found and found[name] != "":
            values[field] = _parse_int(name, found[name])
    pose: dict[str, float] = {}
    for name, field in _POSE_PROPERTIES.items():
        if found.get(name, "").strip():
            pose[field] = _parse_angle(name, found[name])
    values.setdefault("full_width", values.get("cropped_width", 0))
    values.setdefault("full_height", values.get("cropped_height", 0))
    if not values["full_width"] or not values["full_height"]:
        return None
    projection = found.get("ProjectionType", "").strip() or "equirectangular"
    try:
        return GPano(projection_type=projection, **values, **pose)
    except InvalidTypeError as exc:  # pragma: no cover - values are ints here
        raise InvalidValueError(str(exc)) from None
