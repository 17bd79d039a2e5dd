"""Cached maps: build once, apply per frame; the same images as warp()."""

from __future__ import annotations

import numpy as np
import pytest

from spherewarp import coords
from spherewarp.errors import InvalidTypeError, InvalidValueError
from spherewarp.maps import Mobius, PullBack, SphereMap
from spherewarp.render import fast, warp
from spherewarp.render.cache import WarpMap


def _image(shape, dtype, seed=0):
    r = np.random.default_rng(seed)
    if np.dtype(dtype).kind == "u":
        return r.integers(0, np.iinfo(dtype).max, shape, dtype=dtype, endpoint=True)
    return r.random(shape).astype(dtype)


def _smooth(h, w, dtype):
    """0.5 + 0.5 xyz: smooth, so that 1/256-pixel weights change values very little."""
    y, x = np.mgrid[0:h, 0:w] + 0.5
    xyz = coords.xyz_from_lonlat(coords.lonlat_from_pixel(np.stack([x, y], -1), w, h))
    img = 0.5 + 0.5 * xyz
    if np.dtype(dtype).kind == "u":
        return np.rint(img * np.iinfo(dtype).max).astype(dtype)
    return img.astype(dtype)


class FrontHalf(SphereMap):
    def pull_cp1(self, zw):
        return np.asarray(zw, dtype=np.complex128)

    def pull(self, zw):
        return PullBack(self.pull_cp1(zw), valid=coords.xyz_from_cp1(zw)[..., 0] >= 0)


class TwoSheets(SphereMap):
    n_sheets = 2

    def pull_cp1(self, zw):
        return np.asarray(zw, dtype=np.complex128)


MAPS = [
    Mobius.from_yaw_pitch_roll(30, 70, 10),
    Mobius.zoom((20, -30), 6).inverse(),
    Mobius.rotation((0, 0), 90) @ Mobius.zoom((0, 0), 0.5),
]


@pytest.mark.parametrize("m", MAPS, ids=["rotation", "zoom", "composite"])
@pytest.mark.parametrize("antialias", ["none", "auto", "adaptive", 2])
@pytest.mark.parametrize("dtype", [np.uint8, np.uint16, np.float32])
def test_apply_is_warp_bit_for_bit(m, antialias, dtype):
    """A cached map and warp() make one plan: the same pixels, to the bit."""
    img = _image((32, 64, 3), dtype)
    for out_shape in [(32, 64), (20, 50)]:
        wm = WarpMap(m, (32, 64), out_shape, antialias=antialias)
        for kw in ({}, {"alpha": True}, {"background": 7}):
            want = warp(img, m, output_shape=out_shape, antialias=antialias, **kw)
            np.testing.assert_array_equal(wm.apply(img, **kw), want)


@pytest.mark.parametrize("m", MAPS, ids=["rotation", "zoom", "composite"])
@pytest.mark.parametrize("dtype", [np.uint8, np.uint16, np.float32])
def test_transparent_images_are_warp_bit_for_bit(m, dtype):
    """Alpha is filtered premultiplied in the still and in cached frames alike."""
    img = _image((32, 64, 4), dtype, seed=5)
    img[:, 10:30, 3] = 0
    gray = np.ascontiguousarray(img[..., 2:])
    for interp in ("bilinear", "bicubic"):
        wm = WarpMap(m, (32, 64), interp=interp)
        for im in (img, gray):
            for kw in ({}, {"background": 7}):
                np.testing.assert_array_equal(wm.apply(im, **kw), warp(im, m, interp=interp, **kw))


@pytest.mark.parametrize("interp", ["nearest", "bicubic"])
def test_other_interpolations_bit_for_bit(interp):
    for dtype in (np.uint8, np.float32):
        img = _smooth(32, 64, dtype)
        for m in MAPS:
            wm = WarpMap(m, (32, 64), interp=interp)
            np.testing.assert_array_equal(wm.apply(img), warp(img, m, interp=interp))


