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

from ..cli import INTERRUPTED
from ..cliutil import DEVICE_SIZE, SizeType, finite
from ..errors import Rend3rError
from .execute import MAX_DEVICE_SIDE
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
    """The program at ``path`` as a :class:`~rend3r.asm.program.Program`, loaded as
    ``emulate`` loads it (source or any memory image, :func:`rend3r.emu.loader.load_program`)."""
    from ..asm.program import Emitted, Program
    from ..emu.loader import load_program

    return Program([Emitted(0, tuple(load_program(path).words))])


#: ``send -o FILE``: what each file suffix writes.
OUTPUT_KINDS = {".mem": "mem", ".coe": "coe", ".pcap": "pcap"}


def plural(n: int, noun: str) -> str:
    """``"1 frame"``, ``"0 frames"``, ``"3 frames"``."""
    return f"{n} {noun}" if n == 1 else f"{n} {noun}s"


def _output_kind(path: str) -> str:
    kind = OUTPUT_KINDS.get(Path(path).suffix.lower())
    if kind is None:
        raise Rend3rError(f"{path}: -o writes a .mem ($readmemh), .coe (Xilinx) or .pcap (Ethernet frames) file")
    return kind


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
@click.option("-o", "--output", metavar="FILE",
              help="Write the load to a file instead of a device: FILE.mem ($readmemh, the board's main.mem), "
                   "FILE.coe (Xilinx) or FILE.pcap (its Ethernet frames).")
@click.option("--eth", "iface", metavar="IFACE", help="Send raw Ethernet frames on this interface.")
@click.option("--mem", "mem_out", metavar="FILE", hidden=True)  # -o FILE.mem, as before -o existed
@click.option("--coe", "coe_out", metavar="FILE", hidden=True)  # -o FILE.coe
@click.option("--pcap", "pcap_out", metavar="FILE", hidden=True)  # -o FILE.pcap
@click.option("--serial", "port", metavar="PORT", help="Serial device path or pyserial URL (loop://, socket://, rfc2217://).")
@click.option("--mac", default=DEFAULT_MAC, show_default=True, metavar="MAC", help="Device MAC address.")
@click.option("--ethertype", default=f"0x{DEFAULT_ETHERTYPE:04x}", show_default=True, metavar="TYPE")
@click.option("--framing", type=click.Choice(["protocol", "raw"]), default="protocol", show_default=True,
              help="raw: bare big-endian words, no header, no acknowledgement (the original receiver).")
@click.option("--baud", type=int, default=115200, show_default=True, metavar="RATE")
@click.option("--timeout", type=float, default=DEFAULT_TIMEOUT, show_default=True, metavar="SECONDS",
              help="Seconds to wait for each acknowledgement.")
@click.option("--retries", type=click.IntRange(0, 1000), default=DEFAULT_RETRIES, show_default=True, metavar="N",
              help="Resends per frame (and restarts per load) before giving up.")
@click.option("--run", "run_after", is_flag=True, help="Send RUN after the program is committed.")
@click.option("-q", "--quiet", is_flag=True, help="No progress or summary output.")
def send_command(program: str, output: str | None, iface: str | None, mem_out: str | None, coe_out: str | None,
                 pcap_out: str | None, port: str | None, mac: str, ethertype: str, framing: str,
                 baud: int, timeout: float, retries: int, run_after: bool, quiet: bool) -> None:
    """Send PROGRAM (source or any memory image) to a device, or write it to a file.

    Over --eth and --serial the load is acknowledged frame by frame and committed with
    the program's CRC-32; the device keeps its previous program unless the commit matches.
    A running device starts a committed program at once, as the board does; --run
    starts a stopped one.

    \b
    Examples:
      rend3r send programs/sphere.asm -o out/main.mem
      rend3r send programs/sphere.asm --serial /dev/ttyUSB0 --baud 3000000 --run
      rend3r send main.mem --eth enp3s0 --mac 69:69:5a:06:54:91
      rend3r send programs/sphere.asm -o out/load.pcap
    """
    targets = [(n, v) for n, v in (("-o", output), ("--mem", mem_out), ("--coe", coe_out), ("--eth", iface),
                                   ("--pcap", pcap_out), ("--serial", port)) if v]
    if len(targets) != 1:
        raise Rend3rError("choose exactly one of -o FILE, --eth IFACE, --serial PORT"
                          + (f" (got {', '.join(n for n, _ in targets)})" if targets else ""))
    kind = (_output_kind(output) if output else "mem" if mem_out else "coe" if coe_out
            else "pcap" if pcap_out else None)
    out = output or mem_out or coe_out or pcap_out
    if timeout <= 0:
        raise Rend3rError(f"--timeout must be positive, not {timeout:g}")
    if baud <= 0:
        raise Rend3rError(f"--baud must be positive, not {baud}")
    device_mac = parse_mac(mac)
    etype = _ethertype(ethertype)
    if run_after and kind in ("mem", "coe"):
        raise Rend3rError(f"--run needs a device (--eth, --serial) or a .pcap file, not a .{kind} file")
    prog = read_program(program)
    words = prog.words
    say = (lambda msg: None) if quiet else (lambda msg: click.echo(msg, err=True))
    crc = program_crc(words)

    if kind in ("mem", "coe"):
        from ..asm.formats import render
        from ..fileio import write_atomic

        write_atomic(out, render(kind, prog))
        say(f"wrote {plural(len(words), 'word')} (CRC-32 {crc:08x}) to {out}")
        return
    if kind == "pcap":
        _write_pcap(out, words, device_mac, etype, framing, run_after)
        say(f"wrote {plural(len(words), 'word')} (CRC-32 {crc:08x}) as {framing} frames to {out}")
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
                say(f"sent {plural(len(words), 'raw word')} to {where} (no acknowledgement in raw framing)")
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
    say(f"loaded {plural(len(words), 'word')} (CRC-32 {crc:08x}) on {where} in {elapsed * 1e3:.1f} ms "
        f"({plural(s.frames, 'protocol frame')}, {s.resends} resent); {_device_state(status)}")


