"""Schottky groups: several Droste effects at once (paper, "Schottky groups").

Each generator is a closed disk ``D_x`` of the sphere (a spherical cap:
centre and angular radius) and a hyperbolic or loxodromic Möbius map ``X``
that takes the outside of ``D_x`` onto a second disk ``D_X = X(C - D_x)``.
All the disks are pairwise disjoint. For an output point ``q``, while ``q``
lies in a disk it is replaced (``q`` in ``D_X``: ``X^-1(q)``; ``q`` in
``D_x``: ``X(q)``); once it lies outside every disk (the fundamental region)
the input is sampled there. One generator is the straight Droste effect: the
fundamental region is the annulus between ``D_x`` and ``D_X``.

The image is invariant under every generator. The reduction stops after
``depth`` steps; points not reduced by then (next to the limit set, a Cantor
dust) are undefined: background or alpha 0. The compiled renderer runs the
reduction as its ``schottky`` stage (:mod:`spherewarp.render.stages`).

The disks are round, or (the paper's mask workflow) the exact regions of a
mask, one colour per ``D_x`` (:class:`MaskRegions`,
:meth:`Schottky.with_mask_regions`): then ``D_X = X(C - D_x)`` holds the
points ``q`` with ``X^-1(q)`` outside ``D_x`` and the mask's black is the
fundamental region (less the ``D_X``); that reduction is the ``schottky_mask`` stage.

Convention: points are unit-norm pairs in the default chart
(:mod:`spherewarp.coords`); disks are ``(lon, lat, radius)`` in degrees.

Examples
--------
>>> from spherewarp.maps import Schottky
>>> s = Schottky.from_disk_pairs([((0, 0, 20), (180, 0, 20))])
>>> s.apply_lonlat([[90.0, 0.0]]).round(6) + 0.0   # the fundamental region is fixed
array([[90.,  0.]])
"""

from __future__ import annotations

import copy
import math
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .. import coords
from ..errors import InvalidValueError
from .base import PullBack, SphereMap, register_map
from .droste import check_phase
from .mobius import Mobius

__all__ = [
    "Cap",
    "MaskRegions",
    "Schottky",
    "cap_from_mask",
    "cap_image",
    "generator_between",
]

ComplexArray = NDArray[np.complex128]

#: default output width the depth cap is chosen for (copies beyond it are below a pixel), unless
#: the map is sized for its output (:meth:`Schottky.for_output`; the CLI does)
DEFAULT_WIDTH = 8192
#: the most reduction steps allowed
MAX_DEPTH = 10000


class Cap:
    """A closed spherical cap ``{v : n . v >= cos r}``.

    Parameters
    ----------
    lon, lat : float
        The centre, degrees.
    radius : float
        The angular radius, degrees, in (0, 90].

    Examples
    --------
    >>> c = Cap(0, 90, 10)
    >>> bool(c.contains(np.array([0.0, 0.0, 1.0])))
    True
    """

    def __init__(self, lon: float, lat: float, radius: float):
        try:
            lon, lat, radius = float(lon), float(lat), float(radius)
        except (TypeError, ValueError):
            raise InvalidValueError(
                f"expected a disk LON,LAT,R of numbers, got {(lon, lat, radius)!r:.80}"
            ) from None
        if not all(math.isfinite(v) for v in (lon, lat, radius)):
            raise InvalidValueError(f"expected a finite disk LON,LAT,R, got {lon}, {lat}, {radius}")
        if not -90 <= lat <= 90:
            raise InvalidValueError(f"expected a latitude in [-90, 90] for a disk, got {lat}")
        if not 0 < radius <= 90 + 1e-9:
            raise InvalidValueError(
                "expected a disk radius in (0, 90] degrees (at most a hemisphere), "
                f"got {radius:.6g}"
            )
        self.lon, self.lat, self.radius = lon, lat, radius
        self.normal = coords.xyz_from_lonlat(np.radians([lon, lat]))
        self.cos_r = math.cos(math.radians(radius))

    @classmethod
    def from_normal(cls, normal: NDArray[np.float64], radius_deg: float) -> Cap:
        lon, lat = np.degrees(coords.lonlat_from_xyz(normal / np.linalg.norm(normal)))
        return cls(float(lon), float(lat), radius_deg)

    def contains(self, xyz: NDArray[np.float64], strict: bool = False) -> NDArray[np.bool_]:
        """Points in the cap (``strict``: in its interior)."""
        d = xyz @ self.normal
        return d > self.cos_r if strict else d >= self.cos_r

    def distance(self, other: Cap) -> float:
        """Angular gap between the caps, degrees (negative: they overlap by that much)."""
        ang = math.degrees(math.acos(max(-1.0, min(1.0, float(self.normal @ other.normal)))))
        return ang - self.radius - other.radius

    def as_list(self) -> list[float]:
        return [self.lon, self.lat, self.radius]

    def __repr__(self) -> str:
        return f"Cap({self.lon:.6g}, {self.lat:.6g}, {self.radius:.6g})"