def test_one_tap_plans_are_cached_the_others_run_per_frame():
    rot = WarpMap(MAPS[0], (32, 64))
    assert rot.cached and rot.nbytes == 17 * 32 * 64 and rot.antialias == ("adaptive", 0)
    zoom = WarpMap(MAPS[1], (32, 64))  # the area filter: planned, not cached
    assert not zoom.cached and zoom.nbytes == 0 and zoom.antialias == ("area", 0)
    assert "WarpMap(" in repr(zoom) and "cached=False" in repr(zoom)
    assert WarpMap(MAPS[1], (32, 64), antialias="none").cached == fast.available()


@pytest.mark.parametrize("dtype", [np.uint8, np.float32])
@pytest.mark.parametrize("compiled", [True, False], ids=["compiled", "numpy"])
def test_area_is_rendered_on_the_fly_as_warp(dtype, compiled):
    """``antialias="area"`` is not cached: apply gives warp's image exactly, and the map
    holds nothing; for maps with compiled stages and without (the NumPy-geometry area
    filter)."""
    from spherewarp.maps import Lattes

    img = _image((32, 64, 3), dtype)
    m = Mobius.zoom((20, -30), 6).inverse() if compiled else Lattes((2, 1), method="exact")
    wm = WarpMap(m, (32, 64), (24, 48), antialias="area")
    assert wm.nbytes == 0 and wm.n_special == 0
    want = warp(img, m, antialias="area", output_shape=(24, 48))
    np.testing.assert_array_equal(wm.apply(img), want)
    want = warp(img, m, antialias="area", output_shape=(24, 48), alpha=True)
    np.testing.assert_array_equal(wm.apply(img, alpha=True), want)


@pytest.mark.parametrize("m", MAPS, ids=["rotation", "zoom", "composite"])
def test_float32_cached_taps_match_the_scalar_sampler(m):
    """float32 images go through vectorised cached taps; with an alpha channel added,
    through the scalar sampler: the same values."""
    img = _smooth(32, 64, np.float32)
    wm = WarpMap.build(m, (32, 64))
    np.testing.assert_allclose(wm.apply(img), wm.apply(img, alpha=True)[..., :3], atol=1e-6)


@pytest.mark.parametrize("channels", [1, 2, 3, 4])
def test_exact_turns_and_every_pixel(channels):
    h, w = 16, 32
    img = _image((h, w, channels), np.uint8, seed=channels)
    for k in (0, 3, -5):
        m = Mobius.rotation((0, 90), k * 360 / w)
        wm = WarpMap.build(m, (h, w))
        np.testing.assert_array_equal(wm.apply(img), np.roll(img, -k, axis=1))
        f = img.astype(np.float32)
        np.testing.assert_array_equal(wm.apply(f), warp(f, m))  # float taps: to rounding
        np.testing.assert_allclose(wm.apply(f), np.roll(f, -k, axis=1), atol=1e-9)


@pytest.mark.parametrize("antialias", ["auto", "none"])
def test_special_pixels_holes_background_alpha(antialias):
    img = _image((32, 64, 3), np.uint8)
    wm = WarpMap(FrontHalf(), (32, 64), antialias=antialias)
    for kw in ({}, {"background": (10, 20, 30)}, {"alpha": True}):
        want = warp(img, FrontHalf(), antialias=antialias, **kw)
        np.testing.assert_array_equal(wm.apply(img, **kw), want)
    inv = Mobius.zoom((0, 0), 2)  # a compiled map with a hole: none (its pole is a point)
    wm = WarpMap(inv, (32, 64), antialias="none")
    assert wm.n_special == 0 or wm.cached


def test_out_buffer_is_reused_and_checked():
    img = _image((16, 32, 3), np.uint8)
    wm = WarpMap.build(MAPS[0], (16, 32))
    buf = np.empty((16, 32, 3), np.uint8)
    assert wm.apply(img, out=buf) is buf
    np.testing.assert_array_equal(buf, warp(img, MAPS[0]))
    for bad in (np.empty((16, 32, 4), np.uint8), np.empty((16, 32, 3), np.float32)):
        with pytest.raises(InvalidValueError, match="out"):
            wm.apply(img, out=bad)


