"""Formats that exist elsewhere give the same bits: e5m10 is the emulator's fp16
(``rend3r.emu.arith``, ftz and ieee), e8m23 numpy's float32, e11m52 float64, and the
ml_dtypes formats where that package is installed."""

from __future__ import annotations

import numpy as np
import pytest

from rend3r.emu.arith import make_arith
from rend3r.precision import ops
from rend3r.precision.formats import FloatFormat, parse

from .checks import assert_same, random_values

N = 100_000
BINARY = ("add", "sub", "mul", "div")


@pytest.mark.parametrize("subnormals", ["ftz", "ieee"])
def test_e5m10_equals_the_emulators_fp16(subnormals: str) -> None:
    fmt = parse("fp16", subnormals)
    arith = make_arith("fp16", subnormals)
    rng = np.random.default_rng(16)
    for near_one in (1.0, 0.0):  # ordinary magnitudes, then any exponent (under/overflow)
        a = random_values(FloatFormat(5, 10), N, rng, near_one)
        b = random_values(FloatFormat(5, 10), N, rng, near_one)
        a32, b32 = arith.round(a.astype(np.float32)), arith.round(b.astype(np.float32))
        for op in BINARY:
            want = getattr(arith, op)(a32, b32).astype(np.float64)
            assert_same(getattr(ops, op)(fmt, a, b), want, (a, b), f"{fmt} {op}")
        want = arith.sqrt(np.abs(a32)).astype(np.float64)
        assert_same(ops.sqrt(fmt, np.abs(a)), want, (a,), f"{fmt} sqrt")
        assert_same(fmt.round(a * 1.5), arith.round((a * 1.5).astype(np.float32)), (a,), f"{fmt} round")


def test_e8m23_equals_float32_and_e11m52_equals_float64() -> None:
    rng = np.random.default_rng(32)
    for fmt, dtype in ((parse("fp32"), np.float32), (parse("fp64"), np.float64)):
        a, b = random_values(fmt, N, rng, 0.7), random_values(fmt, N, rng, 0.7)
        x, y = a.astype(dtype), b.astype(dtype)
        with np.errstate(all="ignore"):
            native = {"add": x + y, "sub": x - y, "mul": x * y, "div": x / y}
            for op in BINARY:
                assert_same(getattr(ops, op)(fmt, a, b), native[op].astype(np.float64), (a, b), f"{fmt} {op}")
            assert_same(ops.sqrt(fmt, np.abs(a)), np.sqrt(np.abs(x)).astype(np.float64), (a,), f"{fmt} sqrt")


ML_DTYPES = {"bfloat16": "e8m7", "float8_e5m2": "e5m2"}  # the IEEE-like ones (with inf)


@pytest.mark.parametrize("name", sorted(ML_DTYPES))
def test_ml_dtypes_agree_where_installed(name: str) -> None:
    ml_dtypes = pytest.importorskip("ml_dtypes")
    fmt = parse(ML_DTYPES[name])
    rng = np.random.default_rng(8)
    x = rng.standard_normal(N) * np.exp2(rng.integers(-140, 140, N))
    with np.errstate(over="ignore"):
        x = x.astype(np.float32).astype(np.float64)  # float32 inputs: one rounding on either side
        want = x.astype(getattr(ml_dtypes, name)).astype(np.float64)
    assert_same(fmt.round(x), want, (x,), f"{fmt}.round vs ml_dtypes.{name}")
