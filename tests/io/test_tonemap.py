"""Tone mapping, alpha flattening and colours (spherewarp.io.tonemap)."""

from __future__ import annotations

import numpy as np
import pytest

from spherewarp.errors import InvalidTypeError, InvalidValueError
from spherewarp.io import convert_dtype
from spherewarp.io.tonemap import (
    DEFAULT_TONEMAP,
    TONEMAPS,
    flatten_alpha,
    linear_to_srgb,
    parse_color,
    tonemap,
)

RAMP = np.geomspace(1e-4, 1e4, 200, dtype=np.float32).reshape(1, -1, 1)


@pytest.mark.parametrize("method", TONEMAPS)
def test_tonemap_is_monotone_in_range_and_keeps_black(method: str) -> None:
    out = tonemap(np.concatenate([np.zeros((1, 1, 1), np.float32), RAMP], axis=1), method)
    assert out.dtype == np.float32 and out.shape == (1, 201, 1)
    v = out.ravel()
    assert v[0] == 0.0
    assert np.all(np.diff(v) >= 0) and v.min() >= 0.0 and v.max() <= 1.0


def test_aces_rolls_highlights_off_where_clip_cuts_them() -> None:
    px = np.array([[[2.0], [4.0]]], np.float32)
    clip, aces = tonemap(px, "clip").ravel(), tonemap(px, "aces").ravel()
    assert clip.tolist() == [1.0, 1.0]  # both cut to white
    assert aces[0] < aces[1] < 1.0  # still told apart


def test_default_and_reinhard_never_reach_white_below_infinity() -> None:
    assert DEFAULT_TONEMAP == "aces"
    assert tonemap(np.full((1, 1, 1), 1e3, np.float32), "reinhard")[0, 0, 0] < 1.0


def test_exposure_is_stops() -> None:
    px = np.full((1, 1, 3), 0.1, np.float32)
    assert np.allclose(tonemap(px, "clip", exposure=1), tonemap(px * 2, "clip"))


def test_alpha_is_clipped_not_tone_mapped_and_nan_inf_are_safe() -> None:
    px = np.array([[[np.nan, np.inf, -1.0, 1.5]]], np.float32)
    out = tonemap(px, "aces")
    assert np.all(np.isfinite(out))
    assert out[0, 0, 0] == 0.0 and out[0, 0, 1] == 1.0 and out[0, 0, 2] == 0.0
    assert out[0, 0, 3] == 1.0


def test_srgb_transfer_matches_the_standard() -> None:
    # 8-bit sRGB of linear 0.5 is 188 (IEC 61966-2-1)
    assert convert_dtype(linear_to_srgb(np.float32([0.5])), np.uint8).tolist() == [188]


def test_tonemap_refuses_bad_input() -> None:
    with pytest.raises(InvalidTypeError):
        tonemap(np.zeros((2, 2, 3), np.uint8))
    with pytest.raises(InvalidValueError, match="unknown tone map"):
        tonemap(np.zeros((2, 2, 3), np.float32), "filmic")
    with pytest.raises(InvalidValueError):
        tonemap(np.zeros((2, 2, 3), np.float32), exposure=float("nan"))


@pytest.mark.parametrize("dtype", [np.uint8, np.uint16, np.float32])
def test_flatten_alpha_composites_straight_alpha(dtype: type) -> None:
    top = 1.0 if np.dtype(dtype).kind == "f" else np.iinfo(dtype).max
    px = np.zeros((1, 3, 4), dtype)
    px[0, :, 0] = top  # red
    px[0, :, 3] = np.array([0.0, 0.5, 1.0]) * top
    out = flatten_alpha(px, "white").astype(np.float64) / top
    assert out.shape == (1, 3, 3) and out.dtype == np.float64
    assert np.allclose(out[0, 0], [1, 1, 1]) and np.allclose(out[0, 2], [1, 0, 0])
    assert np.allclose(out[0, 1], [1, 0.5, 0.5], atol=1 / 255)
    assert flatten_alpha(px, "black").dtype == dtype


def test_flatten_alpha_grey_and_no_alpha() -> None:
    la = np.array([[[0, 0]]], np.uint8)
    assert flatten_alpha(la, "white").tolist() == [[[255]]]
    rgb = np.zeros((1, 1, 3), np.uint8)
    assert flatten_alpha(rgb, "white") is rgb


def test_parse_color() -> None:
    assert parse_color("Black") == (0.0, 0.0, 0.0)
    assert parse_color("#FFF") == (1.0, 1.0, 1.0)
    for bad in ("#12345", "mauve", "#gg0000", ""):
        with pytest.raises(InvalidValueError, match="colour"):
            parse_color(bad)


def test_cli_lists_the_same_tonemaps() -> None:
    from spherewarp.cli._common import _TONEMAPS

    assert _TONEMAPS == TONEMAPS
