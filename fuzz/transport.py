"""Long fuzz run of the load protocol's frame parser: hostile frames against the real device.

    python fuzz/transport.py --cases 20000 [--seed 1] [--inprocess 200000]

Row 1 drives ``rend3r device`` (the real command, one process for the whole run) over a
``socket://`` serial link to a TCP server on loopback: each case writes a few hostile frames
(garbage, invalid COBS, overlong lines without a delimiter, frames with correct CRCs but any
header fields, huge ``length`` fields, bad CRCs, truncation, loads out of order, duplicated
and mangled) and then a STATUS probe, which must be answered within ``--timeout`` seconds.
A case's time is until that answer; its RSS is the device's peak (VmHWM); a traceback is one
in the device's log; a crash is the device exiting (with any status); a hang is an unanswered probe (the
device is then restarted). Row 2 feeds the same cases' frames to ``DeviceCore.handle`` in
process (time per case, this process's peak RSS; a traceback is any exception).
Prints ``fuzz/harness.py``'s table header and one row per parser.
"""

from __future__ import annotations

import argparse
import os
import random
import resource
import select
import socket
import subprocess
import sys
import tempfile
import time
import zlib
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from harness import HEADER, CaseResult, Tally  # noqa: E402

from rend3r.transport import cobs  # noqa: E402
from rend3r.transport.device import DeviceCore  # noqa: E402
from rend3r.transport.protocol import HEADER as FRAME_HEADER  # noqa: E402
from rend3r.transport.protocol import PROGRAM_INFO, Frame, FrameType, decode  # noqa: E402
from rend3r.transport.session import load_frames  # noqa: E402

MAX_WORDS = 4096  # the device's --max-words in this run


def field_frame(rng: random.Random) -> bytes:
    """Any header fields and payload, CRC correct unless ``length`` claims more than is there."""
    payload = rng.randbytes(rng.choice([0, 4, 8, 12, 1024, 1028, rng.randrange(1100)]))
    ftype = rng.choice([*FrameType, rng.randrange(256)])
    if ftype in (FrameType.BEGIN, FrameType.COMMIT) and rng.random() < 0.5:
        payload = PROGRAM_INFO.pack(rng.choice([0, 1, MAX_WORDS, MAX_WORDS + 1, 0xFFFFFFFF]), rng.getrandbits(32))
    length = len(payload) if rng.random() < 0.75 else rng.choice([0xFFFF, rng.randrange(1 << 16)])
    header = FRAME_HEADER.pack(rng.choice([1, 1, 1, 0, 2, 255]), ftype, rng.getrandbits(16), rng.getrandbits(16),
                               rng.choice([0, 1, 256, 257, 0xFFFF]), rng.choice([0, 1, 4095, 0xFFFFFFFF]),
                               length, rng.getrandbits(8), rng.getrandbits(8))
    body = header + payload[:length]
    return body + zlib.crc32(body).to_bytes(4, "big") + payload[length:]


def mangle(rng: random.Random, data: bytes) -> bytes:
    out = bytearray(data)
    kind = rng.randrange(5)
    if kind == 0:
        for _ in range(rng.randint(1, 4)):
            out[rng.randrange(len(out))] ^= 1 << rng.randrange(8)
    elif kind == 1:
        del out[rng.randrange(len(out)):]
    elif kind == 2:
        out[12:14] = rng.choice([0xFFFF, 0x0405, 0]).to_bytes(2, "big")
    elif kind == 3:
        out[-1] ^= 0xFF
    else:
        out += rng.randbytes(rng.randint(1, 64))
    return bytes(out)


def load_case(rng: random.Random) -> list[bytes]:
    """A random program's load, shuffled, with drops, duplicates and mangled frames."""
    words = [rng.getrandbits(32) for _ in range(rng.choice([0, 1, 5, 300, 1000]))]
    frames = [f.encode() for f in load_frames(words, rng.randrange(1, 4), rng.getrandbits(16), rng.choice([7, 256]))]
    out = []
    for f in frames:
        r = rng.random()
        if r < 0.1:
            continue
        out.append(mangle(rng, f) if r < 0.3 else f)
        if r > 0.9:
            out.append(f)
    if rng.random() < 0.5:
        rng.shuffle(out)
    return out


def case(rng: random.Random) -> tuple[list[bytes], bytes]:
    """(protocol frames, the bytes on the serial line carrying them, with line-level faults)."""
    kind = rng.randrange(6)
    if kind == 0:
        frames = [rng.randbytes(rng.randrange(200)) for _ in range(rng.randint(1, 4))]
    elif kind in (1, 2):
        frames = [field_frame(rng) for _ in range(rng.randint(1, 4))]
    elif kind == 3:
        frames = [mangle(rng, field_frame(rng)) for _ in range(rng.randint(1, 4))]
    else:
        frames = load_case(rng)
    wire = bytearray()
    for f in frames:
        wire += cobs.encode(f) + b"\0"
    r = rng.random()
    if r < 0.1:
        wire[rng.randrange(len(wire) or 1):rng.randrange(len(wire) or 1)] = rng.randbytes(rng.randrange(64))
    elif r < 0.15:
        wire = bytearray(rng.randbytes(rng.randrange(1, 255)).replace(b"\0", b"\1") * rng.randint(1, 12)) + wire
    return frames, b"\0" + bytes(wire) + b"\0"


