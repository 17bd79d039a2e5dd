"""The compiled fast path against the float64 NumPy reference path."""

from __future__ import annotations

import signal
import threading
import time

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.typing import NDArray

from spherewarp import coords
from spherewarp.errors import InvalidValueError
from spherewarp.maps import Mobius, PullBack, SphereMap
from spherewarp.maps.base import Composite
from spherewarp.render import fast, warp

needs_jit = pytest.mark.skipif(not fast.available(), reason="numba is not installed")

#: the issue's precision target: source coordinates within 1/20 pixel, everywhere
TARGET_PX = 1 / 20
#: what the fast path actually reaches on these maps (float64 geometry)
FLOAT64_PX = 1e-6

MAPS = {
    "identity": Mobius.identity(),
    "yaw_pitch_roll": Mobius.from_yaw_pitch_roll(30, 20, 10),
    "poles_to_equator": Mobius.rotation((0, 0), 90),
    "seam_to_front": Mobius.rotation((0, 90), 180),
    "zoom_at_pole": Mobius.zoom((0, 90), 8),
    "zoom8_pulled": Mobius.zoom((30, -20), 8).inverse(),
    "spiral": Mobius.zoom((-120, -35), 1.5 * np.exp(0.8j)),
    "parabolic": Mobius.translation(complex("inf"), 0.5),
    "composite": Mobius.rotation((10, 10), 33) @ Mobius.zoom((40, 20), 3),
}
SHAPES = [((64, 128), (64, 128)), ((50, 100), (37, 75)), ((256, 512), (128, 256))]


def _taps_numpy(
    u: NDArray[np.float64], v: NDArray[np.float64], w_in: int, h_in: int, big: int
) -> tuple[NDArray[np.int32], NDArray[np.int32], NDArray[np.uint16]]:
    """NumPy twin of ``_kernels.taps_u8`` (the oracle of its tests)."""
    xi = np.floor(u * 256.0 + 1024.5).astype(np.int64)
    yi = np.floor(v * 256.0 + 1024.5).astype(np.int64)
    x0 = (xi >> 8) - 4
    y0 = (yi >> 8) - 4
    tx = xi & 255
    ty = yi & 255
    x0 = np.where(x0 < 0, x0 + w_in, x0)
    x0 = np.where(x0 >= w_in, x0 - w_in, x0)
    xs = x0 + w_in // 2
    xs = np.where(xs >= w_in, xs - w_in, xs)
    top = y0 < 0
    bot = y0 + 1 >= h_in
    ya = np.minimum(np.where(top, 0, y0), h_in - 1)
    yb = np.where(bot, h_in - 1, y0 + 1)
    xa = np.where(top, xs, x0)
    xb = np.where(bot, xs, x0)
    ia = ya * w_in + xa
    ib = yb * w_in + xb
    fa = (xa == w_in - 1) | (ia >= big)
    fb = (xb == w_in - 1) | (ib >= big)
    oa = np.where(fa, ia | (1 << 31), ia).astype(np.uint32).view(np.int32)
    ob = np.where(fb, ib | (1 << 31), ib).astype(np.uint32).view(np.int32)
    return oa, ob, (tx | (ty << 8)).astype(np.uint16)


def _pixel_grid(h: int, w: int) -> np.ndarray:
    y, x = np.mgrid[0:h, 0:w] + 0.5
    return np.stack([x, y], axis=-1)


def reference_coords(m: SphereMap, in_shape, out_shape):
    """Source pixel coordinates, source latitude and magnification, float64 NumPy."""
    (h_in, w_in), (h_out, w_out) = in_shape, out_shape
    zw = coords.cp1_from_lonlat(coords.lonlat_from_pixel(_pixel_grid(h_out, w_out), w_out, h_out))
    ll = coords.lonlat_from_cp1(m.pull_cp1(zw))
    px = coords.pixel_from_lonlat(ll, w_in, h_in)
    return px[..., 0], px[..., 1], ll[..., 1], m.local_scale(zw)


