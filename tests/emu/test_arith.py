"""Working-precision arithmetic: fp16 results are correctly rounded, FTZ flushes."""

from fractions import Fraction

import numpy as np
from hypothesis import given, strategies as st

from rend3r.emu.arith import make_arith
from rend3r.isa.float16 import bits_to_float, round_literal

finite16 = st.integers(0, 0xFFFF).filter(lambda b: (b & 0x7C00) != 0x7C00)


def _exact_round(value: Fraction, ftz: bool) -> float:
    r = round_literal(abs(value), negative=value < 0)
    v = r.value
    if ftz and v != 0 and abs(v) < 2.0**-14:
        v = 0.0 * np.sign(v)
    return v


@given(finite16, finite16, st.sampled_from(["add", "sub", "mul", "div"]))
def test_fp16_ieee_ops_are_correctly_rounded(a_bits, b_bits, op):
    ar = make_arith("fp16", "ieee")
    a, b = bits_to_float(a_bits), bits_to_float(b_bits)
    if op == "div" and b == 0:
        return
    exact = {"add": Fraction(a) + Fraction(b), "sub": Fraction(a) - Fraction(b),
             "mul": Fraction(a) * Fraction(b), "div": Fraction(a) / Fraction(b) if b else None}[op]
    got = float(getattr(ar, op)(ar.const(a), ar.const(b)))
    assert got == _exact_round(exact, ftz=False) or (abs(exact) >= 65520 and np.isinf(got))


def test_ftz_flushes_subnormal_results_and_loads():
    ftz, ieee = make_arith("fp16", "ftz"), make_arith("fp16", "ieee")
    tiny = ieee.const(2.0**-14)
    assert float(ieee.mul(tiny, ieee.const(0.5))) == 2.0**-15
    assert float(ftz.mul(tiny, ftz.const(0.5))) == 0.0
    assert float(ftz.from_bits(0x0001)) == 0.0
    assert np.signbit(ftz.from_bits(0x8001))


def test_overflow_is_infinite_not_clamped():
    ar = make_arith("fp16")
    assert np.isinf(ar.mul(ar.const(300.0), ar.const(300.0)))
    assert float(make_arith("fp32").mul(np.float32(300), np.float32(300))) == 90000.0
