"""``--save-recipe`` on the effect commands and ``spherewarp render`` (fresh processes)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from _cli import fails, ok, run

from spherewarp.io import read_image, write_image

COMMANDS = [
    ("rotate", "--yaw", "30", "--pitch", "-10", "--roll", "5"),
    ("rotate", "--axis", "-163,5", "--angle", "45"),
    ("zoom", "--at-pixel", "40,50", "--factor", "3", "--center"),
    ("mobius", "--matrix", "1+1j,0.5,0,1-1j"),
    ("mobius", "--from", "0,0", "90,0", "0,90", "--to", "0,0", "60,0", "0,60"),
    ("power", "--n", "1/2", "--branch-points", "0,0", "180,0", "--look-at", "0,90"),
    ("exp", "--lam", "2", "--size", "96x48"),
    ("map", "--expr", "z**2 + 0.5*z", "--chart", "front", "--interp", "bicubic"),
    ("lattes", "--alpha", "1+1j", "--antialias", "adaptive"),
    ("droste", "--center", "0,0", "--inner-radius", "20", "--phase", "0.3"),
    ("droste", "--frame", "-20,15", "20,15", "20,-15", "-20,-15", "--twist", "--scale", "8"),
]


@pytest.fixture
def pano(tmp_path):
    rng = np.random.default_rng(1)
    a = tmp_path / "a.png"
    b = tmp_path / "b.png"
    write_image(a, rng.integers(0, 256, (64, 128, 3), dtype=np.uint8))
    write_image(b, rng.integers(0, 256, (40, 80, 3), dtype=np.uint8))
    return a, b


@pytest.mark.parametrize("args", COMMANDS, ids=[" ".join(a[:2]) for a in COMMANDS])
def test_save_recipe_then_render_gives_the_same_pixels(tmp_path, pano, args):
    a, b = pano
    r = tmp_path / "r.json"
    ok(None, *args[:1], a, *args[1:], "--save-recipe", r, "-o", tmp_path / "cmd.png", "-q")
    data = json.loads(r.read_text())
    assert data["spherewarp"] == 1 and list(data["steps"][0]) == [args[0]]
    # on this panorama and on another, in one batch (one process)
    ok(None, "render", r, a, b, "-o", f"{tmp_path / 'rec'}/", "-q")
    cmd = read_image(tmp_path / "cmd.png").pixels
    rec = read_image(tmp_path / "rec" / "a-render.png").pixels
    assert cmd.shape == rec.shape and np.array_equal(cmd, rec)
    other = read_image(tmp_path / "rec" / "b-render.png").pixels
    size = data.get("view", {}).get("size")
    assert other.shape[:2] == ((size[1], size[0]) if size else (40, 80))


def test_dry_run_writes_the_recipe_only(tmp_path, pano):
    a, _ = pano
    r = tmp_path / "r.json"
    out = ok(
        None,
        "zoom",
        a,
        "--at",
        "10,0",
        "--factor",
        "2",
        "--save-recipe",
        r,
        "--dry-run",
        "-o",
        tmp_path / "x.png",
    )
    assert "wrote" in out and r.exists() and not (tmp_path / "x.png").exists()
    assert json.loads(r.read_text())["steps"] == [
        {"zoom": {"at": [10.0, 0.0], "factor": 2.0, "center": False}}
    ]


def test_dry_run_needs_save_recipe(tmp_path, pano):
    err = fails(None, "rotate", pano[0], "--yaw", "3", "--dry-run")
    assert "--dry-run goes with --save-recipe" in err


def test_existing_recipe_is_refused_before_any_work(tmp_path, pano):
    a, _ = pano
    r = tmp_path / "r.json"
    r.write_text("{}")
    err = fails(None, "rotate", a, "--yaw", "3", "--save-recipe", r, "-o", tmp_path / "x.png")
    assert "exists; pass --overwrite" in err
    assert r.read_text() == "{}" and not (tmp_path / "x.png").exists()
    ok(None, "rotate", a, "--yaw", "3", "--save-recipe", r, "-o", tmp_path / "x.png", "--overwrite")
    assert json.loads(r.read_text())["steps"] == [{"rotate": {"yaw": 3.0}}]


def test_a_recipe_in_a_missing_folder_is_refused_before_any_work(tmp_path, pano):
    a, _ = pano
    r = tmp_path / "no" / "r.json"
    err = fails(None, "rotate", a, "--yaw", "3", "--save-recipe", r, "-o", tmp_path / "x.png")
    assert f"directory '{tmp_path / 'no'}' does not exist" in err
    (tmp_path / "no").write_text("a file")
    err = fails(None, "rotate", a, "--yaw", "3", "--save-recipe", r, "-o", tmp_path / "x.png")
    assert err.endswith(f"'{tmp_path / 'no'}' is not a directory\n")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.png", "b.png", "no"]


def test_save_recipe_may_not_be_the_input(tmp_path, pano):
    a, _ = pano
    err = fails(None, "rotate", a, "--yaw", "3", "--save-recipe", a, "--overwrite")
    assert "--save-recipe" in err and "is the input" in err
    err = fails(None, "rotate", a, "--yaw", "3", "--save-recipe", tmp_path / "r.txt")
    assert "ending in .json" in err


def test_render_at_a_time_and_the_recipes_options(tmp_path, pano):
    a, _ = pano
    r = tmp_path / "flight.json"
    r.write_text(
        json.dumps(
            {
                "spherewarp": 1,
                "duration": 2,
                "steps": [{"zoom": {"at": [30, 10], "factor": {"keyframes": [[0, 1], [2, 4]]}}}],
                "view": {"size": [64, 32]},
            }
        )
    )
    plain = tmp_path / "plain.json"
    plain.write_text(
        json.dumps(
            {
                "spherewarp": 1,
                "steps": [{"zoom": {"at": [30, 10], "factor": 2.5}}],
                "view": {"size": [64, 32]},
            }
        )
    )
    ok(None, "render", r, a, "--time", "1", "-o", tmp_path / "t1.png", "-q")
    ok(None, "render", plain, a, "-o", tmp_path / "p.png", "-q")
    t1 = read_image(tmp_path / "t1.png").pixels
    assert t1.shape == (32, 64, 3)
    assert np.array_equal(t1, read_image(tmp_path / "p.png").pixels)
    ok(None, "render", r, a, "--size", "32x16", "-o", tmp_path / "small.png", "-q")
    assert read_image(tmp_path / "small.png").pixels.shape == (16, 32, 3)


BAD = {
    "not json": "{",
    "wrong version": '{"spherewarp": 9, "steps": []}',
    "unknown effect": '{"spherewarp": 1, "steps": [{"zooom": {"at": [0, 0], "factor": 2}}]}',
    "negative factor": '{"spherewarp": 1, "steps": [{"zoom": {"at": [0, 0], "factor": -1}}]}',
    "NaN": '{"spherewarp": 1, "steps": [{"rotate": {"yaw": NaN}}]}',
    "unknown field": '{"spherewarp": 1, "steps": [{"rotate": {"yew": 3}}]}',
    "wrong type": '{"spherewarp": 1, "steps": [{"rotate": {"yaw": "3"}}]}',
    "keyframes out of order": (
        '{"spherewarp": 1, "steps": [{"rotate": {"yaw": {"keyframes": [[1, 0], [0, 3]]}}}]}'
    ),
    "deeply nested": "[" * 50000 + "]" * 50000,
    "not utf-8": b'{"spherewarp": 1, "steps": [\xff]}',
}


@pytest.mark.parametrize("name", sorted(BAD))
def test_bad_recipes_give_one_line_and_write_nothing(tmp_path, pano, name):
    a, _ = pano
    r = tmp_path / "bad.json"
    text = BAD[name]
    r.write_bytes(text if isinstance(text, bytes) else text.encode())
    err = fails(None, "render", r, a, "-o", tmp_path / "out.png")
    assert "Traceback" not in err
    assert not (tmp_path / "out.png").exists()


def _recipe(*steps, **top):
    return json.dumps({"spherewarp": 1, **top, "steps": list(steps)})


_G = {"disk": [0, 0, 20], "to": [180, 0, 20]}
#: more bad recipes: (text, what the one line must say: the field's path and what is wrong)
BAD_NAMED = {
    "negative factor named": (
        _recipe({"rotate": {"yaw": 3}}, {"zoom": {"at": [0, 0], "factor": -1}}),
        "steps[1].zoom.factor: expected a number >= 1e-09 and <= 1e+09, got -1",
    ),
    "did you mean": (
        _recipe({"zooom": {"at": [0, 0], "factor": 2}}),
        "steps[0]: unknown effect 'zooom' (did you mean 'zoom'?)",
    ),
    "unknown top-level field": ('{"spherewarp": 1, "stpes": []}', "stpes: unknown field (did you"),
    "infinity": (
        '{"spherewarp": 1, "steps": [{"rotate": {"yaw": 1e999}}]}',
        "steps[0].rotate.yaw: expected a number, got inf",
    ),
    "newer version": ('{"spherewarp": 2, "steps": []}', "format version 2 is newer"),
    "unknown easing": (
        _recipe({"rotate": {"yaw": {"keyframes": [[0, 0], [1, 9]], "easing": "bounce"}}}),
        "steps[0].rotate.yaw.easing: expected one of",
    ),
    "missing parameter": (_recipe({"zoom": {"at": [0, 0]}}), "steps[0].zoom.factor: missing"),
    "steps not a list": ('{"spherewarp": 1, "steps": {}}', "steps: expected a list of steps"),
    "loop without a duration": (_recipe(loop=True), "loop: a loop needs a 'duration'"),
    "overlapping schottky disks": (
        _recipe({"schottky": {"generators": [{"disk": [0, 0, 20], "to": [30, 0, 20]}]}}),
        "steps[0].schottky.generators[0]: the disks (0,0,20) and (30,0,20) overlap by 10",
    ),
    "schottky disk radius": (
        _recipe({"schottky": {"generators": [{"disk": [0, 0, -5], "to": [180, 0, 20]}]}}),
        "steps[0].schottky.generators[0].disk[2]: expected a number > 0 and <= 180, got -5",
    ),
    "schottky generator both forms": (
        _recipe({"schottky": {"generators": [{**_G, "matrix": [1, 0, 0, 1]}]}}),
        "steps[0].schottky.generators[0]: expected 'to' (a second disk) or 'matrix', not both",
    ),
    "schottky targets without a mask": (
        _recipe({"schottky": {"generators": [_G], "targets": [{"colour": "red", "zoom": 4}]}}),
        "steps[0].schottky.mask: missing",
    ),
    "schottky not hyperbolic": (
        _recipe({"schottky": {"generators": [{"disk": [0, 0, 20], "matrix": [1, 0, 0, 1]}]}}),
        "steps[0].schottky: generator 1: expected a hyperbolic",
    ),
    "missing inputs for splitscreen": (
        _recipe({"splitscreen": {"images": 2}}, inputs=["a.png"]),
        "inputs: expected 2 input names for splitscreen, got 1",
    ),
    "splitscreen not alone": (
        _recipe({"rotate": {"yaw": 3}}, {"splitscreen": {}}),
        "steps[1].splitscreen: renders a picture of its own",
    ),
    "peirce with a projection": (
        _recipe({"peirce": {}}, view={"projection": "fisheye"}),
        "view: peirce makes a flat picture of its own",
    ),
    "droste mask not found": (
        _recipe({"droste": {"mask": "nowhere.png"}}),
        "steps[0].droste.mask: expected an image file, got 'nowhere.png'",
    ),
    "torus cells": (
        _recipe({"torus": {"cells": [0, 1]}}),
        "steps[0].torus.cells[0]: expected an integer from 1 to 64, got 0",
    ),
    "an integer beyond a float": (
        '{"spherewarp": 1, "steps": [{"rotate": {"yaw": 1' + "0" * 400 + "}}]}",
        "expected numbers of at most 308 digits, got an integer of 401 digits",
    ),
    "an integer beyond Python's int parsing": (
        '{"spherewarp": 1, "steps": [{"rotate": {"yaw": 1' + "0" * 5000 + "}}]}",
        "expected numbers of at most 308 digits",
    ),
    "mobius amount out of range": (
        _recipe({"mobius": {"matrix": [2, 0, 0, 1], "amount": 5000}}),
        "steps[0].mobius: the power 5000 of this map is out of range",
    ),
    "power exponent out of range": (
        _recipe({"power": {"n": 1e308}}),
        "steps[0].power: expected an exponent of at most 1e+06 in size",
    ),
    "background not a colour": (
        _recipe(options={"background": "notacolour"}),
        "options.background: expected a colour name",
    ),
    "unknown tonemap": (_recipe(options={"tonemap": "filmic"}), "options.tonemap: expected"),
    "a field of view its projection cannot show": (
        _recipe(view={"projection": "rectilinear", "fov": 360}),
        "view: expected a field of view in (0, 180) degrees for rectilinear, got 360",
    ),
    "a cube map's size": (
        _recipe(view={"projection": "cubemap", "size": [5, 3]}),
        "view: expected a cubemap of 3x2 square faces, got 5x3 (e.g. 6x4)",
    ),
}


@pytest.mark.parametrize("name", sorted(BAD_NAMED))
def test_bad_recipes_name_the_field_in_one_line(tmp_path, pano, name):
    a, _ = pano
    r = tmp_path / "bad.json"
    text, message = BAD_NAMED[name]
    r.write_text(text)
    err = fails(None, "render", r, a, "-o", tmp_path / "out.png")
    assert message in err and "Traceback" not in err, err
    assert not (tmp_path / "out.png").exists()


def test_at_least_fifteen_kinds_of_bad_recipe():
    assert len(BAD) + len(BAD_NAMED) + 1 >= 15  # + the 50 MB recipe


def test_a_split_screen_recipe_needs_its_inputs(tmp_path, pano):
    a, b = pano
    r = tmp_path / "s.json"
    r.write_text(_recipe({"splitscreen": {"images": 2, "seam": 0}}))
    err = fails(None, "render", r, a, "-o", tmp_path / "out.png")
    assert "renders from 2 inputs (splitscreen), got 1" in err
    assert not (tmp_path / "out.png").exists()


def test_a_50_mb_recipe_is_refused(tmp_path, pano):
    r = tmp_path / "big.json"
    with r.open("wb") as fh:
        fh.truncate(50 * 1024 * 1024)
    err = fails(None, "render", r, pano[0], "-o", tmp_path / "out.png")
    assert "at most 1000000 bytes" in err and not (tmp_path / "out.png").exists()


def test_render_refuses_to_write_over_the_recipe(tmp_path, pano):
    a, _ = pano
    r = tmp_path / "r.png"
    r.write_text('{"spherewarp": 1, "steps": []}')
    err = fails(None, "render", r, a, "-o", r, "--overwrite")
    assert "is the recipe" in err



def test_render_and_animate_never_write_over_the_recipes_mask(tmp_path):
    """The mask a recipe names is an input: no output of render or animate may be it."""
    import shutil

    from spherewarp.demo import sample_path

    mask = tmp_path / "m_0000.png"
    shutil.copy(sample_path("interior-mask.png"), mask)
    before = mask.read_bytes()
    step = {"schottky": {"mask": mask.name, "targets": [{"colour": "red", "zoom": 40}]}}
    r = tmp_path / "sk.json"
    r.write_text(json.dumps({"spherewarp": 1, "steps": [step]}))
    s = sample_path()
    err = fails(None, "render", r, s, "--size", "64x32", "-o", mask, "--overwrite")
    assert "is the recipe's steps[0].schottky.mask" in err
    err = fails(None, "animate", r, s, "--fps", "2", "--duration", "1", "--size", "64x32",
                "-o", tmp_path / "m.png", "--overwrite")  # fmt: skip
    assert "would write" in err and "steps[0].schottky.mask" in err
    assert mask.read_bytes() == before and sorted(p.name for p in tmp_path.iterdir()) == [
        "m_0000.png", "sk.json"
    ]

def test_droste_frames_recipe_animates_to_the_same_frames(tmp_path, pano):
    a, _ = pano
    r = tmp_path / "loop.json"
    args = ["--center", "0,0", "--inner-radius", "20", "--scale", "4", "-q"]
    ok(None, "droste", a, *args, "--frames", "4", "-o", tmp_path / "cmd.png", "--save-recipe", r)
    data = json.loads(r.read_text())
    assert data["loop"] is True and data["duration"] == 1
    ok(None, "animate", r, a, "--fps", "4", "-o", tmp_path / "rec.png", "-q")
    for k in range(4):
        cmd = read_image(tmp_path / f"cmd_{k:04d}.png").pixels
        assert np.array_equal(cmd, read_image(tmp_path / f"rec_{k:04d}.png").pixels), k


def test_save_recipe_refuses_what_has_no_recipe(tmp_path, pano):
    a, _ = pano
    err = fails(None, "peirce", a, "--inverse", "--save-recipe", tmp_path / "r.json")
    assert "--inverse" in err
    err = fails(None, "project", a, "--from", "cubemap", "--save-recipe", tmp_path / "r.json")
    assert "--from" in err
    assert not (tmp_path / "r.json").exists()


def test_lattes_dry_run_needs_no_input(tmp_path):
    r = tmp_path / "l.json"
    ok(None, "lattes", "--alpha", "2+1j", "--save-recipe", r, "--dry-run")
    assert json.loads(r.read_text())["steps"] == [
        {"lattes": {"alpha": "2+1j", "lattice": "square", "exact": False}}
    ]


def test_a_batch_writes_one_recipe_naming_its_inputs(tmp_path, pano):
    a, b = pano
    r = tmp_path / "r.json"
    ok(None, "rotate", a, b, "--yaw", "20", "--save-recipe", r, "-o", f"{tmp_path / 'out'}/")
    assert json.loads(r.read_text())["inputs"] == ["a.png", "b.png"]
    assert len(list((tmp_path / "out").iterdir())) == 2
    # inputs whose recipes differ (a pixel is another point on another size) say so
    z = tmp_path / "z.json"
    code, _, err = run(
        None,
        "zoom",
        a,
        b,
        "--at-pixel",
        "10,10",
        "--factor",
        "2",
        "--save-recipe",
        z,
        "-o",
        f"{tmp_path / 'zo'}/",
    )
    assert code == 2 and "gives another recipe" in err and "Traceback" not in err
    assert json.loads(z.read_text())["inputs"] == ["a.png"]


@pytest.mark.parametrize(
    "args",
    [
        ("rotate", "--yaw", "30"),
        ("rotate", "--pitch", "10"),
        ("zoom", "--at", "10,20", "--factor", "2"),
        ("zoom", "--at", "40,0", "--factor", "2", "--center"),
        ("mobius", "--matrix", "1j,0,0,-1j"),
        ("power", "--n", "2"),
    ],
    ids=lambda a: " ".join(a[:2]),
)
def test_render_carries_the_gpano_pose_as_the_command_does(tmp_path, args):
    from spherewarp.io import GPano

    px = np.random.default_rng(0).integers(0, 255, (32, 64, 3), dtype=np.uint8)
    src = tmp_path / "posed.png"
    write_image(src, px, gpano=GPano(full_width=64, full_height=32, pose_heading=100.0))
    r = tmp_path / "r.json"
    ok(None, args[0], src, *args[1:], "--save-recipe", r, "-o", tmp_path / "cmd.png", "-q")
    ok(None, "render", r, src, "-o", tmp_path / "rec.png", "-q")
    a, b = read_image(tmp_path / "cmd.png").gpano, read_image(tmp_path / "rec.png").gpano
    pose = (a.pose_heading, a.pose_pitch, a.pose_roll) if a is not None else None
    assert pose == ((b.pose_heading, b.pose_pitch, b.pose_roll) if b is not None else None)


def test_saved_recipe_keeps_the_view_and_render_replays_it(tmp_path):
    """--projection/--look-at/--fov go into the recipe's view; render replays the grid."""
    from spherewarp.io import read_image

    src = str(Path(__file__).resolve().parents[2] / "src" / "spherewarp" / "data" / "interior.png")
    a, b, r = tmp_path / "a.png", tmp_path / "b.png", tmp_path / "r.json"
    view = ("--projection", "rectilinear", "--look-at", "90,10", "--fov", "70", "--size", "96x64")
    code, _, err = run(None, "zoom", src, "--at", "0,0", "--factor", "2", *view,
                       "--save-recipe", r, "-o", a)  # fmt: skip
    assert code == 0, err
    saved = json.loads(r.read_text())["view"]
    assert saved == {"size": [96, 64], "projection": "rectilinear", "look_at": [90.0, 10.0],
                     "fov": 70.0}  # fmt: skip
    code, _, err = run(None, "render", r, src, "-o", b)
    assert code == 0, err
    np.testing.assert_array_equal(read_image(a).pixels, read_image(b).pixels)
    assert read_image(b).gpano is None  # a flat view carries no GPano


