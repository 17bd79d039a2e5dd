"""The map protocol: SphereMap defaults, Composite, PullBack, the registry and plain data."""

from __future__ import annotations

import json

import numpy as np
import pytest

from spherewarp import coords
from spherewarp.errors import InvalidTypeError, InvalidValueError
from spherewarp.maps import (
    Composite,
    Mobius,
    PullBack,
    SphereMap,
    map_from_dict,
    map_from_json,
    register_map,
)
from spherewarp.maps.base import vectorize_plane_function
from tolerances import FINITE_DIFFERENCE_REL, POINTS


class Square(SphereMap):
    """z -> z**2: holomorphic, not Möbius, no inverse; default local scale."""

    def pull_cp1(self, zw):
        zw = np.asarray(zw, dtype=np.complex128)
        return coords.normalize_cp1(zw**2)


@register_map
class Halves(SphereMap):
    """Identity, marking the back half of the sphere undefined and the south on sheet 1."""

    kind = "test-base-halves"
    n_sheets = 2

    def pull_cp1(self, zw):
        return np.asarray(zw, dtype=np.complex128)

    def pull(self, zw):
        xyz = coords.xyz_from_cp1(zw)
        return PullBack(
            self.pull_cp1(zw), sheet=(xyz[..., 2] < 0).astype(np.intp), valid=xyz[..., 0] > 0
        )

    def params(self):
        return {}

    def inverse(self):
        return self


def _points(n: int = 50, seed: int = 3) -> np.ndarray:
    v = np.random.default_rng(seed).normal(size=(n, 3))
    v = np.concatenate([v, [(0, 0, 1), (0, 0, -1), (-1, 0, 0)]])
    return coords.cp1_from_xyz(v / np.linalg.norm(v, axis=-1, keepdims=True))


def chordal(p, q):
    p, q = coords.normalize_cp1(p), coords.normalize_cp1(q)
    return np.abs(p[..., 0] * q[..., 1] - p[..., 1] * q[..., 0])


def test_abstract():
    with pytest.raises(TypeError):
        SphereMap()  # type: ignore[abstract]


def test_defaults():
    s = Square()
    p = _points()
    pb = s.pull(p)
    assert isinstance(pb, PullBack) and pb.sheet is None and pb.valid is None
    assert chordal(pb.points, p**2).max() < 1e-15
    assert s.as_mobius() is None
    assert s.n_sheets == 1
    with pytest.raises(InvalidValueError, match="inverse"):
        s.inverse()
    with pytest.raises(NotImplementedError):
        s.to_dict()


def test_conveniences():
    m = Mobius.zoom((30, 20), 2.0)
    z = np.array([0, 1, 1j, -1, 0.3 - 0.2j, np.inf])
    w = m(z)
    assert w.shape == z.shape and w.dtype == np.complex128
    xyz = coords.xyz_from_cp1(coords.cp1_from_plane(z))
    np.testing.assert_allclose(
        m.apply_xyz(xyz), coords.xyz_from_cp1(coords.cp1_from_plane(w)), atol=1e-12
    )
    ll = np.degrees(coords.lonlat_from_xyz(xyz[2:5]))
    np.testing.assert_allclose(
        coords.xyz_from_lonlat(np.radians(m.apply_lonlat(ll))), m.apply_xyz(xyz[2:5]), atol=1e-12
    )
    # Square at infinity: inf**2 = inf; at the back: 1
    sq = Square()
    out = sq(np.array([np.inf, 1.0, 0.0]))
    assert np.isinf(out[0]) and out[1] == 1 and out[2] == 0


def test_local_scale_finite_difference():
    """Default estimate vs |S'(z)| (1 + |z|^2) / (1 + |S(z)|^2) for S(z) = z**2."""
    p = _points()
    z = coords.plane_from_cp1(p)
    ok = np.abs(z) < 1e3
    r = np.abs(z[ok])
    exact = 2 * r * (1 + r**2) / (1 + r**4)
    est = Square().local_scale(p)
    assert est.shape == p.shape[:-1] and np.all(np.isfinite(est))
    np.testing.assert_allclose(est[ok], exact, rtol=FINITE_DIFFERENCE_REL)
    # at the critical points 0 and infinity the scale is 0
    assert Square().local_scale(coords.cp1_from_plane(np.array([0, np.inf]))).max() < 1e-5


