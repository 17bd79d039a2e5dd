"""The demo: effects on the bundled sample, written into a folder, never clobbering."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from spherewarp import coords
from spherewarp.demo import DEMO_EFFECTS, MANIFEST, PICTURE, DemoEffect, run_demo, sample_path
from spherewarp.errors import InvalidValueError, OutputExistsError
from spherewarp.io import GPano, read_image

SIZE = (128, 64)


@pytest.fixture(scope="module")
def demo_dir(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, list[Path], list[str]]:
    folder = tmp_path_factory.mktemp("demo") / "out"
    lines: list[str] = []
    paths = run_demo(folder, size=SIZE, supersample=1, echo=lines.append)
    return folder, paths, lines


def test_effects_are_well_formed():
    names = [e.name for e in DEMO_EFFECTS]
    assert len(names) == len(set(names)) >= 7
    for e in DEMO_EFFECTS:
        assert re.fullmatch(r"[a-z0-9]+(-[a-z0-9]+)*", e.name), e.name
        assert e.description and "\n" not in e.description
        assert callable(e.render)
    for needed in ("original", "testpattern", "zoom-picture", "testpattern-zoom"):
        assert needed in names


def test_demo_writes_every_effect(demo_dir):
    folder, paths, lines = demo_dir
    assert [p.name for p in paths] == [
        f"{k:02d}-{e.name}.png" for k, e in enumerate(DEMO_EFFECTS, start=1)
    ]
    assert sorted(folder.iterdir()) == sorted([*paths, folder / MANIFEST])
    for p, effect in zip(paths, DEMO_EFFECTS, strict=True):
        img = read_image(p)
        assert img.pixels.shape == (SIZE[1], SIZE[0], 3) and img.pixels.dtype == np.uint8
        # panoramas carry GPano; the Peirce/torus panel is no panorama and carries none
        assert img.gpano == (GPano.full_sphere(*SIZE) if effect.equirectangular else None)
        assert img.pixels.std() > 5  # not blank
    assert len(lines) == len(paths) + 1
    assert all(str(p) in line for p, line in zip(paths, lines, strict=False))
    assert f"{len(paths)} images" in lines[-1]


def test_effects_differ(demo_dir):
    _, paths, _ = demo_dir
    images = [read_image(p).pixels.astype(int) for p in paths]
    for i in range(len(images)):
        for j in range(i + 1, len(images)):
            assert np.abs(images[i] - images[j]).mean() > 2, (paths[i].name, paths[j].name)


def test_refuses_to_clobber_and_writes_nothing(tmp_path):
    folder = tmp_path / "d"
    folder.mkdir()
    third = folder / f"03-{DEMO_EFFECTS[2].name}.png"
    third.write_bytes(b"keep me")
    with pytest.raises(OutputExistsError, match="overwrite") as err:
        run_demo(folder, size=SIZE, echo=None)
    assert "pass overwrite=True" in str(err.value) and "pass --overwrite" in err.value.cli_message
    assert sorted(folder.iterdir()) == [third] and third.read_bytes() == b"keep me"
    run_demo(folder, size=SIZE, supersample=1, overwrite=True, echo=None)
    assert read_image(third).pixels.shape == (SIZE[1], SIZE[0], 3)


def test_runs_again_over_its_own_files_only(tmp_path):
    """A second run replaces what the first wrote, and no file it did not write."""
    folder = tmp_path / "d"
    effects = DEMO_EFFECTS[:3]
    first = run_demo(folder, size=SIZE, supersample=1, effects=effects, echo=None)
    mine = folder / "notes.txt"
    mine.write_text("mine")
    again = run_demo(folder, size=(32, 16), supersample=1, effects=effects, echo=None)
    assert again == first and read_image(again[0]).pixels.shape == (16, 32, 3)
    assert mine.read_text() == "mine"
    # a demo file the user changed (or made) is theirs: refused, and nothing is written
    first[1].write_bytes(b"edited")
    with pytest.raises(OutputExistsError, match="overwrite"):
        run_demo(folder, size=SIZE, supersample=1, effects=effects, echo=None)
    assert first[1].read_bytes() == b"edited"
    assert read_image(first[0]).pixels.shape == (16, 32, 3)


def test_custom_effects_and_default_size(tmp_path):
    effects = [DemoEffect("flat", "the sample itself", lambda d: d.sample)]
    paths = run_demo(tmp_path, effects=effects, echo=None)
    assert [p.name for p in paths] == ["01-flat.png"]
    np.testing.assert_array_equal(read_image(paths[0]).pixels, read_image(sample_path()).pixels)


def test_directory_that_is_a_file(tmp_path):
    (tmp_path / "f").write_text("x")
    with pytest.raises(InvalidValueError, match="not a directory"):
        run_demo(tmp_path / "f", size=SIZE, echo=None)


def test_picture_is_where_the_demo_says():
    # The framed picture is a teal patch on a grey-white wall.
    img = read_image(sample_path()).pixels.astype(float)
    h, w = img.shape[:2]
    x, y = (int(v) for v in coords.pixel_from_lonlat(np.radians(PICTURE), w, h))
    picture = img[y - 40 : y + 40, x - 20 : x + 20].reshape(-1, 3).mean(0)
    wall = img[y - 5 : y + 5, x + 35 : x + 45].reshape(-1, 3).mean(0)
    assert picture[1] - picture[0] > 10
    assert abs(wall[1] - wall[0]) < 5


def test_sample_path_unknown():
    with pytest.raises(InvalidValueError):
        sample_path("nope.png")


def test_a_folder_that_cannot_be_made_is_one_error(tmp_path):
    from spherewarp.errors import ImageFormatError

    (tmp_path / "file").write_text("x")
    with pytest.raises(ImageFormatError, match="cannot make the folder"):
        run_demo(tmp_path / "file" / "d", size=SIZE, echo=None)


def test_a_file_of_the_users_by_the_manifests_name_is_kept(tmp_path):
    """A .spherewarp-demo.json the demo did not write was replaced by the demo's own."""
    folder = tmp_path / "d"
    folder.mkdir()
    (folder / MANIFEST).write_text('{"my": "own data"}')
    with pytest.raises(OutputExistsError, match=re.escape(MANIFEST)):
        run_demo(folder, size=SIZE, supersample=1, effects=DEMO_EFFECTS[:1], echo=None)
    assert sorted(p.name for p in folder.iterdir()) == [MANIFEST]
    assert (folder / MANIFEST).read_text() == '{"my": "own data"}'
    run_demo(folder, size=SIZE, supersample=1, effects=DEMO_EFFECTS[:1], overwrite=True, echo=None)
    assert "spherewarp demo" in (folder / MANIFEST).read_text()


def test_a_folder_made_for_nothing_is_removed(tmp_path, monkeypatch):
    """A first write that fails (a full disk) left the empty folder the demo had made;
    a folder that was there before stays."""
    import errno

    import spherewarp.io as sio

    def full(*args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(sio, "write_image", full)
    folder = tmp_path / "new" / "demo"
    with pytest.raises(OSError):
        run_demo(folder, size=SIZE, supersample=1, effects=DEMO_EFFECTS[:1], echo=None)
    assert not folder.exists()
    folder.mkdir()
    with pytest.raises(OSError):
        run_demo(folder, size=SIZE, supersample=1, effects=DEMO_EFFECTS[:1], echo=None)
    assert folder.is_dir()
