"""``rend3r explore``: render programs in several uniform formats, score them against fp64,
cost each format, and write ``results.csv``, ``pareto.svg`` and ``summary.md``."""

from __future__ import annotations

import shlex
import sys
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING

import click

from ..campaign.options import SCHEDULER
from ..cliutil import JOBS, MAX_MEMORY, SIZE, default_memory
from ..errors import Rend3rError
from ..progress import Progress, quiet_option

if TYPE_CHECKING:
    from .campaign import ProgramSpec

DEFAULT_FORMATS = "fp16,bf16,tf32,fp24,fp32"


def parse_formats(ctx: click.Context, param: click.Parameter, value: str) -> list[str]:
    """Comma-separated format names, each checked (a bad one exits 2); repeats of a format dropped."""
    from ..emu.arith import precision_name

    names: dict[str, str] = {}  # canonical name -> the name as given (bf16 rather than e8m7)
    for text in value.split(","):
        try:
            name = precision_name(text.strip())
        except ValueError as exc:
            raise click.BadParameter(str(exc), ctx, param) from None
        names.setdefault(name, text.strip().lower())
    return list(names.values())


def load_spec(path: Path):
    """A program's words, mode and frame count (from its header, for source)."""
    from ..asm.formats.recognise import kind_by_name
    from ..emu import load_program
    from ..golden.catalog import read_header
    from .campaign import ProgramSpec

    loaded = load_program(path)
    header = read_header(path) if kind_by_name(path) == "source" else None
    mode = (header and header.mode) or loaded.mode_hint or "raytrace"
    return ProgramSpec(path.stem, tuple(loaded.words), mode, header.frames if header else 1)


@click.command("explore")
@click.argument("programs", nargs=-1, required=True, type=click.Path(path_type=Path, dir_okay=False),
                metavar="PROGRAM...")
@click.option("-o", "--output", "out_dir", type=click.Path(path_type=Path), required=True, metavar="DIR",
              help="Folder for results.csv, pareto.svg and summary.md (made if missing).")
@click.option("--formats", default=DEFAULT_FORMATS, show_default=True, callback=parse_formats, metavar="LIST",
              help="Comma-separated working formats: fp16, bf16, tf32, fp24, fp32, fp64 or any eEmM.")
@click.option("--subnormals", type=click.Choice(["ftz", "ieee"]), default="ftz", show_default=True,
              help="Subnormal handling of every format (fp32 and fp64 keep theirs).")
@click.option("--size", type=SIZE, default="256x192", show_default=True, help="Image size (1..8192 each).")
@click.option("--min-psnr", type=click.FloatRange(0), default=40.0, show_default=True, metavar="DB",
              help="PSNR against fp64 a format must reach to serve a program.")
@JOBS
@SCHEDULER
@MAX_MEMORY
@quiet_option
def explore_command(programs: tuple[Path, ...], out_dir: Path, formats: list[str], subnormals: str,
                    size: tuple[int, int], min_psnr: float, jobs: int, scheduler: str, max_memory: int | None,
                    quiet: bool) -> None:
    """Which uniform number format each PROGRAM needs, and what each format costs.

    Renders every program in every format of LIST and in fp64, scores each against
    fp64 (PSNR, largest channel difference, pixels whose nearest shape differs, all
    and off silhouettes), and costs each format as the units of the raytrace and
    raster datapaths times each unit's modelled LUT, FF and DSP48E1
    (docs/precision.md). Writes DIR/results.csv (a row per program and format),
    DIR/pareto.svg (LUTs against worst PSNR, the Pareto front joined) and
    DIR/summary.md (per program the cheapest format reaching --min-psnr, or none),
    all or nothing. The renders run as independent tasks on --scheduler
    (docs/campaigns.md); the results do not depend on where they ran.

    \b
    Example:
      rend3r explore programs/*.asm -o out/explore
      rend3r explore programs/shadow.asm -o out/e --formats e4m3,bf16,e6m9 --size 64x48
      rend3r explore programs/*.asm -o out/explore --scheduler tcp://10.0.0.5:8786
    """
    from ..campaign.runner import Campaign
    from ..fileio import Outputs
    from .campaign import REFERENCE, design_cost, render_and_score, render_design
    from .report import Results, pareto_svg, results_csv, summary_md

    width, height = size
    with Outputs() as out:
        files = {name: out.reserve(out_dir / name) for name in ("results.csv", "pareto.svg", "summary.md")}
        specs = [load_spec(p) for p in programs]
        if len({s.name for s in specs}) != len(specs):
            raise click.UsageError("two programs have the same name; results.csv keys rows by name")
        _check_memory(specs, width, height, scheduler, max_memory or default_memory())
        costs = {f: design_cost(f) for f in formats}
        options = {"subnormals": subnormals, "width": width, "height": height, "jobs": jobs}
        pairs = [(spec, f) for spec in specs for f in formats]
        with Campaign(scheduler) as campaign, Progress(len(specs) + len(pairs), "explore", quiet=quiet) as bar:
            references = campaign.map(partial(render_design, precision=REFERENCE, **options), [(s,) for s in specs],
                                      [f"{s.name} in {REFERENCE}" for s in specs], bar)
            reference = {s.name: r for s, r in zip(specs, references)}
            found = campaign.map(partial(render_and_score, **options), [(s, f, reference[s.name]) for s, f in pairs],
                                 [f"{s.name} in {f}" for s, f in pairs], bar)
        scores = {(s.name, f): score for (s, f), score in zip(pairs, found)}
        results = Results(specs, formats, scores, costs, min_psnr, subnormals, size)
        command = "rend3r " + shlex.join(sys.argv[1:]) if sys.argv[1:2] == ["explore"] else "rend3r explore ..."
        out.write(files["results.csv"], results_csv(results))
        out.write(files["pareto.svg"], pareto_svg(results))
        out.write(files["summary.md"], summary_md(results, command))
        out.commit()
    if not quiet:
        click.echo(f"explore: {len(specs)} program(s) x {len(formats)} format(s) at {width}x{height} -> {out_dir}")


def _check_memory(specs: list[ProgramSpec], width: int, height: int, scheduler: str, budget: int) -> None:
    """Refuse, before any rendering, a campaign estimated to exceed ``budget`` bytes here: the
    fp64 references kept for scoring (RGB565 and provenance, 6 bytes a pixel and frame), and
    on a local cluster one design's frames being rendered on every core at once."""
    from ..emu.budget import BASE, ENGINE, FRAME
    from ..emu.threads import available_cores

    pixels = width * height
    kept = sum(s.frames for s in specs) * pixels * 6
    render = max(ENGINE.get(s.mode, max(ENGINE.values())) + FRAME * s.frames for s in specs) * pixels
    renders = available_cores() if scheduler == "local" else 1
    need = BASE + kept + renders * render
    if need > budget:
        raise Rend3rError(f"explore at {width}x{height} needs about {need / 2**30:.2f} GiB here ({len(specs)} "
                          f"program(s), {renders} render(s) at once); the memory budget is {budget / 2**30:.2f} GiB "
                          "(--max-memory): use a smaller --size or fewer programs, or raise the budget")