def test_composite_flattens_and_applies():
    f, g, h = Mobius.zoom((10, 0), 2), Square(), Mobius.rotation((0, 90), 40)
    c = f @ g
    assert isinstance(c, Composite) and c.maps == (f, g)
    d = c @ h
    assert isinstance(d, Composite) and d.maps == (f, g, h)  # flattened
    assert (h @ c).maps == (h, f, g)
    p = _points()
    expected = f.pull_cp1(g.pull_cp1(h.pull_cp1(p)))
    assert chordal(d.pull_cp1(p), expected).max() < POINTS
    z = np.array([0.2 + 0.1j, 3.0, -1j])
    np.testing.assert_allclose(d(z), f(g(h(z))), rtol=1e-12)
    # Mobius @ Mobius stays Mobius; a composite of Möbius maps knows it is one
    assert isinstance(f @ h, Mobius)
    assert Composite((f, h)).as_mobius() == f @ h
    assert d.as_mobius() is None
    # local scale: chain rule against the flat finite-difference estimate
    np.testing.assert_allclose(d.local_scale(p), _fd_scale(d, p), rtol=1e-5, atol=1e-5)


def _fd_scale(m: SphereMap, p: np.ndarray) -> np.ndarray:
    class Plain(SphereMap):
        def pull_cp1(self, zw):
            return m.pull_cp1(zw)

    return Plain().local_scale(p)


def test_composite_inverse():
    f, h = Mobius.zoom((10, 0), 2), Mobius.rotation((0, 90), 40)
    c = Composite((f, h))
    p = _points()
    assert chordal(c.inverse().pull_cp1(c.pull_cp1(p)), p).max() < POINTS
    with pytest.raises(InvalidValueError):
        Composite((f, Square())).inverse()


def test_composite_validation():
    with pytest.raises(InvalidValueError):
        Composite(())
    with pytest.raises(InvalidTypeError):
        Composite((Mobius.identity(), "zoom"))
    c = Composite((Mobius.zoom((0, 0), 2).to_dict(), Mobius.identity()))  # dicts accepted
    assert isinstance(c.maps[0], Mobius)
    with pytest.raises(TypeError):
        Mobius.identity() @ 3  # foreign operands: NotImplemented -> TypeError
    with pytest.raises(TypeError):
        3 @ Mobius.identity()


def test_composite_sheets_and_holes():
    halves = Halves()
    rot = Mobius.rotation((0, 90), 180)  # front <-> back
    c = Composite((rot, halves))  # halves first: validity judged before the turn
    assert c.n_sheets == 2
    p = _points()
    xyz = coords.xyz_from_cp1(p)
    pb = c.pull(p)
    np.testing.assert_array_equal(pb.valid, xyz[..., 0] > 0)
    np.testing.assert_array_equal(pb.sheet, (xyz[..., 2] < 0).astype(int))
    # halves applied last: validity judged on the turned points
    pb = Composite((halves, rot)).pull(p)
    np.testing.assert_array_equal(pb.valid, xyz[..., 0] < 0)
    # two hole maps: defined where both are
    pb = Composite((halves, rot, halves)).pull(p)
    assert not np.any(pb.valid)


def test_registry_and_plain_data():
    h = Halves()
    assert h.to_dict() == {"kind": "test-base-halves"}
    assert isinstance(map_from_dict({"kind": "TEST-base-halves"}), Halves)
    c = Composite((Mobius.zoom((10, 20), 3), h))
    back = map_from_json(c.to_json())
    assert isinstance(back, Composite) and isinstance(back.maps[1], Halves)
    assert json.loads(c.to_json())["maps"][0]["kind"] == "mobius"
    with pytest.raises(InvalidValueError, match="test-base-halves"):
        map_from_dict({"kind": "nope"})  # lists the allowed kinds
    with pytest.raises(InvalidValueError):
        map_from_dict({"kind": "test-base-halves", "unexpected": 1})
    with pytest.raises(InvalidValueError):
        map_from_json("[1, 2")
    with pytest.raises(InvalidValueError):
        map_from_json("42")


def test_register_twice_or_empty():
    with pytest.raises(RuntimeError):

        @register_map
        class Again(SphereMap):  # noqa: F841 - same kind, another class
            kind = "test-base-halves"

            def pull_cp1(self, zw):
                return zw

    with pytest.raises(RuntimeError):

        @register_map
        class Nameless(SphereMap):  # noqa: F841
            def pull_cp1(self, zw):
                return zw

    assert register_map(Halves) is Halves  # re-registering the same class is harmless


def test_repr():
    assert repr(Halves()) == "Halves()"
    text = repr(Composite((Mobius.identity(), Halves())))
    assert text.startswith("Composite(maps=[") and "test-base-halves" in text


def test_vectorize_plane_function():
    pull = vectorize_plane_function(lambda z: 1 / z)
    p = coords.cp1_from_plane(np.array([0, 2, np.inf, 1j]))
    out = pull(p)
    assert np.all(np.isfinite(out))
    np.testing.assert_allclose(coords.plane_from_cp1(out)[1:], [0.5, 0, -1j], atol=1e-15)
    assert np.isinf(coords.plane_from_cp1(out)[0])  # 1/0 -> infinity, no NaN
    nan_pull = vectorize_plane_function(lambda z: z * np.nan)
    assert np.all(np.isfinite(nan_pull(p)))
