"""Exact expression evaluation, signed zero, and constant folding for .rept bodies."""

from __future__ import annotations

from fractions import Fraction

import pytest
from hypothesis import given, settings, strategies as st

from rend3r.asm.expressions import POISON, EvalError, Value, evaluate, fold
from rend3r.asm.parser import parse_line


def value(text: str, env: dict | None = None) -> Value:
    return evaluate(parse_line(f"x = {text}").expr, env or {})


@pytest.mark.parametrize(
    "text,number,negative_zero",
    [
        ("0.1 * 3", Fraction(3, 10), False),
        ("6 / 3", 2, False),
        ("7 / 2", Fraction(7, 2), False),
        ("1.5e3", 1500, False),
        ("-0", 0, True),
        ("-(-0)", 0, False),
        ("0 * -1", 0, True),
        ("-0 * -1", 0, False),
        ("0 / -3", 0, True),
        ("-0 + -0", 0, True),
        ("-0 + 0", 0, False),
        ("-0 - 0", 0, True),
        ("-0 - -0", 0, False),
        ("2 - 2", 0, False),
        ("-2 + 2", 0, False),
    ],
)
def test_exact_values_and_signed_zero(text, number, negative_zero):
    v = value(text)
    assert (v.number, v.negative_zero) == (number, negative_zero)
    assert type(v.number) is type(number)  # integral results are ints


def test_names_raw_and_errors():
    env = {"A": Value(2), "R": Value(raw=0x3C00), "BAD": POISON}
    assert value("A * A + 1", env).number == 5
    assert value("R", env).raw == 0x3C00
    with pytest.raises(EvalError, match="cannot be used in arithmetic"):
        value("R + 1", env)
    with pytest.raises(EvalError, match="did you mean 'A'"):
        value("a", env)
    with pytest.raises(EvalError) as exc:
        value("BAD + 1", env)
    assert exc.value.message == ""  # already reported where BAD was defined
    with pytest.raises(EvalError, match="division by zero") as exc:
        value("1 / (A - 2)", env)
    assert (exc.value.col, exc.value.end) == (9, 16)


atoms = st.sampled_from(["0", "-0", "1", "2", "3", "0.5", "1e-3", "0x10", "0b11", "0h3c00", "1__0", "N", "Z"])


@st.composite
def expressions(draw, depth=3) -> str:
    if depth == 0 or draw(st.booleans()):
        return draw(atoms)
    kind = draw(st.sampled_from(["bin", "neg", "paren"]))
    if kind == "neg":
        return "-" + draw(expressions(depth - 1))
    if kind == "paren":
        return "(" + draw(expressions(depth - 1)) + ")"
    return f"{draw(expressions(depth - 1))} {draw(st.sampled_from('+-*/'))} {draw(expressions(depth - 1))}"


def _outcome(node, env):
    try:
        v = evaluate(node, env)
    except EvalError as exc:
        return ("error", exc.message, exc.col, exc.end)
    return ("value", v)


@settings(max_examples=400)
@given(expressions())
def test_folding_changes_nothing(text):
    env = {"N": Value(3), "Z": Value(0, negative_zero=True)}
    node = parse_line(f"x = {text}").expr
    assert _outcome(fold(node), env) == _outcome(node, env)
