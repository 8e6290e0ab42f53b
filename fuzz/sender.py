"""Long fuzz run of the load protocol's sender: ``rend3r send`` against a hostile device.

    python fuzz/sender.py --cases 300 [--seed 1]

Each case runs the real command, ``rend3r send PROGRAM --serial socket://127.0.0.1:PORT``,
in a child (``fuzz/harness.py``: its own time and peak RSS from ``wait4``) against a
device served on loopback by this process. The device is an honest ``DeviceCore`` whose
replies one behaviour per case turns hostile: garbage bytes, invalid COBS, replies with
correct CRCs but wrong fields (type, seq, load, ref, length, version), NACK storms with
any code, ACKs for frames never sent, duplicated and reordered ACKs, a huge run of bytes
without a delimiter, silence, closing the connection mid-load, a device that stops
reading, a slowly trickled valid reply, a lying STATUS, TOO_LARGE to every request after
BEGIN, or a mix per frame. A case
passes when ``send`` exits 0 or 1 (1 with an ``error:`` line), never with a traceback or a
signal, within the case's bound (``bound``: every frame's retries and every restart, plus
``MARGIN``) and with a peak RSS of at most ``MAX_RSS``; behaviours that still complete a
valid exchange must exit 0, those that cannot must exit 1. Prints ``fuzz/harness.py``'s
table header and one row, then the failures and the count of wrong verdicts.
"""

from __future__ import annotations

import argparse
import os
import random
import select
import socket
import sys
import tempfile
import threading
import time
import zlib
from dataclasses import dataclass
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from harness import HEADER, CaseResult, Tally, run_case  # noqa: E402

from rend3r.transport import cobs  # noqa: E402
from rend3r.transport.device import DeviceCore  # noqa: E402
from rend3r.transport.protocol import HEADER as FRAME_HEADER  # noqa: E402
from rend3r.transport.protocol import (  # noqa: E402
    LIMIT, MAX_DATA_WORDS, STATUS, Frame, FrameType, Nack, decode,
)

MARGIN = 30.0
"""Seconds a case may take beyond its protocol bound: interpreter start-up on a loaded machine."""

MAX_RSS = 256 << 20
"""Peak RSS a case may reach: ``send`` holds one program and a frame's worth of input."""

#: Behaviour -> the exit statuses that are right for it (0: the exchange still completes).
BEHAVIOURS: dict[str, tuple[int, ...]] = {
    "honest": (0,),
    "garbage": (0, 1),
    "bad-cobs": (0, 1),
    "fields": (0, 1),
    "nack-storm": (0, 1),
    "phantom-acks": (0,),
    "dup-reorder": (0,),
    "huge": (0, 1),
    "silence": (1,),
    "close": (0, 1),  # 0 when the exchange ends before the device closes
    "stall": (0, 1),  # or stops reading
    "trickle": (0, 1),
    "status-lies": (1,),
    "too-large": (1,),
    "mixed": (0, 1),
}
#: Behaviours "mixed" draws from for each reply.
MIXABLE = ("honest", "garbage", "bad-cobs", "fields", "nack-storm", "phantom-acks", "dup-reorder", "silence")


def wire(frame: bytes) -> bytes:
    """One frame as the serial link carries it: COBS and a delimiter."""
    return cobs.encode(frame) + b"\0"


def refield(rng: random.Random, reply: bytes) -> bytes:
    """``reply`` with one or two header fields changed (or its payload resized), CRC correct."""
    fields = list(FRAME_HEADER.unpack_from(reply))
    payload = reply[16:-4]
    length = None
    for _ in range(rng.randint(1, 2)):
        which = rng.randrange(8)
        if which == 0:
            fields[0] = rng.choice([0, 2, 255])  # version
        elif which == 1:
            fields[1] = rng.choice([*FrameType, rng.randrange(256)])  # type
        elif which == 2:
            fields[2] = rng.getrandbits(16)  # load
        elif which == 3:
            fields[3] = (fields[3] + rng.choice([1, -1, 8, 0x8000])) & 0xFFFF  # seq
        elif which == 4:
            fields[7] = rng.choice([*FrameType, rng.randrange(256)])  # ref
        elif which == 5:
            fields[8] = rng.randrange(256)  # code
        elif which == 6:
            payload = rng.randbytes(rng.choice([0, 1, STATUS.size - 1, STATUS.size + 1, 1024, 4000]))
        else:
            length = rng.choice([0xFFFF, rng.randrange(1 << 16)])  # disagrees with the payload
    fields[6] = len(payload) if length is None else length
    body = FRAME_HEADER.pack(*fields) + payload[:fields[6]]
    return body + zlib.crc32(body).to_bytes(4, "big") + payload[fields[6]:]


