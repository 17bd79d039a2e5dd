"""The demo: a few effects on the bundled sample panorama, written into a folder.

``spherewarp demo [DIR]`` (or :func:`run_demo`) renders every effect of
:data:`DEMO_EFFECTS` and writes each as ``NN-name.png`` into ``DIR``. The
effects are plain data, a name, a description and a function of
:class:`DemoInputs` returning an image, so later effects are added with
``DEMO_EFFECTS.append(DemoEffect(...))``.

Running the demo again replaces the files it wrote before: it records them,
with a digest of their contents, in ``DIR/.spherewarp-demo.json``
(:data:`MANIFEST`). Any other file in ``DIR`` is left alone; one that has a
demo file's name but that the demo did not write (or that was changed since)
is an error unless ``overwrite`` (``--overwrite``) is given.

The sample is ``interior.png`` (a hotel room, CC0, see ``data/LICENSE.md``);
the framed picture on its wall is at :data:`PICTURE`.

Examples
--------
>>> import tempfile
>>> from spherewarp.demo import run_demo
>>> paths = run_demo(tempfile.mkdtemp(), size=(128, 64), echo=None)
>>> [p.name for p in paths][:3]
['01-original.png', '02-testpattern.png', '03-rotate-view.png']
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from importlib.resources import files
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .errors import ImageFormatError, InvalidValueError, OutputExistsError
from .maps import Mobius, SphereMap

__all__ = [
    "DEMO_EFFECTS",
    "PICTURE",
    "DemoEffect",
    "DemoInputs",
    "MANIFEST",
    "run_demo",
    "sample_path",
]

#: file in the demo's folder listing what it wrote (name -> sha256 of the contents)
MANIFEST = ".spherewarp-demo.json"

#: LON,LAT (degrees) of the framed picture on the wall of the sample ``interior.png``.
PICTURE: tuple[float, float] = (-163.0, 5.0)
#: the TV and the window of the sample
_TV = (-65.0, 2.0)
_WINDOW = (38.0, 2.0)


def sample_path(name: str = "interior.png") -> Path:
    """Path of a bundled sample panorama (``interior.png``, ``courtyard.png``, ...).

    Examples
    --------
    >>> sample_path().name
    'interior.png'
    """
    path = files("spherewarp") / "data" / name
    if not path.is_file():
        raise InvalidValueError(f"no bundled sample named {name!r}")
    return Path(str(path))


@dataclass(frozen=True)
class DemoInputs:
    """What a demo effect gets: the sample, the test pattern and the render settings.

    Attributes
    ----------
    sample : ndarray (H, W, 3) uint8
        The bundled ``interior.png``.
    pattern : ndarray (H, W, 3) uint8
        The test pattern (:func:`spherewarp.testpattern.make_test_pattern`), same size.
    output_shape : (height, width)
        Size of the images to produce.
    supersample : int
        Anti-aliasing for :meth:`warp`.
    """

    sample: NDArray[np.uint8]
    pattern: NDArray[np.uint8]
    output_shape: tuple[int, int]
    supersample: int = 2

    def warp(self, image: NDArray, inverse_map: SphereMap, **kwargs: Any) -> NDArray:
        """:func:`spherewarp.render.warp` at the demo's size and supersampling."""
        from .render import warp

        kwargs.setdefault("output_shape", self.output_shape)
        kwargs.setdefault("supersample", self.supersample)
        return warp(image, inverse_map, **kwargs)

    def resize(self, image: NDArray) -> NDArray:
        """``image`` at the output size (an identity warp)."""
        if image.shape[:2] == self.output_shape:
            return image
        return self.warp(image, Mobius.identity())


