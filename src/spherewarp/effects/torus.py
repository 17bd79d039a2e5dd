"""Toroidal images: panoramas pulled back to the torus by Weierstrass ℘.

The rescaled ℘̃ of the square lattice ``Z[i]`` or the hexagonal lattice
``Z[ω]`` (see :mod:`spherewarp.maps.elliptic`) is doubly periodic, so it
maps a torus onto the sphere, two to one, with four branch points. Pulling a
panorama back by it gives a *toroidal image*: its unit cell contains two
copies of the panorama (paper, figures "sphere_torus" and "Cutting open the
torus"), and it tiles the plane.

* :func:`render_torus` -- the image of a window of the plane: ``cx x cy``
  unit squares ``[0, cx] x [0, cy]`` for the square lattice (the corners are
  lattice points, which go to the nadir; the centre of each square goes to
  the zenith, the midpoints of its top and bottom sides (u = 1/2) to the
  back and those of its left and right sides (u = i/2) to the front), and the
  rectangle ``[0, cx] x [0, cy √3/2]`` for the hexagonal lattice (each
  ``1 x √3/2`` brick is a fundamental domain). Conformal: angles in the
  image are angles on the sphere.
* :func:`render_torus_texture` -- the same pulled back in lattice
  coordinates ``u = s + t τ`` (τ = i or ω), ``s, t`` in ``[0, 1)``: a
  texture that repeats in both directions for any lattice (sheared for the
  hexagonal one).
* :func:`torus_mesh` / :func:`write_torus_obj` -- a textured torus of
  revolution (Wavefront OBJ + MTL + PNG texture) that 3D viewers open.

Convention: in images, x goes right and y down; the plane's imaginary axis
points up (row 0 is the top of the window). The picture is the view from
inside the sphere, like the panorama itself (not mirrored).

Examples
--------
>>> import numpy as np
>>> from spherewarp.effects import torus
>>> img = np.zeros((32, 64, 3), np.uint8)
>>> torus.render_torus(img, "square", cells=(2, 1), width=64).shape
(32, 64, 3)
>>> torus.render_torus(img, "hex", width=100).shape
(87, 100, 3)
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import coords, special
from ..errors import InvalidValueError, OutputExistsError

__all__ = [
    "parse_cells",
    "render_torus",
    "render_torus_texture",
    "TorusMesh",
    "torus_mesh",
    "write_torus_obj",
]

_TILE_PIXELS = 1 << 17
_SQRT3_2 = math.sqrt(3.0) / 2.0


def parse_cells(value: object) -> tuple[int, int]:
    """Parse ``"2x3"`` (or ``(2, 3)``, or ``"2"`` for 2x2) into ``(cx, cy)``, each 1..16.

    Examples
    --------
    >>> parse_cells("2x1")
    (2, 1)
    """
    try:
        if isinstance(value, str):
            parts = value.lower().replace(" ", "").split("x")
            if len(parts) == 1:
                parts = parts * 2
            cx, cy = (int(p) for p in parts)
        else:
            cx, cy = (int(v) for v in value)  # type: ignore[union-attr]
    except (TypeError, ValueError):
        raise InvalidValueError(f"expected cells as CXxCY (e.g. 2x2), got {value!r}") from None
    if not (1 <= cx <= 16 and 1 <= cy <= 16):
        raise InvalidValueError(f"expected cells between 1x1 and 16x16, got {value!r}")
    return cx, cy


def _window(lattice: str, cells: tuple[int, int]) -> tuple[float, float]:
    cx, cy = cells
    return float(cx), float(cy) * (1.0 if lattice == "square" else _SQRT3_2)


def _pull(
    img: NDArray,
    plane_of_pixels,  # callable (x, y) pixel centres -> complex plane points
    shape: tuple[int, int],
    lattice: str,
    interp: str,
    supersample: int,
    progress: Any = None,
) -> NDArray:
    from ..render.sampling import check_interp, sample

    interp = check_interp(interp)
    h_in, w_in = img.shape[:2]
    h, w = shape
    out = np.empty((h, w, img.shape[2]), img.dtype)
    ss = int(supersample)
    offsets = (np.arange(ss) + 0.5) / ss
    rows_per_tile = max(1, _TILE_PIXELS // (w * ss * ss))
    cols = np.arange(w, dtype=np.float64)
    for r0 in range(0, h, rows_per_tile):
        if progress is not None:
            progress(r0, h)
        r1 = min(h, r0 + rows_per_tile)
        rows = np.arange(r0, r1, dtype=np.float64)
        acc = np.zeros((r1 - r0, w, img.shape[2]), np.float32)
        for oy in offsets:
            for ox in offsets:
                x, y = np.broadcast_arrays(cols[None, :] + ox, rows[:, None] + oy)
                u = plane_of_pixels(x, y)
                zw = special.weierstrass_p_pair(u, lattice, normalized=True)
                px = coords.pixel_from_lonlat(coords.lonlat_from_cp1(zw), w_in, h_in)
                acc += sample(img, px[..., 0], px[..., 1], interp)
        acc /= np.float32(ss * ss)
        if img.dtype.kind == "u":
            info = np.iinfo(img.dtype)
            acc = np.clip(np.rint(acc), info.min, info.max)
        out[r0:r1] = acc.astype(img.dtype)
    if progress is not None:
        progress(h, h)
    return out


def _check_common(
    image: ArrayLike, lattice: str, cells: object, supersample: object, force: bool
) -> tuple[NDArray, str, tuple[int, int], int]:
    from ..render.warp import as_image, check_equirect

    img = as_image(image)
    check_equirect(img, force)
    lat = special.check_lattice(lattice)
    cxy = parse_cells(cells)
    if (
        isinstance(supersample, bool)
        or not isinstance(supersample, (int, np.integer))
        or not 1 <= supersample <= 32
    ):
        raise InvalidValueError(f"expected supersample to be an integer 1..32, got {supersample!r}")
    return img, lat, cxy, int(supersample)


def _check_width(width: object) -> int:
    if isinstance(width, bool) or not isinstance(width, (int, np.integer)) or not 2 <= width:
        raise InvalidValueError(f"expected a width of at least 2 pixels, got {width!r}")
    if width > 65536:
        raise InvalidValueError(f"expected a width up to 65536 pixels, got {width!r}")
    return int(width)


def _check_pixels(w: int, h: int, max_pixels: int | None) -> None:
    from ..io.images import MAX_PIXELS_ENV, pixel_limit

    limit = pixel_limit(max_pixels)
    if w * h > limit:
        what = f"a torus picture of {w}x{h} = {w * h} pixels is more than the pixel limit {limit}"
        raise InvalidValueError(
            f"{what}; choose a smaller width or raise the limit (max_pixels= or {MAX_PIXELS_ENV})",
            cli=f"{what}; choose a smaller --size W or raise the limit (--max-pixels or "
            f"{MAX_PIXELS_ENV})",
        )


def render_torus(
    image: ArrayLike,
    lattice: str = "square",
    *,
    cells: object = (1, 1),
    width: int | None = None,
    interp: str = "bilinear",
    supersample: int = 1,
    force: bool = False,
    progress: Any = None,
    max_pixels: int | None = None,
) -> NDArray:
    """The toroidal image of a panorama: its pull-back by ℘̃ over a window of cells.

    Parameters
    ----------
    image : ndarray (H, W[, C])
        Equirectangular image.
    lattice : {"square", "hex"}
    cells : (cx, cy) or "CXxCY"
        How many cells across and down (see the module docstring for the
        window of each lattice).
    width : int, optional
        Output width in pixels (default: the input's width); the height
        follows from the window's aspect ratio.
    interp : {"bilinear", "nearest", "bicubic"}
    supersample : int
    force : bool
        Accept an input that is not 2:1.
    progress : callable, optional
        ``progress(done, total)`` per band of output rows, as for
        :func:`~spherewarp.render.warp`.
    max_pixels : int, optional
        The most pixels the picture may have (default: the pixel limit of
        :func:`~spherewarp.io.pixel_limit`, which reads it back); its height
        follows from the cells, so a narrow width can still mean a large picture.

    Returns
    -------
    ndarray, shape (height, width, C), the input's dtype

    Examples
    --------
    >>> img = np.zeros((16, 32, 1), np.float32)
    >>> render_torus(img, cells="2x2", width=40).shape
    (40, 40, 1)
    >>> render_torus(img, cells="1x4", width=40, max_pixels=1000)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    spherewarp.errors.InvalidValueError: a torus picture of 40x160 = 6400 pixels is more than ...
    """
    img, lat, cxy, ss = _check_common(image, lattice, cells, supersample, force)
    wx, wy = _window(lat, cxy)
    w = _check_width(width if width is not None else img.shape[1])
    h = max(1, round(w * wy / wx))
    _check_pixels(w, h, max_pixels)

    def plane(x: NDArray, y: NDArray) -> NDArray:
        return x * (wx / w) + 1j * (wy - y * (wy / h))

    return _pull(img, plane, (h, w), lat, interp, ss, progress)


def render_torus_texture(
    image: ArrayLike,
    lattice: str = "square",
    *,
    cells: object = (1, 1),
    size: tuple[int, int] | None = None,
    interp: str = "bilinear",
    supersample: int = 1,
    force: bool = False,
) -> NDArray:
    """A texture of the torus that repeats in both directions: the pull-back in lattice coordinates.

    Pixel ``(x, y)`` of a ``(height, width)`` texture is the point
    ``u = cx s + cy t τ`` with ``s = x/width`` and ``t = 1 - y/height``;
    for the square lattice this is :func:`render_torus`, for the hexagonal
    one a sheared picture of the same tiling.

    Parameters
    ----------
    size : (height, width), optional
        Default: the input's height, and the width in proportion to ``cx/cy``.

    Examples
    --------
    >>> img = np.zeros((16, 32, 3), np.uint8)
    >>> render_torus_texture(img, "hex", size=(20, 30)).shape
    (20, 30, 3)
    """
    img, lat, cxy, ss = _check_common(image, lattice, cells, supersample, force)
    cx, cy = cxy
    if size is None:
        h = img.shape[0]
        size = (h, max(2, round(h * cx / cy)))
    try:
        h, w = (int(v) for v in size)
    except (TypeError, ValueError):
        raise InvalidValueError(f"expected size as (height, width), got {size!r}") from None
    _check_width(w)
    _check_width(h)
    tau = 1j if lat == "square" else complex(0.5, _SQRT3_2)

    def plane(x: NDArray, y: NDArray) -> NDArray:
        return cx * (x / w) + cy * (1.0 - y / h) * tau

    return _pull(img, plane, (h, w), lat, interp, ss)


@dataclass(frozen=True)
class TorusMesh:
    """A torus of revolution as a triangle mesh with texture coordinates.

    Attributes
    ----------
    vertices, normals : ndarray (V, 3)
    uv : ndarray (V, 2)
        Texture coordinates in ``[0, 1]`` (OBJ convention: v up).
    faces : ndarray (F, 3) of int
        Zero-based vertex indices, counter-clockwise seen from outside.
    """

    vertices: NDArray[np.float64]
    normals: NDArray[np.float64]
    uv: NDArray[np.float64]
    faces: NDArray[np.intp]


def torus_mesh(
    major_radius: float = 2.0, minor_radius: float = 1.0, segments: tuple[int, int] = (128, 64)
) -> TorusMesh:
    """A textured torus of revolution about the z axis.

    Texture coordinate s goes once round the z axis (counter-clockwise seen
    from +z) and t once round the tube (from the outer equator upwards),
    so the texture is seen unmirrored from outside. Seam vertices are
    duplicated so that the coordinates stay in ``[0, 1]``.

    Examples
    --------
    >>> m = torus_mesh(segments=(8, 4))
    >>> m.vertices.shape, m.faces.shape
    ((45, 3), (64, 3))
    """
    n_major, n_minor = (int(v) for v in segments)
    big, small = float(major_radius), float(minor_radius)
    if not (n_major >= 3 and n_minor >= 3) or not (big > small > 0):
        raise InvalidValueError(
            "expected at least 3x3 segments and major radius > minor radius > 0, got "
            f"{segments!r}, {major_radius!r}, {minor_radius!r}"
        )
    s = np.linspace(0.0, 1.0, n_major + 1)
    t = np.linspace(0.0, 1.0, n_minor + 1)
    ss, tt = np.meshgrid(s, t, indexing="ij")
    theta, phi = 2 * np.pi * ss, 2 * np.pi * tt
    ring = big + small * np.cos(phi)
    verts = np.stack([ring * np.cos(theta), ring * np.sin(theta), small * np.sin(phi)], -1)
    normals = np.stack([np.cos(phi) * np.cos(theta), np.cos(phi) * np.sin(theta), np.sin(phi)], -1)
    uv = np.stack([ss, tt], -1)
    idx = np.arange((n_major + 1) * (n_minor + 1)).reshape(n_major + 1, n_minor + 1)
    a, b = idx[:-1, :-1], idx[1:, :-1]
    c, d = idx[1:, 1:], idx[:-1, 1:]
    # (theta, phi) is positively oriented for the outward normal: a -> b -> c is CCW outside
    faces = np.concatenate(
        [np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)]
    )
    return TorusMesh(verts.reshape(-1, 3), normals.reshape(-1, 3), uv.reshape(-1, 2), faces)


def check_obj_name(obj_path: str | os.PathLike[str]) -> Path:
    """The mesh's path, if it can name an OBJ file and its companions: ``.obj`` at the end,
    and no space in its name (an OBJ file's ``mtllib`` line and an MTL file's ``map_Kd`` split
    names at spaces, with no quoting).

    Examples
    --------
    >>> check_obj_name("my mesh.obj")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    spherewarp.errors.InvalidValueError: expected a mesh file name without spaces ...
    """
    obj = Path(obj_path)
    if obj.suffix.lower() != ".obj":
        raise InvalidValueError(f"expected a mesh file name ending in .obj, got {str(obj)!r}")
    if any(ch.isspace() for ch in obj.name):
        raise InvalidValueError(
            "expected a mesh file name without spaces (OBJ and MTL files split names at them), "
            f"got {obj.name!r}"
        )
    return obj


def write_torus_obj(
    obj_path: str | os.PathLike[str],
    texture: NDArray,
    *,
    cells: tuple[int, int] = (1, 1),
    lattice: str = "square",
    overwrite: bool = False,
    segments: tuple[int, int] = (128, 64),
) -> tuple[Path, Path, Path]:
    """Write a textured torus: ``NAME.obj``, ``NAME.mtl`` and ``NAME_texture.png``.

    The texture must repeat in both directions (see
    :func:`render_torus_texture`). The torus's radii follow the shape of the
    cells (the major circle carries the texture's width). Files are written
    atomically (a temporary file renamed into place).

    Returns
    -------
    (obj, mtl, png) paths

    Examples
    --------
    >>> import tempfile
    >>> d = Path(tempfile.mkdtemp())
    >>> tex = np.zeros((8, 8, 3), np.uint8)
    >>> [p.name for p in write_torus_obj(d / "t.obj", tex)]
    ['t.obj', 't.mtl', 't_texture.png']
    """
    from ..io import write_image
    from ..io.atomic import write_text

    obj = check_obj_name(obj_path)
    mtl = obj.with_suffix(".mtl")
    png = obj.with_name(obj.stem + "_texture.png")
    if not overwrite:
        for p in (obj, mtl, png):
            if p.exists():
                raise OutputExistsError(f"{str(p)!r} exists; pass --overwrite to replace it")
    lat = special.check_lattice(lattice)
    cx, cy = parse_cells(cells)
    # circumferences in proportion to the cell sides (|1| and |tau| = 1), clamped to a ring torus
    ratio = max(cx / cy, 1.0)
    minor = 1.0
    major = max(2.0, 2.0 * ratio) * minor
    mesh = torus_mesh(major, minor, segments)
    write_image(png, np.asarray(texture), gpano=False, overwrite=overwrite)
    lines = [
        f"# spherewarp: a {lat}-lattice toroidal image ({cx}x{cy} cells) on a torus",
        f"mtllib {mtl.name}",
        "o torus",
    ]
    lines += [f"v {x:.6f} {y:.6f} {z:.6f}" for x, y, z in mesh.vertices]
    lines += [f"vt {s:.6f} {t:.6f}" for s, t in mesh.uv]
    lines += [f"vn {x:.6f} {y:.6f} {z:.6f}" for x, y, z in mesh.normals]
    lines += ["usemtl toroidal_image", "s 1"]
    f1 = mesh.faces + 1
    lines += [f"f {a}/{a}/{a} {b}/{b}/{b} {c}/{c}/{c}" for a, b, c in f1]
    material = "\n".join(
        [
            "newmtl toroidal_image",
            "Ka 1.000 1.000 1.000",
            "Kd 1.000 1.000 1.000",
            "Ks 0.000 0.000 0.000",
            "d 1.0",
            "illum 1",
            f"map_Kd {png.name}",
            "",
        ]
    )
    write_text(mtl, material, overwrite=overwrite)
    write_text(obj, "\n".join(lines) + "\n", overwrite=overwrite)
    return obj, mtl, png