class Device:
    """``rend3r device`` on a socket:// link to a server of ours, its log in a file."""

    def __init__(self, out: Path) -> None:
        server = socket.create_server(("127.0.0.1", 0))
        self.log = tempfile.TemporaryFile()
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "rend3r", "device", "--serial", f"socket://127.0.0.1:{server.getsockname()[1]}",
             "-o", str(out), "--size", "32x24", "--frames", "1", "--max-words", str(MAX_WORDS),
             "--max-frame-rate", "1000"], stderr=self.log)
        server.settimeout(60)
        self.conn, _ = server.accept()
        server.close()
        self.read_at = 0
        self.buf = bytearray()
        while b"listening on" not in self.new_log(keep=True):
            time.sleep(0.02)

    def new_log(self, keep: bool = False) -> bytes:
        self.log.seek(self.read_at)
        text = self.log.read()
        if not keep:
            self.read_at += len(text)
        return text

    def rss(self) -> int:
        with open(f"/proc/{self.proc.pid}/status") as fh:
            return next(int(line.split()[1]) * 1024 for line in fh if line.startswith("VmHWM"))

    def probe(self, seq: int, timeout: float) -> bool:
        """Send STATUS ``seq``; True once its answer arrives."""
        self.conn.sendall(b"\0" + cobs.encode(Frame(FrameType.STATUS, 0x5EED, seq).encode()) + b"\0")
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if select.select([self.conn], [], [], 0.05)[0]:
                data = self.conn.recv(1 << 16)
                if not data:
                    return False
                self.buf += data
                *whole, rest = bytes(self.buf).split(b"\0")
                self.buf = bytearray(rest)
                for w in whole:
                    try:
                        r = decode(cobs.decode(w))
                    except ValueError:
                        continue
                    if (r.load, r.seq, r.ref) == (0x5EED, seq, FrameType.STATUS):
                        return True
        return False

    def close(self) -> None:
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(30)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        self.conn.close()
        self.log.close()


def run_device(cases: int, seed: int, timeout: float) -> Tally:
    tally = Tally("protocol frames: `rend3r device` on a serial link (loopback socket)")
    rng = random.Random(seed)
    with tempfile.TemporaryDirectory() as tmp:
        device = Device(Path(tmp))
        try:
            for i in range(cases):
                frames, wire = case(rng)
                start = time.perf_counter()
                try:
                    device.conn.sendall(wire)
                    answered = device.probe(i & 0xFFFF, timeout)
                except OSError:
                    answered = False
                seconds = time.perf_counter() - start
                code = device.proc.poll()
                log = device.new_log().decode("utf-8", "replace")
                status = 0 if code is None else min(code, -1)  # any exit of the device is a crash
                tally.add(CaseResult((f"case {i}", wire[:64].hex()), status, seconds,
                                     device.rss(), log, not answered and code is None))
                if code is not None or not answered:
                    device.close()
                    device = Device(Path(tmp))
                if i % 500 == 499:  # keep the output folder small: frames of committed programs
                    for png in Path(tmp).glob("*.png"):
                        png.unlink(missing_ok=True)
        finally:
            device.close()
    return tally


def run_inprocess(cases: int, seed: int) -> Tally:
    tally = Tally("protocol frames: `DeviceCore.handle` in process")
    rng = random.Random(seed)
    core = DeviceCore(max_words=MAX_WORDS)
    for i in range(cases):
        frames, _ = case(rng)
        start = time.perf_counter()
        err = ""
        try:
            for f in frames:
                core.handle(f)
        except Exception as exc:  # noqa: BLE001 - what the fuzzer counts
            err = f"Traceback (most recent call last): {exc!r}"
        seconds = time.perf_counter() - start
        rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
        tally.add(CaseResult((f"case {i}",), 0, seconds, rss, err, False))
    return tally


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cases", type=int, default=2000, help="cases against rend3r device")
    parser.add_argument("--inprocess", type=int, default=None, help="in-process cases (default 10x --cases)")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--timeout", type=float, default=10.0, help="seconds a STATUS probe may take")
    args = parser.parse_args()
    import logging

    logging.getLogger("rend3r.device").setLevel(logging.ERROR)  # the in-process core logs each NACK
    tallies = [run_device(args.cases, args.seed, args.timeout),
               run_inprocess(args.inprocess if args.inprocess is not None else 10 * args.cases, args.seed)]
    print(HEADER)
    for t in tallies:
        print(t.report())
    for t in tallies:
        t.print_failures()
    sys.exit(1 if any(t.failures for t in tallies) else 0)


if __name__ == "__main__":
    os.environ.setdefault("PYTHONHASHSEED", "0")
    main()
