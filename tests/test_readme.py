"""Every command in README.md runs as written.

The README's fenced blocks are read from the file each run, so a line added or
changed there is tested without touching this file:

- ``sh`` blocks: a block's lines run in order in one fresh ``bash`` (``set -e``,
  so variables such as ``S=$(...)`` reach the later lines), in a temporary
  directory, with the interpreter's ``bin`` first on ``PATH`` (``python`` and
  ``spherewarp`` resolve as after the README's set-up). Every line must exit 0
  and no traceback may reach stderr.
- The set-up lines (those with ``pip install``) are not re-run: each
  ``pip install`` and ``pytest`` step must be one that ``.ci/run`` runs (CI may
  add ``-q`` and arguments at the end); their other steps (``spherewarp demo``)
  run, twice, as a user who runs the line again does.
- ``python`` blocks: each runs as a script in a fresh ``python``, in a temporary
  directory.

Blocks fenced with another language (``text``, ``console``, none) are not run:
use one of those for output, file trees or commands that need what a fresh
clone lacks.

Reduced size: so that the test takes seconds, not minutes, ``spherewarp`` on
``PATH`` is a small wrapper that runs the real command line (``python -m
spherewarp``) with ``--size 256x128`` appended, for the commands that have a
``--size`` option (found from the command line itself) and only those. The
README's text is run unchanged. ``SPHEREWARP_README_FULL_SIZE=1`` turns the
reduction off.
"""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
CI_SCRIPT = ROOT / ".ci" / "run"

#: what the wrapper appends to the commands that take --size
REDUCED_SIZE = ("--size", "256x128")
#: seconds one block may take
TIMEOUT = 900

_FENCE = re.compile(r"^```([A-Za-z0-9_+-]*)[^\n]*\n(.*?)^```\s*$", re.MULTILINE | re.DOTALL)


def readme_blocks(language: str) -> list[str]:
    """The contents of the README's fenced blocks of ``language``, in order."""
    text = README.read_text(encoding="utf-8")
    return [body for lang, body in _FENCE.findall(text) if lang.lower() == language]


def logical_lines(block: str) -> list[str]:
    """The block's commands: continuation lines joined, blank and comment-only lines left out."""
    lines: list[str] = []
    pending = ""
    for raw in block.splitlines():
        if raw.rstrip().endswith("\\"):
            pending += raw.rstrip()[:-1] + " "
            continue
        line = (pending + raw).strip()
        pending = ""
        if line and not line.startswith("#"):
            lines.append(line)
    if pending.strip():
        lines.append(pending.strip())
    return lines


def _steps(line: str) -> list[list[str]]:
    """The ``&&``-separated steps of a line, as words (comments and ``-q`` dropped)."""
    words = shlex.split(line, comments=True)
    steps: list[list[str]] = [[]]
    for word in words:
        if word == "&&":
            steps.append([])
        elif word != "-q":
            steps[-1].append(word)
    return [s for s in steps if s]


def _is_setup(step: list[str]) -> bool:
    return "pip" in step and "install" in step or step[:3] == ["python", "-m", "pytest"]


def _ci_steps() -> list[list[str]]:
    steps: list[list[str]] = []
    for line in CI_SCRIPT.read_text(encoding="utf-8").splitlines():
        if line.strip() and not line.lstrip().startswith("#"):
            try:
                steps += _steps(line)
            except ValueError:  # a line shlex cannot split is no set-up step
                continue
    return steps


def _sized_commands() -> list[str]:
    """The spherewarp subcommands that have a --size option."""
    import click

    from spherewarp.cli import COMMANDS, cli

    ctx = click.Context(cli)
    sized = []
    for name in COMMANDS:
        command = cli.get_command(ctx, name)
        if command is not None and any("--size" in p.opts for p in command.params):
            sized.append(name)
    return sorted(sized)


def _wrapper(bin_dir: Path) -> None:
    """Write ``bin_dir/spherewarp``: the real command line, --size appended where it applies."""
    full = os.environ.get("SPHEREWARP_README_FULL_SIZE") == "1"
    sized = [] if full else _sized_commands()
    code = textwrap.dedent(
        f"""\
        # test_readme.py: spherewarp at reduced size (see the test's docstring)
        import os, sys
        args = sys.argv[1:]
        if args and args[0] in {sized!r} and not {{"-h", "--help"}} & set(args):
            args += {list(REDUCED_SIZE)!r}
        os.execv(sys.executable, [sys.executable, "-m", "spherewarp", *args])
        """
    )
    (bin_dir / "spherewarp.py").write_text(code, encoding="utf-8")
    # a sh script, so that no long or odd interpreter path goes in a #! line
    launcher = f'#!/bin/sh\nexec {shlex.quote(sys.executable)} "$0.py" "$@"\n'
    path = bin_dir / "spherewarp"
    path.write_text(launcher, encoding="utf-8")
    path.chmod(0o755)


