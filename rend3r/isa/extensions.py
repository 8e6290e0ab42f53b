"""ISA extension ``TS`` (table select) for hybrid frames: see ``docs/isa-extensions.md``.

One word, opcode 0b010 (decoded by the original device as unsupported, i.e. a no-op),
bits 4:3 naming the table that following SE/SD pairs write, every other bit zero.
Base programs never contain it, so they stay bit-identical; only ``--mode hybrid``
accepts it.
"""

from __future__ import annotations

from .tables import Field, Table

#: Extension name -> the mnemonics it adds (what ``--isa-ext`` / ``.isa_ext`` enable).
EXTENSIONS: dict[str, tuple[str, ...]] = {"hybrid": ("ts",)}

TS_OPCODE = 0b010
TS_TABLE = Field(4, 3)
#: Table codes of TS; 0b11 is reserved.
TS_CODES: dict[int, Table] = {0b01: Table.SHAPE, 0b10: Table.TRIANGLE}
_TS_ZERO_MASK = 0xFFFFFFFF & ~(TS_TABLE.mask | 0b111)


def table_select_word(table: Table) -> int:
    """The TS word selecting ``table`` (SHAPE or TRIANGLE)."""
    code = {t: c for c, t in TS_CODES.items()}[table]
    return TS_TABLE.put(code) | TS_OPCODE


def decode_table_select(word: int) -> Table | None:
    """The table a TS word selects, or None if ``word`` is not a canonical TS word."""
    if word & 0b111 != TS_OPCODE or word & _TS_ZERO_MASK:
        return None
    return TS_CODES.get(TS_TABLE.get(word))
