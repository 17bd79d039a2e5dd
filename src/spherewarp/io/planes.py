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

__all__ = ["PLANAR_FORMATS", "PlaneTaps", "PlanarPlan", "RgbPlan", "black_levels", "frame_plan"]

#: pixel formats warped plane by plane (when the encoder writes the same)
PLANAR_FORMATS = ("yuv420p", "yuvj420p", "yuv420p10le")


def plane_kernels() -> Any:
    """:mod:`spherewarp.render._plane_kernels`, its cache dropped first if ``_kernels.py``
    changed since it was compiled (it compiles ``_kernels``' helpers into its code)."""
    import sys

    name = "spherewarp.render._plane_kernels"
    if name not in sys.modules:
        from ..render.plan import _drop_stale_grid_cache

        _drop_stale_grid_cache("_plane_kernels")
    from ..render import _plane_kernels

    return _plane_kernels


def _planes_of(frame: Any) -> list[tuple[Any, int]]:
    """A frame's planes as flat uint8 arrays over its own buffers, with their row pitch."""
    return [(np.frombuffer(p, np.uint8), p.line_size) for p in frame.planes]


def black_levels(pix_fmt: str, color_range: Any = None) -> tuple[int, int]:
    """The luma and chroma values of black in ``pix_fmt`` (limited range unless the format is
    a full-range ``yuvj`` one or ``color_range`` says JPEG/full).

    Examples
    --------
    >>> black_levels("yuv420p"), black_levels("yuvj420p"), black_levels("yuv420p10le")
    ((16, 128), (0, 128), (64, 512))
    """
    shift = 2 if "10" in pix_fmt else 0
    full = pix_fmt.startswith("yuvj") or str(color_range) in ("2", "JPEG", "ColorRange.JPEG")
    return (0 if full else 16 << shift), 128 << shift


class PlaneTaps:
    """A one-tap bilinear render plan as fixed-point taps for 8-bit planes: the pixels of
    :meth:`WarpMap.apply <spherewarp.render.WarpMap.apply>` (bit for bit), read from and
    written into planes with their own row pitch (a decoded frame's buffers), one or two
    planes (U and V) through one table.

    Build with :meth:`of` (None where the plan is not such a plan). The table is made for
    each input row pitch the first time it is seen, from the plan's source coordinates
    band by band (10 bytes a pixel, against a WarpMap's 17).

    Examples
    --------
    >>> from spherewarp.maps import Mobius
    >>> from spherewarp.render import WarpMap
    >>> wm = WarpMap(Mobius.zoom((10, 20), 1.5), (16, 32), antialias="none")
    >>> taps = PlaneTaps.of(wm.plan)
    >>> y = np.random.default_rng(1).integers(0, 256, (16, 32), dtype=np.uint8)
    >>> out = np.empty_like(y)
    >>> taps.apply([y.reshape(-1)], 32, [out.reshape(-1)], 32, background=16)
    >>> bool(np.array_equal(out, wm.apply(y, background=16)[..., 0]))
    True
    """

    def __init__(self, plan: Any) -> None:
        self.plan = plan
        self.in_shape = plan.in_shape
        self.out_shape = plan.out_shape
        self._tables: dict[int, tuple[Any, Any, Any]] = {}
        self._holes: tuple[Any, Any] | None = None

    @classmethod
    def of(cls, plan: Any) -> PlaneTaps | None:
        """The taps of ``plan`` (a :class:`~spherewarp.render.plan.Plan`), or None unless it
        is a one-tap bilinear plan on a compiled path (one a WarpMap caches)."""
        if plan is None or not plan.cacheable or plan.interp != "bilinear":
            return None
        return cls(plan)

    def _table(self, pitch: int) -> tuple[Any, Any, Any]:
        table = self._tables.get(pitch)
        if table is None:
            from ..render import fast

            pk = plane_kernels()
            h, w = self.in_shape
            cols = self.out_shape[1]
            n = self.out_shape[0] * cols
            a, b = np.empty(n, np.int32), np.empty(n, np.int32)
            wt = np.empty(n, np.uint16)
            holes = []
            for r0, r1 in self.plan.bands():
                u, v, ok = self.plan.source(r0, r1)
                s = slice(r0 * cols, r1 * cols)
                args = (u, v, w, h, pitch, a[s], b[s], wt[s])
                fast._run(pk.plane_tap_table, args, self.plan.threads, r1 - r0)
                if self._holes is None:
                    holes.append(r0 * cols + np.flatnonzero(ok.reshape(-1) == 0))
            if self._holes is None:
                flat = np.concatenate(holes)
                self._holes = np.divmod(flat, cols) if flat.size else ()
            table = self._tables[pitch] = (a, b, wt)
        return table

    def apply(
        self,
        src: list[Any],
        pitch: int,
        dst: list[Any],
        dpitch: int,
        *,
        background: int = 0,
        src_offset: int = 0,
        dst_offset: int = 0,
    ) -> None:
        """Warp the planes ``src`` (flat uint8 arrays, rows ``pitch`` bytes apart, the picture
        from byte ``src_offset``) into ``dst`` (the same, ``dpitch``, ``dst_offset``); pixels
        the map leaves undefined get ``background``."""
        from ..render import fast

        pk = plane_kernels()
        a, b, wt = self._table(pitch)
        rows, cols = self.out_shape
        s = [p[src_offset:] for p in src]
        d = [p[dst_offset:] for p in dst]
        s2, d2 = s[-1], d[-1]
        args = (s[0], s2, d[0], d2, pitch, dpitch, rows, cols, a, b, wt, self.in_shape[1], len(src))
        fast._run(pk.plane_taps, args, self.plan.threads, rows)
        if self._holes:
            at = dst_offset + self._holes[0] * dpitch + self._holes[1]
            for d in dst:
                d[at] = background


