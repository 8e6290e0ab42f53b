"""Shared helpers for the precision tests: bitwise comparison and format values."""

from __future__ import annotations

import numpy as np

from rend3r.precision.formats import FloatFormat

SMALL_FORMATS = [(e, m) for e in range(2, 12) for m in range(1, 15) if 1 + e + m <= 16]


def assert_same(got: np.ndarray, want: np.ndarray, inputs: tuple[np.ndarray, ...], what: str) -> None:
    """Equal bit for bit (signed zeros included); any NaN equals any NaN."""
    got = np.asarray(got, dtype=np.float64)
    want = np.asarray(want, dtype=np.float64)
    same = (got.view(np.uint64) == want.view(np.uint64)) | (np.isnan(got) & np.isnan(want))
    if not same.all():
        i = int(np.flatnonzero(~same.ravel())[0])
        args = ", ".join(repr(float(np.asarray(a).ravel()[i])) for a in inputs)
        raise AssertionError(f"{what}({args}): got {got.ravel()[i]!r}, want {want.ravel()[i]!r} "
                             f"({int((~same).sum())} of {same.size} differ)")


def random_values(fmt: FloatFormat, count: int, rng: np.random.Generator, near_one: float = 0.5) -> np.ndarray:
    """Finite values of ``fmt`` built from random encodings (sign, exponent field, fraction);
    a share ``near_one`` has exponents within 8 of zero, the rest any exponent field."""
    m = fmt.frac_bits
    frac = rng.integers(0, 2**m, count, dtype=np.int64) if m < 63 else None
    field = rng.integers(0, 2**fmt.exp_bits - 1, count)
    near = rng.random(count) < near_one
    field = np.where(near, np.clip(fmt.bias + rng.integers(-8, 9, count), 0, 2**fmt.exp_bits - 2), field)
    sig = np.where(field == 0, frac, frac + 2**m).astype(np.float64)  # exact: at most 53 bits
    exp = np.where(field == 0, fmt.emin, field - fmt.bias) - m
    sign = np.where(rng.random(count) < 0.5, -1.0, 1.0)
    return sign * np.ldexp(sig, exp)
