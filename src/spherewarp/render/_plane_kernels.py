"""Compiled kernels of :class:`spherewarp.io.planes.PlaneTaps`: a cached one-tap map as
fixed-point bilinear taps, applied to 8-bit video planes (numba).

:func:`plane_tap_table` turns the tap-space source coordinates of a one-tap
render plan (``u, v``: what a :class:`~spherewarp.render.WarpMap` keeps) into,
for every output pixel, the flat index of its top-left tap in the upper row
(``A``) and in the lower row (``B``) of a plane whose rows are ``pitch`` bytes
apart, and the weights ``tx | ty << 8`` in 1/256 pixel: ``_kernels.taps_u8``'s
taps (the uint8 bilinear path of :meth:`WarpMap.apply`), so the pixels are the
same bit for bit. The sign bit of an index marks a tap in the last column,
whose right-hand neighbour is the row's first pixel (the seam); bit 30 of
``A`` marks a pixel whose lower tap is not the row below its upper one (over
a pole): only there is ``B`` read, 6 bytes a pixel elsewhere. As it compiles
``_kernels``' helpers into its code, its cache is dropped when ``_kernels.py``
changes (``plan._drop_stale_grid_cache``).

:func:`plane_taps` samples one or two planes (U and V share a table) through a
table: four byte loads, the 8.8 fixed-point blend of ``_kernels.blend_u8``
(the taps that weigh nothing are not loaded: the lower ones where the map takes
rows to rows, as a turn about the vertical axis does; the right ones too at
whole pixels).
The work is split by output rows: worker ``wk`` of ``nw`` (see ``fast._run``).
Reading the frame's planes in place (their own row pitch) and writing the
output frame's, it needs no copies.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ._kernels import _LOW31, _SEAM, taps_u8

_OPTS = {"cache": True, "nogil": True}
_NO_BIG = 2**31 - 1  # taps_u8's bound of whole-pixel loads: none here, only the seam is marked
_OWN_B = np.int32(1 << 30)  # a flag of A: the lower tap is B's, not A's row below


@njit(**_OPTS)
def plane_tap_table(U, V, w_in, h_in, pitch, A, B, WT, wk, nw):  # noqa: N803
    """Fill ``A, B, WT`` (flat, ``U.size``) from the tap-space ``(U, V)`` (``(rows, cols)``),
    rows of worker ``wk`` of ``nw``: ``taps_u8``'s taps, re-indexed for rows ``pitch`` apart
    (pixels the map leaves undefined get taps too, which the caller overwrites). Where the
    lower tap is not the upper one's row below (over a pole), ``A`` carries :data:`_OWN_B`
    and ``B`` the lower tap; elsewhere ``B`` is not read."""
    rows, cols = U.shape
    W = np.int32(w_in)
    P = np.int32(pitch)
    for r in range(wk * rows // nw, (wk + 1) * rows // nw):
        s = slice(r * cols, (r + 1) * cols)
        a, b = A[s], B[s]
        taps_u8(U[r], V[r], cols, w_in, h_in, _NO_BIG, a, b, WT[s])
        for k in range(cols):
            for t in (a, b):
                i = t[k] & _LOW31  # y * W + x; the sign bit: the seam (x = W - 1)
                if P != W:
                    y = i // W
                    i = y * P + (i - y * W)
                t[k] = i | _SEAM if t[k] < 0 else i
            if b[k] != a[k] + P:  # also where one is on the seam and the other is not
                a[k] |= _OWN_B


@njit(inline="always", **_OPTS)
def _pair(src, a, wrap):
    """The two pixels of tap ``a``: ``a`` and the next, or (the sign bit: the seam) the
    row's first pixel."""
    i = np.uint32(a & _LOW31)
    if a >= 0:
        return np.uint32(src[i]), np.uint32(src[i + np.uint32(1)])
    return np.uint32(src[i]), np.uint32(src[i + np.uint32(1) - wrap])


@njit(inline="always", **_OPTS)
def _blend(src, a, b, wrap, pitch, ux, tx, uy, ty):
    """The blend of taps ``a`` and ``b``; ``a`` without flags: ``b`` is the row below.
    Unsigned indices: no negative-index checks in the loop."""
    if a >= 0 and a < _OWN_B:
        i = np.uint32(a)
        if ty == np.uint32(0):  # the lower taps weigh nothing (a map of rows to rows)
            if tx == np.uint32(0):
                return src[i]  # (p0 * 65536 + 32768) >> 16
            top = np.uint32(src[i]) * ux + np.uint32(src[i + np.uint32(1)]) * tx
            return np.uint8((top * np.uint32(256) + np.uint32(32768)) >> np.uint32(16))
        j = i + pitch
        p0, p1 = np.uint32(src[i]), np.uint32(src[i + np.uint32(1)])
        q0, q1 = np.uint32(src[j]), np.uint32(src[j + np.uint32(1)])
    else:
        if a & _OWN_B == 0:
            b = a + np.int32(pitch)  # the seam bit comes with it
        p0, p1 = _pair(src, a & ~_OWN_B, wrap)
        q0, q1 = _pair(src, b, wrap)
    top = p0 * ux + p1 * tx
    bot = q0 * ux + q1 * tx
    return np.uint8((top * uy + bot * ty + np.uint32(32768)) >> np.uint32(16))


@njit(inline="always", **_OPTS)
def _weights(wt):
    """``tx, ty, 256 - tx, 256 - ty`` of packed weights ``tx | ty << 8``."""
    ww = np.uint32(wt)
    tx = ww & np.uint32(255)
    ty = ww >> np.uint32(8)
    return tx, ty, np.uint32(256) - tx, np.uint32(256) - ty


@njit(**_OPTS)
def plane_taps(
    src1, src2, dst1, dst2, spitch, dpitch, rows, cols, A, B, WT, w_in, nplanes, wk, nw
):  # fmt: skip
    """Sample ``nplanes`` (1 or 2) planes through the table ``A, B, WT`` of ``rows x cols``
    output pixels: plane ``src`` (``spitch`` bytes a row) into ``dst`` (``dpitch``), flat
    uint8 arrays from the picture's first byte; ``w_in`` the input's width (for the seam)."""
    r_a = wk * rows // nw
    r_b = (wk + 1) * rows // nw
    wrap = np.uint32(w_in)
    sp = np.uint32(spitch)
    for r in range(r_a, r_b):
        o = np.uint64(r * dpitch)
        t0 = np.uint64(r * cols)
        if nplanes == 1:
            for k in range(cols):
                i = t0 + np.uint64(k)
                tx, ty, ux, uy = _weights(WT[i])
                a = A[i]
                b = B[i] if a & _OWN_B else a
                dst1[o + np.uint64(k)] = _blend(src1, a, b, wrap, sp, ux, tx, uy, ty)
        else:
            for k in range(cols):
                i = t0 + np.uint64(k)
                tx, ty, ux, uy = _weights(WT[i])
                a = A[i]
                b = B[i] if a & _OWN_B else a
                dst1[o + np.uint64(k)] = _blend(src1, a, b, wrap, sp, ux, tx, uy, ty)
                dst2[o + np.uint64(k)] = _blend(src2, a, b, wrap, sp, ux, tx, uy, ty)