def test_recipe_view_projection_is_checked():
    from spherewarp.recipe import Recipe, RecipeError

    base = {"spherewarp": 1, "steps": [{"zoom": {"at": [0, 0], "factor": 2}}]}
    with pytest.raises(RecipeError, match=r"view.projection: .*did you mean 'fisheye'"):
        Recipe.from_dict({**base, "view": {"projection": "fishey"}})
    grid = Recipe.from_dict({**base, "view": {"projection": "little-planet"}})
    out = grid.render(np.zeros((32, 64, 3), np.uint8))
    assert out.shape == (32, 32, 3)


# -- every effect command: its recipe replays it bit for bit ------------------------------------
DATA = Path(__file__).resolve().parents[2] / "src" / "spherewarp" / "data"
FRAME = ("--frame", "-173,23.6", "-153.8,24.5", "-153.8,-14.8", "-173,-14.2")
G1, G2 = "38,8,24 -> -40,-55,22", "-163,5,9 -> -110,55,18"
ROUND = ("--target", "red", "-40,-55,22", "--target", "green", "60", "--regions", "round")
#: (command, options...): "{B}" is the second input, "{HOLE}" a Droste mask, "{MASK}" the
#: bundled Schottky mask; every command runs on interior.png at a reduced --size
EVERY = [
    ("rotate", "--yaw", "30", "--pitch", "-10", "--roll", "5"),
    ("rotate", "--axis", "-163,5", "--angle", "45", "--projection", "little-planet"),
    ("zoom", "--at", "-163,5", "--factor", "3", "--interp", "bicubic"),
    ("zoom", "--at", "-163,5", "--factor", "2", "--center", "--background", "white"),
    ("mobius", "--matrix", "1,0.5,0,1", "--antialias", "adaptive"),
    ("mobius", "--from", "-163,5", "-65,2", "38,2", "--to", "-100,0", "-40,-10", "100,10"),
    ("power", "--n", "2", "--look-at", "0,90"),
    ("power", "--n", "3", "--projection", "rectilinear", "--view-at", "20,10", "--fov", "80"),
    ("exp", "--lam", "4"),
    ("map", "--expr", "z**3 + 0.5*z"),
    ("lattes", "--alpha", "1+1j"),
    ("lattes", "--lattice", "hex", "--alpha", "1+w", "--exact"),
    ("droste", "--center", "-163,5", *FRAME),
    ("droste", "--center", "-163,5", *FRAME, "--twist", "--scale", "8", "--phase", "0.3"),
    ("droste", "--center", "-163,5", "--inner-radius", "12", "--far", "17,-5", "--border", "2"),
    ("droste", "--mask", "{HOLE}"),
    ("droste", "--center", "-163,5", *FRAME, "--view", "log", "--periods", "2"),
    ("droste", "--center", "-163,5", *FRAME, "--view", "log-output"),
    ("droste", "--center", "-163,5", *FRAME, "--inside", "{B}"),
    ("droste", "--center", "-163,5", *FRAME, "--projection", "fisheye", "--look-at", "-163,5"),
    ("schottky", "--generator", G1, "--generator", G2),
    ("schottky", "--generator", G1, "--twist", "15", "--depth", "6", "--phase", "0.25"),
    ("schottky", "--generator", "0,90,20:30,0,0,1"),
    ("schottky", "--mask", "{MASK}", "--target", "red", "40", "--target", "green", "60"),
    ("schottky", "--mask", "{MASK}", *ROUND, "--generator", "0,90,10 -> 0,-90,10"),
    ("splitscreen", "{B}", "--cover", "power", "--n", "2"),
    ("splitscreen", "{B}", "--cover", "exp", "--lam", "3", "--seam", "40", "--feather", "20"),
    ("peirce", "--lon0", "30"),
    ("torus", "--lattice", "hex", "--cells", "2x1"),
    ("project", "--to", "little-planet"),
    ("project", "--to", "rectilinear", "--look-at", "90,10", "--roll", "5", "--fov", "70"),
]
SIZE = {"peirce": "96", "torus": "128"}


