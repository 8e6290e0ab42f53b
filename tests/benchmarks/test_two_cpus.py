"""bench_peer.py's measure of what two CPUs give: two pinned worker processes that render on
request, alone and side by side."""

from __future__ import annotations

import math
import os
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
from two_cpus import TwoCpus

CPUS = os.sched_getaffinity(0)


@pytest.mark.skipif(len(CPUS) < 2, reason="needs two CPUs to pin the workers to")
def test_two_workers_pinned_apart_report_a_ceiling():
    with TwoCpus(CPUS, 1, "fp32", 16, 12) as two:
        ceilings = [two.ceiling() for _ in range(2)]
        pids = [w.pid for w in two.workers]
        pinned = [os.sched_getaffinity(pid) for pid in pids]
    assert all(math.isfinite(c) and c > 0 for c in ceilings)
    assert pinned == [{cpu} for cpu in sorted(CPUS)[:2]]  # one CPU each, different ones
    assert all(w.returncode == 0 for w in two.workers)  # they ended when the block did
