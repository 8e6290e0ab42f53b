"""Raytracer speed on the paper's Table IV workloads, beside the paper's device estimate.

Workloads: 1, 16, 256, 4096 spheres with 0 and 1 directional lights at 512x384. Spheres
stand in a G x G wall of columns K deep (4096 = 16 x 16 x 16), sized so that the front
layer stays inside float16's range (|D||S| < 128 in normal space; see docs/emulator.md).
Prints the median wall time per frame over --runs renders (after one warm-up render), the
device estimate (shapes + 205) * (lights + 1) * pixels cycles at 100 MHz, and
device/emulator ratios; first, a calibration figure of the machine's numpy speed.
Targets: fp16 faster than the device on every row; fp32 at least 10x faster.

    python benchmarks/bench_raytrace.py [--runs 5] [--shapes 1 16 256 4096] [--precision fp16 fp32] [--rotated]
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from rend3r.emu.options import EmuOptions
from rend3r.emu.run import run_program
from rend3r.emu.stats import CLOCK_HZ, device_cycles
from rend3r.isa import CameraSet, FrameOp, Func, LightSet, ShapeSet, Table, encode, lookup
from rend3r.isa.float16 import float_to_bits
from rend3r.memory import reuse_freed_memory

LAYOUT = {1: (1, 1), 16: (4, 1), 256: (16, 1), 4096: (16, 16)}  # shapes -> (grid G, depth K)


def _prop(table: Table, name: str) -> int:
    return lookup(table, name).index


#: --rotated: every sphere turned 30 degrees about (1, 1, 1) (unit quaternion, float16).
TURN = (0.9658, 0.1494, 0.1494, 0.1494)


def workload(shapes: int, lights: int, rotated: bool = False) -> list[int]:
    """The program: camera, optional light, the sphere wall, nf, er.

    ``rotated`` gives every sphere a rotation: the same image, but the raycaster cannot
    take its shortcut for unrotated shapes (docs/emulator.md, section 11).
    """
    g, k = LAYOUT[shapes]
    spacing = 8.0 / g
    inv = 1.0 / (0.45 * spacing)
    words = list(encode(FrameOp(Func.NR)))
    for name, value in (("rrot", 1.0), ("hfov", 0.2), ("vfov", 0.2)):
        words += encode(CameraSet(_prop(Table.CAMERA, name), float_to_bits(value)))
    if lights:
        for name, value in (("src", 1), ("xfor", float_to_bits(-0.3)), ("yfor", float_to_bits(-0.4)),
                            ("zfor", float_to_bits(-1.0)), ("col", 0xFFFF), ("int", float_to_bits(1.0))):
            words += encode(LightSet(0, _prop(Table.LIGHT, name), value))
    s = lambda n: _prop(Table.SHAPE, n)  # noqa: E731
    index = 0
    for j in range(g):
        for i in range(g):
            for d in range(k):
                x, y, z = (i - (g - 1) / 2) * spacing, (j - (g - 1) / 2) * spacing, -4.0 - d * spacing
                colour = ((i * 31 // max(1, g - 1)) << 11) | ((j * 63 // max(1, g - 1)) << 5) | (31 - d)
                for (p1, v1), (p2, v2) in (
                    (("type", 1), ("col", colour)),
                    (("xloc", float_to_bits(x)), ("yloc", float_to_bits(y))),
                    (("zloc", float_to_bits(z)), ("rrot", float_to_bits(TURN[0] if rotated else 1.0))),
                    (("xscl", float_to_bits(inv)), ("yscl", float_to_bits(inv))),
                    (("zscl", float_to_bits(inv)), ("mat", 0)),
                ) + ((("irot", float_to_bits(TURN[1])), ("jrot", float_to_bits(TURN[2]))),
                     (("krot", float_to_bits(TURN[3])), ("mat", 0))) * rotated:
                    words += encode(ShapeSet(index, s(p1), s(p2), v1, v2))
                index += 1
    return words + list(encode(FrameOp(Func.NF))) + list(encode(FrameOp(Func.ER)))


def measure(words: list[int], precision: str, runs: int) -> tuple[float, object]:
    """Median wall time of ``runs`` renders after one untimed warm-up render."""
    run_program(words, EmuOptions(precision=precision))
    times, stats = [], None
    for _ in range(runs):
        start = time.perf_counter()
        result = run_program(words, EmuOptions(precision=precision))
        times.append(time.perf_counter() - start)
        stats = result.stats.frames[0]
    return statistics.median(times), stats


def _calibration_us() -> float:
    """A fixed numpy workload, to compare machines and moments (shared machines drift)."""
    a = np.linspace(1.0, 2.0, 1 << 16, dtype=np.float32)
    times = []
    for _ in range(7):
        start = time.perf_counter()
        for _ in range(1000):
            np.multiply(a, a)
        times.append((time.perf_counter() - start) / 1000 * 1e6)
    return statistics.median(times)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--shapes", type=int, nargs="+", default=[1, 16, 256, 4096], choices=sorted(LAYOUT))
    ap.add_argument("--lights", type=int, nargs="+", default=[0, 1], choices=[0, 1])
    ap.add_argument("--precision", nargs="+", default=["fp16", "fp32"], choices=["fp16", "fp32", "fp64"])
    ap.add_argument("--rotated", action="store_true", help="turn every sphere (no shortcut for unrotated shapes)")
    args = ap.parse_args()
    pixels = 512 * 384
    print(f"machine: a float32 multiply of 65,536 elements takes {_calibration_us():.1f} us (median of 7)")
    reuse_freed_memory()  # as the rend3r command does (rend3r/memory.py); the calibration runs before it
    print(f"{'shapes':>6} {'lights':>6} {'prec':>5} {'emulator s':>11} {'device s':>9} {'device/emu':>10} "
          f"{'target':>7} {'tests':>11} {'skipped':>13} {'hits':>7} {'nan':>9}")
    for lights in args.lights:
        for shapes in args.shapes:
            words = workload(shapes, lights, args.rotated)
            device = device_cycles(shapes, lights, pixels) / CLOCK_HZ
            for precision in args.precision:
                secs, st = measure(words, precision, args.runs)
                need = 10.0 if precision == "fp32" else 1.0
                ok = "met" if device / secs >= need else "MISSED"
                print(f"{shapes:>6} {lights:>6} {precision:>5} {secs:>11.3f} {device:>9.3f} {device / secs:>10.2f} "
                      f"{ok:>7} {st.tests:>11} {st.skipped:>13} {st.hits:>7} {st.nan_tests:>9}", flush=True)


if __name__ == "__main__":
    main()
