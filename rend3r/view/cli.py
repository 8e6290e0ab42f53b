"""``rend3r view``: serve the inspector of one program on a local web server."""

from __future__ import annotations

import click

from ..errors import Rend3rError
from .params import MAX_FRAMES

_EPILOG = """\b
Examples:
  rend3r view programs/shadow.asm                 # then open the URL it prints
  rend3r view programs/animation.asm --frames 8 --port 8800 --open
  rend3r view out/torus.svo                       # render, cost image, a ray's traversal
  rend3r view programs/sphere.asm --host 0.0.0.0  # reachable from other machines, with a token
"""


@click.command("view", epilog=_EPILOG)
@click.argument("program", type=click.Path(dir_okay=False))
@click.option("--port", type=click.IntRange(0, 65535), default=8765, show_default=True, metavar="N",
              help="TCP port to listen on (0: any free port).")
@click.option("--host", default="127.0.0.1", show_default=True, metavar="H",
              help="Address to bind. Anything but loopback makes every URL need the random token printed.")
@click.option("--frames", type=click.IntRange(1, MAX_FRAMES), default=64, show_default=True, metavar="N",
              help=f"Show at most N frames (a looping program shows N; 1..{MAX_FRAMES}).")
@click.option("--open", "open_browser", is_flag=True, help="Open the page in the default web browser.")
def view_command(program: str, port: int, host: str, frames: int, open_browser: bool) -> None:
    """Inspect PROGRAM (source, memory image or .svo) in a web browser: its frame in any
    precision beside fp64 and their difference, a clicked pixel's history stage by stage,
    and the frame again each time the source (or a file it includes) is saved.

    Stops with Ctrl-C. Nothing is written; see docs/view.md for the JSON endpoints.
    """
    import asyncio

    try:
        import tornado  # noqa: F401
    except ImportError:
        raise Rend3rError("rend3r view needs Tornado: pip install 'rend3r[view]'") from None
    from pathlib import Path

    from .server import serve

    if not Path(program).is_file():
        raise Rend3rError(f"{program}: no such file")

    def ready(url: str, state: dict) -> None:
        click.echo(f"rend3r view: serving {program} at {url}  (Ctrl-C stops)")
        if not state["loaded"]:
            click.echo(state["message"], err=True)
        if open_browser:
            import webbrowser

            webbrowser.open(url)

    try:
        asyncio.run(serve(program, host, port, frames, ready))
    except OSError as exc:
        raise Rend3rError(f"cannot listen on {host}:{port}: {exc.strerror or exc}") from None
