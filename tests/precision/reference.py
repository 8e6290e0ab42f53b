"""A plain reference for rounding and arithmetic in eEmM formats, in Python integers.

Two independent roundings of a nonnegative exact value ``N/D`` (or ``sqrt(N/D)``) to the
nearest value of a format, ties to the even encoding, ``2**(emax+1)`` standing for infinity:

- :class:`Grid` lists every finite value of a small format from its encodings and picks
  the nearest by bisection (used for formats up to 16 bits);
- :class:`Binades` finds the binade, the quantum there, and the nearest multiple of it
  (used for wider formats, and checked against :class:`Grid` on small ones).

:func:`round_exact` adds signs, infinities and flush-to-zero; :func:`reference_op` applies
an operation to two format values exactly (integer fractions) and rounds once.
"""

from __future__ import annotations

import math
from bisect import bisect_right
from collections.abc import Callable

from rend3r.precision.formats import FloatFormat


class Grid:
    """Every finite nonnegative value of a format, in encoding order, times ``2**scale``."""

    def __init__(self, fmt: FloatFormat) -> None:
        e, m = fmt.exp_bits, fmt.frac_bits
        self.scale = m - fmt.emin + 1  # subnormal k -> 2k, normal (field, f) -> (2**m + f) << field
        values = [2 * f for f in range(2**m)]
        for field in range(1, 2**e - 1):
            values += [(2**m + f) << field for f in range(2**m)]
        self.values = values
        self.overflow = 2 ** (fmt.emax + 1 + self.scale)

    def _pick(self, floor_scaled: int, above_mid: Callable[[int], int]) -> float:
        i = bisect_right(self.values, floor_scaled)  # values[i-1] <= floor <= exact
        lo = self.values[i - 1]
        hi = self.values[i] if i < len(self.values) else self.overflow
        side = above_mid(lo + hi)  # sign of 2*exact - (lo + hi)
        j = i - 1 if side < 0 else i if side > 0 else (i - 1 if (i - 1) % 2 == 0 else i)
        if j == len(self.values):
            return math.inf
        v = self.values[j]
        shift = max(v.bit_length() - 53, 0)  # only zeros below: values have M+1 bits
        return math.ldexp(float(v >> shift), shift - self.scale)

    def nearest(self, n: int, d: int) -> float:
        """``n/d >= 0`` rounded to the format (no flushing)."""
        top = n << self.scale
        return self._pick(top // d, lambda s: _cmp(2 * top, s * d))

    def nearest_sqrt(self, n: int, d: int) -> float:
        """``sqrt(n/d)`` rounded to the format (no flushing)."""
        top = n << (2 * self.scale)
        return self._pick(math.isqrt(top // d), lambda s: _cmp(4 * top, s * s * d))


class Binades:
    """Nearest-even rounding by arithmetic: binade, quantum, nearest multiple."""

    def __init__(self, fmt: FloatFormat) -> None:
        self.fmt = fmt

    def _finish(self, k: int, u: int, side: int) -> float:
        if side > 0 or (side == 0 and k % 2 == 1):
            k += 1
        if k.bit_length() + u > self.fmt.emax + 1:  # k * 2**u >= 2**(emax + 1)
            return math.inf
        shift = max(k.bit_length() - 53, 0)  # only zeros below: k has at most M+1 bits
        return math.ldexp(float(k >> shift), u + shift)

    def _quantum(self, e: int) -> int:
        return max(e, self.fmt.emin) - self.fmt.frac_bits

    def nearest(self, n: int, d: int) -> float:
        if n == 0:
            return 0.0
        u = self._quantum(_floor_log2(n, d))
        num, den = _scaled(n, d, -u)  # (n/d) / 2**u
        k = num // den
        return self._finish(k, u, _cmp(2 * num, (2 * k + 1) * den))

    def nearest_sqrt(self, n: int, d: int) -> float:
        if n == 0:
            return 0.0
        u = self._quantum(_floor_log2(n, d) // 2)
        num, den = _scaled(n, d, -2 * u)  # (n/d) / 4**u
        k = math.isqrt(num // den)
        return self._finish(k, u, _cmp(4 * num, (2 * k + 1) ** 2 * den))


def _cmp(x: int, y: int) -> int:
    return (x > y) - (x < y)


def _scaled(n: int, d: int, k: int) -> tuple[int, int]:
    return (n << k, d) if k >= 0 else (n, d << -k)


def _floor_log2(n: int, d: int) -> int:
    e = n.bit_length() - d.bit_length()
    num, den = _scaled(n, d, -e)
    return e if num >= den else e - 1


def rounder(fmt: FloatFormat) -> Grid | Binades:
    return Grid(fmt) if fmt.bits <= 16 else Binades(fmt)


def round_exact(fmt: FloatFormat, rnd: Grid | Binades, n: int, d: int, negative: bool,
                tininess: str = "after", sqrt: bool = False) -> float:
    """The exact value ``n/d >= 0`` (or its square root), of sign ``negative``, rounded to ``fmt``."""
    v = rnd.nearest_sqrt(n, d) if sqrt else rnd.nearest(n, d)
    if fmt.ftz:
        power = -2 * fmt.emin if sqrt else -fmt.emin  # exact < min normal: n * 2**-emin < d
        if (v < fmt.min_normal) if tininess == "after" else ((n << power) < d):
            v = 0.0
    return -v if negative else v


def read(fmt: FloatFormat, a: float) -> float:
    """An operand as the format reads it: subnormals as signed zero with ftz."""
    return math.copysign(0.0, a) if fmt.ftz and abs(a) < fmt.min_normal else a


def reference_op(fmt: FloatFormat, rnd: Grid | Binades, op: str, a: float, b: float = 0.0,
                 tininess: str = "after") -> float:
    """``a op b`` (or ``sqrt(a)``) on finite format values, exactly, rounded once."""
    a, b = read(fmt, a), read(fmt, b)
    sa, sb = math.copysign(1, a) < 0, math.copysign(1, b) < 0
    (na, da), (nb, db) = a.as_integer_ratio(), b.as_integer_ratio()
    if op == "sqrt":
        if na == 0:
            return a
        return math.nan if na < 0 else round_exact(fmt, rnd, na, da, False, tininess, sqrt=True)
    if op == "div" and nb == 0:
        return math.nan if na == 0 else (-math.inf if sa != sb else math.inf)
    if op in ("add", "sub"):
        if op == "sub":
            nb, sb = -nb, not sb
        n, d = na * db + nb * da, da * db
        negative = n < 0 or (n == 0 and sa and sb)
    else:
        n, d = (na * nb, da * db) if op == "mul" else (na * db, da * nb)
        negative = sa != sb
    return round_exact(fmt, rnd, abs(n), abs(d), negative, tininess)
