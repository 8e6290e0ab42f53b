"""The kernels' builds side by side: each instruction set this processor runs (portable,
AVX2, AVX-512; rend3r/emu/native.py INSTRUCTION_SETS) on the sphere walls of bench_peer.py.

In one process pinned to one CPU, frame by frame: each round renders the wall once with
every build, in an order that turns round by round, each frame after an untimed one with
the same build; a build's figure is the median of its times, and its ratio to the
baseline build (the first given) the median over rounds of the pair in that round, so
that the machine's drift falls on both. The frames of every build are compared (pixels,
depth, provenance and counts): the builds differ in speed only.
Exit status 0; 1 when a build's frame differs from the baseline's (a bug); 2 when this
processor runs fewer than two of the builds asked for.

    python benchmarks/bench_isa.py [--sizes 1 16 256 4096 65536] [--precisions fp32 fp16]
                                   [--isas avx2 avx512] [--rounds 40] [--cpu 0]
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time

import numpy as np
import walls

from rend3r.emu import native
from rend3r.emu.options import EmuOptions
from rend3r.emu.run import RunResult, run_program
from rend3r.memory import reuse_freed_memory


def _frame(words: np.ndarray, options: EmuOptions, isa: str) -> tuple[float, RunResult]:
    """One untimed and one timed run with the kernels of ``isa``."""
    native.choose(isa)
    run_program(words, options)
    start = time.perf_counter()
    result = run_program(words, options)
    return time.perf_counter() - start, result


def _same(a: RunResult, b: RunResult) -> bool:
    fa, fb = a.frames[0], b.frames[0]
    sa, sb = a.stats.frames[0], b.stats.frames[0]
    return (np.array_equal(fa.rgb565, fb.rgb565) and np.array_equal(fa.provenance, fb.provenance)
            and np.array_equal(fa.depth.view(np.uint32), fb.depth.view(np.uint32))
            and (sa.tests, sa.skipped, sa.nan_tests, sa.hits, sa.shadow_rays)
            == (sb.tests, sb.skipped, sb.nan_tests, sb.hits, sb.shadow_rays))


def measure(size: int, precision: str, isas: list[str], rounds: int) -> bool:
    """Prints each build's median time and its paired ratio to the first; False when a
    frame differs."""
    words = walls.wall(size, lights=1).words
    options = EmuOptions(precision=precision, width=512, height=384, jobs=1)
    times: dict[str, list[float]] = {isa: [] for isa in isas}
    first: dict[str, RunResult] = {}
    for r in range(rounds):
        order = isas[r % len(isas):] + isas[:r % len(isas)]
        for isa in order:
            seconds, result = _frame(words, options, isa)
            times[isa].append(seconds)
            first.setdefault(isa, result)
    same = all(_same(first[isas[0]], first[isa]) for isa in isas[1:])
    base = times[isas[0]]
    cells = [f"{isa} {statistics.median(t) * 1e3:.3f} ms" + (
        "" if isa == isas[0] else f" ({statistics.median(b / a for a, b in zip(base, t)):.3f}x)")
        for isa, t in times.items()]
    print(f"{size:>6,} sphere{'s' * (size > 1)} {precision}: " + ", ".join(cells) + ("" if same else "  FRAMES DIFFER"), flush=True)
    return same


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=sorted(walls.LAYOUT), choices=sorted(walls.LAYOUT))
    parser.add_argument("--precisions", nargs="+", default=["fp32", "fp16"], choices=["fp16", "fp32", "fp64"])
    parser.add_argument("--isas", nargs="+", default=None, choices=native.INSTRUCTION_SETS,
                        help="builds to compare, the first the baseline (default: AVX2 and AVX-512 where they run)")
    parser.add_argument("--rounds", type=int, default=40)
    parser.add_argument("--cpu", type=int, default=min(os.sched_getaffinity(0)))
    args = parser.parse_args()
    if args.rounds < 1:
        parser.error("--rounds must be at least 1")
    if args.isas is not None and len(set(args.isas)) != len(args.isas):
        parser.error(f"--isas {' '.join(args.isas)}: name each build once")
    if args.cpu not in os.sched_getaffinity(0):
        parser.error(f"--cpu {args.cpu}: this process may use CPUs {sorted(os.sched_getaffinity(0))}")
    isas = args.isas or [isa for isa in ("avx2", "avx512") if native.runs(isa)]
    missing = [isa for isa in isas if not native.runs(isa)]
    if missing or len(isas) < 2:
        print(f"need two builds this processor runs; it runs {[i for i in native.INSTRUCTION_SETS if native.runs(i)]}"
              + (f", not {missing}" if missing else ""), file=sys.stderr)
        return 2
    reuse_freed_memory()
    os.sched_setaffinity(0, {args.cpu})
    print(f"builds {', '.join(isas)} (ratios to {isas[0]}); pinned to CPU {args.cpu}; 512x384, one light with shadows; "
          f"medians of {args.rounds} rounds")
    ok = True
    for size in args.sizes:
        for precision in args.precisions:
            ok &= measure(size, precision, isas, args.rounds)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
