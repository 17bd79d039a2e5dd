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


# -- PlaneTaps: the compiled warp of 8-bit planes in place -------------------------------------
def _holes(monkeypatch):
    """Make the one-tap plans leave the pixels whose source is left of column 3 undefined
    (no cached map of this library leaves any; undefined pixels must still be black)."""
    from spherewarp.render.plan import Plan

    source = Plan.source

    def holed(self, r0, r1):
        u, v, ok = source(self, r0, r1)
        return u, v, np.where(u < 2.5, 0, ok).astype(np.uint8)

    monkeypatch.setattr(Plan, "source", holed)


MAPS = [
    Mobius.from_yaw_pitch_roll(30, 20, 10),
    Mobius.zoom((10, 20), 1.5),
    Mobius.from_yaw_pitch_roll(0, 90, 0),  # the poles and the seam in every row
    Mobius.from_yaw_pitch_roll(45, 0, 0),  # rows to rows, whole pixels: one tap a pixel
    Mobius.from_yaw_pitch_roll(12.3, 0, 0),  # rows to rows: the lower taps weigh nothing
]


@pytest.mark.parametrize("holes", [False, True])
@pytest.mark.parametrize("shape", [(16, 32), (50, 100)])
def test_plane_taps_equal_warpmap_bit_for_bit(monkeypatch, shape, holes):
    from spherewarp.io.planes import PlaneTaps
    from spherewarp.render import WarpMap

    if holes:
        _holes(monkeypatch)
    rng = np.random.default_rng(0)
    h, w = shape
    for m in MAPS:
        wm = WarpMap(m, shape, antialias="none")
        assert wm.n_special > 0 or not holes
        taps = PlaneTaps.of(wm.plan)
        planes = [rng.integers(0, 256, shape, dtype=np.uint8) for _ in range(2)]
        pitch, dpitch = w + 7, w + 3  # rows padded, as a decoded frame's may be
        src = [np.zeros(h * pitch + 5, np.uint8) for _ in planes]
        for buf, p in zip(src, planes, strict=True):
            buf[: h * pitch].reshape(h, pitch)[:, :w] = p
        dst = [np.full(h * dpitch, 7, np.uint8) for _ in planes]
        taps.apply(src, pitch, dst, dpitch, background=16)
        for out, p in zip(dst, planes, strict=True):
            got = out.reshape(h, dpitch)
            assert np.array_equal(got[:, :w], wm.apply(p, background=16)[..., 0])
            assert np.all(got[:, w:] == 7)  # the padding is left alone


def test_plane_taps_are_taken_only_for_cached_bilinear_plans():
    from spherewarp.io.planes import PlaneTaps
    from spherewarp.render import WarpMap

    turn = Mobius.from_yaw_pitch_roll(30, 0, 0)
    assert PlaneTaps.of(WarpMap(turn, (16, 32)).plan) is not None
    assert PlaneTaps.of(WarpMap(turn, (16, 32), interp="bicubic").plan) is None
    assert PlaneTaps.of(WarpMap(ZOOM, (16, 32)).plan) is None  # the area filter
    assert PlaneTaps.of(None) is None


@pytest.mark.parametrize("stereo", ["mono", "tb", "sbs"])
def test_planes_in_place_equal_planes_through_arrays(stereo):
    turn = Mobius.from_yaw_pitch_roll(30, 20, 0).inverse()

    def make(shape, out):
        return FramePlan(turn, shape, stereo=stereo, out_shape=out, lazy=True)

    shape = {"mono": (32, 64), "tb": (64, 64), "sbs": (32, 128)}[stereo]
    plan = frame_plan(make, shape, "yuv420p", "yuv420p", "rgb24")
    assert isinstance(plan, PlanarPlan) and plan.taps is not None
    h, w = shape
    data = np.random.default_rng(2).integers(0, 256, (h * 3 // 2, w), dtype=np.uint8)
    f = av.VideoFrame.from_ndarray(data, format="yuv420p")
    got = plan.apply(f).to_ndarray()
    assert np.array_equal(got, plan._apply_arrays(f, (16, 128)))


@pytest.mark.parametrize(
    ("pix", "black"),
    [("yuv420p", (16, 128)), ("yuvj420p", (0, 128)), ("yuv420p10le", (64, 512))],
)
def test_undefined_pixels_are_black_not_green(monkeypatch, pix, black):
    _holes(monkeypatch)
    turn = Mobius.from_yaw_pitch_roll(30, 0, 0).inverse()

    def make(shape, out):
        return FramePlan(turn, shape, out_shape=out, lazy=True)

    plan = frame_plan(make, (32, 64), pix, pix, "rgb24")
    assert isinstance(plan, PlanarPlan) and (plan.taps is not None) == (pix != "yuv420p10le")
    dtype = np.uint16 if "10" in pix else np.uint8
    f = av.VideoFrame.from_ndarray(
        np.full((48, 64), 300 if "10" in pix else 200, dtype), format=pix
    )
    out = plan.apply(f).to_ndarray()
    hole = plan.luma.plan.source(0, 32)[2] == 0
    assert hole.any() and not hole.all()
    y, uv = out[:32], out[32:].reshape(2, 16, 32)
    assert np.all(y[hole] == black[0]) and np.all(y[~hole] != black[0])
    chole = plan.chroma.plan.source(0, 16)[2] == 0
    assert chole.any() and np.all(uv[:, chole] == black[1])
