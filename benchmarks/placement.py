"""Where the host put two CPUs of this machine, measured from inside (placement.c): how
long a dependent read on one CPU takes for cache lines the other has just written, against
the same read on the writer itself.

On the host of AMD EPYCs this project's VM first ran on, the host moved the two vCPUs
every few seconds to minutes between three placements, which a split frame feels and two
pinned processes (two_cpus.py) mostly do not:

- ``one core``: the two hardware threads of one core (a shared L2: the other CPU's lines
  read about as fast as its own). Both CPUs then run slower; ``--jobs 2`` measured 1.12x.
- ``shared L3``: two cores of one L3 (some 20 ns a line against 5). ``--jobs 2`` measured
  1.80x.
- ``separate L3s``: the lines cross between L3s (some 85 ns a line). Two processes
  share no data and keep their 2x, but a split frame hands its arrays between the two
  threads from pass to pass: ``--jobs 2`` measured 1.57x.

(Medians over 8,393 rounds of three frames each way at 4,096 spheres, fp32, 2026-12-04;
docs/performance-history.md.) The kinds are told apart by the ratio of the two reads, so that
they do not depend on this machine's clock; the cuts between them are set from that
EPYC's figures (ratios of about 1-1.8, 2.4-5.3 and 9.6-23), so they name L3s on AMD
processors only. Elsewhere a slow read does not tell the L3s apart: on the Xeon host the
VM moved to (2026-12-05), whose cores share one L3 in slices on a mesh, a line crossed in
some 70 ns (a ratio of about 20), as between the EPYC's L3s. There the kind above
``one core`` is ``two cores``, which says nothing of the L3s (nor whether the two cores
are on one socket); the ``one core`` cut is the EPYC's on every processor.

    python benchmarks/placement.py [--measures 10]
"""

from __future__ import annotations

import argparse
import ctypes
import os
import shutil
import subprocess
import sys
import sysconfig
import tempfile
import time
from collections.abc import Iterable
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

SOURCE = Path(__file__).with_suffix(".c")
#: Cross-CPU read time over the writer's own read time: below ONE_CORE the CPUs share an L2,
#: below SHARED_L3 an L3, else neither (each cut near the geometric middle of the ranges
#: measured on either side of it here, on an AMD EPYC: the vendor CALIBRATED names).
ONE_CORE, SHARED_L3 = 2.0, 7.0
CALIBRATED = "AuthenticAMD"
KINDS = ("one core", "shared L3", "separate L3s", "two cores")


@dataclass(frozen=True)
class Placement:
    """One measure: ns per line read on the other CPU and on the writer's own, and what
    their ratio says (about L3s only on a processor of the CALIBRATED vendor)."""

    cross_ns: float
    own_ns: float
    calibrated: bool  # on a processor of the CALIBRATED vendor

    @property
    def kind(self) -> str:
        ratio = self.cross_ns / self.own_ns
        if ratio < ONE_CORE:
            return KINDS[0]
        if not self.calibrated:
            return KINDS[3]
        return KINDS[1] if ratio < SHARED_L3 else KINDS[2]


@lru_cache(maxsize=1)
def vendor() -> str:
    """This processor's vendor as Linux names it (``AuthenticAMD``, ``GenuineIntel``), or
    an empty string where /proc/cpuinfo does not say."""
    try:
        with open("/proc/cpuinfo", encoding="ascii", errors="replace") as f:
            return vendor_of(f)
    except OSError:
        return ""


def vendor_of(cpuinfo: Iterable[str]) -> str:
    """The first ``vendor_id`` of /proc/cpuinfo's lines, or an empty string."""
    for line in cpuinfo:
        key, _, value = line.partition(":")
        if key.strip() == "vendor_id":
            return value.strip()
    return ""


@lru_cache(maxsize=1)
def _library() -> ctypes.CDLL | None:
    """placement.c compiled with the C compiler Python was built with, else cc; None when
    neither is found or the build or its loading fails."""
    configured = (sysconfig.get_config_var("CC") or "").split()[:1]
    compiler = next((c for c in [*configured, "cc"] if shutil.which(c)), None)
    if compiler is None:
        return None
    with tempfile.TemporaryDirectory(prefix="rend3r-placement-") as folder:
        out = Path(folder) / "placement.so"
        try:
            subprocess.run([compiler, "-std=c11", "-O2", "-shared", "-fPIC", "-pthread", str(SOURCE), "-o", str(out)],
                           check=True, capture_output=True)
            lib = ctypes.CDLL(str(out))  # loaded: the file may go with its folder
        except (OSError, subprocess.CalledProcessError):
            return None
    lib.cross_read_ns.restype = ctypes.c_int32
    lib.cross_read_ns.argtypes = [ctypes.c_int32, ctypes.c_int32, ctypes.c_int32, ctypes.POINTER(ctypes.c_double)]
    return lib


def available() -> str | None:
    """Why placements cannot be measured here, or None when they can."""
    if not hasattr(os, "sched_setaffinity"):
        return "needs Linux CPU affinity"
    if len(os.sched_getaffinity(0)) < 2:
        return "needs two CPUs"
    if _library() is None:
        return "needs a C compiler that builds and loads benchmarks/placement.c"
    return None


def measure(cpus: set[int], rounds: int = 5) -> Placement:
    """The placement of the first two of ``cpus``: the medians over ``rounds`` rounds (an
    odd number, 1..63) each way, averaged over the two ways. RuntimeError when it cannot
    be measured (a CPU cannot be used, or no compiler)."""
    if not (1 <= rounds <= 63 and rounds % 2):
        raise ValueError(f"rounds {rounds} is not an odd number in 1..63")
    if len(cpus) < 2:
        raise RuntimeError(f"placement not measured: two CPUs needed, {len(cpus)} given")
    lib = _library()
    if lib is None:
        raise RuntimeError(f"placement not measured: {available()}")
    a, b = sorted(cpus)[:2]
    out = (ctypes.c_double * 2)()
    cross, own = [], []
    for src, dst in ((a, b), (b, a)):
        if lib.cross_read_ns(src, dst, rounds, out) != 0:
            raise RuntimeError(f"placement not measured: CPUs {src} and {dst} could not be used")
        cross.append(out[0])
        own.append(out[1])
    return Placement(sum(cross) / 2, sum(own) / 2, vendor() == CALIBRATED)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--measures", type=int, default=10, help="how many, one a second")
    args = ap.parse_args()
    if args.measures < 1:
        ap.error(f"--measures {args.measures}: at least 1")
    why = available()
    if why:
        print(f"not measured: {why}")
        return 0
    try:
        for k in range(args.measures):
            p = measure(os.sched_getaffinity(0))
            print(f"{p.kind:>12}: a line written on the other CPU read in {p.cross_ns:5.1f} ns, "
                  f"one of its own in {p.own_ns:4.1f} ns", flush=True)
            if k + 1 < args.measures:
                time.sleep(1)
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return 130
    except RuntimeError as e:  # a CPU taken away meanwhile
        print(e, file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