@dataclass(frozen=True)
class DemoEffect:
    """One image of the demo.

    Attributes
    ----------
    name : str
        File stem (``NN-name.png``); lower case letters, digits and ``-``.
    description : str
        One line for the listing.
    render : callable
        ``render(inputs: DemoInputs) -> ndarray`` of shape ``inputs.output_shape``.
    equirectangular : bool
        Whether the image is a 360° equirectangular panorama (it then carries
        GPano metadata); False for a flat picture such as a Peirce square.
    """

    name: str
    description: str
    render: Callable[[DemoInputs], NDArray]
    equirectangular: bool = True


def _facing_picture() -> Mobius:
    """The view turned (yaw) to face the framed picture: pull back by it."""
    return Mobius.from_yaw_pitch_roll(yaw=PICTURE[0])


def _zoom_picture() -> SphereMap:
    """Pull-back of the zoom x3 toward the picture, seen facing it."""
    return Mobius.zoom(PICTURE, 3.0).inverse() @ _facing_picture()


DEMO_EFFECTS: list[DemoEffect] = [
    DemoEffect("original", "the bundled sample, interior.png (CC0)", lambda d: d.resize(d.sample)),
    DemoEffect(
        "testpattern",
        "the test pattern: 0 at the zenith, -1 at the front, 1 at the back, inf at the nadir",
        lambda d: d.pattern,
    ),
    DemoEffect(
        "rotate-view",
        "rotate --yaw 120 --pitch 20 --roll 10 (ffmpeg v360 yaw/pitch/roll)",
        lambda d: d.warp(d.sample, Mobius.from_yaw_pitch_roll(120.0, 20.0, 10.0)),
    ),
    DemoEffect(
        "rotate-picture",
        "rotate --axis -163,5 --angle 30 about the framed picture (view turned to face it)",
        lambda d: d.warp(d.sample, Mobius.rotation(PICTURE, 30.0).inverse() @ _facing_picture()),
    ),
    DemoEffect(
        "zoom-picture",
        "zoom --at -163,5 --factor 3 toward the framed picture (view turned to face it)",
        lambda d: d.warp(d.sample, _zoom_picture()),
    ),
    DemoEffect(
        "mobius-3points",
        "mobius --from -163,5 -65,2 38,2 --to -100,0 -40,-10 100,10: "
        "picture, TV and window moved by one Möbius map",
        lambda d: d.warp(
            d.sample,
            Mobius.from_points(
                [PICTURE, _TV, _WINDOW], [(-100, 0), (-40, -10), (100, 10)]
            ).inverse(),
        ),
    ),
    DemoEffect(
        "testpattern-zoom",
        "the test pattern through the same zoom x3 (magnified 3x there, shrunk 3x opposite)",
        lambda d: d.warp(d.pattern, _zoom_picture()),
    ),
    DemoEffect(
        "power-2",
        "power --n 2: two copies around branch points on the ceiling and the floor",
        lambda d: d.warp(d.sample, _power2()),
    ),
    DemoEffect(
        "power-2-branch-point",
        "power --n 2 --look-at 0,90: the order-2 branch point on the ceiling, at the centre",
        lambda d: d.warp(d.sample, _power2() @ Mobius.from_yaw_pitch_roll(0.0, 90.0)),
    ),
    DemoEffect(
        "exp",
        "exp --lam 4: infinitely many copies side by side, meeting at the back",
        lambda d: d.warp(d.sample, _exp4(), supersample=max(3, d.supersample)),
    ),
    DemoEffect(
        "droste",
        "droste --center -163,5 --frame -173,23.6 -153.8,24.5 -153.8,-14.8 -173,-14.2: "
        "the room inside its own picture, a flower-shaped portal opposite (view facing it)",
        lambda d: _droste(d, twist=False),
    ),
    DemoEffect(
        "droste-twisted",
        "the same with --twist --scale 8 (De Smit-Lenstra, Escher's Print Gallery)",
        lambda d: _droste(d, twist=True),
    ),
    DemoEffect(
        "lattes-square",
        "lattes --alpha 2+1j: the paper's rational map z((-1+2i)+z^2)^2/(-i+(2+i)z^2)^2",
        lambda d: d.warp(d.sample, _lattes("2+1j", "square")),
    ),
    DemoEffect(
        "lattes-hex",
        "lattes --lattice hex --alpha 1+w: the paper's (z^3+sqrt 2)/(3 w z^2)",
        lambda d: d.warp(d.sample, _lattes("1+w", "hex")),
    ),
    DemoEffect(
        "peirce-torus",
        "peirce (the whole sphere in a square) beside torus (the square torus cell: two copies)",
        lambda d: _peirce_and_torus(d),
        equirectangular=False,
    ),
]

