"""cocotb tests of rend3r_loader against rend3r's own transport code (run by tests/firmware).

Frames are built with rend3r.transport, replies are decoded with it and compared byte for
byte with the reference receiver (rend3r.transport.device.DeviceCore), and the instruction
memory is read back through the processor's port.
"""

from __future__ import annotations

import os
import random
import subprocess
import sys
from pathlib import Path

import cocotb
from cocotb.triggers import ClockCycles, Timer

from rend3r.transport.device import DeviceCore
from rend3r.transport.protocol import (
    PROGRAM_INFO, Frame, FrameType, Nack, Status, program_crc, words_to_bytes,
)
from rend3r.transport.session import load_frames

from cobs_patterns import BOUNDARY_RUNS, boundary_words
from sim_links import CLOCK_NS, Pins, eth_for, serial_bytes, wire_bytes

REPO = Path(__file__).resolve().parents[2]
AW = int(os.environ.get("LOADER_AW", "10"))
CPB = int(os.environ.get("LOADER_CPB", "16"))
RETRYABLE = {Nack.NO_LOAD, Nack.OUT_OF_RANGE, Nack.MISMATCH}


def assembled(name: str) -> list[int]:
    """The words the assembler makes of programs/<name>.asm."""
    from rend3r.transport.cli import read_program

    return list(read_program(str(REPO / "programs" / name)).words)


async def bring_up(dut) -> Pins:
    """Reset, idle lines, monitors (tb_loader.v makes the 50 MHz clock)."""
    dut.rst.value = 1
    dut.rmii_crs_dv.value = 0
    dut.rmii_rxd.value = 0
    dut.uart_rx.value = 1
    dut.prog_addr.value = 0
    dut.prog_clk.value = 0
    dut.frames_rendered.value = 0
    await ClockCycles(dut.clk, 4)
    dut.rst.value = 0
    await ClockCycles(dut.clk, 4)
    pins = Pins(dut, CPB)
    pins.start_monitors()
    return pins


