"""Exact evaluation of operand expressions.

Numbers are ints or Fractions (integral results are always ints), so ``0.1 * 3`` is
exactly 3/10 and rounds to float16 once, at the end. The sign of zero is tracked as
IEEE 754 does it (``-0``, ``-0 * 5`` and ``-0 + -0`` are negative zero), so ``-0``
assembles to 0x8000. Raw bits (``0h3c00``) are a value of their own that no arithmetic
accepts. ``inf``, ``infinity`` and ``nan`` (any case; names no constant has taken) are the
float values the original assembler's ``float()`` accepted: they may be negated, nothing more.
"""

from __future__ import annotations

import difflib
import math
from dataclasses import dataclass
from fractions import Fraction
from typing import Mapping

from .parser import MAX_BITS, BinOp, Expr, Neg, Num, Operand, Ref, Str


@dataclass(frozen=True, slots=True)
class Value:
    """An evaluated operand: a number (with the sign of zero) or raw 16 bits."""

    number: int | Fraction | float = 0  # a float only for inf and nan
    negative_zero: bool = False
    raw: int | None = None  # set for 0h literals: the bits, and number is unused
    literal: str = ""  # "hex" or "bin": the operand was exactly one 0x or 0b literal

    @property
    def is_integer(self) -> bool:
        return self.raw is None and type(self.number) is int

    @property
    def sign_negative(self) -> bool:
        return self.number < 0 or self.negative_zero


#: The value of a constant whose definition failed: using it fails without a second
#: message (the definition's error already explains it).
POISON = Value()
#: Names of the non-finite values (lower case), as Python's ``float()`` spells them.
NON_FINITE = {"inf": math.inf, "infinity": math.inf, "nan": math.nan}


class EvalError(Exception):
    """An expression that has no value: message and the span to underline."""

    def __init__(self, message: str, col: int, end: int) -> None:
        super().__init__(message)
        self.message = message
        self.col = col
        self.end = end


def evaluate(node: Expr | Str, env: Mapping[str, Value]) -> Value:
    """The exact value of ``node``; names are looked up in ``env``."""
    cls = type(node)
    if cls is Num:
        if node.error:
            raise EvalError(node.error, node.col, node.end)
        if node.kind == "raw":
            return Value(raw=node.value)
        return Value(node.value, negative_zero=node.negative_zero,
                     literal=node.kind if node.kind in ("hex", "bin") else "")
    if cls is Ref:
        try:
            value = env[node.name]
        except KeyError:
            special = NON_FINITE.get(node.name.lower())
            if special is None:
                raise EvalError(_undefined(node.name, env), node.col, node.end) from None
            return Value(special)
        if value is POISON:
            raise EvalError("", node.col, node.end)
        return value
    if cls is Neg:
        v = evaluate(node.operand, env)
        if type(v.number) is float:
            return Value(-v.number)  # -nan keeps its sign bit, as float("-nan") does
        v = _number(v, node.operand)
        return Value(-v.number, negative_zero=v.number == 0 and not v.negative_zero)
    if cls is BinOp:
        a = _number(evaluate(node.left, env), node.left)
        b = _number(evaluate(node.right, env), node.right)
        return _binop(node, a, b)
    raise EvalError("a string is not a number", node.col, node.end)


def _number(v: Value, node: Expr) -> Value:
    if v.raw is not None:
        raise EvalError("raw bits (0h...) cannot be used in arithmetic", node.col, node.end)
    if type(v.number) is float:
        raise EvalError("inf and nan cannot be used in arithmetic (only negated)", node.col, node.end)
    return v


def _binop(node: BinOp, a: Value, b: Value) -> Value:
    op, x, y = node.op, a.number, b.number
    if op == "+":
        r = x + y
    elif op == "-":
        r = x - y
    elif op == "*":
        r = x * y
    elif y == 0:
        raise EvalError("division by zero", node.right.col, node.right.end)
    elif type(x) is int and type(y) is int:
        q, rem = divmod(x, y)
        r = q if rem == 0 else Fraction(x, y)
    else:
        r = x / y
    if type(r) is int:
        too_large = r.bit_length() > MAX_BITS
    else:
        too_large = max(r.numerator.bit_length(), r.denominator.bit_length()) > MAX_BITS
    if too_large:
        raise EvalError(f"result out of range: exact arithmetic is limited to {MAX_BITS:,}-bit numerators and "
                        f"denominators (about 10^4000)", node.col, node.end)
    if r:
        return Value(r.numerator if type(r) is Fraction and r.denominator == 1 else r)
    # An exact zero: its sign as IEEE 754 gives it. A sum is -0 only when both addends
    # are negative zeros; a product or quotient is -0 when the signs differ.
    if op == "+" or op == "-":
        y_negative = b.negative_zero if op == "+" else not b.negative_zero
        return Value(0, negative_zero=x == 0 and y == 0 and a.negative_zero and y_negative)
    return Value(0, negative_zero=a.sign_negative != b.sign_negative)


def describe(number: int | Fraction) -> str:
    """``number`` for a message: exact when short, else its magnitude (``about 1.2e+4000``)."""
    if type(number) is int:
        text = str(abs(number))  # at most MAX_BITS bits: within Python's int->str limit
        if len(text) <= 24:
            return str(number)
        sign = "-" if number < 0 else ""
        return f"about {sign}{text[0]}.{text[1:4]}e+{len(text) - 1}"
    try:
        return f"{float(number):g}"
    except OverflowError:
        return describe(int(number))


def fold(node: Operand) -> Operand:
    """``node`` with every arithmetic on literals done once, ahead of time (used for
    ``.rept`` bodies, which run many times). Whatever would fail is left as written, so
    the error is still reported where and when it happens."""
    cls = type(node)
    if cls is Neg:
        inner = fold(node.operand)
        node = Neg(inner, node.col, node.end, node.depth)
        if _foldable(inner):
            v = evaluate(node, {})
            return Num(v.number, "dec", node.col, node.end, negative_zero=v.negative_zero)
        return node
    if cls is BinOp:
        node = BinOp(node.op, fold(node.left), fold(node.right), node.col, node.end, node.depth)
        if _foldable(node.left) and _foldable(node.right):
            try:
                v = evaluate(node, {})
            except EvalError:
                return node
            return Num(v.number, "dec", node.col, node.end, negative_zero=v.negative_zero)
    return node


def _foldable(node: Operand) -> bool:
    return type(node) is Num and not node.error and node.kind != "raw"


def _undefined(name: str, env: Mapping[str, Value]) -> str:
    same_case = [n for n in env if n.lower() == name.lower()]
    close = same_case or difflib.get_close_matches(name, list(env), n=1)
    hint = f"; did you mean '{close[0]}'?" if close else ""
    return f"undefined name '{name}'{hint}"
