"""Assembler throughput on a generated 100,000-line program of mixed instructions.

Run: ``python benchmarks/bench_asm.py [--lines N] [--runs R]``. Prints the median
lines/s over R runs (by process CPU time, the one-core figure, and by wall clock) and its
ratio to the 50,000 lines/s target, plus the rate of the
full-grammar path alone (every line through Lark, fast path off) on a sample, as a
baseline measured in the same run.

Then ``programs/stress4096.asm`` (20,480 statements from nested ``.rept`` blocks): the
median seconds to assemble it, by CPU and wall clock, against the 0.3 s target, and the
same with ``fast=False``, which runs the .rept bodies uncompiled through the general
evaluator (the path before rend3r/asm/compiled.py), as the baseline of the same run.

The program mixes every mnemonic and table, float literals of many shapes (integers,
decimals, exponents, negatives, -0), ints in decimal, 0x and 0b 5_6_5 form, raw 0h bits,
comments and blank lines, and about 2% lines with named constants and arithmetic.
"""

from __future__ import annotations

import argparse
import random
import statistics
import time
from pathlib import Path

from rend3r.asm.assembler import assemble_source
from rend3r.asm.fastpath import clear_cache
from rend3r.asm.parser import clear_operand_cache
from rend3r.isa.tables import PROPERTIES, Table, ValueType

TARGET_LINES_PER_S = 50_000
STRESS = Path(__file__).resolve().parents[1] / "programs" / "stress4096.asm"
TARGET_STRESS_S = 0.3


def _float_text(rng: random.Random) -> str:
    kind = rng.randrange(6)
    if kind == 0:
        return str(rng.randint(-100, 100))
    if kind == 1:
        return f"{rng.uniform(-50, 50):.{rng.randint(1, 4)}f}"
    if kind == 2:
        return f"{rng.uniform(1, 9):.2f}e{rng.randint(-3, 3)}"
    if kind == 3:
        return rng.choice(["0", "-0", "1", "0.5", "-1", "65504", "0.25"])
    if kind == 4:
        return f"{rng.uniform(-4, 4):.3f}"
    return f"0h{rng.randrange(0x10000):04x}"


def _value(rng: random.Random, prop) -> str:
    if prop.vtype is ValueType.FLOAT16:
        return _float_text(rng)
    if prop.vtype is ValueType.ZERO:
        return "0"
    if prop.name == "col":
        c = rng.randrange(0x10000)
        return rng.choice([f"0b{c >> 11:05b}_{(c >> 5) & 63:06b}_{c & 31:05b}", f"0x{c:04x}", str(c)])
    return str(rng.randrange(1 << prop.bits))


def _props(table: Table) -> list:
    return [p for p in PROPERTIES[table] if p.vtype is not ValueType.ZERO]


def generate(lines: int, seed: int = 1) -> str:
    """A deterministic program of ``lines`` lines ending in two ``er``."""
    rng = random.Random(seed)
    cam, light, shape, tri = (_props(t) for t in Table)
    out = ["// generated benchmark program", "RADIUS = 0.5", "ORIGIN = -2.25", "RED = 0b11111_000000_00000"]
    while len(out) < lines - 2:
        r = rng.random()
        if r < 0.03:
            out.append(rng.choice(["", "// a comment line", "   ; another"]))
        elif r < 0.05:
            i = rng.randrange(4096)
            out.append(rng.choice([
                f"sp {i}, xloc, yloc, ORIGIN + {i % 64} * RADIUS, -RADIUS * 2",
                f"sp {i}, col, mat, RED, {i % 4}",
                f"cam zloc, ({i} - 2048) / 256",
            ]))
        elif r < 0.07:
            out.append(rng.choice(["nr", "nf", "lr", "er"]))
        elif r < 0.25:
            p = rng.choice(cam)
            out.append(f"cam {rng.choice(p.names)}, {_value(rng, p)}")
        elif r < 0.45:
            p = rng.choice(light)
            out.append(f"lt {rng.randrange(64)}, {p.name}, {_value(rng, p)}   // light")
        else:
            table, props, mn = (Table.SHAPE, shape, "sp") if r < 0.85 else (Table.TRIANGLE, tri, "tr")
            p, q = rng.sample(props, 2)
            out.append(f"{mn} {rng.randrange(1 << 19)}, {p.name}, {q.register}, {_value(rng, p)}, {_value(rng, q)}")
    out += ["er", "er"]
    return "\n".join(out) + "\n"


def _seconds(text: str, name: str, runs: int, fast: bool) -> tuple[float, float]:
    """Median seconds to assemble ``text`` (cold caches), by wall clock and by this
    process's CPU time (the CPU figure is the one-core time even when other jobs share
    the machine)."""
    wall, cpu = [], []
    for _ in range(runs):
        clear_cache()
        clear_operand_cache()
        t0, c0 = time.perf_counter(), time.process_time()
        result = assemble_source(text, name, fast=fast)
        wall.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
        if not result.ok:
            raise SystemExit("benchmark program failed to assemble:\n" + result.format_diagnostics()[:2000])
    return statistics.median(wall), statistics.median(cpu)


def _rate(text: str, runs: int, fast: bool) -> tuple[float, float]:
    """Median lines/s by wall-clock time and by CPU time."""
    lines = text.count("\n")
    wall, cpu = _seconds(text, "bench.asm", runs, fast)
    return lines / wall, lines / cpu


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lines", type=int, default=100_000)
    ap.add_argument("--runs", type=int, default=5)
    args = ap.parse_args()
    text = generate(args.lines)
    sample = generate(5_000, seed=2)
    t0 = time.perf_counter()
    _rate(text, 1, fast=True)  # first run: also builds the Lark parser once per process
    first = time.perf_counter() - t0
    wall, cpu = _rate(text, args.runs, fast=True)
    slow_wall, slow_cpu = _rate(sample, max(args.runs // 2, 1), fast=False)
    print(f"program: {args.lines} lines, {args.runs} runs; first run incl. parser construction {first:.2f} s wall")
    for label, rate in (("CPU time", cpu), ("wall clock", wall)):
        print(f"assembler ({label}): {rate:,.0f} lines/s (median); "
              f"target {TARGET_LINES_PER_S:,} -> ratio {rate / TARGET_LINES_PER_S:.2f}")
    print(f"full-grammar path only (fast path off, 5,000-line sample): {slow_cpu:,.0f} lines/s CPU, "
          f"{slow_wall:,.0f} wall; speed-up of the default path {cpu / slow_cpu:.1f}x")
    stress = STRESS.read_text()
    wall_s, cpu_s = _seconds(stress, str(STRESS), args.runs, fast=True)
    old_wall, old_cpu = _seconds(stress, str(STRESS), args.runs, fast=False)
    print(f"stress4096.asm: {cpu_s:.3f} s CPU, {wall_s:.3f} s wall (median of {args.runs}); target "
          f"{TARGET_STRESS_S} s -> ratio {cpu_s / TARGET_STRESS_S:.2f}; uncompiled .rept bodies {old_cpu:.3f} s CPU, "
          f"{old_wall:.3f} s wall: speed-up {old_cpu / cpu_s:.1f}x")


if __name__ == "__main__":
    main()
