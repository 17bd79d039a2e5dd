"""A short 360° test clip made with PyAV: the bundled panorama turning, with a sine tone."""

from __future__ import annotations

from fractions import Fraction
from pathlib import Path

import numpy as np

W, H = 256, 128
RATE = 24
SECONDS = 2


def panorama(name: str = "interior.png") -> np.ndarray:
    """A bundled panorama at W x H (``interior.png``, or ``courtyard.png``)."""
    from PIL import Image

    from spherewarp.demo import sample_path

    with Image.open(sample_path(name)) as im:
        return np.asarray(im.convert("RGB").resize((W, H), Image.LANCZOS))


def stereo_panorama(layout: str) -> np.ndarray:
    """Two different panoramas as the two eyes: the interior for the left eye, the courtyard
    for the right, one above the other (``"top-bottom"``) or side by side (``"left-right"``)."""
    left, right = panorama(), panorama("courtyard.png")
    return np.concatenate([left, right], axis=0 if layout == "top-bottom" else 1)


def frame(k: int) -> np.ndarray:
    """Frame k: the panorama turned by 4 columns a frame about the vertical axis."""
    return np.roll(panorama(), -4 * k, axis=1)


def make_clip(
    path: Path,
    *,
    frames: int = RATE * SECONDS,
    audio: bool = True,
    size=(W, H),
    pix_fmt="yuv420p",
    stereo: str | None = None,
    audio_codec: str = "aac",
    gop: int | None = None,
    rate: Fraction | int = RATE,
    times: list[Fraction] | None = None,
) -> Path:
    """Write the clip (H.264 at CRF 10, AAC mono at 48 kHz) to ``path``; return ``path`` (its
    extension picks the container: ``.ts`` MPEG-TS...).

    ``gop``: a keyframe every ``gop`` frames (default: x264's, 250). ``rate``: frames a
    second (``Fraction(30000, 1001)``: NTSC's; the time base is its inverse). ``times``: each
    frame's time in seconds (a variable frame rate; time base 1/1000; no audio).

    ``audio_codec``: the tone's encoder instead of AAC (``libmp3lame``, ``adpcm_ima_qt``...;
    PyAV converts the samples to its format). The container follows ``path``'s extension.

    ``stereo`` ("top-bottom", "left-right"): two eyes of W x H from two different
    panoramas (:func:`stereo_panorama`), turning together, marked with ``st3d``.
    """
    import av

    base = panorama() if stereo is None else stereo_panorama(stereo)
    w, h = size if stereo is None else (base.shape[1], base.shape[0])
    with av.open(str(path), "w") as c:
        options = {"crf": "10"} if gop is None else {"crf": "10", "g": str(gop)}
        v = c.add_stream("libx264", rate=rate, options=options)
        v.width, v.height, v.pix_fmt = w, h, pix_fmt
        tb = Fraction(1, 1000) if times is not None else 1 / Fraction(rate)
        v.time_base = v.codec_context.time_base = tb
        audio = audio and times is None
        a = None
        if audio:
            a = c.add_stream(audio_codec, rate=48000)
            a.layout = "mono"
        for k in range(frames):
            img = np.roll(base, -4 * k, axis=1)
            if stereo == "left-right":  # each eye turns on its own
                img = np.concatenate([np.roll(e, -4 * k, axis=1) for e in np.split(base, 2, 1)], 1)
            if (w, h) != (W, H):
                img = np.ascontiguousarray(np.resize(img, (h, w, 3)))
            f = av.VideoFrame.from_ndarray(np.ascontiguousarray(img), format="rgb24")
            f.pts = k if times is None else round(times[k] / tb)
            f.time_base = tb
            c.mux(v.encode(f))
        c.mux(v.encode(None))
        if a is not None:
            n = int(48000 * frames // Fraction(rate))
            t = np.arange(n) / 48000
            tone = (0.3 * np.sin(2 * np.pi * 440 * t)).astype(np.float32)[None, :]
            for i in range(0, n, 1024):
                af = av.AudioFrame.from_ndarray(tone[:, i : i + 1024], format="fltp", layout="mono")
                af.sample_rate = 48000
                af.pts = i
                af.time_base = Fraction(1, 48000)
                c.mux(a.encode(af))
            c.mux(a.encode(None))
    if stereo is not None:
        from spherewarp.io.spherical import Spherical, write_spherical

        write_spherical(path, Spherical(stereo=stereo))
    return path


def ffprobe_side_data(path: Path) -> dict:
    """The first video stream's side data as ffprobe (an independent parser) reads it, by type."""
    import json
    import shutil
    import subprocess

    text = subprocess.run(
        [shutil.which("ffprobe") or "ffprobe", "-v", "error", "-select_streams", "v:0"]
        + ["-show_streams", "-show_entries", "stream_side_data", "-of", "json", str(path)],
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    sides = json.loads(text)["streams"][0].get("side_data_list", [])
    return {d["side_data_type"]: d for d in sides}
