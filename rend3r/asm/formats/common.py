"""Helpers shared by the memory-image readers and writers: positioned errors, limits,
text decoding and word packing."""

from __future__ import annotations

import re
import struct
from collections.abc import Iterator

from ...errors import Rend3rError

#: Largest memory image a reader builds (words), addresses included: an ``@ADDR`` or an
#: Intel HEX address beyond it is refused, not zero-filled. 1 Mi words is 1,024 times the
#: largest original target's program memory (``rend3r.isa.targets``: 1,024 words), 16
#: times the virtual device's default load limit, and room for the 655,360-word program of
#: 65,536 spheres; disassembling it takes seconds and a few hundred MB. (The full 19-bit
#: shape index space, 14 words per shape, would be 7 Mi words: no build holds it.)
MAX_WORDS = 1 << 20
WORD_LIMIT = 1 << 32
BYTEORDERS = ("big", "little")

#: Most bytes of file per word of image, per format: a file larger than
#: ``MAX_WORDS * BYTES_PER_WORD[fmt]`` is refused before it is read. ``bin`` is 4;
#: ``ihex`` fits one-word records with CRLF (21); ``coe`` fits radix 2 (32 digits, comma,
#: CRLF); ``mem`` and ``lst`` leave room for comments and source text (``mem`` and
#: ``mem-annotated`` share the extension, so they share the figure).
BYTES_PER_WORD = {"mem": 64, "mem-annotated": 64, "bin": 4, "coe": 40, "ihex": 24, "lst": 64}

#: Control characters no text format contains (tab, newline, VT, FF and CR are allowed).
_CONTROL = re.compile("[\x00-\x08\x0e-\x1f\x7f]")
#: Linear on any text: only a line start can begin a match, and ``\S`` ends the blanks.
_NON_BLANK_LINE = re.compile(r"^[^\S\n]*\S[^\n]*", re.M)


class TextInput:
    """A decoded text file that can turn an offset into a ``name:line:col:`` error."""

    def __init__(self, data: bytes, name: str, fmt: str) -> None:
        self.name = name
        self.text = decode_text(data, name, fmt)

    def error(self, pos: int, message: str) -> Rend3rError:
        line = self.text.count("\n", 0, pos) + 1
        col = pos - (self.text.rfind("\n", 0, pos) + 1) + 1
        return Rend3rError(f"{self.name}:{line}:{col}: {message}")

    def lines(self) -> Iterator[tuple[int, str]]:
        """(offset of the line's first character, line without its newline) for each line
        that is not blank (found in C, so a file of blank lines costs no Python loop)."""
        for m in _NON_BLANK_LINE.finditer(self.text):
            yield m.start(), m.group()


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


def shown(token: str, limit: int = 24) -> str:
    """``token`` for an error message: cut to ``limit`` characters with its length said,
    so a hostile 60 MB number does not become a 60 MB message."""
    return token if len(token) <= limit else f"{token[:limit]}... ({len(token):,} characters)"
