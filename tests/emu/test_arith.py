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


def _reference_round16(a: np.ndarray, ftz: bool) -> np.ndarray:
    with np.errstate(over="ignore", invalid="ignore"):
        r = a.astype(np.float16).astype(np.float32)
    if ftz:
        r = np.where(np.abs(r) < np.float32(2.0**-14), np.copysign(np.float32(0), r), r)
    return r


def test_fast_float32_rounding_matches_numpy_float16_bit_for_bit():
    """Every float32 whose exponent lies in or near float16's range, sampled densely."""
    rng = np.random.default_rng(7)
    mantissas = rng.integers(0, 1 << 23, 4096, dtype=np.uint32)
    edges = np.array([0, 1, 0xFFF, 0x1000, 0x1001, 0x1FFF, 0x2000, 0x3000, 0x5FFF, 0x6000, 0x7FE000, 0x7FF000, 0x7FFFFF],
                     dtype=np.uint32)
    mant = np.concatenate([mantissas, edges])
    exps = np.arange(90, 256, dtype=np.uint32)  # 2**-37 .. inf/NaN
    bits = (exps[:, None] << np.uint32(23)) | mant[None, :]
    bits = np.concatenate([bits.ravel(), bits.ravel() | np.uint32(0x80000000), np.array([0, 0x80000000], np.uint32)])
    a = bits.view(np.float32)
    for ftz in (True, False):
        ar = make_arith("fp16", "ftz" if ftz else "ieee")
        got, want = ar.round(a), _reference_round16(a, ftz)
        same = (got.view(np.uint32) == want.view(np.uint32)) | (np.isnan(got) & np.isnan(want))
        assert same.all(), hex(int(bits[~same][0]))


@given(st.lists(finite16, min_size=7, max_size=7), st.sampled_from(["ftz", "ieee"]))
def test_hamilton_pure_equals_full_product_bit_for_bit(bits, sub):
    from rend3r.emu.vec import hamilton, hamilton_pure

    ar = make_arith("fp16", sub)
    vals = [ar.from_bits(np.array([b])) for b in bits]
    a, v = tuple(vals[:4]), tuple(vals[4:])
    full = hamilton(ar, a, (np.zeros(1, np.float32), *v))
    fast = hamilton_pure(ar, a, v)
    for x, y in zip(full, fast):
        assert x.view(np.uint32)[0] == y.view(np.uint32)[0] or (np.isnan(x[0]) and np.isnan(y[0]))
