"""Speed against a production renderer: the emulator beside Mitsuba 3 on the same sphere walls.

Scenes: walls.wall(n, lights=1) for n in 1, 16, 256, 4,096, 65,536 spheres filling the view,
512x384, one directional light with shadows; Mitsuba (peer_mitsuba.py) renders the same
spheres, colours and light. The single-core part pins this process, and with it the
Mitsuba subprocess, to one CPU; the emulator runs with jobs=1.

Ours, per precision (fp16, fp32, fp64): median of --runs timed ``run_program`` calls after one
warm-up: "run" is the whole call (decoding the program included, ~655k words at 65,536
spheres), "render" the frame's render time. Each frame but a program's first finds the tree of the
frame before it kept (the shapes did not move; rend3r/emu/bvh.py tree_room), as Mitsuba's
renders find its scene built; the scaling line also times frames with the tree built
("cold"). fp16 and fp32 frames are checked against fp64's
with walls.fp16_faithful (they may differ at silhouettes only). Mitsuba, per variant: its
scene build (objects and BVH) and the median of its timed renders, printed apart; its hit
mask is compared with our fp64 frame (a check that both render the same scene). Each ratio
is the median over --runs rounds, each one timed run of ours (the precision the ratio
names, after WARM_FRAMES untimed) right before one timed Mitsuba render (after one
untimed), so that the machine's drift falls on both and each finds the caches warm.

Targets (reported, not asserted): fp32 at most 0.5x the time of Mitsuba scalar_rgb and of
llvm_ad_rgb, fp16 at most 1x scalar_rgb's, at every size; 16x more spheres (4,096 to 65,536)
at most 3x the time (pinned, the two sizes alternating round by round); jobs=2 at least
1.7x faster than jobs=1 at 4,096 spheres (unpinned, alternating likewise; each round also
measures what two pinned single-thread processes get from the two CPUs in those seconds,
two_cpus.py, the most a jobs=2 frame could gain then). --jobs-sizes picks the sizes of
that part (default 4,096 and 65,536; 16 and 256 show the frames of a few bands).
Exit status 0, except 1 when an fp32 frame is not faithful to fp64 (a bug).

    python benchmarks/bench_peer.py [--sizes 1 16 256 4096 65536] [--runs 5]
                                    [--peer scalar_rgb llvm_ad_rgb | --no-peer]
                                    [--plot PATH] [--markdown PATH]
                                    [--jobs-sizes 4096 65536]
"""

from __future__ import annotations

import argparse
import importlib.util
import math
import os
import shlex
import statistics
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import placement
import walls
from bench_raytrace import calibration_us
from peer_mitsuba import VARIANTS, render_spheres
from two_cpus import TwoCpus

from rend3r.emu import bvh, native
from rend3r.emu.options import EmuOptions
from rend3r.emu.run import RunResult, run_program
from rend3r.memory import reuse_freed_memory

SIZES = tuple(sorted(walls.LAYOUT))
PRECISIONS = ("fp16", "fp32", "fp64")
WIDTH, HEIGHT = 512, 384
FP32_VS_PEER = 0.5  # fp32 time / a Mitsuba variant's render time, at most
FP16_VS_SCALAR = 1.0  # fp16 time / scalar_rgb's render time, at most
SCALING = 3.0  # time(65,536 spheres) / time(4,096 spheres), at most
SPEEDUP = 1.7  # jobs=1 time / jobs=2 time at JOBS_SIZE spheres, at least
JOBS_SIZE = 4096
JOBS_ALSO = 65536  # jobs measured here too (no target: how the threads serve a set-up-heavy frame)
WARM_FRAMES = 3  # untimed frames before each timed one of the paired measurements (peer, jobs)
JOBS_ROUNDS = 15  # alternating rounds of the jobs measurement at least (a frame's speed here drifts within seconds)
#: (label, numerator, denominator, target): numerators are ours ("fp32 run"), denominators
#: a Mitsuba variant's render, paired round by round (measure).
RATIOS = (("fp32 run / scalar", "fp32", "run", "scalar_rgb", FP32_VS_PEER),
          ("fp32 run / llvm", "fp32", "run", "llvm_ad_rgb", FP32_VS_PEER),
          ("fp32 render / scalar", "fp32", "render", "scalar_rgb", FP32_VS_PEER),
          ("fp32 render / llvm", "fp32", "render", "llvm_ad_rgb", FP32_VS_PEER),
          ("fp16 run / scalar", "fp16", "run", "scalar_rgb", FP16_VS_SCALAR))
