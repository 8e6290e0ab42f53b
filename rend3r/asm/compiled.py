"""Instructions of a ``.rept`` body compiled once, then run on each iteration's names.

The general path (:meth:`.OperandEncoder.instruction` over :func:`.expressions.evaluate`)
builds a :class:`.Value` per expression node and looks every property up again; a body run
thousands of times spends nearly all its time there. :func:`compile_instruction` turns a
table instruction (``cam``, ``lt``, ``sp``, ``tr``) whose properties are plain names into
one function of the *plain* constants: ints and Fractions of at most PLAIN_BITS bits (no
-0, no raw bits, no 0x/0b literal, no poisoned name). Each expression becomes one Python
lambda over those numbers, with exact division. The function returns the instruction's
words, or None whenever the general path could report something or needs what plain
numbers do not carry (an undefined name, a division by zero, a float16 zero, whose sign
they do not track, a value out of range or not rounded exactly without a warning by
:func:`.fastpath.half_bits`, an index beyond the target), and the assembler then runs
the statement the general way. ``tests/asm/test_compiled.py`` checks that both paths agree.
"""

from __future__ import annotations

from fractions import Fraction
from typing import Callable, Mapping

from ..isa.tables import LIGHT_INDEX_LIMIT, MNEMONIC_TABLE, SHAPE_INDEX_LIMIT, Property, ValueType
from .expressions import POISON, Value
from .fastpath import camera_word, half_bits, light_word, shape_words
from .operands import OPERANDS, find_property
from .parser import MAX_BITS, BinOp, Instruction, Neg, Num, Operand, Ref, Statement

#: Largest plain constant, in bits of numerator plus denominator: with the literals'
#: sizes it bounds every intermediate result, so none can exceed MAX_BITS unchecked.
PLAIN_BITS = 64
#: Deepest expression compiled (Python's parser allows 200 nested parentheses).
MAX_NESTING = 100

Number = int | Fraction
Plain = Mapping[str, Number]
Words = Callable[[Plain], "tuple[int, ...] | None"]


class _General(Exception):
    """The general path must run this statement."""


def plain_number(value: Value) -> Number | None:
    """``value``'s number when a compiled instruction may use it, else None."""
    n = value.number
    if value is POISON or value.raw is not None or value.negative_zero or value.literal or type(n) is float:
        return None
    return n if _size(n) <= PLAIN_BITS else None


def _size(n: Number) -> int:
    """Bits of numerator plus denominator (an int's denominator, 1, counts one)."""
    return n.bit_length() + 1 if type(n) is int else n.numerator.bit_length() + n.denominator.bit_length()


def _div(x: Number, y: Number) -> Number:
    """``x / y`` exactly (ZeroDivisionError when ``y`` is 0), as :func:`.expressions.evaluate` does it."""
    if type(x) is int and type(y) is int:
        q, rem = divmod(x, y)
        return q if not rem else Fraction(x, y)
    return x / y


def _expr(node: Operand) -> Callable[[Plain], Number] | None:
    """A function computing ``node``'s number from plain constants (KeyError: a name that
    is not one; ZeroDivisionError), or None when it cannot be compiled: a literal that
    needs a diagnostic, nesting beyond MAX_NESTING, or operands whose sizes could add up
    beyond MAX_BITS (the general path reports that error).

    The numbers are the exact evaluator's, but the sign of a zero is not tracked: a zero
    result may be -0 (see :func:`plain_float16`)."""
    consts: list[Number] = []
    size = 0

    def source(node: Operand) -> str | None:
        nonlocal size
        cls = type(node)
        if cls is Num:
            if node.error or node.kind == "raw" or node.negative_zero:
                return None
            consts.append(node.value)
            size += _size(node.value)
            return f"c[{len(consts) - 1}]"
        if cls is Ref:
            size += PLAIN_BITS
            return f"p[{node.name!r}]"
        if cls is Neg:
            inner = source(node.operand)
            return None if inner is None else f"(-{inner})"
        if cls is BinOp:
            left, right = source(node.left), source(node.right)
            if left is None or right is None:
                return None
            size += 1
            return f"_div({left}, {right})" if node.op == "/" else f"({left} {node.op} {right})"
        return None

    if getattr(node, "depth", 0) > MAX_NESTING:
        return None
    text = source(node)
    if text is None or size > MAX_BITS:
        return None
    return eval(f"lambda p: {text}", {"c": tuple(consts), "_div": _div})  # names are identifiers


