"""Compile the kernels ahead of time: ``python -m spherewarp.render._warmup``.

The compiled kernels (:mod:`spherewarp.render._kernels`) are kept in numba's
on-disk cache. The first render after an install would otherwise compile
them (a few minutes, once); this module renders tiny images through every
kernel entry point so that the cache is filled up front. The package build
(``setup.py``) runs it on the freshly copied package, so a wheel ships the
cache files of the machine that built it and a first ``spherewarp`` command
loads them instead of compiling.

Numba keys its cache by the contents of ``_kernels.py``, its own version,
the Python version and the CPU: on another machine, or with another numba,
the shipped files are not used and the first render compiles as before
(saying so on stderr, see :mod:`spherewarp._compile_notice`). Run
this module once there to compile before the first real command::

    python -m spherewarp.render._warmup

Where the package directory is read-only, numba keeps the cache in its user
cache directory instead (or in ``NUMBA_CACHE_DIR`` when set).
"""

from __future__ import annotations

import sys
import time
from typing import Any, TextIO

import numpy as np

__all__ = [
    "ENTRY_POINTS",
    "GRID_ENTRY_POINTS",
    "PLANE_ENTRY_POINTS",
    "compiled_entry_points",
    "run",
]

#: the kernels of ``_kernels`` that Python calls (the rest are inlined or called from these)
ENTRY_POINTS = (
    "render_spec",  # warp() of every map with compiled stages, every dtype
    "sample_csr",  # warp() of maps without compiled stages
    "area_batch",  # the same with antialias="area"
    "spec_coords",  # fast.source_coords
    "spec_subsample_coords",  # fast.subsample_coords
)
#: the kernels of ``_grid_kernels`` (the render plan's) that Python calls
GRID_ENTRY_POINTS = (
    "grid_source",  # warp() into a grid, maps with compiled stages
    "grid_footprints",  # the same, its pixels' footprints (area, adaptive)
    "grid_xyz",  # the same, maps without
    "xyz_source",  # the Peirce and torus grids
    "spec_rows",  # WarpMap of a one-tap plan
    "sample_taps",  # one-tap plans: WarpMap.apply, warp() into a grid
)
#: the kernels of ``_plane_kernels`` (8-bit video planes warped in place, io.planes.PlaneTaps)
PLANE_ENTRY_POINTS = ("plane_tap_table", "plane_taps")


def compiled_entry_points() -> dict[str, int]:
    """How many compiled (or cache-loaded) signatures each entry point has in this process.

    Examples
    --------
    >>> counts = compiled_entry_points()
    >>> every = ENTRY_POINTS + GRID_ENTRY_POINTS + PLANE_ENTRY_POINTS
    >>> sorted(counts) == sorted(every) or counts == {}
    True
    """
    from . import fast
    from .plan import _grid_kernels

    k = fast._kernels()
    if k is None:
        return {}
    counts = {name: len(getattr(k, name).overloads) for name in ENTRY_POINTS}
    gk = _grid_kernels()
    counts.update({name: len(getattr(gk, name).overloads) for name in GRID_ENTRY_POINTS})
    from ..io.planes import plane_kernels

    pk = plane_kernels()
    counts.update({name: len(getattr(pk, name).overloads) for name in PLANE_ENTRY_POINTS})
    return counts


def _images() -> list[np.ndarray]:
    rng = np.random.default_rng(0)
    u8 = rng.integers(0, 256, (8, 16, 3), dtype=np.uint8)
    return [
        u8,
        (u8[..., :2].astype(np.uint16) * 257),  # grey + alpha, 16 bits
        rng.random((8, 16, 4), dtype=np.float32),
    ]


