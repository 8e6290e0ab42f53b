"""Format names, aliases, derived properties and the errors for bad format strings."""

from __future__ import annotations

import numpy as np
import pytest

from rend3r.precision import ALIASES, FloatFormat, FormatError, parse


@pytest.mark.parametrize("alias,e,m", [("fp16", 5, 10), ("bf16", 8, 7), ("tf32", 8, 10), ("fp24", 7, 16),
                                       ("fp32", 8, 23), ("fp64", 11, 52)])
def test_aliases(alias: str, e: int, m: int) -> None:
    assert parse(alias) == FloatFormat(e, m) == parse(f"e{e}m{m}")
    assert ALIASES[alias] == (e, m)


def test_subnormal_suffix_and_default() -> None:
    assert parse("e5m10-ftz").subnormals == "ftz" and parse("fp16").subnormals == "ieee"
    assert parse("fp16", "ftz").ftz and parse("fp16-ieee", "ftz").subnormals == "ieee"
    assert str(parse(" FP16-FTZ ")) == "e5m10-ftz" and parse("bf16").name == "e8m7"


@pytest.mark.parametrize("spec,dtype", [("fp16", np.float16), ("fp32", np.float32), ("fp64", np.float64)])
def test_properties_match_numpy(spec: str, dtype: type) -> None:
    fmt, info = parse(spec), np.finfo(dtype)
    assert fmt.max == float(info.max) and fmt.min_normal == float(info.smallest_normal)
    assert fmt.min_subnormal == float(info.smallest_subnormal)
    assert fmt.unit_roundoff == float(info.eps) / 2 and fmt.bits == info.bits
    assert fmt.emax == info.maxexp - 1 and fmt.emin == info.minexp


def test_small_format_properties() -> None:
    fmt = parse("e2m1")  # values 0, 0.5 | 1, 1.5 | 2, 3
    assert (fmt.bias, fmt.emin, fmt.emax) == (1, 0, 1)
    assert (fmt.max, fmt.min_normal, fmt.min_subnormal, fmt.bits) == (3.0, 1.0, 0.5, 4)


@pytest.mark.parametrize("spec,message", [
    ("e12m3", "exponent bits 12 out of range 2..11"),
    ("e1m3", "exponent bits 1 out of range 2..11"),
    ("e5m0", "fraction bits 0 out of range 1..52"),
    ("e8m53", "fraction bits 53 out of range 1..52"),
    ("fp8", "expected eEmM"),
    ("e5", "expected eEmM"),
    ("e5m10-dn", "subnormal mode 'dn' must be ftz or ieee"),
])
def test_bad_format_strings_say_what_is_wrong(spec: str, message: str) -> None:
    with pytest.raises(FormatError, match=message) as err:
        parse(spec)
    assert repr(spec) in str(err.value)
    assert isinstance(err.value, ValueError)


def test_formats_are_frozen_and_hashable() -> None:
    fmt = parse("fp16")
    with pytest.raises(AttributeError):
        fmt.exp_bits = 6  # type: ignore[misc]
    assert len({parse("fp16"), parse("e5m10"), parse("fp16-ftz")}) == 2
