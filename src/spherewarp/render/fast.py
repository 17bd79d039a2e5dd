"""The fast renderer: compiled kernels for maps that describe themselves as stages.

A map that can be evaluated inside the compiled kernel says so through
:meth:`~spherewarp.maps.SphereMap.kernel_stages`: a tuple of
``(kind, params)`` pairs in application order (``params`` a float64 array).
:func:`kernel_spec` turns a map (a :class:`~spherewarp.maps.base.Composite`
too) into a :class:`KernelSpec`: consecutive Möbius stages are multiplied
into one, and each Möbius stage becomes a 4x4 Lorentz matrix acting on
homogeneous null vectors ``(t, x, y, z)`` of the sphere, so a Möbius
pull-back costs 16 multiply-adds per pixel and no trigonometry until the
final vector -> pixel step. Maps without stages still get compiled sampling
(:func:`sample_samples`) with their coordinates computed by NumPy.

The kinds, their codes and their parameter layouts are the table of
:mod:`spherewarp.render.stages` (:data:`~spherewarp.render.stages.STAGES`):
:func:`kernel_spec` checks each row there, bounds the magnification from it,
and the stages with jumps are its ``has_jumps`` entries (:data:`JUMP_KINDS`).
That module's docstring says how a new map family adds its compiled kernel.

numba is imported lazily, on the first fast render; without numba (or with
``SPHEREWARP_NO_JIT=1`` in the environment) :func:`available` is False and
the renderer uses its NumPy path. The kernels are compiled once and cached
on disk (``cache=True``), and run on this module's own threads (they release
the GIL), so they are safe to call from several threads at once.
"""

from __future__ import annotations

import math
import os
import platform
import threading
from collections.abc import Callable, Collection
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .. import _signals
from ..maps.base import Composite, SphereMap
from . import antialias as _aa
from . import stages as _st
from .stages import lorentz_from_sl2

__all__ = [
    "JUMP_KINDS",
    "OPT_IN_KINDS",
    "KernelSpec",
    "available",
    "jump_codes",
    "kernel_spec",
    "lorentz_from_sl2",
    "render_spec",
    "sample_samples",
    "source_coords",
]

INTERP_CODES = {"nearest": 0, "bilinear": 1, "bicubic": 2}

#: output tile (rows, columns) of the compiled kernels. Rows of 512 rather than 64: each row of
#: a tile is a chunk that the kernels' helpers are called on, so per-call costs (numba's
#: reference counting of the arrays passed) are spread over 8x the pixels; the pixels do not
#: depend on it (bit for bit). 12-15% less time on a zoom with and without the area filter
#: (2048x1024, one thread, CPU time); nothing measurable on the exp variant
TILE = (8, 512)

_STATE: dict[str, Any] = {}
_UNALIGNED_OK = platform.machine().lower() in ("x86_64", "amd64", "aarch64", "arm64")


def available() -> bool:
    """True when the compiled kernels can be used (numba importable, not disabled).

    Examples
    --------
    >>> isinstance(available(), bool)
    True
    """
    return _kernels() is not None


def _kernels() -> Any:
    if os.environ.get("SPHEREWARP_NO_JIT", "").strip() not in ("", "0"):
        return None
    if "kernels" not in _STATE:
        try:
            from .. import _compile_notice

            _compile_notice.install()  # before the first compilation, if any
            from . import _kernels as k
        except Exception:  # ImportError, or a numba that does not fit this NumPy
            k = None
        _STATE["kernels"] = k
    return _STATE["kernels"]


# -- kernel specs ----------------------------------------------------------------------------------
@dataclass(frozen=True)
class KernelSpec:
    """A map as compiled stages.

    Attributes
    ----------
    codes : ndarray of int64, shape (n,)
        Stage codes (see :mod:`spherewarp.render._kernels`).
    params : ndarray of float64, shape (n, p)
        One parameter row per stage.
    max_scale : float
        An upper bound of the map's magnification (``inf`` if unknown).
    """

    codes: NDArray[np.int64]
    params: NDArray[np.float64]
    max_scale: float


