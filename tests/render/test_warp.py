"""The pull-back renderer: exact cases, holes, sheets, continuity, magnification, references."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from spherewarp import coords
from spherewarp.errors import InvalidTypeError, InvalidValueError
from spherewarp.maps import Mobius, PullBack, SphereMap
from spherewarp.render import INTERPOLATIONS, push, warp
from tolerances import (
    MEASURED_SCALE_REL,
    REFERENCE_MAX_LEVELS,
    REFERENCE_MEAN_LEVELS,
    SMOOTH_CLAMPED_BICUBIC,
    SMOOTH_INTERPOLATION,
    full_scale,
    rounding,
)

DTYPES = [np.uint8, np.uint16, np.float32]


# -- test maps -------------------------------------------------------------------------------------
class FrontHalf(SphereMap):
    """The identity, undefined on a half of the sphere (by default the back, x < 0)."""

    def __init__(self, normal=(1.0, 0.0, 0.0)):
        self.normal = np.asarray(normal, float) / np.linalg.norm(normal)

    def pull_cp1(self, zw):
        return np.asarray(zw, dtype=np.complex128)

    def pull(self, zw):
        return PullBack(self.pull_cp1(zw), valid=coords.xyz_from_cp1(zw) @ self.normal >= 0)


class NorthSouth(SphereMap):
    """The identity, sampling image 0 in the north and image 1 in the south."""

    n_sheets = 2

    def pull_cp1(self, zw):
        return np.asarray(zw, dtype=np.complex128)

    def pull(self, zw):
        sheet = (coords.xyz_from_cp1(zw)[..., 2] < 0).astype(np.intp)
        return PullBack(self.pull_cp1(zw), sheet=sheet)


def _pixel_grid(h: int, w: int) -> np.ndarray:
    y, x = np.mgrid[0:h, 0:w] + 0.5
    return np.stack([x, y], axis=-1)


def _random_image(shape, dtype, seed=0):
    r = np.random.default_rng(seed)
    if np.dtype(dtype).kind == "u":
        return r.integers(0, np.iinfo(dtype).max, shape, dtype=dtype, endpoint=True)
    return r.random(shape).astype(dtype)


# -- exact cases -----------------------------------------------------------------------------------
@pytest.mark.parametrize("interp", INTERPOLATIONS)
@pytest.mark.parametrize("dtype", DTYPES)
@pytest.mark.parametrize("channels", [1, 2, 3, 4])
def test_turn_about_zenith_is_roll(interp, dtype, channels):
    h, w = 32, 64
    img = _random_image((h, w, channels), dtype, seed=channels)
    for k in (1, -3, 7, w // 2):
        out = warp(img, Mobius.rotation((0, 90), k * 360 / w), interp=interp)
        assert out.dtype == img.dtype and out.shape == img.shape
        np.testing.assert_array_equal(out, np.roll(img, -k, axis=1))


@pytest.mark.parametrize("interp", INTERPOLATIONS)
def test_identity_is_exact_and_2d_input(interp):
    img = _random_image((16, 32), np.uint16)
    out = warp(img, Mobius.identity(), interp=interp)
    assert out.shape == (16, 32, 1) and out.dtype == np.uint16
    np.testing.assert_array_equal(out[..., 0], img)


@pytest.mark.parametrize("interp", INTERPOLATIONS)
@pytest.mark.parametrize("dtype", DTYPES)
def test_output_shape_constant_image(interp, dtype):
    value = 0.6 * full_scale(dtype)
    img = np.full((64, 128, 3), value, dtype=dtype)
    m = Mobius.zoom((30, 20), 1.7)
    for shape in [(32, 64), (37, 50), (1, 1), (5, 200), (100, 30)]:
        out = warp(img, m, output_shape=shape, interp=interp)
        assert out.shape == (*shape, 3) and out.dtype == img.dtype
        np.testing.assert_allclose(out, img[0, 0, 0], rtol=0, atol=rounding(dtype))
        if np.dtype(dtype).kind == "u":
            assert np.all(out == img[0, 0, 0])


def test_output_shape_downscale_matches_box():
    """Identity at half size with supersample 2 samples the input at its pixel centres."""
    img = _random_image((32, 64, 3), np.float32)
    out = warp(img, Mobius.identity(), output_shape=(16, 32), supersample=2)
    box = img.reshape(16, 2, 32, 2, 3).mean(axis=(1, 3))
    np.testing.assert_allclose(out, box, rtol=0, atol=rounding(np.float32))
    img8 = _random_image((32, 64, 3), np.uint8)
    out8 = warp(img8, Mobius.identity(), output_shape=(16, 32), supersample=2)
    box8 = img8.reshape(16, 2, 32, 2, 3).mean(axis=(1, 3))
    assert np.abs(out8 - box8).max() <= 0.5 + 1e-3  # rounded mean


def test_supersample_averages():
    img = _random_image((32, 64, 1), np.float32, seed=3)
    m = Mobius.zoom((40, -10), 0.6)
    n = 3
    out = warp(img, m, supersample=n)
    # the same as rendering n times larger and box-filtering
    big = warp(img, m, output_shape=(32 * n, 64 * n))
    box = big.reshape(32, n, 64, n, 1).mean(axis=(1, 3))
    np.testing.assert_allclose(out, box, atol=2e-6)
    # and smoother than a single sample (it averages)
    single = warp(img, m, antialias="none")
    assert np.std(out) < np.std(single)


def test_push_is_warp_by_inverse():
    img = _random_image((32, 64, 3), np.uint8)
    m = Mobius.zoom((10, 20), 2.0)
    np.testing.assert_array_equal(push(img, m), warp(img, m.inverse()))
    np.testing.assert_array_equal(
        push(img, m, interp="bicubic", output_shape=(20, 40)),
        warp(img, m.inverse(), interp="bicubic", output_shape=(20, 40)),
    )


# -- holes and sheets ------------------------------------------------------------------------------
@pytest.mark.parametrize("dtype", DTYPES)
def test_holes_background_and_alpha(dtype):
    h, w = 32, 64
    img = _random_image((h, w, 3), dtype)
    xyz = coords.xyz_from_lonlat(coords.lonlat_from_pixel(_pixel_grid(h, w), w, h))
    front = xyz[..., 0] >= 0
    full = full_scale(dtype)
    bg = np.array([0.25, 0.5, 1.0]) * full
    out = warp(img, FrontHalf(), background=bg)
    assert out.dtype == img.dtype and out.shape == img.shape
    np.testing.assert_array_equal(out[front], img[front])
    expected_bg = np.rint(bg) if np.dtype(dtype).kind == "u" else bg
    np.testing.assert_allclose(out[~front], np.broadcast_to(expected_bg, out[~front].shape))
    # alpha: an extra channel, opaque where defined, 0 in the holes
    out = warp(img, FrontHalf(), alpha=True)
    assert out.shape == (h, w, 4) and out.dtype == img.dtype
    assert np.all(out[front][:, 3] == full) and np.all(out[~front][:, 3] == 0)
    np.testing.assert_array_equal(out[front][:, :3], img[front])
    assert np.all(out[~front][:, :3] == 0)
    # a scalar background colour
    out = warp(img[..., :1], FrontHalf(), background=0.5 * full)
    np.testing.assert_allclose(out[~front][:, 0], 0.5 * full, atol=rounding(dtype))


def test_holes_with_supersampling_give_partial_alpha():
    img = np.ones((32, 64, 3), np.float32)
    out = warp(img, FrontHalf((1.0, 0.3, 0.2)), alpha=True, supersample=4)
    a = out[..., 3]
    assert np.all((a >= 0) & (a <= 1))
    assert np.any((a > 0.05) & (a < 0.95))  # the rim of the hole is partly covered
    np.testing.assert_allclose(out[..., :3], np.repeat(a[..., None], 3, -1), atol=1e-6)  # bg 0


def test_holes_keep_existing_alpha():
    img = _random_image((16, 32, 4), np.uint8)
    img[..., 3] = 255
    out = warp(img, FrontHalf(), alpha=True)
    assert out.shape == (16, 32, 4)
    xyz = coords.xyz_from_lonlat(coords.lonlat_from_pixel(_pixel_grid(16, 32), 32, 16))
    assert np.all(out[xyz[..., 0] < 0] == 0)  # default background 0 = transparent


# -- alpha: straight in images, premultiplied while filtering ------------------------------------
ALPHA_RENDERS = [
    (Mobius.from_yaw_pitch_roll(33.3, 17, 5), {}),  # one bilinear tap a pixel
    (Mobius.from_yaw_pitch_roll(33.3, 17, 5), {"interp": "bicubic"}),
    (Mobius.from_yaw_pitch_roll(33.3, 17, 5), {"interp": "nearest"}),
    (Mobius.zoom((20, -10), 2.5), {}),  # the area filter
    (Mobius.zoom((20, -10), 2.5), {"antialias": "adaptive"}),
    (Mobius.zoom((20, -10), 0.6), {"antialias": 3}),  # uniform supersampling
    (Mobius.from_yaw_pitch_roll(10, 40, 0), {"method": "reference", "supersample": 2}),
]
ALPHA_IDS = ["rotation", "bicubic", "nearest", "area", "adaptive", "uniform", "reference"]


def _checker_rgba(dtype, h=32, w=64, cell=4):
    """Opaque green squares and transparent squares that hide red: (full, 0, 0, 0)."""
    full = full_scale(dtype)
    y, x = np.mgrid[0:h, 0:w]
    opaque = ((y // cell + x // cell) % 2).astype(bool)
    img = np.zeros((h, w, 4), np.float64)
    img[opaque] = (0, full, 0, full)
    img[~opaque] = (full, 0, 0, 0)
    return img.astype(dtype)


@pytest.mark.parametrize(("m", "kw"), ALPHA_RENDERS, ids=ALPHA_IDS)
@pytest.mark.parametrize("dtype", DTYPES)
def test_hidden_colour_of_transparent_pixels_does_not_bleed(m, kw, dtype):
    """Colour and alpha are filtered premultiplied: an edge pixel between opaque green
    and transparent red is green, partly transparent (it was a mix of the two: red > 20
    levels in 14,364 of 15,584 such pixels of a 1024 x 512 checkerboard turned 33.3 and
    17 degrees)."""
    full, tol = full_scale(dtype), rounding(dtype)
    img = _checker_rgba(dtype)
    out = warp(img, m, **kw).astype(np.float64)
    a = out[..., 3]
    seen = a > max(tol, full * 2**-16)  # under 2**-16 of full: unseen, not divided
    partial = seen & (a < full - tol)
    if kw.get("interp") != "nearest":
        assert partial.sum() > 100
    # alpha within 2**-16 of full is full: the colour may hold that share of the hidden one
    tol = max(tol, full * 2**-16)
    if kw.get("interp") == "bicubic":  # overshoot next to the edges: a few levels
        seen &= a > 0.05 * full
        tol = 0.02 * full
    np.testing.assert_allclose(out[seen][:, 0], 0, atol=tol)
    np.testing.assert_allclose(out[seen][:, 1], full, atol=tol)
    # grey + alpha: the grey of the visible pixels, whatever the hidden one
    grey = img[..., 1:].copy()  # (green, alpha): 0 where transparent
    grey[..., 0] = np.where(img[..., 3] > 0, np.asarray(0.4 * full, dtype), img[..., 0])
    out = warp(grey, m, **kw).astype(np.float64)
    seen = out[..., 1] > (0.05 * full if kw.get("interp") == "bicubic" else full * 2**-16)
    np.testing.assert_allclose(out[seen][:, 0], 0.4 * full, atol=tol + rounding(dtype))


@pytest.mark.parametrize(("m", "kw"), ALPHA_RENDERS, ids=ALPHA_IDS)
@pytest.mark.parametrize("dtype", DTYPES)
def test_opaque_pixels_and_opaque_images_render_as_before(m, kw, dtype):
    """An opaque RGBA image gives the RGB image's colour, to the bit; in an image with
    transparent parts, every output pixel that comes out opaque keeps the colour of the
    straight render (the RGB image's) too: the division only touches partly
    transparent pixels."""
    rgb = _random_image((32, 64, 3), dtype, seed=3)
    full = full_scale(dtype)
    want = warp(rgb, m, **kw)
    rgba = np.concatenate([rgb, np.full((32, 64, 1), full, dtype)], axis=-1)
    out = warp(rgba, m, **kw)
    np.testing.assert_array_equal(out[..., :3], want)
    np.testing.assert_allclose(out[..., 3], full, rtol=0, atol=rounding(dtype) / 2)
    rgba[:, 20:40, 3] = 0  # a transparent band
    rgba[:, 40, 3] = full // 3 if np.dtype(dtype).kind == "u" else 0.3
    out = warp(rgba, m, **kw)
    # opaque: the alpha written is full, and the filtered alpha not over it (bicubic's
    # overshoot next to an edge: there the colour is divided too)
    filtered = warp(rgba[..., 3:].astype(np.float32), m, **kw)[..., 0]
    opaque = (out[..., 3] >= full * (1 - 2**-16)) & (filtered <= full * (1 + 2**-16))
    assert opaque.sum() > 0.3 * opaque.size and (~opaque).sum() > 50
    np.testing.assert_array_equal(out[opaque][:, :3], want[opaque])
    np.testing.assert_array_equal(out[..., 3], warp(rgba[..., 3:], m, **kw)[..., 0])


@pytest.mark.parametrize("dtype", DTYPES)
def test_an_exact_turn_still_rolls_straight_alpha(dtype):
    """A turn by whole pixels moves every sample, hidden colours of transparent pixels
    and partly transparent ones included, unchanged (no colour x alpha / alpha rounding)."""
    img = _random_image((16, 32, 4), dtype, seed=9)
    img[::3, ::2, 3] = 0
    for interp in INTERPOLATIONS:
        out = warp(img, Mobius.rotation((0, 90), 3 * 360 / 32), interp=interp)
        if np.dtype(dtype).kind == "u":
            np.testing.assert_array_equal(out, np.roll(img, -3, axis=1))
        else:  # a float tap of weight 1e-16 next door: 0 alpha comes out 1e-16
            np.testing.assert_allclose(out, np.roll(img, -3, axis=1), rtol=0, atol=1e-6)


def test_rim_of_a_hole_keeps_the_colour_of_an_rgba_image():
    """The background (default 0: transparent) is mixed in premultiplied too: the rim of
    a hole is the image's colour, partly transparent, not darkened toward black."""
    img = np.zeros((32, 64, 4), np.uint8)
    img[...] = (100, 150, 200, 255)
    out = warp(img, FrontHalf((1.0, 0.3, 0.2)), supersample=4)
    a = out[..., 3]
    rim = (a > 0) & (a < 255)
    assert rim.sum() > 20
    assert np.all(out[rim][:, :3] == (100, 150, 200))
    assert np.all(out[a == 0] == 0)
    # a straight background colour: the colour of a half-covered pixel is between the two
    out = warp(img, FrontHalf((1.0, 0.3, 0.2)), supersample=4, background=(0, 0, 0, 255))
    assert np.all(out[..., 3] == 255)


def test_two_passes_report_progress_once_in_order():
    img = _checker_rgba(np.uint8)
    seen = []
    warp(img, Mobius.from_yaw_pitch_roll(33.3, 17, 5), progress=lambda d, t: seen.append((d, t)))
    assert seen[0][0] == 0 and seen[-1][0] == seen[-1][1]
    assert len({t for _, t in seen}) == 1 and [d for d, _ in seen] == sorted(d for d, _ in seen)


@pytest.mark.parametrize("interp", INTERPOLATIONS)
def test_two_sheets(interp):
    h, w = 32, 64
    a = np.full((h, w, 3), (10, 20, 30), np.uint8)
    b = np.full((h // 2, w // 2, 3), (200, 100, 50), np.uint8)  # sheets may differ in size
    out = warp([a, b], NorthSouth(), interp=interp)
    assert out.shape == (h, w, 3)
    np.testing.assert_array_equal(out[: h // 2], a[: h // 2])
    assert np.all(out[h // 2 :] == (200, 100, 50))
    with pytest.raises(InvalidValueError, match="2 input images"):
        warp(a, NorthSouth())
    with pytest.raises(InvalidValueError):
        warp([a, b.astype(np.uint16)], NorthSouth())


# -- robustness ------------------------------------------------------------------------------------
def test_nearly_singular_mobius_renders():
    """Found by hypothesis: a Möbius matrix this close to singular rounds the time
    component of some pulled-back points to 0, which divided by zero in the compiled
    magnification (a ZeroDivisionError with a traceback). Such pixels now count as
    shrunk as can be."""
    from spherewarp.render import WarpMap

    e = [0.0, 1.175494351e-38, 0.0, 8.123870062916892e-26, 0.0, 0.0, 8.123870062916892e-26, 0.0]
    m = Mobius(np.array(e[:4]).reshape(2, 2) + 1j * np.array(e[4:]).reshape(2, 2))
    img = _random_image((8, 16, 3), np.float32)
    for antialias in ("auto", "area", "none"):
        out = warp(img, m, antialias=antialias, output_shape=(9, 14))
        assert np.all(np.isfinite(out))
        cached = WarpMap.build(m, (8, 16), (9, 14), antialias=antialias).apply(img)
        assert np.all(np.isfinite(cached))


@settings(max_examples=100, deadline=None)
@given(
    entries=st.lists(st.floats(-5, 5), min_size=8, max_size=8),
    interp=st.sampled_from(INTERPOLATIONS),
    scale=st.sampled_from([1.0, 1e-3, 65504.0]),
    supersample=st.integers(1, 2),
)
def test_no_nan_float32(entries, interp, scale, supersample):
    a = np.array(entries[:4]).reshape(2, 2) + 1j * np.array(entries[4:]).reshape(2, 2)
    try:
        m = Mobius(a)
    except InvalidValueError:
        return  # singular
    img = (_random_image((8, 16, 3), np.float32) * scale).astype(np.float32)
    out = warp(img, m, interp=interp, supersample=supersample, output_shape=(9, 14))
    assert out.dtype == np.float32 and np.all(np.isfinite(out))
    # bilinear and nearest cannot leave the input's range; bicubic overshoots a little
    lo, hi = img.min(), img.max()
    slack = 0.0 if interp != "bicubic" else 0.3 * (hi - lo)
    assert out.min() >= lo - slack - 1e-6 * scale and out.max() <= hi + slack + 1e-6 * scale


# -- continuity across the seam and over the poles -------------------------------------------------
@pytest.mark.parametrize("interp", INTERPOLATIONS)
@pytest.mark.parametrize("dtype", [np.float32, np.uint16])
def test_smooth_image_stays_smooth(smooth_image, interp, dtype):
    """0.5 + 0.5 xyz, turned so that both poles and the seam land inside the image.

    A seam, a black column or a pinch at a pole would be an error of order 0.5.
    """
    h = 64
    img = smooth_image(h, dtype)
    m = Mobius.rotation((0, 0), 70) @ Mobius.rotation((0, 90), 33)
    out = warp(img, m, interp=interp).astype(np.float64) / full_scale(dtype)
    xyz = coords.xyz_from_lonlat(coords.lonlat_from_pixel(_pixel_grid(h, 2 * h), 2 * h, h))
    expected = 0.5 + 0.5 * m.apply_xyz(xyz)
    err = np.abs(out - expected).max(axis=-1)
    bound = SMOOTH_INTERPOLATION[interp]
    if interp == "bicubic" and np.dtype(dtype).kind == "f":
        bound = SMOOTH_CLAMPED_BICUBIC
    assert np.all(np.isfinite(out))
    # everywhere, the edges (seam columns, pole rows) included
    assert err.max() <= bound, (err.max(), np.unravel_index(err.argmax(), err.shape))
    for edge in (err[0], err[-1], err[:, 0], err[:, -1]):
        assert edge.max() <= bound


# -- bad inputs ------------------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        ({"interp": "lanczos"}, InvalidValueError, "nearest, bilinear, bicubic"),
        ({"supersample": 0}, InvalidValueError, "supersample"),
        ({"supersample": 1.5}, InvalidValueError, "supersample"),
        ({"supersample": True}, InvalidValueError, "supersample"),
        ({"supersample": 33}, InvalidValueError, "supersample"),
        ({"output_shape": (0, 10)}, InvalidValueError, "output shape"),
        ({"output_shape": "big"}, InvalidValueError, "output_shape"),
        ({"background": (1, 2)}, InvalidValueError, "background"),
        ({"background": np.nan}, InvalidValueError, "background"),
    ],
)
def test_bad_options(kwargs, error, match):
    img = np.zeros((8, 16, 3), np.uint8)
    with pytest.raises(error, match=match):
        warp(img, Mobius.identity(), **kwargs)


@pytest.mark.parametrize(
    ("image", "error", "match"),
    [
        (np.zeros((8, 10, 3), np.uint8), InvalidValueError, "2 x height, got 10x8"),
        (np.zeros((8, 16, 3), np.int32), InvalidTypeError, "int32"),
        (np.zeros((8, 16, 3), bool), InvalidTypeError, "bool"),
        (np.zeros((8, 16, 3), np.complex64), InvalidTypeError, "complex64"),
        (np.zeros((8, 16, 5), np.uint8), InvalidValueError, "1-4 channels"),
        (np.zeros((8, 16, 0), np.uint8), InvalidValueError, "1-4 channels"),
        (np.zeros((2, 8, 16, 3), np.uint8), InvalidValueError, "1-4 channels"),
        (np.zeros(16, np.uint8), InvalidValueError, "1-4 channels"),
        ([], InvalidValueError, "at least one image"),
    ],
)
def test_bad_images(image, error, match):
    with pytest.raises(error, match=match):
        warp(image, Mobius.identity())


def test_force_and_bad_map():
    img = np.zeros((8, 10, 3), np.uint8)
    assert warp(img, Mobius.identity(), force=True).shape == (8, 10, 3)
    with pytest.raises(InvalidTypeError, match="SphereMap"):
        warp(np.zeros((8, 16, 3), np.uint8), lambda z: z)
    with pytest.raises(InvalidValueError, match="interpolation"):
        warp(np.zeros((8, 16, 3), np.uint8), Mobius.identity(), interp="Lanczos")
    # names are case-insensitive
    out = warp(np.zeros((8, 16, 3), np.uint8), Mobius.identity(), interp="BiLinear")
    assert out.shape == (8, 16, 3)


# -- a zoom magnifies by lambda at p and 1/lambda at -p, measured on a rendered image --------------
def _cap_image(h: int, centres_deg, radius_deg: float) -> np.ndarray:
    """1 inside spherical caps, 0 outside, with an anti-aliased rim one pixel wide."""
    w = 2 * h
    xyz = coords.xyz_from_lonlat(coords.lonlat_from_pixel(_pixel_grid(h, w), w, h))
    img = np.zeros((h, w), np.float64)
    px = np.pi / h
    for c in centres_deg:
        d = np.arccos(np.clip(xyz @ coords.xyz_from_lonlat(np.radians(c)), -1, 1))
        img = np.maximum(img, np.clip((np.radians(radius_deg) - d) / px + 0.5, 0, 1))
    return img.astype(np.float32)[..., None]


def _cap_radius(img: np.ndarray, centre_deg, within_deg: float) -> float:
    """Angular radius (degrees) of the cap around centre, from its measured solid angle."""
    h, w = img.shape[:2]
    ll = coords.lonlat_from_pixel(_pixel_grid(h, w), w, h)
    xyz = coords.xyz_from_lonlat(ll)
    d = np.degrees(np.arccos(np.clip(xyz @ coords.xyz_from_lonlat(np.radians(centre_deg)), -1, 1)))
    pixel_area = np.cos(ll[..., 1]) * (2 * np.pi / w) * (np.pi / h)
    area = np.sum(img[..., 0] * pixel_area * (d < within_deg))
    return float(np.degrees(np.arccos(1 - area / (2 * np.pi))))


@pytest.mark.parametrize(
    ("at", "factor"), [((40, 25), 2.0), ((-100, -60), 2.5), ((0, 0), 2 * np.exp(0.6j))]
)
def test_zoom_magnification_measured(at, factor):
    h = 512
    anti = coords.lonlat_from_xyz(-coords.xyz_from_lonlat(np.radians(at)))
    anti = tuple(np.degrees(anti))
    r0 = 6.0
    img = _cap_image(h, [at, anti], r0)
    lam = abs(factor)
    out = push(img, Mobius.zoom(at, factor))
    r_in_p, r_in_q = _cap_radius(img, at, 3 * r0), _cap_radius(img, anti, 3 * r0)
    r_out_p = _cap_radius(out, at, 3 * r0 * lam)
    r_out_q = _cap_radius(out, anti, 3 * r0)
    assert abs(r_in_p / r0 - 1) < 0.01 and abs(r_in_q / r0 - 1) < 0.01  # the ruler works
    assert abs((r_out_p / r_in_p) / lam - 1) < MEASURED_SCALE_REL
    assert abs((r_out_q / r_in_q) * lam - 1) < MEASURED_SCALE_REL
    # the zoom pushes content away from p: nothing left between the two caps but the caps
    assert abs(out[..., 0].sum() - img[..., 0].sum()) / img[..., 0].sum() > 0.05


# -- against a float64 reference written from the paper's formulas ---------------------------------
def _chart(lon: np.ndarray, lat: np.ndarray) -> np.ndarray:
    """z = tan((90 deg - lat)/2) exp(i (lon + 180 deg)) (0 at the zenith)."""
    return np.tan((np.pi / 2 - lat) / 2) * np.exp(1j * (lon + np.pi))


def _apply(mat: np.ndarray, z: np.ndarray):
    """(a z + b)/(c z + d) in the plane, returned as (lon, lat); a zero denominator is the nadir."""
    (a, b), (c, d) = mat
    num, den = a * z + b, c * z + d
    at_inf = np.abs(den) <= 1e-300 * np.maximum(np.abs(num), 1e-300)
    w = num / np.where(at_inf, 1.0, den)
    lat = np.where(at_inf, -np.pi / 2, np.pi / 2 - 2 * np.arctan(np.abs(w)))
    lon = np.angle(w) - np.pi
    return lon, lat


def _bilinear_ref(img: np.ndarray, lon: np.ndarray, lat: np.ndarray) -> np.ndarray:
    """Bilinear in float64, wrapping at the seam and folding over the poles."""
    h, w, _ = img.shape
    fx = (lon + np.pi) / (2 * np.pi) * w - 0.5
    fy = (np.pi / 2 - lat) / np.pi * h - 0.5
    x0, y0 = np.floor(fx).astype(int), np.floor(fy).astype(int)
    tx, ty = (fx - x0)[..., None], (fy - y0)[..., None]
    src = img.astype(np.float64)
    out = 0.0
    for dy, wy in ((0, 1 - ty), (1, ty)):
        for dx, wx in ((0, 1 - tx), (1, tx)):
            r, c = y0 + dy, x0 + dx
            over = (r < 0) | (r >= h)
            c = np.where(over, c + w // 2, c) % w
            r = np.where(r < 0, -1 - r, np.where(r >= h, 2 * h - 1 - r, r))
            out = out + wx * wy * src[r, c]
    return out


def _zoom_matrix(at_deg, factor) -> np.ndarray:
    """T o (zeta -> factor zeta) o T^-1 with T(zeta) = (zeta + q)/(1 - conj(q) zeta), T(0) = q."""
    q = _chart(*np.radians(at_deg))
    t = np.array([[1, q], [-np.conj(q), 1]])
    t_inv = np.array([[1, -q], [np.conj(q), 1]])
    return t @ np.diag([factor, 1]) @ t_inv


def _three_point_matrix(p_deg, q_deg) -> np.ndarray:
    """The map p_k -> q_k via cross-ratios: A_q^-1 A_p, A sending (z1, z2, z3) to (0, 1, inf)."""

    def to_01inf(pts):
        z1, z2, z3 = (_chart(*np.radians(p)) for p in pts)
        return np.array([[z2 - z3, -z1 * (z2 - z3)], [z2 - z1, -z3 * (z2 - z1)]])

    return np.linalg.inv(to_01inf(q_deg)) @ to_01inf(p_deg)


THREE_P = [(0, 0), (90, 0), (0, 60)]
THREE_Q = [(20, 10), (100, -15), (-30, 50)]
RAW = np.array([[1 + 0.5j, 0.3], [-0.2j, 0.8]])

REFERENCE_CASES = {
    "zoom": (Mobius.zoom((30, 10), 2.0), False, _zoom_matrix((30, 10), 2.0)),
    "zoom_spiral": (
        Mobius.zoom((-120, -35), 1.5 * np.exp(0.8j)),
        False,
        _zoom_matrix((-120, -35), 1.5 * np.exp(0.8j)),
    ),
    "zoom_pushed": (Mobius.zoom((30, 10), 2.0), True, np.linalg.inv(_zoom_matrix((30, 10), 2.0))),
    "three_point": (
        Mobius.from_points(THREE_P, THREE_Q),
        False,
        _three_point_matrix(THREE_P, THREE_Q),
    ),
    "raw_matrix": (Mobius(RAW), False, RAW),
}


@pytest.mark.parametrize("name", list(REFERENCE_CASES))
def test_matches_paper_reference(interior, name):
    m, pushed, mat = REFERENCE_CASES[name]
    img = interior
    h, w, _ = img.shape
    out = (push if pushed else warp)(img, m, interp="bilinear", antialias="none")
    ll = coords.lonlat_from_pixel(_pixel_grid(h, w), w, h)
    lon, lat = ll[..., 0], ll[..., 1]
    src_lon, src_lat = _apply(mat, _chart(lon, lat))
    ref = _bilinear_ref(img, src_lon, src_lat)
    diff = np.abs(out.astype(np.float64) - ref)
    assert diff.mean() < REFERENCE_MEAN_LEVELS, diff.mean()
    away = (np.abs(lat) < np.radians(85)) & (np.abs(src_lat) < np.radians(85))
    assert diff[away].max() <= REFERENCE_MAX_LEVELS, diff[away].max()
    # the reference folds over the poles as the sphere does, so the poles agree too
    assert diff.max() <= REFERENCE_MAX_LEVELS, diff.max()


@pytest.mark.parametrize("shape", [(10.5, 20), (True, True), ("a", 3)])
def test_output_shape_must_be_whole_numbers(shape):
    with pytest.raises(InvalidValueError, match="output_shape"):
        warp(np.zeros((8, 16, 3), np.uint8), Mobius.zoom((0, 0), 2), output_shape=shape)
    assert warp(np.zeros((8, 16, 3), np.uint8), Mobius.identity(), output_shape=(4.0, 8)).shape \
        == (4, 8, 3)


def test_a_colour_name_as_background_is_a_type_error():
    with pytest.raises(InvalidTypeError, match="sample values"):
        warp(np.zeros((8, 16, 3), np.uint8), Mobius.zoom((0, 0), 2), background="red")
