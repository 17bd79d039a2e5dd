"""render_video: timing, audio, metadata and pixels of a short turning panorama, zoomed."""

from __future__ import annotations

import json
import shutil
import subprocess
import warnings

import numpy as np
import pytest

from spherewarp.errors import ImageFormatError, InvalidValueError, OutputExistsError
from spherewarp.io.video import probe, render_video, video_encoders
from spherewarp.maps import Mobius
from spherewarp.render import warp
from videoclip import RATE, SECONDS, make_clip

av = pytest.importorskip("av")
ffprobe = shutil.which("ffprobe")
ZOOM = Mobius.zoom((0, 0), 2).inverse()


@pytest.fixture(scope="module")
def clip(tmp_path_factory):
    return make_clip(tmp_path_factory.mktemp("clip") / "turning.mp4")


@pytest.fixture(scope="module")
def zoomed(clip, tmp_path_factory):
    out = tmp_path_factory.mktemp("out") / "zoomed.mp4"
    calls = []

    def frame_map(t):
        calls.append(t)
        return ZOOM, {}

    render_video(clip, out, frame_map)
    return out, calls


def audio_packets(path):
    """Each audio packet's bytes, and its time in milliseconds (time bases differ by container)."""
    with av.open(str(path)) as c:
        return [
            (bytes(p), round(float(p.pts * p.time_base) * 1000))
            for p in c.demux(c.streams.audio[0])
            if p.size
        ]


def frames(path):
    with av.open(str(path)) as c:
        return [f.to_ndarray(format="rgb24") for f in c.decode(video=0)]


def psnr(a, b):
    mse = np.mean((a.astype(np.float64) - b) ** 2)
    return 10 * np.log10(255.0**2 / mse)


def test_timing_and_audio_are_kept(clip, zoomed):
    out, calls = zoomed
    a, b = probe(clip), probe(out)
    assert b.frames == a.frames == RATE * SECONDS
    assert b.rate == a.rate == RATE and b.time_base == a.time_base
    assert b.duration == pytest.approx(a.duration) and a.duration == pytest.approx(SECONDS)
    assert audio_packets(out) == audio_packets(clip)  # copied, not re-encoded
    # the map was asked for at each frame's presentation time
    assert calls == pytest.approx([k / RATE for k in range(RATE * SECONDS)])


