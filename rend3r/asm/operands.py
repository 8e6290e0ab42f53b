"""Instruction encoding: a parsed instruction's operands checked against
:mod:`rend3r.isa.tables` and turned into its words.

The :class:`OperandEncoder` reports problems and evaluates expressions through its
:class:`Host` (the running assembler), which also tells it the target and the mnemonics
enabled so far. It keeps the state of the hybrid extension's table selection (``ts``).
"""

from __future__ import annotations

import difflib
import re
from fractions import Fraction
from typing import Mapping, Protocol

from ..isa.encoding import CameraSet, FrameOp, LightSet, ShapeSet, encode
from ..isa.extensions import EXTENSIONS, table_select_word
from ..isa.float16 import Rounded, float_to_bits, round_literal, shortest_repr
from ..isa.tables import (
    F_MNEMONICS,
    LIGHT_INDEX_LIMIT,
    MNEMONIC_TABLE,
    ORIGINAL_NAMES,
    PROPERTIES,
    SHAPE_INDEX_LIMIT,
    Property,
    Table,
    ValueType,
    lookup,
)
from ..isa.targets import Target
from .expressions import Value, describe
from .fastpath import half_bits
from .parser import Instruction, Operand, Ref

_EXTENSION_OF = {m: name for name, ms in EXTENSIONS.items() for m in ms}
#: ``ts`` operand -> the table it selects
TS_TABLES = {"shape": Table.SHAPE, "triangle": Table.TRIANGLE}
#: each table mnemonic's operands, as a message names them
OPERANDS = {"cam": "PROP, VALUE", "lt": "INDEX, PROP, VALUE", "sp": "INDEX, PROP, PROP2, VALUE, VALUE2"}
OPERANDS["tr"] = OPERANDS["sp"]
#: the SE/SD mnemonics, whose table TS selects under the hybrid extension
PAIRS = ("sp", "tr")
_REGISTER = re.compile(r"a(\d+)", re.IGNORECASE)


class Host(Protocol):
    """What the encoder needs from the assembler running it."""

    target: Target | None
    #: mnemonic -> the target's slots for its table (None without a target)
    limits: Mapping[str, int] | None
    #: the base mnemonics and those of the enabled ISA extensions
    mnemonic_names: tuple[str, ...]

    def error(self, message: str, col: int = 1, end: int = 0) -> None: ...

    def warning(self, message: str, col: int = 1, end: int = 0) -> None: ...

    def evaluate(self, node: Operand) -> Value | None: ...

    def integer(self, node: Operand, what: str, lo: int, limit: int) -> int | None: ...

    def source(self, node: Operand) -> str: ...


def find_property(table: Table, name: str) -> Property | None:
    """The property ``name`` (any of its names, or an original assembler's name) of ``table``."""
    return lookup(table, name) or ORIGINAL_NAMES[table].get(name.lower())


