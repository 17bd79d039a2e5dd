"""The paper's test pattern, drawn procedurally at any size.

A latitude/longitude grid (every 15 degrees, thicker every 45), the equator
in blue and the meridian through the front and the back in red (the paper's
"blue equator and red longitude"), checker shading of the grid cells (warm
in the northern hemisphere, cool in the southern) so that rotations are easy
to read, and the six points 0, 1, i, -1, -i and infinity of a chart of the
Riemann sphere marked with coloured discs and labels.

Everything except the text is computed from each pixel's direction and
anti-aliased analytically (box-filter coverage of each pixel), so the pattern
is sharp at any size. The discs are spherical caps: they stay round after a
rotation brings them anywhere on the sphere.

Charts (where the six points are):

==========  ======  ======  ===========  ======  ===========  ======
chart       0       1       i            -1      -i           inf
==========  ======  ======  ===========  ======  ===========  ======
``zenith``  zenith  back    lon -90      front   lon +90      nadir
``front``   front   lon +90 zenith       lon -90 nadir        back
==========  ======  ======  ===========  ======  ===========  ======

``zenith`` is the library's default chart,
``z = tan((90 - lat)/2) * exp(i (lon + 180))`` (see :mod:`spherewarp.coords`).
``front`` puts 0 at the front as in the paper's test-pattern figure; it is
the default chart turned by the rotation taking the zenith to the front and
the back to lon +90 (both charts have the same orientation), and it reads
as the complex plane drawn as usual seen from the centre looking at the
front: real axis to the right, imaginary axis up,
``z = (y + i z_3) / (1 + x)`` for the unit vector ``(x, y, z_3)``.

Convention: pixel centres at half-integers, lon 0 at the image centre,
lon growing to the right, lat upwards (see :mod:`spherewarp.coords`).

Examples
--------
>>> from spherewarp.testpattern import make_test_pattern, chart_points
>>> img = make_test_pattern(256)
>>> img.shape, img.dtype
((128, 256, 3), dtype('uint8'))
>>> chart_points("front")["1"]
(90.0, 0.0)
"""

from __future__ import annotations

import functools
import math
from typing import Any

import numpy as np
from numpy.typing import DTypeLike, NDArray

from . import coords
from .errors import InvalidTypeError, InvalidValueError

__all__ = ["CHARTS", "chart_points", "make_test_pattern"]

#: The charts :func:`make_test_pattern` can mark: label -> (lon, lat) in degrees.
CHARTS: dict[str, dict[str, tuple[float, float]]] = {
    "zenith": {
        "0": (0.0, 90.0),
        "1": (180.0, 0.0),
        "i": (-90.0, 0.0),
        "-1": (0.0, 0.0),
        "-i": (90.0, 0.0),
        "inf": (0.0, -90.0),
    },
    "front": {
        "0": (0.0, 0.0),
        "1": (90.0, 0.0),
        "i": (0.0, 90.0),
        "-1": (-90.0, 0.0),
        "-i": (0.0, -90.0),
        "inf": (180.0, 0.0),
    },
}

# Colours (sRGB, 0..1).
_NORTH = ((0.985, 0.965, 0.915), (0.905, 0.865, 0.780))  # warm checker
_SOUTH = ((0.925, 0.950, 0.975), (0.800, 0.845, 0.900))  # cool checker
_MINOR = (0.55, 0.55, 0.58)
_MAJOR = (0.30, 0.30, 0.34)
_EQUATOR = (0.10, 0.33, 0.85)
_MERIDIAN = (0.85, 0.12, 0.12)
_OUTLINE = (0.08, 0.08, 0.10)
_TEXT = (0.08, 0.08, 0.10)
_HALO = (1.0, 1.0, 1.0)
_POINT_COLOURS = {
    "0": (0.10, 0.65, 0.25),  # green
    "1": (1.00, 0.55, 0.05),  # orange
    "i": (0.05, 0.75, 0.85),  # cyan
    "-1": (0.90, 0.30, 0.75),  # magenta
    "-i": (0.95, 0.85, 0.10),  # yellow
    "inf": (0.45, 0.22, 0.65),  # purple
}
_POLE_LABEL_LONS = (-157.5, -67.5, 22.5, 112.5)


