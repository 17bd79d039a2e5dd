"""First run after install: how long the first commands take in a fresh virtual environment.

Builds the wheel of this checkout (``pip wheel``, where ``setup.py`` compiles
the kernels into it) and installs it into fresh virtual environments, then
times, from an empty directory:

* the first and the second ``spherewarp rotate IMAGE --yaw 30 -o a.jpg``;
* the first ``spherewarp demo DIR``, in another fresh environment.

``--no-warmup`` builds the wheel without the compiled kernels (the package as
it was before the build hook), for the figures to compare with. Each run takes
a few minutes (environments, and the build compiles for about a minute).
Prints a Markdown table row per figure; see the "First run after install"
section of ``bench/README.md``.

    python bench/first_run.py [--no-warmup] [--image interior.png]
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


def timed(cmd: list[str], cwd: Path, env: dict[str, str] | None = None) -> tuple[float, str]:
    """Run ``cmd``; return (wall seconds, stderr). Fails loudly on a non-zero exit."""
    t0 = time.perf_counter()
    done = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True, check=False)
    dt = time.perf_counter() - t0
    if done.returncode != 0:
        sys.exit(f"failed ({done.returncode}): {' '.join(cmd)}\n{done.stdout}\n{done.stderr}")
    return dt, done.stderr


def fresh_venv(root: Path, name: str, wheel: Path) -> tuple[Path, float]:
    """A new virtual environment with ``wheel`` installed; (its bin dir, install seconds)."""
    venv = root / name
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
    pip = [str(venv / "bin" / "python"), "-m", "pip", "install", "-q", str(wheel)]
    dt, _ = timed(pip, root)
    return venv / "bin", dt


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--no-warmup", action="store_true", help="build without compiled kernels")
    ap.add_argument("--image", default=str(REPO / "src" / "spherewarp" / "data" / "interior.png"))
    args = ap.parse_args()
    env = {k: v for k, v in os.environ.items() if not k.startswith(("NUMBA_", "PYTHONPATH"))}
    if args.no_warmup:
        env["SPHEREWARP_NO_WARMUP"] = "1"
    label = "no warm-up" if args.no_warmup else "warm-up at build"
    with tempfile.TemporaryDirectory(prefix="spherewarp-first-run-") as tmp:
        root = Path(tmp)
        src = root / "src"  # a clean copy: no build/ or cache files of earlier builds
        junk = shutil.ignore_patterns(".git", "build", "dist", "__pycache__", "*.egg-info", ".*")
        shutil.copytree(REPO, src, ignore=junk)
        wheels = root / "wheels"
        build = [sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "-w", str(wheels)]
        dt, _ = timed([*build, str(src)], root, env)
        wheel = next(wheels.glob("spherewarp-*.whl"))
        print(f"| {label} | build the wheel (`pip wheel --no-deps .`) | {dt:.1f} s |")
        print(f"| {label} | wheel size | {wheel.stat().st_size / 1e6:.1f} MB |")

        bin_a, dt = fresh_venv(root, "a", wheel)
        print(
            f"| {label} | install the wheel in a fresh venv (deps from pip's cache) | {dt:.1f} s |"
        )
        work = root / "work"
        work.mkdir()
        rotate = [str(bin_a / "spherewarp"), "rotate", args.image, "--yaw", "30"]
        for which, out in (("first", "a.jpg"), ("second", "b.jpg")):
            dt, err = timed([*rotate, "-o", out], work, env)
            note = " (compile notice shown)" if "compiling kernels" in err else ""
            print(f"| {label} | {which} `rotate` 1024x512{note} | {dt:.2f} s |")

        bin_b, _ = fresh_venv(root, "b", wheel)
        dt, err = timed([str(bin_b / "spherewarp"), "demo", str(work / "demo")], work, env)
        note = " (compile notice shown)" if "compiling kernels" in err else ""
        print(f"| {label} | first `demo` in another fresh venv{note} | {dt:.1f} s |")
        dt, _ = timed([str(bin_b / "spherewarp"), "demo", str(work / "demo2")], work, env)
        print(f"| {label} | second `demo` | {dt:.1f} s |")


if __name__ == "__main__":
    main()
