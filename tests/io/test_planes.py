"""Warping 4:2:0 planes as they are against going through RGB."""

from __future__ import annotations

import numpy as np
import pytest

from spherewarp.io.planes import PlanarPlan, RgbPlan, frame_plan
from spherewarp.io.stereo import FramePlan
from spherewarp.io.video import probe, render_video
from spherewarp.maps import Mobius
from videoclip import make_clip

av = pytest.importorskip("av")
ZOOM = Mobius.zoom((0, 0), 2).inverse()


def psnr(a, b, peak=255.0):
    return 10 * np.log10(peak**2 / np.mean((a.astype(np.float64) - b) ** 2))


def decoded(path, fmt="rgb24"):
    with av.open(str(path)) as c:
        return [f.to_ndarray(format=fmt) for f in c.decode(video=0)]


@pytest.mark.parametrize("pix", ["yuv420p", "yuv420p10le"])
def test_planes_and_rgb_give_the_same_video(tmp_path, pix):
    codec = "libx264" if pix == "yuv420p" else "libx265"
    clip = make_clip(tmp_path / "c.mp4", frames=4, audio=False, pix_fmt=pix)
    a, b = tmp_path / "planes.mp4", tmp_path / "rgb.mp4"
    crf = 0 if codec == "libx264" else 4  # x264 0: lossless, so the warps are compared
    render_video(clip, a, lambda t: (ZOOM, {}), codec=codec, crf=crf)
    render_video(clip, b, lambda t: (ZOOM, {}), codec=codec, crf=crf, planar=False)
    assert probe(a).pix_fmt == probe(b).pix_fmt == pix
    fmt, peak = ("rgb48le", 65535.0) if pix != "yuv420p" else ("rgb24", 255.0)
    for x, y in zip(decoded(a, fmt), decoded(b, fmt), strict=True):
        assert psnr(x, y, peak) >= 40


def test_which_path():
    def make(shape, out):
        return FramePlan(ZOOM, shape, out_shape=out)

    assert isinstance(frame_plan(make, (64, 128), "yuv420p", "yuv420p", "rgb24"), PlanarPlan)
    # another format out, a side not a multiple of 4, or planar=False: through RGB
    assert isinstance(frame_plan(make, (64, 128), "yuv420p", "yuv444p", "rgb24"), RgbPlan)
    assert isinstance(frame_plan(make, (66, 132), "yuv420p", "yuv420p", "rgb24"), RgbPlan)
    assert isinstance(frame_plan(make, (64, 128), "yuv420p", "yuv420p", "rgb24", False), RgbPlan)


def test_colour_tags_kept():
    def make(shape, out):
        return FramePlan(ZOOM, shape, out_shape=out)

    plan = frame_plan(make, (32, 64), "yuv420p", "yuv420p", "rgb24")
    f = av.VideoFrame.from_ndarray(np.full((48, 64), 128, np.uint8), format="yuv420p")
    f.color_range = 2  # full range
    assert plan.apply(f).color_range == 2


def test_a_plain_equirect_grid_takes_the_planes_path_at_their_sizes():
    """'project --to equirect' (an unturned panorama grid): the chroma plane's plan is at
    half the luma's size, not the grid's (the planar path crashed on reshaping)."""
    from spherewarp.grids import Equirect

    def make(shape, out):
        return FramePlan(ZOOM, shape, grid=Equirect((32, 64)), out_shape=out)

    plan = frame_plan(make, (32, 64), "yuv420p", "yuv420p", "rgb24")
    assert isinstance(plan, PlanarPlan) and plan.chroma.out_shape == (16, 32)
    f = av.VideoFrame.from_ndarray(np.full((48, 64), 128, np.uint8), format="yuv420p")
    assert plan.apply(f).to_ndarray().shape == (48, 64)
