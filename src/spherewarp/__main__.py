"""``python -m spherewarp`` and the ``spherewarp`` console script.

SIGINT and SIGTERM are handled from the first line on (before the command line
is imported), so an interrupt during start-up prints one line, not a traceback.
"""

from __future__ import annotations

import sys


def main() -> None:
    """Run the ``spherewarp`` command line (see :func:`spherewarp.cli.main`)."""
    from spherewarp import _signals

    try:
        _signals.install()
        from spherewarp.cli import main as cli_main
    except (KeyboardInterrupt, _signals.Terminated) as exc:
        code, word = _signals.exit_status(exc)
        sys.stderr.write(f"spherewarp: {word} (no partially written file is left)\n")
        sys.exit(code)
    try:
        cli_main()
    finally:
        _signals.ignore()  # shutting down: a second Ctrl-C must not print a traceback


if __name__ == "__main__":
    main()
