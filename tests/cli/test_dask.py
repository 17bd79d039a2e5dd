"""``--dask``: a real ``dask scheduler`` and two ``dask worker`` processes on 127.0.0.1 render
a video's segments (one worker killed mid-render; the client killed and resumed), an
animation's, a split-screen of two clips' and a batch of stills, as a local run does."""

from __future__ import annotations

import hashlib
import json
import signal
from pathlib import Path

import numpy as np
import pytest
from _cli import ok, run
from test_video_segments import (
    ROTATE,
    SEG,
    digest,
    frames,
    packets,
    psnr,
    start,
    stop_midway,
    times,
    wait_for_segments,
)

from spherewarp.io import write_image
from videoclip import make_clip

av = pytest.importorskip("av")
pytest.importorskip("distributed")


@pytest.fixture
def clip(workdir):
    return make_clip(workdir / "in.mp4", frames=48)


@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    from daskcluster import Cluster

    c = Cluster(tmp_path_factory.mktemp("dask"), workers=2)
    yield c
    c.close()


def test_dask_render_equals_the_local_one(clip, cluster):
    ok(None, "video", clip.name, "-o", "local.mp4", "--segment", SEG, "--quiet", *ROTATE)
    code, _, err = run(None, "video", clip.name, "-o", "dask.mp4", "--segment", SEG, "--quiet",
                       "--dask", cluster.address, *ROTATE)  # fmt: skip
    assert code == 0 and err == "", err
    assert times("dask.mp4") == times("local.mp4") == times(clip)
    assert packets("dask.mp4", "audio") == packets(clip, "audio")
    a, b = frames("dask.mp4"), frames("local.mp4")
    assert len(a) == len(b) == 48
    assert min(psnr(x, y) for x, y in zip(a, b, strict=True)) >= 45
    assert not Path("dask.mp4.parts").exists()


def test_dask_refuses_a_path_workers_cannot_read(cluster):
    from spherewarp.errors import InvalidValueError
    from spherewarp.io.segments import check_workers, dask_client

    client = dask_client(cluster.address)
    try:
        with pytest.raises(InvalidValueError, match="cannot reach '/nowhere/in.mp4'"):
            check_workers(client, ["/nowhere/in.mp4"])
    finally:
        client.close()


def test_dask_refuses_a_url_workers_cannot_reach(cluster):
    from spherewarp.errors import InvalidValueError
    from spherewarp.io.segments import check_workers, dask_client

    client = dask_client(cluster.address)
    try:
        with pytest.raises(InvalidValueError, match=r"worker tcp://127\.0\.0\.1:\d+ cannot reach "
                           "'ftp://127.0.0.1:1/in.mp4'"):  # fmt: skip
            check_workers(client, ["ftp://127.0.0.1:1/in.mp4"])
    finally:
        client.close()


def test_dask_reads_and_writes_urls(clip, cluster, ftp):
    import shutil

    shutil.copy(clip, ftp.root / "in.mp4")
    ok(None, "video", clip.name, "-o", "local.mp4", "--segment", SEG, "--quiet", *ROTATE)
    code, _, err = run(None, "video", f"{ftp.url}/in.mp4", "-o", f"{ftp.url}/o/dask.mp4",
                       "--segment", SEG, "--quiet", "--dask", cluster.address, *ROTATE)  # fmt: skip
    assert code == 0 and err == "", err
    got = ftp.root / "o" / "dask.mp4"
    assert sorted(p.name for p in got.parent.iterdir()) == ["dask.mp4"]  # no parts, no temp
    assert times(got) == times("local.mp4")
    assert packets(got, "audio") == packets(clip, "audio")
    a, b = frames(got), frames("local.mp4")
    assert len(a) == len(b) == 48
    assert min(psnr(x, y) for x, y in zip(a, b, strict=True)) >= 45


def test_a_batch_of_stills_on_dask_equals_the_local_files(workdir, cluster):
    rng = np.random.default_rng(7)
    names = []
    for k in range(20):
        img = np.roll(rng.integers(0, 255, (32, 64, 3), dtype=np.uint8), k, axis=1)
        names.append(write_image(workdir / f"s{k:02d}.png", img).name)
    ok(None, "rotate", names[0], "--yaw", "40", "--pitch", "10", "--save-recipe", "r.json",
       "--dry-run")  # fmt: skip
    ok(None, "render", "r.json", *names, "-o", "local/")
    code, out, err = run(None, "render", "r.json", *names, "-o", "remote/", "--dask",
                         cluster.address)  # fmt: skip
    assert code == 0 and err == "", err
    assert len(out.splitlines()) == 20
    same_renders(workdir, names)


def same_renders(workdir, names) -> None:
    """``render``'s files of ``names`` in local/ and remote/ are byte for byte the same."""
    for n in names:
        a = (workdir / "local" / n.replace(".png", "-render.png")).read_bytes()
        b = (workdir / "remote" / n.replace(".png", "-render.png")).read_bytes()
        assert hashlib.sha256(a).digest() == hashlib.sha256(b).digest(), n


