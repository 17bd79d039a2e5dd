"""The build-time warm-up covers every kernel entry point; the compile notice prints once."""

from __future__ import annotations

import io
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from spherewarp import _compile_notice
from spherewarp.render import _warmup, fast

pytestmark = pytest.mark.skipif(not fast.available(), reason="numba is not available")

RENDER = Path(_warmup.__file__).resolve().parent


def _called_kernels() -> set[str]:
    """Names of ``_kernels`` dispatchers that the Python side calls (``k.name``)."""
    from numba.core.dispatcher import Dispatcher

    k = fast._kernels()
    names: set[str] = set()
    for path in RENDER.glob("*.py"):
        if path.name in ("_kernels.py", "_warmup.py"):
            continue
        for name in re.findall(r"(?:\bk|_kernels\(\))\.(\w+)", path.read_text()):
            if isinstance(getattr(k, name, None), Dispatcher):
                names.add(name)
    return names


def test_entry_points_are_the_kernels_python_calls():
    called = _called_kernels()
    assert "render_spec" in called
    assert called == set(_warmup.ENTRY_POINTS)


def _own_kernels(module):
    from numba.core.dispatcher import Dispatcher

    return {
        name
        for name, f in vars(module).items()
        if isinstance(f, Dispatcher)
        and f.__module__ == module.__name__
        and not name.startswith("_")
    }


def test_grid_entry_points_are_the_grid_kernels():
    from spherewarp.render import _grid_kernels

    assert _own_kernels(_grid_kernels) == set(_warmup.GRID_ENTRY_POINTS)


def test_plane_entry_points_are_the_plane_kernels():
    from spherewarp.render import _plane_kernels

    assert _own_kernels(_plane_kernels) == set(_warmup.PLANE_ENTRY_POINTS)


def test_grid_codes_agree():
    from spherewarp.render import _grid_kernels
    from spherewarp.render.plan import _GridCodes

    for name in ("EQUIRECT", "STEREO", "FISHEYE", "EQUISOLID", "RECTILINEAR", "CUBE"):
        assert getattr(_GridCodes, name) == getattr(_grid_kernels, f"GRID_{name}")


def test_warmup_compiles_every_entry_point():
    counts = _warmup.run()  # loads the cache where it fits (compiles once otherwise)
    every = (*_warmup.ENTRY_POINTS, *_warmup.GRID_ENTRY_POINTS, *_warmup.PLANE_ENTRY_POINTS)
    assert set(counts) == set(every)
    assert all(n >= 1 for n in counts.values()), counts


def test_warmup_writes_one_line_per_step():
    out = io.StringIO()
    _warmup.run(out)
    lines = out.getvalue().splitlines()
    assert any(line.strip().startswith("render_spec uint8") for line in lines)
    assert lines[-1].startswith("spherewarp: kernels ready in ")


@pytest.fixture
def notice():
    """The notice enabled on a fresh stream, its state restored afterwards."""
    saved = dict(_compile_notice._STATE)
    _compile_notice._STATE["shown"] = False
    stream = io.StringIO()
    _compile_notice.enable(stream)
    yield stream
    _compile_notice._STATE.update(saved)


def _compile_two_functions() -> None:
    from numba import njit

    @njit(cache=False)
    def first(x):
        return x + 1

    @njit(cache=False)
    def second(x):
        return x * 2

    assert first(1) == 2
    assert second(2.0) == 4.0
    assert first(1.5) == 2.5  # a second signature: another compilation


def test_notice_prints_once_on_compilation(notice):
    _compile_two_functions()
    assert notice.getvalue() == _compile_notice.MESSAGE + "\n"


def test_notice_is_silent_when_disabled(notice):
    _compile_notice.disable()
    _compile_two_functions()
    assert notice.getvalue() == ""


def test_a_cache_load_is_no_compilation():
    """After a warm-up, a fresh process loads every kernel from the cache: no notice."""
    _warmup.run()  # fills the cache where it lacks something
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(RENDER.parents[1]), env.get("PYTHONPATH", "")])
    code = (
        "import sys; from spherewarp import _compile_notice as c; "
        "from spherewarp.render import _warmup; c.enable(sys.stderr); _warmup.run()"
    )
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=600
    )
    assert done.returncode == 0, done.stderr
    assert _compile_notice.MESSAGE not in done.stderr


def test_notice_survives_a_closed_stream(notice):
    notice.close()
    _compile_two_functions()  # no exception
