"""Output grids: equirectangular, little planet, rectilinear, fisheye, cube maps, Peirce, torus.

A grid says which point of the sphere each output pixel shows
(:mod:`spherewarp.grids.base`). :func:`make_grid` builds one by name, with the
default size for an input panorama; :func:`spherewarp.warp` renders any map
into one (``grid=``), and :func:`from_grid` takes a picture in a grid back to
an equirectangular panorama.

Examples
--------
>>> import numpy as np
>>> from spherewarp import warp
>>> from spherewarp.maps import Mobius
>>> pano = np.zeros((64, 128, 3), np.uint8)
>>> planet = warp(pano, Mobius.identity(), grid=make_grid("little-planet", (64, 128)))
>>> planet.shape
(64, 64, 3)
"""

from __future__ import annotations

from ..errors import InvalidValueError
from .base import (
    CubeMap3x2,
    CubeMap6x1,
    Equirect,
    Equisolid,
    Fisheye,
    Grid,
    Peirce,
    Rectilinear,
    Stereographic,
    Torus,
    view_frame,
)
from .render import from_grid

__all__ = [
    "GRIDS",
    "Grid",
    "Equirect",
    "Stereographic",
    "Rectilinear",
    "Fisheye",
    "Equisolid",
    "CubeMap3x2",
    "CubeMap6x1",
    "Peirce",
    "Torus",
    "make_grid",
    "default_shape",
    "from_grid",
    "view_frame",
]

#: the grids by name (``--projection NAME``, ``project --to/--from NAME``)
GRIDS: dict[str, type[Grid]] = {
    "equirect": Equirect,
    "little-planet": Stereographic,
    "stereographic": Stereographic,
    "rectilinear": Rectilinear,
    "fisheye": Fisheye,
    "equisolid": Equisolid,
    "cubemap": CubeMap3x2,
    "cubemap-6x1": CubeMap6x1,
    "peirce": Peirce,
    "torus": Torus,
}


def _cls(name: str) -> type[Grid]:
    key = str(name).strip().lower()
    if key not in GRIDS:
        raise InvalidValueError(
            f"unknown projection {name!r}; expected one of: {', '.join(GRIDS)}",
        )
    return GRIDS[key]


def default_shape(name: str, in_shape: tuple[int, int]) -> tuple[int, int]:
    """The default (height, width) of grid ``name`` for an input panorama of ``in_shape``.

    Equirect: the input's; little planet and fisheyes: a square of the input's
    height; rectilinear: 4:3, two thirds of the input's height wide; cube maps: faces of the
    input's height (twice ffmpeg ``v360``'s default side, four times its pixels: a face
    of ``f`` pixels shows 90° with ``2 / f`` radians a pixel at its centre, so it takes
    ``f >= 2 h / pi`` to hold the panorama's equator there, and ``f = h`` to come back
    from ``project --from`` within 35-43 dB on real photos, against 29-34 dB at
    v360's ``h / 2``); Peirce: 3/2 of the input's height (about its resolution at the
    centre); the torus cell: a square of the input's height.

    Examples
    --------
    >>> default_shape("cubemap", (512, 1024)), default_shape("little-planet", (512, 1024))
    ((1024, 1536), (512, 512))
    """
    cls = _cls(name)
    h, w = (int(v) for v in in_shape[:2])
    if cls is Equirect:
        return (h, w)
    if cls is Rectilinear:  # 90 degrees about as sharp as the panorama at its centre
        return (max(1, round(h / 2)), max(1, round(h * 2 / 3)))
    if cls is CubeMap3x2:
        return (2 * h, 3 * h)
    if cls is CubeMap6x1:
        return (h, 6 * h)
    if cls is Peirce:  # about the input's resolution at the centre (as render_peirce)
        n = max(2, round(1.5 * h / 2) * 2)
        return (n, n)
    return (h, h)


def make_grid(
    name: str,
    in_shape: tuple[int, int] | None = None,
    *,
    shape: tuple[int, int] | None = None,
    look_at: tuple[float, float] | None = None,
    roll: float = 0.0,
    fov: float | None = None,
) -> Grid:
    """The grid ``name`` (see :data:`GRIDS`) of ``shape``, or the default shape for an
    input of ``in_shape`` (:func:`default_shape`).

    ``look_at`` (lon, lat degrees) and ``fov`` (degrees) default to the grid's own
    (the little planet looks at the nadir with a 270° field; the rectilinear view at
    the front with 90°; the fisheyes with 180°).

    Examples
    --------
    >>> make_grid("rectilinear", (512, 1024), fov=60)
    Rectilinear(shape=(256, 341), look_at=(0.0, 0.0), roll=0.0, fov=60.0)
    """
    cls = _cls(name)
    if shape is None:
        if in_shape is None:
            raise InvalidValueError("expected a grid shape or the input's shape")
        shape = default_shape(name, in_shape)
    kwargs: dict = {"roll": float(roll)}
    if look_at is not None:
        kwargs["look_at"] = tuple(float(v) for v in look_at)
    if fov is not None:
        if cls in (Equirect, CubeMap3x2, CubeMap6x1, Peirce, Torus):
            raise InvalidValueError(
                f"a field of view does not apply to {cls.name}",
                cli=f"--fov does not apply to {cls.name} (it shows what its grid shows)",
            )
        kwargs["fov"] = float(fov)
    return cls(tuple(shape), **kwargs)
