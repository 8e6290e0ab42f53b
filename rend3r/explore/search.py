"""``rend3r explore --search``: which stage of the raytrace datapath needs the bits.

Greedy per-stage narrowing. Every stage starts at the first format of a ladder (widest
first), and so does the base format, which the rasterizer's datapath works in (the part
named ``raster``); each round tries every part one rung narrower, renders every program with each
such design, and takes the one that saves the most modelled LUTs per dB of worst PSNR
lost among those that keep every program at the bound or above; the search ends when no
stage can narrow. Every design visited is scored, so per program the cheapest visited
design meeting the bound is known too.

A design is named ``BASE`` (uniform) or ``BASE:STAGE=FORMAT+STAGE=FORMAT`` (stages
differing from the base), which :func:`split_design` reads back.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from itertools import pairwise

from ..precision.datapath import Resources
from ..precision.stages import STAGES, parse_stage_map
from .campaign import Score, cheapest, worst_psnr
from .report import Results, decibels, summary_header

#: What the search narrows: the base format (the rasterizer's datapath) and each stage.
PARTS: tuple[str, ...] = ("raster", *STAGES)
#: A PSNR of inf (identical to fp64) counts as this many dB when losses are compared.
PSNR_CAP = 150.0


def design_name(base: str, stages: dict[str, str]) -> str:
    """``BASE`` or ``BASE:STAGE=FORMAT+...`` (stages in the base format left out, stage order)."""
    differing = [f"{s}={stages[s]}" for s in STAGES if stages.get(s, base) != base]
    return base + (":" + "+".join(differing) if differing else "")


def split_design(design: str) -> tuple[str, tuple[tuple[str, str], ...]]:
    """(base precision, stage map) of a design name (ValueError when malformed)."""
    from ..emu.arith import precision_name

    base, colon, rest = design.partition(":")
    if colon and not rest:
        raise ValueError(f"design {design[:40]!r}: expected BASE:STAGE=FORMAT[+STAGE=FORMAT...]")
    return precision_name(base), parse_stage_map(rest.replace("+", ",")) if rest else ()


@dataclass(frozen=True)
class Step:
    """One round of the search: the design taken, the stage narrowed (None: the start)."""

    design: str
    stage: str | None
    worst_psnr: float
    cost: Resources


#: Renders and scores designs: [design, ...] -> {design: [score per program]}.
Evaluate = Callable[[list[str]], dict[str, list[Score]]]


def _capped(psnr: float) -> float:
    return min(psnr, PSNR_CAP)


def greedy(ladder: list[str], min_psnr: float, evaluate: Evaluate, cost: Callable[[str], Resources]) -> list[Step]:
    """The search's path, from the uniform first rung to the last design taken."""
    rung = dict.fromkeys(PARTS, 0)

    def narrowed_in(narrowed: str) -> str:
        at = {part: ladder[r + (part == narrowed)] for part, r in rung.items()}
        return design_name(at.pop("raster"), at)

    current = design_name(ladder[0], {})
    worst = worst_psnr(evaluate([current])[current])
    path = [Step(current, None, worst, cost(current))]
    while True:
        tries = {narrowed_in(part): part for part, r in rung.items() if r + 1 < len(ladder)}
        if not tries:
            return path
        scores = evaluate(list(tries))
        best, best_key = None, None
        for design, stage in tries.items():
            w = worst_psnr(scores[design])
            if w < min_psnr:
                continue
            saved = path[-1].cost.lut - cost(design).lut
            key = (saved / max(_capped(worst) - _capped(w), 0.01), w, -PARTS.index(stage))
            if best_key is None or key > best_key:
                best, best_key = design, key
        if best is None:
            return path
        rung[tries[best]] += 1
        worst = worst_psnr(scores[best])
        path.append(Step(best, tries[best], worst, cost(best)))


def check_ladder(names: list[str], cost: Callable[[str], Resources]) -> None:
    """ValueError unless the ladder has two or more formats, each cheaper (fewer LUTs) than the one before."""
    if len(names) < 2:
        raise ValueError("the ladder needs at least two formats, widest first")
    for wide, narrow in pairwise(names):
        if not cost(narrow).lut < cost(wide).lut:
            raise ValueError(f"{narrow} does not cost fewer LUTs than {wide}: give the ladder widest first")


def search_summary(path: list[Step], r: Results, ladder: list[str], command: str) -> bytes:
    """summary.md of a search: the path, the design found, per program the cheapest design
    visited that meets the bound and the cheapest uniform rung that does."""
    title = f"rend3r explore --search: {len(r.programs)} program(s), {len(r.formats)} design(s) rendered"
    conditions = (f"ladder {', '.join(ladder)}; bound {r.min_psnr:g} dB on every program. Cost: the raytrace "
                  "datapath's units per stage in each stage's format plus the raster datapath's in the base format "
                  "(`rend3r.precision.datapath`), times each unit's modelled cost (`rend3r.precision.cost`).")
    lines = [*summary_header(r, title, command, conditions), "## The search, round by round", "",
             "| round | stage narrowed | design | worst PSNR (dB) | LUT | FF | DSP48E1 |",
             "|---:|---|---|---:|---:|---:|---:|"]
    for k, step in enumerate(path):
        c = step.cost
        lines.append(f"| {k} | {step.stage or '(start)'} | `{step.design}` | {decibels(step.worst_psnr)} | {c.lut:,} | "
                     f"{c.ff:,} | {c.dsp:,} |")
    final = path[-1]
    everywhere = cheapest({d: min(r.of_format(d), key=lambda s: s.psnr) for d in r.formats}, r.costs, r.min_psnr)
    lines += ["", (f"Found: `{final.design}`, {final.cost.lut:,} LUTs ({final.cost.lut / path[0].cost.lut:.0%} of "
                   f"the uniform start), worst PSNR {decibels(final.worst_psnr)} dB. The cheapest design visited "
                   f"that meets the bound on every program: `{everywhere}`"
                   + (f", {r.costs[everywhere].lut:,} LUTs." if everywhere else ".")), "", "## Per program", "",
              (f"| program | cheapest design meeting {r.min_psnr:g} dB | its PSNR | LUT | cheapest uniform rung | "
               "its LUT |"), "|---|---|---:|---:|---|---:|"]
    for p in r.programs:
        best = cheapest(r.of_program(p), r.costs, r.min_psnr)
        flat = cheapest({f: r.scores[p.name, f] for f in ladder}, r.costs, r.min_psnr)
        mine = f"`{best}` | {decibels(r.scores[p.name, best].psnr)} | {r.costs[best].lut:,}" if best else "none | | "
        lines.append(f"| {p.name} | {mine} | {flat or 'none'} | {f'{r.costs[flat].lut:,}' if flat else ''} |")
    return ("\n".join(lines) + "\n").encode()
