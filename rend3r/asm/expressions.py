"""Exact evaluation of operand expressions.

Numbers are ints or Fractions (integral results are always ints), so ``0.1 * 3`` is
exactly 3/10 and rounds to float16 once, at the end. The sign of zero is tracked as
IEEE 754 does it (``-0``, ``-0 * 5`` and ``-0 + -0`` are negative zero), so ``-0``
assembles to 0x8000. Raw bits (``0h3c00``) are a value of their own that no arithmetic
accepts.
"""

from __future__ import annotations

import difflib
from dataclasses import dataclass
from fractions import Fraction
from typing import Mapping

from .parser import BinOp, Expr, Neg, Num, Ref, Str


@dataclass(frozen=True, slots=True)
class Value:
    """An evaluated operand: a number (with the sign of zero) or raw 16 bits."""

    number: int | Fraction = 0
    negative_zero: bool = False
    raw: int | None = None  # set for 0h literals: the bits, and number is unused
    hex_literal: bool = False  # the operand was exactly one 0x literal

    @property
    def is_integer(self) -> bool:
        return self.raw is None and isinstance(self.number, int)

    @property
    def sign_negative(self) -> bool:
        return self.number < 0 or self.negative_zero


#: The value of a constant whose definition failed: using it fails without a second
#: message (the definition's error already explains it).
POISON = Value()


class EvalError(Exception):
    """An expression that has no value: message and the span to underline."""

    def __init__(self, message: str, col: int, end: int) -> None:
        super().__init__(message)
        self.message = message
        self.col = col
        self.end = end


def _normal(x: int | Fraction) -> int | Fraction:
    if isinstance(x, Fraction) and x.denominator == 1:
        return x.numerator
    return x


def evaluate(node: Expr | Str, env: Mapping[str, Value]) -> Value:
    """The exact value of ``node``; names are looked up in ``env``."""
    cls = type(node)
    if cls is Num:
        if node.error:
            raise EvalError(node.error, node.col, node.end)
        if node.kind == "raw":
            return Value(raw=node.value)
        return Value(node.value, hex_literal=node.kind == "hex")
    if cls is Ref:
        try:
            value = env[node.name]
        except KeyError:
            raise EvalError(_undefined(node.name, env), node.col, node.end) from None
        if value is POISON:
            raise EvalError("", node.col, node.end)
        return value
    if cls is Neg:
        v = _number(evaluate(node.operand, env), node.operand)
        return Value(-v.number, negative_zero=v.number == 0 and not v.negative_zero)
    if cls is BinOp:
        a = _number(evaluate(node.left, env), node.left)
        b = _number(evaluate(node.right, env), node.right)
        return _binop(node, a, b)
    raise EvalError("a string is not a number", node.col, node.end)


def _number(v: Value, node: Expr) -> Value:
    if v.raw is not None:
        raise EvalError("raw bits (0h...) cannot be used in arithmetic", node.col, node.end)
    return v


def _binop(node: BinOp, a: Value, b: Value) -> Value:
    op = node.op
    if op == "+" or op == "-":
        y = b.number if op == "+" else -b.number
        y_neg = b.sign_negative if op == "+" else not b.sign_negative
        r = a.number + y
        # IEEE: an exact zero sum is -0 only when both addends are negative zeros.
        return Value(_normal(r), negative_zero=r == 0 and a.number == 0 and y == 0 and a.sign_negative and y_neg)
    sign = a.sign_negative != b.sign_negative
    if op == "*":
        r = a.number * b.number
        return Value(_normal(r), negative_zero=r == 0 and sign)
    if b.number == 0:
        raise EvalError("division by zero", node.right.col, node.right.end)
    r = Fraction(a.number, b.number)
    return Value(_normal(r), negative_zero=r == 0 and sign)


def _undefined(name: str, env: Mapping[str, Value]) -> str:
    close = difflib.get_close_matches(name, list(env), n=1)
    hint = f"; did you mean '{close[0]}'?" if close else ""
    return f"undefined name '{name}'{hint}"
