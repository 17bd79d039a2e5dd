"""The render plan: every choice of a render, made once.

:func:`plan` decides, from the map, the output grid, the sizes and the options,
how a render is done: which path renders it (the fused compiled kernels, NumPy
geometry with compiled samplers, a grid's geometry, the float64 reference),
what ``antialias="auto"`` means for it, whether jumps of the map are looked
for, whether every pixel is one tap at its centre. The answer is a frozen
:class:`Plan`. :func:`~spherewarp.render.warp` runs one
(:meth:`Plan.run`); :class:`~spherewarp.render.WarpMap` materialises one (for
a one-tap plan, the source coordinates of every pixel, computed and sampled by
the same kernels as the still; for any other plan, the plan itself, run on
every frame), so a still and a cached video frame of one map and one set of
options are the same pixels, bit for bit.

Paths (:attr:`Plan.path`):

``"compiled"``
    An equirectangular output of a map with compiled stages
    (:func:`~spherewarp.render.fast.kernel_spec`): the fused kernels.
``"sampled"``
    An equirectangular output of any other map: NumPy geometry, compiled samplers.
``"grid"``
    Any other output grid (:mod:`spherewarp.grids`): the grid's geometry
    (compiled for the plane grids and cube maps, with the map's stages where it
    has them), compiled samplers where numba is.
``"reference"``
    float64 NumPy throughout (``method="reference"``, or no numba).

Examples
--------
>>> from spherewarp.maps import Mobius
>>> p = plan(Mobius.zoom((0, 0), 2), None, (64, 128))
>>> p.antialias, p.shrinks          # "auto": the area filter, since the zoom shrinks
(('area', 0), True)
>>> plan(Mobius.from_yaw_pitch_roll(30, 0, 0), None, (64, 128)).single_tap   # a rotation
True
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import coords
from .._shape import whole_pair
from ..errors import InvalidTypeError, InvalidValueError
from ..maps.base import SphereMap
from . import antialias as _aa
from .sampling import check_interp
from .warp import check_method

if TYPE_CHECKING:  # pragma: no cover
    from ..grids import Grid
    from .fast import KernelSpec

__all__ = ["PATHS", "Options", "Plan", "plan"]

#: the render paths (see the module docstring)
PATHS = ("compiled", "sampled", "grid", "reference")
#: output pixels a band of one-tap geometry (bounds the memory of the source coordinates)
_BAND_PIXELS = 1 << 18


@dataclass(frozen=True)
class Options:
    """The options of a render, as :func:`~spherewarp.render.warp` takes them.

    Examples
    --------
    >>> Options(antialias="none").antialias
    'none'
    """

    interp: str = "bilinear"
    antialias: str | int = "auto"
    supersample: int | None = None
    method: str = "auto"
    threads: int | None = None
    background: Any = None
    alpha: bool = False


@dataclass(frozen=True, eq=False)
class Plan:
    """How one render is done (see the module docstring); made by :func:`plan`.

    Attributes
    ----------
    inverse_map : SphereMap
        The map rendered (for a turned equirectangular grid, with the grid's turn).
    grid : Grid or None
        The output grid; None for the plain equirectangular panorama.
    in_shape, out_shape : (height, width)
        Of the (first) input and of the output.
    path : str
        One of :data:`PATHS`.
    spec : KernelSpec or None
        The map's compiled stages, where it has them and they are used.
    interp : str
        The interpolation.
    antialias : (mode, n)
        The anti-aliasing, resolved: ``"none"``, ``"adaptive"``, ``"area"`` or
        ``"uniform"`` (``n x n``), never ``"auto"``.
    requested : (mode, n)
        What was asked (:func:`~spherewarp.render.antialias.parse_antialias`).
    shrinks : bool
        Whether an output pixel somewhere covers more than about one input pixel.
    jumps : bool
        Whether the map may jump between neighbouring pixels (a Droste seam): the
        filters then look for jumps.
    threads : int or None
        Worker threads of the compiled kernels (None: all cores).
    background, alpha
        The defaults of :meth:`run` (see :func:`~spherewarp.render.warp`).
    n_images : int
        The inputs the render samples (the sheets of a map with several).
    """

    inverse_map: SphereMap
    grid: Grid | None
    in_shape: tuple[int, int]
    out_shape: tuple[int, int]
    path: str
    spec: KernelSpec | None
    interp: str
    antialias: tuple[str, int]
    requested: tuple[str, int]
    shrinks: bool
    jumps: bool
    threads: int | None = None
    background: Any = None
    alpha: bool = False
    n_images: int = 1

    @property
    def sampler(self) -> str:
        """``"fast"`` (compiled samplers) or ``"reference"`` (NumPy)."""
        from . import fast

        return "fast" if self.path != "reference" and fast.available() else "reference"

    @property
    def single_tap(self) -> bool:
        """Every pixel is one tap at its centre: no filter (``"none"``), or
        ``"adaptive"`` where no pixel shrinks and the map has no jumps."""
        mode = self.antialias[0]
        return mode == "none" or (mode == "adaptive" and not self.shrinks and not self.jumps)

    @property
    def cacheable(self) -> bool:
        """A one-tap plan on a compiled path: :class:`~spherewarp.render.WarpMap` keeps
        its source coordinates (else it runs the plan on every frame)."""
        return (
            self.single_tap
            and self.path in ("compiled", "grid")
            and self.sampler == "fast"
            and self.inverse_map.n_sheets <= 1
        )

    def describe(self) -> str:
        """One line: the path, the filter, and why.

        Examples
        --------
        >>> from spherewarp.maps import Mobius
        >>> plan(Mobius.zoom((0, 0), 2), None, (64, 128)).describe()
        'compiled path, antialias area (auto: the map shrinks), bilinear'
        """
        mode, n = self.antialias
        aa = f"uniform {n}x{n}" if mode == "uniform" else mode
        if self.requested[0] == "auto":
            aa += " (auto: the map shrinks)" if self.shrinks else " (auto: nothing shrinks)"
        return f"{self.path} path, antialias {aa}, {self.interp}"

    # -- running --------------------------------------------------------------------------------
    def run(
        self,
        images: ArrayLike | Sequence[ArrayLike],
        *,
        out: NDArray | None = None,
        background: Any = ...,
        alpha: bool | None = None,
        threads: int | None = ...,  # type: ignore[assignment]
        progress: Callable[[int, int], None] | None = None,
    ) -> NDArray:
        """Render ``images`` (checked as :func:`~spherewarp.render.warp` checks them; of
        :attr:`in_shape`) by the plan; ``background``, ``alpha`` and ``threads``
        default to the plan's.

        Examples
        --------
        >>> from spherewarp.maps import Mobius
        >>> img = np.random.default_rng(0).integers(0, 255, (8, 16, 3), dtype=np.uint8)
        >>> p = plan(Mobius.rotation((0, 90), 45), None, img.shape[:2])
        >>> bool(np.array_equal(p.run(img), np.roll(img, -2, axis=1)))
        True
        """
        from .warp import _background, _check_images

        images = _check_images(images, force=True)
        if images[0].shape[:2] != self.in_shape:
            h, w = self.in_shape
            raise InvalidValueError(
                f"expected an image of {w}x{h} (the plan's input), "
                f"got {images[0].shape[1]}x{images[0].shape[0]}"
            )
        if self.inverse_map.n_sheets > len(images):
            raise InvalidValueError(
                f"this map samples {self.inverse_map.n_sheets} input images, got {len(images)}"
            )
        p = self
        if threads is not ... and threads != self.threads:
            from dataclasses import replace

            p = replace(self, threads=threads)
        channels = images[0].shape[2]
        bg = _background(self.background if background is ... else background, channels)
        add_alpha = (self.alpha if alpha is None else alpha) and channels not in (2, 4)
        out = output_buffer(out, (*self.out_shape, channels + add_alpha), images[0].dtype)

        def render(ims: list[NDArray], dst: NDArray, b: NDArray, prog: Any) -> None:
            p._render(ims, dst, b, add_alpha, prog)

        render_straight_alpha(render, images, out, bg, progress)
        return out

    def _render(
        self,
        images: list[NDArray],
        out: NDArray,
        bg: NDArray[np.float32],
        add_alpha: bool,
        progress: Callable[[int, int], None] | None,
    ) -> None:
        from . import fast
        from .warp import _warp_by_samples, _warp_reference

        if self.path == "compiled":
            fast.render_spec(images[0], self, out, background=bg, progress=progress)
        elif self.path == "grid":
            from ..grids.render import render_into

            if self.cacheable:
                _run_taps(self, images[0], out, bg, progress)
            else:
                render_into(images, self, out, bg, progress)
        elif self.path == "sampled":
            _warp_by_samples(images, self, out, bg, progress)
        elif self.antialias[0] in ("adaptive", "area"):
            _warp_by_samples(images, self, out, bg, progress)
        else:
            n = self.antialias[1] if self.antialias[0] == "uniform" else 1
            _warp_reference(images, self.inverse_map, out, self.interp, n, bg, add_alpha, progress)

    # -- one-tap geometry -----------------------------------------------------------------------
    def bands(self) -> list[tuple[int, int]]:
        """Row bands ``(r0, r1)`` the one-tap geometry is computed in."""
        h, w = self.out_shape
        step = max(1, _BAND_PIXELS // w)
        return [(r0, min(h, r0 + step)) for r0 in range(0, h, step)]

    def source(
        self, r0: int, r1: int
    ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.uint8]]:
        """Tap-space source coordinates ``(u, v)`` (input pixel minus 1/2) and validity of
        the centres of output rows ``r0..r1`` (shape ``(r1 - r0, width)``), as this plan's
        one-tap render samples them (compiled paths only)."""
        from . import fast

        h_in, w_in = self.in_shape
        h_out, w_out = self.out_shape
        kx, ky = w_in / (2 * np.pi), h_in / np.pi
        shape = (r1 - r0, w_out)
        u = np.empty(shape)
        v = np.empty(shape)
        ok = np.empty(shape, np.uint8)
        gk = _grid_kernels()
        if self.grid is None:
            spec = self.spec
            ccos, csin = fast._column_tables(w_out)
            args = (spec.codes, spec.params, ccos, csin, r0, h_out, kx, ky, fast.TILE[1], u, v, ok)
            fast._run(gk.spec_rows, args, self.threads, r1 - r0)
            return u, v, ok
        y, x = np.mgrid[r0:r1, 0:w_out] + 0.5
        pu, pv, pok = grid_points(self, x.reshape(-1), y.reshape(-1), 0.0, 0.0)
        return pu.reshape(shape), pv.reshape(shape), pok.reshape(shape).astype(np.uint8)


#: alpha within this share of full scale of full is full, within it of 0 is 0, for
#: :func:`render_straight_alpha` (one level of uint16; the float32 rounding of a filter's
#: sum of opaque taps, a few 2**-24, is well within it)
_ALPHA_EPS = 2.0**-16


class _Halves:
    """``progress`` of two passes over one render: the first pass reports the first half,
    the second the second half; :meth:`done` reports the whole when the second is skipped."""

    def __init__(self, progress: Callable[[int, int], None] | None) -> None:
        self.progress = progress
        self.total = 1

    def first(self, done: int, total: int) -> None:
        self.total = max(1, int(total))
        self.progress(done, 2 * self.total)  # type: ignore[misc]

    def second(self, done: int, total: int) -> None:
        self.progress(self.total + done, 2 * self.total)  # type: ignore[misc]

    def done(self) -> None:
        if self.progress is not None:
            self.progress(2 * self.total, 2 * self.total)


def render_straight_alpha(
    render: Callable[[list[NDArray], NDArray, NDArray[np.float32], Any], None],
    images: list[NDArray],
    out: NDArray,
    bg: NDArray[np.float32],
    progress: Callable[[int, int], None] | None = None,
) -> None:
    """Render ``images`` into ``out`` by ``render(images, out, bg, progress)``, filtering
    an alpha channel premultiplied.

    Images (files too) hold straight alpha: a pixel's colour is its colour whatever its
    opacity, and a fully transparent pixel may hold any colour. Interpolating and
    averaging the channels of such pixels separately lets the hidden colour of
    transparent pixels bleed into every pixel that mixes them with visible ones (a dark
    outline round a cropped panorama whose uncovered part is black, a red one where the
    hidden colour is red). Every filter of the render is linear in the samples, so it
    is done once more on the premultiplied image (colour x alpha, in float32, float64
    for a float64 image; the background premultiplied too): that pass gives each
    partly transparent output pixel its colour, the filtered premultiplied colour
    divided by the filtered alpha (an integer colour rounded and clipped to its range).

    The first pass is the plain render, straight, in the image's own sample type. Its
    alpha is the output's alpha, and its colour stays where the division has nothing
    to correct: where the output alpha is full and the filtered one not over full (the
    two colours differ there by under one level: a transparent share that rounds to
    full opacity is under half a level of alpha), where either alpha is 0 (nothing is
    seen; the hidden colour is filtered as before), and, for float images, where the
    two agree but for float rounding (taps of one alpha). "Full" and "0" are to
    ``2**-16`` of full scale. So opaque pixels, and a turn by whole pixels, give the
    same samples as before, to the bit. The second pass is skipped when no output
    pixel is partly transparent: images without alpha, and opaque ones whose output
    stays opaque, cost one render.

    Parameters
    ----------
    render : callable
        ``render(images, out, bg, progress)``: one pass of the plan (the still's or a
        cached map's), the images of any sample type.
    images : list of ndarray
        The inputs, ``(H, W, C)`` of one dtype and channel count.
    out : ndarray
        The output, ``(h, w, C)`` or ``(h, w, C + 1)`` (an added alpha channel: then
        there is no alpha in the input and one pass is done).
    bg : ndarray of float32
        The background, ``C`` values in the image's units (straight).
    progress : callable, optional
        As for :func:`~spherewarp.render.warp`; with two passes, each reports half.
    """
    c = images[0].shape[2]
    if c not in (2, 4) or out.shape[2] != c:
        render(images, out, bg, progress)
        return
    halves = _Halves(progress)
    render(images, out, bg, halves.first if progress is not None else None)
    dtype = images[0].dtype
    full = float(np.iinfo(dtype).max) if dtype.kind in "ui" else 1.0
    alpha = out[..., c - 1]
    if np.all((alpha >= full * (1.0 - _ALPHA_EPS)) & (alpha <= full * (1.0 + _ALPHA_EPS))):
        halves.done()  # opaque throughout: nothing to divide
        return
    ftype = np.float64 if dtype == np.float64 else np.float32
    pm_images = []
    for im in images:
        pm = im.astype(ftype)
        pm[..., : c - 1] *= pm[..., c - 1 :] * ftype(1.0 / full)
        pm_images.append(pm)
    pm_bg = np.array(bg, np.float32)
    pm_bg[: c - 1] *= pm_bg[c - 1] / np.float32(full)
    pm_out = np.empty(out.shape, ftype)
    render(pm_images, pm_out, pm_bg, halves.second if progress is not None else None)
    del pm_images
    a = pm_out[..., c - 1]
    fix = (alpha < full * (1.0 - _ALPHA_EPS)) | (a > full * (1.0 + _ALPHA_EPS))  # partly seen,
    fix &= (alpha > full * _ALPHA_EPS) & (a > 0)  # or over full (bicubic); but not unseen
    pm = pm_out[fix]
    straight = out[fix]
    colour = pm[:, : c - 1] * (ftype(full) / pm[:, c - 1 :])
    if dtype.kind in "ui":
        colour = np.clip(np.rint(colour), 0.0, full)
    else:  # where the two agree but for float rounding (taps of one alpha): the straight
        kept = straight[:, : c - 1]
        colour = np.where(np.isclose(colour, kept, rtol=_ALPHA_EPS, atol=0.0), kept, colour)
    straight[:, : c - 1] = colour
    out[fix] = straight


def output_buffer(out: NDArray | None, shape: tuple[int, ...], dtype: np.dtype) -> NDArray:
    """``out`` checked (a writeable C-contiguous array of ``shape`` and ``dtype``), or a
    new one."""
    if out is None:
        return np.empty(shape, dtype)
    if (
        not isinstance(out, np.ndarray)
        or out.shape != shape
        or out.dtype != dtype
        or not out.flags.c_contiguous
        or not out.flags.writeable
    ):
        raise InvalidValueError(
            f"out: expected a writeable C-contiguous {dtype} array of shape {shape}"
        )
    return out


class _GridCodes:
    """The grid codes of :mod:`spherewarp.render._grid_kernels` (kept equal by a test)."""

    EQUIRECT = 0
    STEREO = 1
    FISHEYE = 2
    EQUISOLID = 3
    RECTILINEAR = 4
    CUBE = 5


def _grid_kernels() -> Any:
    from . import fast

    if fast._kernels() is None:
        return None
    if "grid_kernels" not in fast._STATE:
        _drop_stale_grid_cache()
        from . import _grid_kernels

        fast._STATE["grid_kernels"] = _grid_kernels
    return fast._STATE["grid_kernels"]


def _drop_stale_grid_cache(module: str = "_grid_kernels") -> None:
    """Drop numba's cached ``_grid_kernels`` machine code (or another ``module``'s of this
    package that compiles ``_kernels``' helpers: ``_plane_kernels``) when ``_kernels.py``
    changed.

    numba keys a cache by its own source file only, but ``_grid_kernels`` compiles
    ``_kernels``' helpers into its code: after an edit of ``_kernels.py`` alone its
    cache would still load, with the old helpers inlined. A stamp of ``_kernels.py``
    next to the cache files says which version they were compiled against (best
    effort: the package's own ``__pycache__``, where the build puts them).
    """
    import hashlib
    from pathlib import Path

    here = Path(__file__).resolve().parent
    cache = here / "__pycache__"
    try:
        digest = hashlib.sha256((here / "_kernels.py").read_bytes()).hexdigest()
        stamp = cache / f"{module}.kernels-sha256"
        if stamp.is_file() and stamp.read_text().strip() == digest:
            return
        for f in cache.glob(f"{module}.*.nb[ic]"):
            f.unlink()
        cache.mkdir(exist_ok=True)
        stamp.write_text(digest)
    except OSError:  # a read-only install: numba's user cache directory is used there
        pass


def _grid_params(grid: Grid) -> tuple[int, NDArray[np.float64]]:
    """The compiled grid code and parameter row of ``grid`` (-1: NumPy directions)."""
    from .. import grids as g

    codes = _GridCodes
    h, w = grid.shape
    gp = np.zeros(15)
    gp[:9] = grid.frame.ravel()
    gp[9], gp[10] = w, h
    kind = -1
    if isinstance(grid, g.Stereographic):
        kind, gp[11], gp[12] = codes.STEREO, grid._unit(), grid._k()
    elif isinstance(grid, g.Equisolid):
        kind, gp[11], gp[12] = codes.EQUISOLID, grid._unit(), grid._k()
    elif isinstance(grid, g.Fisheye):
        kind, gp[11], gp[12] = codes.FISHEYE, grid._unit(), np.radians(grid.fov) / 2
    elif isinstance(grid, g.Rectilinear):
        kind, gp[11], gp[12] = codes.RECTILINEAR, grid._unit(), np.tan(np.radians(grid.fov) / 2)
    elif isinstance(grid, g.base._Cube):
        kind, gp[11], gp[14] = codes.CUBE, grid.face, grid.cols
    elif isinstance(grid, g.Equirect):
        kind = codes.EQUIRECT
    if isinstance(grid, g.base._Azimuthal):
        gp[13] = 1.0 if grid.disc else 0.0
    return kind, gp


def grid_points(
    p: Plan,
    x: NDArray[np.float64],
    y: NDArray[np.float64],
    dx: ArrayLike,
    dy: ArrayLike,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.bool_]]:
    """Tap-space source coordinates and validity (the grid's and the map's) of grid
    positions ``(x + dx, y + dy)`` (pieces of a grid from ``(x, y)``; see
    :meth:`~spherewarp.grids.Grid.directions_at`), for a one-sheet map: compiled
    directions and stages where there are, NumPy otherwise."""
    from . import fast

    grid = p.grid
    n = x.size
    dx = np.ascontiguousarray(np.broadcast_to(np.asarray(dx, np.float64), (n,)))
    dy = np.ascontiguousarray(np.broadcast_to(np.asarray(dy, np.float64), (n,)))
    x = np.ascontiguousarray(x, np.float64)
    y = np.ascontiguousarray(y, np.float64)
    h_in, w_in = p.in_shape
    kx, ky = w_in / (2 * np.pi), h_in / np.pi
    gk = _grid_kernels() if p.sampler == "fast" else None
    kind, gp = _grid_params(grid) if gk is not None else (-1, None)
    u = np.empty(n)
    v = np.empty(n)
    ok = np.empty(n, np.uint8)
    items = -(-n // 256)
    if gk is not None and p.spec is not None:
        codes, params = p.spec.codes, p.spec.params
        if kind >= 0:
            args = (kind, gp, _FACES, codes, params, x, y, dx, dy, kx, ky, u, v, ok)
            fast._run(gk.grid_source, args, p.threads, items)
        else:
            d, gvalid = grid.directions_at(x, y, dx, dy)
            args = (codes, params, np.ascontiguousarray(d), kx, ky, u, v, ok)
            fast._run(gk.xyz_source, args, p.threads, items)
            ok &= gvalid
        return u, v, ok.astype(bool)
    if gk is not None and kind >= 0:
        d = np.empty((3, n))
        args = (kind, gp, _FACES, x, y, dx, dy, d[0], d[1], d[2], ok)
        fast._run(gk.grid_xyz, args, p.threads, items)
        d, gvalid = d.T, ok.astype(bool)
    else:
        d, gvalid = grid.directions_at(x, y, dx, dy)
    pb = p.inverse_map.pull(coords.cp1_from_xyz(d))
    with np.errstate(invalid="ignore"):
        uv = coords.pixel_from_lonlat(coords.lonlat_from_cp1(pb.points), w_in, h_in) - 0.5
    valid = gvalid if pb.valid is None else gvalid & pb.valid
    return np.nan_to_num(uv[:, 0]), np.nan_to_num(uv[:, 1]), valid


def grid_footprints(
    p: Plan, x: NDArray[np.float64], y: NDArray[np.float64]
) -> tuple[NDArray, NDArray, NDArray, NDArray, NDArray] | None:
    """``(u, v, valid, J, jump)`` of grid pixels centred at ``(x, y)`` in one compiled
    pass (:func:`spherewarp.render._grid_kernels.grid_footprints`), for a map with
    compiled stages on a grid with compiled directions; None otherwise."""
    from . import fast

    gk = _grid_kernels() if p.sampler == "fast" else None
    if gk is None or p.spec is None:
        return None
    kind, gp = _grid_params(p.grid)
    if kind < 0:
        return None
    n = x.size
    h_in, w_in = p.in_shape
    kx, ky = w_in / (2 * np.pi), h_in / np.pi
    u = np.empty(n)
    v = np.empty(n)
    ok = np.empty(n, np.uint8)
    J = np.empty((4, n))
    jump = np.empty(n, np.uint8)
    x = np.ascontiguousarray(x, np.float64)
    y = np.ascontiguousarray(y, np.float64)
    args = (
        kind, gp, _FACES, p.spec.codes, p.spec.params, x, y, kx, ky, w_in, u, v, ok, J, jump,
    )  # fmt: skip
    fast._run(gk.grid_footprints, args, p.threads, -(-n // 256))
    return u, v, ok.astype(bool), J, jump.astype(bool)


def _faces() -> NDArray[np.float64]:
    from ..grids.base import _FACES as faces

    return np.ascontiguousarray(faces)


_FACES = _faces()


def _run_taps(
    p: Plan,
    src: NDArray,
    out: NDArray,
    bg: NDArray[np.float32],
    progress: Callable[[int, int], None] | None,
    coords_of: Callable[[int, int], tuple[NDArray, NDArray, NDArray]] | None = None,
) -> None:
    """A one-tap plan, band by band: the source coordinates (``coords_of(r0, r1)``, by
    default :meth:`Plan.source`), then one tap a pixel (compiled)."""
    bands = p.bands()
    for b, (r0, r1) in enumerate(bands):
        if progress is not None:
            progress(b, len(bands))
        u, v, ok = (coords_of or p.source)(r0, r1)
        sample_taps(src, u, v, ok, r0, out, p.interp, bg, p.threads)
    if progress is not None:
        progress(len(bands), len(bands))


def sample_taps(
    src: NDArray,
    u: NDArray[np.float64],
    v: NDArray[np.float64],
    ok: NDArray[np.uint8],
    r0: int,
    out: NDArray,
    interp: str,
    bg: NDArray[np.float32],
    threads: int | None,
) -> None:
    """One compiled tap a pixel at tap-space ``(u, v)`` into output rows ``r0..`` of
    ``out`` (pixels with ``ok == 0`` get ``bg``), as the fused kernels' one-tap path."""
    from . import fast

    src = fast._native(src)
    fast_u8 = fast._fast_u8_ok(src, out, interp)
    if fast_u8:
        p64, tail, big, o32 = fast._u8_views(src, out)
    else:
        p64, tail, big, o32 = fast._DUMMY64, fast._DUMMY64, 0, fast._DUMMY32
    fast_f = src.dtype == np.float32 and interp == "bilinear" and out.shape[2] == src.shape[2]
    fimg = fast._readonly(src.reshape(-1)) if fast_f else fast._DUMMY_F32
    is_int, maxval, full = fast._value_params(src.dtype)
    th, tw = fast.TILE
    args = (
        fast._image_bundle(src), p64, tail, big, o32, fast._output_bundle(out), *out.shape,
        fast_u8, fast_f, fimg, u, v, ok, r0, fast.INTERP_CODES[interp],
        np.asarray(bg, np.float32), is_int, maxval, full, th, tw,
    )  # fmt: skip
    fast._run(_grid_kernels().sample_taps, args, threads, -(-u.shape[0] // th))


# -- deciding ------------------------------------------------------------------------------------
def plan(
    inverse_map: SphereMap,
    grid: Grid | None,
    in_shape: tuple[int, int],
    out_shape: tuple[int, int] | None = None,
    options: Options | None = None,
    *,
    n_images: int = 1,
    **kwargs: Any,
) -> Plan:
    """Decide how to render ``inverse_map`` from an input of ``in_shape`` into ``grid``.

    Parameters
    ----------
    inverse_map : SphereMap
        The map from output points to input points.
    grid : Grid or None
        The output grid; None for an equirectangular output of ``out_shape``.
    in_shape : (height, width)
        Of the (first) input image.
    out_shape : (height, width), optional
        Of an equirectangular output (default ``in_shape``); with a grid, None or
        the grid's shape.
    options : Options, optional
        The render options; or give them as keywords (``interp="bicubic"``...).
    n_images : int
        How many inputs will be passed (the sheets of a map with several).

    Returns
    -------
    Plan

    Examples
    --------
    >>> from spherewarp.grids import make_grid
    >>> from spherewarp.maps import Mobius
    >>> p = plan(Mobius.identity(), make_grid("rectilinear", (512, 1024)), (512, 1024))
    >>> p.path, p.out_shape, p.single_tap
    ('grid', (256, 341), True)
    """
    from . import fast

    if options is None:
        options = Options(**kwargs)
    elif kwargs:
        raise InvalidValueError("give the options as an Options record or as keywords, not both")
    if not isinstance(inverse_map, SphereMap):
        raise InvalidTypeError(
            f"expected a map (a spherewarp.maps.SphereMap), got {type(inverse_map).__name__}"
        )
    interp = check_interp(options.interp)
    requested = _aa.parse_antialias(options.antialias, options.supersample)
    method = check_method(options.method)
    threads = options.threads
    if threads is not None and (
        isinstance(threads, bool) or not isinstance(threads, (int, np.integer)) or threads < 1
    ):
        raise InvalidValueError(f"expected threads to be a positive integer, got {threads!r}")
    h_in, w_in = (int(v) for v in in_shape)
    if grid is not None:
        from ..grids import Grid

        if not isinstance(grid, Grid):
            raise InvalidTypeError(
                f"expected grid to be a spherewarp.grids.Grid, got {type(grid).__name__}"
            )
        if out_shape is not None and tuple(out_shape) != grid.shape:
            raise InvalidValueError(
                f"expected output_shape None or the grid's {grid.shape}, got {out_shape!r}"
            )
        out_shape = grid.shape
        if grid.name == "equirect" and not grid.is_identity:
            # a turned panorama: the map after v360's view rotation, on the equirect paths
            from ..maps import Mobius

            turn = Mobius.from_yaw_pitch_roll(grid.look_at[0], grid.look_at[1], grid.roll)
            inverse_map = inverse_map @ turn
            grid = None
        elif grid.is_identity:
            grid = None
    if out_shape is None:
        out_shape = (h_in, w_in)
    try:
        h_out, w_out = whole_pair(out_shape)
    except (TypeError, ValueError):
        raise InvalidValueError(
            f"expected output_shape as (height, width), two whole numbers, got {out_shape!r}"
        ) from None
    if h_out < 1 or w_out < 1 or h_out * w_out > 1 << 30:
        raise InvalidValueError(
            f"expected a positive output shape of at most 2**30 pixels, got {out_shape!r}"
        )
    if method == "fast" and not fast.available():
        raise InvalidValueError(
            "method='fast' needs numba (pip install numba), which is not importable here"
        )
    compiled = method != "reference" and fast.available()
    one_sheet = inverse_map.n_sheets <= 1
    spec = fast.kernel_spec(inverse_map) if compiled and one_sheet else None
    if grid is not None:
        from ..grids.render import shrinks_somewhere as grid_shrinks

        path = "grid"
        shrinks = grid_shrinks(grid, inverse_map, (h_in, w_in))
    else:
        path = "compiled" if spec is not None else ("sampled" if compiled else "reference")
        shrinks = shrinks_somewhere(inverse_map, (h_in, w_in), (h_out, w_out), spec)
    aa = _aa.resolve_auto(requested, interp, shrinks)
    if aa[0] == "area" and interp != "bilinear":  # the area filter is of the bilinear surface
        aa = _aa.AREA_FALLBACK
    jumps = spec is None or bool(np.isin(spec.codes, fast.jump_codes()).any())
    return Plan(
        inverse_map=inverse_map, grid=grid, in_shape=(h_in, w_in), out_shape=(h_out, w_out),
        path=path, spec=spec, interp=interp, antialias=aa, requested=requested,
        shrinks=bool(shrinks), jumps=jumps, threads=None if threads is None else int(threads),
        background=options.background, alpha=bool(options.alpha), n_images=int(n_images),
    )  # fmt: skip


def spec_plan(
    spec: KernelSpec,
    in_shape: tuple[int, int],
    out_shape: tuple[int, int],
    interp: str = "bilinear",
    aa: tuple[str, int] = ("none", 1),
    threads: int | None = None,
) -> Plan:
    """A plan for given compiled stages (no map object: for benchmarks and kernel
    tests that call :func:`~spherewarp.render.fast.render_spec` directly)."""
    from ..maps import Mobius
    from . import fast

    interp = check_interp(interp)
    shrinks = _spec_shrinks(spec, in_shape, out_shape)
    res = _aa.resolve_auto(aa, interp, shrinks)
    if res[0] == "area" and interp != "bilinear":
        res = _aa.AREA_FALLBACK
    return Plan(
        inverse_map=Mobius.identity(), grid=None, in_shape=tuple(in_shape),
        out_shape=tuple(out_shape), path="compiled", spec=spec, interp=interp, antialias=res,
        requested=aa, shrinks=shrinks,
        jumps=bool(np.isin(spec.codes, fast.jump_codes()).any()), threads=threads,
    )  # fmt: skip


def _spec_shrinks(spec: KernelSpec, in_shape: tuple[int, int], out_shape: tuple[int, int]) -> bool:
    kx, ky = _aa.footprint_factors(in_shape, out_shape)
    return bool(spec.max_scale * max(kx, ky) > 1.0 + _aa.AUTO_TOLERANCE)


def shrinks_somewhere(
    inverse_map: SphereMap,
    in_shape: tuple[int, int],
    out_shape: tuple[int, int],
    spec: Any = None,
) -> bool:
    """Whether an equirectangular output pixel somewhere covers more than about one
    input pixel.

    From the bound on the magnification of a map with compiled stages
    (``spec``, :func:`spherewarp.render.fast.kernel_spec`), else from the map's
    :meth:`~spherewarp.maps.SphereMap.local_scale` on a 64 x 128 grid of the
    output. ``antialias="auto"`` filters every pixel by its footprint when this
    holds (:func:`~spherewarp.render.antialias.resolve_auto`).

    Examples
    --------
    >>> from spherewarp.maps import Mobius
    >>> shrinks_somewhere(Mobius.from_yaw_pitch_roll(30, 20, 10), (512, 1024), (512, 1024))
    False
    >>> shrinks_somewhere(Mobius.zoom((0, 0), 2), (512, 1024), (512, 1024))
    True
    >>> shrinks_somewhere(Mobius.identity(), (512, 1024), (256, 512))   # a downscale
    True
    """
    if spec is not None:
        return _spec_shrinks(spec, in_shape, out_shape)
    kx, ky = _aa.footprint_factors(in_shape, out_shape)
    limit = 1.0 + _aa.AUTO_TOLERANCE
    if max(kx, ky) > limit:
        return True
    h, w = 64, 128
    px = np.stack(np.broadcast_arrays(np.arange(w)[None, :] + 0.5, np.arange(h)[:, None] + 0.5), -1)
    zw = coords.cp1_from_lonlat(coords.lonlat_from_pixel(px.reshape(-1, 2), w, h))
    with np.errstate(all="ignore"):
        scale = np.nan_to_num(np.asarray(inverse_map.local_scale(zw), np.float64), nan=1.0,
                              posinf=1e6)  # fmt: skip
    return bool(scale.max(initial=0.0) * max(kx, ky) > limit)
