"""The REND3R load protocol: byte-exact frame layout shared by sender and device.

Every frame, on every link, is a 16-byte big-endian header, a payload of ``length`` bytes
and a CRC-32 (IEEE 802.3 / zlib) of header and payload, stored big-endian. Links add their
own delimiting (COBS on serial, an Ethernet II header on Ethernet); see docs/protocol.md.
"""

from __future__ import annotations

import struct
import zlib
from dataclasses import dataclass
from enum import IntEnum

VERSION = 1
HEADER = struct.Struct(">BBHHHIHBB")  # version type load seq count offset length ref code
HEADER_SIZE = HEADER.size  # 16
CRC_SIZE = 4
OVERHEAD = HEADER_SIZE + CRC_SIZE
#: Words per DATA frame: 1 KiB payload fits any Ethernet MTU and a small hardware buffer.
MAX_DATA_WORDS = 256
MAX_PAYLOAD = 4 * MAX_DATA_WORDS
MAX_FRAME = OVERHEAD + MAX_PAYLOAD
WORD_MASK = 0xFFFFFFFF

PROGRAM_INFO = struct.Struct(">II")  # words, program CRC-32 (BEGIN and COMMIT payloads)
STATUS = struct.Struct(">IIIBBHII")  # words crc frames running staging load malformed loads
LIMIT = struct.Struct(">I")  # payload of a TOO_LARGE NACK: the device's word limit


class FrameType(IntEnum):
    """The ``type`` byte. Requests go sender -> device; ACK/NACK answer them."""

    BEGIN = 0x01
    DATA = 0x02
    COMMIT = 0x03
    RUN = 0x04
    STOP = 0x05
    RESET = 0x06
    STATUS = 0x07
    ACK = 0x80
    NACK = 0x81


REQUESTS = frozenset(t for t in FrameType if t < FrameType.ACK)


class Nack(IntEnum):
    """The ``code`` byte of a NACK: why the device refused a request."""

    BAD_VERSION = 1  # version byte is not VERSION
    BAD_TYPE = 2  # unknown request type
    BAD_FIELDS = 3  # header fields inconsistent with the type (count, length, offset)
    NO_LOAD = 4  # DATA/COMMIT for a load the device has not begun (or already replaced)
    OUT_OF_RANGE = 5  # DATA beyond the length announced by BEGIN
    MISMATCH = 6  # COMMIT: staged words do not have the announced length and CRC
    TOO_LARGE = 7  # BEGIN: program exceeds the device's limit (payload: the limit)


#: NACKs after which resending the same frame cannot help.
FATAL_NACKS = frozenset({Nack.BAD_VERSION, Nack.BAD_TYPE, Nack.BAD_FIELDS, Nack.TOO_LARGE})


class FrameError(ValueError):
    """Bytes that are not a well-formed frame (bad CRC, truncated, inconsistent length)."""


@dataclass(frozen=True)
class Frame:
    """One protocol frame; ``ref`` and ``code`` are used by ACK/NACK only."""

    type: int
    load: int = 0
    seq: int = 0
    offset: int = 0
    count: int = 0
    payload: bytes = b""
    ref: int = 0
    code: int = 0
    version: int = VERSION

    def encode(self) -> bytes:
        """The frame's bytes: header, payload, CRC-32."""
        body = HEADER.pack(
            self.version, self.type, self.load, self.seq, self.count, self.offset,
            len(self.payload), self.ref, self.code,
        ) + self.payload
        return body + zlib.crc32(body).to_bytes(4, "big")

    def reply(self, ok: bool, code: int = 0, payload: bytes = b"") -> Frame:
        """The ACK (``ok``) or NACK answering this request."""
        return Frame(
            FrameType.ACK if ok else FrameType.NACK, self.load, self.seq, self.offset,
            self.count, payload, ref=self.type, code=code,
        )


def decode(data: bytes) -> Frame:
    """Parse one frame; trailing bytes beyond ``length`` (Ethernet padding) are ignored.

    Raises FrameError when the frame is truncated or its CRC does not match. The version
    and type are not judged here: the device answers those with a NACK.
    """
    if len(data) < OVERHEAD:
        raise FrameError(f"frame of {len(data)} bytes is shorter than the {OVERHEAD}-byte minimum")
    version, ftype, load, seq, count, offset, length, ref, code = HEADER.unpack_from(data)
    end = HEADER_SIZE + length
    if end + CRC_SIZE > len(data):
        raise FrameError(f"length field {length} exceeds the {len(data)}-byte frame")
    if zlib.crc32(data[:end]) != int.from_bytes(data[end:end + CRC_SIZE], "big"):
        raise FrameError("CRC-32 mismatch")
    return Frame(ftype, load, seq, offset, count, bytes(data[HEADER_SIZE:end]), ref, code, version)


def words_to_bytes(words: list[int] | tuple[int, ...]) -> bytes:
    """Big-endian bytes of 32-bit words (byte 0 is bits 31:24 of the first word)."""
    return struct.pack(f">{len(words)}I", *words)


def bytes_to_words(data: bytes) -> list[int]:
    """Inverse of words_to_bytes; ``len(data)`` must be a multiple of 4."""
    return list(struct.unpack(f">{len(data) // 4}I", data))


def program_crc(words: list[int] | tuple[int, ...]) -> int:
    """CRC-32 (zlib) of the program's big-endian bytes: the value BEGIN and COMMIT carry."""
    return zlib.crc32(words_to_bytes(words))


@dataclass(frozen=True)
class Status:
    """A device's answer to STATUS."""

    words: int  # length of the active program
    crc: int  # program_crc of the active program
    frames: int  # frames rendered since the last RESET
    running: bool
    staging: bool  # a load is in progress
    load: int  # load id of the active program (0: none since reset)
    malformed: int  # frames dropped as malformed since reset
    loads: int  # successful commits since reset

    def pack(self) -> bytes:
        return STATUS.pack(
            self.words, self.crc, self.frames, int(self.running), int(self.staging),
            self.load, self.malformed, self.loads,
        )

    @classmethod
    def unpack(cls, data: bytes) -> Status:
        if len(data) != STATUS.size:
            raise FrameError(f"status payload of {len(data)} bytes, expected {STATUS.size}")
        w, c, f, r, s, load, m, n = STATUS.unpack(data)
        return cls(w, c, f, bool(r), bool(s), load, m, n)