def chart_points(chart: str = "zenith") -> dict[str, tuple[float, float]]:
    """Where the points 0, 1, i, -1, -i and infinity of a chart lie, as (lon, lat) degrees.

    Parameters
    ----------
    chart : {"zenith", "front"}
        ``"zenith"`` is the library's default chart; ``"front"`` puts 0 at the
        front (see the module documentation). Case-insensitive.

    Returns
    -------
    dict
        Keys ``"0"``, ``"1"``, ``"i"``, ``"-1"``, ``"-i"``, ``"inf"``.

    Examples
    --------
    >>> chart_points()["-1"]
    (0.0, 0.0)
    """
    return dict(CHARTS[_check_chart(chart)])


def _check_chart(chart: Any) -> str:
    name = str(chart).strip().lower()
    if name not in CHARTS:
        raise InvalidValueError(f"unknown chart {chart!r}; expected one of: {', '.join(CHARTS)}")
    return name


def _check_dtype(dtype: DTypeLike) -> np.dtype:
    try:
        dt = np.dtype(dtype)
    except TypeError:
        dt = None
    if dt is None or dt not in (np.dtype(np.uint8), np.dtype(np.uint16), np.dtype(np.float32)):
        raise InvalidTypeError(f"expected dtype uint8, uint16 or float32, got {dtype!r}")
    return dt


def _band(d: NDArray, half: NDArray | float, foot: NDArray | float) -> NDArray:
    """Box-filter coverage of the band ``|t| <= half`` by a pixel ``[d - foot/2, d + foot/2]``."""
    lo = np.maximum(d - 0.5 * foot, -half)
    hi = np.minimum(d + 0.5 * foot, half)
    return np.clip((hi - lo) / foot, 0.0, 1.0)


def _paint(img: NDArray, cover: NDArray, colour: tuple[float, float, float]) -> None:
    """Alpha-blend ``colour`` over ``img`` (rows, cols, 3) with coverage ``cover`` (in place).

    Only the covered pixels are touched (lines and discs cover a small part).
    """
    r, c = np.nonzero(cover > 0)
    if r.size == 0:
        return
    a = cover[r, c][:, None]
    img[r, c] = img[r, c] * (1.0 - a) + a * np.asarray(colour)


def _smooth_sign(t: NDArray, pixels_per_unit: NDArray | float) -> NDArray:
    """Box-filtered square wave: +1 on even cells ``floor(t)``, -1 on odd ones."""
    sign = 1.0 - 2.0 * (np.floor(t) % 2)
    edge = np.abs(t - np.rint(t)) * pixels_per_unit  # distance to the nearest edge, pixels
    return sign * np.minimum(1.0, 2.0 * edge)


def _degrees_wave(x: NDArray, step: float) -> NDArray:
    """Signed distance (degrees) from ``x`` to the nearest multiple of ``step``."""
    return x - step * np.rint(x / step)


def _sizes(width: int, height: int) -> dict[str, float]:
    """Line widths, disc radius and rim in degrees of arc for an image size."""
    px = max(360.0 / width, 180.0 / height)  # degrees per pixel (the coarser axis)
    return {
        "px": px,
        "minor": max(0.35, 1.0 * px),
        "major": max(0.70, 1.6 * px),
        "special": max(1.05, 2.4 * px),
        "radius": max(4.0, 5.0 * px),
        "rim": max(0.6, 1.0 * px),
    }