def test_bad_inputs():
    with pytest.raises(InvalidTypeError, match="SphereMap"):
        WarpMap.build(lambda z: z, (16, 32))
    with pytest.raises(InvalidValueError, match="one input image"):
        WarpMap.build(TwoSheets(), (16, 32))
    with pytest.raises(InvalidValueError, match="2 x height"):
        WarpMap.build(MAPS[0], (16, 30))
    assert WarpMap.build(MAPS[0], (16, 30), force=True).in_shape == (16, 30)
    with pytest.raises(InvalidValueError, match="in_shape"):
        WarpMap.build(MAPS[0], (0, 32))
    with pytest.raises(InvalidValueError, match="interpolation"):
        WarpMap.build(MAPS[0], (16, 32), interp="lanczos")
    wm = WarpMap.build(MAPS[0], (16, 32))
    with pytest.raises(InvalidValueError, match="32x16"):
        wm.apply(np.zeros((8, 16, 3), np.uint8))
    with pytest.raises(InvalidTypeError):
        wm.apply(np.zeros((16, 32, 3), np.int32))


def test_without_numba_the_plan_runs_per_frame(monkeypatch):
    img = _image((32, 64, 3), np.uint8)
    monkeypatch.setenv("SPHEREWARP_NO_JIT", "1")
    for m in MAPS:
        wm = WarpMap(m, (32, 64))
        assert not wm.cached and wm.plan.path == "reference"
        np.testing.assert_array_equal(wm.apply(img), warp(img, m))


@pytest.mark.parametrize("jit", [True, False])
def test_jumps_are_antialiased_as_in_warp(monkeypatch, jit):
    """A planned Droste map (it jumps at its seams) gives what ``warp`` gives, with and
    without the compiled kernels; the seam pixels are filtered."""
    from spherewarp.maps import Droste

    if not jit:
        monkeypatch.setenv("SPHEREWARP_NO_JIT", "1")
    elif not fast.available():
        pytest.skip("numba is not installed")
    th = -np.pi + 2 * np.pi * np.arange(32) / 32
    m = Droste((20, 10), np.log(0.3) + 0.1 * np.cos(2 * th), 3.0)
    rng = np.random.default_rng(2)
    img = rng.integers(0, 256, (64, 128, 3), dtype=np.uint8)
    got = WarpMap.build(m, (64, 128)).apply(img).astype(int)
    want = warp(img, m).astype(int)
    plain = warp(img, m, antialias="none").astype(int)
    np.testing.assert_array_equal(got, want)
    got = WarpMap(m, (64, 128), antialias="adaptive").apply(img)
    np.testing.assert_array_equal(got, warp(img, m, antialias="adaptive"))
    assert np.mean(np.abs(plain - want).max(-1) > 8) > 0.01  # the seams differ without AA


@pytest.mark.parametrize("name", ["rectilinear", "fisheye", "cubemap", "little-planet", "peirce"])
def test_a_cached_map_knows_grids(name):
    """``WarpMap(map, in_shape, grid=...)``: the still's view, bit for bit (a rotation's
    source coordinates cached; a zoom's plan run per frame)."""
    from spherewarp.grids import make_grid

    img = _image((32, 64, 3), np.uint8)
    g = make_grid(name, (32, 64), look_at=(20, 10))
    for m in (MAPS[0], MAPS[1]):
        for aa in ("auto", "none"):
            wm = WarpMap(m, (32, 64), grid=g, antialias=aa)
            assert wm.out_shape == g.shape and wm.grid is g
            assert wm.cached == wm.plan.cacheable
            assert wm.cached or aa != "none" or not fast.available()
            np.testing.assert_array_equal(wm.apply(img), warp(img, m, grid=g, antialias=aa))