def _stages_of(m: SphereMap) -> list[tuple[str, NDArray[np.float64]]] | None:
    if isinstance(m, Composite):
        out: list[tuple[str, NDArray[np.float64]]] = []
        for part in reversed(m.maps):  # the last map is applied first
            st = _stages_of(part)
            if st is None:
                return None
            out.extend(st)
        return out
    hook: Callable[[], Any] | None = getattr(m, "kernel_stages", None)
    stages = hook() if hook is not None else None
    if stages is None:
        mob = m.as_mobius()
        if mob is None:
            return None
        stages = (("mobius", np.asarray(mob.matrix, np.complex128).view(np.float64).ravel()),)
    return [(str(kind).lower(), np.asarray(p, dtype=np.float64).ravel()) for kind, p in stages]


#: stage kinds whose maps jump between neighbouring pixels (Droste: its seams; exp: the spiral
#: into its essential singularity; Schottky: its disk edges), the table's ``has_jumps``. In
#: ``antialias="auto"`` the compiled renderer looks for jumps in maps with one of these
#: stages (comparing each pixel's source point with its four neighbours', as
#: :func:`spherewarp.render.antialias.jump_mask`) and supersamples the pixels on them; the
#: magnification alone says nothing there.
JUMP_KINDS: frozenset[str] = frozenset(s.name for s in _st.STAGES if s.has_jumps)

#: stage kinds that compile only on request (``kernel_spec(m, opt_in={kind, ...})``), and why.
#: Empty now: every kind has a compiled stage that is used by default.
OPT_IN_KINDS: dict[str, str] = {}


def jump_codes() -> list[int]:
    """Stage codes of :data:`JUMP_KINDS`.

    Examples
    --------
    >>> sorted(jump_codes()) == sorted(_st.BY_NAME[k].code for k in JUMP_KINDS)
    True
    >>> sorted(JUMP_KINDS)
    ['droste', 'exp', 'schottky', 'schottky_mask']
    """
    return [s.code for s in _st.STAGES if s.has_jumps]


def kernel_spec(m: SphereMap, *, opt_in: Collection[str] = ()) -> KernelSpec | None:
    """The map as compiled stages, or None if some part of it has none.

    Maps with a stage in :data:`OPT_IN_KINDS` get None too unless its kind
    is in ``opt_in`` (``"all"`` for every kind).

    Examples
    --------
    >>> from spherewarp.maps import Mobius
    >>> spec = kernel_spec(Mobius.rotation((0, 0), 30) @ Mobius.zoom((10, 20), 3))
    >>> spec.codes.tolist(), round(spec.max_scale, 9)
    ([1], 3.0)
    """
    stages = _stages_of(m)
    if stages is None:
        return None
    fused: list[tuple[_st.Stage, Any]] = []
    for kind, p in stages:
        stage = _st.BY_NAME.get(kind)
        if stage is None or stage.problem(p) is not None:
            return None
        if kind in OPT_IN_KINDS and kind not in opt_in and "all" not in opt_in:
            return None
        if stage is _st.MOBIUS:
            mat = p.view(np.complex128).reshape(2, 2)
            if fused and fused[-1][0] is _st.MOBIUS:
                fused[-1] = (_st.MOBIUS, mat @ fused[-1][1])  # later after earlier
                continue
            fused.append((_st.MOBIUS, mat))
        else:
            fused.append((stage, p))
    rows = [st.kernel_row(p.view(np.float64).ravel()) for st, p in fused]
    width = 16
    for row in rows:
        width = max(width, row.size)
    codes = np.empty(len(fused), np.int64)
    params = np.zeros((len(fused), width))
    max_scale = 1.0
    for s, ((st, _), row) in enumerate(zip(fused, rows, strict=True)):
        codes[s] = st.code
        params[s, : row.size] = row
        max_scale *= st.max_scale(row)
    return KernelSpec(codes, params, float(max_scale))


