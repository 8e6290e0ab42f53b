"""``rend3r send`` (program -> file, pcap, Ethernet or serial) and ``rend3r device``."""

from __future__ import annotations

import io
import logging
import random
import signal
import sys
import threading
import time
from pathlib import Path

import click

from ..errors import Rend3rError
from .links import (
    DEFAULT_ETHERTYPE, DEFAULT_MAC, ETH_MAX_PAYLOAD, EthernetLink, Link, SerialLink,
    ethernet_frame, format_mac, open_serial, parse_mac,
)
from .protocol import Frame, FrameError, FrameType, program_crc, words_to_bytes
from .session import DEFAULT_RETRIES, DEFAULT_TIMEOUT, Sender, load_frames

#: Source MAC written into --pcap frames (locally administered, never on a real wire).
PCAP_SOURCE_MAC = bytes.fromhex("020000000001")
RAW_WORDS_PER_FRAME = ETH_MAX_PAYLOAD // 4


def _ethertype(text: str) -> int:
    try:
        value = int(text, 0)
    except ValueError:
        raise Rend3rError(f"malformed EtherType {text!r}: expected a number like 0x88b5") from None
    if not 0x0600 <= value <= 0xFFFF:
        raise Rend3rError(f"EtherType 0x{value:x} is not an Ethernet II type (0x0600..0xffff)")
    return value


def read_program(path: str):
    """The program at ``path``: assembled when it is ``.asm``, else read as a memory image."""
    from ..asm.program import Emitted, Program

    if Path(path).suffix.lower() == ".asm":
        from ..asm.assembler import assemble_or_raise

        return assemble_or_raise(path).program
    from ..asm.formats import read_file

    return Program([Emitted(0, tuple(read_file(path)))])


class _Progress:
    """Prints ``words acknowledged / total`` at most twice a second for long sends."""

    def __init__(self, enabled: bool) -> None:
        self.enabled = enabled
        self.last = time.monotonic()

    def __call__(self, done: int, total: int) -> None:
        now = time.monotonic()
        if self.enabled and (now - self.last >= 0.5 or done == total) and total:
            self.last = now
            click.echo(f"  {done}/{total} words ({100 * done // total}%)", err=True)


@click.command("send")
@click.argument("program", type=click.Path(dir_okay=False))
@click.option("--mem", "mem_out", metavar="FILE", help="Write a $readmemh main.mem (atomically).")
@click.option("--coe", "coe_out", metavar="FILE", help="Write a Xilinx .coe file (atomically).")
@click.option("--eth", "iface", metavar="IFACE", help="Send raw Ethernet frames on this interface.")
@click.option("--pcap", "pcap_out", metavar="FILE", help="Write the Ethernet frames to a pcap file instead.")
@click.option("--serial", "port", metavar="PORT", help="Serial device path or pyserial URL (loop://, socket://, rfc2217://).")
@click.option("--mac", default=DEFAULT_MAC, show_default=True, help="Device MAC address.")
@click.option("--ethertype", default=f"0x{DEFAULT_ETHERTYPE:04x}", show_default=True)
@click.option("--framing", type=click.Choice(["protocol", "raw"]), default="protocol", show_default=True,
              help="raw: bare big-endian words, no header, no acknowledgement (the original receiver).")
@click.option("--baud", type=int, default=115200, show_default=True)
@click.option("--timeout", type=float, default=DEFAULT_TIMEOUT, show_default=True,
              help="Seconds to wait for each acknowledgement.")
@click.option("--retries", type=click.IntRange(0, 1000), default=DEFAULT_RETRIES, show_default=True,
              help="Resends per frame (and restarts per load) before giving up.")
