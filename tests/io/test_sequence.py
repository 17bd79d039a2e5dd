"""Image sequences in and out of the video pipeline: PNG, TIFF, EXR frames."""

from __future__ import annotations

import numpy as np
import pytest

from spherewarp.errors import ImageFormatError, InvalidValueError, OutputExistsError
from spherewarp.io import read_image, write_image
from spherewarp.io.sequence import find_frames, frame_path, render_sequence, split_pattern
from spherewarp.io.tonemap import srgb_to_linear
from spherewarp.io.video import probe
from spherewarp.maps import Mobius
from spherewarp.render import warp
from videoclip import frame, make_clip

av = pytest.importorskip("av")
ZOOM = Mobius.zoom((0, 0), 2).inverse()


def psnr(a, b, peak=255.0):
    mse = np.mean((a.astype(np.float64) - b) ** 2)
    return np.inf if mse == 0 else 10 * np.log10(peak**2 / mse)


def decoded(path):
    with av.open(str(path)) as c:
        return [f.to_ndarray(format="rgb24") for f in c.decode(video=0)]


def test_patterns():
    assert split_pattern("a/b_%d.tif") == ("a/b_", 0, ".tif")
    assert frame_path("x{:04d}.png", 12).as_posix() == "x0012.png"
    with pytest.raises(InvalidValueError, match="one field"):
        split_pattern("a_%d_%d.png")
    with pytest.raises(InvalidValueError, match="one field"):
        split_pattern("plain.png")


def test_frames_found_in_number_order(tmp_path):
    for k in (10, 9, 100, 2):
        (tmp_path / f"f_{k:03d}.png").write_bytes(b"")
    (tmp_path / "f_x.png").write_bytes(b"")
    (tmp_path / "g_001.png").write_bytes(b"")
    names = [p.name for p in find_frames(tmp_path / "f_%03d.png")]
    assert names == ["f_002.png", "f_009.png", "f_010.png", "f_100.png"]
    with pytest.raises(ImageFormatError, match="no file matches"):
        find_frames(tmp_path / "h_%03d.png")


def test_video_to_sequence_and_back(tmp_path):
    clip = make_clip(tmp_path / "c.mp4", frames=8)
    pngs = tmp_path / "png" / "%04d.png"
    with pytest.warns(UserWarning, match=r"stream #1 \(audio\) is dropped"):
        assert render_sequence(clip, pngs, lambda t: (ZOOM, {})) == 8
    files = find_frames(pngs)
    assert [p.name for p in files] == [f"{k:04d}.png" for k in range(8)]
    src = decoded(clip)
    for k in (0, 7):  # frame k is the still render of the decoded frame k
        img = read_image(files[k])
        assert img.gpano is not None  # a panorama: GPano
        assert psnr(warp(src[k], ZOOM), img.pixels) >= 45
    # the sequence in, at 12 frames a second, to a video
    out = tmp_path / "back.mp4"
    render_sequence(pngs, out, lambda t: (ZOOM.inverse(), {}), fps=12)
    info = probe(out)
    assert info.frames == 8 and info.rate == 12 and info.duration == pytest.approx(8 / 12)
    assert info.spherical is not None and info.spherical.projection == "equirectangular"
    got = decoded(out)
    assert psnr(warp(read_image(files[3]).pixels, ZOOM.inverse()), got[3]) >= 35


def test_times_of_a_sequence_follow_fps(tmp_path):
    for k in range(3):
        write_image(tmp_path / f"in_{k}.png", frame(k))
    seen = []
    render_sequence(
        tmp_path / "in_%d.png", tmp_path / "out_%d.tif", lambda t: (seen.append(t) or ZOOM, {}),
        fps=10,
    )  # fmt: skip
    assert seen == pytest.approx([0, 0.1, 0.2])
    assert read_image(tmp_path / "out_2.tif").pixels.dtype == np.uint8


def test_sixteen_bit_and_float_frames_keep_their_type(tmp_path):
    base = frame(0).astype(np.uint16) * 257 + 100
    write_image(tmp_path / "a0.png", base)
    write_image(tmp_path / "a1.png", base[:, ::-1].copy())
    render_sequence(tmp_path / "a%d.png", tmp_path / "b%d.exr", lambda t: (ZOOM, {}))
    out = read_image(tmp_path / "b1.exr").pixels
    assert out.dtype == np.float32
    want = warp(base[:, ::-1].copy(), ZOOM).astype(np.float64) / 65535
    want = srgb_to_linear(want)  # EXR holds linear light: 16-bit sRGB is linearised
    assert psnr(out[..., :3], want, peak=1.0) >= 45
    # float frames to 16-bit PNG: tone-mapped (as the still commands do)
    render_sequence(tmp_path / "b%d.exr", tmp_path / "c%d.png", lambda t: (ZOOM.inverse(), {}))
    assert read_image(tmp_path / "c0.png").pixels.dtype == np.uint16


