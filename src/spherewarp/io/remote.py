"""Inputs and outputs named by fsspec URLs (``ftp://host:2121/in.mp4``, ``s3://...``).

A segmented render (:mod:`spherewarp.io.segments`) whose input or output is a URL reads
and writes through `fsspec <https://filesystem-spec.readthedocs.io>`_ (installed with
``pip install "spherewarp[dask]"``), on the client and on every worker alike:

* an input is opened as a file object that PyAV reads (seeking as it needs); a still
  (``animate``'s) is downloaded to a local temporary file and read from it (:func:`local_copy`);
* a file is written to a local temporary file, uploaded under a temporary name beside
  its destination, then moved into place (:func:`put_atomic`): a half-written segment or
  output is never found by its name;
* a local path is a local path: these functions are only called for URLs.

Examples
--------
>>> is_url("ftp://127.0.0.1:2121/in.mp4"), is_url("in.mp4"), is_url("C:/clips/in.mp4")
(True, False, False)
>>> child("ftp://host/out/tour.mp4.parts", "seg-00001.mp4")
'ftp://host/out/tour.mp4.parts/seg-00001.mp4'
"""

from __future__ import annotations

import contextlib
import os
import re
import secrets
import shutil
import tempfile
from collections.abc import Iterator
from typing import Any

from ..errors import InvalidValueError

__all__ = [
    "FSSPEC_INSTALL",
    "child",
    "exists",
    "filesystem",
    "identity",
    "is_url",
    "local_copy",
    "open_input",
    "put_atomic",
    "read_text",
    "reachable",
    "names",
    "remove_tree",
    "size",
]

#: the one line said when a URL is given and fsspec is missing
FSSPEC_INSTALL = 'install fsspec to read and write URLs: pip install "spherewarp[dask]"'

_SCHEME = re.compile(r"^[A-Za-z][A-Za-z0-9+.-]+://")


def is_url(path: Any) -> bool:
    """Whether ``path`` is a URL (``scheme://...``; ``file://`` too), not a local path."""
    return isinstance(path, str) and _SCHEME.match(path) is not None


def child(url: str, name: str) -> str:
    """The URL of ``name`` inside the folder ``url``."""
    return url.rstrip("/") + "/" + name


def filesystem(url: str, fresh: bool = False) -> tuple[Any, str]:
    """``(fsspec filesystem, path in it)`` of ``url`` (``fresh``: a connection of its own, for
    a worker's task; one line saying how to install fsspec when it is missing)."""
    try:
        from fsspec.core import url_to_fs
    except ImportError:
        raise InvalidValueError(f"{url}: {FSSPEC_INSTALL}") from None
    try:
        return url_to_fs(url, skip_instance_cache=fresh)
    except (ImportError, ValueError) as exc:
        raise InvalidValueError(f"{url}: no file system for this URL ({exc})") from None
    except OSError as exc:  # the server refused or cannot be found
        raise InvalidValueError(f"cannot reach '{url}': {exc.strerror or exc}") from None


def exists(url: str) -> bool:
    """Whether ``url`` names an existing file or folder."""
    fs, path = filesystem(url)
    fs.invalidate_cache()
    return bool(fs.exists(path))


def size(url: str) -> int | None:
    """The size of the file ``url`` in bytes, or None when there is none."""
    fs, path = filesystem(url)
    fs.invalidate_cache()
    try:
        info = fs.info(path)
    except (FileNotFoundError, OSError):
        return None
    return int(info["size"]) if info.get("type") == "file" else None


def identity(url: str) -> dict[str, Any]:
    """What tells one version of the file ``url`` from another: its URL, size and modification
    time where the file system gives one."""
    fs, path = filesystem(url)
    fs.invalidate_cache()
    info = fs.info(path)
    when = next(
        (info[k] for k in ("mtime", "modify", "LastModified", "updated") if k in info), None
    )
    return {"path": url, "size": int(info["size"]), "mtime": None if when is None else str(when)}


def open_input(url: str) -> Any:
    """A binary file object reading ``url`` (for PyAV), on a connection of its own."""
    fs, path = filesystem(url, fresh=True)
    return fs.open(path, "rb")