class OperandEncoder:
    """Encodes the instructions of one assembler run."""

    def __init__(self, host: Host) -> None:
        self.host = host
        self.rounded: dict[tuple[int | Fraction, bool], Rounded] = {}  # round_literal cache
        self.selected = Table.SHAPE  # the table the last ts selected (a program starts with the shape table)
        self.ts_seen = False
        self.selection_warned = False  # a mismatch was reported since the last ts

    def instruction(self, stmt: Instruction) -> tuple[int, ...] | None:
        """The words of ``stmt``, or None after reporting why there are none."""
        host = self.host
        m = stmt.mnemonic.lower()
        ops = stmt.operands
        if m in F_MNEMONICS:
            if ops:
                host.error(f"'{m}' takes no operands", ops[0].col, ops[-1].end)
                return None
            return encode(FrameOp(F_MNEMONICS[m]))
        table = MNEMONIC_TABLE.get(m)
        if table is None:
            if m in host.mnemonic_names:
                return self.table_select(stmt)
            if m in _EXTENSION_OF:
                ext = _EXTENSION_OF[m]
                host.error(f"unknown mnemonic '{stmt.mnemonic}': it belongs to the {ext} ISA extension; "
                           f"enable it with '.isa_ext {ext}' in the source (or --isa-ext {ext})", stmt.col, stmt.end)
            else:
                close = difflib.get_close_matches(m, host.mnemonic_names, n=1)
                hint = f"; did you mean '{close[0]}'?" if close else ""
                host.error(f"unknown mnemonic '{stmt.mnemonic}'{hint}", stmt.col, stmt.end)
            return None
        expected = OPERANDS[m].count(",") + 1
        if len(ops) != expected:
            end = ops[-1].end if ops else stmt.end
            host.error(f"'{m}' takes {expected} operands ({OPERANDS[m]}), got {len(ops)}", stmt.col, end)
            return None
        if m == "cam":
            prop = self.prop(table, ops[0])
            data = self.data(prop, ops[1])
            return None if data is None else encode(CameraSet(prop.index, data))
        index_limit = LIGHT_INDEX_LIMIT if m == "lt" else SHAPE_INDEX_LIMIT
        index = host.integer(ops[0], f"{table.value} index", 0, index_limit)
        if index is not None:
            self.target_index(m, table, index, ops[0])
        if m == "lt":
            prop = self.prop(table, ops[1])
            data = self.data(prop, ops[2])
            if index is None or data is None:
                return None
            return encode(LightSet(index, prop.index, data))
        prop, prop2 = self.prop(table, ops[1]), self.prop(table, ops[2])
        data = self.data(prop, ops[3])
        data2 = self.data(prop2, ops[4])
        if prop and prop2 and prop.index == prop2.index and prop.vtype is not ValueType.ZERO:
            host.warning(
                f"prop and prop2 are both '{prop.name}': the device writes both and the second value wins",
                ops[1].col,
                ops[2].end,
            )
        if index is None or data is None or data2 is None:
            return None
        return encode(ShapeSet(index, prop.index, prop2.index, data, data2))

    def table_select(self, stmt: Instruction) -> tuple[int, ...] | None:
        """``ts shape`` / ``ts triangle`` (hybrid extension): one TS word."""
        host = self.host
        ops = stmt.operands
        if len(ops) != 1:
            end = ops[-1].end if ops else stmt.end
            host.error(f"'ts' takes one operand (shape or triangle), got {len(ops)}", stmt.col, end)
            return None
        node = ops[0]
        name = node.name.lower() if isinstance(node, Ref) else ""
        if name not in TS_TABLES:
            close = difflib.get_close_matches(name, TS_TABLES, n=1)
            hint = f"; did you mean '{close[0]}'?" if close else ""
            host.error(f"'ts' selects 'shape' or 'triangle', not '{host.source(node)}'{hint}", node.col, node.end)
            return None
        self.selected = TS_TABLES[name]
        self.ts_seen = True
        self.selection_warned = False
        return (table_select_word(self.selected),)

    def selection_warning(self, mnemonic: str) -> str | None:
        """Under the hybrid extension, the warning (once per ts) for an sp/tr pair that
        writes the table the last ``ts`` selected rather than the one its mnemonic names."""
        table = MNEMONIC_TABLE[mnemonic]
        if table is self.selected or self.selection_warned:
            return None
        self.selection_warned = True
        why = "the last 'ts' selected it" if self.ts_seen else "a hybrid program starts with it selected"
        return f"'{mnemonic}' writes the {self.selected.value} table here ({why}); put 'ts {table.value}' before it"

    def target_index(self, m: str, table: Table, index: int, node: Operand) -> None:
        host = self.host
        if host.limits and index >= host.limits[m]:
            size = host.limits[m]
            host.warning(
                f"{table.value} index {index} is beyond {host.target.name}'s {size} {table.value} slots "
                f"(the device aliases it to {index % size})",
                node.col,
                node.end,
            )

    def prop(self, table: Table, node: Operand) -> Property | None:
        host = self.host
        if not isinstance(node, Ref):
            host.error(f"expected a {table.value} property name, got '{host.source(node)}'", node.col, node.end)
            return None
        prop = find_property(table, node.name)
        if prop is not None:
            return prop
        reg = _REGISTER.fullmatch(node.name)
        if reg:
            named = [n for n, p in ORIGINAL_NAMES[table].items() if p.index == int(reg.group(1))]
            hint = f" (its unused slot {reg.group(1)} is named '{named[0]}')" if named else ""
            host.error(f"the {table.value} table has no property {reg.group(1)}{hint}", node.col, node.end)
            return None
        names = [n for p in PROPERTIES[table] for n in (p.name, *p.extra_names)]
        close = difflib.get_close_matches(node.name.lower(), names, n=1)
        hint = f"; did you mean '{close[0]}'?" if close else ""
        host.error(f"unknown {table.value} property '{node.name}'{hint}", node.col, node.end)
        return None

    def data(self, prop: Property | None, node: Operand) -> int | None:
        """The 16 data bits for ``prop`` from ``node``, or None after reporting why not
        (with no property, only the expression itself is checked)."""
        host = self.host
        v = host.evaluate(node)
        if v is None or prop is None:
            return None
        if v.raw is not None:
            return v.raw
        src = host.source(node)
        if prop.vtype is ValueType.FLOAT16:
            return self.float_bits(prop, v, node, src)
        bits = prop.bits if prop.vtype is ValueType.INT else 16
        what = f"'{prop.name}'" if prop.vtype is ValueType.INT else "the zero property"
        if not v.is_integer:
            host.error(f"{what} takes an integer or 0h raw bits, got {src}", node.col, node.end)
            return None
        if not 0 <= v.number < (1 << bits):
            shown = src if src == describe(v.number) else f"{src} = {describe(v.number)}"
            host.error(
                f"{shown} is out of range for {what} ({bits} bits: 0..{(1 << bits) - 1})",
                node.col,
                node.end,
            )
            return None
        return v.number

    def float_bits(self, prop: Property, v: Value, node: Operand, src: str) -> int | None:
        """float16 bits of ``v`` as the original assembler gave them, with a warning where
        the source likely meant something else."""
        host = self.host
        number = v.number
        if type(number) is float:  # inf or nan, written as such
            return float_to_bits(number)
        if v.literal and 0x8000 <= number <= 0xFFFF:
            number -= 0x10000
            host.warning(
                f"{src} is read as the signed 16-bit integer {number} for float16 property '{prop.name}' "
                f"(as the original assembler did); write 0h{v.number:04x} for raw bits",
                node.col,
                node.end,
            )
        elif v.literal == "hex" and number <= 0xFFFF:
            host.warning(
                f"{src} is the integer {describe(number)} for float16 property '{prop.name}'; "
                f"write 0h{src[2:].replace('_', '').lower()} for raw bits",
                node.col,
                node.end,
            )
        if number and not v.negative_zero:
            try:
                bits = half_bits(float(number))  # quick when no diagnostic can follow
            except OverflowError:
                bits = None
            if bits is not None:
                return bits
        key = (number, v.negative_zero)
        r = self.rounded.get(key)
        if r is None:
            r = self.rounded[key] = round_literal(number, negative=v.negative_zero)
        if r.overflow:
            host.warning(f"{src} overflows float16 to {'-' if number < 0 else ''}infinity (magnitudes of 65520 "
                         f"and above do; the largest finite is 65504); write inf if infinity is meant",
                         node.col, node.end)
        elif r.underflow:
            host.warning(f"{src} underflows to zero in float16 (smallest subnormal is 2^-24, about 5.96e-08)",
                         node.col, node.end)
        elif r.relative_error > 0.01:
            host.warning(f"{src} rounds to {shortest_repr(r.bits)} in float16 ({r.relative_error:.1%} off)",
                         node.col, node.end)
        return r.bits