@click.option("--run", "run_after", is_flag=True, help="Send RUN after the program is committed.")
@click.option("-q", "--quiet", is_flag=True, help="No progress or summary output.")
def send_command(program: str, mem_out: str | None, coe_out: str | None, iface: str | None,
                 pcap_out: str | None, port: str | None, mac: str, ethertype: str, framing: str,
                 baud: int, timeout: float, retries: int, run_after: bool, quiet: bool) -> None:
    """Send PROGRAM (.asm source or any memory image) to a device or a file.

    Over --eth and --serial the load is acknowledged frame by frame and committed with
    the program's CRC-32; the device keeps its previous program unless the commit matches.

    \b
    Examples:
      rend3r send programs/sphere.asm --mem main.mem
      rend3r send programs/sphere.asm --serial /dev/ttyUSB0 --baud 3000000 --run
      rend3r send main.mem --eth enp3s0 --mac 69:69:5a:06:54:91
      rend3r send programs/sphere.asm --pcap load.pcap
    """
    targets = [(n, v) for n, v in (("--mem", mem_out), ("--coe", coe_out), ("--eth", iface),
                                   ("--pcap", pcap_out), ("--serial", port)) if v]
    if len(targets) != 1:
        raise Rend3rError("choose exactly one of --mem, --coe, --eth, --pcap, --serial"
                          + (f" (got {', '.join(n for n, _ in targets)})" if targets else ""))
    if timeout <= 0:
        raise Rend3rError(f"--timeout must be positive, not {timeout:g}")
    if baud <= 0:
        raise Rend3rError(f"--baud must be positive, not {baud}")
    device_mac = parse_mac(mac)
    etype = _ethertype(ethertype)
    if run_after and (mem_out or coe_out):
        raise Rend3rError("--run needs a device (--eth, --serial or --pcap), not a file")
    prog = read_program(program)
    words = prog.words
    say = (lambda msg: None) if quiet else (lambda msg: click.echo(msg, err=True))
    crc = program_crc(words)

    if mem_out or coe_out:
        from ..asm.formats import render
        from ..fileio import write_atomic

        fmt, out = ("mem", mem_out) if mem_out else ("coe", coe_out)
        write_atomic(out, render(fmt, prog))
        say(f"wrote {len(words)} words (CRC-32 {crc:08x}) to {out}")
        return
    if pcap_out:
        _write_pcap(pcap_out, words, device_mac, etype, framing, run_after)
        say(f"wrote {len(words)} words (CRC-32 {crc:08x}) as {framing} frames to {pcap_out}")
        return

    link: Link = (EthernetLink(iface, peer=device_mac, ethertype=etype) if iface
                  else SerialLink(open_serial(port, baud)))
    where = f"{iface} -> {format_mac(device_mac)}" if iface else port
    from serial import SerialException

    with link:
        start = time.monotonic()
        try:
            if framing == "raw":
                _send_raw(link, words)
                say(f"sent {len(words)} raw words to {where} (no acknowledgement in raw framing)")
                return
            sender = Sender(link, timeout=timeout, retries=retries,
                            progress=_Progress(not quiet and len(words) >= 4096))
            sender.load(words)
            if run_after:
                sender.control(FrameType.RUN)
            status = sender.status()
        except (OSError, SerialException) as exc:
            raise Rend3rError(f"{where}: the link failed: {getattr(exc, 'strerror', None) or exc}") from exc
        elapsed = time.monotonic() - start
    if (status.words, status.crc) != (len(words), crc):
        raise Rend3rError(f"the device reports {status.words} words with CRC-32 {status.crc:08x} "
                          f"after loading {len(words)} words with CRC-32 {crc:08x}")
    s = sender.stats
    say(f"loaded {len(words)} words (CRC-32 {crc:08x}) on {where} in {elapsed * 1e3:.1f} ms; "
        f"{s.frames} frames, {s.resends} resent; device: {'running' if status.running else 'stopped'}, "
        f"{status.frames} frames rendered")


def _raw_payloads(words: list[int]) -> list[bytes]:
    return [words_to_bytes(words[i:i + RAW_WORDS_PER_FRAME])
            for i in range(0, len(words), RAW_WORDS_PER_FRAME)]


def _send_raw(link: Link, words: list[int]) -> None:
    if isinstance(link, EthernetLink):
        for payload in _raw_payloads(words):
            link.send_payload(payload)
    else:
        link.write(words_to_bytes(words))


def _write_pcap(path: str, words: list[int], mac: bytes, etype: int, framing: str, run: bool) -> None:
    from scapy.layers.l2 import Ether
    from scapy.utils import PcapWriter

    from ..fileio import write_atomic

    if framing == "raw":
        payloads = _raw_payloads(words)
    else:
        rng = random.Random()
        frames = load_frames(words, rng.randrange(1, 1 << 16), rng.randrange(1 << 16))
        if run:
            frames.append(Frame(FrameType.RUN, 0, (frames[-1].seq + 1) & 0xFFFF))
        payloads = [f.encode() for f in frames]
    buf = io.BytesIO()
    writer = PcapWriter(buf, linktype=1)  # DLT_EN10MB
    writer.write([Ether(ethernet_frame(mac, PCAP_SOURCE_MAC, etype, p)) for p in payloads])
    writer.flush()
    write_atomic(path, buf.getvalue())
    writer.close()


