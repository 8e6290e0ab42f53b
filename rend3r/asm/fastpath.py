"""A regular-expression fast path for the lines most programs are made of.

A line that is blank, a comment, one instruction whose operands are plain literals
(decimal, exponent, 0x, 0b or 0h numbers; property names) or a ``.word`` of one plain
0x or decimal literal (the disassembler's form) is encoded here directly,
without the Lark parser. Anything else, and any line that would produce a diagnostic
(a value out of range, a rounding warning, an SE with prop == prop2, an index beyond the
target), returns None and goes through the full parser, which is the definition of the
language. Property tests check that both paths agree: ``tests/asm/test_fuzz.py``
(``test_fast_path_agrees_with_grammar``, ``test_fast_word_agrees_with_grammar``,
``test_fast_rounding_is_exact``) and ``tests/asm/test_isa_ext.py`` (under the extension).
"""

from __future__ import annotations

import math
import re
import struct
from fractions import Fraction

from ..isa.encoding import FrameOp, encode
from ..isa.float16 import round_literal
from ..isa.tables import (
    DATA,
    F_MNEMONICS,
    LIGHT_INDEX,
    LIGHT_INDEX_LIMIT,
    MNEMONIC_TABLE,
    OPCODE,
    PROP,
    SD_DATA,
    SD_DATA2,
    SE_INDEX_HI,
    SE_INDEX_LO,
    SE_PROP2,
    SHAPE_INDEX_LIMIT,
    Opcode,
    ValueType,
    lookup,
)

_WS = r"[ \t\f\v\r]"
_NAME = r"[A-Za-z_][A-Za-z0-9_]*"
# Bounded digit counts keep exact rounding cheap; longer literals take the full parser.
_VAL = r"-?(?:\d{1,30}(?:\.\d{0,30})?|\.\d{1,30})(?:[eE][+-]?\d{1,3})?|0[xX][0-9a-fA-F]{1,8}(?:_[0-9a-fA-F]{1,8}){0,3}|0[bB][01]{1,32}(?:_[01]{1,32}){0,15}|0[hH][0-9a-fA-F]{1,4}"
_SEP = rf"{_WS}*,{_WS}*"
_LINE = re.compile(
    rf"""{_WS}*(?:
        (?P<f>nr|nf|er|lr)
      | (?P<c>cam){_WS}+(?P<cp>{_NAME}){_SEP}(?P<cv>{_VAL})
      | (?P<l>lt){_WS}+(?P<li>\d{{1,7}}){_SEP}(?P<lp>{_NAME}){_SEP}(?P<lv>{_VAL})
      | (?P<s>sp|tr){_WS}+(?P<si>\d{{1,7}}){_SEP}(?P<sp>{_NAME}){_SEP}(?P<sq>{_NAME}){_SEP}(?P<sv>{_VAL}){_SEP}(?P<sw>{_VAL})
      | (?P<w>\.word){_WS}+(?:0[xX](?P<wx>[0-9a-fA-F]{{1,8}})|(?P<wd>\d{{1,10}}))
    )?{_WS}*(?:(?://|;).*)?""",
    re.IGNORECASE | re.VERBOSE | re.ASCII,
)

_F_WORDS = {m: encode(FrameOp(f))[0] for m, f in F_MNEMONICS.items()}
_C_BASE = OPCODE.put(Opcode.C)
_L_BASE = OPCODE.put(Opcode.L)
_SE_BASE = OPCODE.put(Opcode.SE)

#: literal text -> float16 bits, or None when rounding it needs a diagnostic
_FLOAT_BITS: dict[str, int | None] = {}
_FLOAT_CACHE_LIMIT = 1 << 20
_HALF = struct.Struct("<e")


def clear_cache() -> None:
    """Forget cached literal roundings (benchmarks measure a cold cache)."""
    _FLOAT_BITS.clear()


def _float_bits(text: str) -> int | None:
    bits = _FLOAT_BITS.get(text, -1)
    if bits != -1:
        return bits
    c = text[:2].lower()
    if c == "0x" or c == "0b" and int(text, 2) >= 0x8000:
        bits = None  # a warning follows: 0x literals, and 0b ones read as signed
    elif c == "0h":
        bits = int(text[2:], 16)
    else:
        bits = _round(float(int(text, 2) if c == "0b" else text), text)
    if len(_FLOAT_BITS) >= _FLOAT_CACHE_LIMIT:
        _FLOAT_BITS.clear()
    _FLOAT_BITS[text] = bits
    return bits


def _round(x: float, text: str) -> int | None:
    """float16 bits of the literal ``text`` whose nearest float64 is ``x``; None when
    the literal needs a diagnostic (or is too close to the 1% warning limit to decide
    without exact arithmetic).

    ``float()`` rounds a decimal correctly, and rounding x again to float16 gives the
    correct result unless x is a float16 midpoint: if the exact value and x lay on
    different sides of a midpoint, that midpoint (a float64) would be nearer the exact
    value than x. Midpoints have at most 12 significant bits, so an x that float16
    cannot hold and that has at most 12 significant bits takes the exact path
    (:func:`round_literal`).
    """
    bits = half_bits(x)
    if bits is not None or not _may_be_tie(x):
        return bits
    negative = text.startswith("-")
    body = text[1:] if negative else text
    r = round_literal(int(body, 2) if body[:2].lower() == "0b" else Fraction(body), negative=negative)
    return None if (r.overflow or r.underflow or r.relative_error > 0.01) else r.bits


