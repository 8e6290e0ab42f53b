"""Raytracer speed on the paper's Table IV workloads, beside the paper's device estimate.

Workloads: 1, 16, 256 and 4,096 spheres with 0 and 1 directional lights at 512x384, as the
sphere walls of walls.py (built to stay in float16's range). Per row and precision: the
median wall time of ``run_program`` (decoding included) over --runs renders after one
warm-up, the device estimate (shapes + 205) * (lights + 1) * pixels cycles at 100 MHz, the
device/emulator ratio and the frame's counters. Threads: --jobs (default 0, every core: the
device estimate is for the whole device, so the emulator gets the whole machine).

Every frame is compared with fp64's (walls.fp16_faithful): it may differ at silhouette
pixels only. A frame that differs elsewhere measures a broken render: its row prints
"FP16 FRAME NOT FAITHFUL" (or FP32) and the script exits 1 after the table.
Target: fp16 at least 100x faster than the device estimate on every row; fp32 is reported.
First, a calibration figure of the machine's numpy speed.

    python benchmarks/bench_raytrace.py [--runs 5] [--shapes 1 16 256 4096] [--lights 0 1]
                                        [--precision fp16 fp32] [--jobs 0]
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np
import walls

from rend3r.emu.options import EmuOptions
from rend3r.emu.threads import available_cores
from rend3r.emu.run import RunResult, run_program
from rend3r.memory import reuse_freed_memory

SHAPES = (1, 16, 256, 4096)
#: device time / emulator time, at least, per precision (None: reported only).
TARGET = {"fp16": 100.0, "fp32": None}


def measure(words: np.ndarray, options: EmuOptions, runs: int) -> tuple[float, RunResult]:
    """Median wall time of ``runs`` whole ``run_program`` calls after one untimed warm-up,
    and the last result."""
    run_program(words, options)
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        result = run_program(words, options)
        times.append(time.perf_counter() - start)
    return statistics.median(times), result


def calibration_us() -> float:
    """A fixed numpy workload, to compare machines and moments (shared machines drift):
    the median time of a float32 multiply of 65,536 elements, in microseconds."""
    a = np.linspace(1.0, 2.0, 1 << 16, dtype=np.float32)
    times = []
    for _ in range(7):
        start = time.perf_counter()
        for _ in range(1000):
            np.multiply(a, a)
        times.append((time.perf_counter() - start) / 1000 * 1e6)
    return statistics.median(times)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--shapes", type=int, nargs="+", default=list(SHAPES), choices=SHAPES)
    ap.add_argument("--lights", type=int, nargs="+", default=[0, 1], choices=[0, 1])
    ap.add_argument("--precision", nargs="+", default=["fp16", "fp32"], choices=sorted(TARGET))
    ap.add_argument("--jobs", type=int, default=0, help="threads per frame (0: every core)")
    args = ap.parse_args()
    print(f"machine: a float32 multiply of 65,536 elements takes {calibration_us():.1f} us (median of 7)")
    reuse_freed_memory()  # as the rend3r command does (rend3r/memory.py); the calibration runs before it
    threads = args.jobs or available_cores()
    print(f"jobs: {args.jobs} ({threads} thread{'s' * (threads > 1)}); times: median of {args.runs} runs after "
          "a warm-up, whole run_program;\n'differ (off)': pixels whose shape differs from fp64's (of which off "
          "silhouettes)")
    print(f"{'shapes':>6} {'lights':>6} {'prec':>5} {'emulator s':>11} {'device s':>9} {'device/emu':>10} "
          f"{'target':>12} {'tests':>11} {'hits':>7} {'nan':>9} {'differ (off)':>15}")
    broken = []
    for lights in args.lights:
        for shapes in args.shapes:
            wall = walls.wall(shapes, lights)
            reference = run_program(wall.words, EmuOptions(precision="fp64", jobs=args.jobs)).frames[0].provenance
            for precision in args.precision:
                secs, result = measure(wall.words, EmuOptions(precision=precision, jobs=args.jobs), args.runs)
                st = result.stats.frames[0]
                faithful, differ, off = walls.fp16_faithful(result.frames[0].provenance, reference)
                ratio = st.device_seconds / secs
                need = TARGET[precision]
                target = "-" if need is None else f">={need:g}x {'met' if ratio >= need else 'MISSED'}"
                print(f"{shapes:>6} {lights:>6} {precision:>5} {secs:>11.3f} {st.device_seconds:>9.3f} "
                      f"{ratio:>10.1f} {target:>12} {st.tests:>11} {st.hits:>7} {st.nan_tests:>9} "
                      f"{f'{differ} ({off})':>15}", flush=True)
                if not faithful:
                    broken.append(f"{shapes} shapes, {lights} light{'s' * (lights != 1)}, {precision}")
                    print(f"!!! {precision.upper()} FRAME NOT FAITHFUL: {off} pixels show another shape than fp64 "
                          "off silhouettes; this row's speed measures a broken frame", flush=True)
    if broken:
        print(f"\nFAILED: {len(broken)} frame(s) not faithful to fp64: {'; '.join(broken)}")
        return 1
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
