"""No command overwrites a file it reads: every output against every input.

For each command and each file it reads (the main INPUT, a Droste --mask or
--inside image, a split-screen input, the panorama a torus --mesh texture
would be named as), the output is made to name that file directly, through a
symbolic link and through a hard link, with and without --overwrite: the
command must fail with one line naming the option before any work, and every
input must keep its bytes.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

import numpy as np
import pytest
from _cli import run

from spherewarp.io import write_image

W, H = 64, 32
CENTER = ("--center", "0,0", "--inner-radius", "10")

# command -> (arguments with {a}/{b} for the input files, [the inputs an output may hit])
# The output is given by the command's own option where it is not -o (see OUTPUT_OPTION).
CASES: dict[str, tuple[list[str], list[str]]] = {
    "rotate": (["rotate", "{a}", "--yaw", "10"], ["a"]),
    "zoom": (["zoom", "{a}", "--at", "0,0", "--factor", "2"], ["a"]),
    "zoom-pixel": (["zoom", "{a}", "--at-pixel", "3,3", "--factor", "2"], ["a"]),
    "mobius": (["mobius", "{a}", "--matrix", "1,0.5,0,1"], ["a"]),
    "power": (["power", "{a}", "--n", "2"], ["a"]),
    "exp": (["exp", "{a}"], ["a"]),
    "map": (["map", "{a}", "--expr", "z**2"], ["a"]),
    "splitscreen": (["splitscreen", "{a}", "{b}", "--seam", "0"], ["a", "b"]),
    "droste": (["droste", "{a}", *CENTER], ["a"]),
    "droste-mask": (["droste", "{a}", "--mask", "{b}"], ["a", "b"]),
    "droste-inside": (["droste", "{a}", *CENTER, "--inside", "{b}"], ["a", "b"]),
    "droste-log": (["droste", "{a}", *CENTER, "--view", "log"], ["a"]),
    "schottky": (["schottky", "{a}", "--generator", "0,0,20 -> 180,0,20"], ["a"]),
    "schottky-mask": (["schottky", "{a}", "--mask", "{b}", "--target", "white", "4"], ["a", "b"]),
    "lattes": (["lattes", "{a}", "--alpha", "1+1j"], ["a"]),
    "peirce": (["peirce", "{a}"], ["a"]),
    "peirce-inverse": (["peirce", "{a}", "--inverse"], ["a"]),
    "torus": (["torus", "{a}"], ["a"]),
    "project": (["project", "{a}", "--to", "little-planet"], ["a"]),
    "project-from": (["project", "{a}", "--from", "cubemap-6x1"], ["a"]),
    "render": (["render", "{r}", "{a}"], ["a", "r"]),
    "video": (["video", "{a}", "zoom", "--at", "0,0", "--factor", "2"], ["a"]),
}


def digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


@pytest.fixture
def inputs(workdir: Path) -> dict[str, Path]:
    y, x = np.mgrid[0:H, 0:W]
    a = np.stack([x * 4, y * 8, (x + y) * 2], -1).astype(np.uint8)
    mask = np.zeros((H, W, 3), np.uint8)
    mask[12:20, 28:36] = 255  # a hole in front
    recipe = workdir / "r.json"
    recipe.write_text('{"spherewarp": 1, "steps": [{"rotate": {"yaw": 10}}]}')
    return {
        "a": write_image(workdir / "a.png", a),
        "b": write_image(workdir / "b.png", mask),
        "r": recipe,
    }


def _aliases(workdir: Path, target: Path) -> dict[str, Path]:
    """The target itself, a symbolic link to it and a hard link to it."""
    sym, hard = workdir / f"sym-{target.name}", workdir / f"hard-{target.name}"
    for p in (sym, hard):
        if p.exists() or p.is_symlink():
            p.unlink()
    sym.symlink_to(target.name)
    os.link(target, hard)
    return {"direct": target, "symlink": sym, "hardlink": hard}


def _check_refused(workdir: Path, inputs: dict[str, Path], args: list[str], option: str) -> None:
    before = {p: digest(p) for p in inputs.values()}
    names_before = sorted(p.name for p in workdir.iterdir())
    code, out, err = run(None, *args)
    assert code == 2, (args, code, out, err)
    assert err.startswith("spherewarp: error: ") and err.count("\n") == 1, (args, err)
    assert option in err and "choose another" in err and "Traceback" not in err, (args, err)
    assert {p: digest(p) for p in inputs.values()} == before, args
    assert sorted(p.name for p in workdir.iterdir()) == names_before, (args, "files appeared")


def _fill(args: list[str], inputs: dict[str, Path]) -> list[str]:
    names = {k: inputs[k].name for k in ("a", "b", "r")}
    return [a.format(**names) for a in args]


@pytest.mark.parametrize("case", sorted(CASES))
def test_output_never_overwrites_an_input(workdir, inputs, case):
    template, hit = CASES[case]
    args = _fill(template, inputs)
    for key in hit:
        for alias in _aliases(workdir, inputs[key]).values():
            for extra in ([], ["--overwrite"]):
                _check_refused(workdir, inputs, [*args, "-o", alias.name, *extra], "-o")


@pytest.mark.parametrize("how", ["direct", "symlink", "hardlink"])
def test_droste_frames_never_overwrite_an_input(workdir, inputs, how):
    frame1 = inputs["a"].with_name("loop_0001.png")
    os.replace(inputs["a"], frame1)
    inputs["a"] = frame1
    alias = _aliases(workdir, frame1)[how]
    pattern = alias.name.replace("0001", "%04d")
    args = ["droste", frame1.name, *CENTER, "--frames", "3", "-o", pattern, "--overwrite"]
    _check_refused(workdir, inputs, args, "-o")


@pytest.mark.parametrize("how", ["direct", "symlink", "hardlink"])
@pytest.mark.parametrize("target", ["a", "r"])
def test_animate_frames_never_overwrite_an_input(workdir, inputs, how, target):
    # a frame named as the panorama or as the recipe (which is read by its content)
    frame1 = inputs[target].with_name("loop_0001.png")
    os.replace(inputs[target], frame1)
    inputs[target] = frame1
    timed = workdir / "timed.json"
    timed.write_text(
        '{"spherewarp": 1, "duration": 1, "steps": [{"rotate": '
        '{"yaw": {"keyframes": [[0, 0], [1, 90]]}}}]}'
    )
    recipe = inputs["r"] if target == "r" else timed
    pattern = _aliases(workdir, frame1)[how].name.replace("0001", "%04d")
    args = ["animate", recipe.name, inputs["a"].name, "--fps", "2", "--duration", "1"]
    args += ["-o", pattern, "--overwrite"]
    _check_refused(workdir, inputs, args, "-o")


@pytest.mark.parametrize("how", ["direct", "symlink", "hardlink"])
@pytest.mark.parametrize("role", [".obj", ".mtl", "_texture.png"])
def test_torus_mesh_never_overwrites_an_input(workdir, inputs, role, how):
    # --mesh NAME.obj writes NAME.obj, NAME.mtl and NAME_texture.png: a panorama under each
    # of those names (images are read by their content) is protected
    pano = workdir / f"pano{role}"
    pano.write_bytes(inputs["a"].read_bytes())
    inputs["pano"] = pano
    mesh = _aliases(workdir, pano)[how].name[: -len(role)] + ".obj"
    for extra in ([], ["--overwrite"]):
        args = ["torus", pano.name, "-o", "t.png", "--mesh", mesh, *extra]
        _check_refused(workdir, inputs, args, "--mesh")


def test_every_render_command_is_covered():
    from spherewarp.cli import COMMANDS

    # animate: test_animate_frames_never_overwrite_an_input (its frames are numbered)
    covered = {args[0] for args, _ in CASES.values()} | {"testpattern", "animate"}
    # print only; demo reads the bundled sample; view serves, and renders only into its own
    # temporary folder (tests/viewer/test_server.py: nothing else on disk changes)
    not_rendering = {"info", "fit-rational", "demo", "view"}
    assert set(COMMANDS) - not_rendering == covered


def test_testpattern_writes_only(workdir):
    # testpattern reads nothing; its -o is checked like every output
    code, out, err = run(None, "testpattern", "-o", "p.png", "--size", "64x32")
    assert code == 0, err
