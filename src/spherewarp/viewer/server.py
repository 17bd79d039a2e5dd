"""The viewer's local HTTP server: its own assets, one image, a small JSON API.

Routes
------
``GET /``, ``GET /assets/...``
    The bundled page (``static/``); nothing outside that folder.
``GET /image``
    The image the server was started with, as an 8-bit PNG (any input format).
``GET /video``
    A video the server was started with, as it is, with HTTP range requests
    (``Range: bytes=A-B``: 206; outside the file: 416; a ``Range`` that is not one
    byte range is ignored: 200, the whole file) so that the page's video element
    can seek.
``GET /testpattern``
    The paper's test pattern (:func:`spherewarp.testpattern.make_test_pattern`,
    1024x512), for the page's overlay.
``GET /api/state``
    ``{"recipe", "image": {"width", "height", "name", "video"}, "rate", "stages",
    "glsl_header", "table", "params"}``: the recipe the server was started with (the files
    it names as absolute paths: :func:`absolute_recipe`), its map
    packed as compiled stages (:func:`packed_stages`), the stage table for the
    shader, a video's frame rate (None for an image), and the bounds of the
    effects' number parameters for the page's sliders (:func:`slider_specs`).
``POST /api/stages``
    A recipe in, its packed stages at ``?t=SECONDS`` (default 0) out (400 with
    the recipe's error line):
    :func:`packed_stages`, expression maps as GLSL functions made from their
    syntax tree (:mod:`spherewarp.viewer.glsl`; no text of the recipe reaches
    the shader). An animated recipe's reply also has ``"at"``: its steps at that
    time (:func:`steps_at`), where the page draws the recipe's marks.
``GET /api/labels/KEY``
    The labels of a masked Schottky stage (``/api/stages`` names their key), as
    little-endian int16, row-major.
``POST /api/render``
    A recipe in; renders it at full resolution with the Python renderer in a
    thread (a video: its frame at ``?t=SECONDS``, default the first, and the
    recipe at that time);
    ``{"job": ID}`` out. ``GET /api/render/ID``: ``{"done", "progress",
    "error"}``; ``GET /api/render/ID/file``: the PNG, as a download (409 while
    the render runs; 422 with its error for a render that failed).

Security: the ``Host`` header must name the address the server listens on
(DNS rebinding: 403); an API request with an ``Origin`` (or a cross-site
``Sec-Fetch-Site``) that is not the server's gets 403; a body over
:data:`MAX_BODY` gets 413; a path with ``..`` (also URL-encoded) gets 404; a
posted recipe naming a file (a mask) other than those the server was started with
gets 403 before the file is looked at
(:func:`spherewarp.recipe.params.allowed_files`). A request whose framing two
parsers could read differently (two ``Host`` or ``Content-Length`` headers, any
``Transfer-Encoding``, a length that is not plain digits, a target that is not a
path) gets 400. Every error reply, and any reply to a request whose body was not
read, closes the connection: what is left of a request is never read as the next
one (a refused request's body would pass the checks above).
Renders go to a temporary folder of the server's own, removed on close:
nothing next to the inputs changes.

Examples
--------
>>> import json, urllib.request
>>> srv = ViewerServer(None, None)
>>> with urllib.request.urlopen(srv.url + "api/state") as r:
...     json.load(r)["stages"]["codes"]  # no steps: no stages
[]
>>> srv.close()
"""

from __future__ import annotations

import io
import ipaddress
import json
import mimetypes
import os
import queue
import re
import shutil
import socket
import sys
import tempfile
import threading
import urllib.parse
import uuid
from collections import OrderedDict
from collections.abc import Sequence
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from typing import Any

import numpy as np

__all__ = [
    "MAX_BODY",
    "MAX_JOBS",
    "MAX_QUEUED",
    "STATIC_DIR",
    "LabelCache",
    "RenderQueueFull",
    "ViewerServer",
    "absolute_recipe",
    "byte_range",
    "display_pixels",
    "host_names",
    "is_loopback",
    "packed_stages",
    "slider_specs",
    "steps_at",
    "url_host",
    "video_frame",
]

#: the folder of the built page (``npm run build`` in ``viewer/`` writes it)
STATIC_DIR = Path(__file__).with_name("static")
#: the largest request body read, in bytes (a recipe is at most 1 MB)
MAX_BODY = 1_000_000
#: the MIME subtype of each video extension
_VIDEO_TYPES = {
    ".mp4": "mp4",
    ".m4v": "mp4",
    ".mov": "quicktime",
    ".mkv": "x-matroska",
    ".webm": "webm",
}
_LOOPBACK = {"127.0.0.1", "localhost", "::1"}
#: the addresses that listen on every interface (IPv4, IPv6: both where the system allows)
_WILDCARD = {"0.0.0.0", "::", ""}
#: one byte range (RFC 9110 14.1.2): ``bytes=A-B``, ``bytes=A-``, ``bytes=-N``
_RANGE = re.compile(r"bytes[ \t]*=[ \t]*([0-9]*)-([0-9]*)", re.IGNORECASE)
#: a Content-Length as HTTP has it: digits only (``int()`` also reads ``+27``, ``2_7``)
_LENGTH = re.compile(r"[0-9]{1,18}")
_EMPTY = {"spherewarp": 1, "steps": []}
#: full-resolution renders kept (beyond it the oldest finished one goes, with its file)
MAX_JOBS = 16
#: renders waiting for the one that runs, beyond which a new one is refused (429)
MAX_QUEUED = 4


