"""``ihex``: Intel HEX (I32HEX). Byte address = word address * 4; the bytes of each word
in ``byteorder`` (big-endian by default, as in ``bin``); type-04 extended linear address
records above 64 KiB; an end-of-file record last."""

from __future__ import annotations

import re

from ...errors import Rend3rError
from ..program import Program
from .common import MAX_WORDS, TextInput, pack_words, unpack_words

RECORD_SIZES = (4, 16)
_DATA, _EOF, _SEGMENT, _START_SEGMENT, _LINEAR, _START_LINEAR = range(6)


def _record(rtype: int, address: int, payload: bytes) -> str:
    body = bytes([len(payload), address >> 8, address & 0xFF, rtype]) + payload
    return f":{body.hex().upper()}{(-sum(body)) & 0xFF:02X}\n"


def render_ihex(program: Program, byteorder: str = "big", record_bytes: int = 16) -> bytes:
    """Data records of ``record_bytes`` (16, or 4 for one word per record)."""
    if record_bytes not in RECORD_SIZES:
        raise Rend3rError(f"ihex: record size must be one of {RECORD_SIZES}, not {record_bytes}")
    image = pack_words(program.words, byteorder)
    out = []
    upper = 0
    for offset in range(0, len(image), record_bytes):
        if offset >> 16 != upper:
            upper = offset >> 16
            out.append(_record(_LINEAR, 0, upper.to_bytes(2, "big")))
        out.append(_record(_DATA, offset & 0xFFFF, image[offset : offset + record_bytes]))
    out.append(_record(_EOF, 0, b""))
    return "".join(out).encode("ascii")


def read_ihex(data: bytes, name: str, byteorder: str = "big") -> list[int]:
    """Words of an Intel HEX file (record types 00-05; checksums verified).

    Gaps between data records read as zero words; overlapping data, a word only partly
    covered, data beyond the ``MAX_WORDS`` limit, data after the end-of-file record or a
    missing one are errors.
    """
    src = TextInput(data, name, "ihex")
    image = bytearray()
    runs: list[list[int]] = []  # [start, end, offset of its first record, of its last] per contiguous run
    base = 0
    eof_at: int | None = None
    for pos, raw in src.lines():
        line = raw.strip()
        start = pos + len(raw) - len(raw.lstrip())
        if eof_at is not None:
            raise src.error(start, "record after the end-of-file record")
        rtype, address, payload = _parse_record(src, line, start)
        if rtype == _DATA:
            absolute = base + address
            if absolute + len(payload) > MAX_WORDS * 4:
                raise src.error(start, f"data at byte address 0x{absolute:x} is beyond the {MAX_WORDS:,}-word "
                                       f"limit (byte address 0x{MAX_WORDS * 4:x})")
            if payload:
                end = absolute + len(payload)
                if len(image) < end:
                    image.extend(bytes(end - len(image)))
                image[absolute:end] = payload
                if runs and runs[-1][1] == absolute:
                    runs[-1][1], runs[-1][3] = end, start
                else:
                    runs.append([absolute, end, start, start])
        elif rtype == _EOF:
            eof_at = start
        elif rtype in (_SEGMENT, _LINEAR):
            _expect_length(src, start, payload, 2, rtype)
            base = int.from_bytes(payload, "big") << (4 if rtype == _SEGMENT else 16)
        elif rtype in (_START_SEGMENT, _START_LINEAR):
            _expect_length(src, start, payload, 4, rtype)
        else:
            raise src.error(start + 7, f"unknown record type {rtype:02X}")
    if eof_at is None:
        raise src.error(len(src.text), "no end-of-file record (:00000001FF)")
    if not runs:
        raise src.error(0, "no data records: empty image")
    _check_runs(src, runs)
    return unpack_words(image, byteorder)


_NOT_HEX = re.compile(r"[^0-9A-Fa-f]")


def _parse_record(src: TextInput, line: str, start: int) -> tuple[int, int, bytes]:
    if line[0] != ":":
        raise src.error(start, "an Intel HEX record starts with ':'")
    bad = _NOT_HEX.search(line, 1)
    if bad is not None:
        raise src.error(start + bad.start(), f"bad hex digit {bad.group()!r}")
    digits = line[1:]
    if len(digits) % 2:
        raise src.error(start, "record has an odd number of hex digits")
    if len(digits) > 2 * (5 + 255):
        raise src.error(start, f"record of {len(digits):,} hex digits is longer than any record (520)")
    body = bytes.fromhex(digits)
    if len(body) < 5:
        raise src.error(start, "record too short (at least :LLAAAATTCC)")
    if body[0] != len(body) - 5:
        raise src.error(start + 1, f"byte count field says {body[0]} but the record holds {len(body) - 5} data bytes")
    if sum(body) & 0xFF:
        expected = (-sum(body[:-1])) & 0xFF
        raise src.error(start + len(line) - 2, f"wrong record checksum {body[-1]:02X} (computed {expected:02X})")
    return body[3], (body[1] << 8) | body[2], body[4:-1]


def _expect_length(src: TextInput, start: int, payload: bytes, n: int, rtype: int) -> None:
    if len(payload) != n:
        raise src.error(start + 1, f"record type {rtype:02X} must carry {n} bytes, not {len(payload)}")


def _check_runs(src: TextInput, runs: list[list[int]]) -> None:
    """Runs of data may not overlap, and each contiguous stretch of data (runs that touch
    merged) must start and end on a word boundary."""
    runs.sort(key=lambda r: r[0])
    run_start, run_end, first_at, last_at = runs[0]
    for address, end, at, last in runs[1:]:
        if address < run_end:
            raise src.error(at, f"data at byte address 0x{address:x} overlaps an earlier record")
        if address > run_end:
            _check_whole_words(src, run_start, run_end, first_at, last_at)
            run_start, first_at = address, at
        run_end, last_at = end, last
    _check_whole_words(src, run_start, run_end, first_at, last_at)


def _check_whole_words(src: TextInput, start: int, end: int, first_at: int, last_at: int) -> None:
    """A run of contiguous data must start and end on a word boundary."""
    for edge, at in ((start, first_at), (end, last_at)):
        if edge % 4:
            raise src.error(
                at, f"data from byte address 0x{start:x} to 0x{end:x} covers only part of the 32-bit word at 0x{edge & ~3:x}"
            )
