"""The outputs of ``rend3r explore``: ``results.csv``, ``pareto.svg`` and ``summary.md``,
each made as bytes (the command writes them all or none)."""

from __future__ import annotations

import csv
import io
import math
from dataclasses import dataclass
from xml.sax.saxutils import escape

from ..precision.datapath import Resources
from .campaign import ProgramSpec, Score, cheapest, worst_psnr

#: Above this many designs, pareto.svg names only the front's points (each point's name is its tooltip).
MAX_LABELS = 12
COLUMNS = ("program", "mode", "frames", "format", "subnormals", "psnr_db", "max_channel", "differing_share",
           "provenance_share", "interior_provenance_share", "lut", "ff", "dsp", "meets_min_psnr")


@dataclass(frozen=True)
class Results:
    """Every score of a campaign, with what it was run with."""

    programs: list[ProgramSpec]
    formats: list[str]
    scores: dict[tuple[str, str], Score]  # (program name, format) -> score against fp64
    costs: dict[str, Resources]
    min_psnr: float
    subnormals: str
    size: tuple[int, int]

    def of_format(self, fmt: str) -> list[Score]:
        return [self.scores[p.name, fmt] for p in self.programs]

    def of_program(self, program: ProgramSpec) -> dict[str, Score]:
        return {f: self.scores[program.name, f] for f in self.formats}


def decibels(value: float) -> str:
    return "inf" if math.isinf(value) else f"{value:.2f}"


def results_csv(r: Results) -> bytes:
    """One row per program and format."""
    out = io.StringIO()
    w = csv.writer(out, lineterminator="\n")
    w.writerow(COLUMNS)
    for p in r.programs:
        for f in r.formats:
            s, c = r.scores[p.name, f], r.costs[f]
            w.writerow([p.name, p.mode, p.frames, f, r.subnormals, decibels(s.psnr), s.max_channel, f"{s.differing:.6f}",
                        f"{s.provenance:.6f}", f"{s.interior_provenance:.6f}", c.lut, c.ff, c.dsp,
                        int(s.psnr >= r.min_psnr)])
    return out.getvalue().encode()


def pareto_front(points: dict[str, tuple[Resources, float]]) -> list[str]:
    """The formats no other format beats in both cost and worst PSNR, cheapest first."""
    front: list[str] = []
    for f in sorted(points, key=lambda f: (points[f][0].key, -points[f][1])):
        if not front or points[f][1] > points[front[-1]][1]:
            front.append(f)
    return front


