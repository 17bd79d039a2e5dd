"""``spherewarp render R.json URL...``: inputs read through fsspec (the real FTP server of
tests/ftpserver.py), as ``animate`` reads its still; the output is a local file named from the
URL's file name, the input never written, and refusals one line. Fresh processes."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
from _cli import fails, ok, run

from spherewarp.io import write_image

ZOOM = {"spherewarp": 1, "steps": [{"zoom": {"at": [30, 10], "factor": 2.5}}]}


@pytest.fixture
def room(workdir):
    rng = np.random.default_rng(3)
    write_image(workdir / "room.png", rng.integers(0, 256, (64, 128, 3), dtype=np.uint8))
    (workdir / "r.json").write_text(json.dumps(ZOOM))
    return workdir / "room.png"


def test_a_url_input_renders_the_local_file(room, ftp):
    (ftp.root / "u").mkdir()
    shutil.copy(room, ftp.root / "u" / "room.png")
    url = f"{ftp.url}/u/room.png"
    ok(None, "render", "r.json", "room.png", "-o", "local/")
    want = Path("local/room-render.png").read_bytes()
    out = ok(None, "render", "r.json", url)  # no -o: the URL's name, in the current folder
    assert out == "wrote room-render.png\n"
    assert Path("room-render.png").read_bytes() == want
    ok(None, "render", "r.json", url, "-o", "dir/")  # -o DIR/: the URL's name in DIR
    assert Path("dir/room-render.png").read_bytes() == want
    ok(None, "render", "r.json", url, "-o", "named.png")
    assert Path("named.png").read_bytes() == want
    err = fails(None, "render", "r.json", url, "-o", "dir/")
    assert "'dir/room-render.png' exists; pass --overwrite" in err
    shutil.copy(room, ftp.root / "u" / "other.png")  # a batch of a URL and a local file
    ok(None, "render", "r.json", f"{ftp.url}/u/other.png", "room.png", "-o", "both/")
    assert Path("both/other-render.png").read_bytes() == want
    assert Path("both/room-render.png").read_bytes() == want
    assert sorted(p.name for p in (ftp.root / "u").iterdir()) == ["other.png", "room.png"]
    assert (ftp.root / "u" / "room.png").read_bytes() == room.read_bytes()  # never written


def test_a_url_output_is_refused(room, ftp):
    shutil.copy(room, ftp.root / "o-room.png")
    url = f"{ftp.url}/o-room.png"
    for o in (url, f"{ftp.url}/o-out.png", f"{ftp.url}/o-dir/"):
        err = fails(None, "render", "r.json", url, "-o", o, "--overwrite")
        assert "render writes local files only" in err
    assert sorted(p.name for p in ftp.root.iterdir() if p.name.startswith("o-")) == ["o-room.png"]
    assert (ftp.root / "o-room.png").read_bytes() == room.read_bytes()


def test_an_unreachable_or_missing_url_is_one_line(room, ftp):
    err = fails(None, "render", "r.json", "ftp://127.0.0.1:1/room.png", "-o", "u.png")
    assert "cannot reach 'ftp://127.0.0.1:1/room.png'" in err
    err = fails(None, "render", "r.json", f"{ftp.url}/no-such.png", "-o", "u.png")
    assert f"cannot read '{ftp.url}/no-such.png': no such file" in err
    assert not Path("u.png").exists()
    code, out, err = run(None, "render", "r.json", f"{ftp.url}/no-such.png", "room.png")
    assert code == 2 and out == "wrote room-render.png\n", (code, out, err)
    assert err.splitlines() == [  # a batch: one line an input that failed, and the count
        f"spherewarp: error: cannot read '{ftp.url}/no-such.png': no such file",
        "spherewarp: error: 1 of 2 inputs failed (each said why above)",
    ], err
