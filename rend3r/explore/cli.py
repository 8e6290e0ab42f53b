"""``rend3r explore``: render programs in several designs (uniform formats, or formats per
stage), or search per-stage formats greedily (``--search``); score against fp64, cost each
design, and write ``results.csv``, ``pareto.svg`` and ``summary.md``."""

from __future__ import annotations

import shlex
import sys
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING

import click

from ..campaign.options import SCHEDULER
from ..cliutil import JOBS, MAX_MEMORY, SIZE, default_memory, finite
from ..errors import Rend3rError
from ..progress import Progress, quiet_option

if TYPE_CHECKING:
    from .campaign import ProgramSpec, Score

DEFAULT_FORMATS = "fp16,bf16,tf32,fp24,fp32"
#: --search's default ladder, each format cheaper in every operator than the one before, all
#: with fp32's exponent range (so every design is culled: docs/precision.md section 7).
DEFAULT_LADDER = "fp32,e8m16,e8m13,tf32"


def parse_formats(ctx: click.Context, param: click.Parameter, value: str) -> list[str]:
    """Comma-separated designs (a format, or ``BASE:STAGE=FORMAT+...``), each checked (a bad
    one exits 2); repeats of a design dropped."""
    from .search import design_name, split_design

    names: dict[tuple, str] = {}  # canonical design -> the name as given (bf16 rather than e8m7)
    for text in value.split(","):
        try:
            base, stages = split_design(text.strip().lower())
        except ValueError as exc:
            raise click.BadParameter(str(exc), ctx, param) from None
        shown = text.strip().lower()
        names.setdefault((base, stages), shown if not stages else design_name(shown.partition(":")[0], dict(stages)))
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
              help="Comma-separated designs: a working format (fp16, bf16, tf32, fp24, fp32, fp64 or any eEmM), or "
                   "a base with formats per stage, BASE:STAGE=FORMAT+STAGE=FORMAT (fp32:sqrt=fp16+hit=bf16).")
@click.option("--search", is_flag=True,
              help="Greedy per-stage narrowing down --ladder while every program keeps --min-psnr "
                   "(instead of --formats; docs/precision.md section 7).")
@click.option("--ladder", default=DEFAULT_LADDER, show_default=True, callback=parse_formats, metavar="LIST",
              help="--search: the formats a stage may take, widest first, each cheaper than the one before.")
@click.option("--subnormals", type=click.Choice(["ftz", "ieee"]), default="ftz", show_default=True,
              help="Subnormal handling of every format (fp32 and fp64 keep theirs).")
@click.option("--size", type=SIZE, default="256x192", show_default=True, help="Image size (1..8192 each).")
@click.option("--min-psnr", type=float, callback=finite(0, 1000), default=40.0, show_default=True, metavar="DB",
              help="PSNR against fp64 a format must reach to serve a program.")
@JOBS
@SCHEDULER
@MAX_MEMORY
@quiet_option
def explore_command(programs: tuple[Path, ...], out_dir: Path, formats: list[str], search: bool, ladder: list[str],
                    subnormals: str, size: tuple[int, int], min_psnr: float, jobs: int, scheduler: str,
                    max_memory: int | None, quiet: bool) -> None:
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

    With --search, the designs are found instead of given: every stage of the raytrace
    datapath, and the base format the rasterizer works in, starts at the ladder's first
    format, and round by round the part whose narrowing saves the most LUTs per dB of
    worst PSNR lost (every program staying at --min-psnr) narrows one rung, until none
    can; summary.md shows the path and per program the cheapest design visited that
    meets the bound.

    \b
    Example:
      rend3r explore programs/*.asm -o out/explore
      rend3r explore programs/shadow.asm -o out/e --formats e4m3,bf16,e6m9 --size 64x48
      rend3r explore programs/*.asm -o out/s --search --min-psnr 40 --size 64x48
      rend3r explore programs/*.asm -o out/explore --scheduler tcp://10.0.0.5:8786
    """
    from ..campaign.runner import Campaign
    from ..fileio import Outputs
    from .campaign import REFERENCE, batches, design_cost, render_design, score_designs
    from .report import Results, pareto_svg, results_csv, summary_md
    from .search import check_ladder, greedy, search_summary

    width, height = size
    ctx = click.get_current_context()
    if search and ctx.get_parameter_source("formats") is not click.core.ParameterSource.DEFAULT:
        raise click.UsageError("--search finds the designs: give --ladder, not --formats")
    if search:
        try:
            check_ladder(ladder, design_cost)
        except ValueError as exc:
            raise click.BadParameter(str(exc), ctx, param_hint="--ladder") from None
    with Outputs() as out:
        files = {name: out.reserve(out_dir / name) for name in ("results.csv", "pareto.svg", "summary.md")}
        specs = [load_spec(p) for p in programs]
        if len({s.name for s in specs}) != len(specs):
            raise click.UsageError("two programs have the same name; results.csv keys rows by name")
        _check_memory(specs, width, height, scheduler, max_memory or default_memory())
        options = {"subnormals": subnormals, "width": width, "height": height, "jobs": jobs}
        scores: dict[tuple[str, str], Score] = {}
        with Campaign(scheduler) as campaign:
            with Progress(len(specs), "explore: fp64", quiet=quiet) as bar:  # kept on the workers that render them
                references = campaign.map(partial(render_design, precision=REFERENCE, **options),
                                          [(s,) for s in specs], [f"{s.name} in {REFERENCE}" for s in specs], bar,
                                          keep=True)
            reference = {s.name: r for s, r in zip(specs, references)}

            def evaluate(designs: list[str]) -> dict[str, list[Score]]:
                """Every program in every design not scored yet; the scores of ``designs``."""
                tasks = batches([(s, d) for d in dict.fromkeys(designs) for s in specs if (s.name, d) not in scores],
                                width * height)
                with Progress(len(tasks), "explore", quiet=quiet) as bar:
                    found = campaign.map(partial(score_designs, **options),
                                         [(s, ds, reference[s.name]) for s, ds in tasks],
                                         [f"{s.name} in {', '.join(ds)}" for s, ds in tasks], bar)
                scores.update(((s.name, d), score) for (s, ds), batch in zip(tasks, found) for d, score in zip(ds, batch))
                return {d: [scores[s.name, d] for s in specs] for d in designs}

            if search:
                evaluate(ladder)  # the uniform rungs, for comparison
                path = greedy(ladder, min_psnr, evaluate, design_cost)
            else:
                evaluate(formats)
        designs = list(dict.fromkeys(d for _, d in scores))
        costs = {d: design_cost(d) for d in designs}
        results = Results(specs, designs, scores, costs, min_psnr, subnormals, size)
        command = "rend3r " + shlex.join(sys.argv[1:]) if sys.argv[1:2] == ["explore"] else "rend3r explore ..."
        if search:
            summary = search_summary(path, results, ladder, command)
        else:
            summary = summary_md(results, command)
        out.write(files["results.csv"], results_csv(results))
        out.write(files["pareto.svg"], pareto_svg(results))
        out.write(files["summary.md"], summary)
        out.commit()
    if not quiet:
        click.echo(f"explore: {len(specs)} program(s) x {len(designs)} design(s) at {width}x{height} -> {out_dir}")


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