def coord_errors(m: SphereMap, in_shape, out_shape) -> tuple[float, float, float]:
    """Max |dx| (wrapped, except within 1e-9 rad of a pole), max |dy|, max relative scale error."""
    spec = fast.kernel_spec(m)
    x, y, s, ok = fast.source_coords(spec, in_shape, out_shape)
    rx, ry, rlat, rs = reference_coords(m, in_shape, out_shape)
    w_in = in_shape[1]
    dx = np.abs((x - rx + w_in / 2) % w_in - w_in / 2)
    at_pole = np.abs(rlat) > np.pi / 2 - 1e-9  # longitude is undefined there
    assert ok.all()
    # initial=0: a map that sends every pixel within 1e-9 rad of a pole (a near-singular
    # matrix) leaves no longitude to compare
    ex = float(np.max(dx[~at_pole], initial=0.0))
    return ex, float(np.abs(y - ry).max()), float(np.abs(s / rs - 1).max())


# -- target 7: precision ---------------------------------------------------------------------------
@needs_jit
@pytest.mark.parametrize("name", MAPS)
@pytest.mark.parametrize(("in_shape", "out_shape"), SHAPES)
def test_source_coordinates_match_reference(name, in_shape, out_shape):
    """Everywhere, seam columns and pole rows included."""
    ex, ey, es = coord_errors(MAPS[name], in_shape, out_shape)
    assert ex <= FLOAT64_PX and ey <= FLOAT64_PX, (ex, ey)
    assert es <= 1e-9, es


@needs_jit
@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(-5, 5), min_size=8, max_size=8))
def test_source_coordinates_random_matrices(entries):
    a = np.array(entries[:4]).reshape(2, 2) + 1j * np.array(entries[4:]).reshape(2, 2)
    try:
        m = Mobius(a)
    except InvalidValueError:
        return
    ex, ey, _ = coord_errors(m, (32, 64), (24, 48))
    assert ex <= TARGET_PX and ey <= TARGET_PX, (ex, ey)