def invalid_cobs(rng: random.Random) -> bytes:
    """A delimited block whose COBS code bytes point past its end."""
    body = bytes(rng.randrange(1, 256) for _ in range(rng.randrange(1, 40)))
    return bytes([min(255, len(body) + rng.randint(2, 200))]) + body + b"\0"


@dataclass
class Case:
    """One hostile device and the ``send`` options it is fuzzed with."""

    behaviour: str
    seed: int
    words: int
    timeout: float
    retries: int
    run: bool

    @property
    def frames(self) -> int:
        """Frames ``send`` exchanges with an honest device: BEGIN, DATA, COMMIT, RUN, STATUS."""
        return -(-self.words // MAX_DATA_WORDS) + 3 + self.run

    @property
    def bound(self) -> float:
        """Seconds ``send`` may take: each frame's tries to their timeouts, each load restarted
        ``retries`` times, plus MARGIN."""
        tries = self.retries + 1
        return tries * tries * self.frames * self.timeout + MARGIN


def draw_case(rng: random.Random) -> Case:
    return Case(rng.choice(list(BEHAVIOURS)), rng.getrandbits(32),
                rng.choice([1, 255, 256, 257, 1000, 3000]), rng.choice([0.05, 0.1, 0.2]),
                rng.choice([0, 1, 2, 3]), rng.random() < 0.3)


class HostileDevice:
    """A device on ``socket://127.0.0.1:PORT`` (``url``) answering with one behaviour.

    Serves one connection in a thread; ``close`` ends it.
    """

    def __init__(self, behaviour: str, seed: int = 0) -> None:
        self.behaviour = behaviour
        self.rng = random.Random(seed)
        self.core = DeviceCore(max_words=1 << 16)
        self.server = socket.create_server(("127.0.0.1", 0))
        self.url = f"socket://127.0.0.1:{self.server.getsockname()[1]}"
        self.turns_after = self.rng.randrange(0, 6)  # frames answered before it closes or stops reading
        self.frames = 0
        self._held: list[bytes] = []
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._serve, daemon=True)
        self._thread.start()

    def close(self) -> None:
        self._stop.set()
        self._thread.join()
        self.server.close()

    def _serve(self) -> None:
        self.server.settimeout(0.05)
        while not self._stop.is_set():
            try:
                conn, _ = self.server.accept()
            except TimeoutError:
                continue
            with conn:
                try:
                    self._talk(conn)
                except OSError:  # the sender went away while we wrote
                    pass
            return

    def _talk(self, conn: socket.socket) -> None:
        buf = bytearray()
        while not self._stop.is_set():
            if self.behaviour == "stall" and self.frames > self.turns_after:
                time.sleep(0.05)  # stops reading: the sender's writes back up
                continue
            if not select.select([conn], [], [], 0.01 if self._held else 0.05)[0]:
                if self._held:  # idle: what was held back arrives now
                    conn.sendall(b"".join(self._held))
                    self._held.clear()
                continue
            data = conn.recv(1 << 16)
            if not data:
                return
            buf += data
            *whole, rest = bytes(buf).split(b"\0")
            buf = bytearray(rest)
            for raw in whole:
                if not raw:
                    continue
                try:
                    frame = cobs.decode(raw)
                except cobs.CobsError:
                    continue
                self.frames += 1
                if self.behaviour == "close" and self.frames > self.turns_after:
                    return
                if self.behaviour == "stall" and self.frames > self.turns_after:
                    break
                out = self.answer(frame, self.behaviour)
                if self.behaviour == "trickle":
                    delay = self.rng.choice([0.001, 0.005, 0.02])
                    for i in range(len(out)):
                        conn.sendall(out[i:i + 1])
                        time.sleep(delay)
                else:
                    conn.sendall(out)

    def answer(self, frame: bytes, behaviour: str) -> bytes:
        """The bytes the device writes for one received frame."""
        rng = self.rng
        honest = self.core.handle(frame)
        if behaviour == "mixed":
            behaviour = rng.choice(MIXABLE)
        if honest is None or behaviour in ("honest", "trickle", "close", "stall"):
            return wire(honest) if honest else b""
        if behaviour == "silence":
            return b""
        if behaviour == "garbage":
            junk = rng.randbytes(rng.randrange(1, 300))
            return junk + (wire(honest) if rng.random() < 0.5 else b"")
        if behaviour == "bad-cobs":
            return invalid_cobs(rng) + (wire(honest) if rng.random() < 0.7 else b"")
        if behaviour == "fields":
            out = b"".join(wire(refield(rng, honest)) for _ in range(rng.randint(1, 3)))
            return out + (wire(honest) if rng.random() < 0.5 else b"")
        if behaviour == "nack-storm":
            request = decode(frame)
            nacks = []
            for _ in range(rng.randint(1, 5)):
                payload = rng.choice([b"", b"\0\0\0\1", rng.randbytes(rng.randrange(9))])
                nacks.append(wire(request.reply(False, rng.choice([*range(8), rng.randrange(256)]), payload).encode()))
            return b"".join(nacks) + (wire(honest) if rng.random() < 0.5 else b"")
        if behaviour == "phantom-acks":
            request = decode(frame)
            phantoms = [Frame(FrameType.ACK, rng.getrandbits(16), (request.seq + rng.randint(1, 0xFFFF)) & 0xFFFF,
                              ref=rng.choice(list(FrameType))).encode() for _ in range(rng.randint(1, 4))]
            return b"".join(map(wire, phantoms)) + wire(honest)
        if behaviour == "dup-reorder":
            if not self._held and rng.random() < 0.5:
                self._held.append(wire(honest))  # held back: arrives behind the next reply
                return b""
            out = wire(honest) * rng.randint(1, 2) + b"".join(self._held)
            self._held.clear()
            return out
        if behaviour == "huge":
            return bytes(rng.randrange(1, 256) for _ in range(64)) * rng.choice([40, 1000, 16000]) + b"\0" + wire(honest)
        if behaviour == "too-large":
            request = decode(frame)
            if request.type == FrameType.BEGIN:
                return wire(honest)
            limit = rng.choice([b"", LIMIT.pack(rng.getrandbits(32))])
            return wire(request.reply(False, Nack.TOO_LARGE, limit).encode())
        if behaviour == "status-lies":
            reply = decode(honest)
            if reply.ref != FrameType.STATUS:
                return wire(honest)
            lie = rng.choice([rng.randbytes(rng.choice([0, STATUS.size - 1, STATUS.size + 1])),
                              reply.payload[:4] + bytes(4) + reply.payload[8:],
                              (rng.randrange(1, 1 << 32)).to_bytes(4, "big") + reply.payload[4:]])
            return wire(Frame(reply.type, reply.load, reply.seq, payload=lie, ref=reply.ref).encode())
        raise ValueError(f"unknown behaviour {behaviour!r}")


