"""Conformance: every registered map kind survives the trip and keeps its promises.

As scikit-image tests every transform it registers, this file runs one example
of every map kind (:data:`test_json_fresh.EXAMPLES`, which fails when a kind
lacks one) through the same checks:

- pickle round trip (a map goes to another process: Dask workers, recipes);
- JSON round trip (in a fresh interpreter: ``test_json_fresh``; here in-process,
  through :func:`~spherewarp.maps.map_from_json`, and pickle of the rebuilt map);
- the inverse, where the kind has one: ``m @ m.inverse()`` is the identity;
- ``local_scale`` against finite differences of ``pull_cp1`` (at smooth points);
- the fast (compiled) render against the float64 reference path.
"""

from __future__ import annotations

import pickle

import numpy as np
import pytest
from test_json_fresh import EXAMPLES, NOT_READABLE, _registered_kinds

from spherewarp import coords, map_from_json, warp
from spherewarp.errors import InvalidValueError
from spherewarp.maps.base import _tangent_frame

KINDS = sorted(EXAMPLES)


def _points() -> np.ndarray:
    lon, lat = np.meshgrid(np.linspace(-171, 169, 17), np.linspace(-77, 79, 9))
    return coords.cp1_from_lonlat(np.radians(np.stack([lon, lat], axis=-1))).reshape(-1, 2)


def _same_pull(a, b, zw) -> None:
    pa, pb = a.pull(zw), b.pull(zw)
    np.testing.assert_allclose(
        coords.xyz_from_cp1(pb.points), coords.xyz_from_cp1(pa.points), atol=1e-10
    )
    for field in ("sheet", "valid"):
        x, y = getattr(pa, field), getattr(pb, field)
        assert (x is None) == (y is None), field
        if x is not None:
            np.testing.assert_array_equal(x, y)


def test_every_kind_is_covered():
    assert _registered_kinds() - NOT_READABLE <= set(KINDS)


@pytest.mark.parametrize("kind", KINDS)
def test_pickle_round_trip(kind):
    m = EXAMPLES[kind]()
    back = pickle.loads(pickle.dumps(m))
    assert type(back) is type(m) and back.kind == kind
    _same_pull(m, back, _points())


@pytest.mark.parametrize("kind", KINDS)
def test_json_round_trip_then_pickle(kind):
    m = EXAMPLES[kind]()
    back = map_from_json(m.to_json())
    assert back.kind == kind  # (the text may differ in the last bits: matrices are renormalised)
    _same_pull(m, back, _points())
    _same_pull(m, pickle.loads(pickle.dumps(back)), _points())


def _round_trip(first, then, zw: np.ndarray) -> np.ndarray:
    """Distance of ``then(first(p))`` from ``p``, at the points ``first`` is defined."""
    mid = first.pull(zw)
    back = then.pull_cp1(mid.points)
    d = np.linalg.norm(coords.xyz_from_cp1(back) - coords.xyz_from_cp1(zw), axis=-1)
    return d if mid.valid is None else d[mid.valid]


@pytest.mark.parametrize("kind", KINDS)
def test_inverse_where_there_is_one(kind):
    m = EXAMPLES[kind]()
    try:
        inv = m.inverse()
    except InvalidValueError:
        pytest.skip(f"{kind} has no single-valued inverse")
    zw = _points()
    # m after its inverse is the identity; for a branched map the inverse is one branch
    # (a root, a logarithm), so only one of the two orders holds everywhere
    right, left = _round_trip(inv, m, zw), _round_trip(m, inv, zw)
    assert right.size > len(zw) // 2 and left.size > len(zw) // 2
    assert right.max() < 1e-9 or left.max() < 1e-9, (right.max(), left.max())
    if m.as_mobius() is not None:
        assert right.max() < 1e-9 and left.max() < 1e-9


def _fd_scale(m, zw: np.ndarray, h: float) -> np.ndarray:
    """sqrt of the area ratio of ``pull_cp1`` by central differences of step ``h``."""
    xyz = coords.xyz_from_cp1(zw)
    cols = []
    for t in _tangent_frame(xyz):
        plus = coords.xyz_from_cp1(m.pull_cp1(coords.cp1_from_xyz(xyz + h * t)))
        minus = coords.xyz_from_cp1(m.pull_cp1(coords.cp1_from_xyz(xyz - h * t)))
        cols.append((plus - minus) / (2 * h))
    return np.sqrt(np.linalg.norm(np.cross(cols[0], cols[1]), axis=-1))


@pytest.mark.parametrize("kind", KINDS)
def test_local_scale_against_finite_differences(kind):
    m = EXAMPLES[kind]()
    zw = _points()
    with np.errstate(all="ignore"):
        fine, coarse = _fd_scale(m, zw, 1e-5), _fd_scale(m, zw, 2e-5)
        scale = np.asarray(m.local_scale(zw), dtype=np.float64)
    # smooth points: the two steps agree (no seam, branch point or jump between the taps)
    smooth = np.isfinite(fine) & np.isfinite(coarse) & (fine > 1e-6) & (fine < 1e6)
    smooth &= np.abs(fine - coarse) <= 1e-4 * fine
    assert smooth.mean() > 0.5, f"{kind}: only {smooth.sum()} smooth points"
    np.testing.assert_allclose(scale[smooth], fine[smooth], rtol=1e-6)


@pytest.mark.parametrize("kind", KINDS)
def test_fast_render_matches_the_reference(kind):
    m = EXAMPLES[kind]()
    yy, xx = np.mgrid[0:32, 0:64]
    img = 128 + 100 * np.sin(xx * 2 * np.pi / 64) * np.cos(yy * np.pi / 32)
    img = np.repeat(img.astype(np.float32)[..., None], 3, axis=-1)
    images = [img] * m.n_sheets if m.n_sheets > 1 else img
    fast = warp(images, m, method="fast", antialias="none")
    ref = warp(images, m, method="reference", antialias="none")
    assert fast.shape == ref.shape
    diff = np.abs(fast.astype(np.float64) - ref)
    assert np.mean(diff > 0.5) < 0.01, f"{kind}: {np.mean(diff > 0.5):.2%} pixels differ"
    assert np.median(diff) < 1e-3


def test_expression_map_pickles_with_any_chart():
    from spherewarp.maps import ExpressionMap, Mobius

    for chart in ("zenith", "front", Mobius.zoom((10, 20), 2.0)):
        m = ExpressionMap("sin(z) + z**2/3", chart=chart)
        back = pickle.loads(pickle.dumps(m))
        assert back == m
        _same_pull(m, back, _points())