def packed_stages(
    recipe: Any, t: float = 0.0, labels: LabelCache | dict[str, Any] | None = None
) -> dict[str, Any]:
    """The recipe's map at time ``t`` as the stages the shader runs.

    Returns ``{"codes": [...], "rows": [[...], ...], "glsl": ..., "labels": [...]}``:
    one float row per stage (the layout of :mod:`spherewarp.render.stages`, and the
    shader-only expression stage of :mod:`spherewarp.viewer.glsl` with its GLSL
    functions), a masked Schottky stage's labels by key (stored in ``labels``, if
    given: the page fetches them from ``/api/labels/KEY``); or ``{"codes": None,
    "missing": why}`` when some part of the map has no stage.

    Examples
    --------
    >>> from spherewarp.recipe import Recipe
    >>> r = Recipe.from_dict({"spherewarp": 1, "steps": [{"power": {"n": 3}}]})
    >>> packed_stages(r)["codes"]
    [2]
    >>> r = Recipe.from_dict({"spherewarp": 1, "steps": [{"map": {"expr": "z**2"}}]})
    >>> packed_stages(r)["codes"], packed_stages(r)["glsl"].splitlines()[0]
    ([64], 'vec2 expr0(int s, vec2 z) {')
    """
    from .glsl import shader_spec

    m = recipe.map_at(t)
    spec = shader_spec(m)
    if spec is None:
        return {
            "codes": None,
            "missing": f"{type(m).__name__} has no compiled stage (the shader runs only "
            "compiled stages; 'spherewarp render' renders it on the CPU)",
        }
    if labels is not None:
        labels.update(spec.labels)
    return spec.as_json()


def steps_at(recipe: Any, t: float = 0.0) -> dict[str, Any]:
    """The recipe's steps at time ``t``, as JSON: each track replaced by its value
    there (the recipe's own tracks evaluated, as a render at ``t`` does), the rest as
    given.

    Returns ``{"time": T, "steps": [...]}``, ``T`` the time the tracks are evaluated
    at (``t`` modulo the duration for a loop).

    Examples
    --------
    >>> from spherewarp.recipe import Recipe
    >>> r = Recipe.from_dict({"spherewarp": 1, "duration": 2, "loop": True, "steps": [
    ...     {"droste": {"center": {"keyframes": [[0, [0, 0]], [2, [40, 20]]]},
    ...                 "inner_radius": 15}},
    ...     {"zoom": {"at": [{"keyframes": [[0, 0], [1, 10]]}, 5], "factor": 2}}]})
    >>> steps_at(r, 2.5)
    {'time': 0.5, 'steps': [{'droste': {'center': [10.0, 5.0], 'inner_radius': 15}},
                            {'zoom': {'at': [5.0, 5], 'factor': 2}}]}
    """
    from ..recipe.tracks import Track

    def plain(v: Any) -> Any:
        return [plain(x) for x in v] if isinstance(v, tuple) else v

    def at(given: Any, parsed: Any) -> Any:
        if isinstance(parsed, Track):
            return plain(parsed(tt))
        if isinstance(given, list) and isinstance(parsed, (list, tuple)):
            if len(given) == len(parsed):
                return [at(g, p) for g, p in zip(given, parsed, strict=True)]
        if isinstance(given, dict) and isinstance(parsed, dict):
            return {k: at(v, parsed.get(k)) for k, v in given.items()}
        return given

    tt = recipe.time(t)
    return {"time": tt, "steps": [{s.effect: at(s.given, s.parsed)} for s in recipe.steps]}


class LabelCache:
    """The labels of masked Schottky stages by key: a small LRU under a lock (the
    server's threads share it).

    Parameters
    ----------
    size : int
        How many entries it keeps (the least recently used goes first).

    Examples
    --------
    >>> c = LabelCache(2)
    >>> c.update({"a": 1, "b": 2}); c.get("a"); c.update({"c": 3})
    1
    >>> c.get("b") is None, c.get("a"), c.get("c"), len(c)
    (True, 1, 3, 2)
    """

    def __init__(self, size: int = 8) -> None:
        self.size = size
        self._items: OrderedDict[str, Any] = OrderedDict()
        self._lock = threading.Lock()

    def update(self, items: dict[str, Any]) -> None:
        """Add or refresh entries, dropping the least recently used beyond ``size``."""
        with self._lock:
            for key, value in items.items():
                self._items[key] = value
                self._items.move_to_end(key)
            while len(self._items) > self.size:
                self._items.popitem(last=False)

    def get(self, key: str) -> Any | None:
        """The entry for ``key`` (now the most recently used), or None."""
        with self._lock:
            found = self._items.get(key)
            if found is not None:
                self._items.move_to_end(key)
            return found

    def __len__(self) -> int:
        with self._lock:
            return len(self._items)


def recipe_files(recipe: Any) -> list[Path]:
    """The files a recipe's steps name (their :class:`~spherewarp.recipe.params.File`
    parameters: masks), resolved.

    Examples
    --------
    >>> from spherewarp.recipe import Recipe
    >>> recipe_files(Recipe.from_dict({"spherewarp": 1, "steps": [{"power": {"n": 2}}]}))
    []
    """
    from ..recipe.effects import EFFECTS
    from ..recipe.params import File

    out = []
    for step in recipe.steps:
        specs = EFFECTS[step.effect].params
        for name, value in step.parsed.items():
            if isinstance(specs.get(name), File) and value is not None:
                out.append(Path(value).resolve())
    return out


