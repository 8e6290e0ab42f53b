"""``lst``: a listing, ``line | address | word(s) | source``, readable back.

Header lines start with ``;``. The line column is the source line number, or
``file:line`` for statements from another file than the first (``.include``); empty when
the program has no source positions (a disassembled image). Addresses and words are hex.
A statement with more than two words continues on further rows with empty line and
source columns.
"""

from __future__ import annotations

import re

from ..program import Program
from .common import MAX_WORDS, WORD_LIMIT, TextInput, address_width, count_words, shown

WORDS_PER_ROW = 2
_WORDS_WIDTH = 9 * WORDS_PER_ROW - 1


def render_lst(program: Program) -> bytes:
    entries = program.entries
    main_file = next((e.loc.file for e in entries if e.loc), None)
    total = sum(len(e.words) for e in entries)
    addr_w = address_width(total)
    labels = [
        "" if e.loc is None else str(e.loc.line) if e.loc.file == main_file else f"{e.loc.file}:{e.loc.line}"
        for e in entries
    ]
    line_w = max([len("; line"), *map(len, labels)])
    title = f"; rend3r listing of {main_file}" if main_file else "; rend3r listing"
    rows = [
        f"{title}: {count_words(total)}",
        f"; {'line':>{line_w - 2}} | {'addr':<{addr_w}} | {'word(s)':<{_WORDS_WIDTH}} | source",
    ]
    address = 0
    for entry, label in zip(entries, labels):
        if entry.address != address:
            raise ValueError(f"entry at {entry.loc} claims address {entry.address}, expected {address}")
        chunks = [entry.words[i : i + WORDS_PER_ROW] for i in range(0, len(entry.words), WORDS_PER_ROW)] or [()]
        for k, chunk in enumerate(chunks):
            cells = " ".join(f"{w:08x}" for w in chunk)
            source = entry.text.strip() if k == 0 else ""
            row = f"{label if k == 0 else '':>{line_w}} | {address:0{addr_w}x} | {cells:<{_WORDS_WIDTH}} | {source}"
            rows.append(row.rstrip())
            address += len(chunk)
    return ("\n".join(rows) + "\n").encode("utf-8")


_HEX = re.compile(r"[0-9A-Fa-f]+")
#: A well-formed row (the common case); anything else goes through the checks that
#: find the position of the problem.
_ROW = re.compile(r"[^|]*\|\s*([0-9A-Fa-f]+)\s*\|((?:\s*[0-9A-Fa-f]{1,8}(?![0-9A-Fa-f]))*\s*)(?:\||$)")
#: Longer lines skip ``_ROW``, whose repetition would hold state per word of the line.
_FAST_ROW = 1024
_TOKEN = re.compile(r"\S+")


def read_lst(data: bytes, name: str) -> list[int]:
    """The word column of a listing; each row's address must follow the words before it."""
    src = TextInput(data, name, "lst")
    words: list[int] = []
    for pos, line in src.lines():
        stripped = line.strip()
        if not stripped or stripped.startswith(";"):
            continue
        m = _ROW.match(line) if len(line) <= _FAST_ROW else None
        if m and int(m.group(1), 16) == len(words):
            words.extend(int(w, 16) for w in m.group(2).split())
            if len(words) > MAX_WORDS:
                raise src.error(pos, f"more than {MAX_WORDS:,} words")
            continue
        cells = line.split("|", 3)
        if len(cells) < 3:
            raise src.error(pos, "expected 'line | address | word(s) | source'")
        addr_pos = pos + len(cells[0]) + 1
        words_pos = addr_pos + len(cells[1]) + 1
        address = _hex_cell(src, cells[1], addr_pos, "address")
        if address is None:
            raise src.error(addr_pos, "missing address")
        if address != len(words):
            raise src.error(addr_pos, f"address {shown(f'{address:x}')} out of sequence (expected {len(words):x})")
        for t in _TOKEN.finditer(cells[2]):
            value = _hex_cell(src, t.group(), words_pos + t.start(), "word") or 0
            if value >= WORD_LIMIT:
                raise src.error(words_pos + t.start(), f"word {shown(t.group())} is over 32 bits")
            if len(words) == MAX_WORDS:
                raise src.error(words_pos + t.start(), f"more than {MAX_WORDS:,} words")
            words.append(value)
    if not words:
        raise src.error(0, "no words in listing")
    return words


def _hex_cell(src: TextInput, cell: str, pos: int, what: str) -> int | None:
    """A hex number with optional surrounding spaces; None for an empty cell."""
    text = cell.strip()
    if not text:
        return None
    start = pos + len(cell) - len(cell.lstrip())
    m = _HEX.match(text)
    end = m.end() if m else 0
    if end < len(text):
        raise src.error(start + end, f"bad hex digit {text[end]!r} in {what}")
    return int(text, 16)