COLOURS = {"fp16": (214, 39, 40), "fp32": (31, 119, 180), "fp64": (44, 160, 44),
           "scalar_rgb": (148, 103, 189), "llvm_ad_rgb": (255, 127, 14)}


@dataclass
class Ours:
    """One precision's figures at one size (seconds are medians)."""

    run: float  #: whole run_program
    render: float  #: stats.frames[0].seconds
    tests: int
    hits: int
    nan_tests: int
    differ: int  #: pixels whose shape differs from fp64's
    off: int  #: of which off silhouettes

    @property
    def faithful(self) -> bool:
        """The frame shows fp64's shapes everywhere but at silhouettes."""
        return self.off == 0


@dataclass
class Peer:
    """One Mitsuba variant's figures at one size."""

    build: float  #: scene build, BVH included
    render: float  #: median render
    disagree: float  #: share of pixels whose hit/miss differs from our fp64 frame


@dataclass
class Row:
    """Everything measured at one size."""

    n: int  #: spheres
    ours: dict[str, Ours] = field(default_factory=dict)
    peer: dict[str, Peer] = field(default_factory=dict)
    #: (precision, kind, variant): the median of our time over the variant's render time,
    #: the two alternating render by render (measure)
    paired: dict[tuple[str, str, str], float] = field(default_factory=dict)

    def ratio(self, precision: str, kind: str, variant: str) -> float | None:
        """The median over paired rounds of our ``kind`` time ("run" or "render") over the
        variant's render time, if measured."""
        return self.paired.get((precision, kind, variant))


def time_ours(words: np.ndarray, precision: str, runs: int, jobs: int) -> tuple[float, float, RunResult]:
    """Median whole-run and render seconds of ``runs`` timed runs after one warm-up, and the last result."""
    options = EmuOptions(precision=precision, width=WIDTH, height=HEIGHT, jobs=jobs)
    run_program(words, options)
    runs_s, renders = [], []
    for _ in range(runs):
        start = time.perf_counter()
        result = run_program(words, options)
        runs_s.append(time.perf_counter() - start)
        renders.append(result.stats.frames[0].seconds)
    return statistics.median(runs_s), statistics.median(renders), result


def verdict(value: float, limit: float, at_most: bool = True) -> str:
    """"met" or "MISSED": ``value`` against a target of at most (or at least) ``limit``."""
    return "met" if (value <= limit if at_most else value >= limit) else "MISSED"


