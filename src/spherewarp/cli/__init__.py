"""The ``spherewarp`` command line.

Thin by design: each subcommand parses its options, calls the Python API and
prints what it wrote. Subcommands live in modules of this package and are
imported only when used, so ``spherewarp --help`` and every command start
fast.

Any :class:`~spherewarp.errors.SpherewarpError`, unreadable file or bad
option becomes one line on stderr (``spherewarp: error: ...``) and exit
status 2 (1 for an unexpected internal error, 130 when interrupted by SIGINT,
143 by SIGTERM, 129 by SIGHUP, leaving no partial output and no temporary file); a
traceback is a bug.
"""

from __future__ import annotations

import importlib
import os
import re
import sys
import warnings
from pathlib import Path
from typing import Any

import click

from .. import _compile_notice, _signals
from ..errors import SpherewarpError

__all__ = ["cli", "main", "run", "COMMANDS"]

#: subcommand name -> "module:function" inside spherewarp.cli
COMMANDS: dict[str, str] = {
    "rotate": "mobius_cmds:rotate",
    "zoom": "mobius_cmds:zoom",
    "mobius": "mobius_cmds:mobius",
    "render": "recipe_cmds:render",
    "animate": "recipe_cmds:animate",
    "testpattern": "misc_cmds:testpattern",
    "info": "misc_cmds:info",
    "demo": "misc_cmds:demo",
    "droste": "droste_cmds:droste",
    "schottky": "schottky_cmds:schottky",
    "lattes": "elliptic_cmds:lattes",
    "fit-rational": "elliptic_cmds:fit_rational_cmd",
    "peirce": "elliptic_cmds:peirce",
    "torus": "elliptic_cmds:torus",
    "power": "branched_cmds:power",
    "exp": "branched_cmds:exp",
    "map": "branched_cmds:map_cmd",
    "splitscreen": "branched_cmds:splitscreen",
    "project": "views_cmds:project",
    "video": "video_cmds:video",
    "view": "view_cmds:view",
}


class _Interrupted(Exception):
    """A KeyboardInterrupt inside a command, carried past click's own handler
    (which would print an empty line to stderr first)."""


class LazyGroup(click.Group):
    """A click group that imports a subcommand's module only when it is used."""

    def make_context(self, *args: Any, **kwargs: Any) -> click.Context:
        try:
            return super().make_context(*args, **kwargs)
        except KeyboardInterrupt:
            raise _Interrupted from None

    def invoke(self, ctx: click.Context) -> Any:
        try:
            from ._files import new_job

            new_job()
            return super().invoke(ctx)
        except KeyboardInterrupt:
            raise _Interrupted from None
        finally:  # clear a progress bar left by an error, before the error line
            bars = sys.modules.get(f"{__name__}._progress")
            if bars is not None:
                bars.close_all()

    def resolve_command(self, ctx: click.Context, args: list[str]) -> Any:
        found = super().resolve_command(ctx, args)
        _signals.check()  # an interrupt swallowed while importing the command: stop now
        return found

    def list_commands(self, ctx: click.Context) -> list[str]:
        return sorted(COMMANDS)

    def get_command(self, ctx: click.Context, cmd_name: str) -> click.Command | None:
        target = COMMANDS.get(cmd_name)
        if target is None:
            return None
        module_name, attr = target.split(":")
        module = importlib.import_module(f"{__name__}.{module_name}")
        from ._common import add_view_aliases

        return add_view_aliases(getattr(module, attr))


@click.group(
    cls=LazyGroup,
    context_settings={"help_option_names": ["-h", "--help"], "max_content_width": 100},
)
@click.version_option(package_name="spherewarp")
def cli() -> None:
    """Conformal edits of 360° equirectangular images and video.

    Rotate and zoom about any point with Möbius maps, and more. Every command
    reads an equirectangular image (PNG, JPEG, TIFF, WebP, EXR) and writes one,
    keeping its bit depth, colour profile and 360° metadata.

    \b
    Try:  spherewarp demo            (effects on the bundled sample)
          spherewarp COMMAND --help  (each command shows an example)
    """


