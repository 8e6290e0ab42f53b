"""Frames side by side: a looping animation on every core against one core.

The scene is a benchmark wall (walls.py, one light) whose program loops (its last ``er``
becomes an ``lr``, so each period clears and rebuilds the scene, as an animation does):
``--frames`` frames at 512x384, ``run_program`` with jobs=1 against jobs=2 (one frame per
thread, rend3r/emu/run.py frames_at_once), in alternating rounds after a warm-up; the
figure is the median over ``--runs`` rounds. Both runs' frames must be identical (exit 1
if not). Unpinned: it needs two CPUs.

    python benchmarks/bench_frames.py [--sizes 1 16 4096] [--frames 16] [--runs 5]
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time

import numpy as np
import walls

from rend3r.emu.options import EmuOptions
from rend3r.emu.run import RunResult, frames_at_once, run_program
from rend3r.isa import FrameOp, Func, encode
from rend3r.memory import reuse_freed_memory

ER, LR = (encode(FrameOp(f))[0] for f in (Func.ER, Func.LR))


def looping(n: int) -> np.ndarray:
    """The n-sphere wall's program with its final er turned into an lr."""
    words = walls.wall(n, lights=1).words.copy()
    if words[-1] != ER:
        raise SystemExit("walls.wall no longer ends with er")
    words[-1] = LR
    return words


def same(a: RunResult, b: RunResult) -> bool:
    return len(a.frames) == len(b.frames) and all(
        np.array_equal(x.rgb565, y.rgb565) and np.array_equal(x.depth, y.depth, equal_nan=True)
        and np.array_equal(x.provenance, y.provenance) for x, y in zip(a.frames, b.frames))


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[1, 16, 4096], choices=sorted(walls.LAYOUT))
    ap.add_argument("--frames", type=int, default=16)
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--precision", default="fp32", choices=["fp16", "fp32", "fp64"])
    args = ap.parse_args()
    if len(os.sched_getaffinity(0)) < 2:
        print("frames side by side: not measured (this process may use one CPU)")
        return 0
    reuse_freed_memory()
    ok = True
    for n in args.sizes:
        words = looping(n)
        options = {jobs: EmuOptions(precision=args.precision, width=512, height=384, jobs=jobs) for jobs in (1, 2)}
        results = {jobs: run_program(words, o, args.frames) for jobs, o in options.items()}  # warm-up
        times: dict[int, list[float]] = {1: [], 2: []}
        for _ in range(args.runs):
            for jobs, o in options.items():
                start = time.perf_counter()
                results[jobs] = run_program(words, o, args.frames)
                times[jobs].append(time.perf_counter() - start)
        one, two = (statistics.median(times[j]) for j in (1, 2))
        identical = same(results[1], results[2])
        ok &= identical
        print(f"{n:>6,} spheres, {args.frames} frames, {args.precision}: jobs=1 {one:.3f} s "
              f"({args.frames / one:.0f} frames/s), jobs=2 {two:.3f} s ({args.frames / two:.0f} frames/s, "
              f"{frames_at_once(options[2], args.frames)} at once): {one / two:.2f}x faster; "
              f"frames {'identical' if identical else 'DIFFER'}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
