"""``spherewarp schottky``: the command against the Python API, Droste, phase, errors."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
from _cli import fails, ok

from spherewarp.io import read_image, write_image
from spherewarp.maps import Schottky, map_from_json
from spherewarp.render import warp
from spherewarp.testpattern import make_test_pattern

W = 128
G1 = "-163,5,12 -> 17,-5,25"
G2 = "-75,10,15 -> 105,0,20"


@pytest.fixture
def pattern(workdir):
    pixels = make_test_pattern(W, labels=False)
    return write_image(workdir / "in.png", pixels), pixels


def _img(path):
    return read_image(path).pixels.astype(np.float64)


def test_matches_the_python_api(pattern):
    path, pixels = pattern
    ok(None, "schottky", path, "-o", "out.png", "--generator", G1, "--generator", G2)
    s = Schottky.from_disk_pairs([((-163, 5, 12), (17, -5, 25)), ((-75, 10, 15), (105, 0, 20))])
    assert np.array_equal(read_image("out.png").pixels, warp(pixels, s))


def test_print_round_trips_and_matrix_form(pattern):
    path, _ = pattern
    text = ok(None, "schottky", path, "--print-map", "--generator", "0,90,20:30,0,0,1")
    s = map_from_json(text)
    assert isinstance(s, Schottky)
    assert abs(s.target_disks()[0].lat + 90) < 1e-6


def test_one_generator_is_droste(pattern):
    path, _ = pattern
    lam, r = 10.0, 15.0
    far = 180 - math.degrees(2 * math.atan(lam * math.tan(math.radians(r / 2))))
    gen = f"-163,5,{r} -> 17,-5,{far!r}"
    ok(None, "schottky", path, "-o", "s.png", "--generator", gen)
    ok(
        None,
        "droste",
        path,
        "-o",
        "d.png",
        "--center",
        "-163,5",
        "--inner-radius",
        r,
        "--scale",
        lam,
    )
    a, b = _img("s.png"), _img("d.png")
    diff = np.abs(a - b).max(axis=-1)
    assert (diff <= 3).mean() > 0.97  # the same picture; the two renderers differ at seams
    assert np.abs(a - b).mean() < 2


def test_phase_one_is_phase_zero(pattern):
    path, _ = pattern
    ok(None, "schottky", path, "-o", "p0.png", "--generator", G1)
    ok(None, "schottky", path, "-o", "p1.png", "--generator", G1, "--phase", "1")
    a, b = _img("p0.png"), _img("p1.png")
    assert (np.abs(a - b).max(axis=-1) <= 2).mean() > 0.99


def test_frames(pattern):
    path, _ = pattern
    out = ok(None, "schottky", path, "-o", "f.png", "--generator", G1, "--frames", "2")
    assert "2 frames" in out
    s = Schottky.from_disk_pairs([((-163, 5, 12), (17, -5, 25))], phase=0.5)
    assert np.array_equal(read_image("f_0001.png").pixels, warp(read_image(path).pixels, s))


@pytest.mark.parametrize(
    "args, message",
    [
        (["--generator", "0,0,20 -> 30,0,20"], "overlap by 10 degrees"),
        (["--generator", G1, "--generator", "-150,5,5 -> 90,0,10"], "overlap by"),
        (["--generator", "0,0,100 -> 180,0,10"], "--generator 1: .*hemisphere"),
        (["--generator", "0,0,20:1,0,0,1"], "hyperbolic"),
        (["--generator", "0,0,20"], "LON,LAT,R:a,b,c,d"),
        (["--generator", "0,0,20:30,0,0,1", "--twist", "10"], "--twist"),
        ([], "--generator"),
    ],
)
def test_errors_are_one_line(pattern, args, message):
    path, _ = pattern
    err = fails(None, "schottky", path, "-o", "e.png", *args)
    assert len(err.strip().splitlines()) == 1
    import re

    assert re.search(message, err), err


def test_mask_workflow(pattern):
    """--mask: the disks D_x are the mask's colours (exact by default, the paper's rule), the
    generators built from the round disks inside them; --regions round takes the round
    disks about them."""
    from spherewarp.maps import Mobius
    from spherewarp.maps.schottky import Cap, MaskRegions, cap_from_mask, generator_between

    path, pixels = pattern
    h, w = pixels.shape[:2]
    mask = np.zeros((h, w, 3), np.uint8)
    mask[26:38, 60:68] = (255, 0, 0)  # red: round lon 0, lat 0
    mask[10:16, 10:16] = (0, 255, 0)  # green: up and to the west
    write_image("mask.png", mask)
    args = ("--mask", "mask.png", "--target", "red", "170,0,20", "--target", "green", "100")
    ok(None, "schottky", path, "-o", "m.png", *args)
    ok(None, "schottky", path, "-o", "r.png", *args, "--regions", "round")

    def group(inside):
        red, green = (cap_from_mask(mask, c, inside=inside) for c in ((1, 0, 0), (0, 1, 0)))
        assert abs(red.lon) < 2 and abs(red.lat) < 2
        return Schottky(
            [
                (red, generator_between(red, Cap(170, 0, 20))),
                (green, Mobius.zoom((green.lon, green.lat), 100)),
            ]
        ).for_output(w)

    s = group(inside=False)  # --regions round: the disks round the regions
    exact = group(inside=True).with_mask_regions(MaskRegions(mask, [(1, 0, 0), (0, 1, 0)]))
    assert np.array_equal(read_image("m.png").pixels, warp(pixels, exact))
    assert np.array_equal(read_image("r.png").pixels, warp(pixels, s))
    assert not np.array_equal(read_image("m.png").pixels, read_image("r.png").pixels)
    printed = map_from_json(ok(None, "schottky", path, *args, "--print-map"))
    assert printed.regions is not None and printed == exact
    err = fails(None, "schottky", path, "-o", "g.png", *args, "--generator", G1)
    assert "--regions round" in err
    # a zoom by 30 about green: built from the small disk inside the green square, its D_X
    # reaches the red region (the round disks about the regions stay disjoint)
    weak = (*args[:-1], "30")
    err = fails(None, "schottky", path, "-o", "w.png", *weak)
    assert re.search(r"D_x of generator 1 .* and D_X of generator 2 .*overlap", err), err
    ok(None, "schottky", path, "-o", "w.png", *weak, "--regions", "round")
    err = fails(None, "schottky", path, "-o", "m2.png", "--mask", "mask.png", "--target",
                "blue", "3")  # fmt: skip
    assert "no pixel of the colour #0000ff" in err
    assert "--target goes with --mask" in fails(None, "schottky", path, "--target", "red", "3")


def test_default_depth_is_sized_to_the_output(pattern):
    """Without --depth the map is sized for the output: its width, or for a grid the width
    of an equirect output with pixels as fine as the grid's finest."""
    from spherewarp.cli.schottky_cmds import _output_width
    from spherewarp.grids import Equirect, Rectilinear

    assert _output_width({}, (64, 128, 3)) == 128
    assert _output_width({"output_shape": (100, 200)}, (64, 128, 3)) == 200
    assert abs(_output_width({"grid": Equirect((256, 512))}, (64, 128, 3)) - 512) <= 1
    # rectilinear, 90 degrees over 256 pixels: 2 / 256 radians a pixel at the centre, finer
    # towards the corners
    w = _output_width({"grid": Rectilinear((256, 256), fov=90)}, (64, 128, 3))
    assert 2 * np.pi / (2 / 256) <= w <= 4 * 2 * np.pi / (2 / 256)
    path, _ = pattern
    out = ok(None, "schottky", path, "-o", "d.png", "--generator", G1, "--size", "4096x2048",
             "--antialias", "none")  # fmt: skip
    s = Schottky.from_disk_pairs([((-163, 5, 12), (17, -5, 25))])
    assert f"depth {s.for_output(4096).depth}" in out
    assert f"depth {s.for_output(W).depth}" in ok(None, "schottky", path, "-o", "e.png",
                                                   "--generator", G1)  # fmt: skip