class Sender:
    """Stop-and-wait sender over one link, with optional drops and corruption."""

    def __init__(self, pins: Pins, link: str, rng: random.Random,
                 drop: float = 0.0, corrupt: float = 0.0) -> None:
        self.pins, self.link, self.rng = pins, link, rng
        self.drop, self.corrupt = drop, corrupt
        self.corrupted = self.dropped = 0
        words_time = 1 << AW  # a COMMIT's CRC pass over the whole bank, at most
        self.timeout = words_time + (600 if link == "rmii" else 60 * 10 * CPB)

    async def put(self, frame: bytes, mangle: bool = False) -> None:
        """Send one protocol frame; ``mangle`` flips one byte on the wire after framing."""
        if self.link == "rmii":
            wire = bytearray(wire_bytes(eth_for(frame)))
            lo, hi = 8 + 14, len(wire) - 4  # payload bytes: a bad FCS, not a filtered frame
        else:
            wire = bytearray(serial_bytes(frame))
            lo, hi = 0, len(wire) - 1  # never the delimiter
        if mangle:
            i = self.rng.randrange(lo, hi)
            flip = self.rng.choice([x for x in (1, 2, 4, 8, 16, 32, 64, 128) if x != wire[i]])
            wire[i] ^= flip
        if self.link == "rmii":
            await self.pins.send_rmii(bytes(wire))
        else:
            await self.pins.send_uart(bytes(wire))

    async def reply_to(self, f: Frame) -> Frame | None:
        """The reply matching ``f`` (load, seq, ref), or None after the timeout."""
        step = 16 if self.link == "rmii" else CPB  # polling interval in cycles
        for _ in range(self.timeout // step + 1):
            for r in self.pins.replies:
                if (r.load, r.seq, r.ref) == (f.load, f.seq, f.type):
                    self.pins.replies.remove(r)
                    return r
            await Timer(CLOCK_NS * step, "ns")
        return None

    async def request(self, f: Frame, tries: int = 10) -> Frame:
        """Send ``f`` until it is answered, injecting the configured faults."""
        for _ in range(tries):
            fate = self.rng.random()
            if fate < self.drop:
                self.dropped += 1
                continue  # lost on the way: the sender would time out and resend
            mangle = fate < self.drop + self.corrupt
            self.corrupted += mangle
            await self.put(f.encode(), mangle)
            reply = await self.reply_to(f)
            if reply is not None:
                return reply
        raise AssertionError(f"no reply to {FrameType(f.type).name} seq {f.seq} after {tries} tries")

    async def load(self, words: list[int], chunk: int = 256) -> int:
        """Load ``words`` like rend3r send (restarting on NO_LOAD/OUT_OF_RANGE/MISMATCH)."""
        for attempt in range(8):
            frames = load_frames(words, self.rng.randrange(1, 1 << 16), self.rng.randrange(1 << 16), chunk)
            for f in frames:
                r = await self.request(f)
                if r.type == FrameType.NACK:
                    assert r.code in RETRYABLE, f"fatal NACK {Nack(r.code).name}"
                    break
            else:
                return attempt
        raise AssertionError("load did not complete in 8 attempts")

    async def status(self) -> Status:
        r = await self.request(Frame(FrameType.STATUS, 0, self.rng.randrange(1 << 16)))
        assert r.type == FrameType.ACK
        return Status.unpack(r.payload)


async def check_loaded(pins: Pins, sender: Sender, words: list[int]) -> None:
    """Memory holds ``words`` (zeros after them) and STATUS reports their length and CRC."""
    span = min(len(words) + 8, 1 << AW)
    got = await pins.read_memory(span)
    assert got == (words + [0] * span)[:span]
    st = await sender.status()
    assert (st.words, st.crc) == (len(words), program_crc(words))
    assert pins.bad_replies == 0


@cocotb.test()
async def uart_load_assembled(dut):
    """An assembled program over UART/COBS lands word for word; ACKs decode."""
    pins = await bring_up(dut)
    sender = Sender(pins, "uart", random.Random(1))
    words = assembled("sphere.asm")
    assert await sender.load(words, chunk=8) == 0
    await check_loaded(pins, sender, words)
    st = await sender.status()
    assert (st.loads, st.malformed, st.staging, st.running) == (1, 0, False, True)


@cocotb.test()
async def uart_faults(dut):
    """Corrupted and dropped serial frames: the load still completes exactly."""
    pins = await bring_up(dut)
    sender = Sender(pins, "uart", random.Random(2), drop=0.15, corrupt=0.2)
    words = assembled("shadow.asm")
    await sender.load(words, chunk=4)
    assert sender.corrupted and sender.dropped
    sender.drop = sender.corrupt = 0.0
    await check_loaded(pins, sender, words)
    st = await sender.status()
    assert st.malformed == sender.corrupted


@cocotb.test()
async def rmii_faults_and_atomicity(dut):
    """RMII loads with faults; partial and mismatching loads leave the program untouched."""
    pins = await bring_up(dut)
    rng = random.Random(3)
    sender = Sender(pins, "rmii", rng, drop=0.15, corrupt=0.2)
    first = assembled("camera.asm")
    await sender.load(first, chunk=16)
    assert sender.corrupted and sender.dropped
    sender.drop = sender.corrupt = 0.0
    await check_loaded(pins, sender, first)
    st = await sender.status()
    assert st.malformed == sender.corrupted

    # a partial load (BEGIN and half the DATA, never committed)
    second = assembled("lights.asm")
    frames = load_frames(second, 0x4242, 100, 8)
    for f in frames[: len(frames) // 2]:
        assert (await sender.request(f)).type == FrameType.ACK
    await check_loaded(pins, sender, first)
    assert (await sender.status()).staging

    # a complete load whose DATA carries a wrong word: COMMIT is refused
    frames = load_frames(second, 0x4343, 200, 8)
    bad = list(second)
    bad[5] ^= 0x10
    tampered = load_frames(bad, 0x4343, 200, 8)[1]
    for f in [frames[0], tampered, *frames[2:-1]]:
        assert (await sender.request(f)).type == FrameType.ACK
    r = await sender.request(frames[-1])
    assert (r.type, r.code) == (FrameType.NACK, Nack.MISMATCH)
    await check_loaded(pins, sender, first)

    # resending the good DATA frame repairs the staged words; COMMIT then succeeds
    assert (await sender.request(frames[1])).type == FrameType.ACK
    assert (await sender.request(frames[-1])).type == FrameType.ACK
    await check_loaded(pins, sender, second)


@cocotb.test()
async def rmii_filters(dut):
    """Other MACs and EtherTypes are ignored, broadcast is accepted, bad FCS is counted."""
    pins = await bring_up(dut)
    sender = Sender(pins, "rmii", random.Random(4))
    st = Frame(FrameType.STATUS, 0, 7).encode()
    await pins.send_rmii(wire_bytes(eth_for(st, dst=bytes.fromhex("69695a065492"))))
    await pins.send_rmii(wire_bytes(eth_for(st, ethertype=0x0800)))
    await Timer(CLOCK_NS * 800, "ns")
    assert pins.replies == []
    broken = bytearray(wire_bytes(eth_for(st)))
    broken[-1] ^= 1  # FCS
    await pins.send_rmii(bytes(broken))
    await Timer(CLOCK_NS * 800, "ns")
    assert pins.replies == []
    await pins.send_rmii(wire_bytes(eth_for(st, dst=b"\xff" * 6)))
    r = await sender.reply_to(Frame(FrameType.STATUS, 0, 7))
    assert r is not None and Status.unpack(r.payload).malformed == 1


def reference_script(rng: random.Random) -> list[Frame]:
    """Requests covering every reply the protocol defines, in one sequence."""
    prog = [rng.randrange(1 << 32) for _ in range(20)]
    info = PROGRAM_INFO.pack(len(prog), program_crc(prog))
    too_big = PROGRAM_INFO.pack((1 << AW) + 1, 0)
    load = load_frames(prog, 0x0101, 10, 8)
    other = load_frames(prog[:4], 0x0202, 50, 8)
    return [
        Frame(FrameType.STATUS, 0, 1),
        Frame(FrameType.STATUS, 0, 2, version=2),                           # BAD_VERSION
        Frame(0x09, 0, 3),                                                  # BAD_TYPE
        Frame(FrameType.RUN, 0, 4, count=1),                                # BAD_FIELDS
        Frame(FrameType.BEGIN, 9, 5, payload=too_big),                      # TOO_LARGE
        Frame(FrameType.BEGIN, 9, 6, payload=info[:4]),                     # BAD_FIELDS
        Frame(FrameType.DATA, 9, 7, 0, 1, words_to_bytes(prog[:1])),        # NO_LOAD
        Frame(FrameType.COMMIT, 9, 8, payload=info),                        # NO_LOAD
        load[0], load[0],                                                   # repeated BEGIN
        Frame(FrameType.DATA, 0x0101, 11, 16, 8, words_to_bytes(prog[:8])),  # OUT_OF_RANGE
        Frame(FrameType.DATA, 0x0101, 12, 0, 2, words_to_bytes(prog[:1])),  # BAD_FIELDS
        Frame(FrameType.DATA, 0x0101, 12, 0, 0),                            # BAD_FIELDS
        *load[1:3], Frame(FrameType.STATUS, 0, 13),                         # staging open
        load[-1],                                                           # MISMATCH (missing DATA)
        load[3], load[-1], load[-1], load[1], load[0],                      # commit, late duplicates
        Frame(FrameType.STATUS, 0, 14),
        Frame(FrameType.ACK, 0, 15),                                        # ignored
        Frame(FrameType.STOP, 0, 16), Frame(FrameType.STATUS, 0, 17),
        other[0], other[1], load[1],                                        # NO_LOAD: stale load
        Frame(FrameType.RUN, 0, 18), Frame(FrameType.RESET, 0, 19),
        Frame(FrameType.STATUS, 0, 20),
    ]


@cocotb.test()
async def replies_match_reference(dut):
    """Every reply equals DeviceCore's byte for byte, on both links; RESET zeroes memory."""
    pins = await bring_up(dut)
    rng = random.Random(5)
    core = DeviceCore(max_words=1 << AW)
    script = reference_script(rng)
    for i, f in enumerate(script):
        link = "uart" if i % 3 == 0 else "rmii"
        sender = Sender(pins, link, rng)
        data = f.encode()
        expected = core.handle(data)
        await sender.put(data)
        if expected is None:
            await Timer(CLOCK_NS * sender.timeout, "ns")
            assert pins.replies == [], f"step {i}: unexpected reply"
            continue
        got = await sender.reply_to(Frame(f.type, f.load, f.seq))
        assert got is not None, f"step {i}: no reply to {f}"
        assert got.encode() == expected, f"step {i}: {got} != reference"
    assert await pins.read_memory(8) == [0] * 8
    assert pins.bad_replies == 0


@cocotb.test()
async def rmii_back_to_back(dut):
    """A long assembled program at line rate: no frame lost, every frame ACKed once."""
    pins = await bring_up(dut)
    rng = random.Random(6)
    words = assembled("tri_sphere.asm")[: 1 << AW]
    frames = load_frames(words, 0x7777, 1000)
    sender = Sender(pins, "rmii", rng)
    start = cocotb.utils.get_sim_time("ns")
    for f in frames[:-1]:
        await sender.put(f.encode())  # minimum inter-frame gap, no waiting for ACKs
    await Timer(CLOCK_NS * 400, "ns")
    acked = {r.seq for r in pins.replies if r.type == FrameType.ACK}
    assert acked == {f.seq for f in frames[:-1]}
    pins.replies.clear()
    r = await sender.request(frames[-1])
    assert r.type == FrameType.ACK
    dut._log.info("loaded %d words in %d ns", len(words), cocotb.utils.get_sim_time("ns") - start)
    await check_loaded(pins, sender, words)


def pcap_frames(path: Path) -> list[bytes]:
    """The packets of a pcap file (link type Ethernet, no FCS)."""
    data = path.read_bytes()
    assert int.from_bytes(data[:4], "little") == 0xA1B2C3D4, "little-endian microsecond pcap"
    out, pos = [], 24
    while pos < len(data):
        incl = int.from_bytes(data[pos + 8:pos + 12], "little")
        out.append(data[pos + 16:pos + 16 + incl])
        pos += 16 + incl
    return out


@cocotb.test()
async def rmii_replays_rend3r_send_pcap(dut):
    """The frames `rend3r send -o F.pcap --run` writes load and run the program.

    They are replayed at the minimum gap, except that RUN waits for COMMIT's ACK, as
    `rend3r send` waits on a live link: the COMMIT's CRC pass keeps the engine busy.
    """
    pins = await bring_up(dut)
    pcap = Path(os.environ.get("TMPDIR", "/tmp")) / f"rend3r_firmware_{os.getpid()}.pcap"
    try:
        subprocess.run([sys.executable, "-m", "rend3r", "send", str(REPO / "programs" / "tri_cube.asm"),
                        "-o", str(pcap), "--run"], check=True, capture_output=True)
        frames = pcap_frames(pcap)
    finally:
        pcap.unlink(missing_ok=True)
    for eth in frames:
        if eth[15] == FrameType.RUN:
            for _ in range(1 << AW):
                if len(pins.replies) == len(frames) - 1:
                    break
                await Timer(CLOCK_NS * 16, "ns")
        await pins.send_rmii(wire_bytes(eth))
    await Timer(CLOCK_NS * 400, "ns")
    assert len(pins.replies) == len(frames)
    assert all(r.type == FrameType.ACK for r in pins.replies)
    assert [r.ref for r in pins.replies] == [FrameType.BEGIN] + [FrameType.DATA] * (len(frames) - 3) \
        + [FrameType.COMMIT, FrameType.RUN]
    words = assembled("tri_cube.asm")
    assert await pins.read_memory(len(words)) == words
    assert dut.running.value == 1


#: Words per DATA frame of the boundary loads: all of BOUNDARY_RUNS' frames fit a 1,024-word bank.
BOUNDARY_FRAME_WORDS = min(256, (1 << AW) // len(BOUNDARY_RUNS))


async def load_boundary_frames(dut, link: str) -> None:
    """DATA frames of ~800 bytes whose zeros follow runs of 253-256 non-zero bytes land exact.

    Last in this file: the 1,020-word load leaves words in both banks beyond the shorter
    programs that the earlier tests check are followed by zeros.
    """
    pins = await bring_up(dut)
    sender = Sender(pins, link, random.Random(7))
    words = boundary_words(frame_words=BOUNDARY_FRAME_WORDS)
    assert await sender.load(words, chunk=BOUNDARY_FRAME_WORDS) == 0
    await check_loaded(pins, sender, words)
    assert (await sender.status()).malformed == 0


@cocotb.test()
async def uart_boundary_frames(dut):
    """COBS block boundaries (a 254-byte run then a zero, 253/255/256, zeros back to back) over UART."""
    await load_boundary_frames(dut, "uart")


@cocotb.test()
async def rmii_boundary_frames(dut):
    """The same frames over RMII: no COBS, but the receiver's buffer and CRC see > 254 bytes."""
    await load_boundary_frames(dut, "rmii")