def measure(n: int, runs: int, variants: list[str]) -> Row:
    """Our three precisions and the Mitsuba ``variants`` at ``n`` spheres, printing as it goes.
    A variant that fails is reported and removed from ``variants``."""
    wall = walls.wall(n, lights=1)
    k, depth = walls.LAYOUT[n]
    print(f"\n== {n:,} sphere{'s' * (n > 1)} ({k} x {k}, {depth} deep; {len(wall.words):,} program words)", flush=True)
    reference = run_program(wall.words, EmuOptions(precision="fp64", width=WIDTH, height=HEIGHT, jobs=1))
    ref = reference.frames[0].provenance
    row = Row(n)
    for precision in PRECISIONS:
        run, render, result = time_ours(wall.words, precision, runs, jobs=1)
        st = result.stats.frames[0]
        _, differ, off = walls.fp16_faithful(result.frames[0].provenance, ref)
        o = row.ours[precision] = Ours(run, render, st.tests, st.hits, st.nan_tests, differ, off)
        check = "" if precision == "fp64" else (
            f"  vs fp64: {differ:,} px differ, {off:,} off silhouettes: "
            + ("faithful" if o.faithful else f"{precision.upper()} FRAME NOT FAITHFUL"))
        print(f"  ours {precision:11} run {run:8.4f} s  render {render:8.4f} s  tests {st.tests:>11,}  "
              f"hits {st.hits:>7,}  nan {st.nan_tests:>9,}{check}", flush=True)
    for variant in list(variants):
        compared = sorted({precision for _, precision, _, v, _ in RATIOS if v == variant})
        options = {precision: EmuOptions(precision=precision, width=WIDTH, height=HEIGHT, jobs=1)
                   for precision in compared}
        ours: dict[tuple[str, str], list[float]] = {(p, kind): [] for p in compared for kind in ("run", "render")}

        def between(options=options, ours=ours) -> None:  # before each of Mitsuba's timed renders: ours
            for precision, options_ in options.items():
                for _ in range(WARM_FRAMES):
                    run_program(wall.words, options_)
                start = time.perf_counter()
                result = run_program(wall.words, options_)
                ours[precision, "run"].append(time.perf_counter() - start)
                ours[precision, "render"].append(result.stats.frames[0].seconds)

        try:
            r = render_spheres(variant, wall.centers, wall.radii, wall.colors, wall.light, width=WIDTH,
                               height=HEIGHT, hfov=wall.fov, vfov=wall.fov, runs=runs, threads=1, between=between)
        except RuntimeError as e:
            print(f"  mitsuba {variant} FAILED, skipped from here on: {e}", flush=True)
            variants.remove(variant)
            continue
        p = row.peer[variant] = Peer(r.build_seconds, r.median, float(np.mean(r.hit != (ref >= 0))))
        for (precision, kind), times in ours.items():
            row.paired[precision, kind, variant] = statistics.median(a / b for a, b in zip(times, r.render_seconds))
        print("    ours in the rounds paired with it: " + ", ".join(
            f"{precision} {kind} {statistics.median(times):.4f} s" for (precision, kind), times in ours.items()),
            flush=True)
        print(f"  mitsuba {variant:11} build {p.build:8.4f} s  render {p.render:8.4f} s  "
              f"hit mask vs our fp64: {100 * p.disagree:.3f}% of pixels differ", flush=True)
    cells = []
    for label, precision, kind, variant, limit in RATIOS:
        value = row.ratio(precision, kind, variant)
        if value is not None:
            cells.append(f"{label} {value:.3f} {verdict(value, limit)} (<= {limit:g})")
    if cells:
        print("  ratios (medians of paired renders, ours and Mitsuba's alternating): " + "; ".join(cells), flush=True)
    return row


def scaling(sizes: list[int], runs: int) -> list[str]:
    """Lines on the cost of 16x more spheres (4,096 to 65,536), on the pinned thread,
    printing as it goes: the two sizes alternate round by round (each warmed with one
    frame, then timed), so that a drift of the machine's speed falls on both, and the
    ratio is the median of the rounds' ratios (the table's figures, minutes apart, moved
    by a third between a quiet and a slow spell). The timed frame finds the tree of the
    frame before it kept (bvh.tree_room), as every frame of ours here does; a third frame,
    *cold*, is timed after the kept tree is dropped, as a program's first frame runs."""
    if 4096 not in sizes or 65536 not in sizes:
        return ["scaling 4,096 -> 65,536 spheres: not measured (needs --sizes 4096 65536)"]
    programs = {n: walls.wall(n, lights=1).words for n in (4096, 65536)}
    lines = []
    for precision in ("fp32", "fp16"):
        options = EmuOptions(precision=precision, width=WIDTH, height=HEIGHT, jobs=1)
        run: dict[int, list[float]] = {4096: [], 65536: []}
        render: dict[int, list[float]] = {4096: [], 65536: []}
        cold: dict[int, list[float]] = {4096: [], 65536: []}
        for _ in range(max(runs, JOBS_ROUNDS)):
            for n, words in programs.items():
                run_program(words, options)
                start = time.perf_counter()
                result = run_program(words, options)
                run[n].append(time.perf_counter() - start)
                render[n].append(result.stats.frames[0].seconds)
                bvh.forget()
                start = time.perf_counter()
                run_program(words, options)
                cold[n].append(time.perf_counter() - start)
        ratios = [statistics.median(b / a for a, b in zip(t[4096], t[65536])) for t in (run, render, cold)]
        lines.append(f"scaling 4,096 -> 65,536 spheres, {precision} ({len(run[4096])} alternating rounds, pinned): "
                     f"run {ratios[0]:.2f}x {verdict(ratios[0], SCALING)}, render {ratios[1]:.2f}x "
                     f"{verdict(ratios[1], SCALING)} (target <= {SCALING:g}x; medians {statistics.median(run[4096]):.4f} "
                     f"and {statistics.median(run[65536]):.4f} s run); cold, the tree built: run {ratios[2]:.2f}x "
                     f"{verdict(ratios[2], SCALING)} (medians {statistics.median(cold[4096]):.4f} and "
                     f"{statistics.median(cold[65536]):.4f} s)")
        print(lines[-1], flush=True)
    return lines