def _circle_points(cap: Cap, n: int = 3) -> NDArray[np.float64]:
    c = cap.normal
    helper = np.array([1.0, 0, 0]) if abs(c[0]) < 0.9 else np.array([0, 1.0, 0])
    e1 = np.cross(c, helper)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(c, e1)
    r = math.radians(cap.radius)
    phi = 2 * np.pi * np.arange(n) / n
    return math.cos(r) * c + math.sin(r) * (
        np.cos(phi)[:, None] * e1[None] + np.sin(phi)[:, None] * e2[None]
    )


def cap_image(m: Mobius, cap: Cap) -> tuple[NDArray[np.float64], float]:
    """``m`` of the *outside* of ``cap``: ``(normal, radius_deg)`` of the image cap.

    The radius may exceed 90 (the caller refuses it).
    """
    pts = m.apply_xyz(_circle_points(cap, 3))
    nn = np.cross(pts[1] - pts[0], pts[2] - pts[0])
    nn /= np.linalg.norm(nn)
    d = float(nn @ pts[0])
    inside = m.apply_xyz(-cap.normal)  # a point outside the cap (radius <= 90)
    if float(nn @ inside) < d:
        nn, d = -nn, -d
    return nn, math.degrees(math.acos(max(-1.0, min(1.0, d))))


#: the smallest disk radius (degrees) :func:`generator_between` takes: a thousandth of a
#: degree is a fortieth of a pixel of an 8K panorama
MIN_RADIUS = 1e-3


def generator_between(source: Cap, target: Cap, twist: float = 0.0) -> Mobius:
    """The Möbius map taking the outside of ``source`` onto the inside of ``target``.

    Two disjoint circles have one pair of points symmetric in both (the
    limit points of the pencil of circles they span), one in each disk. In a
    chart with those points at 0 and infinity both circles are centred, and
    the map chosen is the multiplication by the ratio of their radii: the
    hyperbolic map fixing the two limit points (its axis is the geodesic of
    hyperbolic space through them, perpendicular to both circles). ``twist``
    (degrees) turns it about the same fixed points as well (a loxodromic map);
    every map of this family commutes with the others.

    Raises
    ------
    InvalidValueError
        If the disks overlap or touch, or one is smaller than :data:`MIN_RADIUS`.

    Examples
    --------
    >>> a, b = Cap(0, 0, 20), Cap(180, 0, 20)
    >>> m = generator_between(a, b)
    >>> m.classify()
    'hyperbolic'
    >>> n, r = cap_image(m, a)
    >>> round(r, 9), bool(np.allclose(n, b.normal))
    (20.0, True)
    """
    gap = source.distance(target)
    if gap <= 0:
        raise InvalidValueError(
            f"the disks {_fmt(source)} and {_fmt(target)} overlap by {-gap:.3g} degrees"
        )
    small = min(source.radius, target.radius)
    if small < MIN_RADIUS:  # the map's matrix is then singular in double precision
        raise InvalidValueError(
            f"expected disks of radius at least {MIN_RADIUS:g} degrees, got {small:.3g}"
        )
    # Caps as unit spacelike vectors of Minkowski space (signature +---); the limit points
    # are the null vectors of the plane they span.
    r1, r2 = math.radians(source.radius), math.radians(target.radius)
    s1 = np.concatenate([[math.cos(r1)], source.normal]) / math.sin(r1)
    s2 = np.concatenate([[math.cos(r2)], target.normal]) / math.sin(r2)
    k = (s1[0] * s2[0] - s1[1:] @ s2[1:]) * 1.0
    root = math.sqrt(max(k * k - 1.0, 0.0))
    pts = []
    for t in (k + root, k - root):
        v = s1 + t * s2
        pts.append(v[1:] / v[0])
    pts = [p / np.linalg.norm(p) for p in pts]
    if source.contains(pts[1]) and not source.contains(pts[0]):
        pts.reverse()
    p, q = (coords.cp1_from_xyz(v) for v in pts)  # p in the source disk, q in the target
    chart = Mobius([[q[1], -q[0]], [p[1], -p[0]]])  # q -> 0, p -> inf
    z1 = coords.cp1_from_xyz(_circle_points(source, 1)[0])
    z2 = coords.cp1_from_xyz(_circle_points(target, 1)[0])
    rho1 = abs(complex(coords.plane_from_cp1(chart.pull_cp1(z1))))
    rho2 = abs(complex(coords.plane_from_cp1(chart.pull_cp1(z2))))
    factor = (rho2 / rho1) * complex(math.cos(math.radians(twist)), math.sin(math.radians(twist)))
    return Mobius.zoom_between(p, q, factor)


