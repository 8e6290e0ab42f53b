"""Disassembler: 32-bit words to canonical rend3r assembly (see ``docs/isa.md``).

Every word stream disassembles to source that assembles back to the same words: words
that decode to nothing become ``.word`` directives with a comment giving the reason.
With the hybrid ISA extension (``isa_ext="hybrid"``), TS words print as ``ts shape`` /
``ts triangle`` and name the following SE/SD pairs ``sp`` / ``tr``.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from functools import lru_cache

from ..isa.encoding import is_canonical
from ..isa.extensions import EXTENSIONS, TS_OPCODE, TS_TABLE, decode_table_select
from ..isa.float16 import bits_to_float, is_subnormal, round_literal, shortest_repr
from ..isa.tables import (
    DATA,
    F_MNEMONICS,
    FUNC,
    LIGHT_INDEX,
    OPCODE,
    PROP,
    SD_DATA,
    SD_DATA2,
    SE_INDEX_HI,
    SE_INDEX_LO,
    SE_PROP2,
    Func,
    Opcode,
    Property,
    Table,
    ValueType,
    by_index,
)
from .formats.common import address_width, count_words
from .program import Emitted, Program

#: mode -> (shape mnemonic, the table its property operands name)
MODES: dict[str, tuple[str, Table]] = {"raytrace": ("sp", Table.SHAPE), "raster": ("tr", Table.TRIANGLE)}
#: ISA extensions the disassembler prints (named as the assembler's ``.isa_ext`` names them)
ISA_EXTENSIONS = tuple(EXTENSIONS)
_PAIR_MNEMONIC = {table: mnemonic for mnemonic, table in MODES.values()}

_F_NAMES = {func: name for name, func in F_MNEMONICS.items()}
_COMMENT_COLUMN = 40
#: The assembler warns when a float literal loses more than this share of its value
#: (syntax.md); disassembled floats stay within it.
LOSS_WARNING = 0.01


@dataclass(frozen=True)
class Line:
    """One line of disassembly: the word(s) it stands for and its source text."""

    address: int
    words: tuple[int, ...]
    text: str
    note: str = ""  # why a .word line is not an instruction


def format_value(prop: Property, bits: int) -> str:
    """A 16-bit field as the canonical operand for ``prop``."""
    if prop.vtype is ValueType.ZERO:
        return "0" if bits == 0 else f"0h{bits:04x}"
    if prop.vtype is ValueType.FLOAT16:
        return float_operand(bits)
    if bits >> prop.bits:
        return f"0h{bits:04x}"
    if prop.name == "col":
        return f"0b{bits >> 11:05b}_{(bits >> 5) & 0x3F:06b}_{bits & 0x1F:05b}"
    return str(bits)


@lru_cache(maxsize=None)
def float_operand(bits: int) -> str:
    """The shortest decimal that rounds back to ``bits`` without the assembler's
    precision warning; ``0hXXXX`` for NaN and infinities.

    For most values that is ``shortest_repr``. For small subnormals the shortest
    round-tripping decimal can be far from the value (``1.0e-07`` for 0x0002, which is
    1.19e-07, 19% off), so more digits are used until it is within the warning threshold.
    """
    text = shortest_repr(bits)
    if text is None:
        return f"0h{bits:04x}"
    if not is_subnormal(bits):
        # A normal value's shortest decimal lies within half an ulp: under 2**-11 off.
        return text
    digits = 1
    while _loss(text) > LOSS_WARNING:
        digits += 1
        mantissa, exp = f"{bits_to_float(bits):.{digits}e}".split("e")
        mantissa = mantissa.rstrip("0")
        text = f"{mantissa}{'0' if mantissa.endswith('.') else ''}e{exp}"
    return text


def _loss(text: str) -> float:
    return round_literal(text.lstrip("-"), negative=text.startswith("-")).relative_error


def _word(address: int, word: int, note: str) -> Line:
    return Line(address, (word,), f".word 0x{word:08x}", note)


def _single(address: int, word: int) -> Line:
    """A one-word instruction (F, C or L), or a .word saying why it is none."""
    op = OPCODE.get(word)
    if op == Opcode.F:
        if not is_canonical(word):
            return _word(address, word, "F-type with nonzero reserved bits")
        return Line(address, (word,), _F_NAMES[Func(FUNC.get(word))])
    if op == Opcode.C:
        if not is_canonical(word):
            return _word(address, word, "C-type with nonzero reserved bits 10:3")
        prop = by_index(Table.CAMERA).get(PROP.get(word))
        if prop is None:
            return _word(address, word, f"camera property {PROP.get(word)} does not exist")
        return Line(address, (word,), f"cam {prop.name}, {format_value(prop, DATA.get(word))}")
    if op == Opcode.L:
        if not is_canonical(word):
            return _word(address, word, "L-type with nonzero reserved bits 10:9")
        prop = by_index(Table.LIGHT).get(PROP.get(word))
        if prop is None:
            return _word(address, word, f"light property {PROP.get(word)} does not exist")
        value = format_value(prop, DATA.get(word))
        return Line(address, (word,), f"lt {LIGHT_INDEX.get(word)}, {prop.name}, {value}")
    if op == 0b100:
        return _word(address, word, "reserved opcode 100 (shape init, never defined)")
    return _word(address, word, f"unused opcode {op:03b}")


def _table_select(address: int, word: int) -> Line:
    """An opcode-010 word under the hybrid extension: ``ts TABLE``, or a .word saying why not."""
    table = decode_table_select(word)
    if table is not None:
        return Line(address, (word,), f"ts {table.value}")
    if word >> (TS_TABLE.hi + 1):
        return _word(address, word, "opcode 010 with nonzero bits 31:5 (not a TS word)")
    return _word(address, word, f"opcode 010 with reserved table code {TS_TABLE.get(word):02b} (not a TS word)")


def _pair(address: int, se: int, sd: int, table: Table) -> list[Line]:
    """An SE/SD pair as one sp/tr line, or as two .word lines when a property is missing."""
    mnemonic = _PAIR_MNEMONIC[table]
    props = by_index(table)
    prop, prop2 = props.get(PROP.get(se)), props.get(SE_PROP2.get(se))
    if prop is None or prop2 is None:
        missing = PROP.get(se) if prop is None else SE_PROP2.get(se)
        return [
            _word(address, se, f"SE names {table.value} property {missing}, which does not exist"),
            _word(address + 1, sd, "SD of the SE above"),
        ]
    index = (SE_INDEX_HI.get(se) << 3) | SE_INDEX_LO.get(se)
    v1, v2 = format_value(prop, SD_DATA.get(sd)), format_value(prop2, SD_DATA2.get(sd))
    return [Line(address, (se, sd), f"{mnemonic} {index}, {prop.name}, {prop2.name}, {v1}, {v2}")]


def _is_hybrid(mode: str, isa_ext: str | Iterable[str] | None) -> bool:
    """Whether the hybrid extension applies; ValueError for an unknown mode or extension,
    or raster mode with it (a hybrid program starts with the shape table selected)."""
    if mode not in MODES:
        raise ValueError(f"unknown mode {mode!r}; expected one of {', '.join(MODES)}")
    names = {isa_ext.lower()} if isinstance(isa_ext, str) else {n.lower() for n in isa_ext or ()}
    unknown = names - set(ISA_EXTENSIONS)
    if unknown:
        raise ValueError(f"unknown ISA extension {sorted(unknown)[0]!r}; expected one of {', '.join(ISA_EXTENSIONS)}")
    if "hybrid" in names and mode != "raytrace":
        raise ValueError(f"{mode} mode does not apply with the hybrid extension: a program starts with the shape "
                         "table selected and ts words choose the table")
    return "hybrid" in names


def disassemble_lines(words: list[int], mode: str = "raytrace", isa_ext: str | Iterable[str] | None = ()) -> list[Line]:
    """Decode ``words`` as the device does (an SE always takes the next word as its SD).

    Under the hybrid extension (``isa_ext="hybrid"``) a TS word selects the table (and so
    the mnemonic and property names) of the SE/SD pairs after it.
    """
    hybrid = _is_hybrid(mode, isa_ext)
    table = MODES[mode][1]
    lines: list[Line] = []
    address = 0
    while address < len(words):
        word = words[address]
        if not 0 <= word < 1 << 32:
            raise ValueError(f"word {word} at address {address} is not a 32-bit value")
        op = OPCODE.get(word)
        if op == Opcode.SE:
            if address + 1 == len(words):
                lines.append(_word(address, word, "SE with no SD at the end"))
                break
            lines.extend(_pair(address, word, words[address + 1], table))
            address += 2
            continue
        if hybrid and op == TS_OPCODE:
            lines.append(_table_select(address, word))
            table = decode_table_select(word) or table
        else:
            lines.append(_single(address, word))
        address += 1
    return lines


def disassemble_program(words: list[int], mode: str = "raytrace", isa_ext: str | Iterable[str] | None = ()) -> Program:
    """The disassembly as a Program (no source positions), e.g. for a listing."""
    lines = disassemble_lines(words, mode, isa_ext)
    return Program([Emitted(line.address, line.words, None, _with_note(line.text, line.note)) for line in lines])


def disassemble(words: list[int], mode: str = "raytrace", addresses: bool = False,
                isa_ext: str | Iterable[str] | None = ()) -> str:
    """Canonical source for ``words``: a header comment, then one statement per line.

    ``addresses`` adds each statement's word address (hex) as a trailing comment.
    ``isa_ext="hybrid"`` prints TS words as ``ts`` (see :func:`disassemble_lines`) after an
    ``.isa_ext hybrid`` line, so the source assembles without a flag.
    """
    lines = disassemble_lines(words, mode, isa_ext)
    width = address_width(len(words))
    if _is_hybrid(mode, isa_ext):
        out = [f"; rend3r disassembly: {count_words(len(words))}, hybrid ISA extension "
               "(ts selects the table: sp names shape properties, tr triangle ones)", ".isa_ext hybrid"]
    else:
        mnemonic, table = MODES[mode]
        out = [f"; rend3r disassembly: {count_words(len(words))}, {mode} mode ({mnemonic} names {table.value} properties)"]
    for line in lines:
        if addresses:
            comment = f"@{line.address:0{width}x} {line.note}".rstrip()
            out.append(f"{line.text:<{_COMMENT_COLUMN - 1}} ; {comment}")
        else:
            out.append(_with_note(line.text, line.note))
    return "\n".join(out) + "\n"


def _with_note(text: str, note: str) -> str:
    return f"{text}  ; {note}" if note else text