def _steps() -> list[tuple[str, Any]]:
    """(what, callable) pairs, each taking one kernel path on tiny inputs."""
    from ..maps import Mobius
    from . import fast
    from .cache import WarpMap
    from .warp import warp

    rot = Mobius.from_yaw_pitch_roll(30.0, 20.0, 10.0)
    zoom = Mobius.zoom((0.0, 0.0), 3.0)
    steps: list[tuple[str, Any]] = []
    for img in _images():
        steps.append((f"render_spec {img.dtype}", lambda img=img: warp(img, rot, threads=1)))
        steps.append((f"render_spec {img.dtype} area", lambda img=img: warp(img, zoom, threads=1)))

    def by_samples(img: np.ndarray, area: bool) -> None:
        n = 4
        u = np.linspace(0.0, img.shape[1] - 1.0, n)
        v = np.linspace(0.0, img.shape[0] - 1.0, n)
        bg = np.zeros(img.shape[2], np.float32)
        if area:
            box = np.full(n, 1.5)
            fast.area_samples(img, u, v, box, box, None, np.arange(n), n)
        else:
            out = np.empty((n, img.shape[2]), img.dtype)
            start = np.arange(n + 1, dtype=np.int64)
            fast.sample_samples(
                img, u, v, None, start, out, img.shape[2], 0, interp="bilinear", background=bg,
                threads=1,
            )  # fmt: skip

    def cached(img: np.ndarray) -> None:
        for m in (rot, zoom):
            wm = WarpMap(m, img.shape[:2], threads=1)
            wm.apply(img, threads=1)

    def grids(img: np.ndarray) -> None:
        from ..grids import make_grid
        from ..maps import ExpressionMap

        for name in ("rectilinear", "peirce"):
            g = make_grid(name, img.shape[:2])
            for m in (rot, zoom, ExpressionMap("z + 0.5")):
                warp(img, m, grid=g, antialias="none", threads=1)
                warp(img, m, grid=g, antialias="area", threads=1)

    def coords() -> None:
        spec = fast.kernel_spec(zoom)
        fast.source_coords(spec, (8, 16), (8, 16), threads=1)
        one = np.ones(1)
        fast.subsample_coords(spec, (8, 16), (8, 16), one, one, one * 0.5, one * 0.5, threads=1)

    def planes() -> None:
        from ..io.planes import PlaneTaps

        wm = WarpMap(rot, (8, 16), threads=1)
        taps = PlaneTaps.of(wm.plan)
        y = _images()[0][..., 0].reshape(-1).copy()
        out = np.empty_like(y)
        taps.apply([y], 16, [out], 16)  # luma
        taps.apply([y, y], 16, [out, out.copy()], 16)  # U and V together

    steps.append(("spec_coords", coords))
    steps.append(("video planes uint8", planes))
    for img in _images():
        steps.append((f"sample_csr {img.dtype}", lambda img=img: by_samples(img, False)))
        steps.append((f"area_batch {img.dtype}", lambda img=img: by_samples(img, True)))
        steps.append((f"WarpMap {img.dtype}", lambda img=img: cached(img)))
        steps.append((f"grids {img.dtype}", lambda img=img: grids(img)))
    return steps


def run(stream: TextIO | None = None) -> dict[str, int]:
    """Take every kernel path once on tiny images, compiling what the cache lacks.

    Parameters
    ----------
    stream : text file, optional
        Where to write one line per step with its time (default: nothing).

    Returns
    -------
    dict
        :func:`compiled_entry_points` afterwards (empty without numba).

    Examples
    --------
    >>> counts = run()  # loads the cache; compiles only what it lacks
    >>> all(n >= 1 for n in counts.values())
    True
    """
    from . import fast

    if not fast.available():
        if stream is not None:
            print("spherewarp: numba is not available; nothing to compile", file=stream)
        return {}
    t_all = time.perf_counter()
    for what, step in _steps():
        t0 = time.perf_counter()
        step()
        if stream is not None:
            print(f"  {what}: {time.perf_counter() - t0:.1f} s", file=stream, flush=True)
    counts = compiled_entry_points()
    if stream is not None:
        print(f"spherewarp: kernels ready in {time.perf_counter() - t_all:.1f} s", file=stream)
    return counts


def main() -> int:
    """``python -m spherewarp.render._warmup``: compile (or load) every kernel once."""
    print("spherewarp: loading the kernels, compiling what the cache lacks ...", file=sys.stderr)
    counts = run(sys.stderr)
    if not counts:  # no numba here (or SPHEREWARP_NO_JIT): nothing was compiled
        return 1
    missing = [name for name, n in counts.items() if n == 0]
    if missing:
        print(f"spherewarp: not compiled: {', '.join(missing)}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