class PlanarPlan:
    """A frame's warp for its planes: a luma :class:`FramePlan` and a chroma one.

    Build with :meth:`create`; :meth:`apply` takes a decoded ``av.VideoFrame``
    and returns the warped one. Pixels the map leaves undefined are black (luma 16, or 0
    in full range; chroma 128). An 8-bit frame whose maps are cached bilinear ones is
    warped in place by :class:`PlaneTaps` (no copies: from the decoded frame's buffers
    into the new frame's); others through each plane's :meth:`FramePlan.apply`.
    """

    def __init__(self, luma: FramePlan, chroma: FramePlan, pix_fmt: str) -> None:
        self.luma, self.chroma, self.pix_fmt = luma, chroma, pix_fmt
        self.out_shape = luma.out_shape
        self.taps: tuple[PlaneTaps, PlaneTaps] | None = None
        if "10" not in pix_fmt:
            ty, tc = PlaneTaps.of(luma.plan), PlaneTaps.of(chroma.plan)
            if ty is not None and tc is not None:
                self.taps = (ty, tc)

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

        black = black_levels(self.pix_fmt, getattr(frame, "color_range", None))
        oh, ow = self.out_shape
        if self.taps is not None and frame.format.name == self.pix_fmt:
            res = av.VideoFrame(ow, oh, self.pix_fmt)
            self._apply_taps(frame, res, black)
        else:
            res = av.VideoFrame.from_ndarray(self._apply_arrays(frame, black), format=self.pix_fmt)
        for tag in ("colorspace", "color_range", "color_primaries", "color_trc"):
            try:
                setattr(res, tag, getattr(frame, tag))
            except (AttributeError, TypeError, ValueError):
                pass
        return res

    def _apply_taps(self, frame: Any, res: Any, black: tuple[int, int]) -> None:
        src, dst = _planes_of(frame), _planes_of(res)
        for k, (plan, taps) in enumerate(zip((self.luma, self.chroma), self.taps, strict=True)):
            ins, outs = (src[:1], dst[:1]) if k == 0 else (src[1:3], dst[1:3])
            pitch, dpitch = ins[0][1], outs[0][1]
            if any(p != pitch for _, p in ins) or any(p != dpitch for _, p in outs):
                raise ValueError("the U and V planes have different row pitches")
            (eh, ew), (oeh, oew) = plan.eye_in, plan.eye_out
            step_in, step_out = {
                "top-bottom": (eh * pitch, oeh * dpitch),
                "left-right": (ew, oew),
            }.get(plan.stereo, (0, 0))
            for e in range(1 if plan.stereo == "mono" else 2):
                taps.apply(
                    [a for a, _ in ins], pitch, [a for a, _ in outs], dpitch,
                    background=black[k > 0], src_offset=e * step_in, dst_offset=e * step_out,
                )  # fmt: skip

    def _apply_arrays(self, frame: Any, black: tuple[int, int]) -> Any:
        planes = frame.to_ndarray()  # (H * 3/2, W): Y, then U, then V, each row-major
        h, w = frame.height, frame.width
        ch, cw = h // 2, w // 2
        u = planes[h : h + ch // 2].reshape(ch, cw)
        v = planes[h + ch // 2 :].reshape(ch, cw)
        oh, ow = self.out_shape
        out = np.empty((oh * 3 // 2, ow), planes.dtype)
        self.luma.apply(planes[:h], out=out[:oh].reshape(oh, ow, 1), background=black[0])
        # U and V one at a time: an image of two channels is grey and alpha to the renderer
        # (its colour filtered premultiplied by the second), which chroma planes are not
        och = oh // 2
        out[oh : oh + och // 2] = self.chroma.apply(u, background=black[1]).reshape(och // 2, ow)
        out[oh + och // 2 :] = self.chroma.apply(v, background=black[1]).reshape(och // 2, ow)
        return out


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
