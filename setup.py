"""Build hook: compile the numba kernels while building the package.

The metadata is in ``pyproject.toml``; this file only replaces ``build_py``
with one that, after copying the package, runs ``python -m
spherewarp.render._warmup`` on the copy. Numba's cache files (``.nbi``,
``.nbc``) land in ``spherewarp/render/__pycache__`` of the build and so in the
wheel, and the first command after ``pip install`` loads them instead of
compiling for minutes. Numba keys them by the contents of the source, its
own version, the Python version and the CPU, so they are used where the
wheel was built (``pip install .``) and ignored elsewhere (then the first
render compiles, saying so).

An editable install (``pip install -e .``) compiles into the source tree
(``src/spherewarp/render/__pycache__``, ignored by git). A failed warm-up
only prints a warning: the kernels then compile on first use. Set
``SPHEREWARP_NO_WARMUP=1`` to skip it.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py

#: longest the warm-up may take (a slow machine compiles for a few minutes)
WARMUP_TIMEOUT_S = 1800


def warm_up(root: Path) -> bool:
    """Run the warm-up with ``root`` first on the path; False (with a warning) on failure."""
    env = dict(os.environ)
    for name in ("NUMBA_CACHE_DIR", "NUMBA_DISABLE_JIT", "SPHEREWARP_NO_JIT"):
        env.pop(name, None)  # the cache must go next to the sources being built
    env["PYTHONPATH"] = os.pathsep.join([str(root), env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
    env["PYTHONDONTWRITEBYTECODE"] = "1"  # no .pyc of the build Python in the wheel
    cmd = [sys.executable, "-m", "spherewarp.render._warmup"]
    print(f"spherewarp: compiling the kernels into {root} (a few minutes, once) ...", flush=True)
    t0 = time.perf_counter()
    try:
        done = subprocess.run(cmd, env=env, cwd=root, timeout=WARMUP_TIMEOUT_S, check=False)
        ok = done.returncode == 0
        why = f"exit status {done.returncode}"
    except (OSError, subprocess.SubprocessError) as exc:
        ok, why = False, str(exc)
    if ok:
        print(f"spherewarp: kernels compiled in {time.perf_counter() - t0:.0f} s", flush=True)
    else:
        print(
            f"WARNING: spherewarp: compiling the kernels at build time failed ({why}); "
            "they will compile on first use instead",
            file=sys.stderr,
            flush=True,
        )
    return ok


class BuildPyWarm(build_py):
    """``build_py``, then compile the kernels of the built (or, editable, source) package."""

    def run(self) -> None:
        super().run()
        if os.environ.get("SPHEREWARP_NO_WARMUP", "").strip() not in ("", "0"):
            return
        try:
            if getattr(self, "editable_mode", False):  # imported from the sources
                root = Path(self.get_package_dir("spherewarp")).resolve().parent
            else:
                root = Path(self.build_lib).resolve()
                # a build directory kept from an earlier build holds the cache of older sources
                for stale in (root / "spherewarp" / "render" / "__pycache__").glob("*.nb[ic]"):
                    stale.unlink()
            if (root / "spherewarp" / "render" / "_warmup.py").is_file():
                warm_up(root)
        except Exception as exc:  # never fail the install: the kernels compile on first use
            print(f"WARNING: spherewarp: no build-time compilation ({exc})", file=sys.stderr)


setup(cmdclass={"build_py": BuildPyWarm})
