"""Progress: warp(progress=...) and the command line's bar (a terminal only, not --quiet)."""

from __future__ import annotations

import io
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from _cli import run_cli

from spherewarp.cli._progress import ProgressBar
from spherewarp.demo import sample_path
from spherewarp.maps import Mobius
from spherewarp.render import fast, warp

IMG = np.random.default_rng(3).integers(0, 256, (64, 128, 3), dtype=np.uint8)


def _calls(**kwargs: object) -> list[tuple[int, int]]:
    seen: list[tuple[int, int]] = []
    out = warp(IMG, Mobius.zoom((10, 5), 2), progress=lambda d, t: seen.append((d, t)), **kwargs)
    assert np.array_equal(out, warp(IMG, Mobius.zoom((10, 5), 2), **kwargs))  # same image
    return seen


@pytest.mark.parametrize(
    "kwargs",
    [
        pytest.param({"method": "fast"}, id="fast"),
        pytest.param({"method": "fast", "threads": 1}, id="fast-1-thread"),
        pytest.param({"method": "reference", "antialias": "none"}, id="reference"),
        pytest.param({"method": "reference", "antialias": "area"}, id="reference-area"),
        pytest.param({"method": "reference", "antialias": "adaptive"}, id="reference-adaptive"),
    ],
)
def test_progress_is_monotone_from_zero_to_total(kwargs: dict) -> None:
    if kwargs.get("method") == "fast" and not fast.available():
        pytest.skip("numba not available")
    seen = _calls(**kwargs)
    done = [d for d, _ in seen]
    totals = {t for _, t in seen}
    assert len(totals) == 1 and (total := totals.pop()) > 0
    assert done[0] == 0 and done[-1] == total
    assert done == sorted(done) and max(done) == total


def test_progress_of_several_sheets() -> None:
    from spherewarp.effects.splitscreen import splitscreen

    seen: list[tuple[int, int]] = []
    splitscreen([IMG, IMG[::-1].copy()], progress=lambda d, t: seen.append((d, t)))
    assert seen[0][0] == 0 and seen[-1][0] == seen[-1][1]


def test_progress_of_peirce_and_torus() -> None:
    from spherewarp.effects.torus import render_torus
    from spherewarp.grids.peirce import peirce_to_equirect, render_peirce

    for render in (
        lambda p: render_peirce(IMG, 600, progress=p),
        lambda p: peirce_to_equirect(IMG[:, :64], (300, 600), progress=p),
        lambda p: render_torus(IMG, width=600, progress=p),
    ):
        seen: list[tuple[int, int]] = []
        render(lambda d, t, seen=seen: seen.append((d, t)))
        done = [d for d, _ in seen]
        assert len(seen) > 2 and done[0] == 0 and done == sorted(done)
        assert done[-1] == seen[-1][1]


def test_a_failing_progress_callback_stops_the_render() -> None:
    def boom(done: int, total: int) -> None:
        if done:
            raise RuntimeError("stop")

    for method in ("fast", "reference"):
        if method == "fast" and not fast.available():
            continue
        with pytest.raises(RuntimeError, match="stop"):
            warp(IMG, Mobius.zoom((0, 0), 2), progress=boom, method=method)


def test_progress_must_be_callable() -> None:
    from spherewarp.errors import InvalidTypeError

    with pytest.raises(InvalidTypeError, match="progress"):
        warp(IMG, Mobius.identity(), progress=3)


class _Tty(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_bar_draws_after_its_delay_and_clears() -> None:
    s = _Tty()
    bar = ProgressBar("rendering", stream=s, delay=0.0)
    bar(0, 4)
    bar(2, 4)
    bar(4, 4)
    text = s.getvalue()
    assert "rendering" in text and text.endswith("\r")  # cleared, cursor at line start
    quick = _Tty()
    late = ProgressBar("rendering", stream=quick, delay=3600.0)
    late(0, 4)
    late(4, 4)
    assert quick.getvalue() == ""  # done before the delay: nothing drawn


def test_not_a_terminal_draws_nothing(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPHEREWARP_PROGRESS_DELAY", "0")
    code, out, err = run_cli("zoom", sample_path(), "--at", "0,0", "--factor", "2",
                             "-o", tmp_path / "z.png")  # fmt: skip
    assert code == 0 and err == "" and out.startswith("wrote"), err


def _in_pty(args: list[str], cwd: Path) -> tuple[int, str]:
    import fcntl
    import pty
    import struct
    import termios

    master, slave = pty.openpty()
    fcntl.ioctl(slave, termios.TIOCSWINSZ, struct.pack("HHHH", 24, 100, 0, 0))
    env = dict(os.environ, SPHEREWARP_PROGRESS_DELAY="0")
    proc = subprocess.Popen(
        [sys.executable, "-m", "spherewarp", *args], stdin=slave, stdout=slave, stderr=slave,
        cwd=cwd, env=env, close_fds=True,
    )  # fmt: skip
    os.close(slave)
    chunks = []
    while True:
        try:
            data = os.read(master, 65536)
        except OSError:  # the child closed the terminal
            break
        if not data:
            break
        chunks.append(data)
    os.close(master)
    return proc.wait(timeout=600), b"".join(chunks).decode("utf-8", "replace")


@pytest.mark.skipif(sys.platform == "win32", reason="needs a pseudo-terminal")
@pytest.mark.parametrize("quiet", [False, True])
def test_a_terminal_gets_a_bar_unless_quiet(tmp_path: Path, quiet: bool) -> None:
    args = ["zoom", str(sample_path()), "--at", "0,0", "--factor", "2", "-o", "z.png"]
    code, text = _in_pty(args + (["--quiet"] if quiet else []), tmp_path)
    assert code == 0, text
    assert text.rstrip().endswith("wrote z.png")
    assert ("rendering:" in text and "%|" in text) != quiet, text
