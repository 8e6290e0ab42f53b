"""cocotb benchmark (run by benchmarks/bench_firmware.py): cycles to load 1,024 words.

For each link the sender does what rend3r send does on a loss-free line: BEGIN and wait
for its ACK, all DATA frames back to back (4 frames, within the window of 8), wait for
their ACKs, COMMIT and wait for its ACK. Results go to the JSON file $BENCH_OUT.
"""

from __future__ import annotations

import json
import os
import random

import cocotb
from cocotb.triggers import Timer

from rend3r.transport.protocol import FrameType
from rend3r.transport.session import load_frames

from sim_links import IFG_BYTES, eth_for, serial_bytes, wire_bytes
from test_loader import Sender, bring_up

WORDS = 1024


def program() -> list[int]:
    rng = random.Random(WORDS)
    return [rng.getrandbits(32) for _ in range(WORDS)]


def wire_cycles(link: str, frame: bytes, cpb: int) -> int:
    """Clock cycles (50 MHz) the frame occupies on the line, minimum gap included."""
    if link == "rmii":
        return 4 * (len(wire_bytes(eth_for(frame))) + IFG_BYTES)
    return 10 * cpb * len(serial_bytes(frame))


async def bench(dut, link: str) -> None:
    pins = await bring_up(dut)
    sender = Sender(pins, link, random.Random(1))
    words = program()
    frames = load_frames(words, 0x5151, 77)
    begin, data, commit = frames[0], frames[1:-1], frames[-1]
    t0 = pins.now()
    assert (await sender.request(begin)).type == FrameType.ACK
    t_begin = pins.now()
    for f in data:
        await sender.put(f.encode())
    t_sent = pins.now()
    while len(pins.replies) < len(data):
        await Timer(20 * 16, "ns")
    assert all(r.type == FrameType.ACK for r in pins.replies)
    assert sorted(r.seq for r in pins.replies) == sorted(f.seq for f in data)
    t_data = max(pins.reply_cycles[-len(data):])
    pins.replies.clear()
    assert (await sender.request(commit)).type == FrameType.ACK
    t_end = pins.now()
    assert await pins.read_memory(WORDS) == words
    result = {
        "link": link, "words": WORDS, "frames": len(frames), "clks_per_bit": pins.cpb,
        "cycles_total": t_end - t0, "cycles_begin": t_begin - t0,
        "cycles_data_sent": t_sent - t_begin, "cycles_data_acked": t_data - t_begin,
        "cycles_commit": t_end - t_data,
        "wire_cycles_forward": sum(wire_cycles(link, f.encode(), pins.cpb) for f in frames),
        "wire_cycles_data": sum(wire_cycles(link, f.encode(), pins.cpb) for f in data),
    }
    out = os.environ["BENCH_OUT"]
    merged = json.load(open(out)) if os.path.exists(out) else {}
    merged[link] = result
    with open(out, "w") as fh:
        json.dump(merged, fh, indent=1)


@cocotb.test()
async def bench_rmii(dut):
    await bench(dut, "rmii")


@cocotb.test()
async def bench_uart(dut):
    await bench(dut, "uart")
