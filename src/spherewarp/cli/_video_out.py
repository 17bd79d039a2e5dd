"""``spherewarp animate R.json STILL -o OUT.mp4``: the frames of a recipe encoded as a video.

The encoder options are ``spherewarp video``'s (``--codec``, ``--crf``,
``--preset``, ``--pix-fmt``; :func:`spherewarp.io.videowriter.video_writer`);
an equirectangular output carries the spherical metadata (V1 and V2, or
Matroska's), another view none.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import click

__all__ = ["encoding_options", "is_video_output", "animate_video"]


def encoding_options(func: Callable) -> Callable:
    """``--codec``, ``--crf``, ``--preset``, ``--pix-fmt`` (for a video output)."""
    options = [
        click.option(
            "--codec",
            help="With a video -o: the video encoder (default libx264; libvpx-vp9 for .webm): "
            "libx264, libx265, libvpx-vp9, libsvtav1, or another this build offers.",
        ),
        click.option(
            "--crf",
            type=click.FloatRange(0, 63),
            help="With a video -o: constant rate factor, lower is better and bigger "
            "(default: 18 for x264, 20 for x265, 31 for VP9).",
        ),
        click.option(
            "--preset", help="With a video -o: the encoder's speed preset (ultrafast ... veryslow)."
        ),
        click.option(
            "--pix-fmt",
            help="With a video -o: the encoded pixel format (default: yuv420p; 10-bit "
            "yuv420p10le for a 16-bit or HDR still when the encoder takes it).",
        ),
    ]
    for option in reversed(options):
        func = option(func)
    return func


def is_video_output(output: Path | None) -> bool:
    """Whether ``-o`` names a video file (by its extension)."""
    from ..io.video import VIDEO_EXTENSIONS

    return output is not None and output.suffix.lower() in VIDEO_EXTENSIONS


def animate_video(
    src: Any,
    render: Any,
    recipe: Any,
    times: list[float],
    fps: float,
    encoding: dict[str, Any],
    render_frame: Callable[[Any, Any, Any], Any],
) -> int:
    """Render ``recipe`` at ``times`` on the still ``src`` and encode the frames into
    ``render.output`` at ``fps`` (``encoding``: codec, crf, preset, pix_fmt); return the frames
    written. ``render_frame(src, frame, render)`` gives one frame's pixels."""
    import numpy as np

    from ..io.videowriter import EQUIRECT, frame_rate, video_writer

    output = render.output
    first = render_frame(src, recipe.at(times[0]), render)
    deep = first.dtype != np.uint8
    panorama = render.projection in (None, "equirect")
    with video_writer(
        output,
        first.shape[:2],
        frame_rate(fps),
        in_pix="yuv420p10le" if deep else "yuv420p",
        overwrite=render.overwrite,
        spherical=EQUIRECT if panorama else None,
        **encoding,
    ) as writer:
        writer.write(first)
        for t in times[1:]:
            writer.write(render_frame(src, recipe.at(t), render))
    click.echo(f"wrote {output} ({len(times)} frames at {fps:g} fps)")
    return len(times)
