"""Issue 13: a commit storm against ``rend3r device`` over a loopback socket stays flat.

The old executor started a thread per commit and let each replaced render run to its end
(60 commits in 3 s at 4096x4096: 62 threads, > 10 GB). The figures at full scale come from
``benchmarks/bench_device_storm.py``; this test checks the invariants, not the timings.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np
import pytest

HERE = Path(__file__).resolve().parent
sys.path[:0] = [str(HERE.parents[1] / "benchmarks"), str(HERE)]  # the storm driver, the PNG helpers
from bench_device_storm import sphere_programs, storm
from test_execute import read_png, rendered_png


@pytest.mark.skipif(not Path("/proc/self/status").exists(), reason="needs /proc to count threads")
@pytest.mark.timeout(300)
def test_commit_storm_keeps_threads_and_memory_flat_and_renders_the_last_program(tmp_path):
    commits = 120
    r = storm(commits, 3.0, "4096x1024", tmp_path)
    assert r["acked"] == r["loads"] == commits
    # main thread, one render worker, the emulator's pool (one per core), pyserial's slack
    assert r["max_threads"] <= 3 + (os.cpu_count() or 1), r
    assert r["peak_rss"] < 1 << 30, r  # one 4096x1024 frame in flight, not one per commit
    assert r["files"] < commits // 2, r  # superseded renders were cancelled, not finished
    last = read_png(tmp_path / f"run{commits:04d}_frame0000.png")
    assert np.array_equal(last, rendered_png(tuple(sphere_programs(commits)[-1]), 4096, 1024))
