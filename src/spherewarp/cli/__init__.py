"""The ``spherewarp`` command line.

Thin by design: each subcommand parses its options, calls the Python API and
prints what it wrote. Subcommands live in modules of this package and are
imported only when used, so ``spherewarp --help`` and every command start
fast.

Any :class:`~spherewarp.errors.SpherewarpError`, unreadable file or bad
option becomes one line on stderr (``spherewarp: error: ...``) and exit
status 2 (1 for an unexpected internal error, 130 when interrupted); a
traceback is a bug.
"""

from __future__ import annotations

import importlib
import os
import sys
import warnings
from typing import Any

import click

from ..errors import SpherewarpError

__all__ = ["cli", "main", "COMMANDS"]

#: subcommand name -> "module:function" inside spherewarp.cli
COMMANDS: dict[str, str] = {
    "rotate": "mobius_cmds:rotate",
    "zoom": "mobius_cmds:zoom",
    "mobius": "mobius_cmds:mobius",
    "testpattern": "misc_cmds:testpattern",
    "info": "misc_cmds:info",
    "demo": "misc_cmds:demo",
    "droste": "droste_cmds:droste",
    "lattes": "elliptic_cmds:lattes",
    "fit-rational": "elliptic_cmds:fit_rational_cmd",
    "peirce": "elliptic_cmds:peirce",
    "torus": "elliptic_cmds:torus",
    "power": "branched_cmds:power",
    "exp": "branched_cmds:exp",
    "map": "branched_cmds:map_cmd",
    "splitscreen": "branched_cmds:splitscreen",
    "project": "views_cmds:project",
}


class _Interrupted(Exception):
    """A KeyboardInterrupt inside a command, carried past click's own handler
    (which would print an empty line to stderr first)."""


class LazyGroup(click.Group):
    """A click group that imports a subcommand's module only when it is used."""

    def invoke(self, ctx: click.Context) -> Any:
        try:
            return super().invoke(ctx)
        except KeyboardInterrupt:
            raise _Interrupted from None
        finally:  # clear a progress bar left by an error, before the error line
            bars = sys.modules.get(f"{__name__}._progress")
            if bars is not None:
                bars.close_all()

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
    """Print a Python warning as one ``spherewarp: warning: ...`` line (no source path)."""
    click.echo(f"spherewarp: warning: {_one_line(message)}", err=True)


def main(argv: list[str] | None = None) -> Any:
    """Run the command line; never lets a traceback reach the user for bad input."""
    saved = warnings.showwarning
    warnings.showwarning = _show_warning
    try:
        return _main(argv)
    finally:
        warnings.showwarning = saved


def _main(argv: list[str] | None) -> Any:
    prog = "spherewarp"
    try:
        return cli.main(args=argv, prog_name=prog, standalone_mode=False)
    except click.exceptions.Exit as exc:
        sys.exit(exc.exit_code)
    except click.exceptions.Abort:
        click.echo(f"{prog}: interrupted", err=True)
        sys.exit(130)
    except click.ClickException as exc:
        where = ""
        ctx = getattr(exc, "ctx", None)
        if ctx is not None and ctx.command_path:
            where = f" (see '{ctx.command_path} --help')"
        click.echo(f"{prog}: error: {_one_line(exc.format_message())}{where}", err=True)
        sys.exit(exc.exit_code if exc.exit_code else 2)
    except SpherewarpError as exc:
        click.echo(f"{prog}: error: {_one_line(exc.cli_message)}", err=True)
        sys.exit(2)
    except (KeyboardInterrupt, _Interrupted):
        click.echo(f"{prog}: interrupted (no partially written file is left)", err=True)
        sys.exit(130)
    except OSError as exc:
        name = f" {exc.filename!r}" if getattr(exc, "filename", None) else ""
        click.echo(f"{prog}: error:{name} {_one_line(exc.strerror or exc)}", err=True)
        sys.exit(2)
    except MemoryError:
        click.echo(f"{prog}: error: out of memory (try a smaller --size)", err=True)
        sys.exit(2)
    except Exception as exc:  # an internal bug: say so in one line, traceback on request
        if os.environ.get("SPHEREWARP_DEBUG"):
            raise
        click.echo(
            f"{prog}: internal error: {type(exc).__name__}: {_one_line(exc)} "
            "(please report it; set SPHEREWARP_DEBUG=1 for the traceback)",
            err=True,
        )
        sys.exit(1)