def _draw_rows(width: int, height: int, r0: int, r1: int, chart: str) -> NDArray[np.float64]:
    """Rows ``r0:r1`` of the pattern without text, float64 RGB in 0..1."""
    w, h = width, height
    deg_x = 360.0 / w  # degrees of longitude per pixel
    deg_y = 180.0 / h  # degrees of latitude per pixel
    x = (np.arange(w) + 0.5)[None, :]
    y = (np.arange(r0, r1) + 0.5)[:, None]
    lon = x * deg_x - 180.0  # (1, w)
    lat = 90.0 - y * deg_y  # (rows, 1)
    shape = (r1 - r0, w)
    coslat = np.cos(np.radians(lat))
    size = _sizes(w, h)

    # Checker of 15-degree cells, warm in the north and cool in the south.
    sx = _smooth_sign(lon / 15.0, 15.0 / deg_x)
    sy = _smooth_sign(lat / 15.0, 15.0 / deg_y)
    check = (0.5 + 0.5 * sx * sy)[..., None]  # 1 on light cells, 0 on dark ones
    north = np.clip(0.5 + lat / deg_y, 0.0, 1.0)[..., None]  # coverage of lat > 0
    img = np.zeros((*shape, 3))
    for cover, (light, dark) in ((north, _NORTH), (1.0 - north, _SOUTH)):
        img += cover * (check * np.asarray(light) + (1.0 - check) * np.asarray(dark))

    def parallels(step: float, width_deg: float, skip: float | None) -> NDArray:
        # Exact distances in latitude; the pixel footprint is one pixel high.
        d = _degrees_wave(lat, step)
        cover = _band(d, 0.5 * width_deg, deg_y)
        if skip is not None:  # leave the lines that a coarser grid draws
            cover = np.where(np.abs(_degrees_wave(lat, skip)) < 0.5 * step, 0.0, cover)
        return np.broadcast_to(cover, shape)

    def meridians(step: float, width_deg: float, skip: float | None, max_lat: float) -> NDArray:
        # Vertical stripes of constant width on the sphere (so 1/cos(lat) wider in the
        # image), capped at 2x their equator width near the poles.
        d = _degrees_wave(lon, step)
        s = np.sin(np.radians(0.5 * width_deg)) / np.maximum(coslat, 1e-12)
        half = np.minimum(np.degrees(np.arcsin(np.minimum(s, 1.0))), 1.0 * width_deg)
        cover = _band(d, half, deg_x)
        if skip is not None:
            cover = np.where(np.abs(_degrees_wave(lon, skip)) < 0.5 * step, 0.0, cover)
        ends = np.clip((max_lat - np.abs(lat)) / deg_y + 0.5, 0.0, 1.0)
        return np.broadcast_to(cover * ends, shape)

    minor = np.maximum(
        parallels(15.0, size["minor"], 45.0), meridians(15.0, size["minor"], 45.0, 75.0)
    )
    _paint(img, minor, _MINOR)
    major = np.maximum(
        parallels(45.0, size["major"], None), meridians(45.0, size["major"], 180.0, 90.0)
    )
    _paint(img, major, _MAJOR)
    _paint(img, meridians(180.0, size["special"], None, 90.0), _MERIDIAN)
    _paint(img, parallels(1000.0, size["special"], None), _EQUATOR)

    # The six points: spherical caps with a dark rim, each computed on the block of
    # rows and columns that its cap can touch.
    radius, rim = size["radius"], size["rim"]
    reach = radius + 2.0 * max(deg_x, deg_y)  # the cap and its anti-aliased edge
    for name, (plon, plat) in CHARTS[chart].items():
        rows = np.nonzero(np.abs(lat[:, 0] - plat) <= reach)[0]
        if rows.size == 0:
            continue
        if abs(plat) + reach >= 90.0:  # the cap holds a pole: every column
            cols = np.arange(w)
        else:
            half = math.degrees(
                math.asin(
                    min(
                        1.0,
                        math.sin(math.radians(reach)) / math.cos(math.radians(abs(plat) + reach)),
                    )
                )
            )
            cols = np.nonzero(np.abs(_degrees_wave(lon[0] - plon, 360.0)) <= half + deg_x)[0]
        block = img[np.ix_(rows, cols)]
        lon_r, lat_r = np.radians(lon[:, cols]), np.radians(lat[rows])
        xyz = coords.xyz_from_lonlat(np.stack(np.broadcast_arrays(lon_r, lat_r), -1))
        east = np.stack(np.broadcast_arrays(-np.sin(lon_r), np.cos(lon_r), 0.0 * lat_r), -1)
        c = coords.xyz_from_lonlat(np.radians([plon, plat]))
        dot = xyz @ c
        theta = np.degrees(np.arctan2(np.linalg.norm(np.cross(xyz, c), axis=-1), dot))
        # The direction in which theta grows, split into east and north parts: the
        # pixel's extent along it is the footprint for the anti-aliasing.
        g = xyz * dot[..., None] - c
        g /= np.maximum(np.linalg.norm(g, axis=-1, keepdims=True), 1e-300)
        ge = np.abs(np.sum(g * east, axis=-1))
        gn = np.sqrt(np.clip(1.0 - ge * ge, 0.0, 1.0))
        foot = np.maximum(ge * coslat[rows] * deg_x + gn * deg_y, 1e-9)
        _paint(block, np.clip((radius - theta) / foot + 0.5, 0.0, 1.0), _OUTLINE)
        _paint(block, np.clip((radius - rim - theta) / foot + 0.5, 0.0, 1.0), _POINT_COLOURS[name])
        img[np.ix_(rows, cols)] = block
    return img


