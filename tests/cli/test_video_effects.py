"""``spherewarp video``'s subcommands made from the still commands, and the split-screen of
two clips: frame k of the video equals the still command run on frame k (fresh processes)."""

from __future__ import annotations

import shutil
import subprocess

import numpy as np
import pytest
from _cli import ok, run

from spherewarp.io import read_image, write_image
from spherewarp.io.video import probe
from videoclip import make_clip, panorama

av = pytest.importorskip("av")
ffprobe = shutil.which("ffprobe")

DROSTE = ["--center", "0,0", "--inner-radius", "20", "--scale", "8"]


@pytest.fixture
def clip(workdir):
    return make_clip(workdir / "in.mp4", frames=12)


def frames(path):
    with av.open(str(path)) as c:
        return [f.to_ndarray(format="rgb24") for f in c.decode(video=0)]


def psnr(a, b):
    return 10 * np.log10(255.0**2 / np.mean((a.astype(np.float64) - b) ** 2))


def still_of(workdir, pixels, name="f.png"):
    return write_image(workdir / name, pixels, overwrite=True)


def rendered(*args):
    ok(None, *args, "-o", "ref.png", "--overwrite", "-q")
    return read_image("ref.png").pixels[..., :3]


@pytest.mark.parametrize(
    ("video_args", "still_args"),
    [
        (["droste", *DROSTE], ["droste", *DROSTE]),
        (["lattes", "--alpha", "1+1j"], ["lattes", "--alpha", "1+1j"]),
        (["map", "--expr", "z**2"], ["map", "--expr", "z**2"]),
        (
            ["schottky", "--generator", "-163,5,12 -> 17,-5,25"],
            ["schottky", "--generator", "-163,5,12 -> 17,-5,25"],
        ),
        (["project", "--to", "little-planet"], ["project", "--to", "little-planet"]),
    ],
    ids=["droste", "lattes", "map", "schottky", "project"],
)
def test_a_static_effect_frame_equals_the_still_command(clip, workdir, video_args, still_args):
    ok(None, "video", clip.name, "-o", "out.mp4", "-q", *video_args)
    src, out = frames(clip), frames("out.mp4")
    assert len(out) == len(src) == 12
    for k in (0, 7):
        ref = rendered(still_args[0], still_of(workdir, src[k]), *still_args[1:])
        assert ref.shape == out[k].shape
        assert psnr(ref, out[k]) >= 35, k
    info = probe("out.mp4")
    panorama = video_args[0] != "project"
    assert (info.spherical is not None) == panorama


@pytest.mark.parametrize("effect", ["droste", "schottky"])
def test_a_loop_flies_through_the_phase_in_its_seconds(clip, workdir, effect):
    opts = DROSTE if effect == "droste" else ["--generator", "-163,5,12 -> 17,-5,25"]
    # 12 frames at 24 fps = 0.5 s: --loop 0.25 goes round twice; frame k has phase k/6 mod 1
    ok(None, "video", clip.name, "-o", "loop.mp4", "-q", effect, *opts, "--loop", "0.25")
    src, out = frames(clip), frames("loop.mp4")
    assert len(out) == 12
    for k in (3, 8):
        phase = (k / 24 / 0.25) % 1.0
        ref = rendered(effect, still_of(workdir, src[k]), *opts, "--phase", f"{phase:.12g}")
        assert psnr(ref, out[k]) >= 35, k
    assert psnr(out[3], frames(clip)[3]) < 25  # it does change the frame


def test_the_generated_commands_take_the_still_commands_checks(clip, workdir):
    code, _, err = run(None, "video", clip.name, "-o", "x.mp4", "droste", "--scale", "3")
    assert code == 2 and "exactly one of --frame, --mask or --inner-radius" in err
    assert err.count("\n") == 1 and not (workdir / "x.mp4").exists()
    code, _, err = run(None, "video", clip.name, "-o", "x.mp4", "lattes", "--alpha", "1+1q")
    assert code != 0 and "--alpha" in err and err.count("\n") == 1
    args = ["droste", "--center", "0,0", "--inner-radius", "0"]  # a map's error: the option
    code, _, err = run(None, "video", clip.name, "-o", "x.mp4", *args)
    assert code == 2 and "--inner-radius: expected an angular radius" in err
    code, _, err = run(None, "video", clip.name, "-o", "x.mp4", "project")
    assert code == 2 and "--to NAME" in err
    assert not (workdir / "x.mp4").exists()
    out = ok(None, "video", clip.name, "droste", "--help")
    assert "--inner-radius" in out and "--loop" in out and "--periods" in out
    assert "--view" in out and "--inside" in out


@pytest.mark.parametrize(
    "extra", [["--view", "log"], ["--inside", "other.png"]], ids=["view-log", "inside"]
)
def test_droste_log_view_and_inside_frames_equal_the_still_command(clip, workdir, extra):
    write_image(workdir / "other.png", panorama("courtyard.png"), overwrite=True)
    # the log plane's period rectangle is drawn 1 pixel wide in red: 4:2:0 chroma cannot
    # hold it, so that video keeps its chroma whole (4:4:4) and nearly lossless
    enc = ["--pix-fmt", "yuv444p", "--crf", "1"] if "--view" in extra else []
    ok(None, "video", clip.name, "-o", "d.mp4", "-q", *enc, "droste", *DROSTE, *extra)
    src, out = frames(clip), frames("d.mp4")
    assert len(out) == len(src) == 12
    for k in (0, 7):
        ref = rendered("droste", still_of(workdir, src[k]), *DROSTE, *extra)
        h, w = out[k].shape[:2]  # a flat log plane of odd sides loses its last row/column
        assert (ref.shape[0] - h, ref.shape[1] - w) in ((0, 0), (0, 1), (1, 0), (1, 1))
        assert psnr(ref[:h, :w], out[k]) >= 35, k
    if "--inside" in extra:  # the copies show the other panorama: not the plain Droste
        assert psnr(out[7], frames_of_plain(clip, workdir)[7]) < 30
    assert (probe("d.mp4").spherical is not None) == ("--inside" in extra)  # log: flat


