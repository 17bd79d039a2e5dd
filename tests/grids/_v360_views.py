"""Oracle: ffmpeg's ``v360`` from equirect to another projection, in-process via PyAV."""

from __future__ import annotations

from fractions import Fraction

import numpy as np


def v360_view(
    image: np.ndarray, output: str, width: int, height: int, **options: str
) -> np.ndarray:
    """``v360=e:OUTPUT:w=..:h=..`` (plus ``options``, e.g. ``h_fov``) of an (H, W, 3) uint8
    image, bilinear."""
    import av
    import av.filter

    h, w = image.shape[:2]
    frame = av.VideoFrame.from_ndarray(np.ascontiguousarray(image), format="rgb24")
    frame.pts = 0
    frame.time_base = Fraction(1, 25)
    graph = av.filter.Graph()
    src = graph.add_buffer(width=w, height=h, format="rgb24", time_base=Fraction(1, 25))
    node = graph.add(
        "v360", input="e", output=output, w=str(width), h=str(height), interp="linear",
        **{k: str(v) for k, v in options.items()},
    )  # fmt: skip
    fmt = graph.add("format", pix_fmts="rgb24")
    sink = graph.add("buffersink")
    graph.link_nodes(src, node, fmt, sink)
    graph.configure()
    graph.push(frame)
    return np.ascontiguousarray(graph.pull().to_ndarray(format="rgb24"))
