"""The degree forms of the coordinate conversions agree with the radian ones."""

from __future__ import annotations

import numpy as np

from spherewarp import coords
from spherewarp.maps import Mobius


def test_degree_forms_match_radian_forms():
    rng = np.random.default_rng(1)
    ll_deg = np.stack([rng.uniform(-179, 179, 50), rng.uniform(-89, 89, 50)], axis=-1)
    zw = coords.cp1_from_lonlat_deg(ll_deg)
    np.testing.assert_allclose(zw, coords.cp1_from_lonlat(np.radians(ll_deg)), atol=1e-15)
    np.testing.assert_allclose(coords.lonlat_deg_from_cp1(zw), ll_deg, atol=1e-9)
    px = coords.pixel_from_lonlat_deg(ll_deg, 1024, 512)
    np.testing.assert_allclose(px, coords.pixel_from_lonlat(np.radians(ll_deg), 1024, 512))
    np.testing.assert_allclose(coords.lonlat_deg_from_pixel(px, 1024, 512), ll_deg, atol=1e-9)


def test_degrees_round_trip_with_the_maps_points():
    """Maps take points in degrees; lonlat_deg_from_cp1 gives them back in degrees."""
    m = Mobius.rotation_to((30.0, 10.0), (-60.0, 20.0))
    out = coords.lonlat_deg_from_cp1(m.pull_cp1(coords.cp1_from_lonlat_deg([30.0, 10.0])))
    np.testing.assert_allclose(out, [-60.0, 20.0], atol=1e-9)
