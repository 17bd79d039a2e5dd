"""render_video: timing, audio, metadata and pixels of a short turning panorama, zoomed."""

from __future__ import annotations

import json
import shutil
import subprocess
import warnings
from fractions import Fraction

import numpy as np
import pytest

from spherewarp.errors import ImageFormatError, InvalidValueError, OutputExistsError
from spherewarp.io.video import probe, render_video, video_encoders
from spherewarp.maps import Mobius
from spherewarp.render import warp
from videoclip import RATE, SECONDS, ffprobe_side_data, make_clip

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
@pytest.mark.parametrize(
    "container,codec,output",
    [("mp4", "mov_text", "mp4"), ("mkv", "srt", "mp4"), ("mkv", "srt", "mkv")],
)
def test_subtitles_copied_or_dropped_with_a_warning(tmp_path, container, codec, output):
    """SubRip goes by its codec's name (subrip), not its decoder's (srt): kept in Matroska."""
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
    out = tmp_path / f"o.{output}"
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        render_video(src, out, lambda t: (ZOOM, {}))
    with av.open(str(out)) as c:
        kinds = [s.type for s in c.streams]
    if codec == "mov_text" or output == "mkv":
        assert kinds == ["video", "audio", "subtitle"] and not caught

        def subs(path):
            with av.open(str(path)) as c:
                return [(bytes(p), p.pts) for p in c.demux(c.streams.subtitles[0]) if p.size]

        assert subs(out) == subs(src) and len(subs(src)) == 2
    else:
        assert kinds == ["video", "audio"]
        assert [str(w.message) for w in caught] == [
            "stream #2 (subtitle, subrip) is dropped: an MP4 file cannot hold subtitle in subrip"
        ]
    assert audio_packets(out) == audio_packets(src)


def test_mp3_audio_is_copied_into_mp4(tmp_path):
    """MP3 goes by its codec's name (mp3), not its decoder's (mp3float): copied, no warning."""
    src = make_clip(tmp_path / "mp3.mp4", frames=12, audio_codec="libmp3lame")
    out = tmp_path / "o.mp4"
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        render_video(src, out, lambda t: (ZOOM, {}))
    assert not caught
    with av.open(str(out)) as c:
        assert [s.codec_context.codec.canonical_name for s in c.streams] == ["h264", "mp3"]
    assert audio_packets(out) == audio_packets(src) and len(audio_packets(src)) > 5


@pytest.mark.parametrize(
    "src,codec,refused,taken",
    [("mov", "adpcm_ima_qt", ".mkv", ".mov"), ("mkv", "flac", ".mov", ".mp4")],
)
def test_audio_the_muxer_refuses_is_dropped_with_a_warning(tmp_path, src, codec, refused, taken):
    """The muxer decides: Matroska holds no adpcm_ima_qt (it used to be taken for any audio,
    and the muxer then raised), MOV no FLAC (its header refuses it); dropped with one
    warning, the video whole. An output that holds it gets the packets as they are."""
    clip = make_clip(tmp_path / f"in.{src}", frames=12, audio_codec=codec)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        render_video(clip, tmp_path / f"o{refused}", lambda t: (ZOOM, {}))
    kind = {".mkv": "a Matroska", ".mov": "a MOV"}[refused]
    assert [str(w.message) for w in caught] == [
        f"stream #1 (audio, {codec}) is dropped: {kind} file cannot hold audio in {codec}"
    ]
    with av.open(str(tmp_path / f"o{refused}")) as c:
        assert [s.type for s in c.streams] == ["video"]
        assert sum(1 for _ in c.decode(video=0)) == 12
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        render_video(clip, tmp_path / f"o{taken}", lambda t: (ZOOM, {}))
    assert not caught
    assert audio_packets(tmp_path / f"o{taken}") == audio_packets(clip)


