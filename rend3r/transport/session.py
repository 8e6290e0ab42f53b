"""The sender's side of the load protocol: windowed, retransmitting, bounded.

A load is BEGIN, then the DATA frames with up to ``window`` of them unacknowledged, then
COMMIT. A frame is resent when its ACK is late by ``timeout`` seconds or it is NACKed with
a transient reason; after ``retries`` resends it fails with :class:`SendError` (a write
that cannot proceed for as long fails too: a device that stopped reading). If the
device has lost the load (it was reset, or another sender replaced it) the whole load
restarts under a new load id, also at most ``retries`` times.
"""

from __future__ import annotations

import random
import time
from dataclasses import dataclass
from typing import Callable

from ..errors import Rend3rError
from .links import Link
from .protocol import (
    FATAL_NACKS, LIMIT, MAX_DATA_WORDS, PROGRAM_INFO, Frame, FrameError, FrameType, Nack,
    Status, decode, program_crc, words_to_bytes,
)

DEFAULT_TIMEOUT = 0.5
DEFAULT_RETRIES = 8
DEFAULT_WINDOW = 8

Progress = Callable[[int, int], None]  # (words acknowledged, words in the program)


class SendError(Rend3rError):
    """The device did not accept what was sent."""


class _Restart(Exception):
    """The device lost the load in progress; start it again under a new id."""


def load_frames(words: list[int] | tuple[int, ...], load: int, first_seq: int = 0,
                chunk: int = MAX_DATA_WORDS) -> list[Frame]:
    """BEGIN, the DATA frames and COMMIT that load ``words`` under load id ``load``."""
    info = PROGRAM_INFO.pack(len(words), program_crc(words))
    frames = [Frame(FrameType.BEGIN, load, first_seq, payload=info)]
    for i, offset in enumerate(range(0, len(words), chunk)):
        part = words[offset:offset + chunk]
        frames.append(Frame(FrameType.DATA, load, (first_seq + 1 + i) & 0xFFFF, offset,
                            len(part), words_to_bytes(part)))
    frames.append(Frame(FrameType.COMMIT, load, (first_seq + len(frames)) & 0xFFFF, payload=info))
    return frames


@dataclass
class SendStats:
    """What a sender did, for progress reports and benchmarks."""

    frames: int = 0  # frames written, resends included
    resends: int = 0
    timeouts: int = 0
    nacks: int = 0
    ignored: int = 0  # replies that were malformed or answered nothing outstanding
    restarts: int = 0


@dataclass
class _Pending:
    frame: Frame
    data: bytes
    tries: int = 0
    deadline: float = 0.0


