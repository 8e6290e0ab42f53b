"""Instruction processor throughput: programs of 1, 4,096 and 65,536 shapes, no rendering.

Run: ``python benchmarks/bench_processor.py [--runs R] [--shapes N ...]``. Each program is
``nr``, one camera word, one light word, 5 SE/SD pairs (10 words) per shape, ``nf``,
``er``: 65,536 shapes are 327,680 pairs, 655,360 words. For each it prints the
median over R runs of ``execute`` with an ``on_nf`` that does nothing (the program as a
list of ints, as ``load_program`` gives it, and as a uint32 array) in ms of wall clock
and of process CPU time, the best wall time (a guide on a loaded machine), the words/s
and the ratios to the targets (5 M words/s; 0.2 s for the 655,360-word program; above 1
is better; both from the median wall time), and separately the median time of
``shapes_from_scene`` at the nf.
"""

from __future__ import annotations

import argparse
import statistics
import time
from typing import Callable

import numpy as np

from rend3r.emu.options import EmuOptions
from rend3r.emu.processor import execute
from rend3r.emu.scene import Scene
from rend3r.emu.shapes import shapes_from_scene
from rend3r.isa import CameraSet, FrameOp, Func, LightSet, ShapeSet, Table, encode, lookup
from rend3r.isa.float16 import float_to_bits
from rend3r.isa.tables import SD_DATA, SD_DATA2, SE_INDEX_HI, SE_INDEX_LO, SHAPE_TYPE_CODES

TARGET_WORDS_PER_S = 5_000_000
TARGET_SECONDS, TARGET_WORDS = 0.2, 655_360
#: The properties each shape's pairs write (irot, jrot, krot stay 0).
PAIRS = (("type", "col"), ("xloc", "yloc"), ("zloc", "rrot"), ("xscl", "yscl"), ("zscl", "mat"))


def _columns(shapes: int) -> dict[str, np.ndarray]:
    """Each property's data bits per shape: spheres on a 256-wide grid at z = -200."""
    i = np.arange(shapes)
    half = lambda v: np.asarray(v, dtype=np.float16).view(np.uint16).astype(np.uint32)  # noqa: E731
    full = lambda v: np.full(shapes, v, dtype=np.uint32)  # noqa: E731
    x, y = i % 256 - 128.0, i // 256 - 128.0
    return {
        "type": full(SHAPE_TYPE_CODES["sphere"]), "col": full(0xF800), "mat": full(0),
        "xloc": half(x), "yloc": half(y), "zloc": half(np.full(shapes, -200.0)), "rrot": half(np.ones(shapes)),
        "xscl": half(np.full(shapes, 2.0)), "yscl": half(np.full(shapes, 2.0)), "zscl": half(np.full(shapes, 2.0)),
    }


def program(shapes: int) -> list[int]:
    """``nr``, a camera word, a light word, 5 SE/SD pairs per shape, ``nf``, ``er``."""
    i = np.arange(shapes, dtype=np.uint32)
    index_bits = (i >> SE_INDEX_LO.width) << SE_INDEX_HI.lo | (i & ((1 << SE_INDEX_LO.width) - 1)) << SE_INDEX_LO.lo
    data = _columns(shapes)
    prop = lambda name: lookup(Table.SHAPE, name).index  # noqa: E731
    pairs = np.empty((shapes, len(PAIRS), 2), dtype=np.uint32)
    for k, (a, b) in enumerate(PAIRS):
        se, _ = encode(ShapeSet(0, prop(a), prop(b), 0, 0))
        pairs[:, k, 0] = se | index_bits
        pairs[:, k, 1] = data[a] << SD_DATA.lo | data[b] << SD_DATA2.lo
    head = [*encode(FrameOp(Func.NR)), *encode(CameraSet(lookup(Table.CAMERA, "zloc").index, float_to_bits(1.0))),
            *encode(LightSet(0, lookup(Table.LIGHT, "src").index, 1))]
    return head + pairs.ravel().tolist() + [*encode(FrameOp(Func.NF)), *encode(FrameOp(Func.ER))]


def _times(runs: int, f: Callable[[], object]) -> tuple[float, float, float]:
    """Median wall-clock, median process CPU and best wall-clock seconds of ``f``."""
    wall, cpu = [], []
    for _ in range(runs):
        w0, c0 = time.perf_counter(), time.process_time()
        f()
        wall.append(time.perf_counter() - w0)
        cpu.append(time.process_time() - c0)
    return statistics.median(wall), statistics.median(cpu), min(wall)


def measure(words: list[int] | np.ndarray, runs: int) -> tuple[tuple[float, float, float], float]:
    """Seconds of execute with an on_nf that does nothing (see ``_times``), and the median
    wall seconds of shapes_from_scene at the nf (measured in separate runs)."""
    options = EmuOptions()
    reads: list[float] = []

    def read_shapes(scene: Scene, number: int) -> None:
        t0 = time.perf_counter()
        shapes_from_scene(scene, options.arith)
        reads.append(time.perf_counter() - t0)

    for _ in range(runs):
        execute(words, options, None, read_shapes)
    return _times(runs, lambda: execute(words, options, None, lambda scene, number: None)), statistics.median(reads)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--shapes", type=int, nargs="+", default=[1, 4096, 65536])
    args = ap.parse_args()
    print(f"{'shapes':>7} {'words':>8} {'input':>6} {'wall ms':>8} {'cpu ms':>7} {'best ms':>8} {'M words/s':>10} "
          f"{'x 5M/s':>7} {'x 0.2s':>7} {'shapes_from_scene ms':>21}")
    for shapes in args.shapes:
        words = program(shapes)
        for label, given in (("list", words), ("array", np.array(words, dtype=np.uint32))):
            (wall, cpu, best), read = measure(given, args.runs)
            rate = len(words) / wall
            budget = f"{TARGET_SECONDS / wall:.2f}" if len(words) >= TARGET_WORDS else "-"
            print(f"{shapes:>7} {len(words):>8} {label:>6} {wall * 1e3:>8.2f} {cpu * 1e3:>7.2f} {best * 1e3:>8.2f} "
                  f"{rate / 1e6:>10.2f} {rate / TARGET_WORDS_PER_S:>7.2f} {budget:>7} {read * 1e3:>21.2f}")


if __name__ == "__main__":
    main()
