"""``spherewarp view``: the browser viewer and editor."""

from __future__ import annotations

import errno
import socket
from pathlib import Path

import click

from ._common import example

__all__ = ["view"]


def _port_problem(exc: OSError) -> bool:
    """Whether a failure to listen is the port's (in use, or not this user's to take);
    otherwise it is the host's (no such name, not an address of this machine, an
    address family the system lacks)."""
    if isinstance(exc, socket.gaierror):
        return False
    return exc.errno in (errno.EADDRINUSE, errno.EACCES, errno.EPERM)


@click.command(
    epilog=example(
        "spherewarp view room.jpg",
        "spherewarp view room.jpg --recipe zoom.json --port 8360 --no-browser",
        "spherewarp view walk.mp4",
    )
)
@click.argument(
    "image", required=False, type=click.Path(exists=True, dir_okay=False, path_type=Path)
)
@click.option(
    "--recipe",
    type=click.Path(exists=True, dir_okay=False, path_type=Path),
    metavar="R.json",
    help="Start from this recipe (the page edits it; 'Save' downloads the edited one).",
)
@click.option(
    "--mask",
    "masks",
    multiple=True,
    type=click.Path(exists=True, dir_okay=False, path_type=Path),
    metavar="FILE",
    help="A mask image the page's recipes may name (repeatable); the files the --recipe "
    "names are allowed too, and no other file.",
)
@click.option(
    "--port", type=click.IntRange(0, 65535), default=0, help="Port (default: a free one)."
)
@click.option(
    "--host",
    default="127.0.0.1",
    show_default=True,
    help="Address to listen on (IPv4, or IPv6 such as ::1); anything but loopback makes "
    "the page reachable from other machines.",
)
@click.option("--no-browser", is_flag=True, help="Print the URL only; do not open a browser.")
def view(
    image: Path | None,
    recipe: Path | None,
    masks: tuple[Path, ...],
    port: int,
    host: str,
    no_browser: bool,
) -> None:
    """Show IMAGE (or a VIDEO, played) in the browser, with live conformal effects on
    the GPU.

    Drag a point to move the panorama by the Möbius map that takes it to the
    cursor (two pinned points stay fixed); Ctrl + wheel zooms conformally at
    the cursor. The page edits a recipe: save it, copy it as a command, or
    render it at full resolution with the Python renderer. Ctrl-C stops.
    """
    from ..errors import ImageFormatError
    from ..viewer.server import ViewerServer, is_loopback, url_host

    try:
        srv = ViewerServer(image, recipe, masks=masks, host=host, port=port)
    except ImageFormatError:  # an input that is not an image or a video: its own line
        raise
    except OSError as exc:
        raise click.BadParameter(
            f"cannot listen on {url_host(host.strip('[]'))}:{port}: {exc.strerror or exc}",
            param_hint="'--port'" if _port_problem(exc) else "'--host'",
        ) from None
    if not is_loopback(srv.host):
        click.echo(
            f"spherewarp: warning: listening on {srv.host}, not loopback: other machines can "
            f"reach this page; it answers to the host names {', '.join(srv.host_names)} "
            "(any other name is refused)",
            err=True,
        )
    click.echo(f"spherewarp view: {srv.url}  (Ctrl-C stops)", nl=True)
    if not no_browser:
        import webbrowser

        webbrowser.open(srv.url)
    try:
        srv.wait()
    finally:
        srv.close()
