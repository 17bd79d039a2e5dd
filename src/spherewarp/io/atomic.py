"""Atomic file writing: a whole new file or none, for images, meshes and the rest.

A file is written to a hidden temporary file beside its destination, named
``.NAME.spherewarp-PID-XXXXXXXX.tmpSUFFIX`` (``NAME`` the destination's name,
``PID`` the writing process, ``SUFFIX`` the destination's extension, so that
encoders that look at it see the right one), flushed to disk and then renamed
into place (or hard-linked, when an existing file must not be replaced). On
any failure, ``KeyboardInterrupt`` and SIGTERM included, the temporary file is
removed and an existing destination is left untouched.

A process killed outright (SIGKILL, a power cut) cannot clean up; the next
write to the same destination removes that destination's temporary files left
by processes that no longer run (nothing else: other names, other patterns,
and files of live processes are left alone).

Examples
--------
>>> import tempfile
>>> from pathlib import Path
>>> d = Path(tempfile.mkdtemp())
>>> with atomic_file(d / "notes.txt") as tmp:
...     _ = tmp.write_text("hello")
>>> (d / "notes.txt").read_text(), sorted(p.name for p in d.iterdir())
('hello', ['notes.txt'])
>>> write_text(d / "notes.txt", "again")  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
spherewarp.errors.OutputExistsError: '...notes.txt' exists; pass overwrite=True to replace it
"""

from __future__ import annotations

import contextlib
import os
import re
import secrets
from collections.abc import Iterator
from pathlib import Path

from .. import _signals
from ..errors import ImageFormatError, OutputExistsError

__all__ = [
    "atomic_file", "write_bytes", "write_text", "temp_name", "remove_stale", "remove_live",
    "check_writable", "unwritable_error",
]  # fmt: skip

#: temporary files of this process not yet renamed or removed
_LIVE: set[Path] = set()


def temp_name(path: Path, pid: int | None = None) -> str:
    """A fresh temporary file name for ``path`` (see the module documentation).

    Examples
    --------
    >>> temp_name(Path("out/pano.jpg"), pid=42)[:-16]
    '.pano.jpg.spherewarp-42-'
    >>> temp_name(Path("pano.jpg")).endswith(".tmp.jpg")
    True
    """
    pid = os.getpid() if pid is None else pid
    return f".{path.name[:100]}.spherewarp-{pid}-{secrets.token_hex(4)}.tmp{path.suffix}"


_TEMP = re.compile(r"\.(.+)\.spherewarp-(\d+)-[0-9a-f]{8}\.tmp(.*)")

#: directory -> {target name: temporary file names}, listed once per directory and process
#: (writing many frames into one directory must not list it once a frame)
_SCANNED: dict[str, dict[str, list[str]]] = {}


def _candidates(directory: Path) -> dict[str, list[str]]:
    key = os.path.realpath(directory)
    found = _SCANNED.get(key)
    if found is None:
        found = {}
        try:
            names = os.listdir(directory)
        except OSError:
            names = []
        for name in names:
            m = _TEMP.fullmatch(name)
            if m is not None:
                found.setdefault(m.group(1), []).append(name)
        _SCANNED[key] = found
    return found


def _alive(pid: int) -> bool:
    if pid == os.getpid():
        return False  # ours, yet not live: left by an earlier process with this pid
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError, OSError):
        return True  # someone else's process, or a pid we cannot ask about: keep its file
    return True


def remove_stale(path: Path) -> list[Path]:
    """Remove ``path``'s temporary files left by processes that no longer run; return them.

    Only files named as :func:`temp_name` names them for this very ``path``
    are considered; only on POSIX (elsewhere a pid cannot be asked about safely).
    """
    if os.name != "posix":
        return []
    path = Path(path)
    removed = []
    for name in _candidates(path.parent).pop(path.name[:100], []):
        m = _TEMP.fullmatch(name)
        stale = path.parent / name
        if m is None or m.group(3) != path.suffix or stale in _LIVE or _alive(int(m.group(2))):
            continue
        with contextlib.suppress(OSError):
            stale.unlink()
            removed.append(stale)
    return removed


def remove_live() -> None:
    """Remove every temporary file of this process that is still there (the CLI's last resort
    when it is interrupted)."""
    for tmp in list(_LIVE):
        with contextlib.suppress(OSError):
            tmp.unlink()
        _LIVE.discard(tmp)


def _make_temp(path: Path) -> Path:
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_BINARY", 0)
    for _ in range(100):
        tmp = path.parent / temp_name(path)
        # registered before it exists and left registered on an interrupt (which may come
        # just after the file is made): remove_live() then finds it
        _LIVE.add(tmp)
        try:
            fd = os.open(tmp, flags, 0o666)
        except FileExistsError:
            _LIVE.discard(tmp)
            continue
        except OSError as exc:
            _LIVE.discard(tmp)
            raise unwritable_error(path, exc) from exc
        os.close(fd)
        return tmp
    raise OSError(f"no free temporary file name in '{path.parent}'")