@pytest.mark.parametrize("layout", ["top-bottom", "left-right"])
def test_stereo_input_warps_each_eye(tmp_path, layout):
    """Two different panoramas as the eyes: each half of each frame is the still render of
    that half, the layout is kept and the output says so (st3d)."""
    from spherewarp.io.stereo import eyes

    clip = make_clip(tmp_path / "st.mp4", frames=6, audio=False, stereo=layout)
    assert probe(clip).spherical.stereo == layout
    out = tmp_path / "o.mp4"
    render_video(clip, out, lambda t: (ZOOM, {}))
    info = probe(out)
    assert (info.width, info.height) == ((256, 256) if layout == "top-bottom" else (512, 128))
    assert info.spherical.stereo == layout and info.spherical.versions == {"v1", "v2"}
    src, dst = frames(clip), frames(out)
    assert len(dst) == len(src) == 6
    for k in (0, 5):
        for a, b in zip(eyes(src[k], layout), eyes(dst[k], layout), strict=True):
            assert psnr(warp(np.ascontiguousarray(a), ZOOM), b) >= 35, k
        # one map over the whole frame would differ: the eyes are warped apart
        whole = warp(src[k], ZOOM, force=True)
        assert psnr(whole, dst[k]) < 25
    if ffprobe is None:
        pytest.skip("ffprobe is not installed")
    sides = ffprobe_side_data(out)
    assert sides["Stereo 3D"]["type"] == (
        "top and bottom" if layout == "top-bottom" else "side by side"
    )
    assert sides["Spherical Mapping"]["projection"] == "equirectangular"


def test_stereo_layout_given_overrides_the_metadata(tmp_path):
    clip = make_clip(tmp_path / "tb.mp4", frames=2, audio=False, stereo="top-bottom")
    from spherewarp.io.spherical import write_spherical

    write_spherical(clip, None)  # no metadata: a 1:1 frame is refused as mono...
    with pytest.raises(InvalidValueError, match="256x256, not 2:1"):
        render_video(clip, tmp_path / "o.mp4", lambda t: (ZOOM, {}))
    render_video(clip, tmp_path / "o.mp4", lambda t: (ZOOM, {}), stereo="tb")  # ...not as tb
    assert probe(tmp_path / "o.mp4").spherical.stereo == "top-bottom"
    with pytest.raises(InvalidValueError, match="each eye .left-right stereo. is 128x256"):
        render_video(clip, tmp_path / "p.mp4", lambda t: (ZOOM, {}), stereo="sbs")
    assert not (tmp_path / "p.mp4").exists()


def test_a_view_renders_each_frame_into_the_grid(tmp_path, clip):
    """A little planet of each frame: the still render into that grid; no spherical metadata."""
    from spherewarp.grids import make_grid

    grid = make_grid("little-planet", (128, 256), shape=(96, 96))
    out = tmp_path / "planet.mp4"
    render_video(clip, out, lambda t: (ZOOM, {}), grid=grid)
    info = probe(out)
    assert (info.width, info.height) == (96, 96) and info.spherical is None
    assert info.frames == RATE * SECONDS
    src, dst = frames(clip), frames(out)
    for k in (0, 30):
        assert psnr(warp(src[k], ZOOM, grid=grid), dst[k]) >= 35, k
    # an equirect output size of its own: a plain panorama, with metadata
    render_video(clip, tmp_path / "small.mp4", lambda t: (ZOOM, {}), out_shape=(64, 128))
    small = probe(tmp_path / "small.mp4")
    assert (small.width, small.height) == (128, 64) and small.spherical is not None
    with pytest.raises(InvalidValueError, match="even sides"):
        render_video(clip, tmp_path / "odd.mp4", lambda t: (ZOOM, {}), out_shape=(63, 126))