def test_bad_sequences_write_nothing(tmp_path):
    write_image(tmp_path / "s0.png", frame(0))
    write_image(tmp_path / "s1.png", frame(1)[:64, :128].copy())  # another size
    with pytest.raises(ImageFormatError, match="s1.png.*128x64.*first frame is 256x128"):
        render_sequence(tmp_path / "s%d.png", tmp_path / "o%d.png", lambda t: (ZOOM, {}))
    with pytest.raises(ImageFormatError, match="unknown image extension"):
        render_sequence(tmp_path / "s%d.png", tmp_path / "o%d.gif", lambda t: (ZOOM, {}))
    with pytest.raises(ImageFormatError, match="no file matches"):
        render_sequence(tmp_path / "t%d.png", tmp_path / "o.mp4", lambda t: (ZOOM, {}))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s0.png", "s1.png"]
    write_image(tmp_path / "s1.png", frame(1), overwrite=True)
    with pytest.raises(OutputExistsError, match="--overwrite"):
        render_sequence(tmp_path / "s%d.png", tmp_path / "s%d.png", lambda t: (ZOOM, {}))


def test_existing_outputs_are_the_frames_the_writer_names(tmp_path):
    """The check of existing files and the writer name the frames alike, from 0: '%d' next to
    a '%05d' input writes 0.png..., so 00001.png (which '%d' also matches) is no reason to
    refuse; the files it would write are, and --overwrite replaces them."""
    seq = tmp_path / "seq"
    seq.mkdir()
    for k in range(1, 4):
        write_image(seq / f"{k:05d}.png", frame(k))
    n = render_sequence(seq / "%05d.png", seq / "%d.png", lambda t: (ZOOM, {}), fps=12)
    assert n == 3 and sorted(p.name for p in seq.glob("?.png")) == ["0.png", "1.png", "2.png"]
    (seq / "1.png").unlink()
    with pytest.raises(OutputExistsError, match=r"seq/0.png' exists \(2 of the 3 frames"):
        render_sequence(seq / "%05d.png", seq / "%d.png", lambda t: (ZOOM, {}), fps=12)
    assert not (seq / "1.png").exists()  # refused before writing
    render_sequence(seq / "%05d.png", seq / "%d.png", lambda t: (ZOOM, {}), overwrite=True)
    names = {p.name for p in seq.iterdir()}
    assert names == {"00001.png", "00002.png", "00003.png", "0.png", "1.png", "2.png"}
    # a video that records no frame count (Matroska): its frames are counted, so a frame
    # file past the first is found too
    clip = make_clip(tmp_path / "c.mkv", frames=3, audio=False)
    write_image(tmp_path / "f2.png", frame(0))
    with pytest.raises(OutputExistsError, match=r"f2.png' exists \(1 of the 3 frames"):
        render_sequence(clip, tmp_path / "f%d.png", lambda t: (ZOOM, {}))
    assert not (tmp_path / "f0.png").exists()


def test_an_interrupt_removes_the_frames_written(tmp_path):
    clip = make_clip(tmp_path / "c.mp4", frames=24, audio=False)

    def frame_map(t):
        if t > 0.5:
            raise KeyboardInterrupt
        return ZOOM, {}

    with pytest.raises(KeyboardInterrupt):
        render_sequence(clip, tmp_path / "f" / "%03d.png", frame_map)
    assert list((tmp_path / "f").iterdir()) == []


def test_stereo_sequence(tmp_path):
    from spherewarp.io.stereo import eyes
    from videoclip import stereo_panorama

    write_image(tmp_path / "e0.png", stereo_panorama("left-right"), gpano=False)
    render_sequence(tmp_path / "e%d.png", tmp_path / "o%d.png", lambda t: (ZOOM, {}), stereo="sbs")
    out = read_image(tmp_path / "o0.png").pixels
    for a, b in zip(eyes(stereo_panorama("left-right"), "sbs"), eyes(out, "sbs"), strict=True):
        assert (
            np.array_equal(warp(np.ascontiguousarray(a), ZOOM), b)
            or psnr(warp(np.ascontiguousarray(a), ZOOM), b) >= 45
        )
