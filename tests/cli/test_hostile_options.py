"""Extreme option values end in one error line naming the option, never an internal error."""

from __future__ import annotations

import json

import pytest
from _cli import fails, ok, run

from spherewarp.demo import sample_path


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["mobius", "--matrix", "1e308,0,0,1"], "singular in double precision"),
        (["zoom", "--at", "0,0", "--factor", "5e-324"], "--factor"),
        (["zoom", "--at", "0,0", "--factor", "1e-300"], "--factor"),
        (["rotate", "--yaw", "3", "--size", "65536x32768"], "--size"),
        (["rotate", "--yaw", "3", "--size", "32768x16384"], "--max-pixels"),
        (["rotate", "--yaw", "3", "--max-pixels", "1000"], "--max-pixels"),
        (["torus", "--cells", "1x16", "--size", "20000"], "--max-pixels"),  # 20000 x 320000
        (["lattes", "--alpha", "8"], "--exact"),
        (["droste", "--center", "0,0", "--inner-radius", "1e-300"], "--scale"),
        (["droste", "--center", "0,0", "--inner-radius", "10", "--phase", "inf"], "'--phase'"),
        (["schottky", "--generator", "0,0,20 -> 180,0,20", "--phase", "nan"], "'--phase'"),
        (["schottky", "--generator", "0,0,1e-300 -> 180,0,1e-300"], "radius at least 0.001"),
        (["power", "--n", "1e308"], "exponent of at most 1e+06"),
        (["power", "--n", "0.5", "--cut", "nan"], "'--cut'"),
        (["exp", "--lam", "1e308"], "lam of at most 1e+06"),
        (["project", "--to", "cubemap", "--size", "5x3"], "--size WxH sets an output's size"),
        (["project", "--from", "cubemap", "--fov", "90"], "--fov does not apply to cubemap"),
    ],
)
def test_extreme_values_give_one_error_line(tmp_path, monkeypatch, args, needle):
    monkeypatch.chdir(tmp_path)
    err = fails(None, args[0], sample_path(), *args[1:], "-o", "out.png")
    assert needle in err, err
    assert not (tmp_path / "out.png").exists()


def test_lattes_alpha_8_renders_with_exact(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    ok(None, "lattes", sample_path(), "--alpha", "8", "--exact", "--size", "128x64", "-o", "l.png")
    assert (tmp_path / "l.png").exists()


def test_a_recipes_size_obeys_the_pixel_limit(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    step = {"zoom": {"at": [0, 0], "factor": 2}}
    recipe = {"spherewarp": 1, "steps": [step], "view": {"size": [32768, 16384]}}
    (tmp_path / "r.json").write_text(json.dumps(recipe))
    err = fails(None, "render", "r.json", sample_path(), "-o", "out.png")
    assert "the recipe's view.size" in err and "--max-pixels" in err
    ok(None, "render", "r.json", sample_path(), "-o", "out.png", "--size", "64x32")  # overridden


def test_side_outputs_are_checked_before_the_picture_is_written(tmp_path, monkeypatch):
    """--mesh and --save-recipe where they cannot be written: refused before any work."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "ro").mkdir()
    (tmp_path / "afile").write_text("x")
    err = fails(None, "torus", sample_path(), "--mesh", "afile/m.obj", "-o", "t.png")
    assert "'afile' is not a directory" in err
    err = fails(None, "zoom", sample_path(), "--at", "0,0", "--factor", "2",
                "--save-recipe", "afile/r.json", "-o", "z.png")  # fmt: skip
    assert "'afile' is not a directory" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["afile", "ro"]


def test_one_input_of_a_batch_too_small_is_named(tmp_path, monkeypatch):
    from PIL import Image

    monkeypatch.chdir(tmp_path)
    Image.new("RGB", (1, 1)).save("tiny.png")
    code, _, err = run(None, "rotate", sample_path(), "tiny.png", "--yaw", "3", "--force",
                       "--size", "64x32", "-o", "out/")  # fmt: skip
    assert code == 2 and "tiny.png: expected an image at least 2 pixels wide" in err
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["interior-rotate.png"]


def test_project_roll_and_view_roll_are_not_added(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    err = fails(None, "project", sample_path(), "--to", "rectilinear", "--roll", "10",
                "--view-roll", "30", "-o", "x.png")  # fmt: skip
    assert "give --roll or --view-roll, not both" in err


def test_peirce_inverse_takes_a_2_to_1_size_and_antialias(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    ok(None, "peirce", sample_path(), "--size", "64", "-o", "p.png")
    err = fails(None, "peirce", "p.png", "--inverse", "--size", "64x64", "-o", "i.png")
    assert "--size" in err and "2:1" in err
    ok(None, "peirce", "p.png", "--inverse", "--size", "64x32", "-o", "a.png", "--antialias", "4")
    ok(None, "peirce", "p.png", "--inverse", "--size", "64x32", "-o", "b.png")
    assert (tmp_path / "a.png").read_bytes() != (tmp_path / "b.png").read_bytes()


def test_a_warning_quoting_a_traceback_stays_one_line(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("NUMBA_NUM_THREADS", "abc")
    args = ["--yaw", "3", "--size", "64x32", "-o", "r.png"]
    code, _, err = run(None, "rotate", sample_path(), *args)
    assert code == 0 and "NUMBA_NUM_THREADS" in err
    assert "Traceback" not in err and "File " not in err and err.count("\n") == 1


def test_peirce_size_is_a_square(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    for size in ("1x1", "300x100"):
        err = fails(None, "peirce", sample_path(), "--size", size, "-o", "p.png")
        assert "--size" in err and "square" in err
    ok(None, "peirce", sample_path(), "--size", "64", "-o", "a.png")
    ok(None, "peirce", sample_path(), "--size", "64x64", "-o", "b.png")
    assert (tmp_path / "a.png").read_bytes() == (tmp_path / "b.png").read_bytes()
