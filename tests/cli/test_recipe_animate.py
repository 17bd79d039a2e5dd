"""``spherewarp animate``: the numbered frames of a timed recipe (fresh processes)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from _cli import fails, ok, run

from spherewarp.io import read_image, write_image


@pytest.fixture
def pano(tmp_path):
    y, x = np.mgrid[0:96, 0:192]
    rng = np.random.default_rng(3)
    img = rng.integers(0, 256, (96, 192, 3), dtype=np.uint8)
    img[..., 0] = (x * 255 // 191).astype(np.uint8)
    return write_image(tmp_path / "room.png", img)


def recipe(tmp_path, name, data):
    p = tmp_path / name
    p.write_text(json.dumps({"spherewarp": 1, **data}))
    return p


def test_spin_at_24_fps_turns_by_the_same_angle_between_every_pair_of_frames(tmp_path, pano):
    spin = {"keyframes": [[0, 0], [1, 360]]}
    r = recipe(
        tmp_path, "spin.json", {"duration": 1, "loop": True, "steps": [{"rotate": {"yaw": spin}}]}
    )
    ok(None, "animate", r, pano, "--fps", "24", "-o", f"{tmp_path / 'frames'}/", "-q")
    names = sorted(p.name for p in (tmp_path / "frames").iterdir())
    assert names == [f"room-animate_{k:04d}.png" for k in range(24)]  # a loop: 0 .. 23/24 s
    frames = [read_image(tmp_path / "frames" / n).pixels for n in names]
    # 15 degrees a frame = 8 of 192 columns, between every pair, and from the last to the first
    for a, b in zip(frames, frames[1:] + frames[:1], strict=True):
        assert np.array_equal(b, np.roll(a, -8, axis=1))


def test_droste_loop_last_frame_flows_into_the_first(tmp_path, pano):
    step = {"center": [0, 0], "inner_radius": 25, "scale": 4}
    loop = recipe(
        tmp_path,
        "loop.json",
        {
            "duration": 1,
            "loop": True,
            "steps": [{"droste": {**step, "phase": {"keyframes": [[0, 0], [1, 1]]}}}],
        },
    )
    ok(None, "animate", loop, pano, "--fps", "6", "-o", tmp_path / "d" / "%02d.png", "-q")
    names = sorted(p.name for p in (tmp_path / "d").iterdir())
    assert names == [f"{k:02d}.png" for k in range(6)]
    first = read_image(tmp_path / "d" / "00.png").pixels
    # the frame after the last (t = 1 s) is the first
    ok(None, "render", loop, pano, "--time", "1", "-o", tmp_path / "after.png", "-q")
    assert np.array_equal(read_image(tmp_path / "after.png").pixels, first)
    # and so is a whole period of the Droste map itself (phase 1), not just the wrap of time
    one = recipe(tmp_path, "one.json", {"steps": [{"droste": {**step, "phase": 1}}]})
    ok(None, "render", one, pano, "-o", tmp_path / "phase1.png", "-q")
    diff = np.abs(read_image(tmp_path / "phase1.png").pixels.astype(int) - first)
    assert np.mean(diff > 1) < 0.002
    # the frames move: frame 3 is not frame 0
    assert not np.array_equal(read_image(tmp_path / "d" / "03.png").pixels, first)


def test_keyframed_zoom_frames_and_formats(tmp_path, pano):
    r = recipe(
        tmp_path,
        "z.json",
        {
            "duration": 2,
            "steps": [{"zoom": {"at": [30, 10], "factor": {"keyframes": [[0, 1], [2, 4]]}}}],
        },
    )
    ok(None, "animate", r, pano, "--fps", "1", "-o", tmp_path / "z.tif", "-q")
    assert sorted(p.name for p in tmp_path.glob("z_*.tif")) == [
        "z_0000.tif",
        "z_0001.tif",
        "z_0002.tif",  # not a loop: 0, 1 and 2 s
    ]
    plain = recipe(tmp_path, "p.json", {"steps": [{"zoom": {"at": [30, 10], "factor": 2.5}}]})
    ok(None, "render", plain, pano, "-o", tmp_path / "p.tif", "-q")
    assert np.array_equal(
        read_image(tmp_path / "z_0001.tif").pixels, read_image(tmp_path / "p.tif").pixels
    )
    # --duration overrides the recipe's
    ok(None, "animate", r, pano, "--fps", "2", "--duration", "0.5", "-o", tmp_path / "s.png", "-q")
    assert len(list(tmp_path.glob("s_*.png"))) == 2


def test_animate_errors_are_one_line_and_write_nothing(tmp_path, pano):
    still = recipe(tmp_path, "still.json", {"steps": [{"rotate": {"yaw": 3}}]})
    err = fails(None, "animate", still, pano, "--fps", "24", "-o", tmp_path / "f.png")
    assert "has no duration; give --duration" in err
    timed = recipe(
        tmp_path,
        "t.json",
        {"duration": 1, "steps": [{"rotate": {"yaw": {"keyframes": [[0, 0], [1, 9]]}}}]},
    )
    err = fails(None, "animate", timed, pano, "--fps", "0", "-o", tmp_path / "f.png")
    assert "--fps" in err
    err = fails(None, "animate", timed, pano, "--fps", "1e9", "-o", tmp_path / "f.png")
    assert "--fps" in err
    (tmp_path / "f_0001.png").write_bytes(b"keep")
    err = fails(None, "animate", timed, pano, "--fps", "2", "-o", tmp_path / "f.png")
    assert "exists; pass --overwrite" in err
    assert not (tmp_path / "f_0000.png").exists()
    assert (tmp_path / "f_0001.png").read_bytes() == b"keep"
    code, _, err = run(None, "animate", timed, pano, "--fps", "2", "-o", tmp_path / "v.mkv")
    assert code == 0 and (tmp_path / "v.mkv").exists()  # a video output: one file, encoded
    code, _, err = run(None, "animate", timed, pano, "--fps", "2", "-o", tmp_path / "v.avi")
    assert code == 2 and "Traceback" not in err  # not a video extension: an image one, refused


def test_an_animated_droste_loop_to_mp4_loops(tmp_path):
    import shutil
    import subprocess

    av = pytest.importorskip("av")
    from spherewarp.io.video import probe
    from videoclip import panorama

    pano = write_image(tmp_path / "interior.png", panorama())  # a photograph: codec error small

    r = tmp_path / "loop.json"
    ok(
        None, "droste", pano, "--center", "0,0", "--inner-radius", "20", "--scale", "8",
        "--frames", "2", "--save-recipe", r, "--dry-run", "-o", tmp_path / "x.png",
    )  # fmt: skip
    out = tmp_path / "loop.mp4"
    ok(None, "animate", r, pano, "--fps", "12", "--duration", "1", "-o", out, "--crf", "12", "-q")
    with av.open(str(out)) as c:
        frames = [f.to_ndarray(format="rgb24") for f in c.decode(video=0)]
    assert len(frames) == 12  # fps * duration
    info = probe(out)
    assert info.frames == 12 and info.rate == 12
    assert info.spherical is not None and info.spherical.projection == "equirectangular"

    def psnr(a, b):
        return 10 * np.log10(255.0**2 / max(np.mean((a.astype(np.float64) - b) ** 2), 1e-12))

    # the frame after the last (the recipe at t = duration) is the first, within codec error
    after = tmp_path / "after.png"
    ok(None, "render", r, pano, "--time", "1", "-o", after, "-q")
    ref = read_image(after).pixels[..., :3]
    assert psnr(ref, frames[0]) >= 35
    first = tmp_path / "first.png"
    ok(None, "render", r, pano, "--time", "0", "-o", first, "-q")
    assert psnr(read_image(first).pixels[..., :3], ref) >= 50  # t = 0 and t = 1: one image
    ok(None, "render", r, pano, "--time", f"{5 / 12}", "-o", first, "-q", "--overwrite")
    assert psnr(read_image(first).pixels[..., :3], frames[5]) >= 35
    ffprobe = shutil.which("ffprobe")
    if ffprobe is not None:
        args = ["-v", "error", "-show_entries", "stream_side_data=projection", str(out)]
        done = subprocess.run([ffprobe, *args], capture_output=True, text=True, check=True)
        assert "equirectangular" in done.stdout


def test_animate_to_video_options_and_bad_input(tmp_path, pano):
    spin = {"keyframes": [[0, 0], [1, 360]]}
    data = {"duration": 1, "loop": True, "steps": [{"rotate": {"yaw": spin}}]}
    r = recipe(tmp_path, "spin.json", data)
    out = tmp_path / "spin.webm"
    ok(None, "animate", r, pano, "--fps", "4", "-o", out, "-q", "--projection", "little-planet")
    from spherewarp.io.video import probe

    info = probe(out)
    assert info.frames in (0, 4) and info.codec == "vp9" and info.spherical is None
    code, _, err = run(None, "animate", r, pano, "--fps", "4", "-o", out, "-q")
    assert code != 0 and "exists" in err  # no --overwrite
    bad = tmp_path / "bad.mp4"
    code, _, err = run(None, "animate", r, pano, "--fps", "4", "-o", bad, "--codec", "nope")
    assert code != 0 and "no such video encoder" in err and err.count("\n") == 1
    assert not bad.exists()
    code, _, err = run(None, "animate", r, pano, "--fps", "4", "-o", tmp_path / "f/", "--crf", "9")
    assert code == 2 and "--crf" in err and "video" in err