_LABEL_TEXT = {"0": "0", "1": "1", "i": "i", "-1": "-1", "-i": "-i", "inf": "\u221e"}


@functools.cache
def _font(size: int) -> Any:
    from PIL import ImageFont

    return ImageFont.load_default(size=size)


def _text_masks(
    w: int, r0: int, r1: int, items: list[tuple[float, float, str, str, int]]
) -> tuple[NDArray, NDArray]:
    """Coverage masks (fill, halo) of rows ``r0:r1`` of text items ``(x, y, text, anchor, size)``.

    Each item is drawn three times, shifted by -w, 0, +w, so text wraps
    round the seam. ``"\u221e"`` is drawn as a lemniscate (the bundled font
    has no glyph for it).
    """
    from PIL import Image, ImageDraw

    rows = r1 - r0
    ss = 4  # the lemniscate is drawn 4x larger and box-filtered down (anti-aliasing)
    fill, halo = Image.new("L", (w, rows), 0), Image.new("L", (w, rows), 0)
    dfill, dhalo = ImageDraw.Draw(fill), ImageDraw.Draw(halo)
    fill_ss = halo_ss = None
    for x, y, text, anchor, size in items:
        if not (r0 - 2 * size <= y <= r1 + 2 * size):
            continue
        stroke = max(1, round(size / 8))
        for shift in (-w, 0, w):
            if not (-4 * size <= x + shift <= w + 4 * size):
                continue
            if text == "\u221e":
                if fill_ss is None:
                    fill_ss = Image.new("L", (w * ss, rows * ss), 0)
                    halo_ss = Image.new("L", (w * ss, rows * ss), 0)
                pts = [(ss * a, ss * b) for a, b in _lemniscate(x + shift, y - r0, size, anchor)]
                line_w = ss * max(1.0, size / 11)
                ImageDraw.Draw(halo_ss).line(
                    pts, fill=255, width=round(line_w + 2 * ss * stroke), joint="curve"
                )
                ImageDraw.Draw(fill_ss).line(pts, fill=255, width=round(line_w), joint="curve")
                continue
            xy = (x + shift, y - r0)
            font = _font(size)
            dhalo.text(xy, text, font=font, anchor=anchor, fill=255, stroke_width=stroke)
            dfill.text(xy, text, font=font, anchor=anchor, fill=255)

    def down(big: Any) -> NDArray:
        return np.asarray(big, np.float64).reshape(rows, ss, w, ss).mean(axis=(1, 3))

    fill_a, halo_a = np.asarray(fill, np.float64), np.asarray(halo, np.float64)
    if fill_ss is not None:
        fill_a, halo_a = np.maximum(fill_a, down(fill_ss)), np.maximum(halo_a, down(halo_ss))
    return fill_a / 255.0, halo_a / 255.0


def _lemniscate(x: float, y: float, size: int, anchor: str) -> list[tuple[float, float]]:
    """Points of an infinity sign about as wide as two digits of a font of ``size``."""
    half_w = 0.55 * size
    t = np.linspace(0.0, 2.0 * np.pi, 97)
    den = 1.0 + np.sin(t) ** 2
    px = half_w * np.cos(t) / den
    py = 1.0 * half_w * np.sin(t) * np.cos(t) / den
    cx = {"l": x + half_w, "r": x - half_w}.get(anchor[0], x)
    cy = {"t": y + 0.35 * size, "b": y - 0.35 * size}.get(anchor[1], y)
    return [(float(cx + a), float(cy + b)) for a, b in zip(px, py, strict=True)]