def _args(args, tmp_path, b):
    hole = tmp_path / "hole.png"
    if not hole.exists():
        m = np.zeros((64, 128, 3), np.uint8)
        m[24:32, 4:10] = 255  # about the picture at -163, 5
        write_image(hole, m)
    subst = {"{B}": b, "{HOLE}": hole, "{MASK}": DATA / "interior-mask.png"}
    return [subst.get(a, a) for a in args[1:]]


@pytest.mark.parametrize("args", EVERY, ids=[" ".join(a[:3])[:40] for a in EVERY])
def test_every_command_replays_bit_for_bit(tmp_path, args):
    """The command, then 'render' of its --save-recipe on the same input: the same pixels;
    'render' on another panorama works."""
    a, b = DATA / "interior.png", DATA / "courtyard.png"
    name, opts = args[0], _args(args, tmp_path, b)
    size = ("--size", SIZE.get(name, "128x64"))
    r = tmp_path / "r.json"
    ok(None, name, a, *opts, *size, "--save-recipe", r, "-o", tmp_path / "cmd.png", "-q")
    data = json.loads(r.read_text())
    assert data["spherewarp"] == 1
    assert [list(s) for s in data["steps"]] == ([] if name == "project" else [[name]])
    several = "{B}" in args and name in ("splitscreen",) or "--inside" in args
    cmd = read_image(tmp_path / "cmd.png")
    if several:  # one render of both inputs, then the other way round
        ok(None, "render", r, a, b, "-o", tmp_path / "rec.png", "-q")
        ok(None, "render", r, b, a, "-o", tmp_path / "other.png", "-q")
        rec, out = read_image(tmp_path / "rec.png"), read_image(tmp_path / "other.png").pixels
    else:  # this panorama and another, in one batch (one process)
        ok(None, "render", r, a, b, "-o", f"{tmp_path / 'rec'}/", "-q")
        rec = read_image(tmp_path / "rec" / "interior-render.png")
        out = read_image(tmp_path / "rec" / "courtyard-render.png").pixels
    assert cmd.pixels.shape == rec.pixels.shape and np.array_equal(cmd.pixels, rec.pixels)
    assert (cmd.gpano is None) == (rec.gpano is None)
    assert out.shape == cmd.pixels.shape and not np.array_equal(out, cmd.pixels)
    # the saved recipe is valid against the shipped JSON Schema
    from importlib import resources

    from recipe.test_recipe import _check

    schema = json.loads(
        resources.files("spherewarp.recipe").joinpath("recipe.schema.json").read_text()
    )
    assert _check(schema, data, schema)


