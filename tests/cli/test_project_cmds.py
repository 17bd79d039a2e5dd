"""spherewarp project --to/--from and --projection on the effect commands."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from _cli import run

DATA = Path(__file__).resolve().parents[2] / "src" / "spherewarp" / "data"


def _read(path):
    from spherewarp.io import read_image

    return read_image(path)


def test_project_to_and_from_cubemap(tmp_path):
    pano = tmp_path / "pano.png"
    from spherewarp.io import write_image

    src = _read(DATA / "interior.png").pixels[::4, ::4]
    write_image(pano, src)
    cube = tmp_path / "cube.png"
    code, out, err = run(None, "project", str(pano), "--to", "cubemap", "-o", str(cube))
    assert code == 0, err
    c = _read(cube)
    assert c.pixels.shape[:2] == (128, 192) and c.gpano is None
    back = tmp_path / "back.png"
    code, out, err = run(None, "project", str(cube), "--from", "cubemap", "-o", str(back))
    assert code == 0, err
    b = _read(back)
    assert b.pixels.shape == src.shape


def test_effect_with_projection_has_no_gpano(tmp_path):
    out = tmp_path / "planet.png"
    code, _, err = run(
        None, "zoom", str(DATA / "interior.png"), "--at", "0,-90", "--factor", "3",
        "--projection", "little-planet", "--size", "64x64", "-o", str(out),
    )  # fmt: skip
    assert code == 0, err
    img = _read(out)
    assert img.pixels.shape[:2] == (64, 64) and img.gpano is None
    assert np.ptp(img.pixels) > 0


def test_bad_view_options_give_one_line(tmp_path):
    for args in (
        ["project", str(DATA / "interior.png"), "-o", str(tmp_path / "a.png")],
        ["project", str(DATA / "interior.png"), "--to", "cubemap", "--fov", "90",
         "-o", str(tmp_path / "b.png")],
        ["rotate", str(DATA / "interior.png"), "--fov", "90", "-o", str(tmp_path / "c.png")],
        ["project", str(DATA / "interior.png"), "--to", "rectilinear", "--fov", "200",
         "-o", str(tmp_path / "d.png")],
    ):  # fmt: skip
        code, _, err = run(None, *args)
        assert code != 0
        assert len(err.strip().splitlines()) == 1 and "Traceback" not in err, err


def test_from_torus_is_refused_in_one_line(tmp_path):
    pic = tmp_path / "t.png"
    from spherewarp.io import write_image

    write_image(pic, np.zeros((16, 16, 3), np.uint8))
    code, _, err = run(None, "project", str(pic), "--from", "torus", "-o", str(tmp_path / "o.png"))
    assert code != 0 and len(err.strip().splitlines()) == 1
    assert "--from torus" in err