# -- rend3r device ---------------------------------------------------------------------


def serve(link: Link, core, stop: threading.Event, poll: float = 0.1) -> None:
    """Answer frames arriving on ``link`` with ``core`` until ``stop`` is set."""
    from serial import SerialException

    while not stop.is_set():
        try:
            data = link.recv(poll)
        except FrameError as exc:
            core.malformed(str(exc))
            continue
        except (OSError, SerialException) as exc:
            raise Rend3rError(f"the link failed while receiving: {exc}") from exc
        if data is None:
            continue
        reply = core.handle(data)
        if reply is not None:
            try:
                link.send(reply)
            except (OSError, SerialException) as exc:  # the sender resends; keep serving
                logging.getLogger("rend3r.device").warning("could not send a reply: %s", exc)


@click.command("device")
@click.option("--eth", "iface", metavar="IFACE", help="Listen for raw Ethernet frames on this interface.")
@click.option("--serial", "port", metavar="PORT", help="Serial device path or pyserial URL.")
@click.option("-o", "--output", "out_dir", required=True, type=click.Path(file_okay=False),
              help="Directory for the rendered frames (PNG).")
@click.option("--mac", default=DEFAULT_MAC, show_default=True, help="The MAC address the device answers to.")
@click.option("--ethertype", default=f"0x{DEFAULT_ETHERTYPE:04x}", show_default=True)
@click.option("--baud", type=int, default=115200, show_default=True)
@click.option("--max-words", type=click.IntRange(1, 1 << 24), default=1 << 16, show_default=True,
              help="Largest program accepted.")
@click.option("--max-frame-rate", type=click.FloatRange(min=0, min_open=True), default=30.0,
              show_default=True, help="Most frames rendered per second.")
@click.option("--frames", "max_frames", type=click.IntRange(1), default=8, show_default=True,
              help="Frames rendered per program run (bounds looping programs).")
@click.option("--size", default="128x96", show_default=True, help="Rendered frame size WxH.")
def device_command(iface: str | None, port: str | None, out_dir: str, mac: str, ethertype: str,
                   baud: int, max_words: int, max_frame_rate: float, max_frames: int, size: str) -> None:
    """A virtual REND3R device: receive programs, run them, write each frame to DIR.

    It applies the load protocol (docs/protocol.md), swaps in a program only when its
    commit matches, renders it with the emulator and answers status. Ctrl-C stops it.

    \b
    Examples:
      rend3r device --serial /dev/pts/5 -o frames/
      rend3r device --eth veth1 -o frames/ --size 512x384
    """
    from .device import DeviceCore
    from .execute import RenderExecutor, parse_size

    if bool(iface) == bool(port):
        raise Rend3rError("choose exactly one of --eth and --serial")
    device_mac = parse_mac(mac)
    etype = _ethertype(ethertype)
    width, height = parse_size(size)
    out = Path(out_dir)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise Rend3rError(f"{out}: cannot create the output directory: {exc.strerror or exc}") from None
    link: Link = (EthernetLink(iface, ethertype=etype, device_mac=device_mac) if iface
                  else SerialLink(open_serial(port, baud)))
    logging.basicConfig(stream=sys.stderr, level=logging.INFO, format="rend3r device: %(message)s")
    executor = RenderExecutor(out, width=width, height=height, max_frames=max_frames,
                              max_frame_rate=max_frame_rate)
    core = DeviceCore(executor, max_words=max_words)
    stop = threading.Event()
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, lambda *_: stop.set())
    where = f"{iface} as {format_mac(device_mac)}" if iface else port
    click.echo(f"rend3r device: listening on {where}, frames to {out}", err=True)
    with link:
        try:
            serve(link, core, stop)
        finally:
            executor.close()
    c = core.counters
    foreign = f", {link.foreign} frames for other addresses" if isinstance(link, EthernetLink) else ""
    nacks = ", ".join(f"{k.name} {v}" for k, v in sorted(c.nacks.items())) or "none"
    click.echo(f"rend3r device: stopped after {c.loads} loads, {executor.frames} frames rendered, "
               f"{c.malformed} malformed frames{foreign}; NACKs: {nacks}", err=True)
