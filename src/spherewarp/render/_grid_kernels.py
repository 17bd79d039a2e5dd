"""Compiled kernels of the render plan: output grids' geometry, one-tap sampling (numba).

Imported, as :mod:`spherewarp.render._kernels` (whose helpers it calls), only by
:mod:`spherewarp.render.fast` on the first compiled render; every kernel is
cached on disk (``cache=True``) and warmed up at build time
(:mod:`spherewarp.render._warmup`).

Geometry
--------
:func:`grid_source` gives the tap-space source coordinates of points of an
output grid (:mod:`spherewarp.grids`): pixel position ``(x + dx, y + dy)`` ->
the camera-frame direction of the grid's projection -> the world direction
(the grid's frame ``M``) -> the map's compiled stages
(:func:`~spherewarp.render._kernels.run_stages`) -> ``(u, v)`` in the input. It
computes the same directions as the grids' NumPy ``_camera`` methods (to
rounding). :func:`grid_xyz` stops at the world direction (for maps without
stages, pulled back by NumPy), and :func:`xyz_source` starts from given
directions (for the Peirce and torus grids, whose directions NumPy computes).

Grid codes and parameter rows (``gp``, float64):

``GRID_EQUIRECT`` (0), ``GRID_STEREO`` (1), ``GRID_FISHEYE`` (2), ``GRID_EQUISOLID`` (3),
``GRID_RECTILINEAR`` (4), ``GRID_CUBE`` (5)
    ``gp[0:9]`` the frame ``M`` row by row (world = ``M @ camera``), ``gp[9]``
    the width, ``gp[10]`` the height, ``gp[11]`` the plane unit (pixels per unit
    of the plane chart; the face side for the cube), ``gp[12]`` the
    projection's constant (``tan(fov / 4)``, ``fov / 2`` in radians, ``sin(fov / 4)``,
    ``tan(fov / 2)``), ``gp[13]`` 1 where only the inscribed disc is picture, and
    ``gp[14]`` the cube's faces per row. ``faces`` (6, 3, 3): the cube's faces
    (forward, right-in-face, down-in-face) in camera coordinates.

One-tap plans
-------------
:func:`spec_rows` computes the source coordinates of whole equirectangular
rows exactly as ``_kernels.render_spec`` does when it takes one tap a pixel
(same helpers, same chunks), and :func:`sample_taps` samples given coordinates
exactly as that kernel's one-tap path does (uint8 and float32 bilinear through
the same vectorised taps); so a plan cached as coordinates
(:class:`~spherewarp.render.cache.WarpMap`) gives the still's pixels bit for bit.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ._kernels import (
    _H,
    _P,
    _directions,
    _layout,
    _tile,
    acc_sample,
    blend_f32,
    blend_u8,
    finish_pixel,
    gather_u8,
    mobius_to_source,
    run_stages,
    store_u8,
    taps_f32,
    taps_u8,
    to_source,
)

GRID_EQUIRECT = 0
GRID_STEREO = 1
GRID_FISHEYE = 2
GRID_EQUISOLID = 3
GRID_RECTILINEAR = 4
GRID_CUBE = 5

PI = math.pi
HALF_PI = 0.5 * math.pi
#: points a chunk (scratch on the stack of each worker)
CHUNK = 256


@njit(**_H)
def _camera(kind, gp, faces, x, y, dx, dy, n, X, Y, Z, valid):
    """World directions ``(X, Y, Z)`` of grid positions ``(x + dx, y + dy)`` and where
    the grid shows anything (``valid``; outside a fisheye's disc it does not)."""
    w = gp[9]
    h = gp[10]
    s = gp[11]
    kk = gp[12]
    disc = gp[13] != 0.0
    cols = np.int64(gp[14])
    for k in range(n):
        xx = x[k] + dx[k]
        yy = y[k] + dy[k]
        ok = 1
        if kind == GRID_EQUIRECT:
            lon = 2.0 * PI * xx / w - PI
            lat = HALF_PI - PI * yy / h
            cl = math.cos(lat)
            c0 = cl * math.cos(lon)
            c1 = cl * math.sin(lon)
            c2 = math.sin(lat)
        elif kind == GRID_RECTILINEAR:
            a = (xx - 0.5 * w) / s
            b = (0.5 * h - yy) / s
            c0 = 1.0
            c1 = a * kk
            c2 = b * kk
            r = math.sqrt(c0 * c0 + c1 * c1 + c2 * c2)
            c0 /= r
            c1 /= r
            c2 /= r
        elif kind == GRID_CUBE:
            col = min(max(math.floor(x[k] / s), 0.0), cols - 1.0)
            rows = np.int64(h / s + 0.5)
            row = min(max(math.floor(y[k] / s), 0.0), rows - 1.0)
            f = np.int64(col) + cols * np.int64(row)
            uf = 2.0 * (xx - col * s) / s - 1.0
            vf = 2.0 * (yy - row * s) / s - 1.0
            c0 = faces[f, 0, 0] + uf * faces[f, 1, 0] + vf * faces[f, 2, 0]
            c1 = faces[f, 0, 1] + uf * faces[f, 1, 1] + vf * faces[f, 2, 1]
            c2 = faces[f, 0, 2] + uf * faces[f, 1, 2] + vf * faces[f, 2, 2]
            r = max(math.sqrt(c0 * c0 + c1 * c1 + c2 * c2), 1e-300)
            c0 /= r
            c1 /= r
            c2 /= r
        else:  # azimuthal: stereographic, fisheye, equisolid
            a = (xx - 0.5 * w) / s
            b = (0.5 * h - yy) / s
            rho = math.sqrt(a * a + b * b)
            if kind == GRID_STEREO:
                theta = 2.0 * math.atan(rho * kk)
            elif kind == GRID_FISHEYE:
                theta = min(rho * kk, PI)
            else:
                theta = 2.0 * math.asin(min(max(rho * kk, -1.0), 1.0))
            phi = math.atan2(b, a)
            st = math.sin(theta)
            c0 = math.cos(theta)
            c1 = st * math.cos(phi)
            c2 = st * math.sin(phi)
            if disc:
                a0 = (x[k] - 0.5 * w) / s
                b0 = (0.5 * h - y[k]) / s
                ok = 1 if math.sqrt(a0 * a0 + b0 * b0) <= 1.0 else 0
        X[k] = gp[0] * c0 + gp[1] * c1 + gp[2] * c2
        Y[k] = gp[3] * c0 + gp[4] * c1 + gp[5] * c2
        Z[k] = gp[6] * c0 + gp[7] * c1 + gp[8] * c2
        valid[k] = ok


@njit(**_P)
def grid_xyz(kind, gp, faces, x, y, dx, dy, X, Y, Z, valid, wk, nw):
    """World directions of grid positions ``(x + dx, y + dy)`` (flat arrays), in
    chunks of :data:`CHUNK` dealt round-robin to ``nw`` workers."""
    n = x.shape[0]
    for ci in range(wk, (n + CHUNK - 1) // CHUNK, nw):
        a = ci * CHUNK
        m = min(CHUNK, n - a)
        _camera(kind, gp, faces, x[a:], y[a:], dx[a:], dy[a:], m, X[a:], Y[a:], Z[a:], valid[a:])


@njit(**_H)
def _stages_to_source(codes, params, T, X, Y, Z, G, ok, m, kx, ky, u, v, valid):
    for k in range(m):
        T[k] = 1.0
        G[k] = 1.0
    run_stages(codes, params, T, X, Y, Z, G, ok, m)
    to_source(X, Y, Z, m, kx, ky, u, v)
    for k in range(m):
        valid[k] = ok[k]


@njit(**_P)
def grid_source(kind, gp, faces, codes, params, x, y, dx, dy, kx, ky, u, v, valid, wk, nw):
    """Tap-space source coordinates ``(u, v)`` of grid positions ``(x + dx, y + dy)``
    through the stages ``codes, params`` (none: the identity), and their validity
    (the grid's and the map's)."""
    n = x.shape[0]
    f64 = np.empty((5, CHUNK))
    T = f64[0]
    X = f64[1]
    Y = f64[2]
    Z = f64[3]
    G = f64[4]
    ok = np.empty(CHUNK, np.uint8)
    for ci in range(wk, (n + CHUNK - 1) // CHUNK, nw):
        a = ci * CHUNK
        m = min(CHUNK, n - a)
        _camera(kind, gp, faces, x[a:], y[a:], dx[a:], dy[a:], m, X, Y, Z, ok)
        _stages_to_source(codes, params, T, X, Y, Z, G, ok, m, kx, ky, u[a:], v[a:], valid[a:])


@njit(**_P)
def xyz_source(codes, params, xyz, kx, ky, u, v, valid, wk, nw):
    """Tap-space source coordinates of given world directions ``xyz`` (n, 3) through
    the stages (the Peirce and torus grids)."""
    n = xyz.shape[0]
    f64 = np.empty((5, CHUNK))
    T = f64[0]
    X = f64[1]
    Y = f64[2]
    Z = f64[3]
    G = f64[4]
    ok = np.empty(CHUNK, np.uint8)
    for ci in range(wk, (n + CHUNK - 1) // CHUNK, nw):
        a = ci * CHUNK
        m = min(CHUNK, n - a)
        for k in range(m):
            X[k] = xyz[a + k, 0]
            Y[k] = xyz[a + k, 1]
            Z[k] = xyz[a + k, 2]
            ok[k] = 1
        _stages_to_source(codes, params, T, X, Y, Z, G, ok, m, kx, ky, u[a:], v[a:], valid[a:])


@njit(**_P)
def spec_rows(codes, params, ccos, csin, r0, ho, kx, ky, tw, U, V, valid, wk, nw):
    """Tap-space source coordinates and validity of equirectangular output rows
    ``r0 .. r0 + len(U)``, as ``_kernels.render_spec`` computes them when it takes one
    tap a pixel: the same helpers on the same chunks (``tw`` columns of a tile)."""
    nr, wo = U.shape
    f64s = np.empty((7, tw))
    T = f64s[0]
    X = f64s[1]
    Y = f64s[2]
    Z = f64s[3]
    G = f64s[4]
    Us = f64s[5]
    Vs = f64s[6]
    vs = np.empty(tw, np.uint8)
    mob1 = codes.shape[0] == 1 and codes[0] == 1  # one Lorentz stage, fused (as render_spec)
    G[:] = 1.0
    vs[:] = 1
    ntx = (wo + tw - 1) // tw
    for r in range(wk, nr, nw):
        i = r0 + r
        lat = HALF_PI - PI * (i + 0.5) / ho
        cl = math.cos(lat)
        sl = math.sin(lat)
        for tx in range(ntx):
            tx0 = tx * tw
            w = min(tw, wo - tx0)
            cc = ccos[tx0 : tx0 + w]
            cs = csin[tx0 : tx0 + w]
            if mob1:
                mobius_to_source(cl, sl, cc, cs, params[0], w, kx, ky, T, Us, Vs)
            else:
                _directions(cl, sl, cc, cs, w, T, X, Y, Z, G, vs)
                run_stages(codes, params, T, X, Y, Z, G, vs, w)
                to_source(X, Y, Z, w, kx, ky, Us, Vs)
            for k in range(w):
                U[r, tx0 + k] = Us[k]
                V[r, tx0 + k] = Vs[k]
                valid[r, tx0 + k] = vs[k]


@njit(**_P)
def sample_taps(
    img, p64, tail, big, o32, dst, ho, wo, co, fast_u8, fast_f32, fimg, U, V, valid, r0,
    interp, bg, is_int, maxval, full, th, tw, wk, nw,
):  # fmt: skip
    """One tap a pixel at given tap-space coordinates: output rows ``r0 .. r0 +
    len(U)`` (``U, V, valid``: their coordinates and validity, ``(rows, wo)``), in
    tiles of ``th x tw``, as ``_kernels.render_spec``'s one-tap path (``fast_u8``:
    uint8 bilinear two taps a load; ``fast_f32``: float32 bilinear vectorised;
    else the scalar sampler; pixels not valid get the background)."""
    hi = img[5]
    nr = U.shape[0]
    wi, c, obytes, ntx, _, big_w, shift, lom, spill = _layout(img, dst, nr, wo, th, tw)
    ntiles = ((nr + th - 1) // th) * ntx
    i32s = np.empty((2, tw), np.int32)
    oa = i32s[0]
    ob = i32s[1]
    wt = np.empty(tw, np.uint16)
    qs = np.empty((2, tw), np.uint64)
    qa = qs[0]
    qb = qs[1]
    res = np.empty(tw, np.uint32)
    nf = tw if fast_f32 else 1
    fI = np.empty((4, nf), np.int64)
    fT = np.empty((2, nf), np.float32)
    acc = np.zeros((tw, c), np.float32)
    for tt in range(ntiles):
        if (tt // ntx) % nw != wk:
            continue
        ty0, tx0, h, w = _tile(tt, ntx, th, tw, nr, wo)
        for rr in range(h):
            r = ty0 + rr
            u = U[r, tx0 : tx0 + w]
            v = V[r, tx0 : tx0 + w]
            ok = valid[r, tx0 : tx0 + w]
            p0 = (r0 + r) * wo + tx0
            for k in range(w):
                acc[k, :] = 0.0
            if fast_u8:
                taps_u8(u, v, w, wi, hi, big, oa, ob, wt)
                gather_u8(p64, tail, big, big_w, shift, lom, oa, ob, qa, qb, w)
                blend_u8(qa, qb, wt, res, w, c)
                store_u8(res, o32, p0, obytes, p0 * c, w, c, spill)
                for k in range(w):
                    if ok[k] == 0:
                        finish_pixel(acc, k, 0, 1, bg, dst, p0 + k, c, co, is_int, maxval, full)
            elif fast_f32:
                taps_f32(u, v, w, wi, hi, fI, fT[0], fT[1])
                blend_f32(fimg, fI, fT[0], fT[1], dst[2], p0 * c, w, c)
                for k in range(w):
                    if ok[k] == 0:
                        finish_pixel(acc, k, 0, 1, bg, dst, p0 + k, c, co, is_int, maxval, full)
            else:
                for k in range(w):
                    cov = 0
                    if ok[k] != 0:
                        acc_sample(img, u[k], v[k], interp, acc, k)
                        cov = 1
                    finish_pixel(acc, k, cov, 1, bg, dst, p0 + k, c, co, is_int, maxval, full)


#: the footprint's probes: the centre, then half a pixel left, right, up and down
_PROBES = ((0.0, 0.0), (-0.5, 0.0), (0.5, 0.0), (0.0, -0.5), (0.0, 0.5))


@njit(**_P)
def grid_footprints(
    kind, gp, faces, codes, params, x, y, kx, ky, w_in, u, v, valid, J, jump, wk, nw
):  # fmt: skip
    """Source points and footprints of grid pixels centred at ``(x, y)``, as
    ``spherewarp.grids.render.footprints`` measures them: the tap-space points
    ``(u, v)`` and validity of the centres, the Jacobian ``J`` (4, n: du/dx, du/dy,
    dv/dx, dv/dy, input pixels per output pixel, from the points half a pixel left,
    right, above and below; the shorter one-sided difference where the two disagree
    by over a factor of 2) and ``jump`` (1 on a jump of the map or the edge of a hole).
    """
    n = x.shape[0]
    f64 = np.empty((5, CHUNK))
    T = f64[0]
    X = f64[1]
    Y = f64[2]
    Z = f64[3]
    G = f64[4]
    ok = np.empty(CHUNK, np.uint8)
    offs = np.empty((2, CHUNK))
    pu = np.empty((5, CHUNK))
    pv = np.empty((5, CHUNK))
    po = np.empty((5, CHUNK), np.uint8)
    ww = float(w_in)
    for ci in range(wk, (n + CHUNK - 1) // CHUNK, nw):
        a = ci * CHUNK
        m = min(CHUNK, n - a)
        for e in range(5):
            offs[0, :] = _PROBES[e][0]
            offs[1, :] = _PROBES[e][1]
            _camera(kind, gp, faces, x[a:], y[a:], offs[0], offs[1], m, X, Y, Z, ok)
            _stages_to_source(codes, params, T, X, Y, Z, G, ok, m, kx, ky, pu[e], pv[e], po[e])
        for k in range(m):
            cu = pu[0, k]
            cv = pv[0, k]
            okc = po[0, k] != 0
            jmp = False
            for axis in range(2):
                lo = 1 + 2 * axis
                hi = lo + 1
                lu = 2.0 * (cu - pu[lo, k])
                lv = 2.0 * (cv - pv[lo, k])
                ru = 2.0 * (pu[hi, k] - cu)
                rv = 2.0 * (pv[hi, k] - cv)
                lu = (lu + ww) % (2.0 * ww) - ww  # round the seam
                ru = (ru + ww) % (2.0 * ww) - ww
                ll = lu * lu + lv * lv
                lr = ru * ru + rv * rv
                near = 4.0 * min(ll, lr) >= max(ll, lr)
                if not near and max(ll, lr) > 4.0:
                    jmp = True
                if okc and not (po[lo, k] != 0 and po[hi, k] != 0):
                    jmp = True
                if near:
                    du = 0.5 * (lu + ru)
                    dv = 0.5 * (lv + rv)
                elif ll <= lr:
                    du = lu
                    dv = lv
                else:
                    du = ru
                    dv = rv
                if not okc:
                    du = 0.0
                    dv = 0.0
                J[axis, a + k] = du
                J[2 + axis, a + k] = dv
            u[a + k] = cu
            v[a + k] = cv
            valid[a + k] = 1 if okc else 0
            jump[a + k] = 1 if (jmp and okc) else 0