def program_file(folder: Path, words: int, rng: random.Random) -> Path:
    """A ``.mem`` image of ``words`` random words."""
    path = folder / f"p{words}.mem"
    path.write_text("".join(f"{rng.getrandbits(32):08x}\n" for _ in range(words)))
    return path


def run_sender(case: Case, folder: Path) -> CaseResult:
    """``rend3r send`` against ``case``'s hostile device, bounded by ``case.bound``."""
    program = program_file(folder, case.words, random.Random(case.seed))
    device = HostileDevice(case.behaviour, case.seed)
    try:
        args = ["send", str(program), "--serial", device.url, "--timeout", str(case.timeout),
                "--retries", str(case.retries), *(["--run"] if case.run else [])]
        return run_case(args, timeout=case.bound)
    finally:
        device.close()


def right_verdict(case: Case, result: CaseResult) -> bool:
    """The exit status is one the behaviour allows and the peak RSS at most ``MAX_RSS`` (a
    hang or a crash is counted by the tally)."""
    return (result.returncode in BEHAVIOURS[case.behaviour] or not result.ok) and result.rss_bytes <= MAX_RSS


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cases", type=int, default=300)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    tally = Tally("sender: `rend3r send` against a hostile device (loopback socket)")
    wrong: list[tuple[Case, CaseResult]] = []
    rng = random.Random(args.seed)
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(args.cases):
            case = draw_case(rng)
            result = run_sender(case, Path(tmp))
            tally.add(result)
            if not right_verdict(case, result):
                wrong.append((case, result))
    print(HEADER)
    print(tally.report())
    tally.print_failures()
    for case, result in wrong[:5]:
        print(f"WRONG VERDICT {result.returncode} ({result.rss_bytes >> 20} MiB) for {case}: {result.stderr[-500:]}",
              file=sys.stderr)
    print(f"{len(wrong)} wrong verdicts (exit status or RSS)", file=sys.stderr)
    sys.exit(1 if tally.failures or wrong else 0)


if __name__ == "__main__":
    os.environ.setdefault("PYTHONHASHSEED", "0")
    main()