def absolute_recipe(recipe: Any) -> dict[str, Any]:
    """The recipe as JSON data with the files its steps name (masks) as absolute paths,
    so that a copy saved anywhere (the page's "Save recipe") renders as it is.

    Examples
    --------
    >>> from spherewarp.recipe import Recipe
    >>> absolute_recipe(Recipe.from_dict({"spherewarp": 1, "steps": [{"power": {"n": 2}}]}))
    {'spherewarp': 1, 'steps': [{'power': {'n': 2}}]}
    """
    from ..recipe.effects import EFFECTS
    from ..recipe.params import File

    data = recipe.to_dict()
    given = data.get("steps", [])
    for step, item in zip(recipe.steps, given, strict=False):
        params = item.get(step.effect) if isinstance(item, dict) else None
        if not isinstance(params, dict):
            continue
        specs = EFFECTS[step.effect].params
        for name, value in step.parsed.items():
            if isinstance(specs.get(name), File) and value is not None and name in params:
                params[name] = str(Path(value).resolve())
    return data


#: parameters the page's sliders keep to integers other than zero: the shader compiles a
#: power of integer n only (another n renders on the CPU, with no live preview), and n = 0
#: is a constant map
_PREVIEW_INTEGERS = {("power", "n")}


def slider_specs() -> dict[str, dict[str, dict[str, Any]]]:
    """The bounds of every effect's number parameters, for the page's sliders: by effect
    and name, ``{"gt", "ge", "lt", "le", "integer", "nonzero"}`` (a bound None where
    there is none), so that no slider reaches a value the recipe refuses.

    Examples
    --------
    >>> specs = slider_specs()
    >>> specs["zoom"]["factor"]["ge"], specs["power"]["n"]["integer"], specs["exp"]["lam"]["gt"]
    (1e-09, True, 0)
    """
    from ..recipe.effects import EFFECTS
    from ..recipe.params import Integer, Real

    out: dict[str, dict[str, dict[str, Any]]] = {}
    for name, effect in EFFECTS.items():
        for key, spec in effect.params.items():
            if not isinstance(spec, (Real, Integer)):
                continue
            special = (name, key) in _PREVIEW_INTEGERS
            out.setdefault(name, {})[key] = {
                "gt": getattr(spec, "gt", None),
                "ge": spec.ge,
                "lt": getattr(spec, "lt", None),
                "le": spec.le,
                "integer": isinstance(spec, Integer) or special,
                "nonzero": special,
            }
    return out


def video_frame(path: str | os.PathLike[str], t: float = 0.0) -> np.ndarray:
    """The frame of a video shown at time ``t`` (seconds): the last one that starts at or
    before ``t`` (the first for a ``t`` before it), RGB uint8.

    Parameters
    ----------
    path : path
        The video.
    t : float
        Seconds from its start.

    Returns
    -------
    numpy.ndarray
        The frame, ``(height, width, 3)`` uint8.

    Raises
    ------
    ImageFormatError
        For a file that is not a video (one line).
    """
    import av

    from ..errors import ImageFormatError
    from ..io.video import probe

    path = Path(path)
    probe(path)  # a clear error for a file that is no video
    found = None
    with av.open(str(path)) as c:
        if t > 0:
            c.seek(int(t * 1_000_000), backward=True)  # a key frame at or before t
        for frame in c.decode(video=0):
            if found is not None and frame.time is not None and frame.time > t + 1e-6:
                break
            found = frame
    if found is None:
        raise ImageFormatError(f"cannot read '{path}': the video has no frames")
    return found.to_ndarray(format="rgb24")


def byte_range(header: str | None, size: int) -> tuple[int, int] | None:
    """The first and last byte an HTTP ``Range`` header asks of a file of ``size`` bytes
    (one range: ``bytes=A-B``, ``bytes=A-``, ``bytes=-N``); None for the whole file.

    A header that is not one byte range (another unit, bad syntax, a last byte before
    the first, several ranges) is ignored, as RFC 9110 (14.2) has it: None, the whole
    file (200).

    Raises ValueError for one range it cannot satisfy (416).

    Examples
    --------
    >>> byte_range("bytes=0-99", 1000), byte_range("bytes=900-", 1000), byte_range("bytes=-9", 99)
    ((0, 99), (900, 999), (90, 98))
    >>> byte_range(None, 1000), byte_range("bytes=0-5000", 1000)
    (None, (0, 999))
    >>> byte_range("junk", 1000), byte_range("bytes=5-2", 1000), byte_range("bytes=0-1,4-5", 9)
    (None, None, None)
    >>> byte_range("bytes=1000-", 1000)
    Traceback (most recent call last):
    ...
    ValueError: range bytes=1000- is outside the file (1000 bytes)
    """
    if header is None:
        return None
    found = _RANGE.fullmatch(header.strip(" \t"))
    if found is None or not (found[1] or found[2]):
        return None  # not one byte range: ignored
    first, last = found[1], found[2]
    if first and last and int(last) < int(first):
        return None  # an invalid range: ignored
    if not first:
        a, b = max(0, size - int(last)), size - 1
    else:
        a, b = int(first), min(size - 1, int(last)) if last else size - 1
    if a >= size or b < a:
        raise ValueError(f"range {header} is outside the file ({size} bytes)")
    return a, b