def _color_hits(mask: NDArray, color: tuple[float, float, float], tolerance: float) -> NDArray:
    """The pixels of an equirectangular mask within ``tolerance`` of ``color`` (0..1 sRGB)."""
    px = np.asarray(mask)
    if px.ndim == 2:
        px = px[..., None]
    scale = 255.0 if px.dtype == np.uint8 else 65535.0 if px.dtype == np.uint16 else 1.0
    rgb = px[..., :3].astype(np.float64) / scale
    if rgb.shape[2] == 1:
        rgb = np.repeat(rgb, 3, axis=2)
    hit = np.all(np.abs(rgb - np.asarray(color, dtype=np.float64)) <= tolerance, axis=2)
    if not hit.any():
        shown = "#" + "".join(f"{round(255 * v):02x}" for v in color)
        raise InvalidValueError(f"the mask has no pixel of the colour {shown}")
    return hit


def cap_from_mask(
    mask: NDArray,
    color: tuple[float, float, float],
    *,
    tolerance: float = 0.25,
    inside: bool = False,
) -> Cap:
    """The round disk round (or inside) the pixels of one colour of an equirectangular mask.

    The centre is the area-weighted mean direction of the pixels within
    ``tolerance`` (0..1 per channel) of ``color`` (0..1 sRGB). The radius is
    the largest angle from it to their pixel centres plus half a pixel
    diagonal (the smallest cap about that centre holding the traced region),
    or with ``inside=True`` the smallest angle to a pixel centre of any other
    colour less half a pixel diagonal (the largest cap about that centre
    inside the region: every point of it lies in a pixel of the colour). A
    generator built from the inside cap maps the outside of the exact region
    into its target disk, so ``D_X = X(C - D_x)`` stays within the target
    (:meth:`Schottky.with_mask_regions`).

    Raises
    ------
    InvalidValueError
        If no pixel has that colour, or the region is larger than a hemisphere.

    Examples
    --------
    >>> m = np.zeros((90, 180, 3), np.uint8)
    >>> m[40:50, 85:95] = (255, 0, 0)
    >>> c = cap_from_mask(m, (1.0, 0.0, 0.0))
    >>> round(c.lon, 6) + 0.0, round(c.lat, 6) + 0.0, 13 < c.radius < 15
    (0.0, 0.0, True)
    >>> 8 < cap_from_mask(m, (1.0, 0.0, 0.0), inside=True).radius < 10
    True
    """
    hit = _color_hits(mask, color, tolerance)
    h, w = hit.shape
    ys, xs = np.nonzero(hit)
    lonlat = coords.lonlat_from_pixel(np.stack([xs + 0.5, ys + 0.5], axis=-1), w, h)
    xyz = coords.xyz_from_lonlat(lonlat)
    c = (xyz * np.cos(lonlat[:, 1:2])).sum(axis=0)
    if np.linalg.norm(c) < 1e-9:
        raise InvalidValueError("the mask region of one colour surrounds the sphere")
    c /= np.linalg.norm(c)
    half_diagonal = math.hypot(360 / w, 180 / h) / 2
    if inside:
        ys, xs = np.nonzero(~hit)
        if ys.size == 0:
            raise InvalidValueError("the mask region of one colour covers the whole sphere")
        lonlat = coords.lonlat_from_pixel(np.stack([xs + 0.5, ys + 0.5], axis=-1), w, h)
        cos_nearest = float((coords.xyz_from_lonlat(lonlat) @ c).max())
        ang = math.degrees(math.acos(min(1.0, max(-1.0, cos_nearest)))) - half_diagonal
        if ang <= 0:
            raise InvalidValueError(
                "the mask region of one colour is too thin: no round disk about its centre "
                "fits inside it"
            )
    else:
        ang = float(np.degrees(np.arccos(np.clip(xyz @ c, -1, 1))).max()) + half_diagonal
    lon, lat = np.degrees(coords.lonlat_from_xyz(c))
    return Cap(float(lon), float(lat), ang)