def jobs_scaling(runs: int, cpus: set[int], sizes: list[int]) -> list[str]:
    """jobs=1 against jobs=2 at each of ``sizes`` spheres (the target at JOBS_SIZE), on the
    unpinned process, printing as it goes. The two alternate round by round, so that a drift of the machine's
    speed falls on both; in a round each renders WARM_FRAMES frames untimed (its threads
    and caches warm, as in a run of frames: on this VM the first two jobs=2 frames after
    jobs=1 frames run 20-30% slow while the idle second vCPU wakes) and one timed. The
    ratio is the median of the rounds' ratios. Each round then measures the two CPUs'
    ceiling (two_cpus.py); the share of it reached is the median of the rounds' ratio over
    their ceiling. And where the host had put the two CPUs (placement.py), probed before
    and after each round's frames: the rounds of each placement (``moved`` when the two
    probes differ) and their median ratio are printed, so that a miss can be told apart
    from a placement that costs a split frame what it does not cost two processes."""
    if len(cpus) < 2:
        line = f"jobs=2 vs jobs=1: not measured (this process may use {len(cpus)} CPU)"
        print(line)
        return [line]
    lines = []
    unplaced = placement.available()
    for size in sizes:
        wall = walls.wall(size, lights=1)
        for precision in ("fp32", "fp16"):
            options = {jobs: EmuOptions(precision=precision, width=WIDTH, height=HEIGHT, jobs=jobs) for jobs in (1, 2)}
            times: dict[int, list[float]] = {1: [], 2: []}
            ceilings, placed = [], []
            with TwoCpus(cpus, size, precision, WIDTH, HEIGHT, WARM_FRAMES) as two:
                for _ in range(max(runs, JOBS_ROUNDS)):
                    before = _placed(cpus, unplaced)
                    for jobs, options_ in options.items():
                        for _ in range(WARM_FRAMES):
                            run_program(wall.words, options_)
                        start = time.perf_counter()
                        run_program(wall.words, options_)
                        times[jobs].append(time.perf_counter() - start)
                    after = _placed(cpus, unplaced)
                    placed.append(after if before and after and before.kind == after.kind else None)
                    ceilings.append(two.ceiling())
            ratios = [a / b for a, b in zip(times[1], times[2])]
            ratio = statistics.median(ratios)
            share = statistics.median(r / c for r, c in zip(ratios, ceilings))
            target = f"{verdict(ratio, SPEEDUP, False)} (target >= {SPEEDUP:g}x)" if size == JOBS_SIZE \
                else "(no target)"
            low, _, high = statistics.quantiles(ratios, n=4)
            lines.append(f"jobs, {size:,} spheres, {precision} (unpinned, {len(cpus)} CPUs, {len(times[1])} "
                         f"alternating rounds): jobs=1 run {statistics.median(times[1]):.4f} s, jobs=2 run "
                         f"{statistics.median(times[2]):.4f} s: {ratio:.2f}x faster (quartiles of the rounds "
                         f"{low:.2f}-{high:.2f}x) {target}; two pinned "
                         f"processes in the same rounds render {statistics.median(ceilings):.2f}x the frames of one "
                         f"(two_cpus.py), jobs=2 reaches {share:.0%} of that; {_placements(placed, ratios, ceilings, unplaced)}")
            print(lines[-1], flush=True)
    return lines