def test_droste_inside_and_log_view_refuse_bad_input(clip, workdir):
    write_image(workdir / "square.png", np.zeros((32, 32, 3), np.uint8), overwrite=True)
    for extra, said in [
        (["--inside", "missing.png"], "cannot read 'missing.png'"),
        (["--inside", "square.png"], "square.png: expected an equirectangular image"),
        (["--view", "log", "--jobs", "2"], "--jobs"),
    ]:
        video, effect = (["--jobs", "2"], extra[:2]) if "--jobs" in extra else ([], extra)
        code, _, err = run(None, "video", clip.name, "-o", "x.mp4", *video, "droste", *DROSTE,
                           *effect)  # fmt: skip
        assert code == 2 and said in err and err.count("\n") == 1, err
        assert "Traceback" not in err and not (workdir / "x.mp4").exists()


def test_a_saved_droste_recipe_renders_on_video_as_the_droste_command(clip, workdir):
    """'video IN recipe R.json' with a log-view Droste step gives what 'video IN droste ...
    --view log' gives (a flat picture, no 360° metadata), not the plain Droste image; a recipe
    of two images (a split screen's) is refused in one line."""
    enc = ["--pix-fmt", "yuv444p", "--crf", "1"]
    ok(None, "video", clip.name, "-o", "d.mp4", "-q", *enc, "droste", *DROSTE, "--view", "log")
    ok(None, "droste", "x.png", *DROSTE, "--view", "log", "--save-recipe", "log.json",
       "--dry-run", "-q")  # fmt: skip
    ok(None, "video", clip.name, "-o", "r.mp4", "-q", *enc, "recipe", "log.json")
    a, b = frames("d.mp4"), frames("r.mp4")
    assert a[0].shape == b[0].shape
    assert np.array_equal(a[3], b[3]) or psnr(a[3], b[3]) >= 45
    assert probe("r.mp4").spherical is None
    write_image(workdir / "other.png", panorama("courtyard.png"), overwrite=True)
    ok(None, "splitscreen", "other.png", "other.png", "--save-recipe", "two.json", "--dry-run",
       "-q")  # fmt: skip
    code, _, err = run(None, "video", clip.name, "-o", "x.mp4", "recipe", "two.json")
    assert code == 2 and "renders from 2 images" in err and err.count("\n") == 1, err
    assert not (workdir / "x.mp4").exists()


def frames_of_plain(clip, workdir):
    ok(None, "video", clip.name, "-o", "plain.mp4", "-q", "droste", *DROSTE)
    return frames(workdir / "plain.mp4")


def test_splitscreen_of_two_clips(workdir):
    a = make_clip(workdir / "a.mp4", frames=10)
    b = make_clip(workdir / "b.mp4", frames=8)  # shorter: it ends the output
    code, out, err = run(
        None, "video", "a.mp4", "b.mp4", "-o", "two.mp4", "-q", "splitscreen", "--seam", "0"
    )
    assert code == 0, err
    assert "ends with the shortest, 'b.mp4', after 8 frames" in err
    fa, fb, fo = frames(a), frames(b), frames("two.mp4")
    assert len(fo) == 8
    for k in (0, 5):
        ref = rendered(
            "splitscreen",
            still_of(workdir, fa[k], "a.png"),
            still_of(workdir, fb[k], "b.png"),
            "--seam",
            "0",
        )
        assert psnr(ref, fo[k]) >= 35, k
    with av.open("a.mp4") as ca, av.open("two.mp4") as co:  # the first clip's audio, as it is
        pa = [bytes(p) for p in ca.demux(audio=0) if p.size]
        po = [bytes(p) for p in co.demux(audio=0) if p.size]
    assert 0 < len(po) < len(pa) and po == pa[: len(po)]
    info = probe("two.mp4")
    assert info.frames == 8 and info.rate == 24 and info.spherical.projection == "equirectangular"
    if ffprobe is not None:
        args = ["-v", "error", "-show_entries", "stream_side_data=projection", "two.mp4"]
        done = subprocess.run([ffprobe, *args], capture_output=True, text=True, check=True)
        assert "equirectangular" in done.stdout


def test_splitscreen_refuses_clips_of_two_frame_rates_and_one_clip(workdir):
    make_clip(workdir / "a.mp4", frames=4)
    import av as _av

    with _av.open(str(workdir / "c.mp4"), "w") as c:  # 30 fps
        v = c.add_stream("libx264", rate=30)
        v.width, v.height, v.pix_fmt = 64, 32, "yuv420p"
        for _ in range(4):
            c.mux(v.encode(_av.VideoFrame.from_ndarray(np.zeros((32, 64, 3), np.uint8))))
        c.mux(v.encode(None))
    code, _, err = run(None, "video", "a.mp4", "c.mp4", "-o", "x.mp4", "splitscreen")
    assert code != 0 and "need one frame rate" in err and err.count("\n") == 1
    code, _, err = run(None, "video", "a.mp4", "-o", "x.mp4", "splitscreen")
    assert code == 2 and "several clips" in err
    code, _, err = run(None, "video", "a.mp4", "a.mp4", "-o", "x.mp4", "rotate")
    assert code == 2 and "rotate takes one INPUT" in err
    assert not (workdir / "x.mp4").exists()