@pytest.mark.parametrize(
    "args",
    [
        ("rotate", "--yaw", "30"),
        ("zoom", "--at", "10,0", "--factor", "2"),
        ("droste", "--center", "0,0", "--inner-radius", "20"),
        ("schottky", "--generator", "0,0,20 -> 180,0,20"),
        ("lattes", "--alpha", "2"),
        ("peirce",),
        ("power", "--n", "2", "--look-at", "0,90"),
        ("exp", "--lam", "3"),
        ("map", "--expr", "z**3"),
    ],
    ids=lambda a: a[0],
)
def test_print_is_the_recipe_and_print_map_the_map(tmp_path, pano, args):
    from spherewarp.maps import map_from_json
    from spherewarp.recipe import Recipe

    a, _ = pano
    text = ok(None, args[0], a, *args[1:], "--print")
    recipe = Recipe.loads(text)
    assert [s.effect for s in recipe.steps] == [args[0]]
    assert json.loads(text)["inputs"] == ["a.png"]
    if args[0] in ("peirce",):
        assert "not a map" in fails(None, args[0], a, *args[1:], "--print-map")
    elif args[0] != "lattes":
        m = map_from_json(ok(None, args[0], a, *args[1:], "--print-map"))
        assert m.kind == recipe.map_at(0).kind or args[0] in ("rotate", "zoom")
    assert not list(tmp_path.glob("*-*.png"))  # nothing rendered


