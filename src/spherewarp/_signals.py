"""SIGINT and SIGTERM for the command line: unwind, clean up, never lose a request.

Standard library only, so the command line can install it before anything
heavy is imported. :func:`install` turns SIGINT into :class:`KeyboardInterrupt`
and SIGTERM into :class:`Terminated` (both unwind the stack, so every
``finally`` and the atomic writer's clean-up run) and records the request:
a library that swallows the exception (a bare ``except:`` round an optional
import) cannot make it go away, since :func:`check` raises it again, and the
atomic writer calls :func:`check` before it puts a file in place.

The library itself never installs handlers; only ``spherewarp.cli.main`` does.
"""

from __future__ import annotations

import signal
from typing import Any

__all__ = ["Terminated", "install", "restore", "ignore", "check", "requested", "exit_status"]

#: signal numbers received since :func:`install`
_REQUESTS: list[int] = []


class Terminated(BaseException):
    """SIGTERM arrived: like KeyboardInterrupt, not an :class:`Exception` (nothing catches it
    by accident)."""


def _exception(signum: int) -> BaseException:
    return KeyboardInterrupt() if signum == signal.SIGINT else Terminated()


def _handler(signum: int, frame: Any) -> None:
    _REQUESTS.append(signum)
    raise _exception(signum)


def install() -> dict[int, Any]:
    """Handle SIGINT and SIGTERM as above; return the handlers it replaced (for :func:`restore`).

    Does nothing outside the main thread (where handlers cannot be set).
    """
    previous: dict[int, Any] = {}
    for signum in (signal.SIGINT, signal.SIGTERM):
        try:
            previous[signum] = signal.signal(signum, _handler)
        except (ValueError, OSError):  # not the main thread, or not settable here
            pass
    return previous


def restore(previous: dict[int, Any]) -> None:
    """Put back the handlers :func:`install` replaced and forget the requests."""
    for signum, handler in previous.items():
        try:
            signal.signal(signum, handler)
        except (ValueError, OSError, TypeError):
            pass
    _REQUESTS.clear()


def requested() -> int | None:
    """The first signal received since :func:`install`, or None."""
    return _REQUESTS[0] if _REQUESTS else None


def check() -> None:
    """Raise KeyboardInterrupt or :class:`Terminated` again if a stop was requested."""
    signum = requested()
    if signum is not None:
        raise _exception(signum)


def exit_status(exc: BaseException) -> tuple[int, str]:
    """The exit status and word for an interrupt: (130, "interrupted") or (143, "terminated")."""
    if isinstance(exc, Terminated) or requested() == signal.SIGTERM:
        return 143, "terminated"
    return 130, "interrupted"


def ignore() -> None:
    """Ignore SIGINT and SIGTERM from now on (the process is about to exit)."""
    for signum in (signal.SIGINT, signal.SIGTERM):
        try:
            signal.signal(signum, signal.SIG_IGN)
        except (ValueError, OSError):
            pass