class MaskRegions:
    """The exact disks ``D_x`` of a mask: the pixels of one colour each (the paper's workflow).

    ``labels[i, j]`` is the generator whose disk ``D_x`` holds mask pixel ``(i,
    j)`` (its colour's), or -1 (black, or any other colour): a point is in
    ``D_x`` when its nearest mask pixel is. ``D_X = X(C - D_x)`` then holds the
    points ``q`` with ``X^-1(q)`` outside ``D_x``; the fundamental region is what
    is in no disk.

    Parameters
    ----------
    mask : array, shape (H, W) or (H, W, C)
        An equirectangular mask (uint8, uint16 or float in 0..1).
    colors : sequence of (r, g, b)
        One colour (0..1 sRGB) per generator, in order.
    tolerance : float
        How far (0..1 per channel) a pixel may be from a colour.
    path : str, optional
        Where the mask was read from (kept in :meth:`Schottky.params`).

    Examples
    --------
    >>> m = np.zeros((90, 180, 3), np.uint8)
    >>> m[40:50, 85:95] = (255, 0, 0)
    >>> r = MaskRegions(m, [(1.0, 0.0, 0.0)])
    >>> r.contains(0, np.array([[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0]])).tolist()
    [True, False]
    """

    def __init__(
        self,
        mask: NDArray,
        colors: Sequence[tuple[float, float, float]],
        *,
        tolerance: float = 0.25,
        path: str | None = None,
    ):
        hits = [_color_hits(mask, tuple(c), tolerance) for c in colors]
        labels = np.full(hits[0].shape, -1, np.int16)
        for i, hit in enumerate(hits):
            both = hit & (labels >= 0)
            if both.any():
                raise InvalidValueError(
                    f"mask colours {int(labels[both][0]) + 1} and {i + 1} are within the "
                    f"tolerance {tolerance:g} of each other on {int(both.sum())} pixels"
                )
            labels[hit] = i
        self.labels = labels
        self.colors = [tuple(float(v) for v in c) for c in colors]
        self.tolerance = float(tolerance)
        self.path = path

    def label(self, xyz: NDArray[np.float64]) -> NDArray[np.int16]:
        """The label of each point's nearest mask pixel."""
        h, w = self.labels.shape
        px = coords.pixel_from_lonlat(coords.lonlat_from_xyz(xyz), w, h)
        ix = np.floor(px[..., 0]).astype(np.intp) % w
        iy = np.clip(np.floor(px[..., 1]).astype(np.intp), 0, h - 1)
        return self.labels[iy, ix]

    def contains(self, i: int, xyz: NDArray[np.float64]) -> NDArray[np.bool_]:
        """Points in the disk ``D_x`` of generator ``i``."""
        return self.label(xyz) == i


