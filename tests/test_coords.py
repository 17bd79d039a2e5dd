"""Coordinates: round trips, the default chart, and no NaN/inf in CP^1 arrays."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from spherewarp import coords
from spherewarp.errors import InvalidValueError
from tolerances import COORDS, PLANE_REL

PROPERTY = settings(max_examples=150, deadline=None)

# -- strategies: always give the special values a good chance -------------------------------
lon_deg = st.one_of(
    st.sampled_from([-180.0, 180.0, 0.0, 90.0, -90.0, 179.999999, -179.999999]),
    st.floats(-180.0, 180.0),
)
lat_deg = st.one_of(
    st.sampled_from([-90.0, 90.0, 0.0, 89.9999999, -89.9999999, 1e-12, -1e-12]),
    st.floats(-90.0, 90.0),
)
lonlat_rad = st.tuples(lon_deg, lat_deg).map(lambda t: np.radians(np.array(t)))
unit_xyz = st.one_of(
    st.sampled_from(
        [(0, 0, 1), (0, 0, -1), (1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (-1, -0.0, 0)]
    ),
    st.tuples(*[st.floats(-1, 1)] * 3).filter(lambda v: np.linalg.norm(v) > 1e-3),
).map(lambda v: np.asarray(v, float) / np.linalg.norm(v))
_magnitudes = st.one_of(
    st.sampled_from([0.0, 1.0, 1e-300, 1e300, 1e-12, 1e12, 5e-324, 1.7e308]),
    st.floats(-300, 300).map(lambda e: 10.0**e),
)
plane_points = st.one_of(
    st.sampled_from([0j, 1 + 0j, -1 + 0j, 1j, -1j, complex(np.inf, 0)]),
    st.tuples(_magnitudes, st.floats(-np.pi, np.pi)).map(lambda t: t[0] * np.exp(1j * t[1])),
    st.complex_numbers(allow_nan=False, allow_infinity=True),
)


def chordal(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Chordal half-distance between points given as unit pairs: |det| = sin(angle/2)."""
    return np.abs(p[..., 0] * q[..., 1] - p[..., 1] * q[..., 0])