def _integer(node: Operand, limit: int) -> Callable[[Plain], int] | None:
    """An integer operand in [0, limit) (an integer zero's sign does not matter)."""
    f = _expr(node)
    if f is None:
        return None

    def value(p: Plain) -> int:
        x = f(p)
        if type(x) is Fraction and x.denominator == 1:
            x = x.numerator
        if type(x) is not int or not 0 <= x < limit:
            raise _General
        return x

    return value


def plain_float16(x: Number) -> int:
    """float16 bits of a non-zero plain number when no warning can follow (see
    :func:`.fastpath.half_bits`); _General otherwise, and for a zero, which may be -0."""
    try:
        bits = half_bits(float(x)) if x else None
    except OverflowError:
        bits = None
    if bits is None:
        raise _General
    return bits


def _data(prop: Property, node: Operand) -> Callable[[Plain], int] | None:
    """The 16 data bits of ``prop`` from ``node`` (see :meth:`.OperandEncoder.data`)."""
    if type(node) is Num and not node.error and (node.kind == "raw" or prop.vtype is ValueType.FLOAT16):
        if node.kind in ("hex", "bin"):
            return None  # a float16 from such a literal may come with a warning
        try:
            bits = node.value if node.kind == "raw" else 0 if not node.value and not node.negative_zero \
                else plain_float16(node.value)
        except _General:
            return None
        return lambda p: bits
    if prop.vtype is not ValueType.FLOAT16:
        return _integer(node, 1 << (prop.bits if prop.vtype is ValueType.INT else 16))
    f = _expr(node)
    if f is None:
        return None
    return lambda p: plain_float16(f(p))


#: mnemonic -> the positions of its property operands and of their values
_LAYOUT = {"cam": ((0,), (1,)), "lt": ((1,), (2,)), "sp": ((1, 2), (3, 4)), "tr": ((1, 2), (3, 4))}


def compile_instruction(stmt: Statement, limits: Mapping[str, int] | None) -> Words | None:
    """``stmt`` as a function of the plain constants returning its words (None: run the
    general path this time), or None when it cannot be compiled (not a table instruction,
    a property that needs a diagnostic, a 0x or 0b literal for a float16, ...). ``limits``
    are the target's table sizes (an index at or beyond one needs a warning)."""
    if not isinstance(stmt, Instruction):
        return None
    m = stmt.mnemonic.lower()
    table = MNEMONIC_TABLE.get(m)
    ops = stmt.operands
    if table is None or len(ops) != OPERANDS[m].count(",") + 1:
        return None
    prop_at, data_at = _LAYOUT[m]
    props = [find_property(table, ops[i].name) if type(ops[i]) is Ref else None for i in prop_at]
    if None in props or len(props) == 2 and props[0].index == props[1].index and props[0].vtype is not ValueType.ZERO:
        return None  # an unknown property, or a warning that both are the same
    data = [_data(prop, ops[i]) for prop, i in zip(props, data_at)]
    limit = LIGHT_INDEX_LIMIT if m == "lt" else SHAPE_INDEX_LIMIT
    index = _integer(ops[0], min(limit, limits[m]) if limits else limit) if m != "cam" else None
    if None in data or m != "cam" and index is None:
        return None
    p = props[0].index
    if m == "cam":
        (d,) = data
        build = lambda plain: (camera_word(p, d(plain)),)  # noqa: E731
    elif m == "lt":
        (d,) = data
        build = lambda plain: (light_word(index(plain), p, d(plain)),)  # noqa: E731
    else:
        (d, d2), p2 = data, props[1].index
        build = lambda plain: shape_words(index(plain), p, p2, d(plain), d2(plain))  # noqa: E731

    def words(plain: Plain) -> tuple[int, ...] | None:
        try:
            return build(plain)
        except (KeyError, ZeroDivisionError, _General):
            return None

    return words