def half_bits(x: float) -> int | None:
    """float16 bits of ``x``, the correctly rounded float64 of an exact value, or None
    when that value needs the exact path: ``x`` may be a float16 midpoint (see
    :func:`_round`), or the value overflows, underflows or is near the 1% warning."""
    try:
        packed = _HALF.pack(x)
    except OverflowError:
        return None
    back = _HALF.unpack(packed)[0]
    if back != x and (math.frexp(x)[0] * 4096.0).is_integer():
        return None
    if back == 0.0 and x != 0.0 or math.isinf(back) or abs(back - x) > 0.0099 * abs(x):
        return None
    return int.from_bytes(packed, "little")


def _may_be_tie(x: float) -> bool:
    """``x`` is not a float16 and has at most 12 significant bits (a midpoint's)."""
    try:
        back = _HALF.unpack(_HALF.pack(x))[0]
    except OverflowError:
        return False
    return back != x and (math.frexp(x)[0] * 4096.0).is_integer()


def _int_bits(text: str, width: int) -> int | None:
    c = text[:2].lower()
    if c == "0h":
        return int(text[2:], 16)
    if c == "0x" or c == "0b":
        n = int(text, 0)
    elif text.isdigit():
        n = int(text)
    else:
        return None
    return n if n < (1 << width) else None


#: mnemonic -> {name as written -> (property index, field width or 0 for float16) or None}
_PROPS: dict[str, dict[str, tuple[int, int] | None]] = {m: {} for m in MNEMONIC_TABLE}


def _value(mnemonic: str, name: str, text: str) -> tuple[int, int] | None:
    """(property index, 16-bit data) or None."""
    known = _PROPS[mnemonic]
    info = known.get(name, False)
    if info is False:
        prop = lookup(MNEMONIC_TABLE[mnemonic], name)
        if prop is None:
            info = None
        elif prop.vtype is ValueType.FLOAT16:
            info = (prop.index, 0)
        else:
            info = (prop.index, prop.bits if prop.vtype is ValueType.INT else 16)
        known[name] = info
    if info is None:
        return None
    if info[1]:
        bits = _int_bits(text, info[1])
    else:
        bits = _FLOAT_BITS.get(text, -1)
        if bits == -1:
            bits = _float_bits(text)
    return None if bits is None else (info[0], bits)


_DATA = DATA.lo
_PROP = PROP.lo
_LIDX = LIGHT_INDEX.lo
_SEHI = SE_INDEX_HI.lo
_SEP2 = SE_PROP2.lo
_SELO = SE_INDEX_LO.lo
_SD1 = SD_DATA.lo
_SD2 = SD_DATA2.lo


def camera_word(prop: int, data: int) -> int:
    """The C word setting camera property ``prop`` to 16 data bits (fields unchecked)."""
    return data << _DATA | prop << _PROP | _C_BASE


def light_word(index: int, prop: int, data: int) -> int:
    """The L word setting property ``prop`` of light ``index`` (fields unchecked)."""
    return data << _DATA | prop << _PROP | index << _LIDX | _L_BASE


def shape_words(index: int, prop: int, prop2: int, data: int, data2: int) -> tuple[int, int]:
    """The SE and SD words setting two properties of shape or triangle ``index``
    (fields unchecked)."""
    se = (index >> 3) << _SEHI | prop << _PROP | prop2 << _SEP2 | (index & 7) << _SELO | _SE_BASE
    return se, data << _SD1 | data2 << _SD2


def fast_line(text: str, limits: dict[str, int] | None = None) -> tuple | None:
    """Encode a simple line: ``()`` for nothing, ``(mnemonic, words, column)`` for an
    instruction, None when the full parser must handle it.

    ``limits`` maps a mnemonic to the target's table size; an index at or beyond it
    needs a warning, so such lines go to the full parser.
    """
    m = _LINE.fullmatch(text)
    if m is None:
        return None
    f, c, cp, cv, lt, li, lp, lv, s, si, sp, sq, sv, sw, w, wx, wd = m.groups()
    if s:
        mn = s.lower()
        index = int(si)
        pv = _value(mn, sp, sv)
        qw = _value(mn, sq, sw)
        if (
            pv is None
            or qw is None
            or index >= SHAPE_INDEX_LIMIT
            or (pv[0] == qw[0] and pv[0] != 0)
            or (limits and index >= limits[mn])
        ):
            return None
        return mn, shape_words(index, pv[0], qw[0], pv[1], qw[1]), m.start(9) + 1
    if lt:
        index = int(li)
        pv = _value("lt", lp, lv)
        if pv is None or index >= LIGHT_INDEX_LIMIT or (limits and index >= limits["lt"]):
            return None
        return "lt", (light_word(index, pv[0], pv[1]),), m.start(5) + 1
    if c:
        pv = _value("cam", cp, cv)
        if pv is None:
            return None
        return "cam", (camera_word(pv[0], pv[1]),), m.start(2) + 1
    if f:
        mn = f.lower()
        return mn, (_F_WORDS[mn],), m.start(1) + 1
    if w:
        word = int(wx, 16) if wx else int(wd)
        return None if word >> 32 else ("", (word,), m.start(15) + 1)
    return ()
