"""Round float64 values to a :class:`~rend3r.precision.formats.FloatFormat`, vectorised.

Every value of a format with at most 11 exponent and 52 fraction bits is a float64, so
rounding is done on the float64 bit pattern: dropping ``d`` low bits of the pattern with
round-to-nearest-even is ``(bits + 2**(d-1) - 1 + lsb) & ~(2**d - 1)``, where ``lsb`` is the
lowest kept bit; a carry out of the fraction steps the exponent, which is the right answer
at binade boundaries and turns the largest binade into infinity. In the format's normal
range ``d = 52 - M``; below the smallest normal the format's grid is fixed-point (spacing
``2**(emin - M)``), so ``d`` grows by one per binade, and a value under half the smallest
subnormal rounds to zero. The rare lanes (subnormal range, overflow, NaN) are only worked
on when an array holds some.

A caller that knows on which side of a float64 value the exact result lies (the sign of
``exact - x``, see :mod:`rend3r.precision.ops`) passes it as ``toward``: at an exact
midpoint of the format's grid the tie then goes that way instead of to even.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

import numpy as np

from .formats import FloatFormat, Tininess

_ONE = np.uint64(1)
_SIGN = np.uint64(1 << 63)
_ABS = np.uint64((1 << 63) - 1)
_INF = np.uint64(0x7FF0000000000000)
_QUIET = np.uint64(1 << 51)
_WIDEST = 53  # bits dropped when a value lies in [q/2, q), q the smallest subnormal


def _bits(value: float) -> np.uint64:
    return np.float64(value).view(np.uint64)


@dataclass(frozen=True)
class _Grid:
    """Bit-level constants of one format's grid."""

    drop: int  # fraction bits dropped in the normal range: 52 - M
    emin_field: int  # float64 biased exponent of the smallest normal
    min_normal: np.uint64
    overflow: np.uint64  # 2**(emax + 1), or infinity's pattern for 11 exponent bits
    half_q: np.uint64  # half the smallest subnormal (meaningful when exp_bits < 11)
    q: np.uint64
    nan_keep: np.uint64  # the payload bits a NaN keeps


@cache
def _grid(exp_bits: int, frac_bits: int) -> _Grid:
    fmt = FloatFormat(exp_bits, frac_bits)
    drop = 52 - frac_bits
    overflow = _INF if fmt.emax == 1023 else _bits(float(np.ldexp(1.0, fmt.emax + 1)))
    half_q = _bits(fmt.min_subnormal / 2) if exp_bits < 11 else np.uint64(0)
    return _Grid(drop, fmt.emin + 1023, _bits(fmt.min_normal), overflow, half_q,
                 _bits(fmt.min_subnormal), _ABS & ~np.uint64((1 << drop) - 1))


def _small_drops(g: _Grid, mag: np.ndarray) -> np.ndarray:
    """Bits to drop below the smallest normal: 52 - M plus one per binade under it, capped
    where the value is under the smallest subnormal."""
    field = np.maximum(mag >> np.uint64(52), _ONE).astype(np.int64)
    return np.minimum(g.drop + np.maximum(g.emin_field - field, 0), _WIDEST).astype(np.uint64)


def _signed_toward(bits: np.ndarray, toward: np.ndarray) -> np.ndarray:
    """``sign(exact - x)`` as a direction on the magnitude: +1 larger, -1 smaller, 0 exact."""
    t = np.asarray(toward, dtype=np.int8)
    return np.where(bits & _SIGN != 0, -t, t)


