"""The spec camera's viewport tables: fp64 entries are correctly rounded, fp16/fp32 unchanged."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

from rend3r.emu.arith import make_arith
from rend3r.emu.camera import _viewport_axes, exact_viewport_axes


def _correctly_rounded(q: Fraction) -> float:
    """The float64 nearest q (ties to even), by int true division, which rounds once."""
    return q.numerator / q.denominator


@pytest.mark.parametrize("size", [(512, 384), (640, 480), (37, 23)])
def test_fp64_entries_are_the_exact_values_rounded_once(size):
    width, height = size
    ux, uy = _viewport_axes(make_arith("fp64", "ieee"), width, height)
    assert ux.dtype == uy.dtype == np.float64
    for x in range(width):
        q = Fraction(10) * (Fraction(x) + Fraction(1, 2)) / width - 5
        assert ux[x] == _correctly_rounded(q), x
    for y in range(height):
        q = Fraction(15, 2) * (Fraction(1, 2) - (Fraction(y) + Fraction(1, 2)) / height)
        assert uy[y] == _correctly_rounded(q), y


def test_fp64_rows_differ_from_the_thrice_rounded_table():
    """The issue's count: the float64 expression 7.5*(0.5-(y+0.5)/384) misses in 224 rows."""
    _, uy = _viewport_axes(make_arith("fp64", "ieee"), 512, 384)
    old = 7.5 * (0.5 - (np.arange(384) + 0.5) / 384)
    assert int(np.count_nonzero(uy != old)) == 224


@pytest.mark.parametrize("precision", ["fp16", "fp32"])
def test_fp16_fp32_tables_keep_their_bits(precision):
    arith = make_arith(precision, "ftz")
    ux, uy = _viewport_axes(arith, 512, 384)
    x = (np.arange(512) + 0.5) / 512 - 0.5
    y = 0.5 - (np.arange(384) + 0.5) / 384
    assert np.array_equal(ux, arith.round(10.0 * x))
    assert np.array_equal(uy, arith.round(7.5 * y))


def test_exact_axes_are_symmetric():
    ux, uy = exact_viewport_axes(512, 384)
    assert ux[0] == -ux[-1] and uy[0] == -uy[-1] and uy[0] == Fraction(15, 4) - Fraction(15, 1536)
