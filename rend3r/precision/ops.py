"""Correctly rounded + - * / and sqrt in any :class:`~rend3r.precision.formats.FloatFormat`.

Operands are values already in the format (float64 arrays); with ``ftz`` subnormal operands
are read as signed zero first, as the device's units do (and ``rend3r.emu.arith`` for fp16).
Each operation is computed once in float64, ``r = RN64(x)`` for the exact result ``x``, and
``r`` is rounded to the format. That second rounding can differ from rounding ``x`` directly
(double rounding) only when ``r`` lies exactly on a midpoint of the format's grid, and the
fix is to know on which side of ``r`` the exact ``x`` lies:

*Claim.* Let ``G`` be the format's grid (a subset of the float64 grid ``F``: every value of
a format with E <= 11, M <= 52 is a float64), ``g1 < g2`` neighbours in ``G`` around ``x``
and ``mu`` their midpoint. If ``r`` is not a midpoint, ``RN_G(r) = RN_G(x)``; if it is,
``RN_G(x)`` is the neighbour on the side ``sign(x - r)`` (the even one when ``x = r``).

*Proof sketch.* ``RN64`` is monotone and fixes every point of ``F``. ``g1, g2`` are in ``F``,
so ``g1 <= r <= g2``. If ``mu`` is in ``F`` then ``x < mu`` gives ``r <= mu``, ``x > mu``
gives ``r >= mu`` and ``x = mu`` gives ``r = mu``; so ``r`` falls strictly on ``x``'s side of
``mu`` or on ``mu`` itself, where ``sign(x - r)`` says which side ``x`` is on. If ``mu`` is
not in ``F`` (only for 52 fraction bits), ``r`` is never a midpoint and ``r <> mu`` exactly
when ``x <> mu``. The overflow threshold ``max + ulp/2`` is the midpoint between ``max``
and ``2**(emax+1)`` and obeys the same argument; float64 overflow only happens far above it.

The sign of ``x - r`` comes from error-free transformations (:mod:`rend3r.precision.exact`):
TwoSum, Dekker's TwoProduct, and the residuals ``a - q b`` and ``a - r r``. It is computed
only on the lanes that need it. By Figueroa's theorem ("When is double rounding innocuous?",
1995) a float64 result is never a false midpoint for + - * / sqrt when ``53 >= 2(M+1) + 2``,
i.e. M <= 25, so those formats skip the check, except with 11 exponent bits, where results
in float64's own subnormal range carry fewer than 53 bits and the theorem does not apply.

Flush-to-zero with tininess ``before`` rounding needs the same side at the smallest normal
``m``: ``r = m`` may stand for an exact result just below ``m``.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from . import exact
from .formats import FloatFormat, Tininess
from .rounding import midpoints, round_to_format

_ABS = np.uint64((1 << 63) - 1)
Side = Callable[[np.ndarray], np.ndarray]  # flat lane indices -> sign(exact - r) there


def read(fmt: FloatFormat, a: np.ndarray | float) -> np.ndarray:
    """Operands as the format's units read them: float64, subnormals as signed zero with ftz."""
    v = np.asarray(a, dtype=np.float64)
    if fmt.ftz:
        with np.errstate(over="ignore"):  # numpy warns of the wrap for 0-d values
            wrapped = (v.view(np.uint64) & _ABS) - np.uint64(1)  # zero wraps to the top
        limit = np.float64(fmt.min_normal).view(np.uint64) - np.uint64(1)
        if v.size and wrapped.min() < limit:
            v = np.where(wrapped < limit, np.copysign(0.0, v), v)
    return v


def _double_rounding_possible(fmt: FloatFormat) -> bool:
    return fmt.frac_bits > 25 or fmt.exp_bits == 11


def _finish(fmt: FloatFormat, r: np.ndarray, side: Side, tininess: Tininess) -> np.ndarray:
    """Round the float64 result ``r`` to ``fmt`` as the exact result would be rounded: every
    lane at once, then again, knowing the exact side, the few lanes where that matters."""
    out = round_to_format(fmt, r, tininess=tininess)
    need = midpoints(fmt, r) if _double_rounding_possible(fmt) else None
    if fmt.ftz and tininess == "before":
        at_min = np.abs(r) == fmt.min_normal
        need = at_min if need is None else need | at_min
    if need is not None and need.any():
        lanes = np.flatnonzero(need)
        out.reshape(-1)[lanes] = round_to_format(fmt, _at(r, lanes), tininess=tininess, toward=side(lanes))
    return out


def _at(v: np.ndarray, lanes: np.ndarray) -> np.ndarray:
    return v.reshape(-1)[lanes]


def _binary(fmt: FloatFormat, a: np.ndarray | float, b: np.ndarray | float, op: np.ufunc,
            side: Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray], tininess: Tininess) -> np.ndarray:
    """``op(a, b)`` in float64, rounded as the exact result would be (``side(x, y, r)``: the
    sign of exact - r on the lanes given)."""
    x, y = np.broadcast_arrays(read(fmt, a), read(fmt, b))
    with np.errstate(all="ignore"):
        r = op(x, y)
        return _finish(fmt, r, lambda i: side(_at(x, i), _at(y, i), _at(r, i)), tininess)


def add(fmt: FloatFormat, a: np.ndarray | float, b: np.ndarray | float, *,
        tininess: Tininess = "after") -> np.ndarray:
    """``a + b`` correctly rounded to ``fmt``."""
    return _binary(fmt, a, b, np.add, exact.sum_side, tininess)


def sub(fmt: FloatFormat, a: np.ndarray | float, b: np.ndarray | float, *,
        tininess: Tininess = "after") -> np.ndarray:
    """``a - b`` correctly rounded to ``fmt`` (negation is exact)."""
    return add(fmt, a, np.negative(np.asarray(b, dtype=np.float64)), tininess=tininess)


def mul(fmt: FloatFormat, a: np.ndarray | float, b: np.ndarray | float, *,
        tininess: Tininess = "after") -> np.ndarray:
    """``a * b`` correctly rounded to ``fmt``."""
    return _binary(fmt, a, b, np.multiply, exact.product_side, tininess)


def div(fmt: FloatFormat, a: np.ndarray | float, b: np.ndarray | float, *,
        tininess: Tininess = "after") -> np.ndarray:
    """``a / b`` correctly rounded to ``fmt``."""
    return _binary(fmt, a, b, np.divide, exact.quotient_side, tininess)


def sqrt(fmt: FloatFormat, a: np.ndarray | float, *, tininess: Tininess = "after") -> np.ndarray:
    """``sqrt(a)`` correctly rounded to ``fmt`` (NaN for negative ``a``, ``sqrt(-0) = -0``)."""
    x = read(fmt, a)
    with np.errstate(all="ignore"):
        r = np.sqrt(x)
        return _finish(fmt, r, lambda i: exact.sqrt_side(_at(x, i), _at(r, i)), tininess)
