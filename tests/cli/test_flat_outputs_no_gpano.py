"""Outputs that are not equirectangular panoramas (Peirce squares, toroidal images and
their mesh textures) carry no GPano metadata, so no viewer shows them as 360° images."""

from __future__ import annotations

import numpy as np
from _cli import ok

from spherewarp.io import GPano, read_image, write_image


def test_peirce_torus_and_texture_carry_no_gpano(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    px = np.random.default_rng(0).integers(0, 255, (32, 64, 3), dtype=np.uint8)
    write_image("in.png", px, gpano=GPano(full_width=64, full_height=32, pose_heading=10.0))
    ok(None, "peirce", "in.png", "--size", "32", "-o", "p.png")
    ok(None, "torus", "in.png", "--size", "64", "-o", "t.jpg", "--mesh", "m.obj")
    ok(None, "torus", "in.png", "--cells", "2x1", "--size", "64", "-o", "t2.png")
    for name in ("p.png", "t.jpg", "m_texture.png", "t2.png"):
        assert read_image(name).gpano is None, name
