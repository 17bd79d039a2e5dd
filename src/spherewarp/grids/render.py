"""Rendering into a grid, and a grid's picture back to the sphere.

:func:`render_into` is what :func:`spherewarp.warp` does with ``grid=``: each
output pixel's direction comes from the grid, the map pulls it back, and the
input is sampled there, with the same samplers (compiled where numba is) and
the same anti-aliasing modes as the equirectangular renderer. The footprint
of a pixel is measured, not assumed: the directions half a pixel left, right,
above and below its centre are pulled back too, and their differences in the
input's chart are the pixel's Jacobian (the shorter of the two one-sided
differences where they disagree, so that a jump of the map next door does
not count; a pixel whose two sides disagree by more than a factor of 2 is on
a jump and gets ``JUMP_SAMPLES`` plain taps a side). Costs: five pull-backs a
pixel plus the taps, all on the NumPy side, against the fused compiled
kernels of the plain equirectangular output.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from .. import coords
from ..errors import InvalidValueError
from ..maps.base import SphereMap
from ..render import antialias as _aa
from .base import Grid

if TYPE_CHECKING:  # pragma: no cover
    from ..render.plan import Plan

__all__ = ["render_into", "from_grid"]

_BAND_PIXELS = 1 << 15


def _tap_uv(zw: NDArray, in_shape: tuple[int, int]) -> NDArray[np.float64]:
    """Input tap-space coordinates (pixel minus 1/2) of points."""
    h, w = in_shape
    with np.errstate(invalid="ignore"):
        uv = coords.pixel_from_lonlat(coords.lonlat_from_cp1(zw), w, h) - 0.5
    return np.nan_to_num(uv)


def footprints(
    grid: Grid,
    inverse_map: SphereMap,
    x: NDArray[np.float64],
    y: NDArray[np.float64],
    in_shape: tuple[int, int],
) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """The Jacobian ``(4, n)`` (du/dx, du/dy, dv/dx, dv/dy; input pixels per output pixel)
    of pixels centred at ``(x, y)``, and which of them are on a jump of the map or the
    edge of a hole."""
    w_in = in_shape[1]
    offs = ((-0.5, 0.0), (0.5, 0.0), (0.0, -0.5), (0.0, 0.5))
    uvs = []
    oks = []
    for dx, dy in offs:
        d, _ = grid.directions_at(x, y, dx, dy)
        pb = inverse_map.pull(coords.cp1_from_xyz(d))
        uvs.append(_tap_uv(pb.points, in_shape))
        oks.append(np.ones(len(x), bool) if pb.valid is None else pb.valid)
    d, _ = grid.directions_at(x, y)
    pb = inverse_map.pull(coords.cp1_from_xyz(d))
    c = _tap_uv(pb.points, in_shape)
    ok_c = np.ones(len(x), bool) if pb.valid is None else pb.valid
    return _jacobian(c, ok_c, uvs, oks, w_in)


def _jacobian(
    c: NDArray[np.float64],
    ok_c: NDArray[np.bool_],
    uvs: list[NDArray[np.float64]],
    oks: list[NDArray[np.bool_]],
    w_in: int,
) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """The Jacobian and jumps of pixels from the tap-space points of their centres
    (``c``, ``(n, 2)``) and of their left, right, top and bottom edges (``uvs``)."""
    cols = []
    jump = np.zeros(len(c), bool)
    for lo, hi in ((0, 1), (2, 3)):
        dl = 2 * (c - uvs[lo])
        dr = 2 * (uvs[hi] - c)
        for dd in (dl, dr):  # round the seam
            dd[:, 0] = (dd[:, 0] + w_in) % (2 * w_in) - w_in
        ll = np.sum(dl * dl, -1)
        lr = np.sum(dr * dr, -1)
        near = 4.0 * np.minimum(ll, lr) >= np.maximum(ll, lr)
        # a disagreement over a few input pixels: a jump (tiny steps may differ freely)
        jump |= ~near & (np.maximum(ll, lr) > 4.0)
        jump |= ok_c & ~(oks[lo] & oks[hi])
        mean = 0.5 * (dl + dr)
        shorter = np.where((ll <= lr)[:, None], dl, dr)
        cols.append(np.where(near[:, None], mean, shorter))
    J = np.stack([cols[0][:, 0], cols[1][:, 0], cols[0][:, 1], cols[1][:, 1]])
    J[:, ~ok_c] = 0.0
    return J, jump & ok_c


def _counts(
    J: NDArray[np.float64], jump: NDArray[np.bool_], mode: str
) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """Parts (area) or samples (adaptive) per axis of each pixel."""
    tol, cap = _aa.AUTO_TOLERANCE, _aa.AUTO_MAX
    unit = _aa.AREA_SPLIT if mode == "area" else 1.0 / _aa.AUTO_DENSITY
    nx = np.clip(np.ceil(np.hypot(J[0], J[2]) / unit - tol), 1, cap).astype(np.int64)
    ny = np.clip(np.ceil(np.hypot(J[1], J[3]) / unit - tol), 1, cap).astype(np.int64)
    js = min(_aa.JUMP_SAMPLES, cap)
    nx[jump] = np.maximum(nx[jump], js)
    ny[jump] = np.maximum(ny[jump], js)
    return nx, ny


def _samples(
    mode: str,
    n: int,
    J: NDArray[np.float64] | None,
    jump: NDArray[np.bool_] | None,
    gvalid: NDArray[np.bool_],
) -> tuple[NDArray[np.int64], NDArray[np.int64], tuple[NDArray, NDArray] | None]:
    """Samples (or area parts) per axis of each pixel for an anti-aliasing mode, and for
    the area filter the box of each part (input pixels); pixels outside the picture
    (``~gvalid``) get one sample, the background."""
    npx = gvalid.size
    boxes = None
    if mode in ("area", "adaptive"):
        nx, ny = _counts(J, jump, mode)
        if mode == "area":
            J[:, jump] = 0.0
            boxes = (np.hypot(J[0] / nx, J[1] / ny), np.hypot(J[2] / nx, J[3] / ny))
    else:
        nx = np.full(npx, n if mode == "uniform" else 1, np.int64)
        ny = nx.copy()
    nx[~gvalid] = 1
    ny[~gvalid] = 1
    return nx, ny, boxes


def shrinks_somewhere(grid: Grid, inverse_map: SphereMap, in_shape: tuple[int, int]) -> bool:
    """Whether a pixel of the grid somewhere covers more than about one input pixel (on
    a probe of about 64 x 64 pixels): ``antialias="auto"`` then filters by area."""
    h, w = grid.shape
    ys = (np.unique(np.linspace(0, h - 1, min(h, 64)).round()) + 0.5)[:, None]
    xs = (np.unique(np.linspace(0, w - 1, min(w, 64)).round()) + 0.5)[None, :]
    x, y = (a.reshape(-1) for a in np.broadcast_arrays(xs, ys))
    _, valid = grid.directions_at(x, y)
    J, _ = footprints(grid, inverse_map, x[valid], y[valid], in_shape)
    axis = np.maximum(np.hypot(J[0], J[2]), np.hypot(J[1], J[3]))
    return bool(np.any(axis > 1.0 + _aa.AUTO_TOLERANCE))


def render_into(
    images: list[NDArray],
    plan: Plan,
    out: NDArray,
    bg: NDArray[np.float32],
    progress: Callable[[int, int], None] | None = None,
) -> None:
    """Fill ``out`` (the grid's shape) with ``images`` pulled back by a render plan
    (:class:`~spherewarp.render.plan.Plan` of path ``"grid"``; its anti-aliasing is
    resolved: ``"area"``, ``"adaptive"``, ``"uniform"`` or ``"none"``).

    With compiled samplers and a one-sheet map, the geometry (the directions of the
    pixels and of their footprints' corners, and the map's stages where it has them)
    is compiled too (:func:`~spherewarp.render.plan.grid_points`); otherwise it is
    NumPy's.
    """
    grid = plan.grid
    h_out, w_out, co = out.shape
    if (h_out, w_out) != grid.shape:
        raise InvalidValueError(f"expected an output of the grid's shape {grid.shape}")
    if plan.sampler == "fast" and plan.inverse_map.n_sheets <= 1:
        _render_compiled(images[0], plan, out, bg, progress)
    else:
        _render_numpy(images, plan, out, bg, progress)


def _grid_valid(grid: Grid, x: NDArray[np.float64], y: NDArray[np.float64]) -> NDArray[np.bool_]:
    """Where the grid shows anything (inside a fisheye's disc; everywhere elsewhere)."""
    if getattr(grid, "disc", False):
        a, b = grid._ab(x, y)
        return np.hypot(a, b) <= 1.0
    return np.ones(x.shape, bool)


def _fill_outside(out: NDArray, r0: int, r1: int, gvalid: NDArray, bg: NDArray) -> None:
    """Outside the picture (a fisheye's disc): background, transparent."""
    if not np.all(gvalid):
        co = out.shape[2]
        part = out.reshape(-1, co)[r0 * out.shape[1] : r1 * out.shape[1]]
        fill = np.zeros(co, np.float64)
        fill[: len(bg)] = bg
        part[~gvalid] = fill.astype(out.dtype)


def _render_compiled(
    src: NDArray,
    plan: Plan,
    out: NDArray,
    bg: NDArray[np.float32],
    progress: Callable[[int, int], None] | None,
) -> None:
    """The grid path with compiled geometry and samplers (one sheet): per band, the
    centres' source points and footprints, then the samples of each pixel (one, or
    its footprint's parts for the area filter, or its subsamples) in tap space."""
    from ..render import fast
    from ..render.plan import grid_footprints, grid_points
    from ..render.warp import _finish, _rows_done

    grid = plan.grid
    h_out, w_out, co = out.shape
    in_shape = plan.in_shape
    mode, n = plan.antialias
    flat = out.reshape(-1)
    band = max(1, _BAND_PIXELS // w_out)
    cols = np.arange(w_out, dtype=np.float64) + 0.5
    for r0 in range(0, h_out, band):
        _rows_done(progress, r0, h_out)
        r1 = min(h_out, r0 + band)
        rows = np.arange(r0, r1, dtype=np.float64) + 0.5
        x, y = (a.reshape(-1) for a in np.broadcast_arrays(cols[None, :], rows[:, None]))
        npx = x.size
        gvalid = _grid_valid(grid, x, y)
        both = grid_footprints(plan, x, y) if mode in ("area", "adaptive") else None
        J = jump = None
        if both is not None:
            u, v, ok, J, jump = both
        else:
            u, v, ok = grid_points(plan, x, y, 0.0, 0.0)
            if mode in ("area", "adaptive"):
                J, jump = _footprints_uv(plan, x, y, u, v, ok, in_shape)
        nx, ny, boxes = _samples(mode, n, J, jump, gvalid)
        counts = nx * ny
        special = counts > 1
        start = np.concatenate([[0], np.cumsum(counts)])
        if np.any(special):
            sp = np.flatnonzero(special)
            owner, ox, oy = _aa.subsample_offsets(nx[sp], ny[sp])
            su, sv, sok = grid_points(plan, x[sp[owner]], y[sp[owner]], ox - 0.5, oy - 0.5)
            total = int(start[-1])
            first = np.cumsum(counts[sp]) - counts[sp]
            where_sub = start[sp[owner]] + (np.arange(owner.size) - first[owner])
            where_one = start[:-1][~special]
            uu = np.empty(total)
            vv = np.empty(total)
            kk = np.empty(total, bool)
            uu[where_one], vv[where_one], kk[where_one] = u[~special], v[~special], ok[~special]
            uu[where_sub], vv[where_sub], kk[where_sub] = su, sv, sok
        else:
            uu, vv, kk = u, v, ok
        p0 = r0 * w_out
        if boxes is not None:
            own = np.repeat(np.arange(npx), counts)
            acc, cover = fast.area_samples(src, uu, vv, boxes[0][own], boxes[1][own], kk, own, npx)
            _finish(acc, cover, counts, src, bg, flat, co, p0)
        else:
            fast.sample_samples(
                src, uu, vv, kk, start, flat, co, p0, interp=plan.interp, background=bg,
                threads=plan.threads,
            )  # fmt: skip
        _fill_outside(out, r0, r1, gvalid, bg)
    _rows_done(progress, h_out, h_out)


def _footprints_uv(
    plan: Plan,
    x: NDArray[np.float64],
    y: NDArray[np.float64],
    cu: NDArray[np.float64],
    cv: NDArray[np.float64],
    ok_c: NDArray[np.bool_],
    in_shape: tuple[int, int],
) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """:func:`footprints` from compiled geometry (the centres' tap-space points given)."""
    from ..render.plan import grid_points

    uvs = []
    oks = []
    for dx, dy in ((-0.5, 0.0), (0.5, 0.0), (0.0, -0.5), (0.0, 0.5)):
        pu, pv, pok = grid_points(plan, x, y, dx, dy)
        uvs.append(np.stack([pu, pv], -1))
        oks.append(pok)
    return _jacobian(np.stack([cu, cv], -1), ok_c, uvs, oks, in_shape[1])


def _render_numpy(
    images: list[NDArray],
    plan: Plan,
    out: NDArray,
    bg: NDArray[np.float32],
    progress: Callable[[int, int], None] | None,
) -> None:
    """The grid path with NumPy geometry (any number of sheets; NumPy or compiled
    samplers)."""
    from ..render.warp import _rows_done, _sample_batches

    grid, inverse_map, interp = plan.grid, plan.inverse_map, plan.interp
    sampler, threads = plan.sampler, plan.threads
    h_out, w_out, co = out.shape
    in_shape = images[0].shape[:2]
    mode, n = plan.antialias
    if len(images) > 1 and inverse_map.n_sheets > 1 and mode != "area":
        sampler = "reference"
    flat = out.reshape(-1)

    def to_cp1(sub: NDArray[np.float64], centre: NDArray[np.float64]) -> NDArray:
        d, _ = grid.directions_at(centre[:, 0], centre[:, 1], *(sub - centre).T)
        return coords.cp1_from_xyz(d)

    band = max(1, _BAND_PIXELS // w_out)
    cols = np.arange(w_out, dtype=np.float64) + 0.5
    for r0 in range(0, h_out, band):
        _rows_done(progress, r0, h_out)
        r1 = min(h_out, r0 + band)
        rows = np.arange(r0, r1, dtype=np.float64) + 0.5
        px = np.stack(np.broadcast_arrays(cols[None, :], rows[:, None]), -1).reshape(-1, 2)
        x, y = px[:, 0], px[:, 1]
        d, gvalid = grid.directions_at(x, y)
        pb = inverse_map.pull(coords.cp1_from_xyz(d))
        valid = gvalid if pb.valid is None else gvalid & pb.valid
        points = pb.points
        J = jump = None
        if mode in ("area", "adaptive"):
            J, jump = footprints(grid, inverse_map, x, y, in_shape)
        nx, ny, boxes = _samples(mode, n, J, jump, gvalid)
        centre: tuple[Any, Any, Any] = (points, valid, pb.sheet)
        _sample_batches(
            images, inverse_map, px, nx, ny, centre, (h_out, w_out), flat, co, r0 * w_out,
            interp, bg, sampler, threads, boxes, to_cp1=to_cp1,
        )  # fmt: skip
        _fill_outside(out, r0, r1, gvalid, bg)
    _rows_done(progress, h_out, h_out)


def _tile_bounds(grid: Grid, x: NDArray, y: NDArray) -> tuple[NDArray, NDArray, NDArray, NDArray]:
    """The first and last pixel columns and rows that a sample at ``(x, y)`` may read: its
    cube face (a cube map's taps never reach the next face), else the whole picture."""
    h, w = grid.shape
    face = getattr(grid, "face", None)
    if face is None or not hasattr(grid, "cols"):
        zero = np.zeros(x.shape, np.intp)
        return zero, zero + (w - 1), zero, zero + (h - 1)
    col = np.clip(np.floor(x / face), 0, grid.cols - 1).astype(np.intp)
    row = np.clip(np.floor(y / face), 0, grid.rows - 1).astype(np.intp)
    return col * face, col * face + face - 1, row * face, row * face + face - 1


def _sample_clamped(
    image: NDArray, x: NDArray, y: NDArray, bounds: tuple[NDArray, ...], interp: str
) -> NDArray[np.float32]:
    """Samples of a flat picture at pixel positions, taps clamped to ``bounds`` (per
    sample: first and last column, first and last row): bilinear, or bicubic (Keys,
    a = -0.5, as :func:`~spherewarp.render.sample`)."""
    from ..render.sampling import _cubic_weights

    x0b, x1b, y0b, y1b = bounds
    u = np.clip(x - 0.5, x0b, x1b)
    v = np.clip(y - 0.5, y0b, y1b)
    i0 = np.floor(u).astype(np.intp)
    j0 = np.floor(v).astype(np.intp)
    fu = (u - i0).astype(np.float32)
    fv = (v - j0).astype(np.float32)
    im = image.astype(np.float32, copy=False)
    if interp == "bicubic":
        taps = (-1, 0, 1, 2)
        wx, wy = _cubic_weights(fu), _cubic_weights(fv)
    else:
        taps = (0, 1)
        wx, wy = [1 - fu, fu], [1 - fv, fv]
    cols = [np.clip(i0 + d, x0b, x1b) for d in taps]
    out = np.zeros((len(x), image.shape[2]), np.float32)
    for dj, wyj in zip(taps, wy, strict=True):
        jj = np.clip(j0 + dj, y0b, y1b)
        row = sum(wxi[:, None] * im[jj, ci] for wxi, ci in zip(wx, cols, strict=True))
        out += wyj[:, None] * row
    if interp == "bicubic" and image.dtype.kind == "f":  # no ringing (as render.sample)
        near = [im[np.clip(j0 + dj, y0b, y1b), np.clip(i0 + di, x0b, x1b)]
                for dj in (0, 1) for di in (0, 1)]  # fmt: skip
        lo, hi = np.fmin.reduce(near), np.fmax.reduce(near)
        nan = np.isnan(out)
        out = np.clip(out, lo, hi)
        out[nan] = np.nan
    return out


def from_grid(
    image: NDArray,
    grid: Grid,
    output_shape: tuple[int, int],
    *,
    supersample: int | None = None,
    background: Any = None,
    alpha: bool = False,
    interp: str = "bicubic",
) -> NDArray:
    """An equirectangular panorama of ``output_shape`` from a picture in ``grid``.

    Every output pixel averages ``supersample x supersample`` samples (default: one, and
    more where the picture has over twice the output's pixels a side: up to 4), bicubic
    (``interp="bilinear"`` for bilinear), of ``image`` (their taps clamped at its edges;
    a cube map's taps stay on their face) at
    :meth:`Grid.inverse` of their directions; directions the picture does not show
    get ``background`` (and alpha 0 with ``alpha``).

    Examples
    --------
    >>> from spherewarp.grids import CubeMap3x2
    >>> cube = np.full((8, 12, 3), 200, np.uint8)
    >>> from_grid(cube, CubeMap3x2((8, 12)), (8, 16)).shape
    (8, 16, 3)
    """
    from ..render.warp import _background, _full_value, as_image

    img = as_image(image)
    if img.shape[:2] != grid.shape:
        raise InvalidValueError(
            f"expected a picture of the grid's size {grid.shape[1]}x{grid.shape[0]}, "
            f"got {img.shape[1]}x{img.shape[0]}"
        )
    from ..render.sampling import check_interp

    interp = check_interp(interp)
    if interp == "nearest":
        raise InvalidValueError("expected interp 'bilinear' or 'bicubic' for a grid's picture")
    h_out, w_out = (int(v) for v in output_shape)
    c = img.shape[2]
    add_alpha = alpha and c in (1, 3)
    bg = _background(background, c)
    if supersample is None:
        ratio = grid.shape[0] * grid.shape[1] / (h_out * w_out)
        supersample = int(np.clip(np.ceil(np.sqrt(ratio) - 1.0), 1, 4))
    n = max(1, int(supersample))
    out = np.empty((h_out, w_out, c + add_alpha), img.dtype)
    off = (np.arange(n) + 0.5) / n - 0.5
    band = max(1, (1 << 16) // (w_out * n * n))
    for r0 in range(0, h_out, band):
        r1 = min(h_out, r0 + band)
        yy, xx, oy, ox = np.meshgrid(
            np.arange(r0, r1) + 0.5, np.arange(w_out) + 0.5, off, off, indexing="ij"
        )
        ll = coords.lonlat_from_pixel(np.stack([xx + ox, yy + oy], -1), w_out, h_out)
        px, ok = grid.inverse(coords.xyz_from_lonlat(ll).reshape(-1, 3))
        bounds = _tile_bounds(grid, px[:, 0], px[:, 1])
        vals = _sample_clamped(img, px[:, 0], px[:, 1], bounds, interp)
        vals[~ok] = bg
        vals = vals.reshape(r1 - r0, w_out, n * n, c).mean(axis=2)
        if add_alpha:
            cover = ok.reshape(r1 - r0, w_out, n * n).mean(axis=2)
            vals = np.concatenate([vals, cover[..., None] * _full_value(img.dtype)], -1)
        if img.dtype.kind == "u":
            info = np.iinfo(img.dtype)
            vals = np.clip(np.rint(vals), info.min, info.max)
        out[r0:r1] = vals.astype(img.dtype)
    return out
