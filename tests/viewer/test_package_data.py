"""The built page ships in the package: a wheel built from the tree holds it, and the
installed package's server finds every asset its index.html names."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def test_static_assets_referenced_exist():
    from spherewarp.viewer.server import STATIC_DIR

    html = (STATIC_DIR / "index.html").read_text()
    refs = re.findall(r'(?:src|href)="\./([^"]+)"', html)
    assert any(r.endswith(".js") for r in refs), refs
    for r in refs:
        assert (STATIC_DIR / r).is_file(), r


def test_package_data_globs_cover_the_page():
    """Every built file matches a package-data glob of pyproject.toml (so a wheel has it)."""
    import fnmatch
    import tomllib

    if not (ROOT / "pyproject.toml").is_file():
        pytest.skip("not a source tree")
    globs = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"][
        "package-data"
    ]["spherewarp"]
    pkg = ROOT / "src" / "spherewarp"
    files = [p.relative_to(pkg).as_posix() for p in (pkg / "viewer" / "static").rglob("*")]
    files = [f for f in files if (pkg / f).is_file()]
    assert files
    for f in files:
        assert any(fnmatch.fnmatch(f, g) for g in globs), f


def _setuptools_ok() -> bool:
    try:
        from importlib.metadata import version

        return int(version("setuptools").split(".")[0]) >= 77
    except Exception:
        return False


@pytest.mark.skipif(not (ROOT / "pyproject.toml").is_file(), reason="not a source tree")
@pytest.mark.skipif(
    not _setuptools_ok(), reason="building the wheel offline needs setuptools >= 77 here"
)
def test_installed_package_finds_the_page(tmp_path):
    env = {**os.environ, "SPHEREWARP_NO_WARMUP": "1", "PIP_NO_INDEX": "1"}
    wheels = tmp_path / "wheels"
    subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "--no-build-isolation",
         "-w", str(wheels), str(ROOT)],
        check=True, env=env, capture_output=True,
    )  # fmt: skip
    (wheel,) = wheels.glob("spherewarp-*.whl")
    target = tmp_path / "site"
    subprocess.run(
        [sys.executable, "-m", "pip", "install", "-q", "--no-deps", "--target", str(target),
         str(wheel)],
        check=True, env=env, capture_output=True,
    )  # fmt: skip
    code = (
        "import re, spherewarp.viewer.server as s; "
        "h = (s.STATIC_DIR / 'index.html').read_text(); "
        'refs = re.findall(r\'(?:src|href)="\\./([^"]+)"\', h); '
        "assert refs and all((s.STATIC_DIR / r).is_file() for r in refs), refs; "
        "print(s.STATIC_DIR)"
    )
    out = subprocess.run(
        [sys.executable, "-c", code],
        env={**env, "PYTHONPATH": str(target)},
        check=True,
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )
    assert out.stdout.strip().startswith(str(target))


def test_committed_build_is_up_to_date(tmp_path):
    """static/ is what 'npm run build' makes of viewer/ now (skipped without its toolchain)."""
    src = ROOT / "viewer"
    vite = src / "node_modules" / ".bin" / "vite"
    if not vite.exists():
        pytest.skip("viewer/node_modules is not installed (cd viewer && npm ci)")
    out = tmp_path / "static"
    subprocess.run(
        [str(vite), "build", "--outDir", str(out), "--emptyOutDir", "--logLevel", "error"],
        cwd=src, check=True, capture_output=True, timeout=120,
    )  # fmt: skip
    from spherewarp.viewer.server import STATIC_DIR

    def files(root: Path) -> dict[str, bytes]:
        return {
            p.relative_to(root).as_posix(): p.read_bytes() for p in root.rglob("*") if p.is_file()
        }

    assert files(out) == files(STATIC_DIR), "run 'npm run build' in viewer/ and commit static/"
