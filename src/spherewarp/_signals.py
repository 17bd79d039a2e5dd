"""SIGINT, SIGTERM and SIGHUP for the command line: unwind, clean up, never lose a request.

Standard library only, so the command line can install it before anything
heavy is imported. :func:`install` turns SIGINT into :class:`KeyboardInterrupt`
and SIGTERM and SIGHUP (the terminal closed, an ssh session lost; where the platform has
it) into :class:`Terminated` (all unwind the stack, so every
``finally`` and the atomic writer's clean-up run) and records the request:
a library that swallows the exception (a bare ``except:`` round an optional
import) cannot make it go away, since :func:`check` raises it again, and the
atomic writer calls :func:`check` before it puts a file in place.

An interrupt that arrives while Python code runs as a C callback (numba's
kernel cache, through llvmlite and ctypes) or in ``__del__`` is not raised
there (Python would print it and drop it): SIGALRM raises it 20 ms later.

The library itself never installs handlers; only ``spherewarp.cli.main`` does. The library
only uses :func:`held` round a few lines that must not be cut in two (starting and joining
the video pipeline's threads, swapping fds 1 and 2 round a C decoder): it sets whatever
handlers are there aside for those lines, then delivers what arrived.
"""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Iterator
from typing import Any

__all__ = [
    "Terminated", "install", "restore", "ignore", "check", "requested", "exit_status", "held",
]

#: signal numbers received since :func:`install`
_REQUESTS: list[int] = []
#: whether the retry timer (SIGALRM, see below) is armed by us, and so ours to cancel
_ARMED = [False]


class Terminated(BaseException):
    """SIGTERM (or SIGHUP: ``signum``) arrived: like KeyboardInterrupt, not an
    :class:`Exception` (nothing catches it by accident)."""

    def __init__(self, signum: int = signal.SIGTERM) -> None:
        super().__init__(signum)
        self.signum = signum


#: SIGHUP where the platform has it (not on Windows)
_SIGHUP: tuple[int, ...] = (signal.SIGHUP,) if hasattr(signal, "SIGHUP") else ()
#: the signals that stop the command line, each unwinding it as an exception
_STOPS = (signal.SIGINT, signal.SIGTERM, *_SIGHUP)
#: the exit status and word of each (the shell's 128 + the signal's number)
_STATUS = {signal.SIGTERM: (143, "terminated"), **{s: (129, "hung up") for s in _SIGHUP}}


def _exception(signum: int) -> BaseException:
    return KeyboardInterrupt() if signum == signal.SIGINT else Terminated(signum)


#: top-level packages whose Python code runs as callbacks from C (llvmlite's object cache,
#: during numba's kernel loading; the import system's weakref callbacks): an exception raised
#: there is printed and dropped by Python
_CALLBACK_PACKAGES = ("llvmlite", "numba", "ctypes", "importlib", "_frozen_importlib", "weakref")
_RETRY_S = 0.02


def _raise_unless_in_callback(frame: Any) -> None:
    name = str(frame.f_globals.get("__name__", "")) if frame is not None else ""
    in_callback = name.split(".")[0] in _CALLBACK_PACKAGES
    if frame is not None and frame.f_code.co_name in ("__del__", "__set_name__"):
        in_callback = True
    if in_callback and hasattr(signal, "setitimer"):
        signal.setitimer(signal.ITIMER_REAL, _RETRY_S)  # raise it a moment later, elsewhere
        _ARMED[0] = True
        return
    raise _exception(_REQUESTS[0])


def _handler(signum: int, frame: Any) -> None:
    _REQUESTS.append(signum)
    _raise_unless_in_callback(frame)


def _retry(signum: int, frame: Any) -> None:
    if _REQUESTS:
        _raise_unless_in_callback(frame)


def install() -> dict[int, Any]:
    """Handle SIGINT, SIGTERM and SIGHUP as above; return the handlers it replaced (for
    :func:`restore`).

    Does nothing outside the main thread (where handlers cannot be set).
    """
    previous: dict[int, Any] = {}
    handlers: dict[int, Any] = {signum: _handler for signum in _STOPS}
    if hasattr(signal, "SIGALRM"):
        handlers[signal.SIGALRM] = _retry
    for signum, handler in handlers.items():
        try:
            previous[signum] = signal.signal(signum, handler)
        except (ValueError, OSError):  # not the main thread, or not settable here
            pass
    return previous


def _cancel_retry() -> None:
    if _ARMED[0] and hasattr(signal, "setitimer"):
        _ARMED[0] = False
        try:
            signal.setitimer(signal.ITIMER_REAL, 0)
        except (ValueError, OSError):
            pass


def restore(previous: dict[int, Any]) -> None:
    """Put back the handlers :func:`install` replaced and forget the requests."""
    _cancel_retry()
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
    """The exit status and word for an interrupt: (130, "interrupted"), (143, "terminated")
    or, for SIGHUP, (129, "hung up")."""
    signum = exc.signum if isinstance(exc, Terminated) else requested()
    return _STATUS.get(signum, (130, "interrupted"))  # type: ignore[arg-type]


def ignore() -> None:
    """Ignore SIGINT, SIGTERM and SIGHUP from now on (the process is about to exit)."""
    _cancel_retry()
    for signum in _STOPS:
        try:
            signal.signal(signum, signal.SIG_IGN)
        except (ValueError, OSError):
            pass


#: the signals whose Python handlers :func:`held` sets aside
_HELD = tuple(
    getattr(signal, n) for n in ("SIGINT", "SIGTERM", "SIGHUP", "SIGALRM") if hasattr(signal, n)
)


@contextlib.contextmanager
def held() -> Iterator[None]:
    """Hold SIGINT, SIGTERM and SIGHUP (and this module's SIGALRM retry) back for the block, then
    deliver them to the handlers in place.

    For lines an interrupt must not cut in two: starting and joining the video pipeline's
    threads (an interrupt between two ``start()`` calls left a decoding thread running
    while its container was closed: SIGSEGV in FFmpeg, about once in 20 Ctrl-Cs of a
    segmented video), and putting fds 1 and 2 back after a C decoder (an interrupt
    between the two left stderr in a discarded file: the "interrupted" line was lost).
    Only the main thread runs signal handlers; elsewhere, and for a handler not set from
    Python, this does nothing.

    Examples
    --------
    >>> with held():
    ...     pass
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    got: list[int] = []
    previous: dict[int, Any] = {}
    for signum in _HELD:
        handler = signal.getsignal(signum)
        if callable(handler):  # a Python handler (not SIG_DFL, SIG_IGN or one set in C)
            previous[signum] = handler
            signal.signal(signum, lambda n, _frame: got.append(n))
    try:
        yield
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)
        for signum in got:
            signal.raise_signal(signum)  # now, to the handler put back