def test_each_frame_is_the_still_render(clip, zoomed):
    src, out = frames(clip), frames(zoomed[0])
    assert len(out) == len(src)
    for k in (0, len(src) // 2, len(src) - 1):
        assert psnr(warp(src[k], ZOOM), out[k]) >= 35, k


def test_spherical_metadata_written(zoomed):
    meta = probe(zoomed[0]).spherical
    assert meta is not None and meta.versions == {"v1", "v2"}
    if ffprobe is None:
        pytest.skip("ffprobe is not installed")
    text = subprocess.run(
        [ffprobe, "-v", "error", "-select_streams", "v:0", "-show_streams"]
        + ["-show_entries", "stream_side_data", "-of", "json", str(zoomed[0])],
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    sides = json.loads(text)["streams"][0]["side_data_list"]
    assert {"side_data_type": "Spherical Mapping", "projection": "equirectangular"}.items() <= {
        **next(d for d in sides if d["side_data_type"] == "Spherical Mapping")
    }.items()


def test_variable_frame_rate_and_ten_bit(tmp_path):
    src = tmp_path / "vfr.mp4"
    times = [0, 1, 3, 4, 8, 9]  # in 1/24 s
    with av.open(str(src), "w") as c:
        v = c.add_stream("libx265", rate=24, options={"x265-params": "log-level=error"})
        v.width, v.height, v.pix_fmt = 64, 32, "yuv420p10le"
        from fractions import Fraction

        v.codec_context.time_base = v.time_base = Fraction(1, 24)
        for t in times:
            f = av.VideoFrame.from_ndarray(np.full((32, 64, 3), 20 * t, np.uint8), format="rgb24")
            f.pts, f.time_base = t, Fraction(1, 24)
            c.mux(v.encode(f))
        c.mux(v.encode(None))
    out = tmp_path / "out.mp4"
    seen = []
    render_video(src, out, lambda t: (seen.append(t) or ZOOM, {}), codec="libx265")
    assert seen == pytest.approx([t / 24 for t in times])
    info = probe(out)
    assert info.pix_fmt == "yuv420p10le" and info.bit_depth == 10
    with av.open(str(out)) as c:
        pts = [float(f.pts * f.time_base) for f in c.decode(video=0)]
    assert pts == pytest.approx([t / 24 for t in times])


def test_bad_inputs_write_nothing(tmp_path, clip):
    out = tmp_path / "o.mp4"
    text = tmp_path / "notes.mp4"
    text.write_text("not a video")
    with pytest.raises(ImageFormatError, match="not a video"):
        render_video(text, out, lambda t: (ZOOM, {}))
    with pytest.raises(InvalidValueError, match="no such video encoder.*libx264"):
        render_video(clip, out, lambda t: (ZOOM, {}), codec="nope")
    with pytest.raises(ImageFormatError, match="unknown video extension"):
        render_video(clip, tmp_path / "o.png", lambda t: (ZOOM, {}))
    square = make_clip(tmp_path / "square.mp4", frames=2, audio=False, size=(64, 64))
    with pytest.raises(InvalidValueError, match="--force"):
        render_video(square, out, lambda t: (ZOOM, {}))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["notes.mp4", "square.mp4"]
    out.write_bytes(b"x")
    with pytest.raises(OutputExistsError):
        render_video(clip, out, lambda t: (ZOOM, {}))
    render_video(square, tmp_path / "sq.mp4", lambda t: (ZOOM, {}), force=True)
    assert probe(tmp_path / "sq.mp4").frames == 2


def test_an_error_mid_render_leaves_nothing(tmp_path, clip):
    def frame_map(t):
        if t > 0.5:
            raise KeyboardInterrupt
        return ZOOM, {}

    with pytest.raises(KeyboardInterrupt):
        render_video(clip, tmp_path / "o.mp4", frame_map)
    assert list(tmp_path.iterdir()) == []


def test_encoders_listed():
    assert {"libx264", "libx265"} <= set(video_encoders())


@pytest.mark.skipif(shutil.which("ffmpeg") is None, reason="ffmpeg is not installed")
@pytest.mark.parametrize("container,codec", [("mp4", "mov_text"), ("mkv", "srt")])
def test_subtitles_copied_or_dropped_with_a_warning(tmp_path, container, codec):
    clip = make_clip(tmp_path / "c.mp4", frames=24)
    srt = tmp_path / "s.srt"
    srt.write_text(
        "1\n00:00:00,000 --> 00:00:00,500\nhello\n\n2\n00:00:00,500 --> 00:00:01,000\nyou\n"
    )
    src = tmp_path / f"sub.{container}"
    subprocess.run(
        ["ffmpeg", "-v", "error", "-i", str(clip), "-i", str(srt), "-map", "0", "-map", "1"]
        + ["-c", "copy", "-c:s", codec, str(src)],
        check=True,
    )
    out = tmp_path / "o.mp4"
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        render_video(src, out, lambda t: (ZOOM, {}))
    with av.open(str(out)) as c:
        kinds = [s.type for s in c.streams]
    if codec == "mov_text":
        assert kinds == ["video", "audio", "subtitle"] and not caught

        def subs(path):
            with av.open(str(path)) as c:
                return [(bytes(p), p.pts) for p in c.demux(c.streams.subtitles[0]) if p.size]

        assert subs(out) == subs(src) and len(subs(src)) == 2
    else:
        assert kinds == ["video", "audio"]
        assert [str(w.message) for w in caught] == [
            "stream #2 (subtitle, srt) is dropped: an MP4/MOV file cannot hold subtitle in srt"
        ]
    assert audio_packets(out) == audio_packets(src)


def test_stereo_input_needs_force(tmp_path):
    from spherewarp.io.spherical import Spherical, write_spherical

    clip = make_clip(tmp_path / "tb.mp4", frames=2, audio=False)
    write_spherical(clip, Spherical(stereo="top-bottom"))
    with pytest.raises(InvalidValueError, match="stereoscopic.*--force"):
        render_video(clip, tmp_path / "o.mp4", lambda t: (ZOOM, {}))
    assert not (tmp_path / "o.mp4").exists()
    render_video(clip, tmp_path / "o.mp4", lambda t: (ZOOM, {}), force=True)
    assert probe(tmp_path / "o.mp4").spherical.stereo == "mono"
