"""``spherewarp video``: the effects on a short clip, and one line for each bad input."""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import time
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest
from _cli import fails, ok, run

from spherewarp.io.video import probe
from videoclip import make_clip

av = pytest.importorskip("av")
ffprobe = shutil.which("ffprobe")


@pytest.fixture
def clip(workdir):
    return make_clip(workdir / "in.mp4", frames=12)


def frames(path):
    with av.open(str(path)) as c:
        return [f.to_ndarray(format="rgb24") for f in c.decode(video=0)]


def psnr(a, b):
    return 10 * np.log10(255.0**2 / np.mean((a.astype(np.float64) - b) ** 2))


def test_says_what_it_wrote_even_with_quiet(clip):
    """As every command does: the bar and notes go with --quiet, the 'wrote' line stays."""
    assert ok(None, "video", clip.name, "-o", "w.mp4", "rotate", "--yaw", "9") == "wrote w.mp4\n"
    out = ok(None, "video", clip.name, "-o", "q.mp4", "--quiet", "rotate", "--yaw", "9")
    assert out == "wrote q.mp4\n"


def test_rotate_turns_every_frame(clip):
    ok(None, "video", clip.name, "-o", "out.mp4", "--quiet", "rotate", "--yaw", "90")
    src, out = frames(clip), frames("out.mp4")
    assert len(out) == len(src) == 12
    for a, b in zip(src, out, strict=True):  # yaw 90: a quarter turn of the columns
        assert psnr(np.roll(a, -a.shape[1] // 4, axis=1), b) >= 35
    info = probe("out.mp4")
    assert info.spherical is not None and info.spherical.projection == "equirectangular"
    assert info.frames == 12 and info.rate == 24


@pytest.mark.parametrize(
    "effect",
    [
        ["zoom", "--at", "0,0", "--factor", "2", "--center"],
        ["mobius", "--matrix", "1,0.5,0,1"],
    ],
)
def test_effects_and_options_after_the_effect(clip, effect):
    # -o after the effect, then the codec options between INPUT and the effect
    ok(None, "video", clip.name, *effect, "-o", "o.mp4")
    assert probe("o.mp4").frames == 12
    ok(
        None,
        "video",
        clip.name,
        "--crf",
        "30",
        "--preset",
        "ultrafast",
        "-o",
        "o.mp4",
        "--overwrite",
        *effect,
    )
    assert probe("o.mp4").frames == 12


def one_line(err):
    return err.startswith("spherewarp: error: ") and err.count("\n") == 1 and "Traceback" not in err


def test_bad_inputs_one_line_nothing_written(workdir, clip):
    (workdir / "notes.mp4").write_text("hello")
    square = make_clip(workdir / "square.mp4", frames=2, audio=False, size=(64, 64))
    cases = {
        "not a video": ["video", "notes.mp4", "-o", "o.mp4", "rotate", "--yaw", "1"],
        "no such file": ["video", "missing.mp4", "-o", "o.mp4", "rotate", "--yaw", "1"],
        "libx264": ["video", clip.name, "-o", "o.mp4", "--codec", "nope", "rotate"],
        "--force": ["video", square.name, "-o", "o.mp4", "rotate", "--yaw", "1"],
        "unknown video extension": ["video", clip.name, "-o", "o.gif", "rotate"],
        "-o": ["video", clip.name, "rotate", "--yaw", "1"],
        "--preset": ["video", clip.name, "-o", "o.mp4", "--preset", "nope", "rotate"],
    }
    before = sorted(p.name for p in workdir.iterdir())
    for needle, args in cases.items():
        code, out, err = run(None, *args)
        assert code == 2 and one_line(err) and needle in err, (args, err)
    assert sorted(p.name for p in workdir.iterdir()) == before
    ok(None, "video", square.name, "-o", "sq.mp4", "--force", "rotate", "--yaw", "1")
    code, _, err = run(None, "video", square.name, "-o", "sq.mp4", "--force", "rotate")
    assert code == 2 and one_line(err) and "--overwrite" in err


@pytest.mark.skipif(os.name != "posix", reason="POSIX signals")
def test_ctrl_c_leaves_no_file(workdir):
    make_clip(workdir / "long.mp4", frames=72)
    args = ["video", "long.mp4", "-o", "o.mp4", "--preset", "veryslow", "zoom", "--at", "0,0"]
    for _ in range(3):
        proc = subprocess.Popen(
            [sys.executable, "-m", "spherewarp", *args, "--factor", "2"],
            cwd=workdir,
            stdin=subprocess.DEVNULL,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        end = time.monotonic() + 60
        while proc.poll() is None and time.monotonic() < end:
            parts = workdir / "o.mp4.parts"  # the segments' work directory
            if any(".tmp" in p.name for p in (*workdir.iterdir(), *parts.glob("*"))):
                break
            time.sleep(0.002)
        time.sleep(0.2)  # frames in flight in every stage
        if proc.poll() is None:
            break
        proc.communicate()
        (workdir / "o.mp4").unlink()
        shutil.rmtree(workdir / "o.mp4.parts", ignore_errors=True)
    else:
        pytest.skip("the render keeps ending before the signal")
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, err
    assert err.startswith("spherewarp: interrupted") and err.count("\n") == 1, err
    assert "--resume" in err, err
    # no output, no temporary file; the finished segments stay for --resume
    assert sorted(p.name for p in workdir.iterdir()) in (["long.mp4"], ["long.mp4", "o.mp4.parts"])
    assert not [p for p in (workdir / "o.mp4.parts").glob("*") if ".tmp" in p.name]


def test_power_and_exp(clip):
    from spherewarp.maps.branched import Power
    from spherewarp.render import warp

    ok(None, "video", clip.name, "-o", "p.mp4", "power", "--n", "2")
    src, out = frames(clip), frames("p.mp4")
    assert len(out) == 12
    assert psnr(warp(src[5], Power(2)), out[5]) >= 35
    ok(None, "video", clip.name, "-o", "e.mp4", "exp", "--lam", "2", "--look-at", "180,0")
    assert probe("e.mp4").frames == 12


def test_timed_recipe_is_evaluated_at_every_frame(clip, workdir):
    """A yaw track from 0 to 90 degrees over the clip's 0.5 s: frame k turns by k/24 * 180."""
    import json

    recipe = {
        "spherewarp": 1,
        "duration": 0.5,
        "steps": [{"rotate": {"yaw": {"keyframes": [[0, 0], [0.5, 90]]}}}],
    }
    (workdir / "spin.json").write_text(json.dumps(recipe))
    ok(None, "video", clip.name, "-o", "out.mp4", "--quiet", "recipe", "spin.json")
    src, out = frames(clip), frames("out.mp4")
    assert len(out) == len(src) == 12
    w = src[0].shape[1]
    for k, (a, b) in enumerate(zip(src, out, strict=True)):
        shift = round(k / 24 * 180 / 360 * w)  # whole columns: 128 px wide, 7.5 degrees a frame
        assert psnr(np.roll(a, -shift, axis=1), b) >= 33, k


def test_static_recipe_equals_the_effect(clip, workdir):
    import json

    step = {"zoom": {"at": [0, 0], "factor": 2}}
    (workdir / "z.json").write_text(json.dumps({"spherewarp": 1, "steps": [step]}))
    ok(None, "video", clip.name, "-o", "a.mp4", "--quiet", "recipe", "z.json")
    ok(None, "video", clip.name, "-o", "b.mp4", "--quiet", "zoom", "--at", "0,0", "--factor", "2")
    for a, b in zip(frames("a.mp4"), frames("b.mp4"), strict=True):
        assert np.array_equal(a, b) or psnr(a, b) >= 45


def test_stereo_top_bottom_both_eyes_warped(workdir):
    """st3d top-bottom input (two different panoramas): top-bottom output, each eye the still
    render of that eye; --stereo tb says the same of an input without metadata."""
    from spherewarp.io.spherical import write_spherical
    from spherewarp.io.stereo import eyes
    from spherewarp.maps import Mobius
    from spherewarp.render import warp

    clip = make_clip(workdir / "tb.mp4", frames=4, audio=False, stereo="top-bottom")
    ok(None, "video", clip.name, "-o", "o.mp4", "zoom", "--at", "0,0", "--factor", "2")
    pull = Mobius.zoom((0, 0), 2).inverse()
    src, out = frames(clip), frames("o.mp4")
    for a, b in zip(eyes(src[3], "tb"), eyes(out[3], "tb"), strict=True):
        assert psnr(warp(np.ascontiguousarray(a), pull), b) >= 35
    assert probe("o.mp4").spherical.stereo == "top-bottom"
    write_spherical(clip, None)
    code, _, err = run(None, "video", clip.name, "-o", "p.mp4", "rotate", "--yaw", "9")
    assert code == 2 and one_line(err) and "not 2:1" in err and "--force" in err
    ok(None, "video", clip.name, "-o", "p.mp4", "--stereo", "tb", "rotate", "--yaw", "9")
    assert probe("p.mp4").spherical.stereo == "top-bottom"
    code, _, err = run(None, "video", clip.name, "-o", "q.mp4", "--stereo", "xx", "rotate")
    assert code == 2 and "--stereo" in err


def test_views_from_the_command_line_and_from_a_recipe(clip, workdir):
    """--projection (and a recipe's view) render every frame into that grid, with no
    spherical metadata; the default size is rounded to even sides for 4:2:0."""
    import json

    from spherewarp.grids import make_grid
    from spherewarp.maps import Mobius
    from spherewarp.render import warp

    ok(None, "video", clip.name, "-o", "r.mp4", "--projection", "rectilinear", "rotate")
    info = probe("r.mp4")
    assert (info.width, info.height) == (84, 64) and info.spherical is None  # default 85x64
    step = {"zoom": {"at": [0, 0], "factor": 2}}
    view = {"projection": "little-planet", "size": [64, 64]}
    (workdir / "v.json").write_text(json.dumps({"spherewarp": 1, "steps": [step], "view": view}))
    ok(None, "video", clip.name, "-o", "v.mp4", "--crf", "8", "recipe", "v.json")
    info = probe("v.mp4")
    assert (info.width, info.height) == (64, 64) and info.spherical is None and info.frames == 12
    grid = make_grid("little-planet", (128, 256), shape=(64, 64))
    expected = warp(frames(clip)[7], Mobius.zoom((0, 0), 2).inverse(), grid=grid)
    assert psnr(expected, frames("v.mp4")[7]) >= 35
    # the command line's grid options win over the recipe's view
    ok(None, "video", clip.name, "-o", "w.mp4", "--size", "128x64", "--projection", "equirect",
       "--view-at", "90,0", "recipe", "v.json")  # fmt: skip
    info = probe("w.mp4")
    assert (info.width, info.height) == (128, 64) and info.spherical is not None
    code, _, err = run(None, "video", clip.name, "-o", "x.mp4", "--fov", "90", "rotate")
    assert code == 2 and one_line(err) and "--projection" in err
    code, _, err = run(None, "video", clip.name, "-o", "x.mp4", "--size", "85x64", "rotate")
    assert code == 2 and one_line(err) and "even sides" in err


def test_image_sequences_in_and_out(clip, workdir):
    """video IN -o 'png/%05d.png', then 'png/%05d.png' --fps 12 -o 'exr/%05d.exr' and a video."""
    from spherewarp.io import read_image

    out = ok(None, "video", clip.name, "-o", "png/%05d.png", "zoom", "--at", "0,0", "--factor", "2")
    assert "wrote 12 frames to png/%05d.png" in out
    assert sorted(p.name for p in (workdir / "png").iterdir()) == [
        f"{k:05d}.png" for k in range(12)
    ]
    ok(None, "video", "png/%05d.png", "-o", "exr/%05d.exr", "rotate", "--yaw", "90")
    exr = read_image(workdir / "exr" / "00011.exr").pixels
    assert exr.dtype == np.float32 and exr.shape == (128, 256, 3)
    ok(None, "video", "png/%05d.png", "--fps", "12", "-o", "back.mp4", "rotate", "--yaw", "90")
    info = probe("back.mp4")
    assert info.frames == 12 and info.rate == 12 and info.spherical is not None
    before = sorted(p.name for p in workdir.iterdir())
    cases = {
        "--fps": ["video", clip.name, "--fps", "12", "-o", "f/%d.png", "rotate"],
        "--overwrite": ["video", clip.name, "-o", "png/%05d.png", "rotate"],
        "is the input frame": [
            "video",
            "png/%05d.png",
            "-o",
            "png/%05d.png",
            "--overwrite",
            "rotate",
        ],
        "no file matches": ["video", "none/%05d.png", "-o", "o.mp4", "rotate"],
        "one field": ["video", clip.name, "-o", "f/%d_%d.png", "rotate"],
        "unknown image extension": ["video", clip.name, "-o", "f/%d.gif", "rotate"],
    }
    for needle, args in cases.items():
        code, _, err = run(None, *args)
        assert code == 2 and one_line(err) and needle in err, (args, err)
    assert sorted(p.name for p in workdir.iterdir()) == before


def test_the_input_pose_is_carried_over(workdir):
    """sv3d pose yaw 30: kept by a zoom, turned by a yaw (counter-clockwise: 30 - 90), and
    left out with a note after a tilt or a branched map."""
    from spherewarp.io.spherical import Spherical, write_spherical

    clip = make_clip(workdir / "posed.mp4", frames=3, audio=False)
    write_spherical(clip, Spherical(yaw=30.0))
    ok(None, "video", clip.name, "-o", "z.mp4", "zoom", "--at", "10,0", "--factor", "2")
    assert probe("z.mp4").spherical.yaw == pytest.approx(30)
    ok(None, "video", clip.name, "-o", "y.mp4", "rotate", "--yaw", "90")
    assert probe("y.mp4").spherical.yaw == pytest.approx(-60)
    for name, effect in {"p.mp4": ["rotate", "--pitch", "10"], "w.mp4": ["power"]}.items():
        code, _, err = run(None, "video", clip.name, "-o", name, *effect)
        assert code == 0 and "pose (sv3d yaw 30, pitch 0, roll 0)" in err and "left out" in err
        assert probe(name).spherical.yaw == 0
    import json

    yaw = {"keyframes": [[0, 0], [0.125, 90]]}
    spin = {"spherewarp": 1, "duration": 0.125, "steps": [{"rotate": {"yaw": yaw}}]}
    (workdir / "spin.json").write_text(json.dumps(spin))
    code, _, err = run(None, "video", clip.name, "-o", "s.mp4", "recipe", "spin.json")
    assert code == 0 and "left out" in err  # a turn that changes over time: no one pose holds
    if ffprobe is None:
        pytest.skip("ffprobe is not installed")
    args = ["-v", "error", "-show_entries", "stream_side_data=yaw", "-of", "csv=p=0", "y.mp4"]
    text = subprocess.run([ffprobe, *args], capture_output=True, text=True, check=True).stdout
    assert "-60" in text


def test_a_recipe_longer_than_the_clip_is_refused(clip, workdir):
    import json

    yaw = {"keyframes": [[0, 0], [2, 90]]}
    spin = {"spherewarp": 1, "duration": 2, "steps": [{"rotate": {"yaw": yaw}}]}
    (workdir / "long.json").write_text(json.dumps(spin))
    code, _, err = run(None, "video", clip.name, "-o", "o.mp4", "recipe", "long.json")
    assert code == 2 and one_line(err) and "runs 2 s but 'in.mp4' lasts 0.5 s" in err, err
    assert not (workdir / "o.mp4").exists()


def test_more_bad_inputs(workdir, clip):
    """No video stream; a pixel format or codec the encoder/container does not take (the
    choices listed); a stereo layout whose eyes are not 2:1: one line each, nothing written."""
    from fractions import Fraction

    with av.open(str(workdir / "tone.m4a"), "w") as c:
        a = c.add_stream("aac", rate=48000)
        a.layout = "mono"
        f = av.AudioFrame.from_ndarray(
            np.zeros((1, 1024), np.float32), format="fltp", layout="mono"
        )
        f.sample_rate, f.pts, f.time_base = 48000, 0, Fraction(1, 48000)
        c.mux(a.encode(f))
        c.mux(a.encode(None))
    before = sorted(p.name for p in workdir.iterdir())
    cases = {
        "has no video stream": ["video", "tone.m4a", "-o", "o.mp4", "rotate"],
        "use one of": ["video", clip.name, "-o", "o.mp4", "--pix-fmt", "rgb8", "rotate"],
        "libvpx-vp9": ["video", clip.name, "-o", "o.webm", "--codec", "libx264", "rotate"],
        "each eye (left-right stereo) is 128x128": [
            "video", clip.name, "-o", "o.mp4", "--stereo", "sbs", "rotate",
        ],
    }  # fmt: skip
    for needle, args in cases.items():
        code, _, err = run(None, *args)
        assert code == 2 and one_line(err) and needle in err, (args, err)
    code, _, err = run(None, "video", clip.name, "-o", "o.mp4", "--codec", "nope", "rotate")
    assert "libx265" in err and "libvpx-vp9" in err  # the encoders this build has
    assert sorted(p.name for p in workdir.iterdir()) == before


def test_a_stereo_still(workdir):
    """One image is a sequence of one frame: a top-bottom still, warped eye by eye."""
    from spherewarp.io import read_image, write_image
    from spherewarp.io.stereo import eyes
    from spherewarp.maps import Mobius
    from spherewarp.render import warp
    from videoclip import stereo_panorama

    still = stereo_panorama("top-bottom")
    write_image(workdir / "tb.png", still, gpano=False)
    out = ok(None, "video", "tb.png", "--stereo", "tb", "-o", "o.png", "rotate", "--yaw", "90")
    assert out.strip() == "wrote o.png"
    got = read_image(workdir / "o.png")
    assert got.gpano is None  # a stereo pair is no single panorama
    turn = Mobius.from_yaw_pitch_roll(90, 0, 0)
    for a, b in zip(eyes(still, "tb"), eyes(got.pixels, "tb"), strict=True):
        assert np.array_equal(warp(np.ascontiguousarray(a), turn), b)
    make_clip(workdir / "c.mp4", frames=3, audio=False)
    code, _, err = run(None, "video", "c.mp4", "-o", "one.png", "rotate")
    assert code == 2 and one_line(err) and "holds one image" in err
    assert not (workdir / "one.png").exists()


def test_audio_matroska_cannot_hold_is_dropped_with_one_warning(workdir):
    """A MOV's adpcm_ima_qt audio into .mkv (segments joined): one warning line and the video,
    not an internal error with OUT.parts/ left behind."""
    make_clip(workdir / "adpcm.mov", frames=12, audio_codec="adpcm_ima_qt")
    code, out, err = run(None, "video", "adpcm.mov", "-o", "o.mkv", "--quiet", "rotate")
    assert code == 0 and out == "wrote o.mkv\n", err
    said = [line for line in err.splitlines() if "compiling kernels" not in line]
    assert said == [
        "spherewarp: warning: stream #1 (audio, adpcm_ima_qt) is dropped: a Matroska file "
        "cannot hold audio in adpcm_ima_qt"
    ]
    assert sorted(p.name for p in workdir.iterdir()) == ["adpcm.mov", "o.mkv"]
    with av.open("o.mkv") as c:
        assert [s.type for s in c.streams] == ["video"]
        assert sum(1 for _ in c.decode(video=0)) == 12


def with_display_rotation(src, dst, degrees):
    """``src`` remuxed to ``dst`` with a display matrix turning it by ``degrees`` (a phone's
    rotation tag: players show the frames turned)."""
    with av.open(str(src)) as c, av.open(str(dst), "w") as out:
        streams = {}
        for s in c.streams:
            streams[s.index] = out.add_stream_from_template(s)
            if s.type == "video":
                streams[s.index].set_display_rotation(degrees)
        for p in c.demux():
            if p.dts is not None:
                p.stream = streams[p.stream_index]
                out.mux(p)
    return dst


@pytest.mark.parametrize("segment", [[], ["--segment", "0.25"]])
@pytest.mark.parametrize("degrees", [180, 90])
def test_a_display_rotation_is_refused_or_dropped_with_force(clip, segment, degrees):
    """Players show such a video turned, and the map would turn the stored frames: refused
    in one line (the output had lost the matrix silently and played upside down); --force
    warps the frames as stored and says the rotation is dropped."""
    from _cli import fails

    rot = with_display_rotation(clip, clip.with_name("rot.mp4"), degrees)
    err = fails(None, "video", rot.name, "-o", "o.mp4", *segment, "rotate", "--yaw", "0")
    assert f"is shown rotated by {degrees}°" in err and "--force" in err
    assert not os.path.exists("o.mp4")
    code, _, err = run(None, "video", rot.name, "-o", "o.mp4", "-q", "--force", *segment,
                       "rotate", "--yaw", "90")  # fmt: skip
    assert code == 0 and err.count("\n") == 1, err
    assert "warning:" in err and "warped as stored" in err
    assert probe("o.mp4").display is None
    src, out = frames(clip), frames("o.mp4")
    assert psnr(np.roll(src[0], -src[0].shape[1] // 4, axis=1), out[0]) >= 35


@pytest.mark.parametrize(
    "bounds,stereo,what",
    [
        ((0.1, 0.1, 0.1, 0.1), "mono", "a cropped equirectangular"),
        ((0.0, 0.0, 0.25, 0.25), "left-right", "a VR180 (half-sphere) equirectangular"),
    ],
)
@pytest.mark.parametrize("extra", [[], ["--force"], ["--segment", "0.25"]])
def test_cropped_equirectangular_bounds_are_refused(workdir, bounds, stereo, what, extra):
    """An input whose equi bounds are not all 0 (cropped, VR180) is refused in one line that
    says so: it was warped as a full panorama and written as one (bounds 0), or a VR180
    input was refused as 'not 2:1' and with --force written as 360°."""
    from _cli import fails

    from spherewarp.io.spherical import Spherical, write_spherical

    src = make_clip(workdir / "crop.mp4", frames=6, audio=False)  # VR180: each eye 1:1
    write_spherical(src, Spherical(stereo=stereo, bounds=bounds))
    assert probe(src).spherical.bounds == pytest.approx(bounds)
    err = fails(None, "video", src.name, "-o", "o.mp4", *extra, "rotate", "--yaw", "90")
    assert what in err and "bounds" in err and "not 2:1" not in err
    assert not os.path.exists("o.mp4")


@pytest.mark.parametrize(
    "out, codec, says",
    [
        ("u.mkv", "utvideo", "choose another --codec"),
        ("q.mp4", "qtrle", "write .mov"),
        ("v.mov", "libvpx-vp9", "write .mp4 or .mkv"),  # the muxer refuses it at its header
    ],
)
def test_a_codec_the_container_cannot_hold_is_refused_in_one_line(clip, out, codec, says):
    """utvideo into .mkv (PyAV writes it into none of the containers) and qtrle into .mp4
    failed with an internal error after the first segment, leaving OUT.parts/."""
    err = fails(None, "video", clip.name, "-o", out, "--codec", codec, "rotate", "--yaw", "9")
    assert f"--codec {codec}: " in err and "cannot hold" in err and says in err, err
    assert not Path(out).exists() and not Path(f"{out}.parts").exists()


@pytest.mark.parametrize("out", ["h.mov", "h.mp4"])
def test_hevc_in_mp4_and_mov_is_tagged_hvc1(clip, out):
    """HEVC was always tagged hev1, which Apple's players refuse; hvc1 as ffmpeg -tag:v hvc1
    writes it. Every frame still decodes."""
    ok(None, "video", clip.name, "-o", out, "--codec", "libx265", "--quiet", "rotate", "--yaw",
       "9")  # fmt: skip
    with av.open(out) as c:
        assert c.streams.video[0].codec_context.codec_tag == "hvc1"
    assert len(frames(out)) == 12


def test_crf_for_an_encoder_without_one_is_refused(clip):
    """--crf was silently ignored by an encoder without a constant rate factor: mpeg4 with
    --crf 2 and --crf 60 wrote the same bytes. Refused in one line naming --crf; without it,
    mpeg4 encodes."""
    err = fails(None, "video", clip.name, "-o", "m.mp4", "--codec", "mpeg4", "--crf", "2",
                "rotate", "--yaw", "9")  # fmt: skip
    assert err.startswith("spherewarp: error: --crf: mpeg4 has no constant rate factor"), err
    assert not Path("m.mp4").exists() and not Path("m.mp4.parts").exists()
    ok(None, "video", clip.name, "-o", "m.mp4", "--codec", "mpeg4", "--quiet", "rotate", "--yaw",
       "9")  # fmt: skip
    assert len(frames("m.mp4")) == 12
    err = fails(None, "video", clip.name, "-o", "m2.mp4", "--codec", "mpeg4", "--preset", "slow",
                "rotate", "--yaw", "9")  # fmt: skip
    assert err.startswith("spherewarp: error: --preset: mpeg4 has no presets"), err
    assert not Path("m2.mp4").exists()


def test_mpeg2_encodes_a_12_fps_mp4_and_mpeg1_refuses_it_naming_its_rate(workdir):
    """The encoder got the stream's time base (1/12288 s in a 12 fps MP4 file) as its frame
    rate: 'MPEG-1/2 does not support 12288/1 fps; check --preset, --crf and --pix-fmt'. MPEG-1/2
    encode in a time base of one frame: MPEG-2 takes 12 fps (24/2), MPEG-1 does not, and its
    refusal names the input's rate."""
    make_clip(workdir / "in.mp4", frames=6, rate=12)
    assert probe("in.mp4").time_base == Fraction(1, 12288)
    ok(None, "video", "in.mp4", "-o", "m2.mp4", "--codec", "mpeg2video", "--quiet", "rotate",
       "--yaw", "9")  # fmt: skip
    assert len(frames("m2.mp4")) == 6 and probe("m2.mp4").rate == 12
    with av.open("m2.mp4") as c, av.open("in.mp4") as i:
        assert sorted(p.pts for p in c.demux(video=0) if p.size) == sorted(
            p.pts for p in i.demux(video=0) if p.size
        )  # every frame at its time
    err = fails(None, "video", "in.mp4", "-o", "m1.mp4", "--codec", "mpeg1video", "rotate")
    assert "--codec mpeg1video: it does not take the input's 12 fps" in err, err
    assert "12288" not in err and not Path("m1.mp4").exists()


@pytest.mark.parametrize(
    "effect",
    [["rotat", "--yaw", "3"], ["zooom", "--at", "0,0", "--factor", "2"], ["rotat"]],
    ids=lambda e: " ".join(e),
)
def test_a_misspelt_effect_is_named_not_taken_for_an_input(workdir, effect):
    """'rotat' is no second INPUT clip (no such file): it is the effect, misspelt."""
    clip = make_clip(workdir / "tour.mp4", frames=2, audio=False)
    err = fails(None, "video", clip, "-o", workdir / "v.mp4", "--crf", "20", *effect)
    right = {"rotat": "rotate", "zooom": "zoom"}[effect[0]]
    assert f"no such effect '{effect[0]}' (did you mean '{right}'?)" in err
    assert not (workdir / "v.mp4").exists()
