"""``rend3r render-all``: render every example program's frames to PNG files."""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING

import click

from ..campaign.options import SCHEDULER
from ..cliutil import JOBS, PRECISION, SIZE, STAGE_PRECISION
from ..errors import Rend3rError
from ..progress import Progress, ProgressFactory, hidden, quiet_option
from .catalog import ExampleProgram, program_paths, read_header

if TYPE_CHECKING:
    from ..emu import EmuOptions, Frame


@dataclass(frozen=True)
class LoadedExample:
    """A program read and assembled, with the options it renders with: all a render needs."""

    program: ExampleProgram
    words: tuple[int, ...]
    options: EmuOptions


def load_example(program: ExampleProgram, options: EmuOptions) -> LoadedExample:
    """Assemble/load ``program``. The mode comes from the program's header, else from the
    emulator's hint (``tr`` in the source means raster), else ``options.mode``."""
    from ..emu import load_program

    loaded = load_program(program.path)
    mode = program.mode or loaded.mode_hint or options.mode
    return LoadedExample(program, tuple(loaded.words), replace(options, mode=mode))


def render_loaded(example: LoadedExample) -> list[Frame]:
    """Render a loaded program's frames (RGB565, depth, provenance); as many as its header says."""
    from ..emu import run_program

    program = example.program
    result = run_program(list(example.words), options=example.options, frames=program.frames)
    if len(result.frames) != program.frames:
        raise Rend3rError(f"{program.path}: rendered {len(result.frames)} frame(s), header says frames: {program.frames}")
    return list(result.frames)


def render_example(program: ExampleProgram, options: EmuOptions) -> list[Frame]:
    """Assemble/load ``program`` and render its frames (:func:`load_example`, :func:`render_loaded`)."""
    return render_loaded(load_example(program, options))


@dataclass(frozen=True)
class Rendered:
    """One program's outcome: its frames as PNG files (name -> bytes) or why it failed."""

    pngs: dict[str, bytes]
    seconds: float
    error: str | None = None


def read_example(path: Path, options: EmuOptions) -> LoadedExample | Rendered:
    """``path``'s header and words, or the failed outcome when either is wrong."""
    try:
        return load_example(read_header(path), options)
    except Rend3rError as exc:
        return Rendered({}, 0.0, str(exc))


def render_to_pngs(example: LoadedExample) -> Rendered:
    """The campaign task of ``render-all``: render a loaded program and encode each frame as
    a PNG in memory; a Rend3rError is the outcome, not raised, so one program that cannot
    be rendered does not stop the others."""
    from ..emu.image import save_png

    start = time.perf_counter()
    pngs: dict[str, bytes] = {}
    try:
        for i, frame in enumerate(render_loaded(example)):
            save_png(frame.rgb565, Path(f"{example.program.frame_name(i)}.png"),
                     sink=lambda p, data: pngs.__setitem__(p.name, bytes(data)))
    except Rend3rError as exc:
        return Rendered({}, time.perf_counter() - start, str(exc))
    return Rendered(pngs, time.perf_counter() - start)


def render_all(programs_dir: Path, out_dir: Path, options: EmuOptions, scheduler: str = "none",
               echo: Callable[[str], None] = print, progress: ProgressFactory = hidden) -> list[str]:
    """Render every program in ``programs_dir`` to ``out_dir/<name>[.NNN].png``.

    The programs are read and assembled here and render as tasks on ``scheduler``
    (:class:`rend3r.campaign.runner.Campaign`), so workers need no files; then one line per program is printed, in name order, a program that failed is reported,
    and the others' PNGs are written together (:class:`rend3r.fileio.Outputs`). Returns the
    names of the programs that failed.
    """
    from ..campaign.runner import Campaign
    from ..fileio import Outputs, make_output_folder

    paths = program_paths(programs_dir)
    if not paths:
        raise Rend3rError(f"no *.asm programs in {programs_dir}")
    make_output_folder(out_dir)  # an unwritable folder is refused before any work
    examples = [read_example(p, options) for p in paths]
    loaded = [e for e in examples if isinstance(e, LoadedExample)]
    with Campaign(scheduler) as campaign, progress(len(loaded), "render-all") as bar:
        rendered = iter(campaign.map(render_to_pngs, [(e,) for e in loaded], [e.program.name for e in loaded], bar))
    outcomes = [next(rendered) if isinstance(e, LoadedExample) else e for e in examples]
    with Outputs() as out:
        failed: list[str] = []
        for n, (path, outcome) in enumerate(zip(paths, outcomes), 1):
            prefix = f"[{n}/{len(paths)}] {path.stem}:"
            if outcome.error is not None:
                echo(f"{prefix} FAILED: {outcome.error}")
                failed.append(path.stem)
                continue
            for name, data in outcome.pngs.items():
                out.write(out_dir / name, data)
            first, frames = next(iter(outcome.pngs)), len(outcome.pngs)
            echo(f"{prefix} {frames} frame{'s' if frames != 1 else ''} {options.width}x{options.height} "
                 f"{options.arith.label} in {outcome.seconds:.2f} s -> {out_dir / first}" + (" ..." if frames > 1 else ""))
        out.commit()
    return failed


@click.command("render-all")
@click.argument("programs_dir", type=click.Path(path_type=Path, file_okay=False), default="programs")
@click.option("-o", "--output", "out_dir", type=click.Path(path_type=Path), required=True, metavar="DIR",
              help="Folder for the PNGs (made if missing).")
@PRECISION
@STAGE_PRECISION
@click.option("--subnormals", type=click.Choice(["ftz", "ieee"]), default="ftz", show_default=True, help="fp16 subnormal handling.")
@click.option("--size", type=SIZE, default="512x384", show_default=True, help="Image size (1..8192 each).")
@JOBS
@SCHEDULER
@quiet_option
def render_all_command(programs_dir: Path, out_dir: Path, precision: str,
                       stage_precision: tuple[tuple[str, str], ...] | None, subnormals: str, size: tuple[int, int],
                       jobs: int, scheduler: str, quiet: bool) -> None:
    """Render every PROGRAMS_DIR/*.asm (default: programs) to PNGs in folder DIR.

    Each program's header sets its frame count (``; frames: N``) and mode. Files are
    named after the program, with the frame number for animations
    (``animation.000.png``). A program that fails (a bad header, an error while
    rendering) is reported and the others still render; exit status 1 then. The
    programs render as independent tasks on --scheduler (docs/campaigns.md); the PNGs
    are written together once every program has rendered.

    \b
    Example:
      rend3r render-all programs -o out/renders --precision fp32
      rend3r render-all programs -o out/renders --scheduler tcp://10.0.0.5:8786
    """
    from ..emu import EmuOptions

    if not programs_dir.is_dir():
        raise Rend3rError(f"{programs_dir} is not a folder")
    width, height = size
    options = EmuOptions(precision=precision, stage_precision=stage_precision or (), subnormals=subnormals,
                         width=width, height=height, jobs=jobs)
    failed = render_all(programs_dir, out_dir, options, scheduler, echo=click.echo,
                        progress=partial(Progress, quiet=quiet))
    if failed:
        raise Rend3rError(f"{len(failed)} program(s) failed: {', '.join(failed)}")