def url_host(address: str) -> str:
    """An address or name as a URL's host: an IPv6 address in brackets.

    Examples
    --------
    >>> url_host("::1"), url_host("127.0.0.1")
    ('[::1]', '127.0.0.1')
    """
    return f"[{address}]" if ":" in address else address


def _own_addresses(ipv6: bool) -> list[str]:
    """This machine's names and addresses, as far as the standard library tells: its host
    name, its fully qualified name, the addresses that name resolves to, and the address
    it reaches other machines from (a connected UDP socket's; no packet is sent)."""
    names = [socket.gethostname(), socket.getfqdn()]
    families = [socket.AF_INET, socket.AF_INET6] if ipv6 else [socket.AF_INET]
    try:
        for family, *_, sockaddr in socket.getaddrinfo(socket.gethostname(), None):
            if family in families:
                names.append(str(sockaddr[0]))
    except OSError:  # a host name that does not resolve
        pass
    probes = {socket.AF_INET: "192.0.2.1", socket.AF_INET6: "2001:db8::1"}  # documentation
    for family in families:
        try:
            with socket.socket(family, socket.SOCK_DGRAM) as s:
                s.connect((probes[family], 9))
                names.append(str(s.getsockname()[0]))
        except OSError:  # no route: no such address
            pass
    return [n for n in names if n and "%" not in n]  # no link-local zone ids


def is_loopback(host: str) -> bool:
    """Whether ``host`` (an IPv6 address with or without brackets) is this machine's loopback,
    which other machines cannot reach: ``localhost``, any of 127.0.0.0/8, ``::1`` (also as
    an IPv4-mapped address).

    Examples
    --------
    >>> is_loopback("127.0.0.2"), is_loopback("[::1]"), is_loopback("localhost")
    (True, True, True)
    >>> is_loopback("::ffff:127.0.0.1"), is_loopback("0.0.0.0"), is_loopback("192.168.1.2")
    (True, False, False)
    """
    name = host.strip("[]").lower()
    if name in _LOOPBACK:
        return True
    try:
        address = ipaddress.ip_address(name)
    except ValueError:  # a name other than localhost
        return False
    mapped = getattr(address, "ipv4_mapped", None)
    return address.is_loopback or (mapped is not None and mapped.is_loopback)


def host_names(host: str) -> list[str]:
    """The names a server listening on ``host`` answers to (in its requests' ``Host``
    header, with the port); any other is refused, against DNS rebinding.

    ``host`` itself; for a loopback address, the loopback names; for an address that
    listens on every interface (``0.0.0.0``, ``::``), the loopback names and this
    machine's names and addresses too (:func:`_own_addresses`), the ways other machines
    and this one reach it. IPv6 addresses are in brackets, as in a URL.

    Examples
    --------
    >>> host_names("127.0.0.1"), host_names("::1")
    (['127.0.0.1', 'localhost'], ['[::1]', '127.0.0.1', 'localhost'])
    >>> host_names("192.168.1.20"), "localhost" in host_names("0.0.0.0")
    (['192.168.1.20'], True)
    >>> "[::1]" in host_names("::"), "[::1]" in host_names(""), "[::1]" in host_names("0.0.0.0")
    (True, False, False)
    """
    host = host.strip("[]").lower()
    names = [host]
    if host in _LOOPBACK or host in _WILDCARD:  # (not 127.0.0.2: only its own name reaches it)
        names += ["127.0.0.1", "localhost"]
    if host == "::":  # both stacks: IPv6 loopback too
        names.append("::1")
    if host in _WILDCARD:
        names += _own_addresses(ipv6=host == "::")
    out: list[str] = []
    for name in names:
        name = url_host(name.lower()) if name else name
        if name and name not in out:
            out.append(name)
    return out


def display_pixels(
    pixels: np.ndarray,
    dtype: str = "uint8",
    tonemap: str | None = None,
    exposure: float | None = None,
) -> np.ndarray:
    """``pixels`` as integers of ``dtype`` for a PNG, as ``spherewarp render`` writes them:
    HDR (float) pixels tone-mapped (:func:`spherewarp.io.tonemap.tonemap`, the recipe's
    ``options.tonemap`` and ``options.exposure``, default ``aces`` at 0 EV), others
    converted as they are.

    Parameters
    ----------
    pixels : numpy.ndarray
        ``(H, W)`` or ``(H, W, C)`` pixels, any dtype.
    dtype : str
        ``"uint8"`` (the page's picture) or ``"uint16"`` (a render of HDR pixels, as the
        command writes a PNG of them).
    tonemap, exposure : str or None, float or None
        The recipe's tone map and exposure, or None for the defaults.

    Returns
    -------
    numpy.ndarray
        The pixels as ``dtype``.

    Examples
    --------
    >>> px = np.full((1, 1, 3), 1.0, np.float32)
    >>> display_pixels(px, tonemap="clip")[0, 0].tolist(), display_pixels(px)[0, 0].tolist()
    ([255, 255, 255], [232, 232, 232])
    """
    from ..io.images import convert_dtype
    from ..io.tonemap import DEFAULT_TONEMAP
    from ..io.tonemap import tonemap as tone

    a = np.asarray(pixels)
    if a.dtype.kind == "f":
        flat = a.ndim == 2
        a = tone(a[:, :, None] if flat else a, tonemap or DEFAULT_TONEMAP, exposure or 0.0)
        a = a[:, :, 0] if flat else a
    return convert_dtype(a, dtype)


