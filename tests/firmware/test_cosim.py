"""Runs the cocotb co-simulation of firmware/ (Icarus Verilog) from pytest."""

from __future__ import annotations

import shutil
import sys
from pathlib import Path

import pytest

FIRMWARE = Path(__file__).resolve().parents[2] / "firmware"
SOURCES = [*sorted((FIRMWARE / "rtl").glob("*.v")), FIRMWARE / "tests" / "tb_loader.v"]

if shutil.which("iverilog") is None or shutil.which("vvp") is None:
    pytest.skip("Icarus Verilog (iverilog, vvp) is not installed: apt-get install iverilog",
                allow_module_level=True)
runner_mod = pytest.importorskip("cocotb_tools.runner", reason="cocotb 2.x is not installed: pip install cocotb")


def build_and_run(tmp: Path, params: dict[str, int], env: dict[str, str]) -> None:
    """Build rend3r_loader with ``params`` and run firmware/tests/test_loader.py against it."""
    runner = runner_mod.get_runner("icarus")
    runner.build(sources=SOURCES, includes=[FIRMWARE / "rtl"], hdl_toplevel="tb_loader",
                 parameters=params, build_dir=tmp, timescale=("1ns", "1ps"))
    sys.path.insert(0, str(FIRMWARE / "tests"))  # the runner passes sys.path to the simulator
    try:
        results = runner.test(test_module="test_loader", hdl_toplevel="tb_loader",
                              build_dir=tmp, test_dir=tmp, extra_env=env)
    finally:
        sys.path.remove(str(FIRMWARE / "tests"))
    tests, failed = runner_mod.get_results(results)
    assert tests == 9 and failed == 0, f"{failed} of {tests} cocotb tests failed; see {tmp}"


def test_loader_cosim(tmp_path: Path) -> None:
    """All loader tests: 1,024-word banks, 16 clocks per UART bit."""
    build_and_run(tmp_path, {"AW": 10, "CLKS_PER_BIT": 16}, {"LOADER_AW": "10", "LOADER_CPB": "16"})
