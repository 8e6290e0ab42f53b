"""Drive and watch the loader's pins from cocotb with the bytes rend3r's transport code makes.

Frames come from :mod:`rend3r.transport` (``load_frames``, ``Frame.encode``, ``cobs.encode``,
``links.ethernet_frame``): the functions ``rend3r send`` and ``rend3r send --pcap`` use.
Ethernet frames get preamble, SFD and FCS here, as a MAC would add them.
"""

from __future__ import annotations

import zlib

from cocotb.triggers import FallingEdge, RisingEdge, Timer
from cocotb.utils import get_sim_time

from rend3r.transport import cobs
from rend3r.transport.links import DEFAULT_ETHERTYPE, ethernet_frame, parse_mac
from rend3r.transport.protocol import Frame, FrameError, decode

DEVICE_MAC = parse_mac("69:69:5a:06:54:91")
HOST_MAC = parse_mac("02:00:00:00:00:01")  # the --pcap source address
IFG_BYTES = 12  # minimum inter-frame gap
CLOCK_NS = 20  # the 50 MHz RMII reference clock
PREAMBLE = b"\x55" * 7 + b"\xd5"


def wire_bytes(eth: bytes) -> bytes:
    """Preamble, SFD, the frame and its FCS (CRC-32, least significant byte first)."""
    return PREAMBLE + eth + zlib.crc32(eth).to_bytes(4, "little")


def eth_for(frame: bytes, dst: bytes = DEVICE_MAC, ethertype: int = DEFAULT_ETHERTYPE) -> bytes:
    """The Ethernet II frame (without FCS) that carries one protocol frame."""
    return ethernet_frame(dst, HOST_MAC, ethertype, frame)


def dibits(data: bytes) -> list[int]:
    """RMII order: each byte LSB first, two bits per clock, the earlier bit in rxd[0]."""
    return [(b >> s) & 3 for b in data for s in (0, 2, 4, 6)]


def uart_bits(data: bytes) -> list[int]:
    """8N1 line levels: start bit, 8 data bits LSB first, stop bit."""
    return [bit for b in data for bit in ([0] + [(b >> i) & 1 for i in range(8)] + [1])]


def serial_bytes(frame: bytes) -> bytes:
    """One protocol frame on a serial line: COBS and the 0x00 delimiter."""
    return cobs.encode(frame) + b"\0"


class Pins:
    """The loader's link pins: RMII and UART drivers, reply monitors, memory reader."""

    def __init__(self, dut, clks_per_bit: int) -> None:
        self.dut = dut
        self.cpb = clks_per_bit
        self.replies: list[Frame] = []  # decoded replies, in arrival order, both links
        self.bad_replies = 0  # reply bytes that did not decode
        self.reply_cycles: list[int] = []  # clock cycle at which each reply was complete

    def start_monitors(self) -> None:
        import cocotb

        cocotb.start_soon(self._watch_rmii())
        cocotb.start_soon(self._watch_uart())

    async def send_rmii(self, wire: bytes, gap_bytes: int = IFG_BYTES) -> None:
        """Drive preamble..FCS bytes on crs_dv/rxd, then idle for the inter-frame gap."""
        dut = self.dut
        for d in dibits(wire):
            dut.rmii_crs_dv.value = 1
            dut.rmii_rxd.value = d
            await FallingEdge(dut.clk)
        dut.rmii_crs_dv.value = 0
        dut.rmii_rxd.value = 0
        await Timer(CLOCK_NS * 4 * gap_bytes, "ns")

    async def send_uart(self, data: bytes) -> None:
        """Drive the UART rx pin with 8N1 bits at clks_per_bit clocks each."""
        dut = self.dut
        await FallingEdge(dut.clk)
        for bit in uart_bits(data):  # Timer, not ClockCycles: one wake-up per bit, not per clock
            dut.uart_rx.value = bit
            await Timer(CLOCK_NS * self.cpb, "ns")

    def now(self) -> int:
        """Simulated time in cycles of the 50 MHz clock."""
        return int(get_sim_time("ns")) // CLOCK_NS

    def _accept(self, data: bytes) -> None:
        try:
            self.replies.append(decode(data))
            self.reply_cycles.append(self.now())
        except FrameError:
            self.bad_replies += 1

    async def _watch_rmii(self) -> None:
        dut = self.dut
        while True:
            await RisingEdge(dut.rmii_tx_en)
            # Sample mid-cycle: at a rising edge Icarus shows the flops' old values and
            # Verilator their new ones; at the falling edge both show the same.
            await FallingEdge(dut.clk)
            bits: list[int] = []
            while dut.rmii_tx_en.value:
                bits.append(int(dut.rmii_txd.value))
                await FallingEdge(dut.clk)
            raw = bytes(sum(bits[i + k] << (2 * k) for k in range(4)) for i in range(0, len(bits) - 3, 4))
            if len(bits) % 4 or not raw.startswith(PREAMBLE) or len(raw) < len(PREAMBLE) + 64:
                self.bad_replies += 1
                continue
            eth, fcs = raw[len(PREAMBLE):-4], raw[-4:]
            if zlib.crc32(eth).to_bytes(4, "little") != fcs or eth[:6] != HOST_MAC \
                    or int.from_bytes(eth[12:14], "big") != DEFAULT_ETHERTYPE:
                self.bad_replies += 1
                continue
            self._accept(eth[14:])

    async def _watch_uart(self) -> None:
        dut = self.dut
        buf = bytearray()
        while True:
            await FallingEdge(dut.uart_tx)
            await Timer(CLOCK_NS * (self.cpb // 2), "ns")
            byte = 0
            for i in range(8):
                await Timer(CLOCK_NS * self.cpb, "ns")
                byte |= int(dut.uart_tx.value) << i
            await Timer(CLOCK_NS * self.cpb, "ns")  # stop bit centre
            if byte:
                buf.append(byte)
            elif buf:
                try:
                    self._accept(cobs.decode(bytes(buf)))
                except cobs.CobsError:
                    self.bad_replies += 1
                buf.clear()

    async def read_memory(self, words: int) -> list[int]:
        """The active bank's first ``words`` words, through the processor's read port."""
        dut = self.dut
        out = []
        for a in range(words):  # prog_clk is pulsed here only: a free-running clock costs time
            dut.prog_addr.value = a
            await Timer(5, "ns")
            dut.prog_clk.value = 1
            await Timer(5, "ns")
            dut.prog_clk.value = 0
            out.append(int(dut.prog_data.value))
        return out