def _in_cap(cap: Cap, n: int, rng: np.random.Generator) -> NDArray[np.float64]:
    """``n`` points spread over a cap (with its boundary)."""
    c = cap.normal
    helper = np.array([1.0, 0, 0]) if abs(c[0]) < 0.9 else np.array([0, 1.0, 0])
    e1 = np.cross(c, helper)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(c, e1)
    cos_d = 1 - rng.random(n) * (1 - cap.cos_r)
    cos_d[: n // 4] = cap.cos_r
    sin_d = np.sqrt(np.maximum(0.0, 1 - cos_d**2))
    phi = rng.random(n) * 2 * np.pi
    return cos_d[:, None] * c + sin_d[:, None] * (
        np.cos(phi)[:, None] * e1 + np.sin(phi)[:, None] * e2
    )


def _default_depth(
    gens: list[tuple[Cap, Mobius]], targets: list[Cap], width: int = DEFAULT_WIDTH
) -> int:
    """Enough steps that what is left unreduced lies in disks below a pixel at ``width`` across.

    After ``k`` steps the points not yet reduced lie in the disks of words of ``k + 1``
    letters, each the image of a disk under a word of ``k`` letters. A letter (``X`` or
    ``X^-1``) is applied only to points of the disks other than the one it maps out of, so
    its largest magnification there bounds how much each letter shrinks a copy.
    """
    rng = np.random.default_rng(0)
    caps = [c for c, _ in gens] + targets
    n = len(gens)
    samples = [_in_cap(c, 2000, rng) for c in caps]
    mu = 0.0
    for i, (_, m) in enumerate(gens):
        for letter, own in ((m, i), (m.inverse(), n + i)):
            for j, pts in enumerate(samples):
                if j != own:
                    mu = max(mu, float(letter.local_scale(coords.cp1_from_xyz(pts)).max()))
    big = max(math.radians(c.radius) for c in caps)
    pixel = 2 * math.pi / width
    if mu >= 0.999:
        return 200
    need = math.log(pixel / (2 * big)) / math.log(mu)
    return min(MAX_DEPTH, int(math.ceil(need)) + 2)


@register_map
class Schottky(SphereMap):
    """The Schottky map: reduce each point into the fundamental region.

    Parameters
    ----------
    generators : sequence of (disk, matrix)
        ``disk`` is ``(lon, lat, radius)`` in degrees (``D_x``) and ``matrix``
        a :class:`Mobius` (or its 2x2 matrix) ``X``, which takes the outside of
        ``D_x`` onto ``D_X``.
    depth : int, optional
        The most reduction steps; points not reduced by then are undefined.
        Default: enough that the copies left are below a pixel of an output
        8192 pixels wide (:meth:`for_output` sizes it for another output).
    phase : float
        Pre-composes with ``X0 ** -phase`` (``X0`` the first generator, as
        :class:`~spherewarp.maps.Droste` does with its zoom): phase 1 is the
        same image as phase 0, and phases ``k/N`` make a seamless loop zooming
        through the first generator's disks.

    Raises
    ------
    InvalidValueError
        For disks larger than a hemisphere, overlapping disks (the pair and
        the overlap in degrees are named), a generator that is not hyperbolic
        or loxodromic.

    Examples
    --------
    >>> s = Schottky([((0, 0, 20), Mobius.zoom((0, 0), 8.0))])
    >>> round(s.target_disks()[0].radius, 6)
    70.666435
    """

    kind = "schottky"

    def __init__(
        self,
        generators: Sequence[Any],
        *,
        depth: int | None = None,
        phase: float = 0.0,
    ):
        gens: list[tuple[Cap, Mobius]] = []
        try:
            items = list(generators)
        except TypeError:
            raise InvalidValueError("generators: expected a list of (disk, matrix) pairs") from None
        if not items:
            raise InvalidValueError("expected at least one generator")
        for i, g in enumerate(items):
            try:
                disk, mat = g
            except (TypeError, ValueError):
                raise InvalidValueError(
                    f"generator {i + 1}: expected a (disk, matrix) pair, got {g!r:.80}"
                ) from None
            cap = disk if isinstance(disk, Cap) else Cap(*disk)
            m = mat if isinstance(mat, Mobius) else Mobius(mat)
            gens.append((cap, m))
        self._gens = gens
        targets: list[Cap] = []
        for i, (cap, m) in enumerate(gens):
            kind = m.classify()
            if kind not in ("hyperbolic", "loxodromic"):
                raise InvalidValueError(
                    f"generator {i + 1}: expected a hyperbolic (zooming) Möbius map, got "
                    f"{'an' if kind[0] in 'aeiou' else 'a'} {kind} one"
                )
            nn, r = cap_image(m, cap)
            if r > 90 + 1e-9:
                raise InvalidValueError(
                    f"generator {i + 1}: its disk D_X = X(outside of D_x) has radius {r:.4g} "
                    "degrees, more than a hemisphere (the map does not take the outside of "
                    "D_x into a smaller disk)"
                )
            targets.append(Cap.from_normal(nn, r))
        self._targets = targets
        disks: list[tuple[str, Cap]] = []
        for i, (cap, _) in enumerate(gens):
            disks.append((f"D_x of generator {i + 1}", cap))
            disks.append((f"D_X of generator {i + 1}", targets[i]))
        for a in range(len(disks)):
            for b in range(a + 1, len(disks)):
                gap = disks[a][1].distance(disks[b][1])
                if gap <= 0:
                    raise InvalidValueError(
                        f"the disks must be disjoint: {disks[a][0]} {_fmt(disks[a][1])} and "
                        f"{disks[b][0]} {_fmt(disks[b][1])} overlap by {-gap:.3g} degrees"
                    )
        self._width = DEFAULT_WIDTH
        if depth is None:
            self._depth_given = None
            self._depth = _default_depth(gens, targets)
        else:
            if isinstance(depth, bool) or not isinstance(depth, (int, np.integer)):
                raise InvalidValueError(f"depth: expected an integer, got {depth!r}")
            if not 1 <= depth <= MAX_DEPTH:
                raise InvalidValueError(f"depth: expected 1..{MAX_DEPTH}, got {depth}")
            self._depth_given = int(depth)
            self._depth = int(depth)
        self._phase = check_phase(phase)
        t = math.fmod(self._phase, 1.0)  # phase 1 is phase 0: X0 maps the picture onto itself
        self._pre = gens[0][1].power(-t) if t else None
        self._regions: MaskRegions | None = None

    @classmethod
    def from_disk_pairs(
        cls, pairs: Sequence[Any], *, twists: Sequence[float] | None = None, **kwargs: Any
    ) -> Schottky:
        """From pairs of disks ``(D_x, D_X)``, each ``(lon, lat, radius)``.

        Each generator is :func:`generator_between` of its pair (``twists``:
        degrees, one per pair).

        Examples
        --------
        >>> s = Schottky.from_disk_pairs([((0, 0, 20), (180, 0, 20))], twists=[30])
        >>> s.generators[0][1].classify()
        'loxodromic'
        """
        pairs = list(pairs)
        twists = [0.0] * len(pairs) if twists is None else list(twists)
        gens = []
        for i, (pair, tw) in enumerate(zip(pairs, twists, strict=True)):
            src, dst = (d if isinstance(d, Cap) else Cap(*d) for d in pair)
            try:
                gens.append((src, generator_between(src, dst, tw)))
            except InvalidValueError as exc:
                raise InvalidValueError(f"generator {i + 1}: {exc}") from None
        return cls(gens, **kwargs)

    # -- properties -----------------------------------------------------------------
    @property
    def generators(self) -> list[tuple[Cap, Mobius]]:
        """The ``(D_x, X)`` pairs."""
        return list(self._gens)

    def target_disks(self) -> list[Cap]:
        """The disks ``D_X = X(outside of D_x)``, one per generator."""
        return list(self._targets)

    @property
    def depth(self) -> int:
        """The most reduction steps."""
        return self._depth

    @property
    def phase(self) -> float:
        """The zoom phase."""
        return self._phase

    def with_phase(self, phase: float) -> Schottky:
        """The same map at another phase (sized for the same output)."""
        out = type(self)._from_params({**self.params(), "phase": float(phase)})
        return out.for_output(self._width)  # type: ignore[attr-defined,no-any-return]

    def for_output(self, width: int) -> Schottky:
        """The same map with its default depth sized for an output ``width`` pixels across.

        The depth is then enough that the copies left unreduced are below a pixel
        of ``360 / width`` degrees (a given ``depth`` stays as it is). Deeper costs
        only the pixels next to the limit set, so a larger width is safe; the
        sizing is not part of :meth:`params` (a recipe sizes its own output).

        Examples
        --------
        >>> s = Schottky.from_disk_pairs([((0, 0, 20), (180, 0, 20))])
        >>> s.for_output(256).depth < s.depth < s.for_output(65536).depth
        True
        """
        try:
            width = int(width)
        except (TypeError, ValueError):
            raise InvalidValueError(f"width: expected a number of pixels, got {width!r}") from None
        if width < 1:
            raise InvalidValueError(f"width: expected a positive number of pixels, got {width}")
        out = copy.copy(self)
        out._width = width
        if self._depth_given is None:
            out._depth = _default_depth(self._gens, self._targets, width)
        return out

    @property
    def regions(self) -> MaskRegions | None:
        """The exact disks ``D_x`` from a mask, or None (round disks)."""
        return self._regions

    def with_mask_regions(self, regions: MaskRegions) -> Schottky:
        """The same generators with the exact disks of a mask (the paper's workflow).

        ``D_x`` of generator ``i`` becomes the mask's pixels of colour ``i``
        (:class:`MaskRegions`), ``D_X = X(C - D_x)`` the points ``q`` with
        ``X^-1(q)`` outside it, and the fundamental region is the mask's black
        (and every other colour) less the ``D_X``. The generators stay as given.
        Built from the round disk inside each region (:func:`cap_from_mask` with
        ``inside=True``, as ``spherewarp schottky --mask`` does), a generator takes
        the outside of the region into its target disk, so each exact ``D_X`` lies
        in its round one; built from the disk round the region, ``D_X`` also holds
        the image of the disk's part outside the region, which can be large.
        Compiled (the ``schottky_mask`` stage) like the round disks.

        Raises
        ------
        InvalidValueError
            If the number of colours is not the number of generators, or if two of
            the exact disks overlap (the pair and the overlap in square degrees are
            named).

        Examples
        --------
        >>> m = np.zeros((90, 180, 3), np.uint8)
        >>> m[40:50, 85:95] = (255, 0, 0)
        >>> red = cap_from_mask(m, (1.0, 0.0, 0.0))
        >>> s = Schottky([(red, generator_between(red, Cap(180, 0, 20)))])
        >>> e = s.with_mask_regions(MaskRegions(m, [(1.0, 0.0, 0.0)]))
        >>> q = [[0.0, 12.0]]  # in the round disk, outside the square region
        >>> e.apply_lonlat(q).round(6).tolist(), bool(np.allclose(s.apply_lonlat(q), q))
        ([[0.0, 12.0]], False)
        """
        if len(regions.colors) != len(self._gens):
            raise InvalidValueError(
                f"expected one mask colour per generator ({len(self._gens)}), got "
                f"{len(regions.colors)}"
            )
        _check_regions(self, regions)
        out = copy.copy(self)
        out._regions = regions
        return out

    # -- the reduction ------------------------------------------------------------------
    def _reduce(self, zw: ComplexArray) -> tuple[ComplexArray, NDArray[np.bool_], NDArray]:
        zw = coords.normalize_cp1(np.asarray(zw, dtype=np.complex128))
        shape = zw.shape[:-1]
        zw = zw.reshape(-1, 2)
        scale = np.ones(zw.shape[0])
        if self._pre is not None:
            scale *= self._pre.local_scale(zw)
            zw = self._pre.pull_cp1(zw)
        n = len(self._gens)
        # moves: 2*i applies X_i (point in D_x), 2*i + 1 applies X_i^-1 (point in D_X)
        maps = []
        caps = []
        for (cap, m), t in zip(self._gens, self._targets, strict=True):
            maps += [m, m.inverse()]
            caps += [cap, t]
        last = np.full(zw.shape[0], -1)
        active = np.arange(zw.shape[0])
        done = np.zeros(zw.shape[0], dtype=bool)
        for _ in range(self._depth + 1):
            if active.size == 0:
                break
            xyz = coords.xyz_from_cp1(zw[active])
            move = np.full(active.size, -1)
            for j in range(2 * n):
                # never undo the last step (a point on a boundary would bounce)
                hit = (move < 0) & (last[active] != (j ^ 1))
                hit &= self._in_disk(j, xyz, zw[active], maps)
                move[hit] = j
            free = move < 0
            done[active[free]] = True
            active, move = active[~free], move[~free]
            if _ == self._depth:
                break
            for j in range(2 * n):
                sel = active[move == j]
                if sel.size:
                    scale[sel] *= maps[j].local_scale(zw[sel])
                    zw[sel] = maps[j].pull_cp1(zw[sel])
                    last[sel] = j
        return zw.reshape(*shape, 2), done.reshape(shape), scale.reshape(shape)

    def _in_disk(
        self, j: int, xyz: NDArray[np.float64], zw: ComplexArray, maps: list[Mobius]
    ) -> NDArray[np.bool_]:
        """Points in the disk of move ``j`` (``2 i``: ``D_x`` of generator ``i``; ``2 i + 1``:
        its ``D_X``), round or from the mask's regions."""
        i = j // 2
        if self._regions is None:
            cap = self._gens[i][0] if j % 2 == 0 else self._targets[i]
            return cap.contains(xyz, strict=True)
        if j % 2 == 0:
            return self._regions.contains(i, xyz)
        # D_X = X(C - D_x): X^-1(q) outside D_x (maps[j] is X^-1)
        return ~self._regions.contains(i, coords.xyz_from_cp1(maps[j].pull_cp1(zw)))

    def pull_cp1(self, zw: ComplexArray) -> ComplexArray:
        return self._reduce(zw)[0]

    def kernel_stages(self) -> tuple[tuple[str, NDArray[np.float64]], ...] | None:
        """``("schottky", ...)`` after the phase's Möbius stage, or ``("schottky_mask",
        ...)`` with the exact disks of a mask (compiled renderer).

        The moves in :meth:`_reduce`'s order: ``D_x`` with ``X``, then ``D_X`` with
        ``X^-1``, for each generator; each the Lorentz matrix of its map and, with round
        disks, its disk's normal and ``cos r`` (with a mask, its labels follow the
        matrices).
        """
        from ..render.stages import SCHOTTKY, SCHOTTKY_MASK, lorentz_from_sl2

        moves = []
        for (cap, m), t in zip(self._gens, self._targets, strict=True):
            for disk, mat in ((cap, m.matrix), (t, m.inverse().matrix)):
                lor = lorentz_from_sl2(mat / np.sqrt(np.linalg.det(mat))).ravel()
                moves.append(
                    lor if self._regions is not None else np.r_[disk.normal, disk.cos_r, lor]
                )
        if self._regions is None:
            row = SCHOTTKY.pack(count=len(self._gens), depth=self._depth, moves=np.array(moves))
            core: tuple[tuple[str, NDArray[np.float64]], ...] = (("schottky", row),)
        else:
            labels = self._regions.labels
            row = SCHOTTKY_MASK.pack(
                count=len(self._gens),
                depth=self._depth,
                width=labels.shape[1],
                height=labels.shape[0],
                data=np.concatenate([np.ravel(moves), labels.ravel().astype(np.float64)]),
            )
            core = (("schottky_mask", row),)
        return core if self._pre is None else self._pre.kernel_stages() + core

    def pull(self, zw: ComplexArray) -> PullBack:
        points, done, _ = self._reduce(zw)
        return PullBack(points, valid=done)

    def local_scale(self, zw: ComplexArray) -> NDArray[np.float64]:
        """The product of the generators' magnifications along the reduction."""
        return self._reduce(zw)[2]

    # -- plain data ------------------------------------------------------------------------
    def params(self) -> dict[str, Any]:
        out: dict[str, Any] = {
            "generators": [
                {"disk": cap.as_list(), "matrix": m.params()["matrix"]} for cap, m in self._gens
            ]
        }
        if self._depth_given is not None:
            out["depth"] = self._depth_given
        if self._phase:
            out["phase"] = self._phase
        if self._regions is not None:
            r = self._regions
            if r.path is None:
                raise InvalidValueError(
                    "a Schottky map with mask regions has plain data only when its mask was "
                    "read from a file (MaskRegions(..., path=...))"
                )
            out["mask"] = {
                "path": r.path,
                "colors": [list(c) for c in r.colors],
                "tolerance": r.tolerance,
            }
        return out

    @classmethod
    def _from_params(cls, params: dict[str, Any]) -> SphereMap:
        params = dict(params)
        gens = []
        for g in params.pop("generators"):
            m = Mobius._from_params({"matrix": g["matrix"]})
            gens.append((tuple(g["disk"]), m))
        mask = params.pop("mask", None)
        out = cls(gens, **params)
        if mask is None:
            return out
        from ..io import read_image

        pixels = read_image(mask["path"], full_sphere=False).pixels
        regions = MaskRegions(
            pixels,
            [tuple(c) for c in mask["colors"]],
            tolerance=mask.get("tolerance", 0.25),
            path=mask["path"],
        )
        return out.with_mask_regions(regions)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Schottky):
            return NotImplemented
        ra, rb = self._regions, other._regions
        if (ra is None) != (rb is None) or (
            ra is not None and rb is not None and not np.array_equal(ra.labels, rb.labels)
        ):
            return False
        return (
            self._depth_given == other._depth_given
            and self._phase == other._phase
            and len(self._gens) == len(other._gens)
            and all(
                np.allclose(a.as_list(), b.as_list(), atol=1e-9) and m.isclose(n, 1e-9)
                for (a, m), (b, n) in zip(self._gens, other._gens, strict=True)
            )
        )

    __hash__ = None  # type: ignore[assignment]


