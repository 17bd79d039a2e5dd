"""Output grids: which point of the sphere each pixel of a picture shows.

A grid is a picture of the sphere of a given ``shape`` (height, width): an
equirectangular panorama, a little planet, a flat (rectilinear) view, a
fisheye, a cube map. :meth:`Grid.directions_at` gives the unit vector that
pixel position ``(x, y)`` shows (pixel centres at half-integers, as
everywhere in spherewarp), and :meth:`Grid.inverse` the pixel position that
shows a unit vector (what ``spherewarp project --from`` samples).

Every grid looks from a direction: its camera frame ``M`` (columns: forward,
right, up) is ``Rz(lon) Ry(-lat) Rx(-roll)`` for ``look_at = (lon, lat)``
(degrees) and ``roll`` (degrees), so ``look_at``, ``roll`` mean ffmpeg
``v360``'s ``yaw``, ``pitch``, ``roll`` (a positive roll turns the picture's
content counter-clockwise). In camera coordinates the forward axis is
``(1, 0, 0)``, the right ``(0, 1, 0)`` and the up ``(0, 0, 1)``: at the default
look-at (0, 0) they are spherewarp's +x (front), +y (lon +90°) and +z (up).

The azimuthal grids (stereographic, fisheye, equisolid) put a direction at
angle ``theta`` from the look-at point at the radius ``r(theta)`` from the
picture's centre: ``tan(theta / 2)``, ``theta`` and ``sin(theta / 2)``,
scaled so that ``theta = fov / 2`` falls on the circle inscribed in the
picture; the rectilinear grid at ``tan(theta)``, with ``fov`` its horizontal
field of view. Up in the picture is the camera's up.

Cube maps follow ffmpeg ``v360``'s defaults (``out_forder=rludfb``,
``out_frot=000000``): faces right, left, up, down, front, back, in this
order, as a 3 x 2 sheet (``c3x2``: right, left, up on the top row; down,
front, back below) or a 6 x 1 strip (``c6x1``). Seen from inside the cube,
the four side faces have up at the top; the up face has the front at its
bottom edge and the down face has the front at its top edge.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import coords
from .._shape import whole_pair
from ..errors import InvalidValueError

__all__ = [
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
    "view_frame",
]


def _rot(axis: int, t: float) -> NDArray[np.float64]:
    c, s = np.cos(t), np.sin(t)
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    m = np.eye(3)
    m[i, i] = c
    m[j, j] = c
    m[i, j] = -s
    m[j, i] = s
    return m


def view_frame(look_at: tuple[float, float] = (0.0, 0.0), roll: float = 0.0) -> NDArray:
    """The camera frame ``M`` (world = ``M @ camera``) looking at ``look_at`` (degrees).

    Examples
    --------
    >>> view_frame((0, -90)) @ (1.0, 0.0, 0.0)      # forward: the nadir
    array([ 0.,  0., -1.])
    >>> (view_frame((0, -90)) @ (0.0, 0.0, 1.0)).round(12) + 0   # up: the front
    array([1., 0., 0.])
    """
    lon, lat = np.radians(np.asarray(look_at, np.float64))
    m = _rot(2, lon) @ _rot(1, -lat) @ _rot(0, -np.radians(float(roll)))
    m[np.abs(m) < 1e-15] = 0.0
    return m


@dataclass(frozen=True)
class Grid:
    """A picture of the sphere: the base of every output grid.

    Attributes
    ----------
    shape : (height, width)
    look_at : (lon, lat)
        Degrees: the direction the picture's centre shows.
    roll : float
        Degrees, as ffmpeg ``v360``'s roll.
    fov : float
        Degrees (where it applies; see each grid).
    """

    shape: tuple[int, int]
    look_at: tuple[float, float] = (0.0, 0.0)
    roll: float = 0.0
    fov: float = 0.0

    name = "grid"
    #: the grid's equirectangular GPano metadata applies (a full panorama)
    panorama = False

    def __post_init__(self) -> None:
        try:
            h, w = whole_pair(self.shape)
        except (TypeError, ValueError):
            raise InvalidValueError(
                f"expected a grid shape of two whole numbers, got {self.shape!r}"
            ) from None
        if h < 1 or w < 1:
            raise InvalidValueError(f"expected a positive grid shape, got {self.shape!r}")
        object.__setattr__(self, "shape", (h, w))
        lon, lat = (float(v) for v in self.look_at)
        if not (np.isfinite(lon) and np.isfinite(lat) and -90 <= lat <= 90):
            raise InvalidValueError(f"expected look_at as (lon, lat) degrees, got {self.look_at}")
        object.__setattr__(self, "look_at", (lon, lat))
        if not np.isfinite(self.roll):
            raise InvalidValueError(f"expected a finite roll, got {self.roll!r}")
        self._check_fov()

    def _check_fov(self) -> None:
        pass

    @property
    def frame(self) -> NDArray[np.float64]:
        """The camera frame (:func:`view_frame`)."""
        return view_frame(self.look_at, self.roll)

    @property
    def is_identity(self) -> bool:
        """An equirectangular grid looking at (0, 0) without roll: a plain panorama."""
        return False

    # -- the two directions of the grid ------------------------------------------------

    def directions_at(
        self, x: ArrayLike, y: ArrayLike, dx: ArrayLike = 0.0, dy: ArrayLike = 0.0
    ) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
        """Unit vectors shown at pixel positions ``(x + dx, y + dy)``, and where the
        picture shows anything (outside a fisheye's circle it does not).

        Grids made of pieces (cube faces) take the piece from ``(x, y)`` and extend
        it by ``(dx, dy)``, so a footprint at the edge of a face stays on it.

        Returns
        -------
        xyz : ndarray, shape (..., 3)
        valid : ndarray of bool, shape (...)
        """
        x, y, dx, dy = np.broadcast_arrays(*(np.asarray(a, np.float64) for a in (x, y, dx, dy)))
        cam, valid = self._camera(x, y, dx, dy)
        return cam @ self.frame.T, valid

    def directions(self) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
        """:meth:`directions_at` of every pixel centre: ``(H, W, 3)`` and ``(H, W)``.

        Examples
        --------
        >>> xyz, valid = Rectilinear((3, 3), fov=90).directions()
        >>> xyz[1, 1].round(12) + 0, bool(valid.all())
        (array([1., 0., 0.]), True)
        """
        h, w = self.shape
        y, x = np.mgrid[0:h, 0:w] + 0.5
        return self.directions_at(x, y)

    def inverse(self, xyz: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
        """Pixel positions ``(..., 2)`` (x, y) that show unit vectors ``xyz``, and where
        the picture shows them at all.

        Examples
        --------
        >>> g = Stereographic((100, 100))
        >>> px, ok = g.inverse([0.0, 0.0, -1.0])    # the nadir: the centre
        >>> px.round(9).tolist(), bool(ok)
        ([50.0, 50.0], True)
        """
        cam = np.asarray(xyz, np.float64) @ self.frame
        return self._pixel(cam)

    def _camera(self, x, y, dx, dy):  # pragma: no cover - abstract
        raise NotImplementedError

    def _pixel(self, cam):  # pragma: no cover - abstract
        raise NotImplementedError


def _inside(px: NDArray[np.float64], shape: tuple[int, int]) -> NDArray[np.bool_]:
    """Positions on the picture (its edges included, to rounding)."""
    h, w = shape
    e = 1e-9 * max(h, w)
    x, y = px[..., 0], px[..., 1]
    return (x >= -e) & (x <= w + e) & (y >= -e) & (y <= h + e)


def _safe_norm(v: NDArray[np.float64]) -> NDArray[np.float64]:
    return v / np.maximum(np.linalg.norm(v, axis=-1, keepdims=True), 1e-300)


@dataclass(frozen=True)
class Equirect(Grid):
    """An equirectangular panorama seen from ``look_at`` (its centre), rolled by ``roll``.

    ``Equirect(shape)`` is spherewarp's own chart; ``fov`` does not apply.

    Examples
    --------
    >>> Equirect((4, 8)).is_identity, Equirect((4, 8), look_at=(90, 0)).is_identity
    (True, False)
    """

    name = "equirect"
    panorama = True

    @property
    def is_identity(self) -> bool:
        return self.look_at == (0.0, 0.0) and self.roll == 0.0

    def _camera(self, x, y, dx, dy):
        h, w = self.shape
        ll = coords.lonlat_from_pixel(np.stack([x + dx, y + dy], -1), w, h)
        return coords.xyz_from_lonlat(ll), np.ones(x.shape, bool)

    def _pixel(self, cam):
        h, w = self.shape
        px = coords.pixel_from_lonlat(coords.lonlat_from_xyz(cam), w, h)
        px[..., 0] %= w
        return px, np.ones(px.shape[:-1], bool)


@dataclass(frozen=True)
class _Plane(Grid):
    """Grids on one plane chart: plane coordinates ``(a, b)`` (right, up) in units of
    half the picture's shorter side, centred on the picture."""

    def _unit(self) -> float:
        return 0.5 * min(self.shape)

    def _ab(self, x, y):
        h, w = self.shape
        s = self._unit()
        return (x - 0.5 * w) / s, (0.5 * h - y) / s

    def _xy(self, a, b):
        h, w = self.shape
        s = self._unit()
        return np.stack([0.5 * w + a * s, 0.5 * h - b * s], -1)


@dataclass(frozen=True)
class _Azimuthal(_Plane):
    """A direction at angle ``theta`` from the look-at point and azimuth ``phi`` lies
    at radius ``rho(theta)`` (1 at ``theta = fov / 2``)."""

    fov: float = 180.0
    #: the picture is the disc rho <= 1 only (a fisheye circle)
    disc = True
    max_fov = 360.0

    def _check_fov(self) -> None:
        if not 0 < self.fov <= self.max_fov:
            what = f"a field of view in (0, {self.max_fov:g}] degrees for {self.name}"
            raise InvalidValueError(
                f"expected {what}, got {self.fov!r}",
                cli=f"--fov: expected {what}, got {self.fov:g}",
            )

    def _rho(self, theta):  # pragma: no cover - abstract
        raise NotImplementedError

    def _theta(self, rho):  # pragma: no cover - abstract
        raise NotImplementedError

    def _camera(self, x, y, dx, dy):
        a, b = self._ab(x + dx, y + dy)
        rho = np.hypot(a, b)
        theta = self._theta(rho)
        phi = np.arctan2(b, a)
        st = np.sin(theta)
        cam = np.stack([np.cos(theta), st * np.cos(phi), st * np.sin(phi)], -1)
        a0, b0 = self._ab(x, y)
        valid = np.hypot(a0, b0) <= 1.0 if self.disc else np.ones(x.shape, bool)
        return cam, valid

    def _pixel(self, cam):
        theta = np.arccos(np.clip(cam[..., 0], -1.0, 1.0))
        phi = np.arctan2(cam[..., 2], cam[..., 1])
        with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
            rho = self._rho(theta)
        ok = np.isfinite(rho)
        rho = np.where(ok, rho, 0.0)
        px = self._xy(rho * np.cos(phi), rho * np.sin(phi))
        if self.disc:
            ok &= rho <= 1.0 + 1e-12
        return px, ok & _inside(px, self.shape)


@dataclass(frozen=True)
class Stereographic(_Azimuthal):
    """The stereographic projection (the little planet): radius ``∝ tan(theta / 2)``.

    The defaults give the little planet: the nadir (the ground) in the centre, the
    sky round it, the horizon a circle of radius ``1 / tan(fov / 4)`` (0.41 of the
    picture's half-side at the default ``fov = 270``); the front is up. The whole
    rectangle is picture (``fov`` is what the inscribed circle shows).

    Examples
    --------
    >>> g = Stereographic((200, 200))
    >>> px, _ = g.inverse([1.0, 0.0, 0.0])    # the front: above the centre, on the horizon
    >>> px.round(3).tolist()
    [100.0, 58.579]
    """

    look_at: tuple[float, float] = (0.0, -90.0)
    fov: float = 270.0
    name = "little-planet"
    disc = False
    max_fov = 359.0

    def _k(self) -> float:
        return float(np.tan(np.radians(self.fov) / 4))

    def _rho(self, theta):
        return np.tan(theta / 2) / self._k()

    def _theta(self, rho):
        return 2 * np.arctan(rho * self._k())


@dataclass(frozen=True)
class Fisheye(_Azimuthal):
    """The equidistant fisheye: radius ``∝ theta``, ``fov`` the circle's (default 180°).

    Examples
    --------
    >>> g = Fisheye((100, 100), fov=180)
    >>> px, ok = g.inverse([0.0, 1.0, 0.0])   # 90 degrees right: the circle's right edge
    >>> px.round(9).tolist(), bool(ok)
    ([100.0, 50.0], True)
    """

    name = "fisheye"

    def _rho(self, theta):
        return theta / (np.radians(self.fov) / 2)

    def _theta(self, rho):
        return np.minimum(rho * (np.radians(self.fov) / 2), np.pi)


@dataclass(frozen=True)
class Equisolid(_Azimuthal):
    """The equisolid (equal-area) fisheye: radius ``∝ sin(theta / 2)`` (default 180°).

    Examples
    --------
    >>> g = Equisolid((100, 100), fov=180)
    >>> px, ok = g.inverse([0.0, 1.0, 0.0])
    >>> px.round(9).tolist(), bool(ok)
    ([100.0, 50.0], True)
    """

    name = "equisolid"

    def _k(self) -> float:
        return float(np.sin(np.radians(self.fov) / 4))

    def _rho(self, theta):
        return np.sin(theta / 2) / self._k()

    def _theta(self, rho):
        return 2 * np.arcsin(np.clip(rho * self._k(), -1.0, 1.0))


@dataclass(frozen=True)
class Rectilinear(_Plane):
    """The flat (gnomonic) view: radius ``∝ tan(theta)``; ``fov`` is horizontal (default
    90°), the vertical one follows from the aspect (square pixels).

    As ffmpeg ``v360``'s ``flat`` output with ``h_fov = fov`` and ``v_fov`` from the
    aspect, except that v360 puts its pixels' directions at their left/top corners,
    spherewarp at their centres.

    Examples
    --------
    >>> g = Rectilinear((100, 200), fov=90)
    >>> px, ok = g.inverse([1.0, 1.0, 0.0])    # 45 degrees right: the right edge
    >>> px.round(9).tolist(), bool(ok)
    ([200.0, 50.0], True)
    """

    fov: float = 90.0
    name = "rectilinear"

    def _check_fov(self) -> None:
        if not 0 < self.fov < 180:
            what = "a field of view in (0, 180) degrees for rectilinear"
            raise InvalidValueError(
                f"expected {what}, got {self.fov!r}",
                cli=f"--fov: expected {what}, got {self.fov:g}",
            )

    def _unit(self) -> float:
        return 0.5 * self.shape[1]

    def _camera(self, x, y, dx, dy):
        a, b = self._ab(x + dx, y + dy)
        t = np.tan(np.radians(self.fov) / 2)
        cam = _safe_norm(np.stack([np.ones_like(a), a * t, b * t], -1))
        return cam, np.ones(x.shape, bool)

    def _pixel(self, cam):
        t = np.tan(np.radians(self.fov) / 2)
        f = cam[..., 0]
        ok = f > 1e-12
        fs = np.where(ok, f, 1.0)
        px = self._xy(cam[..., 1] / fs / t, cam[..., 2] / fs / t)
        return px, ok & _inside(px, self.shape)


# The cube: faces in v360's default order (rludfb); per face (forward, right-in-face,
# down-in-face) in spherewarp's camera coordinates (front, right, up), from v360's
# cube_to_xyz with its frame (X, Y, Z) = (right, up, back).
_FACES = np.array(
    [
        [(0, 1, 0), (-1, 0, 0), (0, 0, -1)],  # right: seen from inside, the back is right
        [(0, -1, 0), (1, 0, 0), (0, 0, -1)],  # left
        [(0, 0, 1), (0, 1, 0), (1, 0, 0)],  # up: the front at the bottom edge
        [(0, 0, -1), (0, 1, 0), (-1, 0, 0)],  # down: the front at the top edge
        [(1, 0, 0), (0, 1, 0), (0, 0, -1)],  # front
        [(-1, 0, 0), (0, -1, 0), (0, 0, -1)],  # back
    ],
    np.float64,
)


@dataclass(frozen=True)
class _Cube(Grid):
    """Six square faces on a ``cols x rows`` sheet, in v360's default order."""

    cols = 3
    rows = 2

    def __post_init__(self) -> None:
        super().__post_init__()
        h, w = self.shape
        if w * self.rows != h * self.cols:
            s = max(1, round(max(w / self.cols, h / self.rows)))
            what = (
                f"a {self.name} of {self.cols}x{self.rows} square faces, got {w}x{h} "
                f"(e.g. {s * self.cols}x{s * self.rows})"
            )
            raise InvalidValueError(
                f"expected {what}", cli=f"expected {what}; --size WxH sets an output's size"
            )

    @property
    def face(self) -> int:
        """Side of a face, pixels."""
        return self.shape[0] // self.rows

    def _camera(self, x, y, dx, dy):
        s = self.face
        col = np.clip(np.floor(x / s), 0, self.cols - 1).astype(np.intp)
        row = np.clip(np.floor(y / s), 0, self.rows - 1).astype(np.intp)
        k = col + self.cols * row
        uf = 2 * (x + dx - col * s) / s - 1
        vf = 2 * (y + dy - row * s) / s - 1
        f = _FACES[k]
        cam = f[..., 0, :] + uf[..., None] * f[..., 1, :] + vf[..., None] * f[..., 2, :]
        return _safe_norm(cam), np.ones(x.shape, bool)

    def _pixel(self, cam):
        s = self.face
        dots = cam @ _FACES[:, 0, :].T  # (..., 6)
        k = np.argmax(dots, axis=-1)
        f = _FACES[k]
        fw = np.maximum(np.take_along_axis(dots, k[..., None], -1)[..., 0], 1e-300)
        uf = np.einsum("...i,...i->...", cam, f[..., 1, :]) / fw
        vf = np.einsum("...i,...i->...", cam, f[..., 2, :]) / fw
        col = k % self.cols
        row = k // self.cols
        # stay half a pixel inside the face: bilinear taps never reach the next face
        x = col * s + np.clip((uf + 1) * s / 2, 0.5, s - 0.5)
        y = row * s + np.clip((vf + 1) * s / 2, 0.5, s - 0.5)
        return np.stack([x, y], -1), np.ones(k.shape, bool)


@dataclass(frozen=True)
class CubeMap3x2(_Cube):
    """A cube map as ffmpeg ``v360``'s ``c3x2``: right, left, up / down, front, back.

    Examples
    --------
    >>> g = CubeMap3x2((200, 300))
    >>> px, _ = g.inverse([1.0, 0.0, 0.0])    # the front: centre of the bottom middle face
    >>> px.tolist()
    [150.0, 150.0]
    """

    name = "cubemap"


@dataclass(frozen=True)
class CubeMap6x1(_Cube):
    """A cube map as ffmpeg ``v360``'s ``c6x1``: right, left, up, down, front, back.

    Examples
    --------
    >>> g = CubeMap6x1((100, 600))
    >>> px, _ = g.inverse([0.0, 0.0, 1.0])    # the zenith: centre of the third face
    >>> px.tolist()
    [250.0, 50.0]
    """

    name = "cubemap-6x1"
    cols = 6
    rows = 1


#: the Peirce and torus grids' native frame: their zenith is the camera's forward axis
_ZENITH_FORWARD = view_frame((0.0, 90.0))


@dataclass(frozen=True)
class Peirce(Grid):
    """Peirce's quincuncial projection (:mod:`spherewarp.grids.peirce`): the whole sphere
    conformally on a square, ``look_at`` at the centre (default the zenith: then it is
    :func:`~spherewarp.grids.peirce.render_peirce` with ``lon0 = 0``, the front meridian
    running to the bottom-left corner). ``fov`` does not apply.

    Examples
    --------
    >>> g = Peirce((64, 64))
    >>> px, ok = g.inverse([0.0, 0.0, 1.0])     # the zenith: the centre
    >>> px.round(9).tolist(), bool(ok)
    ([32.0, 32.0], True)
    """

    look_at: tuple[float, float] = (0.0, 90.0)
    name = "peirce"

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.shape[0] != self.shape[1]:
            raise InvalidValueError(f"expected a square Peirce picture, got {self.shape!r}")

    def _camera(self, x, y, dx, dy):
        from .peirce import sphere_from_peirce

        n = self.shape[0]
        native = sphere_from_peirce(2 * (x + dx) / n - 1, 1 - 2 * (y + dy) / n)
        return native @ _ZENITH_FORWARD, np.ones(x.shape, bool)

    def _pixel(self, cam):
        from .peirce import peirce_from_sphere

        n = self.shape[0]
        u, v = peirce_from_sphere(cam @ _ZENITH_FORWARD.T)
        px = np.stack([(u + 1) * n / 2, (1 - v) * n / 2], -1)
        return px, np.ones(px.shape[:-1], bool)


@dataclass(frozen=True)
class Torus(Grid):
    """The torus cell (:mod:`spherewarp.effects.torus`): pixel ``(x, y)`` of a ``(h, w)`` picture is
    the point ``u = x/w + (1 - y/h) i`` of the square lattice's unit cell, shown at
    ``℘̃(u)`` (the cell covers the sphere twice; its corners show the nadir, its centre the
    zenith, with ``look_at`` at the default (0, 90)). The picture tiles the plane.
    :meth:`inverse` is not defined (two points of the cell show each direction).

    Examples
    --------
    >>> xyz, _ = Torus((8, 8)).directions_at(4.0, 4.0)    # the centre: the zenith
    >>> xyz.round(9).tolist()
    [0.0, 0.0, 1.0]
    """

    look_at: tuple[float, float] = (0.0, 90.0)
    name = "torus"

    def _camera(self, x, y, dx, dy):
        from .. import special

        h, w = self.shape
        u = (x + dx) / w + 1j * (1 - (y + dy) / h)
        zw = special.weierstrass_p_pair(u, "square", normalized=True)
        return coords.xyz_from_cp1(zw) @ _ZENITH_FORWARD, np.ones(x.shape, bool)

    def _pixel(self, cam):
        raise InvalidValueError(
            "the torus cell covers the sphere twice: it has no inverse",
            cli="--from torus is not supported (the torus cell covers the sphere twice)",
        )
