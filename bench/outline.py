"""An exact outline filter, measured: the bilinear surface integrated over each output
pixel's pulled-back outline by Green's theorem (issue 16, item 7's exp-variant goal).

    python bench/outline.py                    # quality, 1024x512 (about 2 minutes)
    python bench/outline.py --time 4096        # its cost against auto and 4x4, one thread

What it computes. The input's bilinear surface ``B`` is integrated over the polygon whose
corners are the source points of the output pixel's corners, ``int_R B = oint P dv``
with ``P(u, v) = int_0^u B(t, v) dt``. Within a strip between two input rows ``B`` is
``(1 - beta) L_j + beta L_j+1`` (``L_j``: row ``j``'s linear interpolant, ``beta`` the
position across the strip), so along a straight piece of an edge the integral is closed
form in each row's first, second and third antiderivatives (``P``, ``Q``, ``S`` at the
knots, float64), or Simpson's rule (exact for the cubic it is) on a steep piece that
crosses at most one column. The rows are detrended (their mean taken out) so that ``P``
is periodic and an edge's integral does not depend on which copy of the seam it is taken
in; the means come back as ``- oint G(v) du`` with ``G`` the integral of the rows' means
(closing through the north pole costs nothing, through the south pole one whole-image
term). Every edge of the output's corner lattice is integrated once and shared by the two
pixels either side, so a pixel costs one corner pull-back and two edges.

This is the filter that ``bench/README.md`` ("Third round") said the goal needs: its cost
does not grow with a footprint's area. Here it is measured, as a prototype (its pull-backs
in NumPy, its kernels in numba, outside the renderer).
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numba as nb
import numpy as np
from PIL import Image

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))
sys.path.insert(0, str(HERE.parent / "src"))

from bench.maps import exp_map  # noqa: E402
from bench.run import DETAIL, SAMPLE, psnr  # noqa: E402
from spherewarp import coords, warp  # noqa: E402
from spherewarp.render import antialias as _aa  # noqa: E402

_J = {"cache": True, "nogil": True, "fastmath": {"contract", "nsz"}, "error_model": "numpy"}


@nb.njit(**_J)
def build_tables(img, TB, M, GS):
    """``TB[e, i, q, ch]``: at knot ``i`` (``0 .. wi``, pixel centres) of extended row
    ``e`` (0: row 0 half a turn round, as taps fold over the pole; ``1 .. hi``: the rows;
    ``hi + 1``: the last row turned), ``q`` = 0 the detrended sample, 1 ``P``, 2 ``Q``,
    3 ``S``; ``M`` the rows' means, ``GS`` the integral of the means up to each strip."""
    hi, wi, c = img.shape
    half = wi // 2
    for e in range(hi + 2):
        r = 0 if e == 0 else (hi - 1 if e == hi + 1 else e - 1)
        sh = half if (e == 0 or e == hi + 1) else 0
        for ch in range(c):
            s = 0.0
            for i in range(wi):
                s += img[r, i, ch]
            m = s / wi
            M[e, ch] = m
            P = 0.0
            Q = 0.0
            S = 0.0
            ix = sh
            d0 = img[r, ix, ch] - m
            for i in range(wi):
                ix1 = ix + 1 if ix + 1 < wi else 0
                d1 = img[r, ix1, ch] - m
                TB[e, i, 0, ch] = d0
                TB[e, i, 1, ch] = P
                TB[e, i, 2, ch] = Q
                TB[e, i, 3, ch] = S
                sl = d1 - d0
                S += Q + 0.5 * P + d0 / 6.0 + sl / 24.0
                Q += P + 0.5 * d0 + sl / 6.0
                P += d0 + 0.5 * sl
                d0 = d1
                ix = ix1
            TB[e, wi, 0, ch] = d0
            TB[e, wi, 1, ch] = P
            TB[e, wi, 2, ch] = Q
            TB[e, wi, 3, ch] = S
    for ch in range(c):
        GS[0, ch] = -0.5 * M[0, ch]
        for e in range(hi + 1):
            GS[e + 1, ch] = GS[e, ch] + 0.5 * (M[e, ch] + M[e + 1, ch])


@nb.njit(inline="always", **_J)
def _cell(u, wi):
    k = math.floor(u / wi)
    r = u - k * wi
    i = min(max(np.int64(r), 0), wi - 1)
    return k, r, i, r - i


