"""Warping a video frame's Y, U and V planes as they are, without converting to RGB.

A 4:2:0 frame (``yuv420p``, ``yuvj420p``, ``yuv420p10le``) holds a luma plane
at full size and two chroma planes at half the width and height. A map of the
sphere applies to each plane as to a smaller panorama: :class:`PlanarPlan`
plans it once for the luma size and once for the chroma size (the two chroma
planes sampled together, as one two-channel image) and writes the frame to
encode in the same pixel format. This skips the two colour conversions of the
RGB path (YUV to RGB after decoding, RGB to YUV before encoding), which cost
about as much as the warp itself at 4K, and the rounding they add; the
frame's colour space and range tags are kept.

The chroma samples are warped as centred on their 2x2 luma block; H.264's
default siting puts them half a luma pixel to the left, which a map that
changes across a pixel moves by a fraction of a chroma sample.

Examples
--------
>>> import av
>>> from spherewarp.maps import Mobius
>>> turn = Mobius.from_yaw_pitch_roll(90, 0, 0)
>>> make = lambda shape, out: FramePlan(turn, shape, out_shape=out)
>>> plan = frame_plan(make, (32, 64), "yuv420p", "yuv420p", "rgb24")
>>> type(plan).__name__, plan.chroma.eye_in
('PlanarPlan', (16, 32))
>>> f = av.VideoFrame.from_ndarray(np.arange(48 * 64, dtype=np.uint8).reshape(48, 64) % 200,
...                                format="yuv420p")
>>> g = plan.apply(f).to_ndarray()
>>> bool(np.array_equal(g[:32], np.roll(f.to_ndarray()[:32], -16, axis=1)))  # Y turned
True
>>> type(frame_plan(make, (32, 64), "yuv444p", "yuv420p", "rgb24")).__name__
'RgbPlan'
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from .stereo import FramePlan

__all__ = ["PLANAR_FORMATS", "PlanarPlan", "RgbPlan", "frame_plan"]

#: pixel formats warped plane by plane (when the encoder writes the same)
PLANAR_FORMATS = ("yuv420p", "yuvj420p", "yuv420p10le")


class PlanarPlan:
    """A frame's warp for its planes: a luma :class:`FramePlan` and a chroma one.

    Build with :meth:`create`; :meth:`apply` takes a decoded ``av.VideoFrame``
    and returns the warped one.
    """

    def __init__(self, luma: FramePlan, chroma: FramePlan, pix_fmt: str) -> None:
        self.luma, self.chroma, self.pix_fmt = luma, chroma, pix_fmt
        self.out_shape = luma.out_shape

    @classmethod
    def create(
        cls,
        make: Callable[[tuple[int, int], tuple[int, int] | None], FramePlan | None],
        in_pix: str,
        out_pix: str,
        shape: tuple[int, int],
    ) -> PlanarPlan | None:
        """The planar plan, or None where it does not apply (another pixel format, odd
        sides, an output grid: the RGB path then).

        ``make(plane_shape, eye_out_shape)`` builds the :class:`FramePlan` of a plane
        (None when it cannot); ``eye_out_shape`` None asks for the luma plan's own.
        """
        if in_pix != out_pix or in_pix not in PLANAR_FORMATS:
            return None
        h, w = shape
        if h % 4 or w % 4:
            return None
        luma = make((h, w), None)
        if luma is None or luma.grid is not None:
            return None
        eh, ew = luma.eye_out
        oh, ow = luma.out_shape
        if eh % 2 or ew % 2 or oh % 2 or ow % 2:
            return None
        chroma = make((h // 2, w // 2), (eh // 2, ew // 2))
        if chroma is None:
            return None
        return cls(luma, chroma, in_pix)

    def apply(self, frame: Any) -> Any:
        """The warped frame (same pixel format, colour tags, time)."""
        import av

        planes = frame.to_ndarray()  # (H * 3/2, W): Y, then U, then V, each row-major
        h, w = frame.height, frame.width
        ch, cw = h // 2, w // 2
        u = planes[h : h + ch // 2].reshape(ch, cw)
        v = planes[h + ch // 2 :].reshape(ch, cw)
        oh, ow = self.out_shape
        out = np.empty((oh * 3 // 2, ow), planes.dtype)
        self.luma.apply(planes[:h], out=out[:oh].reshape(oh, ow, 1))
        uv = self.chroma.apply(np.stack([u, v], axis=-1))
        och = oh // 2
        out[oh : oh + och // 2] = uv[..., 0].reshape(och // 2, ow)
        out[oh + och // 2 :] = uv[..., 1].reshape(och // 2, ow)
        res = av.VideoFrame.from_ndarray(out, format=self.pix_fmt)
        for tag in ("colorspace", "color_range", "color_primaries", "color_trc"):
            try:
                setattr(res, tag, getattr(frame, tag))
            except (AttributeError, TypeError, ValueError):
                pass
        return res


class RgbPlan:
    """A frame's warp through RGB (``rgb24``, or ``rgb48le`` for a high bit depth): the
    path for the pixel formats and grids :class:`PlanarPlan` does not take."""

    def __init__(self, plan: FramePlan, rgb: str) -> None:
        self.plan, self.rgb = plan, rgb
        self.out_shape = plan.out_shape

    def apply(self, frame: Any) -> Any:
        """The warped frame, in ``rgb`` (the encoder converts it)."""
        import av

        out = self.plan.apply(frame.to_ndarray(format=self.rgb))
        return av.VideoFrame.from_ndarray(np.ascontiguousarray(out), format=self.rgb)


def frame_plan(
    make: Callable[[tuple[int, int], tuple[int, int] | None], FramePlan],
    shape: tuple[int, int],
    in_pix: str,
    out_pix: str,
    rgb: str,
    planar: bool = True,
) -> PlanarPlan | RgbPlan:
    """The plan of a video frame of ``shape`` decoded as ``in_pix`` and encoded as
    ``out_pix``: plane by plane where it can (``planar``), else through ``rgb``."""
    if planar:
        plan = PlanarPlan.create(make, in_pix, out_pix, shape)
        if plan is not None:
            return plan
    return RgbPlan(make(shape, None), rgb)
