"""Shared fixtures: sample panoramas and small synthetic test images.

The directory of this file is on ``sys.path`` (pytest's default prepend
import mode), so test modules anywhere under ``tests/`` can
``import tolerances``. Helpers are handed out as fixtures (factories), never
imported from this module.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from shared_data import SHARED_PANORAMAS

PACKAGE_DATA = Path(__file__).resolve().parents[1] / "src" / "spherewarp" / "data"


def pytest_configure(config: pytest.Config) -> None:
    """Byte-compile the package once, so that each fresh ``spherewarp`` process reads it.

    Where ``PYTHONDONTWRITEBYTECODE`` is set (it is on these machines) an editable
    install is never byte-compiled, and every one of the suite's thousand or so
    command-line processes would compile the package's modules from source again
    (a tenth of a second or more each). Python still reads byte code that exists.
    """
    import compileall

    import spherewarp

    compileall.compile_dir(Path(spherewarp.__file__).parent, quiet=2, workers=1)


@functools.cache
def _read_rgb(path: str) -> np.ndarray:
    from PIL import Image

    with Image.open(path) as im:
        arr = np.asarray(im.convert("RGB"))
    arr = np.ascontiguousarray(arr)
    arr.flags.writeable = False
    return arr


def panorama_path(name: str) -> Path | None:
    """Where the sample panorama ``name`` (e.g. ``"city.png"``) is, or None."""
    for folder in (PACKAGE_DATA, SHARED_PANORAMAS):
        path = folder / name
        if path.exists():
            return path
    return None


def load_panorama(name: str) -> np.ndarray:
    """A sample panorama as a read-only (H, W, 3) uint8 array; skips the test if absent."""
    path = panorama_path(name)
    if path is None:
        pytest.skip(f"sample panorama {name} is not available")
    return _read_rgb(str(path))


@pytest.fixture(scope="session")
def panorama() -> Callable[[str], np.ndarray]:
    """Factory: ``panorama("courtyard.png")`` -> read-only (H, W, 3) uint8 (or skip)."""
    return load_panorama


@pytest.fixture(scope="session")
def interior() -> np.ndarray:
    """The package's 1024x512 interior panorama, read-only uint8 RGB."""
    return load_panorama("interior.png")


@pytest.fixture
def rng() -> np.random.Generator:
    """A fresh seeded generator per test."""
    return np.random.default_rng(20240229)


def _random_image(
    height: int = 64, channels: int = 3, dtype: type = np.uint8, seed: int = 0
) -> np.ndarray:
    """A random (height, 2*height, channels) image over the dtype's full range."""
    gen = np.random.default_rng(seed)
    shape = (height, 2 * height, channels)
    if np.dtype(dtype).kind == "u":
        return gen.integers(0, np.iinfo(dtype).max, shape, dtype=dtype, endpoint=True)
    return gen.random(shape).astype(dtype)


@pytest.fixture
def small_image() -> np.ndarray:
    """A random 128x64 RGB uint8 image."""
    return _random_image()


@pytest.fixture(scope="session")
def random_image() -> Callable[..., np.ndarray]:
    """Factory: ``random_image(height=64, channels=3, dtype=np.uint8, seed=0)``."""
    return _random_image


@pytest.fixture(scope="session")
def smooth_image() -> Callable[..., np.ndarray]:
    """Factory: ``smooth_image(height=64, dtype=np.float32)``, see :func:`_smooth_image`."""
    return _smooth_image


def _smooth_image(height: int = 64, dtype: type = np.float32) -> np.ndarray:
    """A (height, 2*height, 3) image whose value is ``0.5 + 0.5 * xyz`` at each pixel centre.

    A linear function of the unit vector: smooth everywhere on the sphere,
    including across the seam and over the poles.
    """
    from spherewarp import coords

    w = 2 * height
    y, x = np.mgrid[0:height, 0:w] + 0.5
    xyz = coords.xyz_from_lonlat(coords.lonlat_from_pixel(np.stack([x, y], -1), w, height))
    img = 0.5 + 0.5 * xyz
    if np.dtype(dtype).kind == "u":
        return np.rint(img * np.iinfo(dtype).max).astype(dtype)
    return img.astype(dtype)


@pytest.fixture
def workdir(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A temporary directory that is also the current directory (for CLI tests)."""
    monkeypatch.chdir(tmp_path)
    return tmp_path


@pytest.fixture(scope="session")
def ftp(tmp_path_factory):
    """A real FTP server on 127.0.0.1 (tests/ftpserver.py): a remote file system for URLs."""
    pytest.importorskip("fsspec")
    pytest.importorskip("pyftpdlib")
    from ftpserver import FTPServer

    server = FTPServer(tmp_path_factory.mktemp("ftp"))
    yield server
    server.close()