#: corners (LON,LAT) of the canvas on the wall of interior.png, read off the image
PICTURE_FRAME = ((-173.0, 23.6), (-153.8, 24.5), (-153.8, -14.8), (-173.0, -14.2))


def _droste(d: DemoInputs, twist: bool) -> NDArray:
    from .effects.droste import droste_map, hole_from_corners

    hole = hole_from_corners(PICTURE_FRAME, PICTURE)
    droste = droste_map(hole, 8.0 if twist else None, twist=twist)
    return d.warp(d.sample, droste @ _facing_picture())


def _power2() -> SphereMap:
    from .maps.branched import Power

    return Power(2)


def _exp4() -> SphereMap:
    from .maps.branched import ExpMap

    return ExpMap(4.0)


def _lattes(alpha: str, lattice: str) -> SphereMap:
    from .maps.elliptic import Lattes

    return Lattes(alpha, lattice)


def _peirce_and_torus(d: DemoInputs) -> NDArray:
    from .effects.torus import render_torus
    from .grids.peirce import render_peirce

    h, w = d.output_shape
    side = min(h, w // 2)
    canvas = np.zeros((h, w, 3), np.uint8)
    canvas[:side, :side] = render_peirce(d.sample, side, supersample=d.supersample)
    canvas[:side, side : 2 * side] = render_torus(d.sample, width=side, supersample=d.supersample)
    return canvas


def run_demo(
    directory: str | Path = "spherewarp-demo",
    *,
    overwrite: bool = False,
    size: tuple[int, int] | None = None,
    supersample: int = 2,
    effects: Sequence[DemoEffect] | None = None,
    echo: Callable[[str], Any] | None = print,
) -> list[Path]:
    """Render the demo effects on the bundled sample and write them into ``directory``.

    Parameters
    ----------
    directory : str or Path
        Created if missing (with its parents).
    overwrite : bool
        Replace any existing file with a demo file's name. Without it the
        files that an earlier run wrote (listed in :data:`MANIFEST`, contents
        unchanged) are replaced and any other existing file of those names is
        an error, raised before anything is written. Other files in
        ``directory`` are never touched.
    size : (width, height), optional
        Output size; default the sample's (1024x512).
    supersample : int
        Anti-aliasing of the warps (N x N samples per pixel).
    effects : sequence of DemoEffect, optional
        Default :data:`DEMO_EFFECTS`.
    echo : callable or None
        Called with one line per file written and a summary; None is silent.

    Returns
    -------
    list of Path
        The files written, in order.

    Raises
    ------
    OutputExistsError
        If a file with a demo file's name exists that the demo did not write,
        and ``overwrite`` is false (nothing is written).
    """
    from .io import read_image
    from .testpattern import make_test_pattern

    start = time.perf_counter()
    effects = list(DEMO_EFFECTS if effects is None else effects)
    out_dir = Path(directory)
    if out_dir.exists() and not out_dir.is_dir():
        raise InvalidValueError(f"'{out_dir}' exists and is not a directory")
    targets = [out_dir / f"{k:02d}-{e.name}.png" for k, e in enumerate(effects, start=1)]
    manifest = _read_manifest(out_dir)
    if not overwrite:
        existing = [p for p in targets if p.exists() and not _is_ours(p, manifest)]
        if _foreign_manifest(out_dir):  # a file of the user's by the manifest's name
            existing.insert(0, out_dir / MANIFEST)
        if existing:
            more = f" (and {len(existing) - 1} more)" if len(existing) > 1 else ""
            what = f"'{existing[0]}' exists{more} and is not a file the demo wrote; pass"
            raise OutputExistsError(
                f"{what} overwrite=True to replace it, or choose another directory",
                cli=f"{what} --overwrite to replace it, or choose another directory",
            )

    src = read_image(sample_path())
    h, w = src.pixels.shape[:2]
    if size is not None:
        w, h = (int(v) for v in size)
    inputs = DemoInputs(
        sample=src.pixels,
        pattern=make_test_pattern(w, h),
        output_shape=(h, w),
        supersample=supersample,
    )
    made = not out_dir.exists()
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
    except OSError as exc:  # a read-only place, a file on the way
        where = out_dir.resolve().parent
        raise ImageFormatError(
            f"cannot make the folder '{out_dir}' (in '{where}'): {exc.strerror or exc}"
        ) from None
    written: list[Path] = []
    try:
        _write_all(targets, effects, inputs, src, out_dir, manifest, written, echo)
    except BaseException:
        if made and not written:  # a folder it made for nothing (a full disk...): gone
            with contextlib.suppress(OSError):
                (out_dir / MANIFEST).unlink(missing_ok=True)
                out_dir.rmdir()
        raise
    if echo is not None:
        echo(
            f"{len(written)} images in {out_dir}/ in {time.perf_counter() - start:.1f} s "
            "(open them in any 360° viewer; the panoramas carry GPano metadata)"
        )
    return written


def _write_all(
    targets: list[Path],
    effects: list[DemoEffect],
    inputs: DemoInputs,
    src: Any,
    out_dir: Path,
    manifest: dict[str, str],
    written: list[Path],
    echo: Callable[[str], None] | None,
) -> None:
    """Render and write each effect to its target, recording it in the manifest and in
    ``written`` as it goes."""
    from .io import write_image

    for target, effect in zip(targets, effects, strict=True):
        pixels = effect.render(inputs)
        write_image(
            target,
            pixels,
            icc_profile=src.icc_profile,
            exif=src.exif,
            gpano=effect.equirectangular,
            overwrite=True,  # checked above: absent, ours, or overwrite
        )
        manifest[target.name] = _digest(target)
        _write_manifest(out_dir, manifest)
        written.append(target)
        if echo is not None:
            echo(f"wrote {target}  ({effect.description})")


def _digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _read_manifest(directory: Path) -> dict[str, str]:
    """name -> sha256 of the files an earlier run wrote into ``directory`` ({} if none)."""
    try:
        data = json.loads((directory / MANIFEST).read_text(encoding="utf-8"))
        files = data["files"]
    except (OSError, ValueError, KeyError, TypeError):
        return {}
    if not isinstance(files, dict):
        return {}
    return {str(k): str(v) for k, v in files.items()}


def _foreign_manifest(directory: Path) -> bool:
    """True if ``directory`` holds a file by the manifest's name that the demo did not
    write (not its JSON, ``"written_by": "spherewarp demo"``)."""
    path = directory / MANIFEST
    if not os.path.lexists(path):
        return False
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return True
    return not (isinstance(data, dict) and data.get("written_by") == "spherewarp demo")


def _is_ours(path: Path, manifest: dict[str, str]) -> bool:
    """True if the demo wrote ``path`` and it has not changed since."""
    want = manifest.get(path.name)
    return want is not None and path.is_file() and _digest(path) == want


def _write_manifest(directory: Path, manifest: dict[str, str]) -> None:
    path = directory / MANIFEST
    tmp = path.with_name(f"{path.name}.{os.getpid()}.tmp")
    text = json.dumps({"written_by": "spherewarp demo", "files": manifest}, indent=1)
    tmp.write_text(text + "\n", encoding="utf-8")
    os.replace(tmp, path)
