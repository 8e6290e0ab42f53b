"""The ``rend3r`` command line: a thin click group whose commands load on demand.

Each command lives in its concern's sub-package; this module imports it only when that
command runs, so ``rend3r --help`` and ``rend3r asm`` never pay for numpy-heavy or
scapy-heavy modules they do not use.
"""

from __future__ import annotations

import importlib
import signal
import sys
import threading
from contextlib import contextmanager
from typing import Iterator, NoReturn

import click

from . import __version__
from .errors import Rend3rError
from .memory import reuse_freed_memory

#: Exit status of a run stopped by Ctrl-C (128 + SIGINT, as shells report it), and by
#: SIGTERM (128 + 15).
INTERRUPTED, TERMINATED = 130, 143

#: command name -> ("module:attribute", one-line help shown by ``rend3r --help``)
COMMANDS: dict[str, tuple[str, str]] = {
    "emulate": ("rend3r.emu.cli:emulate_command", "Run a program and render its frames to PNG, GIF or APNG (float16 golden model)."),
    "device": ("rend3r.transport.cli:device_command", "Virtual device: receive programs over Ethernet or serial, render them to PNGs."),
    "send": ("rend3r.transport.cli:send_command", "Send a program to a device (Ethernet, serial) or a file (mem, coe, pcap)."),
    "compare": ("rend3r.golden.compare:compare_command", "Compare two images or RGB565 frame buffers by metrics."),
    "asm": ("rend3r.asm.cli_asm:asm_command", "Assemble a .asm source to mem, bin, coe, ihex or a listing."),
    "disasm": ("rend3r.asm.cli_disasm:disasm_command", "Disassemble a memory image (mem, bin, coe, ihex, lst) to source."),
    "render-all": ("rend3r.golden.render_all:render_all_command", "Render every example program to PNGs in a folder."),
    "trace-diff": ("rend3r.emu.trace_diff:trace_diff_command", "Compare two float16 pixel traces; report the first divergence."),
    "explore": ("rend3r.explore.cli:explore_command", "Which uniform number format each program needs, and its hardware cost."),
    "svo": ("rend3r.svo.cli:svo_group", "Sparse voxel octrees: build from meshes, trace in 16.16 fixed point, sweep cache/core designs."),
    "view": ("rend3r.view.cli:view_command", "Inspect a program in the browser: frames, pixel history, live reload."),
}


def interrupted() -> NoReturn:
    """Ctrl-C: say so on stderr and exit 130, without a traceback."""
    click.echo("\nrend3r: interrupted", err=True)
    sys.exit(INTERRUPTED)


class Terminated(KeyboardInterrupt):
    """SIGTERM (kill, a service manager, a CI timeout): unwinds the run as Ctrl-C does,
    so that its staged outputs are removed and nothing is left half-written."""


def _terminate(signum: int, frame: object) -> None:
    raise Terminated


@contextmanager
def _sigterm_unwinds() -> Iterator[None]:
    """While a command runs in the main thread, SIGTERM raises Terminated there (its
    default would end the process at once, leaving staged files behind)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGTERM, _terminate)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


class LazyGroup(click.Group):
    """A click group that imports a command's module only when the command is used."""

    def list_commands(self, ctx: click.Context) -> list[str]:
        return sorted(COMMANDS)

    def get_command(self, ctx: click.Context, name: str) -> click.Command | None:
        if name not in COMMANDS:
            return None
        target, _ = COMMANDS[name]
        module_name, attr = target.split(":")
        try:
            module = importlib.import_module(module_name)
        except KeyboardInterrupt:  # Ctrl-C while the command loads: nothing has run yet
            interrupted()
        return getattr(module, attr)

    def invoke(self, ctx: click.Context):
        reuse_freed_memory()  # the renderers' temporaries: see rend3r/memory.py
        try:
            with _sigterm_unwinds():
                return super().invoke(ctx)
        except Terminated:  # the run's outputs were never committed
            click.echo("\nrend3r: terminated", err=True)
            ctx.exit(TERMINATED)
        except Rend3rError as exc:
            click.echo(str(exc) if exc.preformatted else f"rend3r: error: {exc}", err=True)
            ctx.exit(exc.exit_code)
        except MemoryError as exc:  # past what --max-memory estimated: the limit is the machine's
            detail = f" ({exc})" if str(exc) else ""
            click.echo(f"rend3r: error: out of memory{detail}: lower the work (pixels, frames, shapes) or free "
                       "memory; --max-memory refuses such runs before they start when its estimate sees them",
                       err=True)
            ctx.exit(1)
        except KeyboardInterrupt:  # Ctrl-C: the run's outputs were never committed
            interrupted()

    def format_commands(self, ctx: click.Context, formatter: click.HelpFormatter) -> None:
        rows = [(name, COMMANDS[name][1]) for name in self.list_commands(ctx)]
        if rows:
            with formatter.section("Commands"):
                formatter.write_dl(rows)


@click.group(cls=LazyGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="rend3r")
def main() -> None:
    """Toolchain for the REND3R graphics ISA and rendering device.

    \b
    Example:
      rend3r asm programs/sphere.asm -o sphere.mem
      rend3r emulate programs/sphere.asm -o sphere.png
    """