def _label_items(w: int, h: int, chart: str) -> list[tuple[float, float, str, str, int]]:
    """Text items ``(x, y, text, anchor, font size)`` for an image of ``w x h``."""
    size = round(h / 20)
    if size < 8:  # too small to read: no text
        return []
    small = max(8, round(size * 0.6))
    sizes = _sizes(w, h)
    items: list[tuple[float, float, str, str, int]] = []

    def pix(lon: float, lat: float) -> tuple[float, float]:
        return (lon + 180.0) / 360.0 * w, (90.0 - lat) / 180.0 * h

    gap = (sizes["radius"] + 1.2 * sizes["px"]) / 180.0 * h  # disc centre to label, pixels
    for name, (plon, plat) in CHARTS[chart].items():
        text = _LABEL_TEXT[name]
        if abs(plat) >= 89.0:  # a pole: the cap is a band along the edge; label it 4 times
            yy = gap + 0.2 * size if plat > 0 else h - gap - 0.2 * size
            for lon in _POLE_LABEL_LONS:
                items.append((pix(lon, 0)[0], yy, text, "mt" if plat > 0 else "mb", size))
        else:
            xx, yy = pix(plon, plat)
            gap_x = gap / max(math.cos(math.radians(plat)), 0.05)
            items.append((xx + 0.8 * gap_x, yy - 0.8 * gap, text, "ls", size))

    # Longitudes below the equator, latitudes beside the lon -45 meridian.
    for lon in range(-135, 181, 45):
        xx, yy = pix(lon, 0)
        items.append((xx + 0.3 * small, yy + 0.4 * small, f"{lon}\u00b0", "lt", small))
    for lat in (-45, 45):
        xx, yy = pix(-45, lat)
        items.append((xx + 0.3 * small, yy - 0.3 * small, f"{lat}\u00b0", "ls", small))
    return items


def _to_dtype(img: NDArray[np.float64], dt: np.dtype) -> NDArray:
    if dt.kind == "u":
        return np.rint(np.clip(img, 0.0, 1.0) * np.iinfo(dt).max).astype(dt)
    return np.clip(img, 0.0, 1.0).astype(dt)


def make_test_pattern(
    width: int = 1024,
    height: int | None = None,
    chart: str = "zenith",
    dtype: DTypeLike = np.uint8,
    *,
    labels: bool = True,
) -> NDArray:
    """Render the test pattern as an equirectangular image.

    Parameters
    ----------
    width : int
        Width in pixels (at least 8).
    height : int, optional
        Height in pixels; default ``width // 2`` (a full 2:1 sphere). Any
        size works: the pattern is drawn from each pixel's direction.
    chart : {"zenith", "front"}
        Which points to mark as 0, 1, i, -1, -i, infinity (see the module
        documentation). Case-insensitive.
    dtype : {uint8, uint16, float32}
        Sample type; values span the type's range (0..1 for float32).
    labels : bool
        Draw text labels (the point names and degree marks). Text is left
        out anyway below a height of about 160 pixels.

    Returns
    -------
    ndarray, shape (height, width, 3)
        RGB.

    Raises
    ------
    InvalidValueError
        For a size below 8x4 or above 65536x32768, or an unknown chart.
    InvalidTypeError
        For another dtype.

    Examples
    --------
    >>> img = make_test_pattern(64, dtype=np.float32)
    >>> img.shape, img.dtype, bool(0.0 <= img.min() and img.max() <= 1.0)
    ((32, 64, 3), dtype('float32'), True)
    """
    if isinstance(width, bool) or not isinstance(width, (int, np.integer)):
        raise InvalidTypeError(f"expected an integer width, got {width!r}")
    if height is None:
        height = int(width) // 2
    if isinstance(height, bool) or not isinstance(height, (int, np.integer)):
        raise InvalidTypeError(f"expected an integer height, got {height!r}")
    width, height = int(width), int(height)
    if not (8 <= width <= 65536 and 4 <= height <= 32768):
        raise InvalidValueError(
            f"expected a size between 8x4 and 65536x32768, got {width}x{height}"
        )
    name = _check_chart(chart)
    dt = _check_dtype(dtype)
    items = _label_items(width, height, name) if labels else []
    img = np.empty((height, width, 3), dt)
    rows = max(1, (1 << 17) // width)  # bands of rows bound the memory
    for r0 in range(0, height, rows):
        r1 = min(height, r0 + rows)
        band = _draw_rows(width, height, r0, r1, name)
        if items:
            fill, halo = _text_masks(width, r0, r1, items)
            _paint(band, 0.85 * halo, _HALO)
            _paint(band, fill, _TEXT)
        img[r0:r1] = _to_dtype(band, dt)
    return img


make_test_pattern.__test__ = False  # type: ignore[attr-defined]  # not a test for pytest
