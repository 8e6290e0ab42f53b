"""The device side of the load protocol, as a hardware receiver would implement it.

:class:`DeviceCore` is a pure state machine: bytes of one frame in, bytes of at most one
reply out. It stages a load in a buffer separate from the active program and swaps it in
only when a COMMIT's length and CRC-32 match the staged words, so a partial or corrupted
load never reaches the executor. It never raises on bad input: it counts and logs it.
"""

from __future__ import annotations

import logging
import zlib
from collections import Counter
from dataclasses import dataclass, field
from typing import Protocol

from .protocol import (
    LIMIT, MAX_DATA_WORDS, PROGRAM_INFO, REQUESTS, VERSION, Frame, FrameError, FrameType,
    Nack, Status, bytes_to_words, decode,
)

log = logging.getLogger("rend3r.device")

#: Default largest program the virtual device accepts, in words.
DEFAULT_MAX_WORDS = 1 << 16


class Executor(Protocol):
    """What runs the active program: the emulator in the virtual device, a recorder in tests."""

    frames: int  # frames rendered since the last reset

    def start(self, words: tuple[int, ...]) -> None:
        """(Re)start executing ``words`` from address 0, replacing what was running."""

    def stop(self) -> None:
        """Stop executing."""

    def reset(self) -> None:
        """Stop executing and zero the frame counter."""


class RecordingExecutor:
    """An executor that only records which programs it was asked to run."""

    def __init__(self) -> None:
        self.frames = 0
        self.started: list[tuple[int, ...]] = []
        self.running: tuple[int, ...] | None = None

    def start(self, words: tuple[int, ...]) -> None:
        self.started.append(words)
        self.running = words

    def stop(self) -> None:
        self.running = None

    def reset(self) -> None:
        self.running = None
        self.frames = 0


@dataclass
class _Staging:
    load: int
    words: int
    crc: int
    buffer: bytearray


@dataclass
class DeviceCounters:
    """What the device has seen since the last RESET."""

    malformed: int = 0  # undecodable frames (CRC, truncation, framing)
    unexpected: int = 0  # well-formed ACK/NACK frames sent to the device
    nacks: Counter = field(default_factory=Counter)  # Nack -> count
    loads: int = 0  # successful commits


