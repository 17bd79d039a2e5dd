"""Interrupting a render: SIGINT and SIGTERM at random points leave nothing behind.

A render runs in a fresh process (``python -m spherewarp``) and is sent SIGINT
or SIGTERM after a seeded random delay: during start-up, during the render, or
while the output is being encoded (the moment its temporary file appears).
It must exit 130 (SIGINT) or 143 (SIGTERM) with one line on stderr and no
traceback, and leave neither an output nor a temporary file. After SIGKILL,
which nothing can clean up after, the next write to the same output removes
the dead process's temporary file.
"""

from __future__ import annotations

import os
import random
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from spherewarp.io import write_image
from spherewarp.testpattern import make_test_pattern

pytestmark = pytest.mark.skipif(os.name != "posix", reason="POSIX signals")

RENDER = ("rotate", "in.png", "--yaw", "30", "--size", "3072x1536", "--antialias", "4")


def _env() -> dict[str, str]:
    env = dict(os.environ)
    env.pop("SPHEREWARP_DEBUG", None)
    return env


def _start(workdir: Path, *args: str) -> subprocess.Popen[str]:
    return subprocess.Popen(
        [sys.executable, "-m", "spherewarp", *args],
        cwd=workdir,
        env=_env(),
        stdin=subprocess.DEVNULL,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def _temporaries(workdir: Path) -> list[str]:
    return [p.name for p in workdir.iterdir() if ".tmp" in p.name]


def _wait_for_temporary(workdir: Path, proc: subprocess.Popen[str], limit: float = 60) -> bool:
    """Poll until the output's temporary file exists (encoding has begun)."""
    end = time.monotonic() + limit
    while time.monotonic() < end and proc.poll() is None:
        if _temporaries(workdir):
            return True
        time.sleep(0.002)
    return False


@pytest.fixture(scope="module")
def workdir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    d = tmp_path_factory.mktemp("interrupt")
    write_image(d / "in.png", make_test_pattern(1024, 512, labels=False))
    return d


@pytest.fixture(scope="module")
def timings(workdir: Path) -> tuple[float, float]:
    """(start-up until the handlers are in place, a whole render), measured here and now."""
    t = time.monotonic()
    subprocess.run([sys.executable, "-c", "import spherewarp._signals"], check=True, env=_env())
    startup = time.monotonic() - t
    t = time.monotonic()
    proc = _start(workdir, *RENDER, "-o", "whole.png")
    out, err = proc.communicate(timeout=600)
    assert proc.returncode == 0, err
    whole = time.monotonic() - t
    (workdir / "whole.png").unlink()
    return startup, whole


def _clear(workdir: Path) -> None:
    for p in workdir.iterdir():
        if p.name != "in.png":
            p.unlink()


def _interrupt(workdir: Path, signum: int, delay: float | None) -> None:
    """Send ``signum`` after ``delay`` s (None: when encoding starts); check nothing is left.

    A render that ends first (the machine got faster than when it was timed) is run again
    with half the delay.
    """
    for _ in range(4):
        _clear(workdir)
        proc = _start(workdir, *RENDER, "-o", "out.png")
        if delay is None:
            assert _wait_for_temporary(workdir, proc), "the render ended before it wrote anything"
        else:
            time.sleep(delay)
        if proc.poll() is None:
            break
        proc.communicate()
        assert delay is not None, "the encoding ended before the signal could be sent"
        delay /= 2
    else:
        pytest.fail("the render keeps ending before the signal: make it longer")
    proc.send_signal(signum)
    out, err = proc.communicate(timeout=600)
    expected = (130, "interrupted") if signum == signal.SIGINT else (143, "terminated")
    where = f"{signal.Signals(signum).name} after {delay} s"
    assert proc.returncode == expected[0], (where, proc.returncode, err)
    assert err.startswith(f"spherewarp: {expected[1]}") and err.count("\n") == 1, (where, err)
    assert "Traceback" not in err, (where, err)
    assert sorted(p.name for p in workdir.iterdir()) == ["in.png"], where


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_signal_at_random_points_leaves_nothing(workdir, timings, signum):
    startup, whole = timings
    rng = random.Random(14 + signum)
    delays = [
        1.5 * startup + rng.uniform(0.0, 0.15),  # start-up: importing click, the command
        1.5 * startup + rng.uniform(0.15, 0.5),  # numpy, numba's kernels, reading the input
        rng.uniform(0.3, 0.6) * whole,  # the render
        None,  # encoding: as soon as the temporary file is there
    ]
    for delay in delays:
        _interrupt(workdir, signum, delay)


def test_after_sigkill_the_next_run_removes_the_stale_temporary(workdir):
    _clear(workdir)
    proc = _start(workdir, *RENDER, "-o", "out.png")
    assert _wait_for_temporary(workdir, proc), "the render ended before it wrote anything"
    proc.kill()
    proc.communicate(timeout=600)
    (stale,) = _temporaries(workdir)  # nothing could clean up after SIGKILL
    assert stale.startswith(".out.png.spherewarp-") and stale.endswith(".tmp.png")
    assert not (workdir / "out.png").exists()
    proc = _start(workdir, "rotate", "in.png", "--yaw", "30", "--size", "64x32", "-o", "out.png")
    out, err = proc.communicate(timeout=600)
    assert proc.returncode == 0, err
    assert sorted(p.name for p in workdir.iterdir()) == ["in.png", "out.png"]
    (workdir / "out.png").unlink()


def test_no_leaked_semaphore_warning_after_the_fast_exit(tmp_path):
    """The program leaves with os._exit; a multiprocessing semaphore still referenced then
    (a --jobs pool stopped by Ctrl-C, its manager thread not yet gone) made the resource
    tracker print 'leaked semaphore objects' after the one line."""
    code = (
        "import multiprocessing as mp, sys\n"
        "held = mp.get_context('spawn').Lock()  # registered with the resource tracker\n"
        "sys.argv = ['spherewarp', '--version']\n"
        "from spherewarp.cli import run\n"
        "run()\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=120, cwd=tmp_path)  # fmt: skip
    assert done.returncode == 0 and "leaked" not in done.stderr, done.stderr
