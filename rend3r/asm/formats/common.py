"""Helpers shared by the memory-image readers and writers: positioned errors, limits,
text decoding and word packing."""

from __future__ import annotations

import re
import struct

from ...errors import Rend3rError

#: Largest memory image a reader builds (words). Guards against ``@ffffffff`` or an
#: Intel HEX record at 4 GiB allocating gigabytes; 16 Mi words is 32 times the largest
#: program the 19-bit shape index allows for one property per pair.
MAX_WORDS = 1 << 24
WORD_LIMIT = 1 << 32
BYTEORDERS = ("big", "little")

#: Control characters no text format contains (tab, newline, VT, FF and CR are allowed).
_CONTROL = re.compile("[\x00-\x08\x0e-\x1f\x7f]")


class TextInput:
    """A decoded text file that can turn an offset into a ``name:line:col:`` error."""

    def __init__(self, data: bytes, name: str, fmt: str) -> None:
        self.name = name
        self.text = decode_text(data, name, fmt)

    def error(self, pos: int, message: str) -> Rend3rError:
        line = self.text.count("\n", 0, pos) + 1
        col = pos - (self.text.rfind("\n", 0, pos) + 1) + 1
        return Rend3rError(f"{self.name}:{line}:{col}: {message}")

    def lines(self) -> list[tuple[int, str]]:
        """(offset of the line's first character, line without its newline)."""
        out = []
        pos = 0
        for line in self.text.split("\n"):
            out.append((pos, line))
            pos += len(line) + 1
        return out


def decode_text(data: bytes, name: str, fmt: str) -> str:
    """UTF-8 text without control characters, or a Rend3rError saying the file is binary."""
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise Rend3rError(
            f"{name}: not a text file (byte 0x{data[exc.start]:02x} at offset {exc.start} is not UTF-8); "
            f"expected {fmt} text (use --format bin for raw binary)"
        ) from None
    bad = _CONTROL.search(text)
    if bad is not None:
        raise Rend3rError(
            f"{name}: not a text file (control character 0x{ord(bad.group()):02x} at character {bad.start()}); "
            f"expected {fmt} text (use --format bin for raw binary)"
        )
    return text.removeprefix("\ufeff")


def is_text(data: bytes) -> bool:
    """True when ``data`` is UTF-8 without control characters (what every text format is)."""
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        return False
    return _CONTROL.search(text) is None


def check_byteorder(byteorder: str) -> None:
    if byteorder not in BYTEORDERS:
        raise Rend3rError(f"unknown byte order {byteorder!r}; choose big or little")


def pack_words(words: list[int], byteorder: str) -> bytes:
    """Words as 4 bytes each in ``byteorder``."""
    check_byteorder(byteorder)
    return struct.pack(f"{'>' if byteorder == 'big' else '<'}{len(words)}I", *words)


def unpack_words(data: bytes | bytearray, byteorder: str) -> list[int]:
    """The inverse of :func:`pack_words`; ``len(data)`` must be a multiple of 4."""
    check_byteorder(byteorder)
    return list(struct.unpack(f"{'>' if byteorder == 'big' else '<'}{len(data) // 4}I", data))


def address_width(count: int) -> int:
    """Hex digits for word addresses 0..count-1 (at least 4, so short programs line up)."""
    return max(4, len(f"{max(count - 1, 0):x}"))


def count_words(n: int) -> str:
    """``"1 word"``, ``"5 words"``."""
    return f"{n} word" if n == 1 else f"{n} words"