class DeviceCore:
    """Receiver state machine: active program, staging buffer, limits and counters."""

    def __init__(self, executor: Executor | None = None, max_words: int = DEFAULT_MAX_WORDS) -> None:
        self.executor: Executor = executor if executor is not None else RecordingExecutor()
        self.max_words = max_words
        self.active: tuple[int, ...] = ()
        self.active_crc = zlib.crc32(b"")
        self.active_load = 0
        self.running = True  # like the board: it runs whatever its memory holds
        self.counters = DeviceCounters()
        self._staging: _Staging | None = None

    # -- entry points -------------------------------------------------------------------

    def handle(self, data: bytes) -> bytes | None:
        """Process one received frame; return the encoded reply, or None for no reply."""
        try:
            frame = decode(data)
        except FrameError as exc:
            self.malformed(str(exc))
            return None
        reply = self._dispatch(frame)
        return None if reply is None else reply.encode()

    def malformed(self, reason: str) -> None:
        """Count and log a frame dropped as malformed (also used by links for framing errors)."""
        self.counters.malformed += 1
        log.warning("dropped malformed frame #%d: %s", self.counters.malformed, reason)

    def status(self) -> Status:
        """The device's state as a STATUS request reports it."""
        return Status(
            words=len(self.active), crc=self.active_crc, frames=self.executor.frames,
            running=self.running, staging=self._staging is not None, load=self.active_load,
            malformed=self.counters.malformed, loads=self.counters.loads,
        )

    def _dispatch(self, frame: Frame) -> Frame | None:
        if frame.version != VERSION:
            return self._nack(frame, Nack.BAD_VERSION)
        if frame.type in (FrameType.ACK, FrameType.NACK):
            self.counters.unexpected += 1
            log.warning("ignored a %s frame sent to the device", FrameType(frame.type).name)
            return None
        if frame.type not in REQUESTS:
            return self._nack(frame, Nack.BAD_TYPE)
        handler = {
            FrameType.BEGIN: self._begin,
            FrameType.DATA: self._data,
            FrameType.COMMIT: self._commit,
        }.get(FrameType(frame.type), self._control)
        return handler(frame)

    # -- loading -------------------------------------------------------------------------

    def _begin(self, f: Frame) -> Frame:
        if f.count or f.offset or len(f.payload) != PROGRAM_INFO.size:
            return self._nack(f, Nack.BAD_FIELDS)
        words, crc = PROGRAM_INFO.unpack(f.payload)
        if words > self.max_words:
            return self._nack(f, Nack.TOO_LARGE, LIMIT.pack(self.max_words))
        s = self._staging
        if s is not None and (s.load, s.words, s.crc) == (f.load, words, crc):
            return f.reply(True)  # a repeated BEGIN must not discard what was staged
        if s is None and (self.active_load, len(self.active), self.active_crc) == (f.load, words, crc):
            return f.reply(True)  # a late duplicate of a load already committed
        self._staging = _Staging(f.load, words, crc, bytearray(4 * words))
        return f.reply(True)

    def _data(self, f: Frame) -> Frame:
        if not 1 <= f.count <= MAX_DATA_WORDS or len(f.payload) != 4 * f.count:
            return self._nack(f, Nack.BAD_FIELDS)
        s = self._staging
        if s is None or s.load != f.load:
            if s is None and f.load == self.active_load and self.active_load:
                return f.reply(True)  # late duplicate after the commit: already in place
            return self._nack(f, Nack.NO_LOAD)
        if f.offset + f.count > s.words:
            return self._nack(f, Nack.OUT_OF_RANGE)
        s.buffer[4 * f.offset:4 * (f.offset + f.count)] = f.payload
        return f.reply(True)

    def _commit(self, f: Frame) -> Frame:
        if f.count or f.offset or len(f.payload) != PROGRAM_INFO.size:
            return self._nack(f, Nack.BAD_FIELDS)
        words, crc = PROGRAM_INFO.unpack(f.payload)
        s = self._staging
        if s is None or s.load != f.load:
            if (self.active_load, len(self.active), self.active_crc) == (f.load, words, crc):
                return f.reply(True)  # the ACK of our commit was lost: it is done
            return self._nack(f, Nack.NO_LOAD)
        if (s.words, s.crc) != (words, crc) or zlib.crc32(s.buffer) != crc:
            return self._nack(f, Nack.MISMATCH)
        self.active = tuple(bytes_to_words(bytes(s.buffer)))
        self.active_crc, self.active_load = crc, f.load
        self._staging = None
        self.counters.loads += 1
        log.info("committed load %d: %d words, CRC-32 %08x", f.load, words, crc)
        if self.running:
            self.executor.start(self.active)
        return f.reply(True)

    # -- control -------------------------------------------------------------------------

    def _control(self, f: Frame) -> Frame:
        if f.count or f.offset or f.payload:
            return self._nack(f, Nack.BAD_FIELDS)
        if f.type == FrameType.RUN:
            self.running = True
            self.executor.start(self.active)
        elif f.type == FrameType.STOP:
            self.running = False
            self.executor.stop()
        elif f.type == FrameType.RESET:
            self.executor.reset()
            self.active, self.active_crc, self.active_load = (), zlib.crc32(b""), 0
            self.running = True
            self.counters = DeviceCounters()
            self._staging = None
        elif f.type == FrameType.STATUS:
            return f.reply(True, payload=self.status().pack())
        return f.reply(True)

    def _nack(self, f: Frame, code: Nack, payload: bytes = b"") -> Frame:
        self.counters.nacks[code] += 1
        log.warning("NACK %s to %s load %d seq %d", code.name, _type_name(f.type), f.load, f.seq)
        return f.reply(False, code, payload)


def _type_name(value: int) -> str:
    try:
        return FrameType(value).name
    except ValueError:
        return f"type 0x{value:02x}"
