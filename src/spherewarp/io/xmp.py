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
================================  =======================================

:func:`parse_gpano` accepts the two forms that XMP writers use, properties as
attributes of ``rdf:Description`` or as child elements, and parses with
:mod:`xml.etree.ElementTree`; packets with a DTD are refused.

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

import xml.etree.ElementTree as ET
from dataclasses import dataclass

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

    Raises
    ------
    InvalidTypeError
        If a size or offset is not an int.
    InvalidValueError
        If a size is not positive, an offset is negative, or the stored part
        does not fit in the full panorama (it may wrap horizontally across the
        seam, never vertically).

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

    @classmethod
    def full_sphere(cls, width: int, height: int) -> GPano:
        """Return the GPano of an uncropped equirectangular image of ``width`` x ``height``.

        Examples
        --------
        >>> GPano.full_sphere(8, 4)  # doctest: +NORMALIZE_WHITESPACE
        GPano(projection_type='equirectangular', full_width=8, full_height=4,
              cropped_width=8, cropped_height=4, cropped_left=0, cropped_top=0)
        """
        return cls(full_width=width, full_height=height)

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
    size, the cropped size and the cropped offsets, as attributes of one
    ``rdf:Description``. It is plain ASCII apart from the BOM in the
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


def _parse_xml(data: bytes) -> ET.Element:
    try:
        return ET.fromstring(data)
    except ET.ParseError as first_error:
        # Some writers pad the packet or put bytes around it: retry on the
        # <x:xmpmeta> ... </x:xmpmeta> element alone.
        start = data.find(b"<x:xmpmeta")
        end = data.rfind(b"</x:xmpmeta>")
        if start >= 0 and end > start:
            try:
                return ET.fromstring(data[start : end + len(b"</x:xmpmeta>")])
            except ET.ParseError:
                pass
        raise InvalidValueError(f"XMP packet is not well-formed XML: {first_error}") from None


def _parse_int(name: str, text: str) -> int:
    text = text.strip()
    try:
        return int(text)
    except ValueError:
        pass
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if value != value or value != int(value):
        raise InvalidValueError(f"GPano:{name} must be an integer, got {text!r}")
    return int(value)


def parse_gpano(xmp: bytes | str) -> GPano | None:
    """Parse the GPano properties of an XMP packet.

    Parameters
    ----------
    xmp : bytes or str
        An XMP packet (with or without the ``<?xpacket?>`` wrapper), as found
        in a PNG ``iTXt`` chunk, a JPEG APP1 segment, a WebP ``XMP`` chunk or
        TIFF tag 700. Bytes are taken as UTF-8 unless the packet declares
        another encoding; trailing NUL padding is ignored.

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
        If the packet is not well-formed XML, contains a DTD, or has GPano
        values that are not integers or do not describe a valid placement.

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
    if isinstance(xmp, str):
        data = xmp.encode("utf-8")
    elif isinstance(xmp, (bytes, bytearray, memoryview)):
        data = bytes(xmp)
    else:
        raise InvalidTypeError(f"xmp must be bytes or str, got {type(xmp).__name__}")
    data = data.strip(b"\x00 \t\r\n")
    if not data:
        return None
    if b"<!DOCTYPE" in data or b"<!ENTITY" in data:
        raise InvalidValueError("XMP packet contains a DTD (<!DOCTYPE or <!ENTITY), refused")
    root = _parse_xml(data)

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
    values.setdefault("full_width", values.get("cropped_width", 0))
    values.setdefault("full_height", values.get("cropped_height", 0))
    if not values["full_width"] or not values["full_height"]:
        return None
    projection = found.get("ProjectionType", "").strip() or "equirectangular"
    try:
        return GPano(projection_type=projection, **values)
    except InvalidTypeError as exc:  # pragma: no cover - values are ints here
        raise InvalidValueError(str(exc)) from None