def angle_diff(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """|a - b| modulo 2 pi, in [0, pi]."""
    return np.abs(np.angle(np.exp(1j * (np.asarray(a) - np.asarray(b)))))


def assert_cp1_clean(zw: np.ndarray) -> None:
    """Complex, (..., 2), finite, unit norm."""
    assert zw.dtype == np.complex128 and zw.shape[-1] == 2
    assert np.all(np.isfinite(zw))
    np.testing.assert_allclose(np.linalg.norm(zw, axis=-1), 1.0, rtol=0, atol=1e-15)


# -- the six marked points of the default chart --------------------------------------------
# (chart value, lon, lat, xyz)
MARKED = [
    (0j, 0.0, 90.0, (0, 0, 1)),  # zenith (the top row)
    (complex(np.inf, 0), 0.0, -90.0, (0, 0, -1)),  # nadir (the bottom row)
    (1 + 0j, 180.0, 0.0, (-1, 0, 0)),  # back
    (1j, -90.0, 0.0, (0, -1, 0)),  # lon -90
    (-1 + 0j, 0.0, 0.0, (1, 0, 0)),  # front
    (-1j, 90.0, 0.0, (0, 1, 0)),  # lon +90
]


@pytest.mark.parametrize(("z", "lon", "lat", "xyz"), MARKED)
def test_marked_points(z, lon, lat, xyz):
    ll = np.radians([lon, lat])
    xyz = np.asarray(xyz, float)
    # plane -> sphere
    np.testing.assert_allclose(coords.xyz_from_cp1(coords.cp1_from_plane(z)), xyz, atol=1e-15)
    # sphere -> plane: exact zero and infinity, the others to rounding
    for zw in (coords.cp1_from_xyz(xyz), coords.cp1_from_lonlat(ll)):
        w = complex(coords.plane_from_cp1(zw))
        if np.isinf(z):
            assert np.isinf(w)
        elif z == 0:
            assert w == 0
        else:
            assert abs(w - z) < 1e-15
    np.testing.assert_allclose(coords.xyz_from_lonlat(ll), xyz, atol=1e-15)


def test_marked_points_in_pixels():
    w, h = 1024, 512
    # top row is the zenith, bottom row the nadir, whatever the column
    x = np.linspace(0, w, 9)
    top = coords.cp1_from_lonlat(coords.lonlat_from_pixel(np.stack([x, 0 * x], -1), w, h))
    bottom = coords.cp1_from_lonlat(coords.lonlat_from_pixel(np.stack([x, h + 0 * x], -1), w, h))
    assert np.all(coords.plane_from_cp1(top) == 0)
    assert np.all(np.isinf(coords.plane_from_cp1(bottom)))
    # the middle row: back at both edges, i at a quarter, -1 at the centre, -i at three quarters
    x = np.array([0.0, w / 4, w / 2, 3 * w / 4, w])
    mid = coords.lonlat_from_pixel(np.stack([x, np.full(5, h / 2)], -1), w, h)
    z = coords.plane_from_cp1(coords.cp1_from_lonlat(mid))
    np.testing.assert_allclose(z, [1, 1j, -1, -1j, 1], atol=1e-15)


# -- the chart formula, written independently ------------------------------------------------
@PROPERTY
@given(lon=lon_deg, lat=st.floats(-89.9, 90.0))
@example(lon=180.0, lat=90.0)
@example(lon=-180.0, lat=-89.9)
def test_chart_formula(lon, lat):
    """z = tan((90 deg - lat)/2) * exp(i (lon + 180 deg)), the paper's labelling."""
    expected = np.tan(np.radians(90.0 - lat) / 2) * np.exp(1j * np.radians(lon + 180.0))
    ll = np.radians([lon, lat])
    for z in (coords.plane_from_lonlat(ll), coords.plane_from_cp1(coords.cp1_from_lonlat(ll))):
        assert abs(z - expected) <= PLANE_REL * max(1.0, abs(expected))


@PROPERTY
@given(xyz=unit_xyz)
def test_chart_is_stereographic_from_the_nadir(xyz):
    """z = -(x + iy) / (1 + z) on the unit sphere (projection from (0, 0, -1))."""
    zw = coords.cp1_from_xyz(xyz)
    if xyz[2] > -0.5:
        expected = -(xyz[0] + 1j * xyz[1]) / (1 + xyz[2])
        assert abs(coords.plane_from_cp1(zw) - expected) <= PLANE_REL * max(1, abs(expected))
    else:  # 1/z = -(x - iy)/(1 - z) is the well-conditioned form near the nadir
        expected_inv = -(xyz[0] - 1j * xyz[1]) / (1 - xyz[2])
        assert abs(zw[1] / zw[0] - expected_inv) <= PLANE_REL


# -- round trips ----------------------------------------------------------------------------
@PROPERTY
@given(
    h=st.integers(1, 8192),
    fx=st.one_of(st.sampled_from([0.0, 1.0, 0.5]), st.floats(0, 1)),
    fy=st.one_of(st.sampled_from([0.0, 1.0, 0.5]), st.floats(0, 1)),
)
def test_pixel_lonlat_round_trip(h, fx, fy):
    w = 2 * h
    p = np.array([fx * w, fy * h])
    ll = coords.lonlat_from_pixel(p, w, h)
    assert -np.pi <= ll[0] <= np.pi and -np.pi / 2 <= ll[1] <= np.pi / 2
    back = coords.pixel_from_lonlat(ll, w, h)
    np.testing.assert_allclose(back, p, rtol=0, atol=COORDS * w)
    np.testing.assert_allclose(coords.lonlat_from_pixel(back, w, h), ll, rtol=0, atol=COORDS)


def test_pixel_lonlat_conventions():
    w, h = 16, 8
    # pixel centres at half-integers; the edges are the seam and the poles
    corners = np.array([[0, 0], [w, h], [w / 2, h / 2], [0.5, 0.5]])
    ll = np.degrees(coords.lonlat_from_pixel(corners, w, h))
    np.testing.assert_allclose(ll[:3], [[-180, 90], [180, -90], [0, 0]], atol=1e-12)
    np.testing.assert_allclose(ll[3], [-180 + 360 / 32, 90 - 180 / 16], atol=1e-12)
    # vectorised over any leading shape
    grid = np.zeros((3, 4, 5, 2))
    assert coords.lonlat_from_pixel(grid, w, h).shape == (3, 4, 5, 2)


EDGES = [np.radians(v) for v in ([180, 90], [-180, -90], [-180, 0], [180, 0], [0, -90], [45, 90])]


def _with_edges(test):
    for ll in EDGES:
        test = example(ll=ll)(test)
    return test


@PROPERTY
@given(ll=lonlat_rad)
@_with_edges
def test_lonlat_xyz_round_trip(ll):
    xyz = coords.xyz_from_lonlat(ll)
    np.testing.assert_allclose(np.linalg.norm(xyz), 1.0, atol=1e-15)
    back = coords.lonlat_from_xyz(xyz)
    assert abs(back[1] - ll[1]) <= COORDS
    # longitude is meaningless at the poles and +-180 are the same meridian
    assert angle_diff(back[0], ll[0]) * np.cos(ll[1]) <= COORDS
    np.testing.assert_allclose(coords.xyz_from_lonlat(back), xyz, rtol=0, atol=COORDS)


@PROPERTY
@given(xyz=unit_xyz)
@example(xyz=np.array([0.0, 0.0, -1.0]))
@example(xyz=np.array([0.0, 0.0, 1.0]))
@example(xyz=np.array([-1.0, -0.0, 0.0]))
def test_xyz_cp1_round_trip(xyz):
    zw = coords.cp1_from_xyz(xyz)
    assert_cp1_clean(zw)
    np.testing.assert_allclose(coords.xyz_from_cp1(zw), xyz, rtol=0, atol=COORDS)
    # and cp1 -> xyz -> cp1, as points (a pair is only defined up to phase)
    assert chordal(coords.cp1_from_xyz(coords.xyz_from_cp1(zw)), zw) <= COORDS


@PROPERTY
@given(z=plane_points)
@example(z=complex(np.inf, 0))
@example(z=1e-300 + 0j)
@example(z=complex(1e300, -1e300))
@example(z=complex(1.7e308, 1.7e308))
def test_plane_cp1_round_trip(z):
    zw = coords.cp1_from_plane(z)
    assert_cp1_clean(zw)
    back = complex(coords.plane_from_cp1(zw))
    if not np.isfinite(z):
        assert np.isinf(back)
        assert chordal(zw, np.array([1, 0])) == 0
        return
    # as points of the sphere, always (even past 1e308, where z/w overflows to inf)
    assert chordal(coords.cp1_from_plane(back), zw) <= 1e-15
    z = complex(z)
    if z == 0:
        assert back == 0
    elif 1e-300 <= max(abs(z.real), abs(z.imag)) <= 1e300:
        assert abs(back / z - 1) <= PLANE_REL
    # cp1 -> plane -> cp1 as points
    assert chordal(coords.cp1_from_plane(coords.plane_from_cp1(zw)), zw) <= 1e-15


def test_plane_extremes_no_warnings():
    z = np.array([0, 5e-324, 1e-300, 1e300, 1.7e308, complex(1.7e308, -1.7e308), np.inf, -np.inf])
    z = np.append(z, [complex(np.inf, 1), complex(1, -np.inf), complex(np.nan, 0)])
    with np.errstate(all="raise", under="ignore"):
        zw = coords.cp1_from_plane(z)
        assert_cp1_clean(zw)
        back = coords.plane_from_cp1(zw)
    assert np.all(np.isinf(back[6:]))
    assert np.all(np.isfinite(back[:5]))


@PROPERTY
@given(ll=lonlat_rad)
@_with_edges
def test_cp1_from_lonlat_matches_xyz_route(ll):
    direct = coords.cp1_from_lonlat(ll)
    assert_cp1_clean(direct)
    via = coords.cp1_from_xyz(coords.xyz_from_lonlat(ll))
    np.testing.assert_allclose(coords.xyz_from_cp1(direct), coords.xyz_from_cp1(via), atol=COORDS)
    assert chordal(direct, via) <= COORDS


@PROPERTY
@given(ll=lonlat_rad)
@_with_edges
def test_lonlat_from_cp1(ll):
    zw = coords.cp1_from_lonlat(ll)
    back = coords.lonlat_from_cp1(zw)
    assert abs(back[1] - ll[1]) <= COORDS
    assert angle_diff(back[0], ll[0]) * np.cos(ll[1]) <= COORDS
    # the pair need not be normalised, nor its phase fixed
    scaled = zw * (3.5 * np.exp(0.7j))
    np.testing.assert_allclose(
        coords.xyz_from_lonlat(coords.lonlat_from_cp1(scaled)),
        coords.xyz_from_lonlat(ll),
        atol=COORDS,
    )
    # same as the route through xyz
    via = coords.lonlat_from_xyz(coords.xyz_from_cp1(zw))
    np.testing.assert_allclose(
        coords.xyz_from_lonlat(back), coords.xyz_from_lonlat(via), rtol=0, atol=COORDS
    )


@PROPERTY
@given(ll=lonlat_rad)
@_with_edges
def test_plane_lonlat_round_trip(ll):
    z = coords.plane_from_lonlat(ll)
    back = coords.lonlat_from_plane(z)
    np.testing.assert_allclose(
        coords.xyz_from_lonlat(back), coords.xyz_from_lonlat(ll), rtol=0, atol=COORDS
    )


@PROPERTY
@given(xyz=unit_xyz)
def test_antipode(xyz):
    zw = coords.cp1_from_xyz(xyz)
    anti = coords.antipode_cp1(zw)
    assert_cp1_clean(anti)
    np.testing.assert_allclose(coords.xyz_from_cp1(anti), -xyz, rtol=0, atol=COORDS)
    assert chordal(coords.antipode_cp1(anti), zw) <= 1e-15


def test_vectorised_shapes_and_no_nan():
    rng = np.random.default_rng(1)
    xyz = rng.normal(size=(4, 5, 3))
    xyz /= np.linalg.norm(xyz, axis=-1, keepdims=True)
    xyz[0, 0] = (0, 0, -1)
    xyz[0, 1] = (0, 0, 1)
    zw = coords.cp1_from_xyz(xyz)
    assert zw.shape == (4, 5, 2)
    assert_cp1_clean(zw)
    assert coords.xyz_from_cp1(zw).shape == (4, 5, 3)
    assert coords.lonlat_from_cp1(zw).shape == (4, 5, 2)
    assert coords.plane_from_cp1(zw).shape == (4, 5)
    assert coords.cp1_from_plane(coords.plane_from_cp1(zw)).shape == (4, 5, 2)
    ll = coords.lonlat_from_xyz(xyz)
    assert_cp1_clean(coords.cp1_from_lonlat(ll))


def test_normalize_cp1():
    out = coords.normalize_cp1([[3.0, 4.0j], [0.0, 0.0], [1e-320, 0.0], [1e300, 1e300]])
    assert_cp1_clean(out)
    np.testing.assert_allclose(out[0], [0.6, 0.8j])
    np.testing.assert_array_equal(out[1], [0, 1])  # no point at all -> the origin, no NaN


@pytest.mark.parametrize(
    ("text", "expected"),
    [("30,-45.5", (30.0, -45.5)), (" -180 , 90 ", (-180.0, 90.0)), ("0,-90", (0.0, -90.0))],
)
def test_parse_lonlat(text, expected):
    assert coords.parse_lonlat(text) == expected


@pytest.mark.parametrize("text", ["", "30", "1,2,3", "a,b", "0,91", "0,-90.5", "nan,0", "inf,0"])
def test_parse_lonlat_errors(text):
    with pytest.raises(InvalidValueError, match="LON,LAT|latitude"):
        coords.parse_lonlat(text)