def _one_line(text: str) -> str:
    return " ".join(str(text).split())


def _show_warning(message: Any, category: Any, *args: Any, **kwargs: Any) -> None:
    """Print a Python warning as one ``spherewarp: warning: ...`` line (no source path).

    A warning that quotes a traceback (numba's for a ``NUMBA_NUM_THREADS`` it cannot
    parse) keeps its text and the traceback's last line, the error, only.
    """
    text = str(message)
    head, sep, tb = text.partition("Traceback (most recent call last):")
    if sep:
        last = [line for line in tb.splitlines() if line.strip()][-1:]
        text = head + " ".join(last)
    click.echo(f"spherewarp: warning: {_one_line(text)}", err=True)


#: a temporary file's name (spherewarp.io.atomic.temp_name): ``.NAME.spherewarp-PID-HEX.tmpSUFFIX``
_TEMP_NAME = re.compile(r"\.([^/\\'\"\s]*?)\.spherewarp-\d+-[0-9a-f]{8}\.tmp(?:\.[A-Za-z0-9]+)?")


def _named(text: str) -> str:
    """``text`` with each temporary file's name replaced by the name of the file it becomes
    (a temporary one of a temporary one too): the user named that one, not the other.

    Examples
    --------
    >>> _named("'/d/.out.exr.spherewarp-17-9c6c2b97.tmp.exr': No space left on device")
    "'/d/out.exr': No space left on device"
    >>> _named("/d/..seg-0.mp4.spherewarp-1-9c6c2b97.tmp.mp4.spherewarp-1-39ed5f44.tmp.mp4")
    '/d/seg-0.mp4'
    """
    while True:
        named = _TEMP_NAME.sub(r"\1", text)
        if named == text:
            return text
        text = named


def _os_error(exc: OSError) -> str:
    """An OSError's message, naming the file the user named: a video's, not a segment's in
    its work folder (``OUT.parts``), nor a temporary file's; a full disk said as such."""
    import errno

    reason = str(exc.strerror or exc)
    full = exc.errno in (errno.ENOSPC, errno.EDQUOT)
    if full:
        reason += " (the disk is full)"
    if not getattr(exc, "filename", None):
        return reason
    path = Path(_named(os.fsdecode(exc.filename)))
    parts = next((p for p in path.parents if p.name.endswith(".parts")), None)
    if parts is None:
        return f"cannot write '{path}': {reason}" if _is_write(exc) else f"'{path}': {reason}"
    output = parts.with_name(parts.name[: -len(".parts")])
    text = f"cannot write '{output}': {reason}"
    if parts.is_dir():
        then = "free some space, then rerun" if full else "rerun"
        text += f"; {then} with --resume to continue from '{parts}'"
    return text


def _is_write(exc: OSError) -> bool:
    import errno

    return exc.errno in (errno.ENOSPC, errno.EDQUOT, errno.EFBIG, errno.EROFS)


def error_line(exc: BaseException, prog: str = "spherewarp") -> tuple[str, int] | None:
    """The one line and exit status for an error a user can fix, or None for another exception."""
    if isinstance(exc, click.ClickException):
        where = ""
        ctx = getattr(exc, "ctx", None)
        if ctx is not None and ctx.command_path:
            where = f" (see '{ctx.command_path} --help')"
        return f"{prog}: error: {_one_line(exc.format_message())}{where}", exc.exit_code or 2
    if isinstance(exc, SpherewarpError):
        return f"{prog}: error: {_one_line(_named(exc.cli_message))}", 2
    if isinstance(exc, OSError):
        return f"{prog}: error: {_one_line(_os_error(exc))}", 2
    if isinstance(exc, MemoryError):
        return f"{prog}: error: out of memory (try a smaller --size)", 2
    return None