def _png_bytes(
    pixels: np.ndarray, tonemap: str | None = None, exposure: float | None = None
) -> bytes:
    from PIL import Image

    a = display_pixels(pixels, "uint8", tonemap, exposure)
    if a.ndim == 3 and a.shape[2] == 1:
        a = a[:, :, 0]
    elif a.ndim == 3 and a.shape[2] == 2:
        a = np.repeat(a[:, :, :1], 3, axis=2)
    buf = io.BytesIO()
    Image.fromarray(np.ascontiguousarray(a)).save(buf, format="PNG", compress_level=1)
    return buf.getvalue()


class _Server(ThreadingHTTPServer):
    """The HTTP server on IPv4 (``http.server``'s), one thread a connection."""

    daemon_threads = True

    def handle_error(self, request: Any, client_address: Any) -> None:
        """A client that went away (reset, broken pipe) is no error; anything else
        unexpected is one line on stderr, not socketserver's traceback."""
        exc = sys.exc_info()[1]
        if isinstance(exc, ConnectionError):
            return
        where = client_address[0] if isinstance(client_address, tuple) else client_address
        line = f"{type(exc).__name__}: {exc}".splitlines()[0]
        print(f"spherewarp view: error serving {where}: {line}", file=sys.stderr, flush=True)


class _Server6(_Server):
    """The HTTP server on IPv6; on ``::``, IPv4 too where the system allows."""

    address_family = socket.AF_INET6

    def server_bind(self) -> None:
        if self.server_address[0] == "::":  # every interface: both stacks
            try:
                self.socket.setsockopt(socket.IPPROTO_IPV6, socket.IPV6_V6ONLY, 0)
            except (OSError, AttributeError):  # a system with IPv6 sockets only
                pass
        super().server_bind()


def _server(host: str, port: int) -> _Server:
    """A server listening on ``host`` (an IPv6 address: on IPv6) and ``port``."""
    cls = _Server6 if ":" in host else _Server
    return cls((host, port), _Handler)


class _Job:
    def __init__(self) -> None:
        self.progress = 0.0
        self.started = False
        self.done = False
        self.error: str | None = None
        self.path: Path | None = None


class RenderQueueFull(RuntimeError):
    """:data:`MAX_QUEUED` renders already wait: the page should try again later."""


