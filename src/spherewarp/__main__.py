"""``python -m spherewarp`` and the ``spherewarp`` console script.

SIGINT, SIGTERM and SIGHUP are handled from the first line on (before the command line
is imported), so an interrupt during start-up prints one line, not a traceback.
"""

from __future__ import annotations

import contextlib
import os
import sys


def main() -> None:
    """Run the ``spherewarp`` command line (see :func:`spherewarp.cli.main`)."""
    try:
        from spherewarp import _signals

        _signals.install()
        from spherewarp.cli import run as cli_run
    except BaseException as exc:
        signals = sys.modules.get("spherewarp._signals")
        stopped = signals is not None and signals.requested() is not None
        if not (stopped or isinstance(exc, KeyboardInterrupt)):
            raise
        code, word = signals.exit_status(exc) if signals is not None else (130, "interrupted")
        sys.stderr.write(f"spherewarp: {word} (no partially written file is left)\n")
        sys.stderr.flush()
        os._exit(code)
    try:
        cli_run()  # ends the process with os._exit (see spherewarp.cli.run)
    except SystemExit as exc:
        if exc.code not in (129, 130, 143):
            raise
        # Interrupted (the files are cleaned up): exit now with that status. A normal exit
        # would wait for the render threads, and Python turns 130 into death by SIGINT when
        # the KeyboardInterrupt passed through a library's C code on its way.
        _signals.ignore()
        for stream in (sys.stdout, sys.stderr):
            with contextlib.suppress(Exception):
                stream.flush()
        os._exit(exc.code)
    finally:
        _signals.ignore()  # shutting down: a second Ctrl-C must not print a traceback


if __name__ == "__main__":
    main()