def test_render_urls_on_dask_equal_the_local_files(workdir, cluster, ftp):
    rng = np.random.default_rng(8)
    (ftp.root / "rd").mkdir()
    names = []
    for k in range(3):
        img = np.roll(rng.integers(0, 255, (32, 64, 3), dtype=np.uint8), k, axis=1)
        names.append(write_image(workdir / f"u{k}.png", img).name)
        write_image(ftp.root / "rd" / names[-1], img)
    ok(None, "rotate", names[0], "--yaw", "40", "--pitch", "10", "--save-recipe", "r.json",
       "--dry-run")  # fmt: skip
    ok(None, "render", "r.json", *names, "-o", "local/")
    urls = [f"{ftp.url}/rd/{n}" for n in names]
    code, out, err = run(None, "render", "r.json", *urls, "-o", "remote/", "--dask",
                         cluster.address)  # fmt: skip
    assert code == 0 and err == "", err
    assert len(out.splitlines()) == 3
    same_renders(workdir, names)
    assert sorted(p.name for p in (ftp.root / "rd").iterdir()) == names  # never written
    code, _, err = run(None, "render", "r.json", "ftp://127.0.0.1:1/u0.png", "--dask",
                       cluster.address)  # fmt: skip
    assert code == 2 and err.count("\n") == 1, err
    assert "cannot reach 'ftp://127.0.0.1:1/u0.png'" in err


def test_animate_on_dask_gives_the_same_file(workdir, cluster):
    from test_animate_segments import SPIN

    from videoclip import panorama

    write_image(workdir / "pano.png", panorama())
    (workdir / "spin.json").write_text(json.dumps({"spherewarp": 1, **SPIN}))
    args = ("animate", "spin.json", "pano.png", "--fps", "24", "--segment", SEG, "-q")
    ok(None, *args, "-o", "local.mp4")
    code, _, err = run(None, *args, "-o", "dask.mp4", "--dask", cluster.address)
    assert code == 0 and err == "", err
    assert digest("dask.mp4") == digest("local.mp4")
    assert not Path("dask.mp4.parts").exists()


def test_animate_urls_on_dask_give_the_same_file(workdir, cluster, ftp):
    from test_animate_segments import SPIN

    from videoclip import panorama

    write_image(ftp.root / "d-pano.png", panorama())
    write_image(workdir / "pano.png", panorama())
    (workdir / "spin.json").write_text(json.dumps({"spherewarp": 1, **SPIN}))
    args = ("--fps", "24", "--segment", SEG, "-q")
    ok(None, "animate", "spin.json", "pano.png", *args, "-o", "local.mp4")
    code, _, err = run(None, "animate", "spin.json", f"{ftp.url}/d-pano.png", *args,
                       "-o", f"{ftp.url}/d-out/dask.mp4", "--dask", cluster.address)  # fmt: skip
    assert code == 0 and err == "", err
    assert digest(ftp.root / "d-out" / "dask.mp4") == digest("local.mp4")
    assert sorted(p.name for p in (ftp.root / "d-out").iterdir()) == ["dask.mp4"]


def test_splitscreen_of_clips_on_dask_gives_the_same_file(workdir, cluster):
    make_clip(workdir / "a.mp4", frames=12)
    make_clip(workdir / "b.mp4", frames=12)
    split = ("splitscreen", "--seam", "0")
    args = ("video", "a.mp4", "b.mp4", "--segment", SEG, "-q")
    ok(None, *args, *split, "-o", "local.mp4")
    code, _, err = run(None, *args, "--dask", cluster.address, *split, "-o", "dask.mp4")
    assert code == 0 and err == "", err
    assert digest("dask.mp4") == digest("local.mp4")
    assert not Path("dask.mp4.parts").exists()


def test_resume_after_the_client_is_killed(clip, cluster):
    args = ("video", clip.name, "--segment", SEG, "--dask", cluster.address)
    ok(None, *args, "-o", "whole.mp4", "-q", *ROTATE)
    done = stop_midway((*args, "-q", *ROTATE), "cut.mp4", signal.SIGKILL, after=1)  # in flight
    code, _, err = run(None, *args, "-o", "cut.mp4", "--resume", "--progress", "json", *ROTATE)
    assert code == 0, err
    assert json.loads(err.splitlines()[0])["frames"] >= 6 * len(done)  # not rendered again
    assert digest("cut.mp4") == digest("whole.mp4")
    assert not Path("cut.mp4.parts").exists()


def test_dask_survives_a_killed_worker(clip, cluster):  # last: it leaves one worker
    ok(None, "video", clip.name, "-o", "local.mp4", "--segment", SEG, "--quiet", *ROTATE)
    p = start("video", clip.name, "-o", "dask.mp4", "--segment", SEG, "--quiet", "--dask",
              cluster.address, *ROTATE)  # fmt: skip
    wait_for_segments(Path("dask.mp4.parts"), 1, p)
    cluster.kill_worker(0)  # with segments in flight
    _, err = p.communicate(timeout=300)
    assert p.returncode == 0, err
    assert times("dask.mp4") == times("local.mp4")
    assert packets("dask.mp4", "audio") == packets(clip, "audio")
    a, b = frames("dask.mp4"), frames("local.mp4")
    assert len(a) == len(b) == 48
    assert min(psnr(x, y) for x, y in zip(a, b, strict=True)) >= 45
