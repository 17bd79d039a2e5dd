"""``spherewarp animate R.json URL -o URL.mp4``: a still read and a video written through fsspec
(the real FTP server of tests/ftpserver.py), as ``video`` reads and writes URLs: the same file
as a local render, ``--jobs``, ``--resume``, and one-line refusals. Fresh processes."""

from __future__ import annotations

import json
import os
import shutil
import signal
from pathlib import Path

import pytest
from _cli import fails, ok, run
from test_animate_segments import SPIN
from test_video_segments import digest, start, wait_for_segments

from spherewarp.io import write_image
from videoclip import panorama

pytest.importorskip("av")

SEG = "0.25"  # 6 frames a segment at 24 fps: 8 segments


@pytest.fixture
def spin(workdir):
    write_image(workdir / "pano.png", panorama())
    (workdir / "spin.json").write_text(json.dumps({"spherewarp": 1, **SPIN}))
    return ("spin.json", "pano.png", "--fps", "24", "--segment", SEG, "-q")


def on_ftp(ftp, name: str) -> str:
    """Copy the test's pano.png to the server as ``name``; its URL."""
    shutil.copy("pano.png", ftp.root / name)
    return f"{ftp.url}/{name}"


def test_a_url_still_to_a_url_video_gives_the_local_file(spin, ftp):
    still = on_ftp(ftp, "a-pano.png")
    ok(None, "animate", *spin, "-o", "local.mp4")
    out = f"{ftp.url}/a-out/anim.mp4"
    args = ("animate", "spin.json", still, "--fps", "24", "--segment", SEG, "-q")
    ok(None, *args, "-o", out, "--jobs", "2")
    got = ftp.root / "a-out" / "anim.mp4"
    assert digest(got) == digest("local.mp4")
    assert sorted(p.name for p in got.parent.iterdir()) == ["anim.mp4"]  # no parts, no temp
    err = fails(None, *args, "-o", out)
    assert f"'{out}' exists; pass --overwrite" in err
    ok(None, *args, "-o", out, "--overwrite")  # one process, a URL still
    assert digest(got) == digest("local.mp4")
    ok(None, *args, "-o", "from-url.mp4")  # a URL still to a local video
    assert digest("from-url.mp4") == digest("local.mp4")


def test_resume_a_url_video(spin, ftp):
    still = on_ftp(ftp, "r-pano.png")
    ok(None, "animate", *spin, "-o", "whole.mp4")
    out = f"{ftp.url}/r-out/cut.mp4"
    args = ("animate", "spin.json", still, "--fps", "24", "--segment", SEG)
    p = start(*args, "-q", "-o", out)
    parts = ftp.root / "r-out" / "cut.mp4.parts"
    wait_for_segments(parts, 2, p)
    p.send_signal(signal.SIGINT)
    _, err = p.communicate(timeout=60)
    assert p.returncode == 130 and err.count("\n") == 1 and "--resume" in err, err
    assert not (ftp.root / "r-out" / "cut.mp4").exists()
    done = json.loads((parts / "manifest.json").read_text())["done"]
    code, _, err = run(None, *args, "-o", out, "--resume", "--progress", "json")
    assert code == 0, err
    first = json.loads(err.splitlines()[0])
    assert first["frames"] >= 6 * len(done) and first["total"] == 48  # not rendered again
    assert digest(ftp.root / "r-out" / "cut.mp4") == digest("whole.mp4")
    assert sorted(os.listdir(ftp.root / "r-out")) == ["cut.mp4"]


def test_an_unreachable_or_missing_still_is_one_line(spin, ftp):
    err = fails(None, "animate", "spin.json", "ftp://127.0.0.1:1/pano.png", "--fps", "24",
                "-o", "u.mp4")  # fmt: skip
    assert "cannot reach 'ftp://127.0.0.1:1/pano.png'" in err
    err = fails(None, "animate", "spin.json", f"{ftp.url}/no-such.png", "--fps", "24",
                "-o", "u.mp4")  # fmt: skip
    assert f"cannot read '{ftp.url}/no-such.png': no such file" in err
    assert not Path("u.mp4").exists() and not Path("u.mp4.parts").exists()


def test_refused_url_outputs(spin, ftp):
    still = on_ftp(ftp, "x-pano.png")
    for o in (f"{ftp.url}/x-frames/", f"{ftp.url}/x-frames/%04d.png"):
        err = fails(None, "animate", "spin.json", still, "--fps", "24", "-o", o)
        assert "numbered images are written to local files only" in err
    assert not (ftp.root / "x-frames").exists()
    shutil.copy("pano.png", ftp.root / "x-still.mp4")  # a PNG by its content
    same = f"{ftp.url}/x-still.mp4"
    err = fails(None, "animate", "spin.json", same, "--fps", "24", "-o", same, "--overwrite")
    assert "names the input; an input is never overwritten" in err
    assert (ftp.root / "x-still.mp4").read_bytes() == Path("pano.png").read_bytes()


def test_urls_without_fsspec_say_how_to_install(spin, workdir):
    blocker = workdir / "nofsspec"
    blocker.mkdir()
    (blocker / "fsspec.py").write_text("raise ImportError('hidden for the test')\n")
    env = {**os.environ, "PYTHONPATH": f"{blocker}{os.pathsep}{os.environ.get('PYTHONPATH', '')}"}
    url = "ftp://127.0.0.1:1/x.png"
    for still, out in ((url, "u.mp4"), ("pano.png", "ftp://127.0.0.1:1/u.mp4")):
        p = start("animate", "spin.json", still, "--fps", "24", "-o", out, env=env)
        _, err = p.communicate(timeout=120)
        assert p.returncode == 2 and err.count("\n") == 1, err
        assert 'pip install "spherewarp[dask]"' in err and "ftp://127.0.0.1:1/" in err
    assert not Path("u.mp4").exists()