@needs_jit
def test_fixed_point_taps_are_within_target():
    """The uint8 path rounds source coordinates to 1/256 pixel; decode its taps and compare."""
    h, w = 64, 128
    m = MAPS["yaw_pitch_roll"] @ MAPS["zoom_at_pole"]
    x, y, *_ = reference_coords(m, (h, w), (h, w))
    u, v = x - 0.5, y - 0.5
    oa, ob, wt = _taps_numpy(u, v, w, h, h * w)
    ia = (oa & 0x7FFFFFFF).astype(np.int64)
    ya, xa = ia // w, ia % w
    tx, ty = (wt & 255) / 256, (wt >> 8) / 256
    inner = (v >= 0) & (v < h - 1)  # rows that are not folded over a pole
    dx = (xa + tx - u + w / 2) % w - w / 2
    dy = ya + ty - v
    assert np.abs(dx[inner]).max() <= 1 / 512 + 1e-9
    assert np.abs(dy[inner]).max() <= 1 / 512 + 1e-9
    # folded rows: the top tap row is row 0 turned half a turn, the bottom one row H - 1
    top = v < 0
    assert np.all(ya[top] == 0) and np.all((xa[top] - np.floor(u[top] + 1 / 512) - w // 2) % w == 0)


@needs_jit
def test_compiled_taps_equal_numpy_taps():
    rng = np.random.default_rng(1)
    h, w = 16, 32
    u = np.concatenate([rng.uniform(-0.5, w - 0.5, 500), [-0.5, w - 0.5, 0.0, w - 1.0, 3.998]])
    v = np.concatenate([rng.uniform(-0.5, h - 0.5, 500), [-0.5, h - 0.5, 0.0, h - 1.0, 7.002]])
    u, v = u[None, :], v[None, :]
    n = u.size
    got = [np.empty(n, np.int32), np.empty(n, np.int32), np.empty(n, np.uint16)]
    fast._run(fast._kernels().build_taps, (u, v, w, h, h * w - 8, *got), 1, 1)
    want = _taps_numpy(u[0], v[0], w, h, h * w - 8)
    for a, b in zip(got, want, strict=True):
        np.testing.assert_array_equal(a, b)


# -- images: fast against reference ----------------------------------------------------------------
def _image(shape, dtype, seed=0):
    r = np.random.default_rng(seed)
    if np.dtype(dtype).kind == "u":
        return r.integers(0, np.iinfo(dtype).max, shape, dtype=dtype, endpoint=True)
    return r.random(shape).astype(dtype)


TOL = {np.uint8: 1, np.uint16: 1, np.float32: 2e-6, np.float64: 2e-6}


@needs_jit
@pytest.mark.parametrize("dtype", [np.uint8, np.uint16, np.float32])
@pytest.mark.parametrize("interp", ["bilinear", "nearest", "bicubic"])
@pytest.mark.parametrize("antialias", ["none", "auto", 2])
def test_render_matches_reference(dtype, interp, antialias):
    img = _image((24, 48, 3), dtype)
    m = MAPS["poles_to_equator"] @ Mobius.zoom((20, 30), 2.5)
    for shape in [(24, 48), (17, 40), (1, 1)]:
        kw = {"interp": interp, "antialias": antialias, "output_shape": shape}
        a = warp(img, m, method="fast", **kw)
        b = warp(img, m, method="reference", **kw)
        assert a.dtype == b.dtype and a.shape == b.shape
        np.testing.assert_allclose(a.astype(float), b.astype(float), rtol=0, atol=TOL[dtype])


@needs_jit
@pytest.mark.parametrize("channels", [1, 2, 3, 4])
def test_uint8_fast_path_every_channel_count(channels):
    """Two taps a load and overlapping stores: exact on whole-pixel turns, all channel counts."""
    h, w = 32, 64
    img = _image((h, w, channels), np.uint8, seed=channels)
    for k in (0, 1, -3, w // 2):
        out = warp(img, Mobius.rotation((0, 90), k * 360 / w), method="fast")
        np.testing.assert_array_equal(out, np.roll(img, -k, axis=1))
    m = Mobius.from_yaw_pitch_roll(10, 80, 0)  # the poles in view
    for shape in [(h, w), (31, 50), (5, 3), (1, 2), (2, 1)]:
        a = warp(img, m, output_shape=shape, antialias="none", method="fast")
        b = warp(img, m, output_shape=shape, antialias="none", method="reference")
        assert np.abs(a.astype(int) - b).max() <= 1


@needs_jit
@pytest.mark.parametrize("channels", [1, 3, 4])
@pytest.mark.parametrize("antialias", ["none", "auto"])
def test_float32_fast_path_matches_the_scalar_sampler(channels, antialias):
    """float32 bilinear takes vectorised taps (wrapped round the seam, folded over the
    poles); with an alpha channel added it takes the scalar sampler: the same values."""
    from spherewarp.maps import Droste

    img = _image((32, 64, channels), np.float32, seed=channels)
    rho = np.full(16, np.log(np.tan(np.radians(20.0) / 2)))
    for m in (Mobius.from_yaw_pitch_roll(10, 80, 0), Droste((0.0, 0.0), rho, 3.0)):
        for shape in [(32, 64), (31, 50), (5, 3)]:
            a = warp(img, m, output_shape=shape, antialias=antialias, method="fast")
            b = warp(img, m, output_shape=shape, antialias=antialias, method="fast", alpha=True)
            np.testing.assert_allclose(a, b[..., :channels], rtol=0, atol=1e-6)


@needs_jit
def test_taps_stay_inside_the_image_for_nan_and_huge_coordinates():
    """No stage gives such coordinates; the tap functions still read inside the image."""
    k = fast._kernels()
    u = np.array([np.nan, np.inf, -1e300, 5.0, -0.5, 15.5])
    n, w, h = u.size, 16, 8
    idx = np.empty((4, n), np.int64)
    k.taps_f32(u, u[::-1].copy(), n, w, h, idx, np.empty(n, np.float32), np.empty(n, np.float32))
    assert idx.min() >= 0 and idx.max() < w * h
    oa, ob = np.empty(n, np.int32), np.empty(n, np.int32)
    k.taps_u8(u, u[::-1].copy(), n, w, h, w * h, oa, ob, np.empty(n, np.uint16))
    for o in (oa, ob):
        assert np.all((o & 0x7FFFFFFF) < w * h)


@needs_jit
def test_uint8_last_pixel_and_alpha_background():
    img = _image((16, 32, 3), np.uint8)
    # the identity samples every input pixel, the last one (bottom right) too
    np.testing.assert_array_equal(warp(img, Mobius.identity()), img)
    out = warp(img, Mobius.identity(), alpha=True)
    assert out.shape == (16, 32, 4) and np.all(out[..., 3] == 255)
    np.testing.assert_array_equal(out[..., :3], img)


@needs_jit
def test_non_native_byte_order():
    img = _image((16, 32, 3), np.uint16).astype(">u2")
    m = Mobius.zoom((0, 0), 3)
    out = warp(img, m)
    assert out.dtype == np.uint16
    np.testing.assert_array_equal(out, warp(img.astype(np.uint16), m))


class FrontHalf(SphereMap):
    """Identity with a hole on the back half (no compiled stages: the generic path)."""

    def pull_cp1(self, zw):
        return np.asarray(zw, dtype=np.complex128)

    def pull(self, zw):
        return PullBack(self.pull_cp1(zw), valid=coords.xyz_from_cp1(zw)[..., 0] >= 0)


class Squared(SphereMap):
    """z -> z**2 (no compiled stages; has a derivative)."""

    def pull_cp1(self, zw):
        zw = np.asarray(zw, dtype=np.complex128)
        return coords.normalize_cp1(zw**2)

    def local_scale(self, zw):
        z = coords.plane_from_cp1(zw)
        with np.errstate(all="ignore"):
            s = 2 * np.abs(z) * (1 + np.abs(z) ** 2) / (1 + np.abs(z) ** 4)
        return np.where(np.isfinite(s), s, 0.0)


@needs_jit
@pytest.mark.parametrize("dtype", [np.uint8, np.float32])
@pytest.mark.parametrize("antialias", ["none", "auto", 3])
def test_generic_maps_use_compiled_sampling(dtype, antialias):
    img = _image((32, 64, 3), dtype, seed=4)
    assert fast.kernel_spec(Squared()) is None
    for m in (Squared(), FrontHalf()):
        for kw in ({}, {"alpha": True, "background": (0.2, 0.4, 0.6)}):
            a = warp(img, m, antialias=antialias, method="fast", **kw)
            b = warp(img, m, antialias=antialias, method="reference", **kw)
            np.testing.assert_allclose(a.astype(float), b.astype(float), rtol=0, atol=TOL[dtype])


@needs_jit
def test_threads_give_identical_results():
    img = _image((64, 128, 3), np.uint8, seed=5)
    m = Mobius.zoom((10, 10), 6)
    ref = warp(img, m, threads=1)
    for t in (2, 3, 8):
        np.testing.assert_array_equal(warp(img, m, threads=t), ref)
    results = [None] * 4

    def work(i):
        results[i] = warp(img, m, threads=2)

    threads = [threading.Thread(target=work, args=(i,)) for i in range(4)]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    for r in results:
        np.testing.assert_array_equal(r, ref)


def test_a_second_interrupt_while_the_kernels_stop_waits_for_them():
    """Ctrl-C, then Ctrl-C again while the kernels are told to stop: no kernel outlives
    the call (the second interrupt is held back until they have stopped)."""
    stop = threading.Event()
    running = []

    def kernel(wk, nw):
        running.append(wk)
        while not stop.wait(0.01):
            pass
        time.sleep(0.2)  # stopping takes a moment
        running.remove(wk)

    def poll():
        raise KeyboardInterrupt  # the first Ctrl-C

    def cancel():
        stop.set()
        signal.raise_signal(signal.SIGINT)  # the second, as the kernels stop

    with pytest.raises(KeyboardInterrupt):
        fast._run(kernel, (), 2, 2, poll=poll, cancel=cancel)
    assert running == []


@needs_jit
@settings(max_examples=40, deadline=None)
@given(st.lists(st.floats(-5, 5), min_size=8, max_size=8), st.sampled_from(["none", "auto"]))
def test_no_nan_and_in_range(entries, antialias):
    a = np.array(entries[:4]).reshape(2, 2) + 1j * np.array(entries[4:]).reshape(2, 2)
    try:
        m = Mobius(a)
    except InvalidValueError:
        return
    img = _image((8, 16, 3), np.float32)
    out = warp(img, m, antialias=antialias, output_shape=(9, 14))
    assert np.all(np.isfinite(out))
    assert out.min() >= img.min() - 1e-6 and out.max() <= img.max() + 1e-6


# -- specs ---------------------------------------------------------------------------------------
def test_kernel_spec_fuses_mobius_and_rejects_others():
    a, b = Mobius.rotation((10, 20), 30), Mobius.zoom((40, -10), 3)
    spec = fast.kernel_spec(Composite((a, b, Mobius.identity())))
    assert spec is not None and spec.codes.tolist() == [1]
    np.testing.assert_allclose(
        spec.params[0, :16], fast.kernel_spec(a @ b).params[0, :16], rtol=0, atol=1e-12
    )
    assert spec.max_scale == pytest.approx(3.0)
    assert fast.kernel_spec(Mobius.rotation((0, 0), 40)).max_scale == pytest.approx(1.0)
    assert fast.kernel_spec(Composite((a, Squared()))) is None

    class Unknown(Mobius):
        def kernel_stages(self):
            return (("no-such-kind", np.zeros(3)),)

    assert fast.kernel_spec(Unknown(np.eye(2))) is None
    assert Mobius(np.eye(2)).kernel_stages()[0][0] == "mobius"
    assert SphereMap.kernel_stages(Squared()) is None


def test_lorentz_matrix_moves_points_like_the_map():
    m = Mobius([[1 + 0.5j, 0.3], [-0.2j, 0.8]])
    lor = fast.lorentz_from_sl2(m.matrix / np.sqrt(np.linalg.det(m.matrix)))
    xyz = coords.xyz_from_lonlat(np.radians([[10.0, 20.0], [-170.0, -89.0], [0.0, 90.0]]))
    t = lor[0, 0] + xyz @ lor[0, 1:]
    img = (lor[1:, 0] + xyz @ lor[1:, 1:].T) / t[:, None]
    np.testing.assert_allclose(img, m.apply_xyz(xyz), atol=1e-12)
    np.testing.assert_allclose(1 / t, m.local_scale(coords.cp1_from_xyz(xyz)), rtol=1e-12)


# -- without numba ---------------------------------------------------------------------------------
def test_without_numba_the_numpy_path_renders(monkeypatch):
    img = _image((16, 32, 3), np.uint8)
    m = Mobius.zoom((0, 0), 3)
    with_jit = warp(img, m)
    monkeypatch.setenv("SPHEREWARP_NO_JIT", "1")
    assert not fast.available()
    without = warp(img, m)
    assert np.abs(with_jit.astype(int) - without).max() <= 1
    with pytest.raises(InvalidValueError, match="numba"):
        warp(img, m, method="fast")
    with pytest.raises(InvalidValueError, match="fast, reference"):
        warp(img, m, method="quick")
    with pytest.raises(InvalidValueError, match="threads"):
        warp(img, m, threads=0)


@needs_jit
@pytest.mark.parametrize("interp", ["nearest", "bicubic"])
@pytest.mark.parametrize("channels", [1, 2, 3, 4])
def test_uint8_nearest_and_bicubic_loads_are_the_scalar_sampler(interp, channels):
    """The fused kernel's uint8 nearest (a load a pixel) and bicubic (8 loads of two) give
    the scalar sampler's pixels bit for bit (a cached one-tap map samples through it), seam
    and poles included, every channel count; bicubic (fixed point in both) within 1 of the
    float64 reference (nearest may break a tie at a pixel's edge the other way)."""
    from spherewarp.render.cache import WarpMap

    img = _image((32, 64, channels), np.uint8, seed=channels)
    for m in (Mobius.from_yaw_pitch_roll(10, 80, 0), MAPS["seam_to_front"], MAPS["spiral"]):
        for shape in [(32, 64), (31, 50), (5, 3)]:
            kw = {"interp": interp, "antialias": "none", "output_shape": shape}
            a = warp(img, m, **kw)
            np.testing.assert_array_equal(
                a, WarpMap(m, (32, 64), shape, interp=interp, antialias="none").apply(img)
            )
            if interp == "bicubic":
                b = warp(img, m, method="reference", **kw)
                assert np.abs(a.astype(int) - b).max() <= 1


def _keys(t: float) -> np.ndarray:
    """Keys' cubic weights (a = -0.5) of the fraction ``t``, float64."""
    return np.array(
        [
            -0.5 * t * (1 - t) ** 2,
            1 - 2.5 * t**2 + 1.5 * t**3,
            0.5 * t + 2 * t**2 - 1.5 * t**3,
            -0.5 * t**2 * (1 - t),
        ]
    )


@needs_jit
def test_fixed_point_cubic_weights():
    """uint8 bicubic's integer weights (``_cubic_q``): each set sums to exactly
    2**CUBIC_BITS and keeps Keys' first moment (``-w0 + w2 + 2 w3 = q``: linear ramps are
    reproduced), mirrors in ``q <-> 1 - q``, and is within 1.5 / 2**CUBIC_BITS of Keys'
    float64 weights; a weighted sum of 16 pixels fits in int32."""
    k = fast._kernels()
    one = 1 << k.CUBIC_BITS
    W = np.array([k._cubic_q(np.int32(q)) for q in range(one + 1)], np.int64)
    q = np.arange(one + 1)
    np.testing.assert_array_equal(W.sum(1), one)
    np.testing.assert_array_equal(-W[:, 0] + W[:, 2] + 2 * W[:, 3], q)
    np.testing.assert_array_equal(W[::-1, ::-1], W)
    exact = np.array([_keys(t) for t in q / one]) * one
    assert np.abs(W - exact).max() <= 1.5
    assert 255 * np.abs(W).sum(1).max() ** 2 < 2**31


def _cubic_u8_taps(img, u, v):
    """The fused kernel's uint8 bicubic taps (``cubic_u8``) of tap-space ``(u, v)``, and
    the scalar sampler's (``acc_sample``) before rounding; ``(n, c)`` each."""
    k = fast._kernels()
    h, w, c = img.shape
    n = u.size
    p64, tail, big, _ = fast._u8_views(img, np.empty_like(img))
    sc = (np.empty((4, n), np.int32), np.empty((4, n), np.int32), np.empty(n, np.int32),
          np.empty(n, np.int32), np.empty((8, n), np.uint64), np.empty(n, np.uint32),
          np.empty((4, n), np.float32))  # fmt: skip
    res = np.empty(n, np.uint32)
    k.cubic_u8(p64, tail, big, w, h, c, u, v, n, res, sc)
    fused = (res[:, None] >> (8 * np.arange(c, dtype=np.uint32))) & 255
    acc = np.zeros((n, c), np.float32)
    bundle = fast._image_bundle(img)
    for j in range(n):
        k.acc_sample(bundle, u[j], v[j], k.BICUBIC, acc, j)
    return fused, acc


@needs_jit
@pytest.mark.parametrize("channels", [1, 3, 4])
def test_fixed_point_cubic_reproduces_a_linear_ramp(channels):
    """Away from the seam and the poles, uint8 bicubic (fixed point) gives ``a + b x + c y``
    exactly at the coordinates rounded to 1/2**CUBIC_BITS (scalar sampler, before
    rounding), as the float path did up to float error; the fused kernel gives that value
    rounded, half to even."""
    k = fast._kernels()
    h, w = 16, 32
    r = np.random.default_rng(channels)
    yy, xx = np.mgrid[0:h, 0:w]
    b = r.integers(-3, 4, channels)
    cy = r.integers(-2, 3, channels)
    img = (128 + b * xx[..., None] + cy * yy[..., None]).astype(np.uint8)
    u = np.concatenate([r.uniform(1, w - 3, 400), [1.0, w - 3.0, 7.5, 7.5 + 0.5 / 2048]])
    v = np.concatenate([r.uniform(1, h - 3, 400), [1.0, h - 3.0, 3.25, 3.0 - 1.5 / 2048]])
    one = 1 << k.CUBIC_BITS
    uq = np.floor(u * one + 0.5) / one
    vq = np.floor(v * one + 0.5) / one
    want = 128 + b * uq[:, None] + cy * vq[:, None]
    fused, acc = _cubic_u8_taps(img, u, v)
    np.testing.assert_array_equal(acc, want)
    np.testing.assert_array_equal(fused, np.rint(want))


@needs_jit
def test_fixed_point_cubic_fused_taps_are_the_scalar_sampler():
    """``cubic_u8`` and ``acc_sample`` give the same uint8 bicubic values on taps round the
    seam, past the poles, outside the image, NaN and huge (both count as 0)."""
    img = _image((16, 32, 3), np.uint8, seed=5)
    r = np.random.default_rng(5)
    u = np.concatenate([r.uniform(-3, 35, 3000), [np.nan, 1e7, -1e9, 31.9999, -0.5]])
    v = np.concatenate([r.uniform(-3, 19, 3000), [2.0, np.nan, 1e300, -0.0001, 15.5]])
    fused, acc = _cubic_u8_taps(img, u, v)
    np.testing.assert_array_equal(fused, np.clip(np.rint(acc), 0, 255))
    assert fused.min() == 0 and fused.max() == 255  # overshoot clamped


@needs_jit
@pytest.mark.parametrize("method", ["fast", "reference"])
def test_area_takes_one_tap_where_the_footprint_is_tiny(monkeypatch, method):
    """Pixels whose footprint's box is under AREA_ONE_TAP input pixels take the bilinear
    tap of antialias="none" (both paths decide it from the magnification); the others
    keep the area filter."""
    from spherewarp.render import antialias as aa

    img = _image((32, 64, 3), np.float32, seed=3)
    m = Mobius.zoom((0, 0), 6)  # magnifies 6 times round (0, 0)
    monkeypatch.setattr(aa, "AREA_ONE_TAP", 0.5)
    area = warp(img, m, antialias="area", method=method)
    none = warp(img, m, antialias="none", method=method)
    h, w = 32, 64
    x, y, s, ok = fast.source_coords(fast.kernel_spec(m), (h, w), (h, w))
    lat = np.pi / 2 - np.pi * (np.arange(h) + 0.5) / h
    one = aa.one_tap_pixels(s, y - 0.5, ok, lat, (h, w), (h, w))
    assert 0.05 < one.mean() < 0.9
    np.testing.assert_allclose(area[one], none[one], atol=1e-3)
    assert np.abs(area[~one] - none[~one]).max() > 1e-2


@needs_jit
def test_sliver_taps(monkeypatch):
    """The area filter's sliver taps (on by default, ``AREA_SLIVER_BOX = 0``: off): the exp
    variant's footprints near the input's poles as one exact tap each: close to the parts
    they replace, no NaN, and a still equals a WarpMap's frame."""
    from spherewarp.maps.branched import ExpMap
    from spherewarp.render import antialias as aa
    from spherewarp.render.cache import WarpMap

    img = _image((64, 128, 3), np.uint8, seed=5)
    m = ExpMap(4.0)
    assert aa.AREA_SLIVER_BOX == 0.25
    monkeypatch.setattr(aa, "AREA_SLIVER_ROWS", 0.25)  # (0.05: a row or two at this size)
    monkeypatch.setattr(aa, "AREA_SLIVER_BOX", 0.0)
    parts = warp(img, m)
    monkeypatch.setattr(aa, "AREA_SLIVER_BOX", 0.25)
    for dtype in (np.uint8, np.float32):
        im = img.astype(dtype)
        got = warp(im, m)
        assert not np.isnan(got.astype(float)).any()
        np.testing.assert_array_equal(got, WarpMap(m, (64, 128)).apply(im))
    got = warp(img, m).astype(float)
    changed = np.any(got != parts, axis=-1)
    assert changed.any()
    assert np.abs(got - parts)[changed].mean() < 8.0
