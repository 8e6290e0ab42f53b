"""Where the host put two CPUs of this machine, measured from inside (placement.c): how
long a dependent read on one CPU takes for cache lines the other has just written, against
the same read on the writer itself.

On this project's VM (2 vCPUs of an AMD EPYC) the host moves the two vCPUs every few
seconds to minutes between three placements, which a split frame feels and two pinned
processes (two_cpus.py) mostly do not:

- ``one core``: the two hardware threads of one core (a shared L2: the other CPU's lines
  read about as fast as its own). Both CPUs then run slower; ``--jobs 2`` measured 1.12x
  and two processes about as little.
- ``shared L3``: two cores of one L3 (some 20 ns a line against 5). ``--jobs 2`` measured
  1.80x.
- ``separate L3s``: the lines cross between L3s (some 85 ns a line). Two processes
  share no data and keep their 2x, but a split frame hands its arrays between the two
  threads from pass to pass: ``--jobs 2`` measured 1.57x.

(Medians over 8,393 rounds of three frames each way at 4,096 spheres, fp32, 2026-12-04;
docs/performance.md.) The kinds are told apart by the ratio of the two reads, so that
they do not depend on this machine's clock.

    python benchmarks/placement.py [--rounds 10]
"""

from __future__ import annotations

import argparse
import ctypes
import os
import shutil
import subprocess
import sysconfig
import tempfile
import time
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

SOURCE = Path(__file__).with_suffix(".c")
#: Cross-CPU read time over the writer's own read time: below ONE_CORE the CPUs share an L2,
#: below SHARED_L3 an L3, else neither (measured here: about 1.4, 3.5 and 17).
ONE_CORE, SHARED_L3 = 2.0, 8.0
KINDS = ("one core", "shared L3", "separate L3s")


@dataclass(frozen=True)
class Placement:
    """One measure: ns per line read on the other CPU and on the writer's own, and what
    their ratio says."""

    cross_ns: float
    own_ns: float

    @property
    def kind(self) -> str:
        ratio = self.cross_ns / self.own_ns
        return KINDS[0] if ratio < ONE_CORE else KINDS[1] if ratio < SHARED_L3 else KINDS[2]


@lru_cache(maxsize=1)
def _library() -> ctypes.CDLL | None:
    """placement.c compiled with the C compiler Python was built with (or cc), None when
    there is none."""
    compiler = (sysconfig.get_config_var("CC") or "cc").split()[0]
    if shutil.which(compiler) is None:
        return None
    folder = Path(tempfile.mkdtemp(prefix="rend3r-placement-"))
    out = folder / "placement.so"
    subprocess.run([compiler, "-std=c11", "-O2", "-shared", "-fPIC", "-pthread", str(SOURCE), "-o", str(out)],
                   check=True, capture_output=True)
    lib = ctypes.CDLL(str(out))
    lib.cross_read_ns.restype = ctypes.c_int32
    lib.cross_read_ns.argtypes = [ctypes.c_int32, ctypes.c_int32, ctypes.c_int32, ctypes.POINTER(ctypes.c_double)]
    shutil.rmtree(folder)  # loaded: the file may go
    return lib


def available() -> str | None:
    """Why placements cannot be measured here, or None when they can."""
    if not hasattr(os, "sched_setaffinity"):
        return "needs Linux CPU affinity"
    if len(os.sched_getaffinity(0)) < 2:
        return "needs two CPUs"
    if _library() is None:
        return "needs a C compiler to build benchmarks/placement.c"
    return None


def measure(cpus: set[int], rounds: int = 4) -> Placement:
    """The placement of the first two of ``cpus``: the medians over ``rounds`` rounds
    (1..64) each way, averaged over the two ways. RuntimeError when a CPU cannot be used."""
    if not 1 <= rounds <= 64:
        raise ValueError(f"rounds {rounds} is outside 1..64")
    lib = _library()
    if lib is None or len(cpus) < 2:
        raise RuntimeError(f"placement not measured: {available()}")
    a, b = sorted(cpus)[:2]
    out = (ctypes.c_double * 2)()
    cross, own = [], []
    for src, dst in ((a, b), (b, a)):
        if lib.cross_read_ns(src, dst, rounds, out) != 0:
            raise RuntimeError(f"placement not measured: CPUs {src} and {dst} could not be used")
        cross.append(out[0])
        own.append(out[1])
    return Placement(sum(cross) / 2, sum(own) / 2)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=10, help="measures, one a second")
    args = ap.parse_args()
    if args.rounds < 1:
        ap.error(f"--rounds {args.rounds}: at least 1")
    why = available()
    if why:
        print(f"not measured: {why}")
        return 0
    for k in range(args.rounds):
        p = measure(os.sched_getaffinity(0))
        print(f"{p.kind:>12}: a line written on the other CPU read in {p.cross_ns:5.1f} ns, "
              f"one of its own in {p.own_ns:4.1f} ns", flush=True)
        if k + 1 < args.rounds:
            time.sleep(1)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
