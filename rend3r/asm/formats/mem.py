"""``mem`` and ``mem-annotated``: ``$readmemh`` text, one 32-bit word per line.

``mem`` is byte for byte what the original assembler wrote. ``mem-annotated`` adds a
``//`` comment to each line (address, source position and source text), which
``$readmemh`` ignores. The reader accepts the ``$readmemh`` subset a memory image needs.
"""

from __future__ import annotations

import re

from ...isa.tables import OPCODE, Opcode
from ..program import Program
from .common import MAX_WORDS, WORD_LIMIT, TextInput, address_width, shown


def render_mem(program: Program) -> bytes:
    """8 lowercase hex digits per word, one word per line, newline after the last."""
    return "".join(f"{w:08x}\n" for w in program.words).encode("ascii")


def render_mem_annotated(program: Program) -> bytes:
    """``mem`` with ``// @addr file:line: source`` after each word.

    Words the device reads as the SD of the SE before them say ``(SD)``; further words
    of a multi-word statement (``.word a, b``) say ``(continued)``.
    """
    words = program.words
    sd_addresses = sd_positions(words)
    width = address_width(len(words))
    out = []
    address = 0
    for entry in program.entries:
        where = f"{entry.loc.file}:{entry.loc.line}: " if entry.loc else ""
        for k, word in enumerate(entry.words):
            parts = [f"@{address:0{width}x}"]
            if address in sd_addresses:
                parts.append("(SD)")
            if k == 0:
                parts.append(f"{where}{entry.text.strip()}")
            elif address not in sd_addresses:
                parts.append(f"{where}(continued)")
            out.append(f"{word:08x} // {' '.join(p for p in parts if p)}".rstrip() + "\n")
            address += 1
    return "".join(out).encode("utf-8")


def sd_positions(words: list[int]) -> set[int]:
    """Addresses the device reads as SD words: each one right after an SE."""
    sds = set()
    addr = 0
    while addr < len(words):
        if OPCODE.get(words[addr]) == Opcode.SE and addr + 1 < len(words):
            sds.add(addr + 1)
            addr += 2
        else:
            addr += 1
    return sds


_PLAIN = re.compile(r"(?:[0-9A-Fa-f]{1,8}\r?\n)*(?:[0-9A-Fa-f]{1,8}\r?\n?)?")
_TOKEN = re.compile(
    r"""(?P<ws>\s+)
      | (?P<line>//[^\n]*)
      | (?P<block>/\*.*?\*/)
      | (?P<addr>@[0-9A-Fa-f][0-9A-Fa-f_]*)
      | (?P<word>[0-9A-Fa-f][0-9A-Fa-f_]*)
      | (?P<bad>.)""",
    re.X | re.S,
)


def read_mem(data: bytes, name: str) -> list[int]:
    """Words of a ``$readmemh`` file: hex words separated by whitespace, ``//`` and
    ``/* */`` comments, and ``@addr`` (hex word address) jumps that zero-fill the gap.

    An ``@addr`` may not go back over words already read; ``x``/``z`` digits are errors.
    """
    src = TextInput(data, name, "mem")
    text = src.text
    # Plain words only, the usual case; problems (and too many lines) go the long way.
    if text.count("\n") <= MAX_WORDS and _PLAIN.fullmatch(text):
        words = [int(w, 16) for w in text.split()]
        if 0 < len(words) <= MAX_WORDS:
            return words
    words = []
    for m in _TOKEN.finditer(text):
        kind = m.lastgroup
        if kind == "word":
            value = int(m.group().replace("_", ""), 16)
            if value >= WORD_LIMIT:
                raise src.error(m.start(), f"word {shown(m.group())} is over 32 bits")
            if len(words) >= MAX_WORDS:
                raise src.error(m.start(), f"more than {MAX_WORDS:,} words")
            words.append(value)
        elif kind == "addr":
            target = int(m.group()[1:].replace("_", ""), 16)
            if target > MAX_WORDS:
                raise src.error(m.start(), f"address {shown(m.group())} is beyond the {MAX_WORDS:,}-word limit "
                                           f"(@{MAX_WORDS:x})")
            if target < len(words):
                raise src.error(m.start(), f"address {shown(m.group())} goes back over words already read "
                                           f"(next address is @{len(words):x})")
            words.extend([0] * (target - len(words)))
        elif kind == "bad":
            raise src.error(m.start(), _bad_character(text, m.start()))
    if not words:
        raise src.error(0, "empty file: no words" if not text.strip() else "no words in file")
    return words


def _bad_character(text: str, pos: int) -> str:
    c = text[pos]
    if text.startswith("/*", pos):
        return "unterminated /* comment"
    if c == "@":
        return "'@' must be followed by a hex address"
    if c.isalnum() or c == "_":
        return f"bad hex digit {c!r}"
    return f"unexpected character {c!r} (expected a hex word, @address or comment)"
