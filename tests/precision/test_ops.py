"""+ - * / sqrt in every format against the plain reference: all operand pairs of the
formats of at most 8 bits, random operands of the rest (up to e11m52), and constructed
double-rounding traps where the float64 result lands exactly on a midpoint."""

from __future__ import annotations

import numpy as np
import pytest

from rend3r.precision import ops
from rend3r.precision.formats import FloatFormat, parse

from .checks import SMALL_FORMATS, assert_same, random_values
from .reference import Grid, reference_op, rounder

BINARY = ("add", "sub", "mul", "div")
TINY_FORMATS = [(e, m) for e, m in SMALL_FORMATS if 1 + e + m <= 8]


def _all_values(fmt: FloatFormat) -> np.ndarray:
    grid = Grid(fmt)
    mags = np.array([np.ldexp(float(v), -grid.scale) for v in grid.values])
    return np.concatenate([mags, -mags])


def _check(fmt: FloatFormat, op: str, a: np.ndarray, b: np.ndarray | None = None,
           tininess: str = "after") -> None:
    rnd = rounder(fmt)
    if op == "sqrt":
        got = ops.sqrt(fmt, a, tininess=tininess)
        want = [reference_op(fmt, rnd, op, x, tininess=tininess) for x in a.tolist()]
        assert_same(got, np.array(want), (a,), f"{fmt} sqrt[{tininess}]")
        return
    got = getattr(ops, op)(fmt, a, b, tininess=tininess)
    want = [reference_op(fmt, rnd, op, x, y, tininess) for x, y in zip(a.tolist(), b.tolist())]
    assert_same(got, np.array(want), (a, b), f"{fmt} {op}[{tininess}]")


@pytest.mark.parametrize("e,m", TINY_FORMATS, ids=[f"e{e}m{m}" for e, m in TINY_FORMATS])
def test_every_pair_of_tiny_formats(e: int, m: int) -> None:
    modes = [("ieee", "after"), ("ftz", "after")] + ([("ftz", "before")] if 1 + e + m <= 7 else [])
    for subnormals, tininess in modes:
        fmt = FloatFormat(e, m, subnormals)
        v = _all_values(fmt)
        a, b = (x.ravel() for x in np.meshgrid(v, v))
        for op in BINARY:
            _check(fmt, op, a, b, tininess)
        _check(fmt, "sqrt", v, tininess=tininess)


RANDOM_FORMATS = [f"e{e}m{m}" for e, m in SMALL_FORMATS if 1 + e + m > 8] + [
    "tf32", "fp24", "fp32", "e8m26", "e11m26", "e5m30", "e9m37", "e11m44", "e4m51", "e11m51",
    "e11m20", "e11m25", "fp64"]


@pytest.mark.parametrize("spec", RANDOM_FORMATS)
def test_random_operands(spec: str) -> None:
    rng = np.random.default_rng(sum(map(ord, spec)))
    count = 300 if parse(spec).bits <= 16 else 1500
    for subnormals, tininess in (("ieee", "after"), ("ftz", "after"), ("ftz", "before")):
        fmt = parse(spec, subnormals)
        a, b = random_values(fmt, count, rng), random_values(fmt, count, rng)
        for op in BINARY:
            _check(fmt, op, a, b, tininess)
        _check(fmt, "sqrt", np.abs(a), tininess=tininess)


def _inverse(b: int, bits: int) -> int:
    return pow(b, -1, 1 << bits)