def test_a_stereo_view_says_only_its_layout(tmp_path):
    from spherewarp.grids import make_grid

    clip = make_clip(tmp_path / "tb.mp4", frames=2, audio=False, stereo="top-bottom")
    out = tmp_path / "o.mp4"
    grid = lambda eye: make_grid("rectilinear", eye, shape=(eye[0] // 2, eye[0] // 2))  # noqa: E731
    render_video(clip, out, lambda t: (ZOOM, {}), grid=grid)
    info = probe(out)
    assert (info.width, info.height) == (64, 128) and info.spherical is None
    if ffprobe is None:
        pytest.skip("ffprobe is not installed")
    sides = ffprobe_side_data(out)
    assert sides["Stereo 3D"]["type"] == "top and bottom" and "Spherical Mapping" not in sides


@pytest.mark.parametrize("where", ["produce", "work", "consume", "finish"])
def test_the_pipeline_stops_at_the_first_error(where):
    import threading

    from spherewarp.io.video import pipeline

    def boom(*_):
        raise ValueError(where)

    def produce():
        for k in range(1000):
            if where == "produce" and k == 5:
                boom()
            yield k

    got = []
    before = threading.active_count()
    with pytest.raises(ValueError, match=where):
        pipeline(
            produce(),
            boom if where == "work" else (lambda x: x),
            boom if where == "consume" else got.append,
            boom if where == "finish" else None,
        )
    assert threading.active_count() == before  # both threads ended
    assert len(got) < 1000 or where == "finish"


@pytest.mark.parametrize("when", ["start", "join"])
def test_an_interrupt_while_threads_start_or_join_leaves_none_running(monkeypatch, when):
    """A Ctrl-C between the two threads' starts (or in the last join) once left the
    decoding thread running while the caller closed its container: SIGSEGV in FFmpeg."""
    import signal
    import threading
    import time

    from spherewarp.io.video import pipeline

    real_start, real_join = threading.Thread.start, threading.Thread.join
    state = {"returned": False, "late": 0, "sent": False}

    def start(self):
        real_start(self)
        if when == "start" and not state["sent"]:
            state["sent"] = True
            signal.raise_signal(signal.SIGINT)  # after the first thread, before the second

    def join(self, timeout=None):
        if when == "join" and not state["sent"] and threading.current_thread() is \
                threading.main_thread():  # fmt: skip
            state["sent"] = True
            signal.raise_signal(signal.SIGINT)
        return real_join(self, timeout)

    def produce():
        for k in range(200):
            if state["returned"]:
                state["late"] += 1  # decoding after the caller moved on
            time.sleep(0.002)
            yield k

    monkeypatch.setattr(threading.Thread, "start", start)
    monkeypatch.setattr(threading.Thread, "join", join)
    before = threading.active_count()
    with pytest.raises(KeyboardInterrupt):
        pipeline(produce(), lambda x: x, lambda x: None)
    state["returned"] = True
    assert state["sent"] and threading.active_count() == before  # no thread outlives it
    time.sleep(0.05)
    assert state["late"] == 0


def test_a_static_map_is_planned_once_for_all_segments(tmp_path, monkeypatch):
    import spherewarp.io.video as video
    from spherewarp.io.segments import frame_times, render_segmented
    from videoclip import make_clip

    made = []

    def counted(*args, **kwargs):
        made.append(args[1])
        return plan_of(*args, **kwargs)

    plan_of = video.frame_plan
    monkeypatch.setattr(video, "frame_plan", counted)
    clip = make_clip(tmp_path / "in.mp4", frames=12, audio=False)
    turn = Mobius.from_yaw_pitch_roll(30, 0, 0).inverse()
    render_segmented(clip, tmp_path / "out.mp4", lambda t: (turn, {}), segment_seconds=0.125)
    assert len(frame_times(tmp_path / "out.mp4")[0]) == 12
    assert len(made) == 1  # 4 segments of 3 frames, one plan


def test_each_segment_closes_its_containers_and_joins_its_threads(tmp_path, monkeypatch):
    """Nothing of a segment outlives it: no container, stream or codec context is left for
    the garbage collector, and its decode and encode threads have ended."""
    import gc
    import threading

    import spherewarp.io.segments as segments
    from videoclip import make_clip

    clip = make_clip(tmp_path / "in.mp4", frames=12, audio=False)
    turn = Mobius.from_yaw_pitch_roll(30, 0, 0).inverse()
    render = segments.render_segment
    kinds = (av.container.Container, av.codec.context.CodecContext, av.stream.Stream)
    left = []

    def alive():
        # type(), not isinstance(): a weak proxy among the objects may be dead already
        return sum(issubclass(type(o), kinds) for o in gc.get_objects()), threading.active_count()

    def checked(job, progress=None):
        result = render(job, progress)
        left.append(alive())
        return result

    monkeypatch.setattr(segments, "render_segment", checked)
    gc.collect()
    before = alive()
    gc.disable()  # what a segment leaves in a reference cycle stays where it can be counted
    try:
        segments.render_segmented(clip, tmp_path / "out.mp4", lambda t: (turn, {}),
                                  segment_seconds=0.125)  # fmt: skip
    finally:
        gc.enable()
    assert [n for n, _ in left] == [before[0]] * 4  # no container, stream or codec context
    # no thread either (the render's own pool of warp threads starts with the first segment)
    assert [t for _, t in left] == [left[0][1]] * 4


def test_each_segment_gives_its_memory_back(tmp_path, monkeypatch):
    import spherewarp.io.segments as segments
    from videoclip import make_clip

    segments.release_memory()  # glibc's malloc_trim, or nothing: never an error
    calls = []
    monkeypatch.setattr(segments, "release_memory", lambda: calls.append(1))
    clip = make_clip(tmp_path / "in.mp4", frames=12, audio=False)
    turn = Mobius.from_yaw_pitch_roll(30, 0, 0).inverse()
    segments.render_segmented(clip, tmp_path / "out.mp4", lambda t: (turn, {}),
                              segment_seconds=0.125)  # fmt: skip
    assert len(calls) == 4  # once after each segment


def lossless_clip(path, pix_fmt, color_range, frames=3):
    """The turning panorama as FFV1 (lossless) in Matroska, in ``pix_fmt`` and ``color_range``
    (2: full, as ffmpeg tags grey), the samples converted from RGB in that range."""
    from videoclip import frame

    with av.open(str(path), "w") as c:
        v = c.add_stream("ffv1", rate=12)
        v.width, v.height, v.pix_fmt = 256, 128, pix_fmt
        v.codec_context.color_range = color_range
        for k in range(frames):
            f = av.VideoFrame.from_ndarray(frame(k), format="rgb24")
            f.color_range = color_range
            f.pts = k
            c.mux(v.encode(f))
        c.mux(v.encode(None))
    return path


def first_frame(path, fmt="rgb24"):
    with av.open(str(path)) as c:
        f = next(c.decode(video=0))
        return f.to_ndarray(format=fmt).astype(np.int32), int(f.color_range)


@pytest.mark.parametrize("how", ["planes", "rgb", "segments"])
@pytest.mark.parametrize(
    "pix_fmt,color_range", [("gray", 2), ("gray10le", 2), ("yuv420p", 2), ("yuv420p", 0)]
)
def test_levels_are_kept_grey_and_full_range_too(tmp_path, pix_fmt, color_range, how):
    """A turn by 360 degrees, lossless (--crf 0), gives the input's values back: a grey or a
    full-range input's stream says full range (grey H.264 not so flagged was read as limited,
    its contrast stretched by 255/219), a limited-range one stays limited; warped plane by
    plane, through RGB, or in segments (the CLI's way)."""
    from spherewarp.io.segments import render_segmented

    src = lossless_clip(tmp_path / "in.mkv", pix_fmt, color_range)
    out = tmp_path / "o.mp4"
    turn = Mobius.from_yaw_pitch_roll(360, 0, 0)
    if how == "segments":
        render_segmented(src, out, lambda t: (turn, {}), crf=0)
    else:
        render_video(src, out, lambda t: (turn, {}), crf=0, planar=how == "planes")
    (want, _), (got, got_range) = first_frame(src), first_frame(out)
    assert got_range == (2 if color_range == 2 else 0)
    slope = np.polyfit(want.ravel(), got.ravel(), 1)[0]
    assert abs(slope - 1) < 0.02  # not stretched (255 / 219 = 1.16)
    assert np.abs(got - want).max() <= (6 if how == "rgb" else 2)  # RGB and back: rounding


@pytest.mark.parametrize("pix_fmt", ["gray", "yuvj420p"])
def test_grey_and_yuvj_outputs_of_a_colour_clip_say_full_range(tmp_path, pix_fmt):
    """--pix-fmt gray (or yuvj420p) of a limited-range colour clip, video_writer's (animate,
    splitscreen) and an image sequence's: the encoder gets full-range samples (the luma of
    the RGB frames), and the stream says so."""
    from spherewarp.io import write_image
    from spherewarp.io.sequence import render_sequence
    from spherewarp.io.videowriter import video_writer
    from videoclip import frame

    src = lossless_clip(tmp_path / "in.mkv", "yuv420p", 0)
    out = tmp_path / "o.mp4"
    turn = Mobius.from_yaw_pitch_roll(360, 0, 0)
    render_video(src, out, lambda t: (turn, {}), crf=0, pix_fmt=pix_fmt)

    def grey(rgb):  # the luma of RGB pixels, in full range
        f = av.VideoFrame.from_ndarray(np.ascontiguousarray(rgb, np.uint8), format="rgb24")
        return f.reformat(format="gray").to_ndarray()

    got, got_range = first_frame(out, "gray")
    assert got_range == 2 and np.abs(got - grey(first_frame(src)[0])).max() <= 2
    with video_writer(tmp_path / "w.mp4", (128, 256), 12, pix_fmt=pix_fmt, crf=0) as w:
        w.write(frame(0))
    got, got_range = first_frame(tmp_path / "w.mp4", "gray")
    assert got_range == 2 and np.abs(got - grey(frame(0))).max() <= 2
    for k in range(2):  # an image sequence to video
        write_image(tmp_path / f"s{k}.png", frame(k))
    render_sequence(tmp_path / "s%d.png", tmp_path / "s.mp4", lambda t: (turn, {}), crf=0,
                    pix_fmt=pix_fmt)  # fmt: skip
    got, got_range = first_frame(tmp_path / "s.mp4", "gray")
    assert got_range == 2 and np.abs(got - grey(frame(0))).max() <= 2


@pytest.mark.parametrize("seconds", [float("nan"), float("inf"), 0.0, -1.0])
def test_a_segment_length_that_is_not_a_finite_positive_number_is_refused(tmp_path, seconds):
    from spherewarp.io.segments import render_segmented, segment_frames
    from videoclip import make_clip

    with pytest.raises(InvalidValueError, match="--segment"):
        segment_frames(seconds, 24)
    clip = make_clip(tmp_path / "in.mp4", frames=2, audio=False)
    turn = Mobius.from_yaw_pitch_roll(30, 0, 0).inverse()
    with pytest.raises(InvalidValueError, match="--segment"):
        render_segmented(clip, tmp_path / "out.mp4", lambda t: (turn, {}), segment_seconds=seconds)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["in.mp4"]


@pytest.mark.parametrize("suffix", [".ts", ".mp4"])
def test_frames_from_a_frame_are_those_of_a_whole_decode(tmp_path, suffix):
    """frames_from seeks to a keyframe before the frame and decodes from there; a seek that
    lands after that keyframe (MPEG-TS, sought by byte position, lands on any packet) is
    tried again further back, or the file is decoded from its start."""
    from spherewarp.io.video import frames_from
    from videoclip import make_clip

    clip = make_clip(tmp_path / f"in{suffix}", frames=48, audio=False, gop=10)
    with av.open(str(clip)) as c:
        whole = [(f.pts, f.to_ndarray(format="yuv420p")) for f in c.decode(video=0)]
    opened = []

    def reopen():
        opened.append(av.open(str(clip)))
        return opened[-1]

    for k in (12, 20, 36, 47):  # in a GOP, on a keyframe, one GOP later, the last frame
        with av.open(str(clip)) as c:
            got = [(f.pts, f.to_ndarray(format="yuv420p"))
                   for f in frames_from(c, whole[k][0], True, reopen)]  # fmt: skip
        assert [p for p, _ in got] == [p for p, _ in whole[k:]], k
        assert all(np.array_equal(a, b) for (_, a), (_, b) in zip(got, whole[k:], strict=True)), k
    for c in opened:
        c.close()


def test_render_video_keeps_frame_times_exactly(tmp_path):
    """A first frame at 1/12 s (MPEG-TS) or 1001/15000 s came back at 0.083 s or 0.066 s:
    the MP4's edit list was in the default movie time scale of 1/1000 s."""
    from fractions import Fraction

    import av

    def times(path):
        with av.open(str(path)) as c:
            v = c.streams.video[0]
            return sorted(Fraction(p.pts) * p.time_base for p in c.demux(v) if p.size)

    for name, rate in (("late", None), ("ntsc", Fraction(30000, 1001))):
        src = tmp_path / f"{name}.ts"
        make_clip(src, frames=6, gop=3, **({} if rate is None else {"rate": rate}))
        out = tmp_path / f"{name}.mp4"
        render_video(src, out, lambda t: (Mobius.from_yaw_pitch_roll(30, 0, 0), {}))
        assert times(out) == times(src) and times(src)[0] > 0


def tagged_clip(path, pix_fmt, colors, frames=2):
    """Saturated colour bars as FFV1 (lossless) in Matroska, in ``pix_fmt``, tagged with
    ``colors`` (primaries, transfer, matrix) and converted from RGB with that matrix."""
    bars = np.array(
        [[255, 0, 0], [0, 255, 0], [0, 0, 255], [255, 255, 0], [0, 255, 255], [255, 0, 255]],
        np.uint8,
    )
    rgb = np.ascontiguousarray(np.repeat(np.repeat(bars[None], 128, 0), 256 // 6 + 1, 1)[:, :256])
    with av.open(str(path), "w") as c:
        v = c.add_stream("ffv1", rate=12)
        v.width, v.height, v.pix_fmt = 256, 128, pix_fmt
        cc = v.codec_context
        cc.color_primaries, cc.color_trc, cc.colorspace = colors
        for k in range(frames):
            f = av.VideoFrame.from_ndarray(rgb, format="rgb24")
            f.colorspace = colors[2]
            f.pts = k
            c.mux(v.encode(f))
        c.mux(v.encode(None))
    return path, rgb.astype(np.int32)


@pytest.mark.parametrize("how", ["planes", "rgb", "segments"])
@pytest.mark.parametrize(
    "pix_fmt,colors,out_pix",
    [
        ("yuv420p10le", (9, 18, 9), None),  # BT.2020 HLG
        ("yuv420p", (1, 1, 1), None),  # BT.709
        ("yuv420p", (1, 1, 1), "yuv444p"),  # through RGB and back with BT.709's matrix
        ("yuv420p", (6, 6, 6), "yuv444p"),  # smpte170m (BT.601)
    ],
)
def test_colour_tags_are_kept_and_match_the_conversion(tmp_path, pix_fmt, colors, out_pix, how):
    """The input's colour primaries, transfer and matrix are the output's (they came out
    unspecified), and a saturated colour comes back: frames warped through RGB are converted
    back with the matrix the output says, not BT.601's under a BT.709 tag."""
    from spherewarp.io.segments import render_segmented

    src, rgb = tagged_clip(tmp_path / "in.mkv", pix_fmt, colors)
    out = tmp_path / "o.mp4"
    turn = Mobius.from_yaw_pitch_roll(360, 0, 0)
    if how == "segments":
        render_segmented(src, out, lambda t: (turn, {}), crf=0, pix_fmt=out_pix)
    else:
        render_video(src, out, lambda t: (turn, {}), crf=0, pix_fmt=out_pix,
                     planar=how == "planes")  # fmt: skip
    with av.open(str(out)) as c:
        cc = c.streams.video[0].codec_context
        assert (cc.color_primaries, cc.color_trc, cc.colorspace) == colors
        got = next(c.decode(video=0)).to_ndarray(format="rgb24").astype(np.int32)
    # away from the bars' edges (4:2:0 chroma), each bar's colour is the input's
    cols = [k * 43 + 21 for k in range(6)]
    assert np.abs(got[32:96, cols] - rgb[32:96, cols]).max() <= 8
    assert probe(out).colors == colors


def rich_clip(path, src):
    """``src`` (video and audio) remuxed to ``path`` with a title and an artist, two chapters,
    and its audio twice: English (the default track) and French, titled."""
    with av.open(str(src)) as c, av.open(str(path), "w") as out:
        out.metadata.update({"title": "My VR Tour", "artist": "QA"})
        out.set_chapters([
            {"id": 1, "start": 0, "end": 1000, "time_base": Fraction(1, 1000),
             "metadata": {"title": "Intro"}},
            {"id": 2, "start": 1000, "end": 2000, "time_base": Fraction(1, 1000),
             "metadata": {"title": "Street"}},
        ])  # fmt: skip
        v = out.add_stream_from_template(c.streams.video[0])
        a = c.streams.audio[0]
        en, fr = out.add_stream_from_template(a), out.add_stream_from_template(a)
        en.metadata["language"], fr.metadata["language"] = "eng", "fra"
        fr.metadata["title"] = "Commentary"
        v.disposition = en.disposition = 1  # the English track is the default
        fr.disposition = 0
        for p in c.demux():
            if p.dts is None:
                continue
            if p.stream.type == "video":
                p.stream = v
                out.mux(p)
            else:
                for s in (en, fr):
                    q = av.Packet(bytes(p))
                    q.pts, q.dts, q.time_base, q.stream = p.pts, p.dts, p.time_base, s
                    out.mux(q)
    return path


@pytest.mark.parametrize("how", ["whole", "segments"])
@pytest.mark.parametrize("suffix", [".mp4", ".mkv"])
def test_tags_chapters_and_languages_are_kept(tmp_path, clip, suffix, how):
    """The container's tags (title, artist), its chapters and each stream's language, title
    and default flag are the input's (all were dropped: both audio tracks came out 'und',
    the French one the default in MKV); an MP4 chapter track draws no warning."""
    from spherewarp.io.segments import render_segmented

    src = rich_clip(tmp_path / f"in{suffix}", clip)
    out = tmp_path / f"o{suffix}"
    turn = Mobius.from_yaw_pitch_roll(90, 0, 0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        if how == "segments":
            render_segmented(src, out, lambda t: (turn, {}), segment_seconds=0.5)
        else:
            render_video(src, out, lambda t: (turn, {}))
        if suffix == ".mp4":  # the output's own chapter track, as the input's, is no loss
            render_video(out, tmp_path / "again.mp4", lambda t: (turn, {}))
    with av.open(str(out)) as c:
        tags = {k.lower(): v for k, v in c.metadata.items()}
        assert tags["title"] == "My VR Tour" and tags["artist"] == "QA"
        assert [(float(ch["start"] * ch["time_base"]), ch["metadata"]["title"])
                for ch in c.chapters()] == [(0, "Intro"), (1, "Street")]  # fmt: skip
        audio = c.streams.audio
        assert [s.metadata.get("language") for s in audio] == ["eng", "fra"]
        fr = {k.lower(): v for k, v in audio[1].metadata.items()}
        assert fr.get("title", fr.get("name")) == "Commentary"  # MP4 reads a track's 'name'
        default = av.stream.Disposition.default
        assert [bool(s.disposition & default) for s in audio] == [True, False]
        assert c.streams.video[0].disposition & default


def timecode_clip(path, src, timecode="01:02:03:04"):
    """``src``'s video remuxed to the MOV file ``path`` with a timecode (a ``tmcd`` track)."""
    with av.open(str(src)) as c, av.open(str(path), "w") as out:
        v = out.add_stream_from_template(c.streams.video[0])
        v.metadata["timecode"] = timecode
        v.codec_context.framerate = c.streams.video[0].average_rate
        for p in c.demux(c.streams.video[0]):
            if p.dts is not None:
                p.stream = v
                out.mux(p)
    return path


@pytest.mark.parametrize("how", ["whole", "segments"])
@pytest.mark.parametrize("suffix", [".mov", ".mp4", ".mkv"])
def test_a_timecode_is_kept(tmp_path, clip, suffix, how):
    """A MOV input's timecode track is the output's (it was dropped, with a warning naming
    'stream #1 (data, unknown)'); a Matroska file holds no timecode track, and says so in
    one warning, its video keeping the timecode tag."""
    from spherewarp.io.segments import render_segmented

    src = timecode_clip(tmp_path / "tc.mov", clip)
    with av.open(str(src)) as c:
        assert [s.type for s in c.streams] == ["video", "data"]
    out = tmp_path / f"o{suffix}"
    turn = Mobius.from_yaw_pitch_roll(90, 0, 0)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        if how == "segments":
            render_segmented(src, out, lambda t: (turn, {}), segment_seconds=0.5)
        else:
            render_video(src, out, lambda t: (turn, {}))
    said = [str(w.message) for w in caught]
    with av.open(str(out)) as c:
        video = {k.lower(): v for k, v in c.streams.video[0].metadata.items()}
        assert video["timecode"] == "01:02:03:04"
        tracks = [s for s in c.streams if s.type == "data"]
        if suffix == ".mkv":
            assert not tracks and len(said) == 1 and "timecode track" in said[0], said
        else:
            assert not said, said
            assert [s.metadata.get("timecode") for s in tracks] == ["01:02:03:04"]


def alpha_clip(path, frames=2):
    """The turning panorama as PNG in MOV (``rgba``), its left quarter transparent."""
    from videoclip import frame

    with av.open(str(path), "w") as c:
        v = c.add_stream("png", rate=12)
        v.width, v.height, v.pix_fmt = 256, 128, "rgba"
        for k in range(frames):
            rgba = np.concatenate([frame(k), np.full((128, 256, 1), 255, np.uint8)], axis=-1)
            rgba[:, :64, 3] = 0
            f = av.VideoFrame.from_ndarray(rgba, format="rgba")
            f.pts = k
            c.mux(v.encode(f))
        c.mux(v.encode(None))
    return path


@pytest.mark.parametrize("how", ["whole", "segments"])
def test_alpha_is_warped_or_its_loss_said(tmp_path, how):
    """An RGBA input's alpha turns with the picture where the output format has alpha (it
    came out opaque everywhere); dropped with one warning where it has none; VP9's alpha
    (which the segments do not carry) is refused in one line naming --pix-fmt."""
    from spherewarp.io.segments import render_segmented

    src = alpha_clip(tmp_path / "in.mov")
    turn = Mobius.from_yaw_pitch_roll(90, 0, 0)
    render = render_video if how == "whole" else render_segmented
    render(src, tmp_path / "o.mov", lambda t: (turn, {}), codec="png")
    with av.open(str(tmp_path / "o.mov")) as c:
        f = next(c.decode(video=0))
        assert f.format.name == "rgba"
        alpha = f.to_ndarray(format="rgba")[..., 3].astype(np.int32)
    want = np.full((128, 256), 255)
    want[:, :64] = 0
    want = np.roll(want, -64, axis=1)  # yaw 90: a quarter turn of the columns
    assert np.mean(np.abs(alpha - want) > 8) < 0.02  # the edges resampled
    with pytest.warns(UserWarning, match="alpha channel is dropped: yuv420p has none"):
        render(src, tmp_path / "o.mp4", lambda t: (turn, {}))
    with pytest.raises(InvalidValueError, match="--pix-fmt yuva420p: .*alpha"):
        render(src, tmp_path / "o.webm", lambda t: (turn, {}), pix_fmt="yuva420p")
    assert not (tmp_path / "o.webm").exists()
