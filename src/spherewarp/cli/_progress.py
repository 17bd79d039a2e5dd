"""The progress bar of the command line.

:class:`ProgressBar` is a ``progress(done, total)`` callback for
:func:`spherewarp.render.warp` that draws a bar on stderr with ``tqdm``, and
only where someone can see it: when stderr is a terminal, ``--quiet`` was not
given, and the render has lasted more than :data:`DELAY` seconds (a quick
render shows nothing). Each render (each call sequence from ``done = 0`` to
``done == total``) gets its own bar, so a command that renders several images
(Droste ``--frames``) shows one at a time; the bar is cleared when it is done,
leaving the ``wrote ...`` line alone.

``tqdm`` is imported only when a bar is drawn, so commands start fast.
"""

from __future__ import annotations

import os
import sys
import time
from typing import Any, TextIO

__all__ = ["DELAY", "FrameBar", "JsonProgress", "ProgressBar", "close_all"]


#: seconds a render runs before its bar appears (``SPHEREWARP_PROGRESS_DELAY`` in the
#: environment overrides it, for tests)
def _delay() -> float:
    try:
        return max(0.0, float(os.environ.get("SPHEREWARP_PROGRESS_DELAY", "")))
    except ValueError:
        return 1.0


DELAY = _delay()

_OPEN: list[ProgressBar] = []


class ProgressBar:
    """A ``progress(done, total)`` callback drawing a delayed bar on a terminal.

    Parameters
    ----------
    desc : str
        The label in front of the bar.
    enabled : bool, optional
        Draw at all; default: when ``stream`` is a terminal.
    stream : file, optional
        Where to draw (default ``sys.stderr``).
    delay : float
        Seconds from a render's start before its bar appears.

    Examples
    --------
    >>> import io
    >>> bar = ProgressBar("rendering", stream=io.StringIO())   # not a terminal: silent
    >>> bar.enabled
    False
    >>> bar(0, 10); bar(10, 10)
    """

    def __init__(
        self,
        desc: str = "rendering",
        *,
        enabled: bool | None = None,
        stream: TextIO | None = None,
        delay: float | None = None,
    ) -> None:
        self.stream = sys.stderr if stream is None else stream
        if enabled is None:
            isatty = getattr(self.stream, "isatty", None)
            enabled = bool(isatty and isatty())
        self.enabled = enabled
        self.desc = desc
        self.delay = DELAY if delay is None else delay
        self._bar: Any = None
        self._start = 0.0
        self._done = 0

    def __call__(self, done: int, total: int) -> None:
        if not self.enabled:
            return
        now = time.monotonic()
        if self._start == 0.0 or done < self._done:  # a new render
            self.close()
            self._start = now
        self._done = done
        if self._bar is None and now - self._start >= self.delay and done < total:
            from tqdm import tqdm

            self._bar = tqdm(
                total=total,
                desc=self.desc,
                file=self.stream,
                leave=False,
                dynamic_ncols=True,
                bar_format="{desc}: {percentage:3.0f}%|{bar}| {elapsed}<{remaining}",
            )
            _OPEN.append(self)
        if self._bar is not None:
            self._bar.update(max(0, done - self._bar.n))
        if done >= total:
            self.close()
            self._start = 0.0

    def close(self) -> None:
        """Clear the bar if one is drawn."""
        bar, self._bar = self._bar, None
        if bar is not None:
            bar.close()
        if self in _OPEN:
            _OPEN.remove(self)


def close_all() -> None:
    """Clear every bar still drawn (an error or an interrupt mid-render)."""
    for bar in list(_OPEN):
        bar.close()


class JsonProgress:
    """A ``progress(done, total)`` callback writing one JSON object a line on stderr, for
    scripts: ``{"frames": 12, "total": 48, "fps": 30.5, "eta": 1.2}`` (``eta`` in seconds,
    null until known), at most every :attr:`every` seconds and always at the end.

    Examples
    --------
    >>> import io
    >>> out = io.StringIO()
    >>> p = JsonProgress(stream=out, every=0.0)
    >>> p(0, 2); p(2, 2)
    >>> out.getvalue().splitlines()[-1].startswith('{"frames": 2, "total": 2')
    True
    """

    def __init__(self, stream: TextIO | None = None, every: float = 0.5) -> None:
        self.stream = sys.stderr if stream is None else stream
        self.every = every
        self._start: float | None = None
        self._first = 0
        self._last = -1.0
        self._said: tuple[int, int] | None = None

    def __call__(self, done: int, total: int) -> None:
        import json

        now = time.monotonic()
        if self._start is None:
            self._start, self._first = now, done
        if done < total and now - self._last < self.every:
            return
        if self._said == (done, total):
            return
        self._last, self._said = now, (done, total)
        spent = now - self._start
        fps = (done - self._first) / spent if spent > 0 else None
        eta = (total - done) / fps if fps else (0.0 if done >= total else None)
        line = {"frames": done, "total": total, "fps": None if fps is None else round(fps, 2),
                "eta": None if eta is None else round(eta, 2)}  # fmt: skip
        self.stream.write(json.dumps(line) + "\n")
        self.stream.flush()

    def close(self) -> None:
        """Nothing to clear (the lines stay)."""


class FrameBar:
    """A ``progress(done, total)`` callback: frames done, frames a second and the time left,
    on a terminal (``enabled``), with ``tqdm``.

    Examples
    --------
    >>> bar = FrameBar(enabled=False)
    >>> bar(1, 10); bar.close()
    """

    def __init__(self, enabled: bool) -> None:
        self.enabled = enabled
        self._bar: Any = None

    def __call__(self, done: int, total: int) -> None:
        if not self.enabled:
            return
        if self._bar is None:
            from tqdm import tqdm

            self._bar = tqdm(total=total or None, unit="frame", file=sys.stderr, leave=False)
        if total and self._bar.total != total:
            self._bar.total = total
        self._bar.update(done - self._bar.n)

    def close(self) -> None:
        if self._bar is not None:
            self._bar.close()
            self._bar = None
