"""Spherical video metadata: our writer, our parser, and ffprobe as an independent reader."""

from __future__ import annotations

import json
import shutil
import struct
import subprocess

import pytest

from spherewarp.errors import ImageFormatError
from spherewarp.io.spherical import (
    V1_UUID,
    Spherical,
    box,
    parse_boxes,
    read_spherical,
    write_spherical,
)
from videoclip import make_clip

ffprobe = shutil.which("ffprobe")
needs_ffprobe = pytest.mark.skipif(ffprobe is None, reason="ffprobe is not installed")


@pytest.fixture(scope="module")
def clip(tmp_path_factory):
    return make_clip(tmp_path_factory.mktemp("clip") / "c.mp4", frames=6)


def side_data(path) -> list[dict]:
    out = subprocess.run(
        [ffprobe, "-v", "error", "-select_streams", "v:0", "-show_streams"]
        + ["-show_entries", "stream_side_data", "-of", "json", str(path)],
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    return json.loads(out)["streams"][0].get("side_data_list", [])


def test_box_sizes_and_64_bit_headers():
    assert box(b"free", b"x" * 3) == struct.pack(">I4s", 11, b"free") + b"xxx"
    data = struct.pack(">I4sQ", 1, b"free", 18) + b"ab"
    assert [(b.kind, b.payload) for b in parse_boxes(data)] == [(b"free", b"ab")]
    with pytest.raises(ImageFormatError):
        parse_boxes(struct.pack(">I4s", 100, b"free"))


def test_a_plain_clip_has_none(clip):
    assert read_spherical(clip) is None


@pytest.mark.parametrize("stereo", ["mono", "top-bottom"])
def test_round_trip_through_our_parser(clip, tmp_path, stereo):
    out = tmp_path / "s.mp4"
    shutil.copy(clip, out)
    write_spherical(out, Spherical(stereo=stereo, yaw=12.5, pitch=-3, roll=1))
    meta = read_spherical(out)
    assert meta.versions == {"v1", "v2"}
    assert (meta.projection, meta.stereo) == ("equirectangular", stereo)
    assert (meta.yaw, meta.pitch, meta.roll) == (12.5, -3, 1)
    # written again: replaced, not added twice
    before = out.stat().st_size
    write_spherical(out, Spherical(stereo=stereo, yaw=12.5, pitch=-3, roll=1))
    assert out.stat().st_size == before
    assert out.read_bytes().count(V1_UUID) == 1 and out.read_bytes().count(b"sv3d") == 1
    write_spherical(out, None)
    assert read_spherical(out) is None


@needs_ffprobe
def test_ffprobe_reads_equirectangular(clip, tmp_path):
    out = tmp_path / "s.mp4"
    shutil.copy(clip, out)
    write_spherical(out, Spherical(yaw=30))
    found = {d["side_data_type"]: d for d in side_data(out)}
    sph = found["Spherical Mapping"]
    assert sph["projection"] == "equirectangular" and sph["yaw"] == 30
    assert found["Stereo 3D"]["type"] == "2D"
    assert side_data(clip) == []


@needs_ffprobe
def test_moov_before_mdat_moves_the_chunk_offsets(clip, tmp_path):
    import av
    import numpy as np

    fast = tmp_path / "fast.mp4"
    with av.open(str(clip)) as src, av.open(str(fast), "w", options={"movflags": "faststart"}) as d:
        s = d.add_stream_from_template(src.streams.video[0])
        for p in src.demux(src.streams.video[0]):
            if p.dts is not None:
                p.stream = s
                d.mux(p)
    kinds = [b.kind for b in parse_boxes(fast.read_bytes())]
    assert kinds.index(b"moov") < kinds.index(b"mdat")

    def frames(path):
        with av.open(str(path)) as c:
            return [f.to_ndarray(format="rgb24") for f in c.decode(video=0)]

    before = frames(fast)
    write_spherical(fast, Spherical())
    assert read_spherical(fast).versions == {"v1", "v2"}
    after = frames(fast)  # the samples are still found where the offsets say
    assert len(after) == len(before)
    assert all(np.array_equal(a, b) for a, b in zip(before, after, strict=True))
    assert any(d["side_data_type"] == "Spherical Mapping" for d in side_data(fast))


def test_not_an_mp4(tmp_path):
    p = tmp_path / "x.mp4"
    p.write_bytes(b"hello world, not a video")
    with pytest.raises(ImageFormatError):
        read_spherical(p)
