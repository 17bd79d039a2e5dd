"""Toroidal images and the textured torus mesh."""

from __future__ import annotations

import math

import numpy as np
import pytest

from spherewarp import coords
from spherewarp.effects.torus import (
    parse_cells,
    render_torus,
    render_torus_texture,
    torus_mesh,
    write_torus_obj,
)
from spherewarp.errors import InvalidValueError, OutputExistsError


def test_square_cell_holds_two_copies_and_its_branch_points(smooth_image):
    img = smooth_image(64)  # value 0.5 + 0.5 xyz
    n = 65  # odd: pixel centres at the centre and the midpoints of the sides
    cell = render_torus(img, "square", width=n)
    assert cell.shape == (n, n, 3)
    # two copies: p~(-u) = p~(u), so the cell is symmetric under a half-turn about its centre
    assert np.max(np.abs(cell - cell[::-1, ::-1])) < 1e-6
    c = n // 2

    def colour(lon, lat):
        return 0.5 + 0.5 * coords.xyz_from_lonlat(np.radians([lon, lat]))

    tol = 5e-3
    np.testing.assert_allclose(cell[c, c], colour(0, 90), atol=tol)  # zenith at the centre
    np.testing.assert_allclose(cell[c, -1], colour(0, 0), atol=tol)  # front at u = i/2 (+1)
    np.testing.assert_allclose(cell[0, c], colour(180, 0), atol=tol)  # back at u = 1/2 (+i)
    np.testing.assert_allclose(cell[-1, -1], colour(0, -90), atol=0.02)  # nadir at a corner


def test_windows_of_several_cells_are_periodic(random_image):
    img = random_image(32)
    two = render_torus(img, "square", cells=(2, 1), width=64)
    assert two.shape == (32, 64, 3)
    assert np.max(np.abs(two[:, :32].astype(int) - two[:, 32:])) <= 1
    hexa = render_torus(img, "hex", cells="2x2", width=80)
    assert hexa.shape == (round(80 * math.sqrt(3) / 2), 80, 3)
    assert np.max(np.abs(hexa[:, :40].astype(int) - hexa[:, 40:])) <= 1


@pytest.mark.parametrize("lattice", ["square", "hex"])
def test_texture_repeats_in_both_directions(lattice, random_image):
    img = random_image(32)
    tex = render_torus_texture(img, lattice, cells=(2, 2), size=(40, 60))
    assert tex.shape == (40, 60, 3)
    assert np.max(np.abs(tex[:, :30].astype(int) - tex[:, 30:])) <= 1
    assert np.max(np.abs(tex[:20].astype(int) - tex[20:])) <= 1
    if lattice == "square":
        direct = render_torus(img, "square", cells=(2, 2), width=60)
        assert direct.shape == (60, 60, 3)


def test_hex_cell_is_conformal_and_threefold(smooth_image):
    img = smooth_image(64)
    out = render_torus(img, "hex", width=120, supersample=2)
    assert out.dtype == np.float32 and np.all(np.isfinite(out))
    assert out.shape == (round(120 * math.sqrt(3) / 2), 120, 3)


def test_dtypes_are_kept(random_image, interior):
    for dtype in (np.uint8, np.uint16, np.float32):
        img = random_image(16, dtype=dtype)
        assert render_torus(img, width=20).dtype == dtype
    out = render_torus(interior[::8, ::8], "hex", cells=(1, 2), interp="bicubic")
    assert out.dtype == np.uint8 and out.shape[1] == 128


def test_mesh_is_a_closed_outward_torus():
    m = torus_mesh(2.0, 0.5, (24, 12))
    assert m.vertices.shape == (25 * 13, 3) and m.faces.shape == (2 * 24 * 12, 3)
    assert np.all((m.uv >= 0) & (m.uv <= 1))
    a, b, c = (m.vertices[m.faces[:, k]] for k in range(3))
    normal = np.cross(b - a, c - a)
    centre = (a + b + c) / 3
    ring = centre.copy()
    ring[:, 2] = 0
    ring *= (2.0 / np.linalg.norm(ring, axis=1))[:, None]  # nearest point of the core circle
    assert np.all(np.einsum("ij,ij->i", normal, centre - ring) > 0)  # counter-clockwise outside
    np.testing.assert_allclose(np.linalg.norm(m.normals, axis=1), 1.0)
    with pytest.raises(InvalidValueError):
        torus_mesh(1.0, 2.0)


def test_obj_mtl_and_texture_files(tmp_path, random_image):
    from spherewarp.io import read_image

    tex = render_torus_texture(random_image(16), "hex")
    obj, mtl, png = write_torus_obj(tmp_path / "donut.obj", tex, lattice="hex", segments=(16, 8))
    lines = obj.read_text().splitlines()
    assert lines[1] == "mtllib donut.mtl"
    counts = {k: sum(1 for line in lines if line.startswith(k + " ")) for k in ("v", "vt", "vn")}
    assert counts == {"v": 17 * 9, "vt": 17 * 9, "vn": 17 * 9}
    faces = [line for line in lines if line.startswith("f ")]
    assert len(faces) == 2 * 16 * 8
    idx = np.array([[int(p.split("/")[0]) for p in f.split()[1:]] for f in faces])
    assert idx.min() == 1 and idx.max() == 17 * 9
    assert "map_Kd donut_texture.png" in mtl.read_text()
    assert png.name == "donut_texture.png"
    np.testing.assert_array_equal(read_image(png).pixels, tex)
    with pytest.raises(OutputExistsError):
        write_torus_obj(obj, tex)
    write_torus_obj(obj, tex, overwrite=True)
    with pytest.raises(InvalidValueError, match=".obj"):
        write_torus_obj(tmp_path / "donut.stl", tex)


def test_cells_and_arguments_are_checked(random_image):
    assert parse_cells("3") == (3, 3)
    assert parse_cells((2, 1)) == (2, 1)
    for bad in ("0x1", "2x", "axb", "17x1", (1, 2, 3)):
        with pytest.raises(InvalidValueError, match="cells"):
            parse_cells(bad)
    img = random_image(16)
    with pytest.raises(InvalidValueError, match="lattice"):
        render_torus(img, "triangle")
    with pytest.raises(InvalidValueError, match="width"):
        render_torus(img, width=1)
    with pytest.raises(InvalidValueError, match="supersample"):
        render_torus(img, supersample=0)