# -- threads and views -----------------------------------------------------------------------------
def default_threads() -> int:
    """Worker threads used when ``threads=None``: the CPUs this process may run on."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - not Linux
        return max(1, os.cpu_count() or 1)


_POOL: list[Any] = [None, 0, 0]  # executor, its size, the process it belongs to
_POOL_LOCK = threading.Lock()


def _pool(n: int) -> Any:
    from concurrent.futures import ThreadPoolExecutor

    with _POOL_LOCK:
        if _POOL[2] != os.getpid():  # a forked child does not have its parent's threads
            _POOL[:] = [None, 0, os.getpid()]
        if _POOL[1] < n:
            if _POOL[0] is not None:
                _POOL[0].shutdown(wait=False)
            _POOL[0] = ThreadPoolExecutor(max_workers=n, thread_name_prefix="spherewarp")
            _POOL[1] = n
        return _POOL[0]


#: seconds between two looks at the progress counters of a running kernel
PROGRESS_INTERVAL = 0.1


def _run(
    kernel: Callable[..., Any],
    args: tuple[Any, ...],
    threads: int | None,
    items: int,
    poll: Callable[[], None] | None = None,
    cancel: Callable[[], None] | None = None,
) -> None:
    """Run ``kernel(*args, wk, nw)`` for ``nw`` workers on threads (the kernels drop the GIL).

    The shares run on the pool while the calling thread waits in Python, so a
    Ctrl-C (which Python delivers to the main thread only) is seen at once:
    ``cancel()`` then asks the kernels to stop early (where they can), and the
    call waits for them before it raises, so no kernel outlives it. With
    ``poll``, the calling thread calls ``poll()`` every :data:`PROGRESS_INTERVAL`
    seconds until the shares are done (and once more at the end). A second Ctrl-C while
    the kernels stop is held back until they have (:func:`spherewarp._signals.held`).
    """
    from concurrent.futures import FIRST_EXCEPTION, wait

    nw = default_threads() if threads is None else int(threads)
    nw = max(1, min(nw, items))
    futures = [_pool(nw).submit(kernel, *args, wk, nw) for wk in range(nw)]
    try:
        while wait(futures, PROGRESS_INTERVAL, FIRST_EXCEPTION).not_done:
            if any(f.done() and f.exception() is not None for f in futures):
                break
            if poll is not None:
                poll()
    except BaseException:  # poll raised, or Ctrl-C: stop the kernels, then let it through
        with _signals.held():  # a second Ctrl-C waits too: no kernel outlives the call
            if cancel is not None:
                cancel()
            wait(futures)
        raise
    for f in futures:
        f.result()
    if poll is not None:
        poll()


def _native(a: NDArray) -> NDArray:
    """C-contiguous, native byte order (what the kernels are compiled for)."""
    return np.ascontiguousarray(a, dtype=a.dtype.newbyteorder("="))


def _readonly(a: NDArray) -> NDArray:
    v = a.view()
    v.flags.writeable = False
    return v


_SAMPLE_TYPES = (np.uint8, np.uint16, np.float32, np.float64)
_DUMMY_IMAGES = tuple(_readonly(np.zeros((1, 1, 1), t)) for t in _SAMPLE_TYPES)
_DUMMY_FLATS = tuple(np.zeros(1, t) for t in _SAMPLE_TYPES)
_DUMMY_F32 = _readonly(np.zeros(1, np.float32))


def _image_bundle(src: NDArray) -> tuple[Any, ...]:
    """``(u8, u16, f32, f64, code, h, w, c)``: the image in its own slot, dummies elsewhere.

    One compiled kernel then serves every sample type (it picks the slot at
    run time), instead of one compilation per dtype.
    """
    src = _readonly(_native(src))
    code = _SAMPLE_TYPES.index(src.dtype.type)
    slots = list(_DUMMY_IMAGES)
    slots[code] = src
    h, w, c = src.shape
    return (*slots, code, h, w, c)


def _output_bundle(out: NDArray) -> tuple[Any, ...]:
    """``(u8, u16, f32, f64, code)`` with the flat output in its slot."""
    code = _SAMPLE_TYPES.index(out.dtype.type)
    slots = list(_DUMMY_FLATS)
    slots[code] = out.reshape(-1)
    return (*slots, code)


_DUMMY_BYTES = np.zeros(32, np.uint8)
_DUMMY64 = _readonly(np.ndarray((2,), np.uint64, buffer=_DUMMY_BYTES, strides=(1,)))
_DUMMY32 = np.ndarray((2, 2), np.uint32, buffer=np.zeros(32, np.uint8), strides=(1, 0))


def _u8_views(src: NDArray[np.uint8], out: NDArray[np.uint8]) -> tuple[Any, Any, int, Any]:
    """Unaligned views for the two-taps-a-load path (see ``_kernels``)."""
    c = src.shape[2]
    raw = src.reshape(-1)
    n = src.shape[0] * src.shape[1]
    big = (n * c - 8) // c + 1
    p64 = np.ndarray((big,), np.uint64, buffer=raw, strides=(c,))
    rest = n - big
    ntail = max(2, rest)
    tb = np.zeros(ntail * c + 8, np.uint8)
    tb[: rest * c] = raw[big * c :]
    tail = np.ndarray((ntail,), np.uint64, buffer=tb, strides=(c,))
    no = out.shape[0] * out.shape[1]
    o32 = np.ndarray(((no * c - 4) // c + 1, 2), np.uint32, buffer=out.reshape(-1), strides=(c, 0))
    return _readonly(p64), _readonly(tail), big, o32


def _fast_u8_ok(src: NDArray, out: NDArray, interp: str | None) -> bool:
    """Whether the uint8 whole-pixel loads serve ``interp`` (None: any interpolation;
    the fused kernel takes nearest and bicubic through them too)."""
    return (
        _UNALIGNED_OK
        and src.dtype == np.uint8
        and interp in ("bilinear", None)
        and out.shape[2] == src.shape[2]
        and src.size >= 64
        and out.shape[0] * out.shape[1] >= 2
        and out.size >= 4  # one 4-byte store (a 1 x 2 grey output has 2 bytes)
    )


def _value_params(dtype: np.dtype) -> tuple[bool, float, float]:
    if dtype.kind == "u":
        mx = float(np.iinfo(dtype).max)
        return True, mx, mx
    return False, math.inf, 1.0


def _offset_tables(out_shape: tuple[int, int], cap: int) -> NDArray[np.float64]:
    """cos/sin of the column and row offsets of subsample m of n, n <= cap."""
    h, w = out_shape
    tabs = np.zeros((4, cap + 1, cap))
    for n in range(1, cap + 1):
        f = (np.arange(n) + 0.5) / n - 0.5
        ex = 2 * np.pi * f / w
        dy = np.pi * f / h
        tabs[0, n, :n] = np.cos(ex)
        tabs[1, n, :n] = np.sin(ex)
        tabs[2, n, :n] = np.cos(dy)
        tabs[3, n, :n] = np.sin(dy)
    return tabs


def _column_tables(w_out: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    lon = 2 * np.pi * (np.arange(w_out) + 0.5) / w_out - np.pi
    return np.cos(lon), np.sin(lon)


_NO_SLIVERS = (np.zeros((2, 1, 3, 1)), np.full(1, -1, np.int64), 0.0, 0.0)


def _sliver_rows(src: NDArray, area: bool) -> tuple[NDArray, NDArray, float, float]:
    """The prefix sums of the input rows near the poles for the area filter's sliver taps
    (see ``_kernels._slivers``): ``(PQ, index, box)``, ``PQ[0, r, k]`` the sum of the
    first ``k`` pixels of the ``r``-th such row (``k = 0 .. W + 1``, the last past the
    seam), ``PQ[1, r, k]`` the second antiderivative of the row's linear interpolant at
    ``k``, ``index`` the row of ``PQ`` of each input row (or -1), ``box`` and ``bend``
    the limits (:data:`~spherewarp.render.antialias.AREA_SLIVER_BOX`, ``AREA_SLIVER_BEND``)."""
    box = float(_aa.AREA_SLIVER_BOX)
    if not area or box <= 0.0:
        return _NO_SLIVERS
    h, w, _ = src.shape
    cs = np.sin(np.pi * (np.arange(h) + 0.5) / h)
    rows = np.flatnonzero(cs < _aa.AREA_SLIVER_ROWS)
    if rows.size == 0 or w < 2:
        return _NO_SLIVERS
    band = src[rows]
    PQ = np.zeros((2, rows.size, w + 2, src.shape[2]))
    P = PQ[0]
    np.cumsum(band, axis=1, dtype=np.float64, out=P[:, 1 : w + 1])
    P[:, w + 1] = P[:, w] + band[:, 0]
    p = P[:, 1:] - P[:, :-1]  # the samples, p[w] = p[0]
    g = 0.5 * (P[:, :-1] + P[:, 1:] - P[:, 1:2])  # the first antiderivative at the integers
    np.cumsum(g[:, :w] + p[:, :w] / 3.0 + p[:, 1:] / 6.0, axis=1, out=PQ[1][:, 1 : w + 1])
    index = np.full(h, -1, np.int64)
    index[rows] = np.arange(rows.size)
    return PQ, index, box, float(_aa.AREA_SLIVER_BEND)


# -- entry points ----------------------------------------------------------------------------------
def render_spec(
    src: NDArray,
    plan: Any,
    out: NDArray,
    *,
    background: NDArray[np.float32],
    progress: Callable[[int, int], None] | None = None,
    interp: str | None = None,
    aa: tuple[str, int] | None = None,
    threads: int | None = None,
) -> None:
    """Fill ``out`` (``(H, W, C or C+1)``, the input's dtype) with the pull-back of ``src``
    by a render plan (:class:`~spherewarp.render.plan.Plan`, path ``"compiled"``).

    The plan has decided everything: the stages, the interpolation, the resolved
    anti-aliasing, whether a pixel shrinks somewhere, the threads. (A
    :class:`KernelSpec` instead of a plan, with ``interp``, ``aa`` and ``threads``,
    is planned here by :func:`~spherewarp.render.plan.spec_plan`: for benchmarks and
    kernel tests.) With one channel more in ``out`` than in ``src``, the last is
    alpha. ``progress(done, total)``: called from this thread with the tiles finished
    (:data:`TILE`) while the kernel runs, last with ``done == total``.
    """
    if isinstance(plan, KernelSpec):
        from .plan import spec_plan

        plan = spec_plan(
            plan, src.shape[:2], out.shape[:2], interp or "bilinear", aa or ("none", 1), threads
        )
    k = _kernels()
    src = _native(src)
    spec = plan.spec
    interp = plan.interp
    threads = plan.threads
    h_in, w_in, _ = src.shape
    h_out, w_out, _ = out.shape
    kx, ky = w_in / (2 * np.pi), h_in / np.pi
    aa_kx, aa_ky = _aa.footprint_factors((h_in, w_in), (h_out, w_out))
    aa_kx *= _aa.AUTO_DENSITY
    aa_ky *= _aa.AUTO_DENSITY
    tol = float(_aa.AUTO_TOLERANCE)
    mode, n = plan.antialias
    area = mode == "area"
    cap = _aa.AUTO_MAX if mode in ("adaptive", "area") else max(1, n)
    do_aa = not plan.single_tap
    uniform = n if mode == "uniform" else 0
    jumps = plan.jumps
    rho_in = min(math.pi / h_in, 2 * math.pi / w_in)
    # jump pixels get JUMP_SAMPLES per axis whatever the cap: the tables must cover them
    tabs = _offset_tables((h_out, w_out), max(cap, _aa.JUMP_SAMPLES))
    ccos, csin = _column_tables(w_out)
    is_int, maxval, full = _value_params(src.dtype)
    fast = _fast_u8_ok(src, out, None)  # the kernel picks its path by interp
    if fast:
        p64, tail, big, o32 = _u8_views(src, out)
    else:
        p64, tail, big, o32 = _DUMMY64, _DUMMY64, 0, _DUMMY32
    fast_f = src.dtype == np.float32 and interp == "bilinear" and out.shape[2] == src.shape[2]
    fimg = _readonly(src.reshape(-1)) if fast_f else _DUMMY_F32
    th, tw = TILE
    args = (
        _image_bundle(src), p64, tail, big, o32, _output_bundle(out), h_out, w_out, out.shape[2],
        fast, fast_f, fimg, spec.codes, spec.params, ccos, csin, tabs, kx, ky,
        do_aa, aa_kx, aa_ky, tol, cap, uniform, jumps, rho_in, _aa.JUMP_SAMPLES, area,
        float(_aa.AREA_SPLIT), float(_aa.AREA_ONE_TAP), *_sliver_rows(src, area),
        INTERP_CODES[interp], np.asarray(background, np.float32), is_int, maxval, full,
        th, tw,
    )  # fmt: skip
    nw = default_threads() if threads is None else int(threads)
    stride = k.PROGRESS_STRIDE
    prog = np.zeros(max(1, nw) * stride + 1, np.int64)  # + the cancel slot (see render_spec)
    poll = None
    if progress is not None:
        total = -(-h_out // th) * -(-w_out // tw)

        def poll() -> None:
            progress(int(prog[:-1:stride].sum()), total)

        progress(0, total)

    def cancel() -> None:
        prog[-1] = 1

    _run(k.render_spec, (*args, prog), threads, -(-h_out // th), poll, cancel)


def source_coords(
    spec: KernelSpec,
    in_shape: tuple[int, int],
    out_shape: tuple[int, int],
    rows: tuple[int, int] | None = None,
    threads: int | None = None,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.bool_]]:
    """Source pixel coordinates of output pixel centres as the compiled kernel computes them.

    Returns ``(x, y, scale, valid)`` for output rows ``rows`` (default all):
    ``x, y`` in pixel coordinates of the input (centres at half-integers, as
    :func:`spherewarp.coords.pixel_from_lonlat`), the magnification and the
    validity.

    Examples
    --------
    >>> from spherewarp.maps import Mobius
    >>> x, y, s, ok = source_coords(kernel_spec(Mobius.identity()), (4, 8), (4, 8))
    >>> x[0].round(12).tolist(), y[:, 0].round(12).tolist()
    ([0.5, 1.5, 2.5, 3.5, 4.5, 5.5, 6.5, 7.5], [0.5, 1.5, 2.5, 3.5])
    """
    k = _kernels()
    h_in, w_in = in_shape
    h_out, w_out = out_shape
    r0, r1 = rows if rows is not None else (0, h_out)
    u = np.empty((r1 - r0, w_out))
    v = np.empty_like(u)
    scale = np.empty_like(u)
    valid = np.empty(u.shape, np.uint8)
    ccos, csin = _column_tables(w_out)
    args = (
        spec.codes, spec.params, ccos, csin, r0, h_out, w_in / (2 * np.pi), h_in / np.pi,
        u, v, scale, valid,
    )  # fmt: skip
    _run(k.spec_coords, args, threads, r1 - r0)
    return u + 0.5, v + 0.5, scale, valid.astype(bool)


def subsample_coords(
    spec: KernelSpec,
    in_shape: tuple[int, int],
    out_shape: tuple[int, int],
    py: NDArray[np.floating],
    px: NDArray[np.floating],
    oy: NDArray[np.floating],
    ox: NDArray[np.floating],
    threads: int | None = None,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.bool_]]:
    """Tap-space source coordinates of the output points ``(px + ox, py + oy)``."""
    k = _kernels()
    h_in, w_in = in_shape
    h_out, w_out = out_shape
    n = np.size(py)
    u = np.empty(n)
    v = np.empty(n)
    valid = np.empty(n, np.uint8)
    f64 = np.float64
    args = (
        spec.codes, spec.params, h_out, w_out, w_in / (2 * np.pi), h_in / np.pi,
        np.ascontiguousarray(py, f64), np.ascontiguousarray(px, f64),
        np.ascontiguousarray(oy, f64), np.ascontiguousarray(ox, f64), u, v, valid,
    )  # fmt: skip
    _run(k.spec_subsample_coords, args, threads, -(-n // 1024))
    return u, v, valid.astype(bool)


def area_samples(
    src: NDArray,
    u: NDArray[np.float64],
    v: NDArray[np.float64],
    bx: NDArray[np.float64],
    by: NDArray[np.float64],
    valid: NDArray[np.bool_] | None,
    own: NDArray[np.int64],
    n_pixels: int,
) -> tuple[NDArray[np.float32], NDArray[np.int64]]:
    """Compiled area taps of given samples (tap space ``u, v``, boxes ``bx x by`` input
    pixels), summed per pixel: ``(acc, cover)``, the sums of the valid samples of
    each pixel ``own[k]`` (shape ``(n_pixels, C)``) and how many there were."""
    k = _kernels()
    src = _native(src)
    n = len(u)
    keep = np.ones(n, np.uint8) if valid is None else np.ascontiguousarray(valid, np.uint8)
    acc = np.zeros((n_pixels, src.shape[2]), np.float32)
    cover = np.zeros(n_pixels, np.int64)
    f64 = np.float64
    k.area_batch(
        _image_bundle(src), np.ascontiguousarray(u, f64), np.ascontiguousarray(v, f64),
        np.ascontiguousarray(bx, f64), np.ascontiguousarray(by, f64), n, keep,
        np.ascontiguousarray(own, np.int64), acc, cover, np.empty((8, n), np.float32),
        np.empty(n, np.int64), np.empty(n, np.int64),
    )  # fmt: skip
    return acc, cover


def sample_samples(
    src: NDArray,
    u: NDArray[np.float64],
    v: NDArray[np.float64],
    valid: NDArray[np.bool_] | None,
    start: NDArray[np.int64],
    out_flat: NDArray,
    out_channels: int,
    p0: int,
    *,
    interp: str,
    background: NDArray[np.float32],
    threads: int | None = None,
) -> None:
    """Compiled sampling of given coordinates: pixel ``p0 + j`` of ``out_flat``
    gets the mean of samples ``start[j]:start[j + 1]`` (tap space ``u, v``)."""
    k = _kernels()
    is_int, maxval, full = _value_params(src.dtype)
    if valid is None:
        valid = np.ones(np.shape(u), np.uint8)
    args = (
        _image_bundle(src), np.ascontiguousarray(u, np.float64),
        np.ascontiguousarray(v, np.float64), np.ascontiguousarray(valid, np.uint8),
        np.ascontiguousarray(start, np.int64), INTERP_CODES[interp],
        np.asarray(background, np.float32), _output_bundle(out_flat), int(out_channels), int(p0),
        is_int, maxval, full,
    )  # fmt: skip
    _run(k.sample_csr, args, threads, -(-(len(start) - 1) // 256))
