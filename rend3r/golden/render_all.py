"""``rend3r render-all``: render every example program's frames to PNG files."""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

import click

from ..cliutil import JOBS, PRECISION, SIZE
from ..errors import Rend3rError
from .catalog import ExampleProgram, program_paths, read_header

if TYPE_CHECKING:
    from ..emu import EmuOptions, Frame


def render_example(program: ExampleProgram, options: EmuOptions) -> list[Frame]:
    """Assemble/load ``program`` and render its frames (RGB565, depth, provenance).

    The mode comes from the program's header, else from the emulator's hint (``tr`` in the
    source means raster), else ``options.mode``.
    """
    from ..emu import load_program, run_program

    loaded = load_program(program.path)
    mode = program.mode or loaded.mode_hint or options.mode
    result = run_program(loaded.words, options=replace(options, mode=mode), frames=program.frames)
    if len(result.frames) != program.frames:
        raise Rend3rError(f"{program.path}: rendered {len(result.frames)} frame(s), header says frames: {program.frames}")
    return list(result.frames)


def render_all(
    programs_dir: Path, out_dir: Path, options: EmuOptions, echo: Callable[[str], None] = print
) -> list[str]:
    """Render every program in ``programs_dir`` to ``out_dir/<name>[.NNN].png``.

    Prints one progress line per program; a program that fails is reported and skipped.
    Returns the names of the programs that failed.
    """
    from ..emu.image import save_png
    from ..fileio import make_output_folder

    paths = program_paths(programs_dir)
    if not paths:
        raise Rend3rError(f"no *.asm programs in {programs_dir}")
    make_output_folder(out_dir)
    failed: list[str] = []
    for n, path in enumerate(paths, 1):
        prefix = f"[{n}/{len(paths)}] {path.stem}:"
        start = time.perf_counter()
        try:
            program = read_header(path)
            frames = render_example(program, options)
            for i, frame in enumerate(frames):
                save_png(frame.rgb565, out_dir / f"{program.frame_name(i)}.png")
        except Rend3rError as exc:
            echo(f"{prefix} FAILED: {exc}")
            failed.append(path.stem)
            continue
        elapsed = time.perf_counter() - start
        plural = "s" if len(frames) != 1 else ""
        echo(
            f"{prefix} {len(frames)} frame{plural} {options.width}x{options.height} "
            f"{options.arith.label} in {elapsed:.2f} s -> {out_dir / program.frame_name(0)}.png"
            + (" ..." if len(frames) > 1 else "")
        )
    return failed


@click.command("render-all")
@click.argument("programs_dir", type=click.Path(path_type=Path, file_okay=False), default="programs")
@click.option("-o", "--output", "out_dir", type=click.Path(path_type=Path), required=True, metavar="DIR",
              help="Folder for the PNGs (made if missing).")
@PRECISION
@click.option("--subnormals", type=click.Choice(["ftz", "ieee"]), default="ftz", show_default=True, help="fp16 subnormal handling.")
@click.option("--size", type=SIZE, default="512x384", show_default=True, help="Image size (1..8192 each).")
@JOBS
def render_all_command(programs_dir: Path, out_dir: Path, precision: str, subnormals: str, size: tuple[int, int],
                       jobs: int) -> None:
    """Render every PROGRAMS_DIR/*.asm (default: programs) to PNGs in folder DIR.

    Each program's header sets its frame count (``; frames: N``) and mode. Files are
    named after the program, with the frame number for animations
    (``animation.000.png``). A program that fails (a bad header, an error while
    rendering or writing) is reported and the others still render; exit status 1 then.

    \b
    Example:
      rend3r render-all programs -o out/renders --precision fp32
    """
    from ..emu import EmuOptions

    if not programs_dir.is_dir():
        raise Rend3rError(f"{programs_dir} is not a folder")
    width, height = size
    options = EmuOptions(precision=precision, subnormals=subnormals, width=width, height=height, jobs=jobs)
    failed = render_all(programs_dir, out_dir, options, echo=click.echo)
    if failed:
        raise Rend3rError(f"{len(failed)} program(s) failed: {', '.join(failed)}")