def check_writable(path: str | os.PathLike[str]) -> None:
    """Raise now, not after the work, if ``path`` could not be written: its temporary file
    is made and removed (the folder exists, is a folder, and takes a new file).

    Raises
    ------
    ImageFormatError
        :func:`unwritable_error`'s line for ``path``.

    Examples
    --------
    >>> check_writable(Path("no/such/dir/a.obj"))  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    spherewarp.errors.ImageFormatError: cannot write 'no/such/dir/a.obj': directory ... not exist
    """
    tmp = _make_temp(Path(path))
    with contextlib.suppress(OSError):
        tmp.unlink()
    _LIVE.discard(tmp)


def unwritable_error(path: Path, exc: OSError) -> ImageFormatError:
    """The error for a file that cannot be made or written next to ``path``: what the file
    system said (a missing folder, no permission, a read-only or full disk), not the
    temporary file's name.

    Examples
    --------
    >>> str(unwritable_error(Path("no/such/dir/a.mp4"), FileNotFoundError(2, "No such file")))
    "cannot write 'no/such/dir/a.mp4': directory 'no/such/dir' does not exist"
    >>> str(unwritable_error(Path("/a.png"), PermissionError(13, "Permission denied")))
    "cannot write '/a.png': Permission denied"
    >>> bad = NotADirectoryError(20, "Not a directory")
    >>> str(unwritable_error(Path(__file__) / "a.mp4", bad))  # doctest: +ELLIPSIS
    "cannot write '.../atomic.py/a.mp4': '.../atomic.py' is not a directory"
    """
    parent = path.parent
    if isinstance(exc, FileNotFoundError) and not parent.exists():
        return ImageFormatError(f"cannot write '{path}': directory '{parent}' does not exist")
    if isinstance(exc, NotADirectoryError):  # a file where a folder of the path should be
        for folder in path.parents:
            if os.path.lexists(folder) and not folder.is_dir():
                return ImageFormatError(f"cannot write '{path}': '{folder}' is not a directory")
    return ImageFormatError(f"cannot write '{path}': {exc.strerror or exc}")


def _fsync(path: Path) -> None:
    fd = os.open(path, os.O_RDWR | getattr(os, "O_BINARY", 0))
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def _fsync_dir(path: Path) -> None:
    with contextlib.suppress(OSError, AttributeError):
        fd = os.open(path, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


def exists_error(path: Path) -> OutputExistsError:
    """The error for an existing destination that must not be replaced."""
    return OutputExistsError(
        f"'{path}' exists; pass overwrite=True to replace it",
        cli=f"'{path}' exists; pass --overwrite to replace it",
    )


def _commit(tmp: Path, path: Path, overwrite: bool) -> None:
    _signals.check()  # a stop that something swallowed: do not put the file in place
    if overwrite:
        os.replace(tmp, path)
        return
    try:
        os.link(tmp, path)  # atomic and never clobbers
    except FileExistsError:
        raise exists_error(path) from None
    except OSError:  # no hard links on this file system
        if os.path.lexists(path):
            raise exists_error(path) from None
        os.replace(tmp, path)
    else:
        with contextlib.suppress(OSError):
            os.unlink(tmp)


@contextlib.contextmanager
def atomic_file(path: str | os.PathLike[str], *, overwrite: bool = False) -> Iterator[Path]:
    """Yield a temporary path to write ``path``'s new content to; put it in place on success.

    On leaving the ``with`` block normally the temporary file is flushed to
    disk and renamed to ``path`` (an existing ``path`` is an
    :class:`~spherewarp.errors.OutputExistsError` unless ``overwrite``). On any
    exception it is removed and ``path`` is left as it was. The temporary file
    exists (empty) when the block starts.

    Examples
    --------
    >>> import tempfile
    >>> d = Path(tempfile.mkdtemp())
    >>> with atomic_file(d / "a.bin") as tmp:
    ...     _ = tmp.write_bytes(b"abc")
    >>> (d / "a.bin").read_bytes()
    b'abc'
    """
    p = Path(path)
    if not overwrite and os.path.lexists(p):
        raise exists_error(p)
    remove_stale(p)
    tmp = _make_temp(p)
    try:
        yield tmp
        _fsync(tmp)
        _commit(tmp, p, overwrite)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
    finally:
        if not os.path.lexists(tmp):  # else remove_live() still finds it
            _LIVE.discard(tmp)
    _fsync_dir(p.parent)


def write_bytes(path: str | os.PathLike[str], data: bytes, *, overwrite: bool = False) -> Path:
    """Write ``data`` to ``path`` atomically; return ``path``.

    Examples
    --------
    >>> import tempfile
    >>> d = Path(tempfile.mkdtemp())
    >>> write_bytes(d / "b.bin", b"xyz").read_bytes()
    b'xyz'
    """
    p = Path(path)
    with atomic_file(p, overwrite=overwrite) as tmp:
        tmp.write_bytes(data)
    return p


def write_text(path: str | os.PathLike[str], text: str, *, overwrite: bool = False) -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically; return ``path``."""
    return write_bytes(path, text.encode("utf-8"), overwrite=overwrite)
