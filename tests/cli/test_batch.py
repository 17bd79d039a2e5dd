"""Several inputs in one command: ``spherewarp rotate *.png --yaw 30 -o out/``."""

from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np
import pytest
from _cli import run

from spherewarp.io import read_image, write_image

W, H = 64, 32


def digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


@pytest.fixture
def images(workdir: Path) -> list[Path]:
    rng = np.random.default_rng(4)
    return [
        write_image(workdir / f"{name}.png", rng.integers(0, 255, (H, W, 3), dtype=np.uint8))
        for name in ("a", "b", "c")
    ]


def test_batch_into_a_directory(workdir, images):
    code, out, err = run(None, "rotate", *[p.name for p in images], "--yaw", "30", "-o", "out/")
    assert code == 0, err
    assert out.splitlines() == [f"wrote out/{n}-rotate.png" for n in "abc"]
    for n, src in zip("abc", images, strict=True):
        # each output is what the command gives for that input alone
        code, _, err = run(None, "rotate", src.name, "--yaw", "30", "-o", f"{n}-alone.png")
        assert code == 0, err
        a = read_image(workdir / "out" / f"{n}-rotate.png").pixels
        assert np.array_equal(a, read_image(workdir / f"{n}-alone.png").pixels)


def test_existing_directory_without_slash_and_default_names(workdir, images):
    (workdir / "dir").mkdir()
    code, out, err = run(None, "power", "a.png", "b.png", "--n", "2", "-o", "dir")
    assert code == 0, err
    assert sorted(p.name for p in (workdir / "dir").iterdir()) == ["a-power.png", "b-power.png"]
    code, out, err = run(None, "zoom", "a.png", "b.png", "--at", "0,0", "--factor", "2")
    assert code == 0, err
    assert (workdir / "a-zoom.png").exists() and (workdir / "b-zoom.png").exists()


def test_one_input_into_a_directory(workdir, images):
    code, out, err = run(None, "lattes", "a.png", "--alpha", "1+1j", "-o", "new/")
    assert code == 0, err
    assert out == "wrote new/a-lattes.png\n"


def test_several_inputs_and_a_file_is_one_line(workdir, images):
    code, out, err = run(None, "rotate", "a.png", "b.png", "--yaw", "3", "-o", "x.png")
    assert code == 2 and err.count("\n") == 1, err
    assert "-o DIR/" in err and not (workdir / "x.png").exists()


def test_a_failing_input_is_reported_and_the_others_go_on(workdir, images):
    (workdir / "bad.png").write_bytes(b"not an image")
    before = {p.name: digest(p) for p in workdir.iterdir()}
    code, out, err = run(None, "rotate", "a.png", "bad.png", "c.png", "--yaw", "3", "-o", "o/")
    assert code == 2, err
    lines = err.splitlines()
    assert len(lines) == 2 and "bad.png" in lines[0], err
    assert lines[1] == "spherewarp: error: 1 of 3 inputs failed (each said why above)"
    assert out.splitlines() == ["wrote o/a-rotate.png", "wrote o/c-rotate.png"]
    assert {p.name: digest(p) for p in workdir.iterdir() if p.is_file()} == before


def test_a_folder_among_the_inputs_fails_on_its_own(workdir, images):
    (workdir / "d").mkdir()
    code, out, err = run(None, "rotate", "a.png", "d", "c.png", "--yaw", "3", "-o", "o/")
    assert code == 2, err
    assert err.splitlines()[0] == "spherewarp: error: cannot read 'd': is a directory, " \
        "expected an image file"
    assert out.splitlines() == ["wrote o/a-rotate.png", "wrote o/c-rotate.png"]


def test_batch_never_overwrites_an_input_or_an_earlier_output(workdir, images):
    # keeping the names in the inputs' own directory would overwrite them
    (workdir / "x").mkdir()
    write_image(workdir / "x" / "a.png", np.zeros((H, W, 3), np.uint8))
    before = {p: digest(p) for p in workdir.rglob("*.png")}
    code, out, err = run(None, "rotate", "a.png", "x/a.png", "--yaw", "3", "-o", "o/")
    assert code == 2
    assert out == "wrote o/a-rotate.png\n"
    assert "also the output of input 'a.png'" in err and "choose another -o" in err, err
    # an input that is an earlier input's output
    before[workdir / "o" / "a-rotate.png"] = digest(workdir / "o" / "a-rotate.png")
    code, out, err = run(
        None, "rotate", "b.png", "o/a-rotate.png", "a.png", "--yaw", "3", "-o", "o/", "--overwrite"
    )
    assert code == 2
    assert "is the input 'o/a-rotate.png'" in err, err
    assert {p: digest(p) for p in before} == before


def test_lattes_print_needs_no_input(workdir):
    code, out, err = run(None, "lattes", "--alpha", "2", "--print-map")
    assert code == 0 and out.startswith("{"), err
