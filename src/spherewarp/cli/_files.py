"""The files a command reads and writes: no output may be one of its inputs.

Every command registers each file it reads (:meth:`Job.reads`) and each file
it will write (:meth:`Job.writes`) before it does any work; a write that is a
read (the same path, the same file through a symbolic link or a hard link),
or that another output of the command also writes, is refused at once with
one line naming both and the option to change. ``--overwrite`` replaces
earlier *outputs* only: an input is never overwritten.

Examples
--------
>>> import tempfile
>>> from pathlib import Path
>>> d = Path(tempfile.mkdtemp())
>>> _ = (d / "in.png").write_bytes(b"x")
>>> job = Job()
>>> job.reads(d / "in.png", "input") == d / "in.png"
True
>>> _ = job.writes(d / "out.png", "-o")
>>> job.writes(d / "sub" / ".." / "in.png", "-o")  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
spherewarp.errors.InvalidValueError: -o '...in.png' is the input '...in.png'; choose another -o (an input is never overwritten, not even with --overwrite)
"""  # noqa: E501

from __future__ import annotations

import os
from pathlib import Path

from ..errors import InvalidValueError

__all__ = ["Job", "job", "new_job", "same_file"]


def _key(path: Path) -> str:
    return os.path.normcase(os.path.realpath(path))


def same_file(a: str | os.PathLike[str], b: str | os.PathLike[str]) -> bool:
    """Whether ``a`` and ``b`` name one file: the same resolved path (whether or not it exists),
    or an existing file reached through a symbolic or a hard link."""
    if _key(Path(a)) == _key(Path(b)):
        return True
    try:
        return os.path.samefile(a, b)
    except (OSError, ValueError):
        return False


class Job:
    """The inputs and outputs of one run of a command (one input of a batch).

    ``reads`` and ``writes`` seed it with files another part of the run owns
    (the other inputs and earlier outputs of a batch), as (path, label) pairs.
    """

    def __init__(
        self,
        reads: tuple[tuple[Path, str], ...] = (),
        writes: tuple[tuple[Path, str], ...] = (),
    ) -> None:
        self._reads: list[tuple[Path, str]] = list(reads)
        self._writes: list[tuple[Path, str]] = list(writes)

    @property
    def written(self) -> list[tuple[Path, str]]:
        """The outputs registered so far, as (path, option) pairs."""
        return list(self._writes)

    def reads(self, path: str | os.PathLike[str], label: str = "input") -> Path:
        """Register a file the command reads; refuse it if an output already registered is it."""
        p = Path(path)
        for out, option in self._writes:
            if same_file(out, p):
                raise _clash(out, option, None, p, label)
        self._reads.append((p, label))
        return p

    def writes(
        self, path: str | os.PathLike[str], option: str = "-o", given: str | None = None
    ) -> Path:
        """Register a file the command will write, named through ``option``.

        ``given`` is what the user typed when it is not ``path`` itself (a
        frame pattern, the ``.obj`` a mesh's texture is named after). Raises
        :class:`~spherewarp.errors.InvalidValueError` if ``path`` is an input,
        or an output that another option writes.
        """
        p = Path(path)
        for inp, label in self._reads:
            if same_file(inp, p):
                raise _clash(p, option, given, inp, label)
        for out, other in self._writes:
            if same_file(out, p):
                if other == option and str(out) == str(p):
                    return p  # registered twice by the same step: fine
                raise _clash(p, option, given, out, f"output of {other}", read=False)
        self._writes.append((p, option))
        return p


def _clash(
    out: Path, option: str, given: str | None, other: Path, label: str, *, read: bool = True
) -> InvalidValueError:
    named = f"{option} {str(out)!r}"
    if given is not None and given != str(out):
        named = f"{option} {given!r} would write {str(out)!r}, which"
    if read:
        return InvalidValueError(
            f"{named} is the {label} {str(other)!r}; choose another {option} "
            "(an input is never overwritten, not even with --overwrite)"
        )
    return InvalidValueError(
        f"{named} is also the {label} ({str(other)!r}); choose another {option}"
    )


_CURRENT: list[Job] = [Job()]


def job() -> Job:
    """The job of the command now running."""
    return _CURRENT[0]


def new_job(job: Job | None = None) -> Job:
    """Start a new job (a fresh command, or the next input of a batch) and return it."""
    _CURRENT[0] = Job() if job is None else job
    return _CURRENT[0]