def test_splitscreen_prints_its_recipe_and_has_no_map(tmp_path, pano):
    """--print: the split screen's recipe, both inputs named, which 'render' replays;
    --print-map is refused in one line (each sheet shows another input, no one map)."""
    from spherewarp.recipe import Recipe

    a, b = pano
    text = ok(None, "splitscreen", a, b, "--seam", "30", "--print")
    recipe = Recipe.loads(text)
    assert [s.effect for s in recipe.steps] == ["splitscreen"] and recipe.n_inputs == 2
    assert json.loads(text)["inputs"] == ["a.png", "b.png"]
    assert "use --print" in fails(None, "splitscreen", a, b, "--print-map")
    assert not list(tmp_path.glob("*-*.png"))  # nothing rendered
    r = tmp_path / "r.json"
    r.write_text(text)
    opts = ["--size", "64x32", "-q"]
    ok(None, "splitscreen", a, b, "--seam", "30", *opts, "-o", tmp_path / "cmd.png")
    ok(None, "render", r, a, b, *opts, "-o", tmp_path / "rec.png")
    cmd, rec = (read_image(tmp_path / n).pixels for n in ("cmd.png", "rec.png"))
    assert np.array_equal(cmd, rec)


def test_a_schottky_loop_recipe_loops(tmp_path, pano):
    """--frames N saves a loop whose phase is a track; 'animate' writes the command's frames,
    and the frame after the last is the first."""
    a = DATA / "interior.png"
    r = tmp_path / "loop.json"
    args = ["--generator", G1, "--size", "96x48", "-q"]
    ok(None, "schottky", a, *args, "--frames", "4", "-o", tmp_path / "cmd.png", "--save-recipe", r)
    data = json.loads(r.read_text())
    assert data["loop"] is True and data["duration"] == 1
    assert data["steps"][0]["schottky"]["phase"] == {"keyframes": [[0, 0.0], [1, 1.0]]}
    ok(None, "animate", r, a, "--fps", "4", "-o", tmp_path / "rec.png", "-q")
    frames = [read_image(tmp_path / f"rec_{k:04d}.png").pixels for k in range(4)]
    for k in range(4):
        assert np.array_equal(read_image(tmp_path / f"cmd_{k:04d}.png").pixels, frames[k])
    assert not np.array_equal(frames[0], frames[1])  # it moves
    ok(None, "render", r, a, "--time", "1", "-o", tmp_path / "after.png", "-q")
    assert np.array_equal(read_image(tmp_path / "after.png").pixels, frames[0])
    # without the wrap: phase 1 is the same picture as phase 0 (the group's period)
    data["loop"] = False
    r.write_text(json.dumps(data))
    ok(None, "render", r, a, "--time", "1", "-o", tmp_path / "one.png", "-q")
    one = read_image(tmp_path / "one.png").pixels.astype(int)
    assert (np.abs(one - frames[0]).max(axis=-1) <= 2).mean() > 0.98


