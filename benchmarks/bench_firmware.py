"""Simulated cycles for the firmware loader to take a 1,024-word program, against wire time.

    python benchmarks/bench_firmware.py

Builds firmware/rtl with Icarus Verilog (1,024-word banks, 434 clocks per UART bit:
115,200 baud at 50 MHz) and runs firmware/tests/bench_loader.py under cocotb. The sender
sends BEGIN, waits for its ACK, sends the DATA frames back to back at line rate (minimum
inter-frame gap on RMII, no gap between bytes on UART), waits for their ACKs, then COMMIT.
The baseline is the wire time of the same frames sent back to back with nothing lost.
The simulation is deterministic, so one run is the figure (no median needed).
"""

from __future__ import annotations

import json
import sys
import tempfile
import time
from pathlib import Path

FIRMWARE = Path(__file__).resolve().parents[1] / "firmware"
CLOCK_HZ = 50_000_000


def main() -> None:
    from cocotb_tools.runner import get_runner

    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "bench.json"
        runner = get_runner("icarus")
        runner.build(sources=[*sorted((FIRMWARE / "rtl").glob("*.v")), FIRMWARE / "tests" / "tb_loader.v"],
                     includes=[FIRMWARE / "rtl"], hdl_toplevel="tb_loader", parameters={"AW": 10, "CLKS_PER_BIT": 434},
                     build_dir=tmp, timescale=("1ns", "1ps"))
        start = time.perf_counter()
        sys.path.insert(0, str(FIRMWARE / "tests"))  # the runner passes sys.path to the simulator
        runner.test(test_module="bench_loader", hdl_toplevel="tb_loader", build_dir=tmp,
                    test_dir=tmp, extra_env={"BENCH_OUT": str(out), "LOADER_AW": "10",
                                             "LOADER_CPB": "434"})
        wall = time.perf_counter() - start
        results = json.loads(out.read_text())
    print(f"1,024-word load, 50 MHz clock (simulated in {wall:.1f} s wall)")
    print(f"{'link':<14}{'cycles':>12}{'ms':>9}{'wire cycles':>13}{'ratio':>8}"
          f"{'DATA wire':>11}{'DATA+ACKs':>11}")
    for link, label in (("rmii", "RMII 100M"), ("uart", "UART 115200")):
        r = results[link]
        print(f"{label:<14}{r['cycles_total']:>12,}{1e3 * r['cycles_total'] / CLOCK_HZ:>9.2f}"
              f"{r['wire_cycles_forward']:>13,}{r['cycles_total'] / r['wire_cycles_forward']:>8.3f}"
              f"{r['wire_cycles_data']:>11,}{r['cycles_data_acked']:>11,}")
    print("ratio = cycles from BEGIN's first bit to COMMIT's ACK / forward wire time; "
          "DATA+ACKs = cycles from the end of BEGIN's ACK to the last DATA ACK")


if __name__ == "__main__":
    main()