def main(argv: list[str] | None = None) -> Any:
    """Run the command line; never lets a traceback reach the user for bad input.

    SIGINT, SIGTERM and SIGHUP unwind the command (removing any temporary file) and
    exit with status 130, 143 and 129.
    """
    previous = _signals.install()
    saved = warnings.showwarning
    warnings.showwarning = _show_warning
    try:
        return _main(argv)
    finally:
        warnings.showwarning = saved
        _signals.restore(previous)


def _stop(exc: BaseException, prog: str) -> None:
    """Exit after an interrupt: remove any temporary file left, say so in one line."""
    atomic = sys.modules.get("spherewarp.io.atomic")
    if atomic is not None:
        atomic.remove_live()
    code, word = _signals.exit_status(exc)
    segments = sys.modules.get("spherewarp.io.segments")
    hint = getattr(segments, "resume_hint", None)
    more = f"; {hint}" if hint else ""
    try:
        click.echo(f"{prog}: {word} (no partially written file is left{more})", err=True)
    except (OSError, ValueError):  # a hang-up: the terminal is gone
        pass
    sys.exit(code)


def _main(argv: list[str] | None) -> Any:
    prog = "spherewarp"
    _compile_notice.enable(sys.stderr)  # one line, not a silent minute, if numba compiles
    try:
        result = cli.main(args=argv, prog_name=prog, standalone_mode=False)
        _signals.check()  # a stop that something swallowed on the way
        return result
    except click.exceptions.Exit as exc:
        sys.exit(exc.exit_code)
    except click.exceptions.NoArgsIsHelpError as exc:  # 'spherewarp' alone: the help, as is
        click.echo(exc.ctx.get_help() if exc.ctx else exc.format_message(), err=True)
        sys.exit(2)
    except (KeyboardInterrupt, _Interrupted, _signals.Terminated, click.exceptions.Abort) as exc:
        _stop(exc, prog)
    except Exception as exc:
        if _signals.requested() is not None:  # e.g. wrapped by Python into a RuntimeError
            _stop(exc, prog)
        report = error_line(exc, prog)
        if report is not None:
            click.echo(report[0], err=True)
            sys.exit(report[1])
        if os.environ.get("SPHEREWARP_DEBUG"):  # an internal bug: one line, traceback on request
            raise
        click.echo(
            f"{prog}: internal error: {type(exc).__name__}: {_one_line(exc)} "
            "(please report it; set SPHEREWARP_DEBUG=1 for the traceback)",
            err=True,
        )
        sys.exit(1)


def _release_semaphores() -> None:
    """Unlink the semaphores that ``multiprocessing`` registered, as a normal exit would
    (its exit-time finalizers), before :func:`run` leaves with ``os._exit``.

    A ``--jobs`` pool that an interrupt stopped can still hold its queues' semaphores at
    that moment (its manager thread not yet gone), and the resource tracker then printed
    "There appear to be 5 leaked semaphore objects" after the one line (about once in 8
    interrupts under load). ``multiprocessing.util._run_finalizers`` is private; without
    it, this does nothing.
    """
    util = sys.modules.get("multiprocessing.util")
    run_finalizers = getattr(util, "_run_finalizers", None)
    if run_finalizers is not None:
        try:
            run_finalizers(0)
        except Exception:  # noqa: BLE001 - leaving anyway: the tracker's warning at worst
            pass


def run() -> None:
    """The ``spherewarp`` program: :func:`main`, then end the process at once.

    Tearing the interpreter down after a render (numba's compiled code, its
    LLVM state, a thousand modules) takes about 0.3 s, a quarter of a short
    command. Every output is written, closed and renamed into place before
    :func:`main` returns, so this flushes stdout and stderr and leaves with
    ``os._exit``. (A normal exit when coverage is measuring, which writes its
    data at exit.)
    """
    try:
        main()
        code = 0
    except SystemExit as exc:
        if exc.code is None or isinstance(exc.code, int):
            code = exc.code or 0
        else:
            print(exc.code, file=sys.stderr)
            code = 1
    if "coverage" in sys.modules:
        sys.exit(code)
    _release_semaphores()
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):  # a closed pipe (spherewarp info | head)
            pass
    os._exit(code)