class ViewerServer:
    """The viewer's server, serving in a thread from construction until :meth:`close`.

    Parameters
    ----------
    image : path or None
        The panorama to show (None: the bundled sample), or a video (by its
        extension, :data:`spherewarp.io.video.VIDEO_EXTENSIONS`): the page plays it
        with the effect applied live.
    recipe : path or None
        A recipe to start from (None: no steps). Relative file names in the recipes
        the page sends are read from its folder.
    masks : sequence of paths
        Mask images a recipe from the page may name, besides those the starting
        recipe names: no other file is read for a recipe that comes over HTTP
        (``schottky.mask``, ``droste.mask``: 403 otherwise).
    host : str
        The address to listen on (loopback by default): IPv4, or IPv6 (``::1``, also as
        ``[::1]``). Requests must name it, or another name of it, in their ``Host``
        header (:func:`host_names`; 403 otherwise): an address that listens on every
        interface (``0.0.0.0``, ``::``) answers to the loopback names and this machine's
        own names and addresses.
    port : int
        The port (0: a free one).
    """

    def __init__(
        self,
        image: str | os.PathLike[str] | None,
        recipe: str | os.PathLike[str] | None,
        *,
        masks: Sequence[str | os.PathLike[str]] = (),
        host: str = "127.0.0.1",
        port: int = 0,
    ) -> None:
        from ..io.images import read_image
        from ..io.video import VIDEO_EXTENSIONS
        from ..recipe import Recipe

        if image is None:
            image = Path(__file__).parent.parent / "data" / "courtyard.png"
        self.image_path = Path(image)
        #: whether the input is a video: the page plays it (``/video``) as its texture
        self.video = self.image_path.suffix.lower() in VIDEO_EXTENSIONS
        # a video's first frame stands for it in /image and in "render full resolution"
        self.image = video_frame(self.image_path) if self.video else read_image(self.image_path)
        #: a video's frame rate (frames a second; the page times the recipe by its frames)
        self.rate: float | None = None
        if self.video:
            from ..io.video import probe

            rate = probe(self.image_path).rate
            self.rate = float(rate) if rate else None
        self.recipe = Recipe.load(recipe) if recipe is not None else Recipe.from_dict(_EMPTY)
        # HDR shown as 'spherewarp render' writes it: the recipe's tone map and exposure
        first = self.recipe.at(0.0)
        self.image_png = _png_bytes(self.pixels, first.tonemap, first.exposure)
        #: the folder relative file names in posted recipes are read from
        self.base = self.recipe.base
        #: the only files a posted recipe may name: the starting recipe's, and ``masks``
        self.files = frozenset([*(Path(m).resolve() for m in masks), *recipe_files(self.recipe)])
        #: full-resolution renders by key, oldest first (at most :data:`MAX_JOBS`)
        self.jobs: dict[str, _Job] = {}
        self._jobs_lock = threading.Lock()
        # renders run one at a time, in one worker (each one uses every core already)
        self._queue: queue.SimpleQueue[Any] = queue.SimpleQueue()
        threading.Thread(target=self._render_worker, daemon=True).start()
        self.labels = LabelCache()  # masked Schottky labels by key (/api/labels/KEY)
        self._pattern: bytes | None = None
        host = host.strip("[]")  # an IPv6 address as in a URL: [::1]
        self.httpd = _server(host, port)  # OSError: cannot listen (nothing made yet)
        self.httpd.viewer = self  # type: ignore[attr-defined]
        self.tmp = Path(tempfile.mkdtemp(prefix="spherewarp-view-"))
        #: the address it listens on (an IPv6 address without brackets)
        self.host = host
        self.port = self.httpd.server_address[1]
        #: the names requests may give in their Host header (without the port)
        self.host_names = host_names(host)
        self.allowed_hosts = {f"{h}:{self.port}" for h in self.host_names}
        self.origins = {f"http://{h}" for h in self.allowed_hosts}
        self.url = f"http://{url_host(host)}:{self.port}/"
        self._thread = threading.Thread(target=self.httpd.serve_forever, daemon=True)
        self._thread.start()

    def close(self) -> None:
        """Stop serving and remove the rendered files."""
        self._queue.put(None)  # the render worker stops after the render it is on
        self.httpd.shutdown()
        self.httpd.server_close()
        shutil.rmtree(self.tmp, ignore_errors=True)

    def wait(self) -> None:
        """Block until interrupted."""
        self._thread.join()

    @property
    def pixels(self) -> np.ndarray:
        """The image's pixels (a video's first frame)."""
        return np.asarray(getattr(self.image, "pixels", self.image))

    def pattern_png(self) -> bytes:
        """The test pattern as PNG (made on first use)."""
        if self._pattern is None:
            from ..testpattern import make_test_pattern

            self._pattern = _png_bytes(make_test_pattern(1024, 512))
        return self._pattern

    # -- the API --------------------------------------------------------------------------
    def state(self) -> dict[str, Any]:
        from ..render import stages
        from .glsl import EXPRESSION, glsl_header

        h, w = self.pixels.shape[:2]
        return {
            # file names absolute: a recipe the page saves renders wherever it is saved
            "recipe": absolute_recipe(self.recipe),
            "image": {"width": w, "height": h, "name": self.image_path.name, "video": self.video},
            "rate": self.rate,
            "stages": packed_stages(self.recipe, labels=self.labels),
            "glsl_header": glsl_header(),
            "table": json.loads(stages.as_json(extra=(EXPRESSION,))),
            "params": slider_specs(),
        }

    def start_render(self, recipe: Any, t: float | None = None) -> str:
        """Render ``recipe`` at full resolution (a video: its frame at time ``t``, default
        the first); returns the job's key.

        Renders run one at a time, in the order asked; :data:`MAX_JOBS` are kept (the
        oldest finished one goes, with its file, when a new one comes).

        Raises
        ------
        RenderQueueFull
            If :data:`MAX_QUEUED` renders already wait.
        """
        job = _Job()
        key = uuid.uuid4().hex
        with self._jobs_lock:
            if sum(not j.started for j in self.jobs.values()) >= MAX_QUEUED:
                raise RenderQueueFull(f"{MAX_QUEUED} renders are waiting already")
            self.jobs[key] = job
            self._prune()
        self._queue.put((key, job, recipe, t))
        return key

    def _prune(self) -> None:
        """Forget the oldest finished renders, and remove their files, beyond
        :data:`MAX_JOBS` (called with the jobs' lock held)."""
        extra = len(self.jobs) - MAX_JOBS
        for key in [k for k, j in self.jobs.items() if j.done][: max(extra, 0)]:
            gone = self.jobs.pop(key)
            if gone.path is not None:
                gone.path.unlink(missing_ok=True)

    def _render_worker(self) -> None:
        while (item := self._queue.get()) is not None:
            self._render(*item)

    def _render(self, key: str, job: _Job, recipe: Any, t: float | None) -> None:
        from ..io.images import write_image

        def progress(done: float, total: float | None = None) -> None:
            job.progress = float(done) / float(total) if total else float(done)

        job.started = True
        try:
            image = self.image
            if self.video and t is not None:
                image = video_frame(self.image_path, t)
            when = 0.0 if t is None else t  # a video's time is the recipe's
            try:
                out = recipe.render(image, t=when, progress=progress)
            except TypeError:  # a renderer without progress reporting
                out = recipe.render(image, t=when)
            pixels = np.asarray(getattr(out, "pixels", out))
            if pixels.dtype.kind == "f":  # HDR: tone-mapped to 16 bits, as the command does
                frame = recipe.at(when)
                pixels = display_pixels(pixels, "uint16", frame.tonemap, frame.exposure)
            path = self.tmp / f"{self.image_path.stem}-{key[:8]}.png"
            write_image(path, pixels, gpano=None)
            job.path = path
            job.progress = 1.0
        except Exception as exc:  # reported to the page, not raised in a thread
            # the server's own folder is nobody's business: the file's name is enough
            job.error = f"{type(exc).__name__}: {exc}".replace(f"{self.tmp}{os.sep}", "")
        finally:
            job.done = True


class _Error(Exception):
    def __init__(self, status: int, message: str, headers: dict[str, str] | None = None) -> None:
        super().__init__(message)
        self.status = status
        self.message = message
        self.headers = headers or {}


