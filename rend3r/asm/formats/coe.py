"""``coe``: Xilinx memory coefficient file (``memory_initialization_radix=16;
memory_initialization_vector=...;``), one 8-digit hex word per line."""

from __future__ import annotations

import re

from ...errors import Rend3rError
from ..program import Program
from .common import MAX_WORDS, WORD_LIMIT, TextInput, count_words, shown

RADIX_KEY = "memory_initialization_radix"
VECTOR_KEY = "memory_initialization_vector"
_RADIX_DIGITS = {2: "01", 10: "0123456789", 16: "0123456789abcdefABCDEF"}
#: Most significant digits a value below 2**32 has in each radix: longer values are
#: refused before conversion (Python refuses to convert over 4,300 decimal digits).
_MAX_DIGITS = {2: 32, 10: 10, 16: 8}
_NOT_DIGIT = {radix: re.compile(f"[^{digits}]") for radix, digits in _RADIX_DIGITS.items()}


def render_coe(program: Program) -> bytes:
    words = program.words
    if not words:
        raise Rend3rError("coe: a memory initialization vector cannot be empty")
    body = ",\n".join(f"{w:08x}" for w in words)
    return (
        f"; rend3r: {count_words(len(words))} of 32 bits\n{RADIX_KEY}=16;\n{VECTOR_KEY}=\n{body};\n"
    ).encode("ascii")


_STATEMENT_START = re.compile(r"[^\s;]")
_COMMENT = re.compile(r"^[^\S\n]*;[^\n]*", re.M)
_STATEMENT = re.compile(r"\s*([A-Za-z_][A-Za-z0-9_]*)\s*=", re.S)
_VECTOR_TOKEN = re.compile(r"(?P<value>[^\s,]+)|(?P<comma>,)|(?P<ws>\s+)")


def read_coe(data: bytes, name: str) -> list[int]:
    """Words of a COE file: ``;`` at the start of a line begins a comment; statements are
    ``keyword=value;``; radix 2, 10 or 16 (given before the vector); values separated by
    commas or whitespace."""
    src = TextInput(data, name, "coe")
    text = _blank_comments(src.text)
    radix: int | None = None
    words: list[int] | None = None
    pos = 0
    while True:
        first = _STATEMENT_START.search(text, pos)  # past blanks and empty statements (';;')
        if first is None:
            break
        pos = first.start()
        end = text.find(";", pos)
        if end < 0:
            raise src.error(pos, "statement not ended by ';'")
        m = _STATEMENT.match(text, pos, end)
        if not m:
            raise src.error(pos, "expected 'keyword=value;'")
        key = m.group(1).lower()
        if key == RADIX_KEY:
            if radix is not None:
                raise src.error(m.start(1), f"{RADIX_KEY} given twice")
            radix = _read_radix(src, text, m.end(), end)
        elif key == VECTOR_KEY:
            if words is not None:
                raise src.error(m.start(1), f"{VECTOR_KEY} given twice")
            if radix is None:
                raise src.error(m.start(1), f"{VECTOR_KEY} before {RADIX_KEY}")
            words = _read_vector(src, text, m.end(), end, radix)
        else:
            raise src.error(m.start(1), f"unknown keyword {shown(m.group(1))!r} (expected {RADIX_KEY} or {VECTOR_KEY})")
        pos = end + 1
    if words is None:
        raise src.error(len(text), f"no {VECTOR_KEY}")
    return words


def _blank_comments(text: str) -> str:
    """Replace comment lines by spaces, keeping every offset (and so every position)."""
    return _COMMENT.sub(lambda m: " " * len(m.group()), text)


def _read_radix(src: TextInput, text: str, start: int, end: int) -> int:
    value = text[start:end].strip()
    if value not in ("2", "10", "16"):
        at = start + len(text[start:end]) - len(text[start:end].lstrip())
        raise src.error(at, f"unsupported radix {shown(value)!r} (expected 2, 10 or 16)")
    return int(value)


def _read_vector(src: TextInput, text: str, start: int, end: int, radix: int) -> list[int]:
    words: list[int] = []
    expect_value = True  # after '=' or ','
    last_comma = start
    for m in _VECTOR_TOKEN.finditer(text, start, end):
        if m.lastgroup == "comma":
            if expect_value:
                raise src.error(m.start(), "empty value before ','")
            expect_value, last_comma = True, m.start()
        elif m.lastgroup == "value":
            words.append(_parse_value(src, m.group(), m.start(), radix))
            if len(words) > MAX_WORDS:
                raise src.error(m.start(), f"more than {MAX_WORDS:,} words")
            expect_value = False
    if not words:
        raise src.error(end, "empty memory_initialization_vector")
    if expect_value:
        raise src.error(last_comma, "trailing ',' before ';'")
    return words


def _parse_value(src: TextInput, token: str, pos: int, radix: int) -> int:
    bad = _NOT_DIGIT[radix].search(token)
    if bad is not None:
        raise src.error(pos + bad.start(), f"bad radix-{radix} digit {bad.group()!r}")
    if len(token.lstrip("0")) > _MAX_DIGITS[radix] or int(token, radix) >= WORD_LIMIT:
        raise src.error(pos, f"value {shown(token)} is over 32 bits")
    return int(token, radix)