def _check_regions(s: Schottky, regions: MaskRegions) -> None:
    """The exact disks pairwise disjoint, at the centres of the mask's pixels (at most about
    2 million of them)."""
    labels = regions.labels
    h, w = labels.shape
    step = max(1, int(math.ceil(math.sqrt(h * w / 2_000_000))))
    ys, xs = np.mgrid[0:h:step, 0:w:step] + 0.5
    lonlat = coords.lonlat_from_pixel(np.stack([xs, ys], axis=-1).reshape(-1, 2), w, h)
    xyz = coords.xyz_from_lonlat(lonlat)
    zw = coords.cp1_from_xyz(xyz)
    area = np.cos(lonlat[:, 1]) * (360.0 * step / w) * (180.0 * step / h)  # square degrees
    own = regions.label(xyz)
    names, member = [], []
    for i, (_, m) in enumerate(s.generators):
        d_x = own == i
        d_big = ~regions.contains(i, coords.xyz_from_cp1(m.inverse().pull_cp1(zw)))
        names += [f"D_x of generator {i + 1} (its mask region)", f"D_X of generator {i + 1}"]
        member += [d_x, d_big]
    for a in range(len(member)):
        for b in range(a + 1, len(member)):
            both = member[a] & member[b]
            if both.any():
                raise InvalidValueError(
                    f"the disks must be disjoint: {names[a]} and {names[b]} overlap on "
                    f"{float(area[both].sum()):.3g} square degrees"
                )


def _fmt(cap: Cap) -> str:
    return f"({cap.lon:.4g},{cap.lat:.4g},{cap.radius:.4g})"
