"""``spherewarp lattes``, ``fit-rational``, ``peirce`` and ``torus`` against the Python API."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from _cli import fails, ok, run  # noqa: F401

from spherewarp.effects.torus import render_torus, render_torus_texture
from spherewarp.grids.peirce import peirce_to_equirect, render_peirce
from spherewarp.io import read_image, write_image
from spherewarp.maps import Lattes, Rational, map_from_dict
from spherewarp.render import warp


@pytest.fixture
def pano(workdir: Path, random_image) -> tuple[Path, np.ndarray]:
    img = random_image(32, seed=3)
    return write_image(workdir / "in.png", img), img


# ---------------------------------------------------------------------- lattes
def test_lattes_print_gives_the_papers_map(capsys):
    data = json.loads(ok(capsys, "lattes", "--lattice", "square", "--alpha", "1+1j", "--print-map"))
    assert data["degree"] == 2 and data["residual"] < 1e-12
    np.testing.assert_allclose(data["numerator"], [[0, -0.5], [0, 0], [0, 0.5]], atol=1e-12)
    assert data["denominator"] == [[1.0, 0.0], [0.0, 0.0]]
    assert map_from_dict(data) == Rational([-0.5j, 0, 0.5j], [1, 0])
    hexa = json.loads(ok(capsys, "lattes", "--lattice", "HEX", "--alpha", "1+w", "--print-map"))
    assert hexa["degree"] == 3 and len(hexa["numerator"]) == 4


def test_lattes_renders_like_the_api(capsys, workdir, pano):
    path, img = pano
    assert "wrote out.png" in ok(capsys, "lattes", path, "--alpha", "2+1j", "-o", "out.png")
    np.testing.assert_array_equal(read_image("out.png").pixels, warp(img, Lattes("2+1j")))
    ok(capsys, "lattes", path, "--lattice", "hex", "--alpha", "2-w", "--exact", "-o", "h.png")
    expected = warp(img, Lattes("2-w", "hex"))
    assert np.max(np.abs(read_image("h.png").pixels.astype(int) - expected)) <= 1


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--lattice", "hex", "--alpha", "1+1j", "--print"], "Eisenstein integer"),
        (["--alpha", "1+w", "--print"], "Gaussian integer"),
        (["--alpha", "0.5", "--print"], "Gaussian integer"),
        (["--alpha", "8+1j", "--print"], "<= 64"),
        (["--alpha", "8", "--print-map"], "<= 49"),
        (["--alpha", "2"], "missing INPUT"),
        (["--lattice", "triangle", "--alpha", "2", "--print"], "triangle"),
    ],
)
def test_lattes_errors_are_one_line(capsys, args, message):
    assert message in fails(capsys, "lattes", *args)


# ---------------------------------------------------------------------- fit-rational
def test_fit_rational_prints_json(capsys):
    pytest.importorskip("spherewarp.maps.expression")
    data = json.loads(ok(capsys, "fit-rational", "--expr", "(z**2 + 1)**2 / (4*z*(z**2 - 1))"))
    assert data["degree"] == 4
    np.testing.assert_allclose(
        np.array(data["numerator"]) * 4, [[1, 0], [0, 0], [2, 0], [0, 0], [1, 0]], atol=1e-10
    )
    np.testing.assert_allclose(data["denominator"], [[1, 0], [0, 0], [-1, 0], [0, 0]], atol=1e-10)
    data = json.loads(ok(capsys, "fit-rational", "--expr", "z**3 + 1/z", "--degree", "4"))
    assert data["degree"] == 4


def test_fit_rational_refuses_what_is_not_rational(capsys):
    pytest.importorskip("spherewarp.maps.expression")
    assert "not a rational map" in fails(capsys, "fit-rational", "--expr", "exp(z)")
    assert "lower than 3" in fails(capsys, "fit-rational", "--expr", "z**2", "--degree", "3")
    assert "expression" in fails(capsys, "fit-rational", "--expr", "z.real")


# ---------------------------------------------------------------------- peirce
def test_peirce_forward_and_inverse(capsys, workdir, pano):
    path, img = pano
    ok(capsys, "peirce", path, "-o", "sq.png", "--size", "48")
    sq = read_image("sq.png")
    assert sq.gpano is None  # a square is not an equirectangular panorama
    np.testing.assert_array_equal(sq.pixels, render_peirce(img, 48))
    ok(capsys, "peirce", "sq.png", "--inverse", "-o", "back.png", "--size", "64x32")
    back = read_image("back.png").pixels
    np.testing.assert_array_equal(back, peirce_to_equirect(sq.pixels, (32, 64)))
    ok(capsys, "peirce", path, "-o", "sq30.png", "--lon0", "30", "--supersample", "2")
    assert read_image("sq30.png").pixels.shape == (48, 48, 3)  # default: 1.5 x height


def test_peirce_errors(capsys, workdir, pano):
    path, _ = pano
    assert "square" in fails(capsys, "peirce", path, "--inverse", "-o", "x.png")
    ok(capsys, "peirce", path, "-o", "sq.png")
    assert "exists" in fails(capsys, "peirce", path, "-o", "sq.png")
    assert "extension" in fails(capsys, "peirce", path, "-o", "sq.xyz")


# ---------------------------------------------------------------------- torus
def test_torus_image_and_mesh(capsys, workdir, pano):
    path, img = pano
    out = ok(
        capsys,
        "torus",
        path,
        "-o",
        "t.png",
        "--cells",
        "2x1",
        "--size",
        "40",
        "--mesh",
        "donut.obj",
    )
    for name in ("t.png", "donut.obj", "donut.mtl", "donut_texture.png"):
        assert f"wrote {name}" in out
        assert (workdir / name).exists()
    np.testing.assert_array_equal(
        read_image("t.png").pixels, render_torus(img, cells=(2, 1), width=40)
    )
    np.testing.assert_array_equal(
        read_image("donut_texture.png").pixels, render_torus_texture(img, cells=(2, 1))
    )
    ok(capsys, "torus", path, "-o", "h.png", "--lattice", "hex")
    assert read_image("h.png").pixels.shape == (round(64 * 3**0.5 / 2), 64, 3)


def test_torus_errors(capsys, workdir, pano):
    path, _ = pano
    assert "cells" in fails(capsys, "torus", path, "-o", "t.png", "--cells", "0x2")
    assert ".obj" in fails(capsys, "torus", path, "-o", "t.png", "--mesh", "m.stl")
    assert "without spaces" in fails(capsys, "torus", path, "-o", "t.png", "--mesh", "m m.obj")
    (workdir / "m.mtl").write_text("")
    assert "exists" in fails(capsys, "torus", path, "-o", "t.png", "--mesh", "m.obj")
    assert not (workdir / "t.png").exists()  # refused before anything was written
