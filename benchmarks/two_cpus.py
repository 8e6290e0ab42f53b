"""What two CPUs of this machine give a frame right now: two processes, each pinned to one
CPU and rendering the same frame with jobs=1, timed alone and side by side.

The ceiling of a round is 2 x (mean time alone) / (mean time side by side): the frames two
cores finish in the time one core finishes one. It is the yardstick for a ``--jobs 2``
frame in the same seconds, which splits one frame over the same two cores and cannot
split its serial part (caches may differ a little between one split frame and two
processes, so a share above 100% is possible). On a VM whose host is busy, two busy vCPUs
each run slower than one busy vCPU alone, and the ceiling falls well below 2.
bench_peer.py measures it in the rounds of its jobs measurement, so that a missed speedup
can be told apart from a machine that had no second core to give. It assumes an
otherwise idle machine: a third process on one CPU slows both measures of a round alike
here, but a split frame far more (each of its passes waits for its slowest chunk; with a
test suite running beside it, `--jobs 2` measured 0.95x against a ceiling of 1.98x).

    python benchmarks/two_cpus.py [--size 4096] [--precision fp32] [--rounds 10] [--warm 3]
"""

from __future__ import annotations

import argparse
import contextlib
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path
from typing import Self

import walls


def _worker(cpu: int, size: int, precision: str, width: int, height: int) -> None:
    """Renders on request: each line read (a count of untimed frames) is answered with
    the seconds of one more frame."""
    os.sched_setaffinity(0, {cpu})
    from rend3r.emu.options import EmuOptions
    from rend3r.emu.run import run_program
    from rend3r.memory import reuse_freed_memory

    reuse_freed_memory()
    wall, options = walls.wall(size, lights=1), EmuOptions(precision=precision, width=width, height=height, jobs=1)
    run_program(wall.words, options)
    print("ready", flush=True)
    for line in sys.stdin:
        for _ in range(int(line)):
            run_program(wall.words, options)
        start = time.perf_counter()
        run_program(wall.words, options)
        print(time.perf_counter() - start, flush=True)


class TwoCpus:
    """Two worker processes pinned to the first two of ``cpus``, rendering the wall of
    ``size`` spheres in ``precision``, each timed frame after ``warm`` untimed ones; a
    context manager (the workers end on exit)."""

    def __init__(self, cpus: set[int], size: int, precision: str, width: int, height: int, warm: int = 3) -> None:
        if len(cpus) < 2:
            raise ValueError(f"two CPUs needed, {len(cpus)} given")
        self.warm, self.workers = warm, []
        try:
            for cpu in sorted(cpus)[:2]:
                self.workers.append(subprocess.Popen(
                    [sys.executable, str(Path(__file__).resolve()), "--worker", str(cpu), "--size", str(size),
                     "--precision", precision, "--width", str(width), "--height", str(height)],
                    stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True))
            for w in self.workers:
                if w.stdout.readline().strip() != "ready":
                    raise RuntimeError(f"a two_cpus.py worker did not start (exit status {w.wait()})")
        except BaseException:
            self.close()
            raise

    def _frames(self, which: list[int]) -> list[float]:
        for i in which:
            self.workers[i].stdin.write(f"{self.warm}\n")
            self.workers[i].stdin.flush()
        answers = [self.workers[i].stdout.readline() for i in which]
        if not all(answers):
            raise RuntimeError("a two_cpus.py worker ended in the middle of a round")
        return [float(a) for a in answers]

    def ceiling(self) -> float:
        """One round: each worker alone, then both at once; 2 x mean alone / mean together."""
        alone = self._frames([0]) + self._frames([1])
        together = self._frames([0, 1])
        return 2 * statistics.mean(alone) / statistics.mean(together)

    def close(self) -> None:
        """Ends the workers (their stdin closed: they finish the loop) and waits for them."""
        for w in self.workers:
            with contextlib.suppress(BrokenPipeError):  # closed even when a dead worker's pipe fails the flush
                w.stdin.close()
        for w in self.workers:
            w.stdout.close()
            w.wait()

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def _at_least(low: int):
    """An argparse type: an integer of at least ``low``."""
    def check(text: str) -> int:
        value = int(text)
        if value < low:
            raise argparse.ArgumentTypeError(f"{value} is below {low}")
        return value
    return check


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", type=int, default=4096, choices=sorted(walls.LAYOUT), help="spheres in the wall")
    ap.add_argument("--precision", default="fp32", choices=("fp16", "fp32", "fp64"))
    ap.add_argument("--rounds", type=_at_least(1), default=10)
    ap.add_argument("--warm", type=_at_least(0), default=3, help="untimed frames before each timed one")
    ap.add_argument("--width", type=_at_least(1), default=512)
    ap.add_argument("--height", type=_at_least(1), default=384)
    ap.add_argument("--worker", type=int, help=argparse.SUPPRESS)  # the CPU of a worker process
    args = ap.parse_args()
    if args.worker is not None:
        _worker(args.worker, args.size, args.precision, args.width, args.height)
        return 0
    cpus = os.sched_getaffinity(0)
    if len(cpus) < 2:
        print(f"not measured: this process may use {len(cpus)} CPU")
        return 0
    with TwoCpus(cpus, args.size, args.precision, args.width, args.height, args.warm) as two:
        rounds = [two.ceiling() for _ in range(args.rounds)]
    print(f"{args.size:,} spheres, {args.precision}: two pinned processes render {statistics.median(rounds):.2f}x "
          f"the frames of one (median of {args.rounds} rounds; {min(rounds):.2f}-{max(rounds):.2f})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