def round_to_format(fmt: FloatFormat, x: np.ndarray | float, *, tininess: Tininess = "after",
                    toward: np.ndarray | None = None) -> np.ndarray:
    """float64 values rounded to ``fmt`` (see :meth:`FloatFormat.round`), as float64.

    ``toward`` (optional, int8 per lane): the sign of ``exact - x`` when ``x`` stands for an
    exact value it approximates; it breaks ties at midpoints and decides ``before``
    tininess at the smallest normal. Zero (or None) means ``x`` is exact.
    """
    if tininess not in ("after", "before"):
        raise ValueError(f"tininess {tininess!r} must be 'after' or 'before'")
    a = np.asarray(x, dtype=np.float64)
    shape = a.shape
    bits = a.reshape(-1).view(np.uint64)  # flat, so 0-d values index like arrays
    mag = bits & _ABS
    g = _grid(fmt.exp_bits, fmt.frac_bits)
    direction = None if toward is None else _signed_toward(bits, np.broadcast_to(toward, shape).reshape(-1))
    r = _round_normal(g, mag, direction)
    small = _nonzero_below(mag, g.min_normal)
    if small is not None:  # the format's subnormal range, lane by lane
        m = mag[small]
        rs = _round_small(g, m, None if direction is None else direction[small])
        if fmt.ftz:
            rs[(rs < g.min_normal) if tininess == "after" else (m < g.min_normal)] = 0
        r[small] = rs
    if fmt.ftz and tininess == "before" and direction is not None:
        r[(mag == g.min_normal) & (direction < 0)] = 0  # the exact value lies just below it
    if r.size and r.max() >= g.overflow:  # overflow, infinities or NaNs present
        r[r >= g.overflow] = _INF
        nan = mag > _INF
        r[nan] = (mag[nan] & g.nan_keep) | _QUIET
    r |= bits & _SIGN
    return r.view(np.float64).reshape(shape)


def _nonzero_below(mag: np.ndarray, limit: np.uint64) -> np.ndarray | None:
    """Indices of the magnitudes in (0, limit), or None when there are none (a common case
    checked in one pass: zero wraps to the top when one is subtracted)."""
    wrapped = mag - _ONE
    if not mag.size or wrapped.min() >= limit - _ONE:
        return None
    return np.flatnonzero(wrapped < limit - _ONE)


def _tie_bits(tie: np.ndarray, direction: np.ndarray | None) -> np.ndarray:
    if direction is None:
        return tie
    return np.where(direction > 0, _ONE, np.where(direction < 0, np.uint64(0), tie))


def _round_normal(g: _Grid, mag: np.ndarray, direction: np.ndarray | None) -> np.ndarray:
    """Every lane rounded as if in the format's normal range (a fresh array)."""
    drop = np.uint64(g.drop)
    if g.drop == 0:
        return mag.copy()
    r = np.right_shift(mag, drop)
    r &= _ONE  # the lowest kept bit: ties go to even
    r = _tie_bits(r, direction)
    r += ((_ONE << drop) >> _ONE) - _ONE
    r += mag
    r &= ~((_ONE << drop) - _ONE)
    return r


def _round_small(g: _Grid, mag: np.ndarray, direction: np.ndarray | None) -> np.ndarray:
    """Magnitudes below the smallest normal rounded to the subnormal grid (no flushing)."""
    drop = _small_drops(g, mag)
    tie = (mag >> drop) & _ONE
    # a kept part of just the hidden bit is odd; of nothing (under the smallest subnormal), even
    tie = np.where(drop == 52, (mag >> np.uint64(52)) != 0, tie).astype(np.uint64)
    tie = _tie_bits(np.where(drop == _WIDEST, np.uint64(0), tie), direction)
    r = (mag + ((_ONE << drop) >> _ONE) - _ONE + tie) & ~((_ONE << drop) - _ONE)
    r = np.where(drop == 0, mag, r)  # 11 exponent and 52 fraction bits: float64's own grid
    up = (mag > g.half_q) | ((mag == g.half_q) & (tie == _ONE))
    return np.where(drop == _WIDEST, np.where(up, g.q, np.uint64(0)), r)


def midpoints(fmt: FloatFormat, x: np.ndarray) -> np.ndarray:
    """Lanes where a finite ``x`` lies exactly halfway between two neighbours of ``fmt``'s grid
    (the largest finite value and 2**(emax+1) count as neighbours)."""
    a = np.asarray(x, dtype=np.float64)
    mag = a.reshape(-1).view(np.uint64) & _ABS
    g = _grid(fmt.exp_bits, fmt.frac_bits)
    if g.drop == 0:
        on_half = np.zeros(mag.shape, dtype=bool)
    else:
        low = mag & np.uint64((1 << g.drop) - 1)
        on_half = (low == np.uint64(1 << (g.drop - 1))) & (mag < _INF)
    small = _nonzero_below(mag, g.min_normal)
    if small is not None:
        m = mag[small]
        drop = _small_drops(g, m)
        half = (_ONE << drop) >> _ONE
        mid = np.where(drop == _WIDEST, m == g.half_q, ((m & ((_ONE << drop) - _ONE)) == half) & (half != 0))
        on_half[small] = mid
    return on_half.reshape(a.shape)
