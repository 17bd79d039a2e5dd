"""Adaptive anti-aliasing: supersample where the map shrinks, and only there."""

from __future__ import annotations

import numpy as np
import pytest

from spherewarp import coords
from spherewarp.errors import InvalidValueError
from spherewarp.maps import Mobius, PullBack, SphereMap
from spherewarp.render import antialias as aa
from spherewarp.render import warp


def _grid_latlon(h: int, w: int) -> tuple[np.ndarray, np.ndarray]:
    y, x = np.mgrid[0:h, 0:w] + 0.5
    ll = coords.lonlat_from_pixel(np.stack([x, y], -1), w, h)
    return ll, coords.cp1_from_lonlat(ll)


def _stripes(h: int, w: int) -> np.ndarray:
    """Fine detail everywhere: one-pixel stripes in both directions (uint8 RGB)."""
    y, x = np.mgrid[0:h, 0:w]
    v = ((x + y) % 2 * 170 + (x // 2 % 2) * 85).astype(np.uint8)
    return np.repeat(v[..., None], 3, axis=-1)


def test_parse_antialias():
    assert aa.parse_antialias("Auto") == ("auto", 0)
    assert aa.parse_antialias(" none ") == ("none", 1)
    assert aa.parse_antialias(1) == ("none", 1)
    assert aa.parse_antialias(np.int64(5)) == ("uniform", 5)
    assert aa.parse_antialias("auto", supersample=3) == ("uniform", 3)
    assert aa.parse_antialias("none", supersample=1) == ("none", 1)
    for bad in ("fast", 0, 33, 1.5, True, "-2"):
        with pytest.raises(InvalidValueError, match="antialias"):
            aa.parse_antialias(bad)
    for bad in (0, 33, True, 2.0):
        with pytest.raises(InvalidValueError, match="supersample"):
            aa.parse_antialias("auto", supersample=bad)
    img = np.zeros((8, 16, 3), np.uint8)
    with pytest.raises(InvalidValueError, match="antialias"):
        warp(img, Mobius.identity(), antialias="lots")


def test_footprint_counts():
    kx, ky = aa.footprint_factors((512, 1024), (512, 1024))
    assert (kx, ky) == pytest.approx((1.0, 1.0))
    # an input pixel is 2 pi / 300 wide; output pixels are 2 pi / 100 wide and pi / 50 high
    assert aa.footprint_factors((100, 300), (50, 100)) == pytest.approx((3.0, 3.0))
    lat = np.radians([0.0, 0.0, 0.0, 60.0, 89.0, 0.0])
    s = np.array([1.0, 1.2, 2.0, 3.0, 3.0, 100.0])
    nx, ny = aa.sample_counts(s, lat, (kx, ky), tol=0.25, cap=8)
    assert nx.tolist() == [1, 1, 2, 2, 1, 8]
    assert ny.tolist() == [1, 1, 2, 3, 3, 8]


def test_subsample_offsets_are_grids():
    owner, ox, oy = aa.subsample_offsets(np.array([2, 1, 3]), np.array([2, 1, 1]))
    assert owner.tolist() == [0, 0, 0, 0, 1, 2, 2, 2]
    np.testing.assert_allclose(ox, [0.25, 0.75, 0.25, 0.75, 0.5, 1 / 6, 0.5, 5 / 6])
    np.testing.assert_allclose(oy, [0.25, 0.25, 0.75, 0.75, 0.5, 0.5, 0.5, 0.5])


@pytest.mark.parametrize("method", ["fast", "reference"])
def test_rotation_is_never_supersampled(method):
    """Nothing shrinks under a rotation: 'auto' is exactly 'none' (and costs nothing more)."""
    from spherewarp.render import fast

    if method == "fast" and not fast.available():
        pytest.skip("numba is not installed")
    img = _stripes(32, 64)
    for m in (Mobius.from_yaw_pitch_roll(30, 20, 10), Mobius.rotation((0, 0), 90)):
        a = warp(img, m, antialias="auto", method=method)
        b = warp(img, m, antialias="none", method=method)
        np.testing.assert_array_equal(a, b)
    _, zw = _grid_latlon(32, 64)
    s = Mobius.from_yaw_pitch_roll(30, 20, 10).local_scale(zw)
    ll, _ = _grid_latlon(32, 64)
    nx, ny = aa.sample_counts(s, ll[..., 1], (1.0, 1.0))
    assert np.all(nx * ny == 1)


def test_downscale_is_a_box_filter():
    """Output half the size: each pixel covers 2x2 input pixels; adaptive takes 2x2 samples,
    and auto (the area filter, a downscale shrinks) averages the bilinear surface over them."""
    img = _stripes(32, 64).astype(np.float32)
    out = warp(img, Mobius.identity(), output_shape=(16, 32), antialias="adaptive")
    np.testing.assert_array_equal(
        out, warp(img, Mobius.identity(), output_shape=(16, 32), antialias=2)
    )
    box = img.reshape(16, 2, 32, 2, 3).mean(axis=(1, 3))
    np.testing.assert_allclose(out, box, atol=1e-4)
    auto = warp(img, Mobius.identity(), output_shape=(16, 32))
    np.testing.assert_array_equal(
        auto, warp(img, Mobius.identity(), output_shape=(16, 32), antialias="area")
    )
    # the bilinear surface over each 2x2 box: what heavy supersampling converges to
    dense = warp(img, Mobius.identity(), output_shape=(16, 32), antialias=16)
    np.testing.assert_allclose(auto, dense, atol=0.02)


def test_zoom_aliasing_is_removed_where_the_map_shrinks():
    """Against a 12x12 reference: auto is far better than one sample where pixels shrink,
    with a fraction of the samples of uniform 4x4 (counted, not timed)."""
    h, w = 64, 128
    img = _stripes(h, w)
    m = Mobius.zoom((0, 0), 6).inverse()
    ref = warp(img, m, antialias=12).astype(float)
    ll, zw = _grid_latlon(h, w)
    s = m.local_scale(zw)
    shrink = s > 1.5

    def err(a):
        return np.sqrt(np.mean((a.astype(float) - ref)[shrink] ** 2))

    none, adaptive, u4 = (warp(img, m, antialias=a) for a in ("none", "adaptive", 4))
    assert err(adaptive) < 0.4 * err(none)
    assert err(adaptive) < 2.5 * err(u4)
    nx, ny = aa.sample_counts(s, ll[..., 1], aa.footprint_factors((h, w), (h, w)))
    assert (nx * ny).mean() <= 16 / 4
    # where the map magnifies, adaptive takes the same single sample as none
    np.testing.assert_array_equal(adaptive[s < 1.0], none[s < 1.0])
    # auto is the area filter here: over the whole image nearly as close to the reference
    # as 4x4 (1.2 dB behind on this small uint8 image; ahead of it in bench/aa_profile.py)
    auto = warp(img, m)
    np.testing.assert_array_equal(auto, warp(img, m, antialias="area"))
    rms = {k: np.sqrt(np.mean((a - ref) ** 2)) for k, a in (("auto", auto), ("4", u4))}
    assert rms["auto"] < 1.25 * rms["4"]


@pytest.mark.parametrize("antialias", ["auto", "adaptive", "area"])
def test_reference_and_fast_paths_agree(antialias):
    img = _stripes(32, 64)
    m = Mobius.zoom((30, 10), 5)
    a = warp(img, m, method="reference", antialias=antialias)
    b = warp(img, m, antialias=antialias)
    assert np.abs(a.astype(int) - b).max() <= 1


class HalfTurnedBack(SphereMap):
    """The identity on the front half, a quarter turn about the zenith on the back: a jump."""

    def pull_cp1(self, zw):
        zw = np.asarray(zw, dtype=np.complex128)
        back = coords.xyz_from_cp1(zw)[..., 0] < 0
        turned = Mobius.rotation((0, 90), 90).pull_cp1(zw)
        return np.where(back[..., None], turned, zw)

    def local_scale(self, zw):
        return np.ones(np.shape(zw)[:-1])


def test_jumps_are_supersampled():
    h, w = 32, 64
    img = _stripes(h, w)
    m = HalfTurnedBack()
    auto = warp(img, m, method="reference")
    none = warp(img, m, antialias="none", method="reference")
    diff = np.any(auto != none, axis=-1)
    ll, _ = _grid_latlon(h, w)
    lon = np.degrees(ll[..., 0])
    near_jump = np.minimum(np.abs(np.abs(lon) - 90), 180) < 360 / w * 1.5
    assert diff.any() and np.all(~diff | near_jump)
    np.testing.assert_array_equal(auto[~near_jump], none[~near_jump])


def test_jump_mask_finds_a_jump_in_a_column():
    lon = np.linspace(-np.pi, np.pi, 16, endpoint=False)
    rows = [np.stack([np.cos(lon) * np.cos(a), np.sin(lon) * np.cos(a), np.sin(a) + 0 * lon], -1)
            for a in (0.1, 0.0, -0.1, -0.2)]  # fmt: skip
    xyz = np.array(rows)
    xyz[2:, 5] = (0.0, 0.0, -1.0)  # rows 2 and 3 of column 5 jump to the nadir
    m = aa.jump_mask(xyz, np.ones((4, 16)), np.array([0.1, 0.0, -0.1, -0.2]), None, 0.01, 32)
    assert m.shape == (3, 16)
    assert m[1, 5] and m[2, 5] and m[2, 4] and m[2, 6]
    assert not m[0].any()


# -- antialias="area" --------------------------------------------------------------------------
needs_jit = pytest.mark.skipif(
    not __import__("spherewarp.render.fast", fromlist=["available"]).available(),
    reason="numba is not installed",
)


def _psnr(a: np.ndarray, ref: np.ndarray) -> float:
    mse = np.mean((a.astype(np.float64) - ref.astype(np.float64)) ** 2)
    return float(10 * np.log10(255.0**2 / mse))


@needs_jit
def test_area_of_the_identity_is_the_one_pixel_box():
    """Through the identity every footprint is one input pixel square, so the area
    filter is the bilinear surface averaged over one pixel: ``[1/8, 3/4, 1/8]`` on
    each axis, wrapping round the seam and folding over the poles."""
    rng = np.random.default_rng(4)
    img = rng.uniform(0, 1, (32, 64, 3)).astype(np.float32)
    got = warp(img, Mobius.identity(), antialias="area")
    k = (0.125, 0.75, 0.125)
    rows = np.concatenate([np.roll(img[:1], 32, axis=1), img, np.roll(img[-1:], 32, axis=1)])
    ver = k[0] * rows[:-2] + k[1] * rows[1:-1] + k[2] * rows[2:]
    want = k[0] * np.roll(ver, 1, axis=1) + k[1] * ver + k[2] * np.roll(ver, -1, axis=1)
    np.testing.assert_allclose(got, want, atol=2e-6)


@needs_jit
@pytest.mark.parametrize(
    "m", [Mobius.zoom((20.0, 10.0), 4.0).inverse(), Mobius.from_yaw_pitch_roll(30, 20, 10)]
)
def test_area_matches_heavy_supersampling(m):
    """Against 12 x 12 supersampling of a photograph, the area filter does as well as
    4 x 4 (to 0.5 dB) and far better than one bilinear tap."""
    from spherewarp.demo import sample_path
    from spherewarp.io import read_image

    img = np.ascontiguousarray(read_image(sample_path()).pixels[::4, ::4])  # 128 x 256
    ref = warp(img, m, antialias=12)
    area = _psnr(warp(img, m, antialias="area"), ref)
    assert area >= _psnr(warp(img, m, antialias=4), ref) - 0.5
    assert area >= _psnr(warp(img, m, antialias="none"), ref) + 10.0


@needs_jit
def test_area_follows_the_map_inside_large_footprints():
    """A Droste map rendered at half the input's size: footprints of several input
    pixels, over which the map bends (round the centre, along the seams). Their parts
    are pulled back through the map, not placed by a linear model of the footprint
    (which lost 8 dB here): within 1 dB of 4 x 4 against 12 x 12."""
    from spherewarp.demo import sample_path
    from spherewarp.effects.droste import droste_map, hole_from_radius
    from spherewarp.io import read_image

    img = np.ascontiguousarray(read_image(sample_path()).pixels[::4, ::4])  # 128 x 256
    m = droste_map(hole_from_radius((0, 0), 25), 3.0)
    kw = {"output_shape": (64, 128)}
    ref = warp(img, m, antialias=12, **kw)
    area = _psnr(warp(img, m, antialias="area", **kw), ref)
    assert area >= _psnr(warp(img, m, antialias=4, **kw), ref) - 1.0


@needs_jit
def test_area_fixed_point_taps_on_an_input_two_pixels_wide():
    """The 4 x 4 taps wrap round the seam more than once (found by review)."""
    img = np.random.default_rng(3).integers(0, 256, (32, 2, 1), dtype=np.uint8)
    m = Mobius.from_yaw_pitch_roll(10, 80, 0)
    kw = {"antialias": "area", "output_shape": (40, 80), "force": True}
    a = warp(img, m, **kw).astype(int)
    b = np.rint(warp(img.astype(np.float32), m, **kw)).astype(int)
    assert np.abs(a - b).max() <= 1


@needs_jit
@pytest.mark.parametrize(("kind", "channels"), [("zoom", 1), ("zoom", 4), ("droste", 3)])
def test_area_fixed_point_taps_match_float_taps(kind, channels):
    """uint8 images take 4 x 4 fixed-point taps (weights in 1/4096); float images the
    float32 ones: the same filter, to within a level (two where rounding meets on
    pixels that sum many taps)."""
    from spherewarp.maps import Droste

    rng = np.random.default_rng(7)
    img = rng.integers(0, 256, (64, 128, channels), dtype=np.uint8)
    if kind == "zoom":
        m = Mobius.zoom((20.0, 10.0), 6.0).inverse()
    else:
        m = Droste((0.0, 0.0), np.full(16, np.log(np.tan(np.radians(20.0) / 2))), 3.0)
    a = warp(img, m, antialias="area").astype(int)
    b = np.rint(warp(img.astype(np.float32), m, antialias="area")).astype(int)
    d = np.abs(a - b)
    assert d.max() <= 2
    assert (d > 1).mean() < 1e-3


def test_area_falls_back_to_uniform_supersampling():
    """Where the area filter is not compiled (a map without kernel stages, nearest
    sampling) ``"area"`` is uniform 4 x 4."""
    from spherewarp.maps import ExpressionMap

    img = _stripes(32, 64)
    m = ExpressionMap("z**2")
    np.testing.assert_array_equal(warp(img, m, antialias="area"), warp(img, m, antialias=4))
    r = Mobius.rotation((0.0, 0.0), 30)
    np.testing.assert_array_equal(
        warp(img, r, antialias="area", interp="nearest"),
        warp(img, r, antialias=4, interp="nearest"),
    )


class FrontHalf(SphereMap):
    """The identity, defined on the front half of the sphere only (a hole behind)."""

    def pull_cp1(self, zw):
        return np.asarray(zw, dtype=np.complex128)

    def pull(self, zw):
        zw = np.asarray(zw, dtype=np.complex128)
        return PullBack(zw, valid=coords.xyz_from_cp1(zw)[..., 0] > 0)

    def local_scale(self, zw):
        return np.full(np.shape(zw)[:-1], 1.5)


@pytest.mark.parametrize("method", ["auto", "reference"])
def test_area_antialiases_the_edges_of_holes(method):
    """Pixels on either side of the edge of an undefined region are partly covered: their
    alpha and colour follow a supersampled render."""
    img = _stripes(32, 64).astype(np.float32) / 255
    kw = {"output_shape": (31, 62), "alpha": True}  # the edges cross pixels (not between)
    ref = warp(img, FrontHalf(), antialias=16, **kw)
    out = warp(img, FrontHalf(), antialias="area", method=method, **kw)
    assert np.abs(out - ref).max() < 0.1
    partly = (ref[..., -1] > 0.05) & (ref[..., -1] < 0.95)
    assert partly.sum() >= 2 * 31  # both edges, every row


@pytest.mark.parametrize("shape", [(33, 130), (129, 258)])
def test_area_at_a_droste_maps_fixed_point(shape):
    """At the centre of a Droste map with scale 3, neighbouring pixels land on the same
    spot of other copies: their differences say the footprint is small, the magnification
    says it is large, and the magnification wins (as supersampling would)."""
    from spherewarp.maps import Droste

    img = _stripes(64, 128).astype(np.float32) / 255
    m = Droste((0, 0), np.full(64, np.log(0.2)), 3.0)
    ref = warp(img, m, output_shape=shape, antialias=16)
    for method in ("auto", "reference"):
        out = warp(img, m, output_shape=shape, antialias="area", method=method)
        assert np.abs(out - ref).max() < 0.15, method


@pytest.mark.parametrize("shape", [(1, 2), (2, 4), (3, 6)])
def test_area_on_tiny_outputs_is_as_good_as_adaptive(shape):
    """Neighbours half the input apart: differences cancel round the seam, and the
    magnification says how large the footprint is."""
    img = _stripes(32, 64).astype(np.float32) / 255
    for m in (Mobius.zoom((0, 0), 2), Mobius.zoom((30, 10), 3).inverse()):
        ref = warp(img, m, output_shape=shape, antialias=16)
        area = warp(img, m, output_shape=shape, antialias="area")
        adaptive = warp(img, m, output_shape=shape, antialias="adaptive")
        assert np.abs(area - ref).mean() <= np.abs(adaptive - ref).mean() + 0.02


@needs_jit
@pytest.mark.parametrize(
    "box", [(1.5, 1.0), (2.0, 2.0), (3.0, 1.0), (0.5, 2.6), (2.5, 3.9), (3.9, 3.0)]
)
@pytest.mark.parametrize("dtype", [np.uint8, np.float32])
def test_area_taps_are_exact_for_wide_boxes(box, dtype):
    """An area tap is the bilinear surface averaged over its box, exactly: the 4 x 4 taps
    for boxes up to 2 input pixels, wider taps up to ``AREA_BOX_MAX`` (4) beyond (a turned
    part of a footprint, or a part of one split into ``AUTO_MAX`` parts, can be wider than
    2; the 4 x 4 taps clamped it to 2), against a dense numerical average; round the seam
    too, and in fixed point (to rounding) for uint8."""
    from spherewarp.render import fast

    k = fast._kernels()
    rng = np.random.default_rng(1)
    img = rng.integers(0, 256, (64, 128, 3)).astype(dtype)
    f = img.astype(np.float64)

    def bilinear(u, v):
        x0 = np.floor(u).astype(int)
        y0 = np.floor(v).astype(int)
        fx = (u - x0)[:, None]
        fy = (v - y0)[:, None]
        g = lambda y, x: f[y, x % 128]  # noqa: E731 (rows stay inside here)
        top = (1 - fx) * g(y0, x0) + fx * g(y0, x0 + 1)
        return (1 - fy) * top + fy * ((1 - fx) * g(y0 + 1, x0) + fx * g(y0 + 1, x0 + 1))

    bx, by = box
    s = (np.arange(600) + 0.5) / 600 - 0.5
    for u, v in ((40.3, 30.7), (126.8, 20.2)):
        uu, vv = np.meshgrid(u + s * bx, v + s * by)
        want = bilinear(uu.ravel(), vv.ravel()).mean(0)
        U, V, BX, BY = (np.array([x]) for x in (u, v, bx, by))
        if dtype == np.float32:
            acc = np.zeros((1, 3), np.float32)
            cover = np.zeros(1, np.int64)
            k.area_batch(
                fast._image_bundle(img), U, V, BX, BY, 1, np.ones(1, np.uint8),
                np.zeros(1, np.int64), acc, cover, np.empty((8, 1), np.float32),
                np.empty(1, np.int64), np.empty(1, np.int64),
            )  # fmt: skip
            np.testing.assert_allclose(acc[0], want, atol=2e-3)
        else:
            p64, tail, big, _ = fast._u8_views(img, np.empty_like(img))
            sc = (np.empty((4, 1), np.int32), np.empty((4, 1), np.int32), np.empty(1, np.int32),
                  np.empty(1, np.int32), np.empty((8, 1), np.uint64), np.empty(1, np.uint32),
                  np.empty((4, 1), np.float32))  # fmt: skip
            res = np.empty(1, np.uint32)
            k.area_u8(p64, tail, big, img, 128, 64, 3, U, V, BX, BY, 1, res, sc, True,
                      np.zeros(1, np.uint8), 0)  # fmt: skip
            got = [(int(res[0]) >> (8 * ch)) & 255 for ch in range(3)]
            assert np.abs(np.array(got) - want).max() <= 0.51


@needs_jit
@pytest.mark.parametrize("channels", [1, 3, 4])
def test_uint8_area_taps_match_the_float_taps_at_the_poles_and_the_seam(channels):
    """The uint8 area taps (4 x 4 in fixed point, and the wide taps for boxes over 2 input
    pixels) give the float taps' average to within a level, as packed pixels and as the
    unrounded sums of parts: inside, round the seam, over both poles (rows fold half a
    turn round) and for NaN and huge coordinates."""
    from spherewarp.render import fast

    k = fast._kernels()
    rng = np.random.default_rng(7)
    h, w = 32, 64
    img = rng.integers(0, 256, (h, w, channels)).astype(np.uint8)
    n = 4000
    U = rng.uniform(-1.0, w + 1.0, n)
    V = np.concatenate([rng.uniform(-0.5, 3.0, n // 4), rng.uniform(h - 4.0, h - 0.5, n // 4),
                        rng.uniform(-0.5, h - 0.5, n - n // 2)])  # fmt: skip
    U0 = U.copy()
    U0[:3] = 0.0  # what the uint8 taps make of NaN and huge coordinates
    U[:3] = (np.nan, 1e9, -1e9)
    BX = rng.uniform(0.5, 4.0, n)
    BY = rng.uniform(0.5, 4.0, n)
    wide = rng.random(n) < 0.5
    BY[wide] = rng.uniform(2.05, 4.0, wide.sum())  # most of them wide in one axis at least
    acc = np.zeros((n, channels), np.float32)
    cover = np.zeros(n, np.int64)
    f32 = img.astype(np.float32)
    k.area_batch(
        fast._image_bundle(f32), U0, V, BX, BY, n, np.ones(n, np.uint8), np.arange(n), acc,
        cover, np.empty((8, n), np.float32), np.empty(n, np.int64), np.empty(n, np.int64),
    )  # fmt: skip
    p64, tail, big, _ = fast._u8_views(img, np.empty_like(img))
    na = n
    for packed in (True, False):
        sc = (np.empty((4, na), np.int32), np.empty((4, na), np.int32), np.empty(na, np.int32),
              np.empty(na, np.int32), np.empty((8, na), np.uint64), np.empty(na, np.uint32),
              np.zeros((4, na), np.float32))  # fmt: skip
        res = np.empty(n, np.uint32)
        k.area_u8(p64, tail, big, img, w, h, channels, U, V, BX, BY, n, res, sc, packed,
                  np.zeros(n, np.uint8), 0)  # fmt: skip
        if packed:
            got = np.stack([(res >> np.uint32(8 * ch)) & 255 for ch in range(channels)], -1)
            assert np.abs(got - np.rint(acc)).max() <= 1
        else:
            assert np.abs(sc[6][:channels].T - acc).max() <= 0.6