@nb.njit(inline="always", **_J)
def _qs(TB, e, i, f, k, r, wi, ch):
    """``Q`` and ``S`` of extended row ``e`` at ``u = i + f + k wi`` (``r = i + f``)."""
    d0 = TB[e, i, 0, ch]
    sl = TB[e, i + 1, 0, ch] - d0
    P = TB[e, i, 1, ch]
    Q = TB[e, i, 2, ch]
    QW = TB[e, wi, 2, ch]
    q = Q + f * (P + f * (0.5 * d0 + f * (sl / 6.0)))
    s = TB[e, i, 3, ch] + f * (Q + f * (0.5 * P + f * (d0 / 6.0 + f * (sl / 24.0))))
    return q + k * QW, s + k * TB[e, wi, 3, ch] + (k * r + wi * k * (k - 1.0) * 0.5) * QW


@nb.njit(inline="always", **_J)
def _p(TB, e, i, f, ch):
    d0 = TB[e, i, 0, ch]
    return TB[e, i, 1, ch] + f * (d0 + 0.5 * (TB[e, i + 1, 0, ch] - d0) * f)


@nb.njit(inline="always", **_J)
def _pb(TB, e, i, f, b, ch):
    return (1.0 - b) * _p(TB, e, i, f, ch) + b * _p(TB, e + 1, i, f, ch)


@nb.njit(**_J)
def edge(TB, M, GS, u0, v0, u1, v1, wi, hi, c, out):
    """``out[0:c] += int P dv - int G du`` along the chord from ``(u0, v0)`` to ``(u1, v1)``
    (input pixel coordinates, the shorter way round the seam); ``out[c] += - int v du``."""
    du = u1 - u0
    if du > 0.5 * wi:
        du -= wi
    elif du < -0.5 * wi:
        du += wi
    u0 -= 0.5
    v0 -= 0.5
    dv = v1 - 0.5 - v0
    t = 0.0
    while True:
        va = v0 + t * dv
        ua = u0 + t * du
        if dv > 0.0:
            j = np.int64(math.floor(va + 1e-12))
            tn = (j + 1.0 - v0) / dv
        elif dv < 0.0:
            j = np.int64(math.ceil(va - 1e-12)) - 1
            tn = (j - v0) / dv
        else:
            j = np.int64(math.floor(va))
            tn = 1.0
        tn = min(tn, 1.0)
        if tn <= t:
            tn = min(1.0, t + 1e-12)
        j = min(max(j, -1), hi - 1)
        e = j + 1
        vb = v0 + tn * dv
        ub = u0 + tn * du
        ba = va - j
        bb = vb - j
        sdu = ub - ua
        sdv = vb - va
        b1 = 0.5 * (ba + bb)
        b2 = (ba * ba + ba * bb + bb * bb) / 3.0
        out[c] -= sdu * (b1 + j + 0.5)
        for ch in range(c):
            m0 = M[e, ch]
            out[ch] -= sdu * (GS[e, ch] + m0 * b1 + 0.5 * (M[e + 1, ch] - m0) * b2)
        if sdv != 0.0:
            ka, ra, ia, fa = _cell(ua, wi)
            kb, rb, ib, fb = _cell(ub, wi)
            if abs(sdu) >= 1.0:  # closed form in Q and S
                kk = sdv / sdu
                for ch in range(c):
                    qa0, sa0 = _qs(TB, e, ia, fa, ka, ra, wi, ch)
                    qb0, sb0 = _qs(TB, e, ib, fb, kb, rb, wi, ch)
                    qa1, sa1 = _qs(TB, e + 1, ia, fa, ka, ra, wi, ch)
                    qb1, sb1 = _qs(TB, e + 1, ib, fb, kb, rb, wi, ch)
                    out[ch] += kk * ((qb0 - qa0) + (bb * (qb1 - qb0) - ba * (qa1 - qa0))
                                     - kk * ((sb1 - sb0) - (sa1 - sa0)))  # fmt: skip
            elif ia == ib and ka == kb:  # steep, in one cell: Simpson (a cubic)
                fm = 0.5 * (fa + fb)
                for ch in range(c):
                    out[ch] += sdv * (_pb(TB, e, ia, fa, ba, ch) + 4.0 * _pb(TB, e, ia, fm, b1, ch)
                                      + _pb(TB, e, ia, fb, bb, ch)) / 6.0  # fmt: skip
            else:  # steep, across one column: Simpson either side of it
                uc = math.floor(ua) + 1.0 if sdu > 0.0 else math.floor(ua)
                tc = (uc - ua) / sdu
                bc = ba + tc * sdv
                fea = 1.0 if sdu > 0.0 else 0.0
                feb = 1.0 - fea
                bma = 0.5 * (ba + bc)
                bmb = 0.5 * (bc + bb)
                for ch in range(c):
                    f0 = _pb(TB, e, ia, fa, ba, ch)
                    f1 = _pb(TB, e, ia, 0.5 * (fa + fea), bma, ch)
                    f2 = _pb(TB, e, ia, fea, bc, ch)
                    g1 = _pb(TB, e, ib, 0.5 * (fb + feb), bmb, ch)
                    g2 = _pb(TB, e, ib, fb, bb, ch)
                    out[ch] += (tc * sdv) * (f0 + 4.0 * f1 + f2) / 6.0 + (
                        (1.0 - tc) * sdv) * (f2 + 4.0 * g1 + g2) / 6.0  # fmt: skip
        if tn >= 1.0:
            break
        t = tn