def _placed(cpus: set[int], unplaced: str | None) -> placement.Placement | None:
    """Where the host has put the two CPUs now (placement.py), None when it cannot be
    measured."""
    if unplaced is not None:
        return None
    try:
        return placement.measure(cpus)
    except RuntimeError:
        return None


def _placements(placed: list[placement.Placement | None], ratios: list[float], ceilings: list[float],
                unplaced: str | None) -> str:
    """Where the host had put the two CPUs in the rounds (placement.py): per placement, its
    rounds, the median time of a line read across the CPUs, the rounds' median ratio and
    their median ceiling (two_cpus.py); then the rounds in which the CPUs moved (or a probe
    failed)."""
    if unplaced is not None:
        return f"the CPUs' placement not measured ({unplaced})"
    rounds = list(zip(placed, ratios, ceilings))
    parts = []
    for kind in placement.KINDS:
        mine = [(p, r, c) for p, r, c in rounds if p is not None and p.kind == kind]
        if mine:
            parts.append(f"{len(mine)} rounds on {kind} (a line read across in "
                         f"{statistics.median(p.cross_ns for p, _, _ in mine):.0f} ns): "
                         f"{statistics.median(r for _, r, _ in mine):.2f}x, two processes "
                         f"{statistics.median(c for _, _, c in mine):.2f}x")
    moved = [(r, c) for p, r, c in rounds if p is None]
    if moved:
        parts.append(f"{len(moved)} rounds moved between placements: {statistics.median(r for r, _ in moved):.2f}x, "
                     f"two processes {statistics.median(c for _, c in moved):.2f}x")
    return "the host placed the two CPUs (placement.py, probed before and after each round's frames): " + \
        ", ".join(parts)


def _table(head: list[str], align: list[str], body: list[list[str]]) -> list[str]:
    """A Markdown table."""
    return ["| " + " | ".join(cells) + " |" for cells in (head, align, *body)]


def markdown(rows: list[Row], variants: list[str], notes: list[str], header: list[str]) -> str:
    """The results as Markdown: how measured, a times table, a ratios table, the scaling lines."""
    lines = [*header, "",
             ("Times in seconds, medians. Ours: *run* is the whole `run_program` call (decoding the program "
              "included), *render* the frame's render time; one core (`jobs=1`). Mitsuba: *render* is "
              "`mi.render` plus the copy to numpy, its scene build (objects and BVH) excluded and shown apart; "
              "one core. *fp16 faithful*: the fp16 frame shows fp64's shape everywhere but at silhouettes. "
              "Our times here are from our runs back to back; the ratios below pair each run of ours with a "
              "Mitsuba render in the same seconds, so they need not equal the quotient of these columns."), ""]
    head = ["spheres", "fp16 run", "fp16 faithful", "fp32 run", "fp32 render", "fp64 run"]
    head += [f"{v} {what}" for v in variants for what in ("build", "render")]
    body = []
    for r in rows:
        fp16 = r.ours["fp16"]
        cells = [f"{r.n:,}", f"{fp16.run:.4f}", "yes" if fp16.faithful else f"**no** ({fp16.off:,} px)",
                 f"{r.ours['fp32'].run:.4f}", f"{r.ours['fp32'].render:.4f}", f"{r.ours['fp64'].run:.4f}"]
        for v in variants:
            cells += [f"{r.peer[v].build:.4f}", f"{r.peer[v].render:.4f}"] if v in r.peer else ["-", "-"]
        body.append(cells)
    lines += _table(head, ["---:", "---:", ":---:"] + ["---:"] * (len(head) - 3), body)
    ratios = [x for x in RATIOS if x[3] in variants]
    if ratios:
        body = []
        for r in rows:
            cells = [f"{r.n:,}"]
            for _, precision, kind, variant, limit in ratios:
                value = r.ratio(precision, kind, variant)
                cells.append("-" if value is None else f"{value:.3f} {verdict(value, limit)}")
            body.append(cells)
        lines += ["", ("Ratios (our time / Mitsuba's render time; lower is faster), each the median over rounds of one "
                       "run of ours then one Mitsuba render, each after untimed ones; against the targets:"), "",
                  *_table(["spheres", *(f"{label} (<= {limit:g})" for label, *_, limit in ratios)],
                          ["---:"] * (len(ratios) + 1), body)]
    lines += ["", *(f"- {note}" for note in notes)]
    return "\n".join(lines) + "\n"


