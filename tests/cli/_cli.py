"""Run the ``spherewarp`` command line as users do: one fresh process a command.

Each call starts ``python -m spherewarp`` in a new interpreter (in the current
directory, with this process's environment), so no module imported by the test
process, or by an earlier command, can hide an import-order bug in a command.
The ``capsys`` argument is kept for the call sites' sake and is not used.
"""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

#: seconds one command may take (the first command of a run may compile kernels)
TIMEOUT = 600


def run_cli(*args: object, timeout: float = TIMEOUT, **kw: object) -> tuple[int, str, str]:
    """Run ``spherewarp ARGS...`` in a fresh process; return (exit code, stdout, stderr)."""
    env = dict(os.environ)
    env.pop("SPHEREWARP_DEBUG", None)
    env.setdefault("PYTHONIOENCODING", "utf-8")
    done = subprocess.run(
        [sys.executable, "-m", "spherewarp", *(str(a) for a in args)],
        capture_output=True,
        text=True,
        timeout=timeout,
        env=env,
        stdin=subprocess.DEVNULL,
        **kw,
    )
    return done.returncode, done.stdout, done.stderr


def run(capsys: pytest.CaptureFixture[str] | None, *args: object) -> tuple[int, str, str]:
    return run_cli(*args)


def ok(capsys: pytest.CaptureFixture[str] | None, *args: object) -> str:
    code, out, err = run(capsys, *args)
    assert code == 0, err
    return out


def fails(capsys: pytest.CaptureFixture[str] | None, *args: object) -> str:
    code, out, err = run(capsys, *args)
    assert code == 2, (code, out, err)
    assert err.startswith("spherewarp: error:") and err.count("\n") == 1, err
    return err