class Sender:
    """Loads programs into, and controls, one device over one link."""

    def __init__(self, link: Link, *, timeout: float = DEFAULT_TIMEOUT,
                 retries: int = DEFAULT_RETRIES, window: int = DEFAULT_WINDOW,
                 progress: Progress | None = None, rng: random.Random | None = None) -> None:
        if timeout <= 0 or retries < 0 or window < 1:
            raise ValueError("timeout must be > 0, retries >= 0, window >= 1")
        self.link = link
        self.timeout = timeout
        self.retries = retries
        self.window = window
        self.progress = progress
        self.rng = rng or random.Random()
        self.stats = SendStats()
        self._seq = self.rng.randrange(1 << 16)
        link.limit_writes((retries + 1) * timeout)  # a frame unwritable that long is unacknowledged too

    def load(self, words: list[int] | tuple[int, ...]) -> None:
        """Load ``words`` as the device's program; return once the device committed it."""
        words = tuple(words)
        for attempt in range(self.retries + 1):
            load = self.rng.randrange(1, 1 << 16)
            frames = load_frames(words, load, self._take_seq(len(words) // MAX_DATA_WORDS + 3))
            try:
                self._exchange(frames[:1])
                self._exchange(frames[1:-1], total=len(words))
                self._exchange(frames[-1:])
                return
            except _Restart as why:
                self.stats.restarts += 1
                last = str(why)
        raise SendError(f"the device kept losing the load ({last}); gave up after "
                        f"{self.retries + 1} attempts")

    def control(self, ftype: FrameType) -> Frame:
        """Send RUN, STOP, RESET or STATUS and return the device's ACK."""
        frame = Frame(ftype, 0, self._take_seq(1))
        try:
            return self._exchange([frame])[frame.seq]
        except _Restart as exc:  # not a reason a control request can be refused
            raise SendError(f"the device refused {ftype.name}: {exc}") from exc

    def status(self) -> Status:
        """The device's STATUS answer."""
        ack = self.control(FrameType.STATUS)
        try:
            return Status.unpack(ack.payload)
        except FrameError as exc:
            raise SendError(f"the device's status answer is malformed: {exc}") from exc

    # -- the exchange engine -------------------------------------------------------------

    def _take_seq(self, n: int) -> int:
        first = self._seq
        self._seq = (self._seq + n) & 0xFFFF
        return first

    def _transmit(self, p: _Pending) -> None:
        if p.tries > self.retries:
            f = p.frame
            what = FrameType(f.type).name + (f" (words {f.offset}..{f.offset + f.count - 1})"
                                             if f.type == FrameType.DATA else "")
            raise SendError(f"no acknowledgement for {what} after {p.tries} tries "
                            f"({self.timeout:g} s each): is a device listening on this link?")
        if p.tries:
            self.stats.resends += 1
        p.tries += 1
        self.link.send(p.data)
        self.stats.frames += 1
        p.deadline = time.monotonic() + self.timeout

    def _exchange(self, frames: list[Frame], total: int = 0) -> dict[int, Frame]:
        """Send ``frames`` with at most ``window`` unacknowledged; return their ACKs by seq."""
        queue = [_Pending(f, f.encode()) for f in reversed(frames)]
        outstanding: dict[int, _Pending] = {}
        acks: dict[int, Frame] = {}
        done_words = 0
        while queue or outstanding:
            while queue and len(outstanding) < self.window:
                p = queue.pop()
                outstanding[p.frame.seq] = p
                self._transmit(p)
            first_deadline = min(p.deadline for p in outstanding.values())
            try:
                data = self.link.recv(max(0.0, first_deadline - time.monotonic()))
            except FrameError:
                self.stats.ignored += 1
                continue
            if data is None:
                # recv waited until the earliest deadline (or knows nothing more will come)
                self.stats.timeouts += 1
                cutoff = max(time.monotonic(), first_deadline)
                for p in [p for p in outstanding.values() if p.deadline <= cutoff]:
                    self._transmit(p)
                continue
            reply = self._match(data, outstanding)
            if reply is None:
                continue
            p = outstanding[reply.seq]
            if reply.type == FrameType.ACK:
                del outstanding[reply.seq]
                acks[reply.seq] = reply
                if p.frame.type == FrameType.DATA and self.progress is not None:
                    done_words += p.frame.count
                    self.progress(done_words, total)
                continue
            self._nacked(p, reply)
        return acks

    def _match(self, data: bytes, outstanding: dict[int, _Pending]) -> Frame | None:
        try:
            reply = decode(data)
        except FrameError:
            self.stats.ignored += 1
            return None
        p = outstanding.get(reply.seq)
        if (reply.type not in (FrameType.ACK, FrameType.NACK) or p is None
                or reply.load != p.frame.load or reply.ref != p.frame.type):
            self.stats.ignored += 1  # a duplicate, or an answer to an older attempt
            return None
        return reply

    def _nacked(self, p: _Pending, reply: Frame) -> None:
        self.stats.nacks += 1
        try:
            code = Nack(reply.code)
        except ValueError:
            raise SendError(f"the device refused {FrameType(p.frame.type).name} with unknown "
                            f"code {reply.code}") from None
        if code == Nack.TOO_LARGE and p.frame.type == FrameType.BEGIN:  # to any other request: a mismatch
            limit = LIMIT.unpack(reply.payload)[0] if len(reply.payload) == LIMIT.size else "?"
            words = PROGRAM_INFO.unpack(p.frame.payload)[0]
            raise SendError(f"the device refuses a program of {words} words: its limit is {limit}")
        if code in FATAL_NACKS:
            raise SendError(f"the device refused {FrameType(p.frame.type).name}: {code.name} "
                            "(protocol mismatch between sender and device?)")
        raise _Restart(code.name)
