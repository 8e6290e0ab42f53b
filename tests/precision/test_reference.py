"""The two plain references agree with each other, so the wide formats' oracle is as good
as the enumerated one."""

from __future__ import annotations

import random

import pytest

from rend3r.precision.formats import FloatFormat

from .reference import Binades, Grid


@pytest.mark.parametrize("e", range(2, 7))
def test_enumerated_and_binade_references_agree(e: int) -> None:
    rng = random.Random(e)
    for m in range(1, 9):
        fmt = FloatFormat(e, m)
        grid, binades = Grid(fmt), Binades(fmt)
        for _ in range(1500):
            n = rng.randrange(0, 1 << rng.randrange(1, 48))
            d = rng.randrange(1, 1 << rng.randrange(1, 48))
            assert grid.nearest(n, d) == binades.nearest(n, d), (fmt, n, d)
            assert grid.nearest_sqrt(n, d) == binades.nearest_sqrt(n, d), (fmt, n, d)


def test_references_on_known_values() -> None:
    fp16 = FloatFormat(5, 10)
    for rnd in (Grid(fp16), Binades(fp16)):
        assert rnd.nearest(1, 3) == 0.333251953125
        assert rnd.nearest(65519, 1) == 65504.0 and rnd.nearest(65520, 1) == float("inf")
        assert rnd.nearest(2049, 1) == 2048.0 and rnd.nearest(2051, 1) == 2052.0  # ties to even
        assert rnd.nearest(1, 2**25) == 0.0 and rnd.nearest(3, 2**26) == 2.0**-24
        assert rnd.nearest_sqrt(2, 1) == 1.4140625