@contextlib.contextmanager
def local_copy(url: str) -> Iterator[str]:
    """Download the file ``url`` into a fresh local temporary folder, under its own name, and
    yield the local path (for a reader that wants a file, such as a still's); the copy is
    removed when the block ends. An error is one line naming ``url``."""
    fs, path = filesystem(url, fresh=True)
    folder = local_copy_dir()
    try:
        local = os.path.join(folder, path.rstrip("/").rsplit("/", 1)[-1] or "input")
        try:
            with fs.open(path, "rb") as src, open(local, "wb") as dst:
                shutil.copyfileobj(src, dst, 1 << 20)
        except FileNotFoundError:
            raise InvalidValueError(f"cannot read '{url}': no such file") from None
        except OSError as exc:
            raise InvalidValueError(f"cannot read '{url}': {exc.strerror or exc}") from None
        except Exception as exc:  # noqa: BLE001 - a file system's own error (ftplib's, ...)
            raise InvalidValueError(f"cannot read '{url}': {exc}") from None
        yield local
    finally:
        remove_local(folder)


def read_text(url: str) -> str:
    """The text of the file ``url``."""
    fs, path = filesystem(url)
    fs.invalidate_cache()
    with fs.open(path, "rb") as f:
        return f.read().decode("utf-8")


def put_atomic(local: str | os.PathLike[str], url: str, fresh: bool = False) -> None:
    """Upload the local file ``local`` to ``url`` under a temporary name beside it, then move it
    into place (replacing what is there): ``url`` is whole or as it was."""
    fs, path = filesystem(url, fresh=fresh)
    parent, name = path.rsplit("/", 1) if "/" in path else ("", path)
    tmp = f"{parent}/.{name}.spherewarp-{os.getpid()}-{secrets.token_hex(4)}.tmp"
    fs.put_file(os.fspath(local), tmp)
    try:
        fs.mv(tmp, path)
    except BaseException:
        try:
            fs.rm(tmp)
        except OSError:
            pass
        raise
    fs.invalidate_cache()


def write_atomic(url: str, data: bytes, fresh: bool = False) -> None:
    """Write ``data`` to ``url`` atomically (:func:`put_atomic`)."""
    with tempfile.TemporaryDirectory(prefix="spherewarp-") as d:
        local = os.path.join(d, "data")
        with open(local, "wb") as f:
            f.write(data)
        put_atomic(local, url, fresh=fresh)


def make_folder(url: str) -> None:
    """Create the folder ``url`` (and its parents) if it is not there."""
    fs, path = filesystem(url)
    fs.invalidate_cache()
    fs.makedirs(path, exist_ok=True)


def names(url: str) -> list[str] | None:
    """The names of what the folder ``url`` holds, or None when nothing is there.

    Raises
    ------
    NotADirectoryError
        When ``url`` names a file.
    """
    fs, path = filesystem(url)
    fs.invalidate_cache()
    if not fs.exists(path):
        return None
    if not fs.isdir(path):
        raise NotADirectoryError(20, "Not a directory", url)
    return [str(p).rstrip("/").rsplit("/", 1)[-1] for p in fs.ls(path, detail=False)]


def remove_tree(url: str) -> None:
    """Remove the folder ``url`` and what it holds, if it is there."""
    fs, path = filesystem(url)
    fs.invalidate_cache()
    if fs.exists(path):
        fs.rm(path, recursive=True)
    fs.invalidate_cache()


def reachable(read: list[str], write: list[str]) -> list[str]:
    """The URLs of ``read`` that cannot be read and the folders of ``write`` that cannot be
    written (a small file is written there and removed), from this process: what
    :func:`spherewarp.io.segments.check_workers` runs on each worker."""
    bad = []
    for url in read:
        try:
            fs, path = filesystem(url, fresh=True)
            with fs.open(path, "rb") as f:
                f.read(1)
        except Exception:  # noqa: BLE001 - any failure means the worker cannot read it
            bad.append(url)
    for url in write:
        probe = child(url, f".spherewarp-probe-{secrets.token_hex(4)}")
        try:
            fs, path = filesystem(probe, fresh=True)
            fs.pipe_file(path, b"")
            fs.rm(path)
        except Exception:  # noqa: BLE001 - any failure means the worker cannot write there
            bad.append(url)
    return bad


def local_copy_dir() -> str:
    """A fresh local temporary folder (for a file on its way to a URL)."""
    return tempfile.mkdtemp(prefix="spherewarp-")


def remove_local(folder: str) -> None:
    shutil.rmtree(folder, ignore_errors=True)
