"""Cached maps: compute a pull-back once, apply it to many images.

For video, or any effect whose map does not change from frame to frame, the
geometry (and the anti-aliasing decisions) need not be redone per frame:
:meth:`WarpMap.build` computes, for every output pixel, where its samples
come from, and :meth:`WarpMap.apply` only samples. This is what OpenCV's
``convertMaps`` + ``remap`` and ffmpeg's ``v360`` tables do.

Storage, per output pixel (bilinear, the default): the index of the top-left
tap as an int32 (the other three taps are its right and lower neighbours;
the sign bit sends a pair across the seam to the slow path) and the two
weights in 1/256 pixel as one uint16: 6 bytes a pixel, like OpenCV's
fixed-point maps, laid out tile by tile in the order the compiled kernel
walks them. Pixels that need more (several samples for anti-aliasing, a
hole, taps folded over a pole, or ``nearest``/``bicubic`` sampling) keep an
explicit list of float32 sample coordinates instead.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import coords
from ..errors import InvalidTypeError, InvalidValueError
from ..maps.base import SphereMap
from . import antialias as _aa
from . import fast
from .sampling import check_interp, sample
from .warp import _background, _full_value, as_image

__all__ = ["WarpMap"]

_SEAM = np.int32(-(2**31))
_LOW31 = np.int32(0x7FFFFFFF)


def _taps_numpy(
    u: NDArray[np.float64], v: NDArray[np.float64], w_in: int, h_in: int, big: int
) -> tuple[NDArray[np.int32], NDArray[np.int32], NDArray[np.uint16]]:
    """NumPy twin of ``_kernels.taps_u8`` (used when numba is not installed)."""
    xi = np.floor(u * 256.0 + 1024.5).astype(np.int64)
    yi = np.floor(v * 256.0 + 1024.5).astype(np.int64)
    x0 = (xi >> 8) - 4
    y0 = (yi >> 8) - 4
    tx = xi & 255
    ty = yi & 255
    x0 = np.where(x0 < 0, x0 + w_in, x0)
    x0 = np.where(x0 >= w_in, x0 - w_in, x0)
    xs = x0 + w_in // 2
    xs = np.where(xs >= w_in, xs - w_in, xs)
    top = y0 < 0
    bot = y0 + 1 >= h_in
    ya = np.minimum(np.where(top, 0, y0), h_in - 1)
    yb = np.where(bot, h_in - 1, y0 + 1)
    xa = np.where(top, xs, x0)
    xb = np.where(bot, xs, x0)
    ia = ya * w_in + xa
    ib = yb * w_in + xb
    fa = (xa == w_in - 1) | (ia >= big)
    fb = (xb == w_in - 1) | (ib >= big)
    oa = np.where(fa, ia | (1 << 31), ia).astype(np.uint32).view(np.int32)
    ob = np.where(fb, ib | (1 << 31), ib).astype(np.uint32).view(np.int32)
    return oa, ob, (tx | (ty << 8)).astype(np.uint16)


class WarpMap:
    """A precomputed pull-back: build it once, apply it to every frame.

    Build with :meth:`build`; :meth:`apply` gives the same image as
    :func:`~spherewarp.render.warp` with the same options (to the rounding of
    the stored coordinates: 1/256 pixel for bilinear taps, float32
    otherwise), at the cost of sampling alone. Two exceptions:

    * ``antialias="auto"`` (the default) is ``"adaptive"`` here: supersampling
      where a pixel covers more than one input pixel, whose samples are cached.
      :func:`~spherewarp.render.warp`'s ``"auto"`` uses the area filter for a
      map that shrinks the input somewhere, which is not cached.
    * ``antialias="area"``: its taps would take more memory than the image (16
      bytes each), so :meth:`apply` renders on the fly, the image of
      :func:`~spherewarp.render.warp` exactly, and the map holds nothing.

    Attributes
    ----------
    in_shape, out_shape : (height, width)
        The input size the map was built for, and the output size.
    interp : str
        The interpolation.
    n_special : int
        Output pixels with their own sample lists (anti-aliased, holes, or
        every pixel for ``nearest``/``bicubic``).

    Examples
    --------
    >>> from spherewarp.maps import Mobius
    >>> img = np.random.default_rng(0).integers(0, 255, (32, 64, 3), dtype=np.uint8)
    >>> wm = WarpMap.build(Mobius.rotation((0, 90), 45), (32, 64))
    >>> bool(np.array_equal(wm.apply(img), np.roll(img, -8, axis=1)))
    True
    >>> wm.out_shape, wm.n_special   # the last row's taps fold over the pole
    ((32, 64), 64)
    """

    def __init__(self, **state: Any):
        self.__dict__.update(state)
        for v in state.values():
            if isinstance(v, np.ndarray):
                v.flags.writeable = False

    # -- building ----------------------------------------------------------------------------------
    @classmethod
    def build(
        cls,
        inverse_map: SphereMap,
        in_shape: tuple[int, int],
        out_shape: tuple[int, int] | None = None,
        *,
        interp: str = "bilinear",
        antialias: str | int = "auto",
        supersample: int | None = None,
        force: bool = False,
        threads: int | None = None,
    ) -> WarpMap:
        """Precompute the pull-back through ``inverse_map`` (see :func:`~spherewarp.render.warp`).

        Parameters
        ----------
        inverse_map : SphereMap
            The map from output points to input points; one sheet.
        in_shape : (height, width)
            Size of the images the map will be applied to.
        out_shape : (height, width), optional
            Default: ``in_shape``.
        interp, antialias, supersample, force, threads
            As for :func:`~spherewarp.render.warp`, but ``antialias="auto"`` is
            ``"adaptive"``, and ``"area"`` is not cached (see the class).

        Raises
        ------
        InvalidTypeError, InvalidValueError
            For a bad map, shapes or options.
        """
        if not isinstance(inverse_map, SphereMap):
            raise InvalidTypeError(
                f"expected a map (a spherewarp.maps.SphereMap), got {type(inverse_map).__name__}"
            )
        if inverse_map.n_sheets > 1:
            raise InvalidValueError(
                f"a cached map samples one input image; this map samples {inverse_map.n_sheets}"
            )
        h_in, w_in = _check_shape(in_shape, "in_shape")
        if w_in != 2 * h_in and not force:
            raise InvalidValueError(
                f"in_shape: expected an equirectangular image with width = 2 x height, got "
                f"{w_in}x{h_in} (force=True treats it as equirectangular anyway)"
            )
        h_out, w_out = _check_shape(
            out_shape if out_shape is not None else in_shape, "out_shape", min_width=1
        )
        interp = check_interp(interp)
        mode, n = _aa.parse_antialias(antialias, supersample)
        if mode == "auto":  # cacheable: the adaptive supersampling
            mode = "adaptive"
        use_jit = fast.available()
        spec = fast.kernel_spec(inverse_map) if use_jit else None
        if mode == "area" and interp == "bilinear":
            # the area filter is not cached (its taps would take 16 bytes each, more than
            # the image): apply renders on the fly, the same image as warp
            empty = np.empty(0, np.int64)
            return cls(
                in_shape=(h_in, w_in), out_shape=(h_out, w_out), interp=interp,
                antialias=(mode, n), _live=inverse_map, _oa=np.empty(0, np.int32),
                _wt=np.empty(0, np.uint16), _sp_pix=empty, _sp_start=np.zeros(1, np.int64),
                _sp_u=np.empty(0, np.float32), _sp_v=np.empty(0, np.float32),
                _sp_valid=np.empty(0, np.uint8), _sp_tile=empty,
            )  # fmt: skip
        if mode == "area":  # not bilinear: uniform supersampling, which it approximates
            mode, n = _aa.AREA_FALLBACK
        th, tw = fast.TILE
        nty, ntx = -(-h_out // th), -(-w_out // tw)
        bilinear = interp == "bilinear"
        npx = h_out * w_out
        big = h_in * w_in - 8  # taps from here on take the slow path whatever the channels
        if bilinear:
            oa = np.empty(npx, np.int32)
            wt = np.empty(npx, np.uint16)
        else:
            oa = np.empty(0, np.int32)
            wt = np.empty(0, np.uint16)
        factors = _aa.footprint_factors((h_in, w_in), (h_out, w_out))
        factors = (factors[0] * _aa.AUTO_DENSITY, factors[1] * _aa.AUTO_DENSITY)
        sp_pix: list[NDArray] = []
        sp_count: list[NDArray] = []
        sp_u: list[NDArray] = []
        sp_v: list[NDArray] = []
        sp_valid: list[NDArray] = []
        sp_tile = np.zeros(nty * ntx + 1, np.int64)
        ccols = np.arange(w_out) + 0.5
        rho_in = min(np.pi / h_in, 2 * np.pi / w_in)
        jumps = mode == "adaptive" and (
            spec is None or bool(np.isin(spec.codes, fast.jump_codes()).any())
        )

        def centres(ra: int, rb: int) -> tuple[NDArray, NDArray, NDArray | None, NDArray]:
            """Tap-space source coordinates, magnification and validity of rows ra..rb."""
            if spec is not None:
                x, y, scale, valid = fast.source_coords(
                    spec, (h_in, w_in), (h_out, w_out), (ra, rb), threads
                )
                return x - 0.5, y - 0.5, scale, valid
            px = np.stack(np.broadcast_arrays(ccols[None, :], np.arange(ra, rb)[:, None] + 0.5), -1)
            zw = coords.cp1_from_lonlat(coords.lonlat_from_pixel(px, w_out, h_out))
            pb = inverse_map.pull(zw)
            src = coords.pixel_from_lonlat(coords.lonlat_from_cp1(pb.points), w_in, h_in)
            valid = np.ones(src.shape[:-1], bool) if pb.valid is None else pb.valid
            scale = (
                np.nan_to_num(inverse_map.local_scale(zw), nan=1.0, posinf=1e6)
                if mode == "adaptive"
                else None
            )
            return src[..., 0] - 0.5, src[..., 1] - 0.5, scale, valid

        for ty in range(nty):
            r0, r1 = ty * th, min(h_out, (ty + 1) * th)
            h = r1 - r0
            # centre samples of this row of tiles (and, to find jumps, of the rows next to it)
            ra, rb = (max(0, r0 - 1), min(h_out, r1 + 1)) if jumps else (r0, r1)
            u, v, scale, valid = centres(ra, rb)
            if jumps:
                xyz = coords.xyz_from_lonlat(
                    coords.lonlat_from_pixel(np.stack([u + 0.5, v + 0.5], -1), w_in, h_in)
                )
                lat_rows = np.pi / 2 - np.pi * (np.arange(ra, rb) + 0.5) / h_out
                if rb == r1:  # no row below: repeat the last one (no jump there)
                    xyz = np.concatenate([xyz, xyz[-1:]])
                    scale = np.concatenate([scale, scale[-1:]])
                    valid = np.concatenate([valid, valid[-1:]])
                    lat_rows = np.concatenate([lat_rows, lat_rows[-1:]])
                jump = _aa.jump_mask(xyz, scale, lat_rows, valid, rho_in, h_out)
                inner = slice(r0 - ra, r0 - ra + h)
                jump = jump[inner]
                u, v, scale, valid = u[inner], v[inner], scale[inner], valid[inner]
            if mode == "uniform":
                nx = ny = np.full(u.shape, n, np.int64)
            elif mode == "adaptive":
                lat = (np.pi / 2 - np.pi * (np.arange(r0, r1) + 0.5) / h_out)[:, None]
                nx, ny = _aa.sample_counts(
                    scale, np.broadcast_to(lat, u.shape), factors, _aa.AUTO_TOLERANCE, _aa.AUTO_MAX
                )
                if jumps:
                    nx[jump] = np.maximum(nx[jump], _aa.JUMP_SAMPLES)
                    ny[jump] = np.maximum(ny[jump], _aa.JUMP_SAMPLES)
            else:
                nx = ny = np.ones(u.shape, np.int64)
            special = (nx * ny > 1) | ~valid | (not bilinear)
            if bilinear:
                if use_jit:
                    a = np.empty(u.size, np.int32)
                    b = np.empty(u.size, np.int32)
                    c = np.empty(u.size, np.uint16)
                    fast._run(
                        fast._kernels().build_taps, (u, v, w_in, h_in, big, a, b, c), threads, h
                    )
                    a, b, c = a.reshape(u.shape), b.reshape(u.shape), c.reshape(u.shape)
                else:
                    a, b, c = _taps_numpy(u, v, w_in, h_in, big)
                # keep the top-left tap only: the lower pair is w_in further on, except
                # where the taps fold over a pole (those pixels get sample lists)
                fold = (b & _LOW31) != (a & _LOW31) + w_in
                special |= fold
                a = np.where(b < 0, a | _SEAM, a)  # the lower pair's seam or end: slow path
                a = np.where(fold, 0, a)  # a safe dummy: the sample list overwrites it
            for tx in range(ntx):
                c0, c1 = tx * tw, min(w_out, (tx + 1) * tw)
                base = r0 * w_out + c0 * h
                if bilinear:
                    size = h * (c1 - c0)
                    oa[base : base + size] = a[:, c0:c1].ravel()
                    wt[base : base + size] = c[:, c0:c1].ravel()
                t = ty * ntx + tx
                sel = special[:, c0:c1]
                rr, cc = np.nonzero(sel)
                sp_tile[t + 1] = sp_tile[t] + rr.size
                if rr.size == 0:
                    continue
                pix = (r0 + rr) * w_out + c0 + cc
                snx, sny = nx[:, c0:c1][sel], ny[:, c0:c1][sel]
                counts = snx * sny
                sp_pix.append(pix)
                sp_count.append(counts)
                if np.all(counts == 1):
                    sp_u.append(u[:, c0:c1][sel].astype(np.float32))
                    sp_v.append(v[:, c0:c1][sel].astype(np.float32))
                    sp_valid.append(valid[:, c0:c1][sel].astype(np.uint8))
                    continue
                owner, ox, oy = _aa.subsample_offsets(snx, sny)
                py = (r0 + rr)[owner].astype(np.float64)
                pxx = (c0 + cc)[owner].astype(np.float64)
                if spec is not None:
                    su, sv, sok = fast.subsample_coords(
                        spec, (h_in, w_in), (h_out, w_out), py, pxx, oy, ox, threads
                    )
                else:
                    pts = np.stack([pxx + ox, py + oy], -1)
                    pb = inverse_map.pull(
                        coords.cp1_from_lonlat(coords.lonlat_from_pixel(pts, w_out, h_out))
                    )
                    src = coords.pixel_from_lonlat(coords.lonlat_from_cp1(pb.points), w_in, h_in)
                    su, sv = src[:, 0] - 0.5, src[:, 1] - 0.5
                    sok = np.ones(su.shape, bool) if pb.valid is None else pb.valid
                sp_u.append(su.astype(np.float32))
                sp_v.append(sv.astype(np.float32))
                sp_valid.append(sok.astype(np.uint8))

        def cat(parts: list[NDArray], dtype: Any) -> NDArray:
            return np.concatenate(parts).astype(dtype) if parts else np.empty(0, dtype)

        counts_all = cat(sp_count, np.int64)
        return cls(
            in_shape=(h_in, w_in),
            out_shape=(h_out, w_out),
            interp=interp,
            antialias=(mode, n),
            _oa=oa,
            _wt=wt,
            _sp_pix=cat(sp_pix, np.int64),
            _sp_start=np.concatenate([[0], np.cumsum(counts_all)]).astype(np.int64),
            _sp_u=cat(sp_u, np.float32),
            _sp_v=cat(sp_v, np.float32),
            _sp_valid=cat(sp_valid, np.uint8),
            _sp_tile=sp_tile,
        )

    # -- properties --------------------------------------------------------------------------------
    @property
    def n_special(self) -> int:
        return int(self._sp_pix.size)

    @property
    def nbytes(self) -> int:
        """Memory held by the map's arrays, in bytes."""
        return sum(v.nbytes for v in self.__dict__.values() if isinstance(v, np.ndarray))

    def __repr__(self) -> str:
        return (
            f"WarpMap(in_shape={self.in_shape}, out_shape={self.out_shape}, "
            f"interp={self.interp!r}, n_special={self.n_special}, "
            f"nbytes={self.nbytes / 2**20:.1f} MiB)"
        )

    # -- applying ----------------------------------------------------------------------------------
    def apply(
        self,
        image: ArrayLike,
        *,
        background: ArrayLike | None = None,
        alpha: bool = False,
        out: NDArray | None = None,
        threads: int | None = None,
    ) -> NDArray:
        """Warp one image (a video frame) through the cached map.

        Parameters
        ----------
        image : ndarray (H, W[, C])
            ``(H, W) == in_shape``; uint8, uint16, float32 or float64, 1-4 channels.
        background, alpha
            As for :func:`~spherewarp.render.warp`.
        out : ndarray, optional
            Where to write the result (shape ``out_shape + (C,)``, or ``C + 1``
            with ``alpha``; the image's dtype; C-contiguous), e.g. to reuse one
            buffer for every frame.
        threads : int, optional
            Worker threads (default: all cores).

        Returns
        -------
        ndarray
        """
        img = as_image(image)
        img = img.astype(img.dtype.newbyteorder("="), copy=False)
        h, w, c = img.shape
        if (h, w) != self.in_shape:
            raise InvalidValueError(
                f"expected an image of {self.in_shape[1]}x{self.in_shape[0]} (the map's "
                f"in_shape), got {w}x{h}"
            )
        add_alpha = alpha and c not in (2, 4)
        co = c + (1 if add_alpha else 0)
        shape = (*self.out_shape, co)
        if out is None:
            out = np.empty(shape, img.dtype)
        elif (
            not isinstance(out, np.ndarray)
            or out.shape != shape
            or out.dtype != img.dtype
            or not out.flags.c_contiguous
            or not out.flags.writeable
        ):
            raise InvalidValueError(
                f"out: expected a writeable C-contiguous {img.dtype} array of shape {shape}"
            )
        bg = _background(background, c)
        live = getattr(self, "_live", None)
        if live is not None:  # antialias="area": on the fly
            from .warp import warp

            res = warp(
                img, live, output_shape=self.out_shape, antialias="area", background=background,
                alpha=alpha, force=True, threads=threads,
            )  # fmt: skip
            out[...] = res
        elif fast.available():
            self._apply_jit(fast._native(img), out, bg, threads)
        else:
            self._apply_numpy(img, out, bg)
        return out

    def _apply_jit(self, img: NDArray, out: NDArray, bg: NDArray, threads: int | None) -> None:
        k = fast._kernels()
        fast_u8 = fast._fast_u8_ok(img, out, self.interp) and self._oa.size > 0
        if fast_u8:
            p64, tail, big, o32 = fast._u8_views(img, out)
        else:
            p64, tail, big, o32 = fast._DUMMY64, fast._DUMMY64, 0, fast._DUMMY32
        fast_f = (
            img.dtype == np.float32
            and self.interp == "bilinear"
            and out.shape[2] == img.shape[2]
            and self._oa.size > 0
        )
        fimg = fast._readonly(fast._native(img).reshape(-1)) if fast_f else fast._DUMMY_F32
        is_int, maxval, full = fast._value_params(img.dtype)
        th, tw = fast.TILE
        args = (
            fast._image_bundle(img), p64, tail, big, o32, fast._output_bundle(out),
            *out.shape, fast_u8, fast_f, fimg, self._oa, self._wt, th, tw,
            self._sp_pix, self._sp_start, self._sp_u, self._sp_v, self._sp_valid,
            self._sp_tile, fast.INTERP_CODES[self.interp], bg, is_int, maxval, full,
        )  # fmt: skip
        fast._run(k.apply_cache, args, threads, -(-self.out_shape[0] // th))

    def _apply_numpy(self, img: NDArray, out: NDArray, bg: NDArray) -> None:
        h_in, w_in, c = img.shape
        h_out, w_out, co = out.shape
        flat_in = img.reshape(-1, c)
        flat = out.reshape(-1, co)
        th, tw = fast.TILE
        nty, ntx = -(-h_out // th), -(-w_out // tw)
        full = _full_value(img.dtype)
        if self._oa.size:
            for ty in range(nty):
                r0, r1 = ty * th, min(h_out, (ty + 1) * th)
                h = r1 - r0
                s0, s1 = r0 * w_out, r1 * w_out
                a = (self._oa[s0:s1] & _LOW31).astype(np.int64)
                b = a + w_in
                a1 = np.where(a % w_in == w_in - 1, a - w_in + 1, a + 1)
                b1 = np.where(b % w_in == w_in - 1, b - w_in + 1, b + 1)
                tx = ((self._wt[s0:s1] & 255).astype(np.float32) / 256)[:, None]
                ty_ = ((self._wt[s0:s1] >> 8).astype(np.float32) / 256)[:, None]
                one = np.float32(1)
                top = (one - tx) * flat_in[a].astype(np.float32) + tx * flat_in[a1]
                bot = (one - tx) * flat_in[b].astype(np.float32) + tx * flat_in[b1]
                res = (one - ty_) * top + ty_ * bot
                if co > c:
                    res = np.concatenate([res, np.full((len(res), 1), full, np.float32)], -1)
                if img.dtype.kind == "u":
                    info = np.iinfo(img.dtype)
                    np.clip(np.rint(res), info.min, info.max, out=res)
                # tile-major -> rows
                pos = 0
                for tx_i in range(ntx):
                    c0, c1 = tx_i * tw, min(w_out, (tx_i + 1) * tw)
                    size = h * (c1 - c0)
                    block = res[pos : pos + size].reshape(h, c1 - c0, co)
                    out[r0:r1, c0:c1] = block
                    pos += size
        if self.n_special:
            start = self._sp_start
            for q0 in range(0, self.n_special, 1 << 16):
                q1 = min(self.n_special, q0 + (1 << 16))
                s0, s1 = start[q0], start[q1]
                u = self._sp_u[s0:s1].astype(np.float64)
                v = self._sp_v[s0:s1].astype(np.float64)
                ok = self._sp_valid[s0:s1].astype(bool)
                vals = sample(img, u + 0.5, v + 0.5, self.interp)
                vals[~ok] = 0
                seg = start[q0:q1] - s0
                acc = np.add.reduceat(vals, seg, axis=0)
                cover = np.add.reduceat(ok.astype(np.float32), seg)
                counts = np.diff(start[q0 : q1 + 1]).astype(np.float32)
                inv = (np.float32(1) / counts)[:, None]
                res = (acc + (counts - cover)[:, None] * bg) * inv
                if co > c:
                    res = np.concatenate([res, cover[:, None] * inv * full], -1)
                if img.dtype.kind == "u":
                    info = np.iinfo(img.dtype)
                    np.clip(np.rint(res), info.min, info.max, out=res)
                flat[self._sp_pix[q0:q1]] = res


def _check_shape(shape: Any, name: str, min_width: int = 2) -> tuple[int, int]:
    try:
        h, w = (int(v) for v in shape)
    except (TypeError, ValueError):
        raise InvalidValueError(f"{name}: expected (height, width), got {shape!r}") from None
    if h < 1 or w < min_width or h * w > 1 << 30:
        raise InvalidValueError(f"{name}: expected a positive (height, width), got {shape!r}")
    return h, w
