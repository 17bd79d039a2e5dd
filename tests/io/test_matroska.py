"""Spherical metadata in Matroska/WebM outputs: StereoMode and Projection, read by ffprobe."""

from __future__ import annotations

import shutil
import struct
import zlib

import pytest

from spherewarp.errors import ImageFormatError, InvalidValueError
from spherewarp.io import matroska as mk
from spherewarp.io.spherical import Spherical, read_spherical, write_spherical
from spherewarp.io.video import probe, render_video
from spherewarp.maps import Mobius
from videoclip import ffprobe_side_data, make_clip

av = pytest.importorskip("av")
ffprobe = shutil.which("ffprobe")
ZOOM = Mobius.zoom((0, 0), 2).inverse()


def crcs_hold(path):
    """Every EBML CRC-32 element of the level-1 elements before the clusters is right."""
    data = path.read_bytes()
    seg = mk._segment(data, path)
    checked = 0
    for el in mk._level1(data, seg):
        if el.id == mk.CLUSTER:
            break
        kids = mk._children(data, el.data, el.end) if el.id != mk.VOID else []
        if kids and kids[0].id == mk.CRC32:
            (crc,) = struct.unpack("<I", data[kids[0].data : kids[0].end])
            assert crc == zlib.crc32(data[kids[0].end : el.end]), hex(el.id)
            checked += 1
    return checked


@pytest.fixture(scope="module")
def stereo_clip(tmp_path_factory):
    return make_clip(tmp_path_factory.mktemp("mkv") / "tb.mp4", frames=6, stereo="top-bottom")


def test_mkv_output_is_marked_stereo_and_equirectangular(tmp_path, stereo_clip):
    out = tmp_path / "o.mkv"

    def posed(meta):
        meta.yaw = 12.0
        return meta

    render_video(stereo_clip, out, lambda t: (ZOOM, {}), spherical=posed)
    meta = read_spherical(out)
    assert meta.versions == {"mkv"} and meta.stereo == "top-bottom"
    assert meta.projection == "equirectangular" and meta.yaw == pytest.approx(12.0)
    assert crcs_hold(out) >= 2  # SeekHead and Tracks: rewritten, CRCs redone
    with av.open(str(out)) as c:  # every frame still decodes, the audio is there
        assert sum(1 for _ in c.decode(video=0)) == 6
        assert [s.type for s in c.streams] == ["video", "audio"]
    assert probe(out).frames in (0, 6)
    if ffprobe is None:
        pytest.skip("ffprobe is not installed")
    sides = ffprobe_side_data(out)
    assert sides["Stereo 3D"]["type"] == "top and bottom"
    assert sides["Spherical Mapping"]["projection"] == "equirectangular"
    assert float(sides["Spherical Mapping"]["yaw"]) == pytest.approx(12.0)


def test_rewrite_in_place_keeps_the_size_and_can_remove(tmp_path):
    clip = make_clip(tmp_path / "c.mp4", frames=3, audio=False)
    out = tmp_path / "o.mkv"
    render_video(clip, out, lambda t: (ZOOM, {}))
    size = out.stat().st_size
    for meta in (Spherical(stereo="left-right", pitch=3.0), None, Spherical()):
        write_spherical(out, meta)
        assert out.stat().st_size == size
        got = read_spherical(out)
        if meta is None:
            assert got is None
        else:
            assert got.stereo == meta.stereo and got.pitch == pytest.approx(meta.pitch)
    assert crcs_hold(out) >= 2
    with av.open(str(out)) as c:
        assert sum(1 for _ in c.decode(video=0)) == 3


def test_not_matroska_and_webm_codecs(tmp_path):
    bad = tmp_path / "x.mkv"
    bad.write_bytes(b"\x1a\x45\xdf\xa3" + b"\x00" * 20)
    with pytest.raises(ImageFormatError, match="not a Matroska file"):
        mk.read_matroska_spherical(bad)
    clip = make_clip(tmp_path / "c.mp4", frames=2)
    with pytest.raises(InvalidValueError, match="WebM file holds VP8, VP9 or AV1"):
        render_video(clip, tmp_path / "o.webm", lambda t: (ZOOM, {}), codec="libx264")
    with pytest.warns(UserWarning, match="WebM file cannot hold audio in aac"):
        render_video(clip, tmp_path / "o.webm", lambda t: (ZOOM, {}))  # libvpx-vp9 by default
    assert probe(tmp_path / "o.webm").codec == "vp9"
    assert read_spherical(tmp_path / "o.webm").projection == "equirectangular"