def pareto_svg(r: Results) -> bytes:
    """Cost (LUTs) against worst PSNR over the programs, one point per format, the front joined."""
    points = {f: (r.costs[f], worst_psnr(r.of_format(f))) for f in r.formats}
    finite = [v for _, v in points.values() if math.isfinite(v)] or [0.0]
    lo, hi = min(finite + [r.min_psnr]) - 5, max(finite + [r.min_psnr]) + 5
    top = hi + 5  # where "identical to fp64" (inf) is drawn
    luts = [c.lut for c, _ in points.values()]
    x0, x1 = 0, max(luts) * 1.1
    W, H, L, R, T, B = 640, 420, 70, 30, 30, 50

    def x(v: float) -> float:
        return L + (v - x0) / (x1 - x0) * (W - L - R)

    def y(v: float) -> float:
        return T + (top - min(v, top)) / (top - lo) * (H - T - B)

    parts = [(f'<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" font-family="sans-serif" '
             f'font-size="12">'),
             f'<rect width="{W}" height="{H}" fill="white"/>',
             f'<line x1="{L}" y1="{H - B}" x2="{W - R}" y2="{H - B}" stroke="black"/>',
             f'<line x1="{L}" y1="{T}" x2="{L}" y2="{H - B}" stroke="black"/>',
             (f'<text x="{(L + W - R) / 2}" y="{H - 12}" text-anchor="middle">modelled LUTs (raytrace + raster '
             f'datapaths)</text>'),
             (f'<text x="16" y="{(T + H - B) / 2}" text-anchor="middle" transform="rotate(-90 16 '
             f'{(T + H - B) / 2})">worst PSNR over the programs (dB)</text>')]
    step = 10 ** max(0, math.floor(math.log10(max(x1, 1))))
    while x1 / step < 4 and step >= 2:
        step //= 2
    for k in range(int(x1 // step) + 1):
        parts.append(f'<text x="{x(k * step):.1f}" y="{H - B + 16}" text-anchor="middle">{k * step:,}</text>')
    for v in range(int(math.ceil(lo / 10) * 10), int(hi) + 1, 10):
        parts.append(f'<text x="{L - 6}" y="{y(v) + 4:.1f}" text-anchor="end">{v}</text>')
    parts.append(f'<text x="{L - 6}" y="{y(top) + 4:.1f}" text-anchor="end">= fp64</text>')
    parts.append(f'<line x1="{L}" y1="{y(r.min_psnr):.1f}" x2="{W - R}" y2="{y(r.min_psnr):.1f}" stroke="grey" '
                 f'stroke-dasharray="4 4"/>')
    parts.append(f'<text x="{W - R}" y="{y(r.min_psnr) - 4:.1f}" text-anchor="end" fill="grey">--min-psnr '
                 f'{r.min_psnr:g}</text>')
    front = pareto_front(points)
    line = " ".join(f"{x(points[f][0].lut):.1f},{y(points[f][1]):.1f}" for f in front)
    parts.append(f'<polyline points="{line}" fill="none" stroke="steelblue" stroke-width="2"/>')
    labelled = set(front) if len(points) > MAX_LABELS else set(points)  # a search's many designs: the front's
    for f, (c, psnr) in points.items():
        colour = "steelblue" if f in front else "grey"
        parts.append(f'<circle cx="{x(c.lut):.1f}" cy="{y(psnr):.1f}" r="4" fill="{colour}"><title>{escape(f)}'
                     '</title></circle>')
        if f in labelled:
            parts.append(f'<text x="{x(c.lut) + 6:.1f}" y="{y(psnr) - 6:.1f}">{escape(f)}</text>')
    parts.append("</svg>\n")
    return "\n".join(parts).encode()


def summary_header(r: Results, title: str, command: str, conditions: str) -> list[str]:
    """The opening lines of a summary.md: title, command, size, subnormals and ``conditions``."""
    w, h = r.size
    return [f"# {title}", "", f"`{command}`", "", f"{w}x{h}, subnormals {r.subnormals}, scored against fp64; {conditions}",
            ""]


def summary_md(r: Results, command: str) -> bytes:
    """Per program the cheapest format meeting the bound, then per format its cost."""
    title = f"rend3r explore: {len(r.programs)} program(s) x {len(r.formats)} format(s)"
    conditions = (f"a format meets the bound when its PSNR is at least {r.min_psnr:g} dB. Cost: the raytrace and "
                  "raster datapaths' units (`rend3r.precision.datapath`) times each unit's modelled cost "
                  "(`rend3r.precision.cost`); the cheapest is the one with fewest LUTs.")
    lines = [*summary_header(r, title, command, conditions),
             "| program | mode | cheapest meeting the bound | " + " | ".join(f"{f} PSNR" for f in r.formats) + " |",
             "|---|---|---|" + "---:|" * len(r.formats)]
    for p in r.programs:
        by_format = r.of_program(p)
        best = cheapest(by_format, r.costs, r.min_psnr)
        lines.append(f"| {p.name} | {p.mode} | {best or 'none'} | "
                     + " | ".join(decibels(by_format[f].psnr) for f in r.formats) + " |")
    lines += ["", "| format | LUT | FF | DSP48E1 | worst PSNR (dB) | programs meeting the bound |",
              "|---|---:|---:|---:|---:|---:|"]
    for f in r.formats:
        c, scores = r.costs[f], r.of_format(f)
        meeting = sum(s.psnr >= r.min_psnr for s in scores)
        lines.append(f"| {f} | {c.lut:,} | {c.ff:,} | {c.dsp:,} | {decibels(worst_psnr(scores))} | "
                     f"{meeting}/{len(scores)} |")
    return ("\n".join(lines) + "\n").encode()