@nb.njit(**_J)
def edges_all(TB, M, GS, U, V, wi, hi, EH, EV):
    """Every edge of the corner lattice ``U, V`` (rows x columns of source points):
    ``EH[r, q]`` from corner ``(r, q)`` to ``(r, q + 1)``, ``EV[r, q]`` to ``(r + 1, q)``."""
    R, C = U.shape
    c = TB.shape[3]
    for r in range(R):
        for q in range(C - 1):
            EH[r, q, :] = 0.0
            edge(TB, M, GS, U[r, q], V[r, q], U[r, q + 1], V[r, q + 1], wi, hi, c, EH[r, q])
    for r in range(R - 1):
        for q in range(C):
            EV[r, q, :] = 0.0
            edge(TB, M, GS, U[r, q], V[r, q], U[r + 1, q], V[r + 1, q], wi, hi, c, EV[r, q])


def tables(img: np.ndarray):
    hi, wi, c = img.shape
    TB = np.empty((hi + 2, wi + 1, 4, c))
    M = np.empty((hi + 2, c))
    GS = np.empty((hi + 2, c))
    build_tables(img, TB, M, GS)
    return TB, M, GS


def corners(m, w: int, h: int, wi: int, hi: int):
    """Source points (input pixel coordinates) of the output's ``(h + 1) x (w + 1)`` corners."""
    px = np.stack(np.broadcast_arrays(np.arange(w + 1.0)[None, :], np.arange(h + 1.0)[:, None]), -1)
    zw = coords.cp1_from_lonlat(coords.lonlat_from_pixel(px, w, h))
    src = coords.pixel_from_lonlat(coords.lonlat_from_cp1(m.pull_cp1(zw)), wi, hi)
    return np.ascontiguousarray(src[..., 0] % wi), np.ascontiguousarray(np.clip(src[..., 1], 0, hi))


def outline(img: np.ndarray, m, w: int, h: int, T=None, UV=None):
    """The outline filter's value (float) and footprint area (input pixels) per pixel."""
    hi, wi, c = img.shape
    TB, M, GS = tables(img) if T is None else T
    U, V = corners(m, w, h, wi, hi) if UV is None else UV
    EH = np.empty((h + 1, w, c + 1))
    EV = np.empty((h, w + 1, c + 1))
    edges_all(TB, M, GS, U, V, wi, hi, EH, EV)
    tot = EH[:-1] + EV[:, 1:] - EH[1:] - EV[:, :-1]

    def wrapped(d):
        return (d + wi / 2) % wi - wi / 2

    du_h = wrapped(np.diff(U, axis=1))
    du_v = wrapped(np.diff(U, axis=0))
    turns = np.rint((du_h[:-1] + du_v[:, 1:] - du_h[1:] - du_v[:, :-1]) / wi)
    vmean = 0.25 * (V[:-1, :-1] + V[1:, :-1] + V[:-1, 1:] + V[1:, 1:])
    south = (turns != 0) & (vmean > hi / 2)  # closed through the south pole
    g_end = GS[hi] + 0.5 * (M[hi] + 0.25 * (M[hi + 1] - M[hi]))
    tot[..., :c] += np.where(south[..., None], turns[..., None] * wi * g_end, 0.0)
    tot[..., c] += np.where(south, turns * wi * hi, 0.0)
    area = tot[..., c]
    return tot[..., :c] / np.where(area == 0, 1.0, area)[..., None], np.abs(area)