@pytest.fixture
def shell_env(tmp_path: Path) -> dict[str, str]:
    """The environment of a user who has run the set-up: python and spherewarp on PATH."""
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    _wrapper(bin_dir)
    env = dict(os.environ)
    env["PATH"] = os.pathsep.join(
        [str(bin_dir), os.path.dirname(sys.executable), env.get("PATH", "")]
    )
    env.pop("SPHEREWARP_DEBUG", None)
    env.setdefault("PYTHONIOENCODING", "utf-8")
    return env


def _run(argv: list[str], cwd: Path, env: dict[str, str]) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        argv,
        cwd=cwd,
        env=env,
        capture_output=True,
        text=True,
        timeout=TIMEOUT,
        stdin=subprocess.DEVNULL,
    )


def _run_bash(lines: list[str], cwd: Path, env: dict[str, str]) -> None:
    """Run ``lines`` in order in one bash; fail naming the line that failed."""
    script = ["set -e"]
    for k, line in enumerate(lines):
        script += [line, f"echo '@@readme-line-done {k}' >&2"]
    done = _run(["bash", "-c", "\n".join(script)], cwd, env)
    finished = [int(m) for m in re.findall(r"^@@readme-line-done (\d+)$", done.stderr, re.M)]
    stderr = re.sub(r"^@@readme-line-done \d+\n", "", done.stderr, flags=re.M)
    if done.returncode != 0:
        failed = lines[len(finished)] if len(finished) < len(lines) else "(after the last line)"
        pytest.fail(f"README line failed (exit {done.returncode}):\n  {failed}\n{stderr}")
    assert "Traceback" not in stderr, stderr
    assert len(finished) == len(lines)


def _tour_blocks() -> list[str]:
    """The sh blocks other than the set-up ones."""
    return [b for b in readme_blocks("sh") if not any(_is_setup(s) for s in _setup_steps(b))]


def _setup_steps(block: str) -> list[list[str]]:
    return [s for line in logical_lines(block) for s in _steps(line)]


def test_readme_has_the_blocks():
    assert _tour_blocks(), "no sh block of commands in README.md"
    assert readme_blocks("python"), "no python block in README.md"
    assert any(_is_setup(s) for b in readme_blocks("sh") for s in _setup_steps(b)), (
        "no set-up (pip install) line in README.md"
    )


def test_setup_steps_are_what_ci_runs():
    ci = _ci_steps()
    setup = [s for b in readme_blocks("sh") for s in _setup_steps(b) if _is_setup(s)]
    assert setup
    for step in setup:
        assert any(c[: len(step)] == step for c in ci), (
            f"README set-up step {shlex.join(step)!r} is not run by .ci/run"
        )


def test_setup_lines_other_steps_run_twice(tmp_path, shell_env):
    """``spherewarp demo`` from the set-up line, run and run again (it replaces its files)."""
    others = [
        shlex.join(s)
        for b in readme_blocks("sh")
        for line in logical_lines(b)
        if any(_is_setup(x) for x in _steps(line))
        for s in _steps(line)
        if not _is_setup(s)
    ]
    assert others
    _run_bash(others + others, tmp_path, shell_env)


@pytest.mark.parametrize("index", range(len(readme_blocks("sh"))))
def test_sh_block_runs_as_written(index, tmp_path, shell_env):
    block = readme_blocks("sh")[index]
    if block not in _tour_blocks():
        pytest.skip("the set-up block: see the two tests above")
    _run_bash(logical_lines(block), tmp_path, shell_env)


@pytest.mark.parametrize("index", range(len(readme_blocks("python"))))
def test_python_block_runs_as_written(index, tmp_path, shell_env):
    block = readme_blocks("python")[index]
    done = _run([sys.executable, "-c", block], tmp_path, shell_env)
    assert done.returncode == 0, done.stderr
    assert "Traceback" not in done.stderr, done.stderr


def test_area_cost_agrees_with_the_help():
    """The README and ``--antialias``'s help give area's cost against 4x4 in the same words."""
    from spherewarp.cli.mobius_cmds import rotate

    (option,) = [p for p in rotate.params if "--antialias" in p.opts]
    cost = re.search(r"1/\d+(?: to 1/\d+)?", option.help)
    assert cost, option.help
    area = [
        line
        for line in README.read_text(encoding="utf-8").split("\n- ")
        if "`--antialias area`" in line
    ]
    assert area and cost.group(0) in area[0], (cost.group(0), area)
