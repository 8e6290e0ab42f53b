"""bench_peer.py's measure of where the host put two CPUs (placement.py, placement.c)."""

from __future__ import annotations

import ctypes
import math
import os
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
import placement

WHY = placement.available()


@pytest.mark.parametrize(("cross", "own", "kind"), [
    (4.2, 4.1, "one core"), (7.9, 4.0, "one core"), (8.0, 4.0, "shared L3"), (19.0, 5.0, "shared L3"),
    (27.9, 4.0, "shared L3"), (28.0, 4.0, "separate L3s"), (85.0, 5.0, "separate L3s")])
def test_the_kind_follows_the_ratio_of_the_reads(cross, own, kind):
    assert placement.Placement(cross, own, calibrated=True).kind == kind


@pytest.mark.parametrize(("cross", "own", "kind"), [
    (7.9, 4.0, "one core"), (8.0, 4.0, "two cores"), (70.0, 3.5, "two cores")])
def test_a_design_the_cuts_were_not_set_for_names_no_l3(cross, own, kind):
    assert placement.Placement(cross, own, calibrated=False).kind == kind


@pytest.mark.skipif(WHY is not None, reason=f"placement not measured: {WHY}")
def test_two_cpus_are_measured_and_placed():
    p = placement.measure(os.sched_getaffinity(0), rounds=3)
    assert all(math.isfinite(x) and 0 < x < 10_000 for x in (p.cross_ns, p.own_ns))
    assert p.kind in placement.KINDS
    assert p.calibrated == (placement.vendor() == "AuthenticAMD")


@pytest.mark.parametrize(("lines", "vendor"), [
    (["processor\t: 0\n", "vendor_id\t: AuthenticAMD\n", "vendor_id\t: GenuineIntel\n"], "AuthenticAMD"),
    (["vendor_id : GenuineIntel\n"], "GenuineIntel"), (["processor\t: 0\n", "model name\t: vendor_id\n"], ""), ([], "")])
def test_the_vendor_is_the_first_vendor_id_line(lines, vendor):
    assert placement.vendor_of(lines) == vendor


@pytest.mark.skipif(WHY is not None, reason=f"placement not measured: {WHY}")
def test_cpus_it_may_not_use_and_bad_counts_are_refused():
    cpu = min(os.sched_getaffinity(0))
    with pytest.raises(RuntimeError, match="could not be used"):
        placement.measure({cpu, 1000})  # not a CPU of this machine: the reader cannot be pinned
    out = (ctypes.c_double * 2)()
    lib = placement._library()
    assert lib.cross_read_ns(1000, cpu, 1, out) == -1  # nor the writer
    assert lib.cross_read_ns(cpu, cpu, 1, out) == -1  # one CPU is not two
    for rounds in (0, 2, 65):
        with pytest.raises(ValueError, match="not an odd number"):
            placement.measure(os.sched_getaffinity(0), rounds)
    with pytest.raises(RuntimeError, match="two CPUs needed"):
        placement.measure({cpu})