def _traps(m: int, rng: np.random.Generator, count: int) -> dict[str, list[tuple[float, ...]]]:
    """Operands (significands scaled to about 1) whose exact result lies within a float64 half
    ulp of a midpoint of the m-bit grid, so float64 lands on it: built with 2-adic inverses."""
    p = m + 1
    traps: dict[str, list[tuple[float, ...]]] = {"add": [], "mul": [], "div": [], "sqrt": []}
    for _ in range(count):
        c = int(rng.choice([-3, -1, 1, 3]))
        big = int(rng.integers(1 << m, 1 << p))
        b = big | 1
        # a * b = odd * 2**s + c with the product in [2**(s+p), 2**(s+p+1)): a midpoint plus c
        for s in (m - 1, m):
            a = ((1 << s) + c) * _inverse(b, s + 1) % (1 << (s + 1))
            while a < (1 << m):
                a += 1 << (s + 1)
            if a < (1 << p) and (1 << (s + p)) <= a * b < (1 << (s + p + 1)):
                traps["mul"].append((np.ldexp(a, -m), np.ldexp(b, -m)))
        # a / b = odd / 2**(p+1) - c / (2**(p+1) b): a = (odd * b - c) / 2**(p+1)
        odd = c * _inverse(b, p + 1) % (1 << (p + 1))
        if odd >= 1 << p:
            a = (odd * b - c) >> (p + 1)
            traps["div"].append((np.ldexp(a, -m), np.ldexp(b, -m)))
        # a + b = big + 1/2 + c/2**p, b of p bits just above or below one half
        half = np.ldexp((1 << m) + (c > 0), -p) if c > 0 else np.ldexp((1 << p) - 1, -p - 1)
        traps["add"].append((float(big), float(half)))
    for x in range(1, 1 << min(p + 1, 12), 2):  # sqrt(odd**2 - c) with odd**2 = c mod 2**(p+1)
        for odd in (x, (1 << (p + 1)) - x):
            sq = odd * odd
            if (1 << p) <= odd < (1 << (p + 1)) and sq % (1 << (p + 1)) in (1, 9, 17, 25):
                traps["sqrt"].append((np.ldexp(sq >> (p + 1), -m),))
    return traps


@pytest.mark.parametrize("m", [26, 27, 30, 35, 40, 45, 50, 51])
@pytest.mark.parametrize("e", [8, 11])
def test_double_rounding_traps_are_rounded_once(e: int, m: int) -> None:
    fmt = FloatFormat(e, m)
    rng = np.random.default_rng(e * 64 + m)
    fooled = 0
    for op, cases in _traps(m, rng, 200).items():
        assert cases, f"no {op} traps built"
        args = [np.array(col) for col in zip(*cases)]
        scale = np.ldexp(1.0, rng.integers(-20, 20, len(args[0])))
        sign = np.where(rng.random(len(args[0])) < 0.5, -1.0, 1.0)
        if op == "sqrt":
            args = [args[0] * scale * scale]
            naive = fmt.round(np.sqrt(args[0]))
        else:
            args = [args[0] * scale * sign, args[1] * np.where(op == "add", scale, 1.0)]
            naive = fmt.round(getattr(np, {"add": "add", "mul": "multiply", "div": "divide"}[op])(*args))
        _check(fmt, op, *args)
        fooled += int((naive != getattr(ops, op)(fmt, *args)).sum())
    assert fooled > 50, "the traps do catch float64-then-round"


def test_subnormal_products_of_e11_formats_avoid_double_rounding() -> None:
    """With 11 exponent bits, results in float64's own subnormal range carry fewer than 53
    bits, so even M <= 25 needs the exact side there: a * b = odd * 2**-1043 + c * 2**-1076
    (a 21-bit grid's midpoint plus a quarter of float64's spacing) lands float64 on the midpoint."""
    fmt = FloatFormat(11, 20)
    rng = np.random.default_rng(11)
    pairs = []
    while len(pairs) < 4:
        b, c = int(rng.integers(1 << 20, 1 << 21)) | 1, int(rng.choice([-1, 1]))
        a = ((1 << 33) + c) * _inverse(b, 34) % (1 << 34)
        if a < 1 << 21:
            pairs.append((np.ldexp(a, -540), np.ldexp(b, -536)))
    a, b = (np.array(col) for col in zip(*pairs))
    _check(fmt, "mul", a, b)
    assert (fmt.round(a * b) != ops.mul(fmt, a, b)).any(), "float64-then-round goes wrong here"
    x, y = random_values(fmt, 3000, rng, near_one=1.0), random_values(fmt, 3000, rng, near_one=1.0)
    _check(fmt, "mul", x * np.ldexp(1.0, -520), y * np.ldexp(1.0, -520))
    _check(fmt, "div", x * np.ldexp(1.0, -520), y * np.ldexp(1.0, 520))


def test_specials() -> None:
    fmt = parse("e6m20")
    inf, nan = np.inf, np.nan
    assert np.isnan(ops.add(fmt, inf, -inf)) and np.isnan(ops.mul(fmt, 0.0, inf))
    assert ops.div(fmt, -1.0, 0.0) == -inf and np.isnan(ops.sqrt(fmt, -1.0))
    assert np.isnan(ops.add(fmt, nan, 1.0)) and ops.add(fmt, inf, 1.0) == inf
    assert np.signbit(ops.sqrt(fmt, -0.0)) and not np.signbit(ops.add(fmt, -0.0, 0.0))
    assert ops.mul(fmt, fmt.max, 2.0) == inf
