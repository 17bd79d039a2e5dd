"""warp() and push() take the ImageData that read_image returns, as well as arrays."""

from __future__ import annotations

import numpy as np

import spherewarp as sw
from spherewarp.demo import sample_path
from spherewarp.maps import Mobius


def test_warp_accepts_image_data():
    data = sw.read_image(sample_path())
    view = Mobius.from_yaw_pitch_roll(yaw=30, pitch=-10)
    out = sw.warp(data, view, output_shape=(64, 128))
    assert isinstance(out, np.ndarray) and out.dtype == data.pixels.dtype
    np.testing.assert_array_equal(out, sw.warp(data.pixels, view, output_shape=(64, 128)))


def test_push_and_sheets_accept_image_data():
    data = sw.read_image(sample_path())
    zoom = Mobius.zoom((-163, 5), 3.0)
    np.testing.assert_array_equal(
        sw.push(data, zoom, output_shape=(32, 64)),
        sw.push(data.pixels, zoom, output_shape=(32, 64)),
    )
    court = sw.read_image(sample_path("courtyard.png"))
    from spherewarp.maps.sheeted import SheetedCover

    cover = SheetedCover(sw.Power(2), 2)
    np.testing.assert_array_equal(
        sw.warp([data, court], cover, output_shape=(32, 64)),
        sw.warp([data.pixels, court.pixels], cover, output_shape=(32, 64)),
    )