class _Handler(BaseHTTPRequestHandler):
    server_version = "spherewarp-view"
    protocol_version = "HTTP/1.1"
    _body_read = False  # whether the request's body was read (set by _begin, _body)
    _replied = False  # whether the reply's status line went out (set by _serve, _head)

    @property
    def viewer(self) -> ViewerServer:
        return self.server.viewer  # type: ignore[attr-defined]

    def log_message(self, format: str, *args: Any) -> None:  # quiet
        pass

    # -- checks ---------------------------------------------------------------------------
    def _begin(self) -> None:
        """Start on a request (the handler serves each request of a kept-alive
        connection in turn): its body is not read yet, and its framing must be plain."""
        self._body_read = False
        self._check_framing()

    def _check_framing(self) -> None:
        """Refuse (400) what two HTTP parsers could read as different requests: a proxy
        in front, or this server after a refusal, must never see a body as a request.

        Raises
        ------
        _Error
            400 for a second ``Host`` or ``Content-Length``, any ``Transfer-Encoding``
            (only ``Content-Length`` bodies are read), a length that is not plain
            digits, or a request target that is not a path (absolute-form
            ``http://host/path``, authority-form, ``*``).
        """
        if not self.path.startswith("/"):
            raise _Error(400, "the request target must be a path (/...)")
        for name in ("Host", "Content-Length"):
            if len(self.headers.get_all(name, [])) > 1:
                raise _Error(400, f"more than one {name} header")
        if self.headers.get("Transfer-Encoding") is not None:
            raise _Error(400, "Transfer-Encoding is not supported: send a Content-Length")
        length = self.headers.get("Content-Length")
        if length is not None and not _LENGTH.fullmatch(length.strip(" \t")):
            raise _Error(400, f"bad Content-Length {length:.20}")

    def _body_pending(self) -> bool:
        """Whether the request has a body not read (or a length not understood)."""
        if self._body_read:
            return False
        length = self.headers.get("Content-Length")
        if length is None:
            return self.headers.get("Transfer-Encoding") is not None
        length = length.strip(" \t")
        return not (_LENGTH.fullmatch(length) and int(length) == 0)

    def _check_common(self, api: bool) -> None:
        host = self.headers.get("Host", "")
        if host.lower() not in self.viewer.allowed_hosts:
            raise _Error(403, f"Host {host!r} is not this server (DNS rebinding?)")
        if api:
            origin = self.headers.get("Origin")
            if origin is not None and origin.lower() not in self.viewer.origins:
                raise _Error(403, f"cross-origin request from {origin!r} refused")
            site = self.headers.get("Sec-Fetch-Site")
            if site is not None and site not in ("same-origin", "none"):
                raise _Error(403, f"cross-site request ({site}) refused")

    def _path(self) -> str:
        # the path as sent: urlsplit would read "//name/x" as a host and the path /x
        raw = self.path.partition("?")[0].partition("#")[0]
        path = urllib.parse.unquote(raw)
        if "\x00" in path or "\\" in path:
            raise _Error(400, "bad path")
        if any(part in ("..", ".") for part in path.split("/")):
            raise _Error(404, "not found")
        return path

    def _time(self) -> float | None:
        """The ``t`` of the query (a video's time in seconds), if any."""
        query = urllib.parse.parse_qs(urllib.parse.urlsplit(self.path).query)
        if "t" not in query:
            return None
        try:
            t = float(query["t"][0])
        except ValueError:
            t = float("nan")
        if not (0 <= t < 1e7):
            raise _Error(400, f"t: expected a time in seconds >= 0, got {query['t'][0]!r:.40}")
        return t

    def _body(self) -> bytes:
        length = self.headers.get("Content-Length")
        if length is None:
            raise _Error(411, "a Content-Length is required")
        n = int(length.strip(" \t"))  # plain digits (_check_framing)
        if n > MAX_BODY:  # refused unread: the reply closes the connection
            raise _Error(413, f"body of {n} bytes is over the limit of {MAX_BODY} bytes")
        body = self.rfile.read(n)
        if len(body) < n:  # the client went away: nothing more to read
            self.close_connection = True
        self._body_read = True
        return body

    def _recipe(self) -> Any:
        from ..recipe import Recipe, RecipeError
        from ..recipe.params import FileRefused, allowed_files

        body = self._body()
        try:
            with allowed_files(self.viewer.files):
                return Recipe.loads(body, base=self.viewer.base)
        except FileRefused as exc:  # refused before the file is looked at
            raise _Error(403, f"recipe: {exc}") from None
        except RecipeError as exc:
            raise _Error(400, f"recipe: {exc}") from None
        except Exception as exc:  # a builder's own error on odd values
            raise _Error(400, f"recipe: {exc}") from None

    # -- replies --------------------------------------------------------------------------
    def _head(self, status: int, ctype: str, length: int, extra: dict[str, str]) -> None:
        """The status line and headers. An error reply, or a reply to a request whose body
        was not read, ends the connection (``Connection: close``): what is left of the
        request is never read as the next one."""
        self._replied = True
        self.send_response(status)
        self.send_header("Content-Type", ctype)
        self.send_header("Content-Length", str(length))
        self.send_header("X-Content-Type-Options", "nosniff")
        self.send_header("Cache-Control", "no-store")
        for k, v in extra.items():
            self.send_header(k, v)
        if status >= 400 or self._body_pending():
            self.send_header("Connection", "close")  # also sets self.close_connection
        self.end_headers()

    def _send(
        self, status: int, body: bytes, ctype: str, extra: dict[str, str] | None = None
    ) -> None:
        try:
            self._head(status, ctype, len(body), extra or {})
            if self.command != "HEAD":
                self.wfile.write(body)
        except ConnectionError:  # the client went away (reset, broken pipe)
            self.close_connection = True

    def _send_file(self, path: Path, ctype: str) -> None:
        """The file, or the one byte range asked for (206), in pieces: a video may be big."""
        size = path.stat().st_size
        try:
            rng = byte_range(self.headers.get("Range"), size)
        except ValueError as exc:
            raise _Error(416, str(exc), {"Content-Range": f"bytes */{size}"}) from None
        a, b = rng if rng is not None else (0, size - 1)
        extra = {"Accept-Ranges": "bytes"}
        if rng is not None:
            extra["Content-Range"] = f"bytes {a}-{b}/{size}"
        try:
            self._head(206 if rng is not None else 200, ctype, max(0, b - a + 1), extra)
            if self.command == "HEAD":
                return
            with open(path, "rb") as f:
                f.seek(a)
                left = b - a + 1
                while left > 0:
                    chunk = f.read(min(left, 1 << 20))
                    if not chunk:
                        break
                    self.wfile.write(chunk)
                    left -= len(chunk)
        except ConnectionError:  # the browser had enough (reset, broken pipe)
            self.close_connection = True

    def _json(self, data: Any, status: int = 200) -> None:
        self._send(status, json.dumps(data).encode(), "application/json")

    def _fail(self, err: _Error) -> None:
        body = json.dumps({"error": err.message}).encode()
        self._send(err.status, body, "application/json", err.headers)

    def _serve(self, work: Any) -> None:
        """Run ``work`` on a request: a refusal (:class:`_Error`) is its status and
        message; anything else unexpected is one line on stderr and a 500 (or, past the
        headers, the connection's end), never a dropped connection without a reply."""
        self._replied = False
        try:
            self._begin()
            work()
        except _Error as err:
            self._fail(err)
        except Exception as exc:
            self.server.handle_error(self.request, self.client_address)
            if self._replied:  # part of a reply went out: nothing else can follow
                self.close_connection = True
            else:
                self._fail(_Error(500, f"internal error: {type(exc).__name__}"))

    def do_GET(self) -> None:  # noqa: N802
        def work() -> None:
            path = self._path()
            self._check_common(path.startswith("/api/"))
            self._get(path)

        self._serve(work)

    do_HEAD = do_GET

    def do_POST(self) -> None:  # noqa: N802
        def work() -> None:
            path = self._path()
            self._check_common(True)
            if path == "/api/stages":
                recipe = self._recipe()
                try:
                    t = self._time() or 0.0  # a video's time: an animated recipe's too
                    reply = {"stages": packed_stages(recipe, t, labels=self.viewer.labels)}
                    if recipe.animated:  # where its marks are at that time
                        reply["at"] = steps_at(recipe, t)
                except Exception as exc:
                    raise _Error(400, f"recipe: {exc}") from None
                self._json(reply)
            elif path == "/api/render":
                recipe, t = self._recipe(), self._time()
                try:
                    key = self.viewer.start_render(recipe, t)
                except RenderQueueFull as exc:
                    raise _Error(429, f"{exc}: try again when one is done",
                                 {"Retry-After": "5"}) from None  # fmt: skip
                self._json({"job": key})
            else:
                raise _Error(404, "not found")

        self._serve(work)

    def _get(self, path: str) -> None:
        v = self.viewer
        if path == "/api/state":
            return self._json(v.state())
        if path == "/image":
            return self._send(200, v.image_png, "image/png")
        if path == "/video" and v.video:
            return self._send_file(
                v.image_path, "video/" + _VIDEO_TYPES.get(v.image_path.suffix.lower(), "mp4")
            )
        if path == "/testpattern":
            return self._send(200, v.pattern_png(), "image/png")
        if path.startswith("/api/labels/"):
            found = v.labels.get(path[len("/api/labels/") :])
            if found is None:
                raise _Error(404, "no such labels")
            return self._send(200, found[2].astype("<i2").tobytes(), "application/octet-stream")
        if path.startswith("/api/render/"):
            parts = path[len("/api/render/") :].split("/")
            job = v.jobs.get(parts[0])
            if job is None or len(parts) > 2 or (len(parts) == 2 and parts[1] != "file"):
                raise _Error(404, "no such render")
            if len(parts) == 1:
                return self._json({"started": job.started, "done": job.done,
                                   "progress": job.progress, "error": job.error})  # fmt: skip
            if job.error is not None:  # done, and no file will come
                raise _Error(422, f"the render failed: {job.error}")
            if job.path is None:
                raise _Error(409, "the render is not done")
            try:
                data = job.path.read_bytes()
            except FileNotFoundError:  # forgotten (MAX_JOBS) since it was looked up
                raise _Error(404, "no such render") from None
            return self._send(
                200,
                data,
                "image/png",
                {"Content-Disposition": f'attachment; filename="{job.path.name}"'},
            )
        if path.startswith("/api/"):
            raise _Error(404, "not found")
        rel = "index.html" if path in ("/", "/index.html") else path.lstrip("/")
        root = STATIC_DIR.resolve()
        target = (root / rel).resolve()
        if root not in target.parents or not target.is_file():
            raise _Error(404, "not found")
        ctype = mimetypes.guess_type(target.name)[0] or "application/octet-stream"
        if target.suffix == ".js":
            ctype = "text/javascript"
        self._send(200, target.read_bytes(), ctype)
