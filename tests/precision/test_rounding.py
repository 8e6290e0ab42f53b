"""``FloatFormat.round`` against the plain reference: every format of at most 16 bits over
every finite float16 and a sample of float32 (midpoints and their neighbours included);
wider formats against numpy's own casts and on constructed midpoints."""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest

from rend3r.precision.formats import FloatFormat, parse
from rend3r.precision.rounding import midpoints

from .checks import SMALL_FORMATS, assert_same, random_values
from .reference import Binades, Grid

_ALL_FLOAT16 = np.arange(1 << 16, dtype=np.uint32).astype(np.uint16).view(np.float16).astype(np.float64)
FLOAT16_INPUTS = _ALL_FLOAT16[np.isfinite(_ALL_FLOAT16)]


def _float32_inputs(fmt: FloatFormat, grid: Grid, rng: np.random.Generator) -> np.ndarray:
    """Every 2**18+1-th float32 pattern, plus float32 midpoints of the format's grid (and the
    float32 values either side of each), the overflow threshold and half the smallest subnormal."""
    stride = np.arange(0, 1 << 32, (1 << 18) + 1, dtype=np.uint64).astype(np.uint32).view(np.float32)
    picks = rng.integers(0, len(grid.values), 3000)
    top = len(grid.values)
    mids = np.array([float(Fraction(grid.values[i] + (grid.values[i + 1] if i + 1 < top else grid.overflow),
                                    2 ** (grid.scale + 1))) for i in picks.tolist()])
    mids = np.concatenate([mids, [fmt.max + (fmt.max - np.nextafter(fmt.max, 0)) / 2, fmt.min_subnormal / 2]])
    with np.errstate(over="ignore"):
        m32 = mids.astype(np.float32)
    m32 = m32[(m32.astype(np.float64) == mids) & np.isfinite(m32)]
    near = [m32, np.nextafter(m32, np.float32(np.inf)), np.nextafter(m32, np.float32(0))]
    with np.errstate(invalid="ignore"):
        x = np.concatenate([stride] + near).astype(np.float64)
    x = x[np.isfinite(x)]
    return np.concatenate([x, -x[: len(x) // 2]])


def _expected(fmt: FloatFormat, grid: Grid, x: np.ndarray) -> dict[str, np.ndarray]:
    """Reference results for ieee, ftz (tininess after) and ftz (before)."""
    near = np.array([grid.nearest(*abs(v).as_integer_ratio()) for v in x.tolist()])
    near = np.copysign(near, x)
    tiny_after = np.abs(near) < fmt.min_normal
    tiny_before = np.abs(x) < fmt.min_normal
    zero = np.copysign(0.0, x)
    return {"ieee": near, "after": np.where(tiny_after, zero, near), "before": np.where(tiny_before, zero, near)}


@pytest.mark.parametrize("e,m", SMALL_FORMATS, ids=[f"e{e}m{m}" for e, m in SMALL_FORMATS])
def test_small_formats_round_like_the_reference(e: int, m: int) -> None:
    ieee, ftz = FloatFormat(e, m, "ieee"), FloatFormat(e, m, "ftz")
    grid = Grid(ieee)
    x = np.concatenate([FLOAT16_INPUTS, _float32_inputs(ieee, grid, np.random.default_rng(e * 100 + m))])
    want = _expected(ieee, grid, x)
    assert_same(ieee.round(x), want["ieee"], (x,), f"{ieee}.round")
    assert_same(ftz.round(x), want["after"], (x,), f"{ftz}.round")
    assert_same(ftz.round(x, tininess="before"), want["before"], (x,), f"{ftz}.round[before]")


@pytest.mark.parametrize("subnormals", ["ftz", "ieee"])
def test_nan_stays_a_quiet_nan_and_infinities_stay(subnormals: str) -> None:
    fmt = FloatFormat(5, 3, subnormals)
    payload = np.array([0x7FF0000000000001, 0xFFF4000000000000, 0x7FF8000000000000], dtype=np.uint64)
    x = np.concatenate([payload.view(np.float64), [np.inf, -np.inf]])
    r = fmt.round(x)
    assert np.isnan(r[:3]).all()
    assert (r[:3].view(np.uint64) & np.uint64(1 << 51)).all(), "quiet bit set"
    assert list(np.signbit(r[:3])) == [False, True, False]
    assert r[3] == np.inf and r[4] == -np.inf


def test_e5m10_is_numpy_float16_and_e8m23_is_float32_and_e11m52_is_float64() -> None:
    rng = np.random.default_rng(5)
    x = rng.standard_normal(200_000) * np.exp2(rng.integers(-160, 140, 200_000))
    x = np.concatenate([x, random_values(parse("fp64"), 50_000, rng, near_one=0.0)])
    with np.errstate(over="ignore"):
        assert_same(parse("fp16").round(x), x.astype(np.float16).astype(np.float64), (x,), "fp16")
        assert_same(parse("fp32").round(x), x.astype(np.float32).astype(np.float64), (x,), "fp32")
    assert_same(parse("fp64").round(x), x, (x,), "fp64")


WIDE = ["e8m30", "e11m26", "e9m40", "e11m51", "e6m45", "e3m52", "e10m20", "e11m20", "bf16", "fp24"]


@pytest.mark.parametrize("spec", WIDE)
def test_wide_formats_round_like_the_binade_reference(spec: str) -> None:
    fmt = parse(spec)
    rnd = Binades(fmt)
    rng = np.random.default_rng(len(spec) * 7 + fmt.frac_bits)
    v = random_values(fmt, 3000, rng)
    ulp = np.abs(np.nextafter(v, np.inf) - v)  # float64 ulp: midpoints of fmt and their neighbours
    gap = np.ldexp(1.0, np.frexp(np.abs(v))[1] - 1 - fmt.frac_bits)
    mids = v + np.copysign(gap / 2, v)
    x = np.concatenate([v, mids, mids + ulp, mids - ulp, rng.standard_normal(3000) * 1e3,
                        random_values(parse("fp64"), 3000, rng, near_one=0.0)])
    x = x[np.isfinite(x)]
    assert midpoints(fmt, x).sum() > 500, "the sample hits exact midpoints"
    near = np.array([rnd.nearest(*abs(t).as_integer_ratio()) for t in x.tolist()])
    assert_same(fmt.round(x), np.copysign(near, x), (x,), f"{fmt}.round")


def test_tininess_before_and_after_differ_just_below_the_smallest_normal() -> None:
    fp16 = parse("fp16-ftz")
    x = np.array([2.0**-14 - 2.0**-25])  # issue 14's (2^-7 - 2^-18) * 2^-7
    assert fp16.round(x)[0] == 2.0**-14
    assert fp16.round(x, tininess="before")[0] == 0.0
    with pytest.raises(ValueError, match="tininess"):
        fp16.round(x, tininess="during")  # type: ignore[arg-type]


def test_zero_dimensional_and_empty_inputs() -> None:
    fmt = parse("e4m3")
    assert float(fmt.round(1.0625)) == 1.0
    assert fmt.round(np.array([], dtype=np.float64)).shape == (0,)
    assert math.copysign(1, float(parse("e4m3-ftz").round(-1e-30))) == -1
