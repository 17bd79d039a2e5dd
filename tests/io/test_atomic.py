"""spherewarp.io.atomic: whole files or none, and no stale temporaries of dead processes."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from spherewarp.errors import OutputExistsError
from spherewarp.io import atomic


def _dead_pid() -> int:
    proc = subprocess.Popen([sys.executable, "-c", "pass"])
    proc.wait()
    return proc.pid


def test_temp_name_is_tied_to_the_process_and_the_target():
    name = atomic.temp_name(Path("d/pano.jpg"))
    assert name.startswith(f".pano.jpg.spherewarp-{os.getpid()}-") and name.endswith(".tmp.jpg")


def test_failure_inside_removes_the_temporary_and_keeps_the_old_file(tmp_path):
    target = tmp_path / "a.obj"
    target.write_text("old")
    for exc in (RuntimeError, KeyboardInterrupt):
        with pytest.raises(exc):
            with atomic.atomic_file(target, overwrite=True) as tmp:
                tmp.write_text("half")
                raise exc()
        assert target.read_text() == "old"
        assert sorted(p.name for p in tmp_path.iterdir()) == ["a.obj"]
    assert not atomic._LIVE


def test_existing_file_is_kept_without_overwrite(tmp_path):
    target = atomic.write_text(tmp_path / "m.mtl", "one")
    with pytest.raises(OutputExistsError):
        atomic.write_text(target, "two")
    assert atomic.write_text(target, "two", overwrite=True).read_text() == "two"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.mtl"]


@pytest.mark.skipif(os.name != "posix", reason="pids are asked about on POSIX only")
def test_stale_temporaries_of_dead_processes_are_removed_and_nothing_else(tmp_path):
    target = tmp_path / "out.png"
    dead = _dead_pid()
    stale = tmp_path / atomic.temp_name(target, pid=dead)
    live = tmp_path / atomic.temp_name(target, pid=os.getppid())  # a running process
    other_target = tmp_path / atomic.temp_name(tmp_path / "other.png", pid=dead)
    old_style = tmp_path / ".out.png.0123abcd.tmp.png"  # not ours to judge
    lookalike = tmp_path / f".out.png.spherewarp-{dead}-xyz.tmp.png"
    for p in (stale, live, other_target, old_style, lookalike):
        p.write_bytes(b"x")
    atomic.write_bytes(target, b"new")
    left = sorted(p.name for p in tmp_path.iterdir())
    assert stale.name not in left
    assert left == sorted(p.name for p in (target, live, other_target, old_style, lookalike))


def test_remove_live_cleans_up_what_an_interrupt_left(tmp_path):
    target = tmp_path / "x.png"
    cm = atomic.atomic_file(target)
    tmp = cm.__enter__()
    assert tmp in atomic._LIVE and tmp.exists()
    atomic.remove_live()
    assert not tmp.exists() and not atomic._LIVE


def test_a_file_that_cannot_be_made_says_why_in_the_output_name(tmp_path):
    """Not the hidden temporary file's name (a library caller of render_video got a bare
    FileNotFoundError naming '.x.mp4.spherewarp-...tmp.mp4')."""
    from spherewarp.errors import ImageFormatError

    target = tmp_path / "no" / "such" / "x.mp4"
    with pytest.raises(ImageFormatError) as info, atomic.atomic_file(target):
        pass
    assert str(info.value) == f"cannot write '{target}': directory '{target.parent}' does not exist"
    assert isinstance(info.value, OSError) and not (tmp_path / "no").exists()
