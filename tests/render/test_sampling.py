"""The samplers: exact at pixel centres, wrapping at the seam, folding over the poles."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from spherewarp.errors import InvalidValueError
from spherewarp.render.sampling import INTERPOLATIONS, check_interp, sample, sample_area

PROPERTY = settings(max_examples=100, deadline=None)


def _image(h: int = 8, c: int = 3, dtype=np.float32, seed: int = 0) -> np.ndarray:
    r = np.random.default_rng(seed)
    if np.dtype(dtype).kind == "u":
        return r.integers(0, np.iinfo(dtype).max, (h, 2 * h, c), dtype=dtype, endpoint=True)
    return r.random((h, 2 * h, c)).astype(dtype)


@pytest.mark.parametrize("interp", INTERPOLATIONS)
@pytest.mark.parametrize("dtype", [np.uint8, np.uint16, np.float32, np.float64])
def test_exact_at_pixel_centres(interp, dtype):
    img = _image(dtype=dtype)
    h, w, c = img.shape
    y, x = np.mgrid[0:h, 0:w] + 0.5
    out = sample(img, x, y, interp)
    assert out.dtype == np.float32 and out.shape == (h, w, c)
    np.testing.assert_array_equal(out, img.astype(np.float32))


@pytest.mark.parametrize("interp", INTERPOLATIONS)
def test_wraps_at_the_seam(interp):
    img = _image()
    h, w, _ = img.shape
    r = np.random.default_rng(1)
    x = r.uniform(0, w, 50)
    y = r.uniform(0, h, 50)
    base = sample(img, x, y, interp)
    for shift in (-w, w, 3 * w):
        np.testing.assert_allclose(sample(img, x + shift, y, interp), base, atol=1e-5)
    # across the seam: between the last and the first column
    mid = sample(img, np.array([0.0, float(w)]), np.array([h / 2 + 0.5] * 2), "bilinear")
    row = img[h // 2].astype(np.float32)
    np.testing.assert_allclose(mid[0], 0.5 * (row[0] + row[-1]), rtol=1e-6)
    np.testing.assert_allclose(mid[1], mid[0])


@pytest.mark.parametrize("interp", INTERPOLATIONS)
def test_fold_over_the_poles(interp):
    """Above the top row is the top row half a turn round; the poles are single points."""
    img = _image(h=16)
    h, w, _ = img.shape
    x = np.arange(w) + 0.5
    # exactly at a pole the value cannot depend on the side (nearest breaks the tie instead)
    for y in (0.0, float(h)) if interp != "nearest" else ():
        at = sample(img, x, np.full(w, y), interp)
        opposite = sample(img, x + w / 2, np.full(w, y), interp)
        np.testing.assert_allclose(at, opposite, atol=1e-5)
    # a little past the pole is a little before it on the other side
    for eps in (0.1, 0.3, 0.5, 1.2):
        np.testing.assert_allclose(
            sample(img, x, np.full(w, -eps), interp),
            sample(img, x + w / 2, np.full(w, eps), interp),
            atol=1e-5,
        )
        np.testing.assert_allclose(
            sample(img, x, np.full(w, h + eps), interp),
            sample(img, x + w / 2, np.full(w, h - eps), interp),
            atol=1e-5,
        )
    # bilinear at the top edge: the average of the two antipodal top pixels
    if interp == "bilinear":
        top = sample(img, np.array([0.5]), np.array([0.0]), interp)[0]
        np.testing.assert_allclose(top, 0.5 * (img[0, 0] + img[0, w // 2]), rtol=1e-6)


def test_bilinear_weights():
    img = np.arange(2 * 4, dtype=np.float32).reshape(2, 4, 1)
    out = sample(img, np.array([1.0, 1.25, 1.0]), np.array([0.5, 0.5, 1.0]), "bilinear")
    np.testing.assert_allclose(out[:, 0], [0.5, 0.75, 2.5])
    # nearest rounds to the closest centre
    out = sample(img, np.array([0.9, 1.1, 3.99]), np.array([0.5, 1.49, 1.51]), "nearest")
    np.testing.assert_array_equal(out[:, 0], [0, 5, 7])


@PROPERTY
@given(
    x=st.floats(0, 32),
    y=st.floats(1.5, 14.5),
    a=st.floats(-3, 3),
    b=st.floats(-3, 3),
    c0=st.floats(-3, 3),
)
def test_reproduces_linear_functions(x, y, a, b, c0):
    """Bilinear and bicubic (Keys) reproduce a + b*x + c*y exactly away from the seam."""
    h, w = 16, 32
    yy, xx = np.mgrid[0:h, 0:w] + 0.5
    x = min(max(x, 2.0), w - 2.0)  # linear in x only away from the wrap
    img = (c0 + a * xx + b * yy)[..., None].astype(np.float64)
    expected = c0 + a * x + b * y
    for interp in ("bilinear", "bicubic"):
        got = sample(img, np.array([x]), np.array([y]), interp)[0, 0]
        assert abs(got - expected) <= 1e-4 * (1 + abs(expected))


@pytest.mark.parametrize("interp", INTERPOLATIONS)
def test_constant_image_anywhere(interp):
    img = np.full((8, 16, 2), 0.375, np.float32)
    r = np.random.default_rng(2)
    x, y = r.uniform(-40, 40, 200), r.uniform(0, 8, 200)
    np.testing.assert_allclose(sample(img, x, y, interp), 0.375, rtol=1e-6)


def test_shapes():
    img = _image(c=4)
    out = sample(img, np.zeros((3, 5)) + 1.5, np.zeros((3, 5)) + 2.5)
    assert out.shape == (3, 5, 4)
    assert sample(img, np.float64(1.5), np.float64(2.5)).shape == (4,)


@pytest.mark.parametrize(
    ("name", "expected"),
    [
        ("bilinear", "bilinear"),
        ("BiCubic", "bicubic"),
        (" nearest ", "nearest"),
        ("linear", "bilinear"),
        ("cubic", "bicubic"),
        ("near", "nearest"),
    ],
)
def test_check_interp(name, expected):
    assert check_interp(name) == expected


@pytest.mark.parametrize("name", ["lanczos", "", "bilinearr", None])
def test_check_interp_errors(name):
    with pytest.raises(InvalidValueError) as info:
        check_interp(name)
    for allowed in INTERPOLATIONS:
        assert allowed in str(info.value)


def test_sample_rejects_bad_shape():
    with pytest.raises(InvalidValueError):
        sample(np.zeros((4, 8)), np.zeros(2), np.zeros(2))


# -- area taps -------------------------------------------------------------------------------
def _dense_box_mean(img, x, y, bx, by, n=64):
    """The bilinear surface averaged over a box by brute force (n x n midpoints)."""
    f = (np.arange(n) + 0.5) / n - 0.5
    xs = (x + bx * f)[None, :].repeat(n, 0)
    ys = (y + by * f)[:, None].repeat(n, 1)
    return sample(img, xs, ys, "bilinear").reshape(-1, img.shape[2]).mean(0)


@pytest.mark.parametrize(
    "x, y, bx, by",
    [
        (5.3, 3.7, 1.0, 1.0),
        (0.2, 4.1, 2.0, 0.5),  # across the seam
        (15.9, 0.3, 1.5, 1.2),  # across the seam and over the top pole
        (7.6, 7.8, 0.3, 2.0),  # over the bottom pole
        (3.5, 2.5, 1e-6, 1e-6),  # a bilinear tap
    ],
)
def test_sample_area_is_the_mean_of_the_bilinear_surface(x, y, bx, by):
    img = _image(8, 2, np.float32, seed=4)
    got = sample_area(img, np.array([x]), np.array([y]), bx, by)[0]
    np.testing.assert_allclose(got, _dense_box_mean(img, x, y, bx, by), atol=2e-3)


def test_sample_area_clamps_boxes_to_four_pixels():
    img = _image(8, 1, np.float32, seed=5)
    x, y = np.array([4.2]), np.array([3.9])
    np.testing.assert_array_equal(sample_area(img, x, y, 5.0, 9.0), sample_area(img, x, y, 4, 4))


def test_sample_area_of_wide_boxes_matches_the_compiled_taps():
    """Boxes over 2 input pixels (up to 4) are exact in both: 6 x 6 taps here, the
    compiled wide taps there."""
    from spherewarp.render import fast

    if not fast.available():
        pytest.skip("numba is not installed")
    k = fast._kernels()
    img = _image(16, 3, np.float32, seed=6)
    x = np.array([4.2, 9.7, 0.3, 30.9])
    y = np.array([3.9, 8.1, 0.6, 15.2])
    bx = np.array([2.6, 3.9, 1.0, 3.3])
    by = np.array([1.0, 3.5, 2.9, 0.2])
    want = sample_area(img, x, y, bx, by)
    acc = np.zeros((4, 3), np.float32)
    k.area_batch(
        fast._image_bundle(img), x - 0.5, y - 0.5, bx, by, 4, np.ones(4, np.uint8),
        np.arange(4), acc, np.zeros(4, np.int64), np.empty((8, 4), np.float32),
        np.empty(4, np.int64), np.empty(4, np.int64),
    )  # fmt: skip
    np.testing.assert_allclose(acc, want, atol=1e-5)


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_float_bicubic_does_not_ring_past_its_nearest_samples(dtype):
    """An HDR step (a sun of 50,000 in a sky of 1) rang to -2,269 beside it (black specks
    once tone-mapped): a float image's bicubic value stays within its four nearest
    samples, in the NumPy sampler, the compiled one, and warp's reference and fast paths
    alike; a smooth image's values do not change."""
    from spherewarp.maps import Mobius
    from spherewarp.render import warp

    img = np.ones((16, 32, 3), dtype)
    img[6:9, 10:13] = 50_000.0
    m = Mobius.from_yaw_pitch_roll(7.3, 3.1, 1.7)
    for method in ("fast", "reference"):
        out = warp(img, m, interp="bicubic", antialias="none", method=method)
        assert out.min() >= 1.0 and out.max() <= 50_000.0, method
    rng = np.random.default_rng(3)
    x, y = rng.uniform(0, 32, 500), rng.uniform(0.5, 15.5, 500)
    got = sample(img, x, y, "bicubic")
    assert got.min() >= 1.0
    smooth = 1 + np.sin(np.arange(32) * np.pi / 16)[None, :, None] + np.zeros((16, 32, 1))
    y = rng.uniform(3, 13, 500)  # away from the poles (a step: the fold's half turn)
    as_float = sample(smooth.astype(np.float32), x, y, "bicubic")
    as_int = sample(np.rint(smooth * 10_000).astype(np.uint16), x, y, "bicubic") / 10_000
    assert np.abs(as_float - as_int).max() < 1e-3  # the clamp is no blur
