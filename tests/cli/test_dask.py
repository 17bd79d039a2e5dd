"""``--dask``: a real ``dask scheduler`` and two ``dask worker`` processes on 127.0.0.1 render
a video's segments (one worker killed mid-render) and a batch of stills, as a local run does."""

from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np
import pytest
from _cli import ok, run
from test_video_segments import ROTATE, SEG, frames, packets, psnr, start, times, wait_for_segments

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
    for n in names:
        a = (workdir / "local" / n.replace(".png", "-render.png")).read_bytes()
        b = (workdir / "remote" / n.replace(".png", "-render.png")).read_bytes()
        assert hashlib.sha256(a).digest() == hashlib.sha256(b).digest(), n


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
