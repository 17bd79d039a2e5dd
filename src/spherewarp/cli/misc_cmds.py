"""``spherewarp testpattern``, ``info`` and ``demo``."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import click

from ._common import SIZE, example, max_pixels_option

__all__ = ["testpattern", "info", "demo"]


_UINT8_ONLY = (".jpg", ".jpeg", ".webp")


@click.command(
    epilog=example(
        "spherewarp testpattern -o pattern.png",
        "spherewarp testpattern -o pattern.exr --size 4096x2048 --chart front --dtype float32",
    )
)
@click.option(
    "-o",
    "--output",
    type=click.Path(dir_okay=False, path_type=Path),
    default=Path("testpattern.png"),
    show_default=True,
    help="Output file; its extension picks the format.",
)
@click.option("--overwrite", is_flag=True, help="Replace an existing output file.")
@click.option(
    "--size", type=SIZE, default="1024x512", show_default=True, help="Output size WxH (any size)."
)
@click.option(
    "--chart",
    type=click.Choice(["zenith", "front"], case_sensitive=False),
    default="zenith",
    show_default=True,
    help="Where the marked points 0, 1, i, -1, -i, inf lie: zenith = the library's default "
    "chart (0 at the zenith, -1 at the front, 1 at the back, i at lon -90); front = 0 at "
    "the front, 1 at lon +90, i at the zenith, inf at the back.",
)
@click.option(
    "--dtype",
    type=click.Choice(["uint8", "uint16", "float32"], case_sensitive=False),
    default="uint8",
    show_default=True,
    help="Sample type (uint16: PNG/TIFF; float32: EXR/TIFF).",
)
@click.option("--no-labels", is_flag=True, help="Leave out the text labels.")
@click.option(
    "--quality",
    type=click.IntRange(1, 100),
    default=95,
    show_default=True,
    help="JPEG/WebP quality.",
)
def testpattern(
    output: Path,
    overwrite: bool,
    size: tuple[int, int],
    chart: str,
    dtype: str,
    no_labels: bool,
    quality: int,
) -> None:
    """Write the paper's test pattern: a latitude/longitude grid with a blue equator,
    a red meridian through the front and back, and the points 0, 1, i, -1, -i, inf.
    """
    from ..errors import InvalidValueError, OutputExistsError
    from ..io import write_image
    from ..testpattern import make_test_pattern
    from ._common import check_size_limit
    from ._files import job
    from .mobius_cmds import check_output_suffix

    check_size_limit(size, None, option=False)  # what spherewarp writes, it can read back
    job().writes(output, "-o")
    if output.exists() and not overwrite:
        raise OutputExistsError(f"'{output}' exists; pass --overwrite to replace it")
    check_output_suffix(output)
    kind = output.suffix.lower()
    dtype = dtype.lower()
    if dtype != "uint8" and kind in _UINT8_ONLY or dtype == "float32" and kind == ".png":
        raise InvalidValueError(
            f"{output.suffix} cannot store {dtype} samples; use --dtype uint8"
            + (", or write .png or .tif" if dtype == "uint16" else ", or write .exr or .tif")
        )
    w, h = size
    if w < 8 or h < 4:
        raise InvalidValueError(f"--size: expected at least 8x4, got {w}x{h}")
    pixels = make_test_pattern(w, h, chart=chart.lower(), dtype=dtype, labels=not no_labels)
    written = write_image(output, pixels, gpano=True, quality=quality, overwrite=overwrite)
    click.echo(f"wrote {written}")


def _describe_icc(icc: bytes) -> str | None:
    try:
        import io

        from PIL import ImageCms

        profile = ImageCms.ImageCmsProfile(io.BytesIO(icc))
        return ImageCms.getProfileDescription(profile).strip() or None
    except Exception:  # any unreadable profile: just its size is reported
        return None


_CHANNEL_NAMES = {1: "Y", 2: "YA", 3: "RGB", 4: "RGBA"}


def image_info(path: Path, max_pixels: int | None = None) -> dict[str, Any]:
    """What ``spherewarp info`` reports about an image file, as a JSON-ready dict."""
    import numpy as np

    from ..io import read_image

    kwargs = {} if max_pixels is None else {"max_pixels": max_pixels}
    data = read_image(path, full_sphere=False, **kwargs)
    px = data.pixels
    h, w, c = px.shape
    names = _CHANNEL_NAMES[c]
    ranges = {}
    for k, name in enumerate(names):
        ch = px[..., k]
        if ch.dtype.kind == "f":
            finite = ch[np.isfinite(ch)]
            lo, hi = (float(finite.min()), float(finite.max())) if finite.size else (None, None)
            entry: dict[str, Any] = {"min": lo, "max": hi}
            bad = int(ch.size - finite.size)
            if bad:
                entry["non_finite"] = bad
        else:
            entry = {"min": int(ch.min()), "max": int(ch.max())}
        ranges[name] = entry
    g = data.gpano
    gpano = None
    placed = _placed_size(g, h, w)
    if g is not None:
        gpano = {
            "projection": g.projection_type,
            "full_size": [g.full_width, g.full_height],
            "cropped_size": [g.cropped_width, g.cropped_height],
            "cropped_left_top": [g.cropped_left, g.cropped_top],
            "cropped": bool(g.is_cropped),
            "pose_degrees": None
            if not g.has_pose
            else {"heading": g.pose_heading, "pitch": g.pose_pitch, "roll": g.pose_roll},
        }
    return {
        "path": str(path),
        "format": data.format,
        "width": w,
        "height": h,
        "dtype": str(px.dtype),
        "channels": c,
        "channel_names": names,
        "equirectangular_2to1": w == 2 * h,
        "full_sphere_size": None if placed is None else list(placed),
        "gpano": gpano,
        "icc_profile": None
        if data.icc_profile is None
        else {"bytes": len(data.icc_profile), "description": _describe_icc(data.icc_profile)},
        "exif": None if data.exif is None else {"bytes": len(data.exif)},
        "value_range": ranges,
    }


def _placed_size(gpano: Any, height: int, width: int) -> tuple[int, int] | None:
    """(W, H) of the full sphere that commands place a GPano-cropped file on, or None.

    None when the file is read as stored: no GPano, not equirectangular, not
    cropped, or a GPano that does not fit the image (read_image warns then).
    """
    from ..errors import InvalidValueError
    from ..io.images import _scaled_placement

    if gpano is None or gpano.projection_type.lower() != "equirectangular":
        return None
    if not gpano.is_cropped and (gpano.cropped_width, gpano.cropped_height) == (width, height):
        return None
    try:
        fw, fh, _, _ = _scaled_placement(gpano, height, width)
    except InvalidValueError:
        return None
    return fw, fh


def _ratio(w: int, h: int) -> str:
    """w / h with the digits that tell it from 2: 1025x512 is 2.002, not 2 (as 3 digits say).

    Examples
    --------
    >>> _ratio(1025, 512), _ratio(1000, 400), _ratio(200001, 100000)
    ('2.002', '2.5', '2.00001')
    """
    for digits in range(3, 17):
        text = f"{w / h:.{digits}g}"
        if float(text) != 2.0:
            return text
    return text  # pragma: no cover - w / h is 2 only for a 2:1 size


def _format_info(info: dict[str, Any]) -> str:
    def num(v: Any) -> str:
        return "n/a" if v is None else f"{v:g}" if isinstance(v, float) else str(v)

    w, h = info["width"], info["height"]
    placed = info.get("full_sphere_size")
    if placed is not None:
        fw, fh = placed
        shape = f"a crop of a {fw}x{fh} sphere, by its GPano; commands read it placed on it"
        if fw != 2 * fh:
            shape += f", not 2:1 (ratio {_ratio(fw, fh)}): they need --force"
    elif info["equirectangular_2to1"]:
        shape = "2:1, a full equirectangular sphere"
    else:
        shape = f"not 2:1 (ratio {_ratio(w, h)}); commands need --force"
    g = info["gpano"]
    if g is None:
        gp = "none"
    else:
        fw, fh = g["full_size"]
        cw, ch = g["cropped_size"]
        left, top = g["cropped_left_top"]
        gp = f"{g['projection']}, full {fw}x{fh}"
        gp += f", cropped {cw}x{ch} at {left},{top}" if g["cropped"] else " (not cropped)"
        pose = g.get("pose_degrees")
        if pose:
            gp += ", pose " + ", ".join(f"{k} {v:g}°" for k, v in pose.items() if v is not None)
    icc = info["icc_profile"]
    icc_s = "none" if icc is None else f"{icc['bytes']} bytes"
    if icc and icc["description"]:
        icc_s += f" ({icc['description']})"
    exif = info["exif"]
    ranges = ", ".join(
        f"{name} {num(r['min'])}..{num(r['max'])}"
        + (f" ({r['non_finite']} non-finite)" if r.get("non_finite") else "")
        for name, r in info["value_range"].items()
    )
    rows = [
        ("file", info["path"]),
        ("format", info["format"]),
        ("size", f"{w}x{h} ({shape})"),
        ("samples", f"{info['dtype']}, {info['channels']} channel(s) {info['channel_names']}"),
        ("values", ranges),
        ("GPano", gp),
        ("ICC profile", icc_s),
        ("EXIF", "none" if exif is None else f"{exif['bytes']} bytes"),
    ]
    return "\n".join(f"{k + ':':<13}{v}" for k, v in rows)


@click.command(epilog=example("spherewarp info room.jpg", "spherewarp info room.exr --json"))
@click.argument("input", type=click.Path(path_type=Path), metavar="INPUT")  # a folder: read_image
@click.option("--json", "as_json", is_flag=True, help="Print the information as JSON.")
@max_pixels_option
def info(input: Path, as_json: bool, max_pixels: int | None) -> None:
    """Describe an image: size, sample type, channels, 360° metadata, colour profile."""
    data = image_info(input, max_pixels)
    click.echo(json.dumps(data, indent=2) if as_json else _format_info(data))


@click.command(
    epilog=example(
        "spherewarp demo",
        "spherewarp demo my-demo --size 2048x1024 --overwrite",
    )
)
@click.argument(
    "directory",
    type=click.Path(file_okay=False, path_type=Path),
    default=Path("spherewarp-demo"),
    metavar="[DIR]",
)
@click.option("--overwrite", is_flag=True, help="Replace the demo's files if they exist.")
@click.option("--size", type=SIZE, help="Output size WxH (default: the sample's, 1024x512).")
@click.option(
    "--supersample",
    type=click.IntRange(1, 16),
    default=2,
    show_default=True,
    help="Average NxN samples per output pixel (anti-aliasing).",
)
def demo(directory: Path, overwrite: bool, size: tuple[int, int] | None, supersample: int) -> None:
    """Run a few effects on the bundled sample panorama and write them into DIR
    (default ./spherewarp-demo).
    """
    from ..demo import run_demo
    from ._common import check_size_limit

    check_size_limit(size, None, option=False)
    if size is not None and (size[0] < 8 or size[1] < 4):  # the smallest test pattern
        raise click.BadParameter(
            f"expected a size of at least 8x4, got {size[0]}x{size[1]}", param_hint="'--size'"
        )

    # run_demo removes a folder it made and wrote nothing into (a full disk)
    run_demo(directory, overwrite=overwrite, size=size, supersample=supersample, echo=click.echo)