def test_a_fifo_or_a_device_is_no_recipe(tmp_path, pano):
    import os

    fifo = tmp_path / "f.json"
    os.mkfifo(fifo)
    for r in (fifo, "/dev/zero"):
        err = fails(None, "render", r, pano[0], "-o", tmp_path / "out.png")  # no hang
        assert "not a regular file" in err


def test_print_with_save_recipe_is_refused(tmp_path, pano):
    r = tmp_path / "r.json"
    for flag in ("--print", "--print-map"):
        for args in ([flag, "--save-recipe", r], ["--save-recipe", r, flag]):
            code, _, err = run(None, "zoom", pano[0], "--at", "0,0", "--factor", "2", *args)
            assert code == 2 and f"{flag} prints instead of rendering" in err
    assert not r.exists()


def test_tonemap_and_exposure_are_in_the_recipe(tmp_path):
    hdr = tmp_path / "x.exr"
    write_image(hdr, np.random.default_rng(0).uniform(0, 8, (32, 64, 3)).astype(np.float32))
    r = tmp_path / "r.json"
    opts = ["--tonemap", "reinhard", "--exposure", "1", "-q"]
    ok(None, "exp", hdr, "--lam", "3", *opts, "-o", tmp_path / "a.png", "--save-recipe", r)
    options = json.loads(r.read_text())["options"]
    assert options["tonemap"] == "reinhard" and options["exposure"] == 1.0
    ok(None, "render", r, hdr, "-o", tmp_path / "b.png", "-q")
    a, b = (read_image(tmp_path / n).pixels for n in ("a.png", "b.png"))
    assert a.dtype == np.uint16 and np.array_equal(a, b)
    ok(None, "render", r, hdr, "-o", tmp_path / "c.png", "-q", "--tonemap", "clip")  # wins
    assert not np.array_equal(read_image(tmp_path / "c.png").pixels, a)
