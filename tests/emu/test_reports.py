"""The kernels' per-chunk reports live on cache lines of their own (no false sharing
between threads adding to them per packet)."""

import numpy as np
import pytest

from rend3r.emu.raytracer import _LINE, _own_lines


@pytest.mark.parametrize("count", [1, 2, 5, 8])
def test_each_report_row_owns_its_cache_lines(count):
    last = np.arange(10, dtype=np.float64)
    rows = _own_lines(last, count)
    assert rows.shape == (count, 10) and (rows == last).all()
    starts = [rows[k].ctypes.data for k in range(count)]
    assert all(a % _LINE == 0 for a in starts)
    ends = [a + rows[k].nbytes for k, a in enumerate(starts)]
    lines = [set(range(a // _LINE, (e - 1) // _LINE + 1)) for a, e in zip(starts, ends)]
    assert all(not (lines[i] & lines[j]) for i in range(count) for j in range(i))  # no line shared by two rows
    base = rows.base if rows.base is not None else rows
    while base.base is not None:
        base = base.base
    lo, hi = base.ctypes.data, base.ctypes.data + base.nbytes
    assert starts[0] - lo >= _LINE and hi - ends[-1] >= _LINE  # nor with another array


def test_a_report_row_is_bounded():
    with pytest.raises(ValueError):
        _own_lines(np.zeros(17), 2)
