"""The narrow kernels (csrc/fnarrow.h): formats of at most 10 fraction bits and 7 exponent
bits (8 with ftz) computed in float lanes. Their rounding equals the format's at every
rounding boundary of every such format, and a float32 operation rounded once more equals
the correctly rounded operation of the format (the double-rounding and exponent-range
argument of fnarrow.h), against the reference of rend3r.precision. Scenes rendered by them
are compared with the reference renderer in test_engine_vs_reference.py."""

from __future__ import annotations

import numpy as np
import pytest

from rend3r.emu import native
from rend3r.emu.arith import make_arith
from rend3r.precision import ops
from rend3r.precision.formats import FloatFormat

from tests.precision.checks import random_values

MODES = [("ieee", "after"), ("ftz", "after"), ("ftz", "before")]
NARROW = [(e, m, sub, tin) for e in range(2, 9) for m in range(1, 11) for sub, tin in MODES
          if e < 8 or sub == "ftz"]


@pytest.mark.parametrize("precision, subnormals, tininess, suffix", [
    ("e6m9", "ftz", "after", "nar"), ("e6m9", "ieee", "after", "nar"), ("bf16", "ftz", "after", "nar"),
    ("tf32", "ftz", "before", "nar"), ("fp16", "ftz", "before", "nar"), ("e2m1", "ieee", "after", "nar"),
    ("bf16", "ieee", "after", "fmt"), ("e6m11", "ftz", "after", "fmt"), ("e9m7", "ftz", "after", "fmt"),
    ("fp16", "ftz", "after", "h16"), ("fp32", "ftz", "after", "f32"), ("fp64", "ftz", "after", "f64")])
def test_the_narrow_kernels_serve_exactly_the_narrow_formats(precision, subnormals, tininess, suffix):
    ar = make_arith(precision, subnormals, tininess)
    assert native.suffix(ar) == suffix
    assert native.dtype(ar) == (np.float64 if suffix in ("fmt", "f64") else np.float32)
    assert native.suffix(make_arith(precision, subnormals, tininess, (("lighting", "e7m20"),))) == "fmt"


def _boundaries(fmt: FloatFormat) -> np.ndarray:
    """Every finite value of the format, the midpoints between neighbours and the float32
    numbers on either side of each, the overflow threshold and its neighbours, float32
    subnormals, infinity and NaN; both signs, as float32."""
    e, m = fmt.exp_bits, fmt.frac_bits
    field, frac = np.divmod(np.arange((2**e - 1) << m, dtype=np.int64), 1 << m)
    values = np.ldexp(np.where(field == 0, frac, frac + 2**m).astype(np.float64),
                      np.where(field == 0, fmt.emin, field - fmt.bias) - m)
    top = np.append(values, fmt.overflow)
    mids = ((top[:-1] + top[1:]) / 2).astype(np.float32)
    pts = np.concatenate([values.astype(np.float32), mids, np.nextafter(mids, np.float32(0)),
                          np.nextafter(mids, np.float32(np.inf)), np.float32([2.0**-149, 2.0**-127, 3e38, np.inf, np.nan])])
    return np.concatenate([pts, -pts])


def _same_bits(got: np.ndarray, want: np.ndarray) -> np.ndarray:
    return (got.view(np.uint32) == want.view(np.uint32)) | (np.isnan(got) & np.isnan(want))


@pytest.mark.parametrize("instruction_set", native.INSTRUCTION_SETS)
def test_rounding_at_every_boundary_of_every_narrow_format(instruction_set):
    if not native.runs(instruction_set):
        pytest.skip(f"this processor does not run the {instruction_set} kernels")
    for e, m, sub, tin in NARROW:
        ar = make_arith(f"e{e}m{m}", sub, tin)
        x = _boundaries(ar.format)
        got = native.round_narrow(x, ar, instruction_set)
        want = ar.format.round(x.astype(np.float64), tininess=tin).astype(np.float32)
        bad = ~_same_bits(got, want)
        assert not bad.any(), f"e{e}m{m} {sub} {tin}: round({x[bad][:4]}) = {got[bad][:4]}, want {want[bad][:4]}"


@pytest.mark.parametrize("e, m, sub, tin", NARROW, ids=[f"e{e}m{m}-{s}-{t}" for e, m, s, t in NARROW])
def test_a_float32_operation_rounded_again_is_the_formats_operation(e, m, sub, tin):
    ar = make_arith(f"e{e}m{m}", sub, tin)
    fmt, rng = ar.format, np.random.default_rng(e * 100 + m)
    a, b = (ops.read(fmt, random_values(fmt, 4000, rng, near)) for near in (0.5, 0.2))
    a32, b32 = a.astype(np.float32), b.astype(np.float32)
    with np.errstate(all="ignore"):
        cases = {"add": (a32 + b32, ops.add(fmt, a, b, tininess=tin)),
                 "sub": (a32 - b32, ops.sub(fmt, a, b, tininess=tin)),
                 "mul": (a32 * b32, ops.mul(fmt, a, b, tininess=tin)),
                 "div": (a32 / b32, ops.div(fmt, a, b, tininess=tin)),
                 "sqrt": (np.sqrt(np.abs(a32)), ops.sqrt(fmt, np.abs(a), tininess=tin))}
    for op, (float32, want) in cases.items():
        got = native.round_narrow(float32, ar)
        bad = ~_same_bits(got, want.astype(np.float32))
        assert not bad.any(), f"{op}({a[bad][:3]}, {b[bad][:3]}) = {got[bad][:3]}, want {want[bad][:3]}"
