"""One line on stderr when numba compiles the kernels (instead of silent minutes).

The compiled kernels are normally loaded from numba's on-disk cache, which
the package build fills (see :mod:`spherewarp.render._warmup`). When the cache
does not fit (another CPU, another numba version) the first render compiles
for a few minutes; numba then broadcasts a ``"numba:compile"`` event, which
happens only on a cache miss. The command line calls :func:`enable` so that
the first such event in a process prints :data:`MESSAGE` once; the library
alone prints nothing.

This module imports nothing heavy: ``enable`` costs nothing to a command
that never renders. :func:`install` (called by :mod:`spherewarp.render.fast`
when it imports the kernels) registers the listener with numba.
"""

from __future__ import annotations

import sys
from typing import Any, TextIO

__all__ = ["MESSAGE", "disable", "enable", "install"]

#: the line printed on the first compilation in a process
MESSAGE = "spherewarp: compiling kernels, once after install (a few minutes) ..."

_STATE: dict[str, Any] = {"stream": None, "shown": False, "listener": None}


def enable(stream: TextIO | None = None) -> None:
    """Print :data:`MESSAGE` to ``stream`` (default stderr) on the next compilation.

    At most once per process. Call :func:`disable` to keep quiet again.

    Examples
    --------
    >>> import io
    >>> enable(io.StringIO())
    >>> disable()
    """
    _STATE["stream"] = sys.stderr if stream is None else stream
    if "numba" in sys.modules:  # the kernels may be imported already
        install()


def disable() -> None:
    """Print nothing on compilation (the default for the library).

    Examples
    --------
    >>> disable()
    """
    _STATE["stream"] = None


def _on_compile() -> None:
    stream = _STATE["stream"]
    if stream is None or _STATE["shown"]:
        return
    _STATE["shown"] = True
    try:
        print(MESSAGE, file=stream, flush=True)
    except (OSError, ValueError):  # a closed or broken stream must not stop the render
        pass


def install() -> None:
    """Listen to numba's ``"numba:compile"`` events (once; does nothing without numba).

    Examples
    --------
    >>> install()
    """
    if _STATE["listener"] is not None:
        return
    try:
        from numba.core import event
    except Exception:  # no numba, or one without the event API: no notice
        return

    class _Listener(event.Listener):
        def on_start(self, ev: Any) -> None:
            _on_compile()

        def on_end(self, ev: Any) -> None:
            pass

    listener = _Listener()
    event.register("numba:compile", listener)
    _STATE["listener"] = listener
