"""Oracle: run ffmpeg's ``v360`` filter (equirect -> equirect) in-process via PyAV.

Only used by tests.  Import is lazy-safe: importing this module does not import
PyAV; call :func:`have_v360` first (or let :func:`v360` raise ImportError).
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np

_INTERPS = {
    "near",
    "nearest",
    "line",
    "linear",
    "lagrange9",
    "cube",
    "cubic",
    "lanc",
    "lanczos",
    "sp16",
    "spline16",
    "gauss",
    "gaussian",
    "mitchell",
}


def have_v360() -> bool:
    """True when PyAV is importable and its libavfilter provides ``v360``."""
    try:
        import av.filter
    except Exception:  # ImportError, or a broken binary wheel
        return False
    try:
        return "v360" in av.filter.filters_available
    except Exception:
        return False


def v360(
    image: np.ndarray,
    *,
    yaw: float = 0.0,
    pitch: float = 0.0,
    roll: float = 0.0,
    interp: str = "linear",
) -> np.ndarray:
    """Rotate an equirectangular (H, W, 3) uint8 image with ``v360=e:e``.

    Equivalent to ``ffmpeg -vf v360=e:e:yaw=..:pitch=..:roll=..:interp=..``
    (default ``rorder=ypr``).  Angles are in degrees; ffmpeg accepts
    [-180, 180] for each.  Returns a new (H, W, 3) uint8 array.
    See ``_v360_convention.v360_matrix`` for the geometry.
    """
    import av
    import av.filter

    img = np.asarray(image)
    if img.dtype != np.uint8 or img.ndim != 3 or img.shape[2] != 3:
        raise ValueError(f"expected (H, W, 3) uint8, got {img.shape} {img.dtype}")
    if interp not in _INTERPS:
        raise ValueError(f"unknown interp {interp!r}")
    for name, val in (("yaw", yaw), ("pitch", pitch), ("roll", roll)):
        if not -180.0 <= float(val) <= 180.0:
            raise ValueError(f"{name}={val} outside ffmpeg's range [-180, 180]")
    h, w = img.shape[:2]

    frame = av.VideoFrame.from_ndarray(np.ascontiguousarray(img), format="rgb24")
    frame.pts = 0
    frame.time_base = Fraction(1, 25)

    graph = av.filter.Graph()
    src = graph.add_buffer(width=w, height=h, format="rgb24", time_base=Fraction(1, 25))
    # repr() of a float is exact round-trip; ffmpeg parses it with strtod.
    rot = graph.add(
        "v360",
        input="e",
        output="e",
        yaw=repr(float(yaw)),
        pitch=repr(float(pitch)),
        roll=repr(float(roll)),
        interp=interp,
    )
    # Pin the sink to rgb24 so ffmpeg does not negotiate a YUV format for
    # v360 (which would add chroma subsampling + colour conversion).
    fmt = graph.add("format", pix_fmts="rgb24")
    sink = graph.add("buffersink")
    graph.link_nodes(src, rot, fmt, sink)
    graph.configure()

    graph.push(frame)
    out = graph.pull()
    arr = out.to_ndarray(format="rgb24")
    if arr.shape != img.shape:
        raise RuntimeError(f"v360 returned shape {arr.shape}, expected {img.shape}")
    return np.ascontiguousarray(arr)