def on_jumps(m, w: int, h: int, wi: int) -> np.ndarray:
    """The renderer's own jump test (:func:`~spherewarp.render.antialias.jump_mask`)."""
    px = np.stack(np.broadcast_arrays(np.arange(w)[None, :] + 0.5, np.arange(h + 1)[:, None] + 0.5),
                  -1)  # fmt: skip
    px[-1, :, 1] = h - 0.5
    zw = coords.cp1_from_lonlat(coords.lonlat_from_pixel(px, w, h))
    pb = m.pull(zw)
    xyz = coords.xyz_from_cp1(pb.points)
    scale = np.nan_to_num(m.local_scale(zw), nan=1.0, posinf=1e6)
    lat = np.pi / 2 - np.pi * (np.arange(h + 1) + 0.5) / h
    return _aa.jump_mask(xyz, scale, lat, pb.valid, 2 * np.pi / wi, h)


def quality(size=(1024, 512)) -> None:
    path = DETAIL if DETAIL.exists() else SAMPLE
    with Image.open(path) as im:
        img = np.ascontiguousarray(np.asarray(im.convert("RGB").resize(size)))
    w, h = size
    hi, wi = img.shape[:2]
    m = exp_map(4.0)[0]
    ref = warp(img, m, antialias=16)
    auto = warp(img, m, antialias="auto")
    four = warp(img, m, antialias=4)
    T = tables(img)
    one, area = outline(img, m, w, h, T)
    two = outline(img, m, 2 * w, 2 * h, T)[0].reshape(h, 2, w, 2, 3).mean((1, 3))
    jumps = on_jumps(m, w, h, wi)
    print(f"exp variant, {path.name} {w}x{h}, PSNR against 16x16:")
    print(f"  auto {psnr(auto, ref):.2f} dB, 4x4 {psnr(four, ref):.2f} dB")
    print(f"  pixels on a jump (auto's own there): {jumps.mean():.2%}")
    for lo in (0.5, 2.0):
        for big in (64.0, np.inf):
            use = (area > lo) & ~jumps
            val = np.where((area > big)[..., None], two, one)
            out = np.where(use[..., None], np.clip(np.rint(val), 0, 255), auto)
            sub = "" if big == np.inf else f", 2x2 sub-pixels where over {big:g}"
            print(
                f"  outline where the footprint is over {lo:g} input pixels{sub} "
                f"({use.mean():.1%} of the pixels): {psnr(out, ref):.2f} dB"
            )


def cost(width: int) -> None:
    path = DETAIL if DETAIL.exists() else SAMPLE
    w, h = width, width // 2
    with Image.open(path) as im:
        img = np.ascontiguousarray(np.asarray(im.convert("RGB").resize((w, h))))
    m = exp_map(4.0)[0]
    outline(img[:4].copy(), m, 8, 4)  # compile (cached)
    clk = time.process_time
    t0 = clk()
    T = tables(img)
    t1 = clk()
    UV = corners(m, w, h, w, h)
    t2 = clk()
    c = img.shape[2]
    EH = np.empty((h + 1, w, c + 1))
    EV = np.empty((h, w + 1, c + 1))
    edges_all(*T, *UV, w, h, EH, EV)
    t3 = clk()
    del T, EH, EV
    a = {}
    for k in ("none", "auto", 4):
        t = clk()
        warp(img, m, antialias=k, threads=1)
        a[k] = clk() - t
    print(
        f"exp variant {w}x{h}, one thread, CPU seconds: tables {t1 - t0:.2f}, corners (NumPy) "
        f"{t2 - t1:.2f}, edges {t3 - t2:.2f}; the renderer's none {a['none']:.2f}, auto "
        f"{a['auto']:.2f}, 4x4 {a[4]:.2f}"
    )
    print(
        f"  {2 * w * h / 1e6:.1f} M edges: {1e9 * (t3 - t2) / (2 * w * h):.0f} ns an edge; "
        f"tables {(h + 2) * (w + 1) * 4 * 3 * 8 / 2**20:.0f} MiB"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--time", type=int, metavar="WIDTH", help="time it at this width instead")
    a = ap.parse_args()
    cost(a.time) if a.time else quality()


if __name__ == "__main__":
    main()