def plot(rows: list[Row], variants: list[str], path: Path) -> None:
    """Time against spheres, log-log, one line with markers per series, drawn with Pillow."""
    from PIL import Image, ImageDraw, ImageFont

    series: dict[str, list[tuple[int, float]]] = {
        **{f"ours {p} (run)": [(r.n, r.ours[p].run) for r in rows] for p in PRECISIONS},
        **{f"Mitsuba {v} (render)": [(r.n, r.peer[v].render) for r in rows if v in r.peer] for v in variants},
    }
    colours = dict(zip(series, [COLOURS[p] for p in PRECISIONS] + [COLOURS[v] for v in variants]))
    W, H, L, R, T, B = 900, 560, 80, 230, 40, 60
    img = Image.new("RGB", (W, H), "white")
    d = ImageDraw.Draw(img)
    font = ImageFont.load_default(size=13)
    xs = [n for pts in series.values() for n, _ in pts]
    ys = [t for pts in series.values() for _, t in pts]
    x_lo, x_hi = math.floor(math.log10(min(xs))), math.ceil(math.log10(max(xs)))
    y_lo, y_hi = math.floor(math.log10(min(ys))), math.ceil(math.log10(max(ys)))
    x_hi, y_hi = max(x_hi, x_lo + 1), max(y_hi, y_lo + 1)

    def at(n: float, t: float) -> tuple[float, float]:
        return (L + (math.log10(n) - x_lo) / (x_hi - x_lo) * (W - L - R),
                H - B - (math.log10(t) - y_lo) / (y_hi - y_lo) * (H - T - B))

    d.rectangle([L, T, W - R, H - B], outline="black")
    for e in range(x_lo, x_hi + 1):
        x, _ = at(10.0**e, 10.0**y_lo)
        d.line([x, T, x, H - B], fill=(225, 225, 225))
        d.line([x, H - B, x, H - B + 5], fill="black")
        d.text((x - 15, H - B + 8), f"{10**e:,}", fill="black", font=font)
    for e in range(y_lo, y_hi + 1):
        _, y = at(10.0**x_lo, 10.0**e)
        d.line([L, y, W - R, y], fill=(225, 225, 225))
        d.line([L - 5, y, L, y], fill="black")
        d.text((L - 70, y - 7), f"{10.0**e:g} s", fill="black", font=font)
    d.text((L + (W - L - R) // 2 - 120, H - 25), "spheres (log scale), 512x384, one light", fill="black", font=font)
    d.text((L, 12), "median time per frame, one core (log scale; lower is faster)", fill="black", font=font)
    for i, (name, pts) in enumerate(series.items()):
        xy = [at(n, t) for n, t in pts]
        if len(xy) > 1:
            d.line(xy, fill=colours[name], width=2)
        for x, y in xy:
            d.ellipse([x - 4, y - 4, x + 4, y + 4], fill=colours[name], outline="black")
        y = T + 10 + 22 * i
        d.line([W - R + 15, y, W - R + 35, y], fill=colours[name], width=2)
        d.ellipse([W - R + 21, y - 4, W - R + 29, y + 4], fill=colours[name], outline="black")
        d.text((W - R + 42, y - 8), name, fill="black", font=font)
    path.parent.mkdir(parents=True, exist_ok=True)
    img.save(path)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=list(SIZES), choices=SIZES)
    ap.add_argument("--runs", type=int, default=5, help="timed runs per measurement; medians are reported")
    ap.add_argument("--peer", nargs="+", default=list(VARIANTS), choices=VARIANTS, help="Mitsuba variants")
    ap.add_argument("--no-peer", action="store_true", help="skip Mitsuba")
    ap.add_argument("--plot", type=Path, help="write a log-log PNG of time against spheres")
    ap.add_argument("--markdown", type=Path, help="write the results as Markdown")
    ap.add_argument("--jobs-sizes", type=int, nargs="+", default=[JOBS_SIZE, JOBS_ALSO], choices=SIZES,
                    help="sizes of the jobs=1 against jobs=2 part (its target is at 4,096)")
    args = ap.parse_args()
    command = shlex.join(["python", "benchmarks/bench_peer.py", *sys.argv[1:]])
    cpus = os.sched_getaffinity(0)
    pinned = min(cpus)
    # Pins this thread, which renders with jobs=1; Mitsuba's subprocess and later threads inherit it.
    os.sched_setaffinity(0, {pinned})
    calibration = f"machine: a float32 multiply of 65,536 elements takes {calibration_us():.1f} us (median of 7)"
    reuse_freed_memory()  # as the rend3r command does (rend3r/memory.py); the calibration runs before it
    model = next((line.split(":", 1)[1].strip() for line in Path("/proc/cpuinfo").read_text().splitlines()
                  if line.startswith("model name")), "unknown")
    header = [calibration, (f"cpu: {model}; kernels: {native.isa()}; single-core figures pinned to CPU {pinned} "
                            f"(of {', '.join(map(str, sorted(cpus)))}); {WIDTH}x{HEIGHT}, one light with shadows; "
                            f"median of {args.runs} timed runs after a warm-up; load average at start "
                            f"{os.getloadavg()[0]:.2f}")]
    print("\n".join(header))
    variants = [] if args.no_peer else list(dict.fromkeys(args.peer))
    if args.no_peer:
        print("Mitsuba skipped (--no-peer): no peer figures or ratios")
    elif importlib.util.find_spec("mitsuba") is None:
        print("Mitsuba skipped: it is not installed (python -m pip install mitsuba; see peer_mitsuba.py)")
        variants = []
    print("ours 'run' = the whole run_program call, decoding the program included; 'render' = the frame's render "
          "time.\nMitsuba 'render' = median of mi.render + copy to numpy, EXCLUDING its scene build (objects + BVH), "
          "printed apart as 'build'.\nratios = our time / Mitsuba's render time (lower is faster), each the median "
          "over rounds of one our run then one Mitsuba render, each after untimed ones.")
    active = list(variants)  # measure() drops a variant that fails
    rows = {n: measure(n, args.runs, active) for n in sorted(args.sizes)}
    variants = [v for v in variants if any(v in r.peer for r in rows.values())]
    print()
    notes = scaling(sorted(args.sizes), args.runs)
    os.sched_setaffinity(0, cpus)  # unpinned: the jobs=2 threads start after this and inherit it
    notes += jobs_scaling(args.runs, cpus, list(dict.fromkeys(args.jobs_sizes)))
    if args.markdown:
        header_md = [f"Measured by `{command}`.", "", f"- {calibration}", f"- {header[1]}"]
        args.markdown.parent.mkdir(parents=True, exist_ok=True)
        args.markdown.write_text(markdown(list(rows.values()), variants, notes, header_md), encoding="utf-8")
        print(f"wrote {args.markdown}")
    if args.plot:
        plot(list(rows.values()), variants, args.plot)
        print(f"wrote {args.plot}")
    bad = [r.n for r in rows.values() if not r.ours["fp32"].faithful]
    if bad:
        print(f"\n!!! BUG: the fp32 frame is NOT FAITHFUL to fp64 off silhouettes at "
              f"{', '.join(f'{n:,}' for n in bad)} spheres (fp32 must match fp64 there)")
        return 1
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