def _device_state(status) -> str:
    """What the device does with the program, as its STATUS reply tells (frames render in the
    background, so a count taken at the commit is usually 0 and is not shown then)."""
    if not status.running:
        return "the device is stopped (--run starts it)"
    if status.frames == 0:
        return "the device is running it"
    return f"the device is running it ({plural(status.frames, 'frame')} rendered since its last reset)"


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
@click.option("-o", "--output", "out_dir", required=True, metavar="DIR",
              help="Folder for the rendered frames, runNNNN_frameFFFF.png (made if missing).")
@click.option("--mac", default=DEFAULT_MAC, show_default=True, metavar="MAC", help="The MAC address the device answers to.")
@click.option("--ethertype", default=f"0x{DEFAULT_ETHERTYPE:04x}", show_default=True, metavar="TYPE")
@click.option("--baud", type=int, default=115200, show_default=True, metavar="RATE")
@click.option("--max-words", type=click.IntRange(1, 1 << 24), default=1 << 16, show_default=True, metavar="N",
              help="Largest program accepted.")
@click.option("--max-frame-rate", type=float, callback=finite(1e-3, 1e6), default=30.0,
              show_default=True, metavar="FPS", help="Most frames rendered per second.")
@click.option("--frames", "max_frames", type=click.IntRange(1), default=8, show_default=True, metavar="N",
              help="Frames rendered per program run (bounds looping programs).")
@click.option("--size", type=SizeType(MAX_DEVICE_SIDE), default=DEVICE_SIZE, show_default=True,
              help=f"Rendered frame size (1..{MAX_DEVICE_SIDE} each); the board's is {DEVICE_SIZE}.")
def device_command(iface: str | None, port: str | None, out_dir: str, mac: str, ethertype: str,
                   baud: int, max_words: int, max_frame_rate: float, max_frames: int, size: tuple[int, int]) -> None:
    """A virtual REND3R device: receive programs, run them, write each frame to DIR.

    It applies the load protocol (docs/protocol.md), swaps in a program only when its
    commit matches, renders it with the emulator and answers status. Each program run
    is numbered from 1 (run0001_...) and its frames from 0 (..._frame0000.png), as
    emulate numbers them. Ctrl-C stops it (exit status 130; SIGTERM: 0).

    \b
    Examples:
      rend3r device --serial /dev/pts/5 -o out/frames
      rend3r device --eth veth1 -o out/frames --size 128x96
    """
    from ..fileio import make_output_folder
    from .device import DeviceCore
    from .execute import RenderExecutor

    if bool(iface) == bool(port):
        raise Rend3rError("choose exactly one of --eth and --serial")
    device_mac = parse_mac(mac)
    etype = _ethertype(ethertype)
    width, height = size
    out = make_output_folder(out_dir)
    link: Link = (EthernetLink(iface, ethertype=etype, device_mac=device_mac) if iface
                  else SerialLink(open_serial(port, baud)))
    logging.basicConfig(stream=sys.stderr, level=logging.INFO, format="rend3r device: %(message)s")
    executor = RenderExecutor(out, width=width, height=height, max_frames=max_frames,
                              max_frame_rate=max_frame_rate)
    core = DeviceCore(executor, max_words=max_words)
    stop = threading.Event()
    received: list[int] = []

    def on_signal(signum: int, _frame) -> None:
        received.append(signum)
        stop.set()

    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, on_signal)
    where = f"{iface} as {format_mac(device_mac)}" if iface else port
    click.echo(f"rend3r device: listening on {where}, frames to {out}", err=True)
    with link:
        try:
            serve(link, core, stop)
        finally:
            executor.close()
    c = core.counters
    foreign = (f", {plural(link.foreign, 'frame')} for other addresses" if isinstance(link, EthernetLink) else "")
    nacks = ", ".join(f"{k.name} {v}" for k, v in sorted(c.nacks.items())) or "none"
    click.echo(f"rend3r device: stopped after {plural(c.loads, 'load')} ({plural(executor.runs, 'run')}), "
               f"{plural(executor.frames, 'frame')} rendered, {plural(c.malformed, 'malformed protocol frame')}"
               f"{foreign}; NACKs: {nacks}", err=True)
    if signal.SIGINT in received:  # Ctrl-C: the status every command gives when interrupted
        click.get_current_context().exit(INTERRUPTED)
