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
from functools import lru_cache

import numpy as np

from .formats import FloatFormat, Tininess

_ONE = np.uint64(1)
_SIGN = np.uint64(1 << 63)
_ABS = np.uint64((1 << 63) - 1)
_INF = np.uint64(0x7FF0000000000000)
_QUIET = np.uint64(1 << 51)
_WIDEST = 53  # bits dropped when a value lies in [q/2, q), q the smallest subnormal


def _bits(value: float) -> np.uint64:
    return np.array(value, dtype=np.float64).view(np.uint64)[()]


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


@lru_cache(maxsize=None)
def _grid(exp_bits: int, frac_bits: int) -> _Grid:
    fmt = FloatFormat(exp_bits, frac_bits)
    drop = 52 - frac_bits
    overflow = _INF if fmt.emax == 1023 else _bits(float(np.ldexp(1.0, fmt.emax + 1)))
    half_q = _bits(fmt.min_subnormal / 2) if exp_bits < 11 else np.uint64(0)
    return _Grid(drop, fmt.emin + 1023, _bits(fmt.min_normal), overflow, half_q,
                 _bits(fmt.min_subnormal), _ABS & ~np.uint64((1 << drop) - 1))


def _drops(g: _Grid, mag: np.ndarray) -> np.uint64 | np.ndarray:
    """Bits to drop from each magnitude's pattern: a scalar while every value is normal in the
    format, else per lane (52 - M plus one per binade below the smallest normal, capped)."""
    if mag.size == 0 or mag.min() >= g.min_normal:
        return np.uint64(g.drop)
    field = np.maximum(mag >> np.uint64(52), _ONE).astype(np.int64)
    return np.minimum(g.drop + np.maximum(g.emin_field - field, 0), _WIDEST).astype(np.uint64)


def _signed_toward(bits: np.ndarray, toward: np.ndarray | None) -> np.ndarray | None:
    """``sign(exact - x)`` as a direction on the magnitude: +1 larger, -1 smaller, 0 exact."""
    if toward is None:
        return None
    t = np.broadcast_to(np.asarray(toward, dtype=np.int8), bits.shape)
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
    bits = a.view(np.uint64)
    mag = bits & _ABS
    g = _grid(fmt.exp_bits, fmt.frac_bits)
    drop = _drops(g, mag)
    direction = _signed_toward(bits, toward)
    r = _round_magnitudes(g, mag, drop, direction)
    if r.size and r.max() >= g.overflow:  # overflow, infinities or NaNs present
        r = np.where(r >= g.overflow, _INF, r)
        r = np.where(mag > _INF, (mag & g.nan_keep) | _QUIET, r)
    if fmt.ftz:
        r = _flush(g, mag, r, tininess, direction, below_normal=np.ndim(drop) > 0)
    return (r | (bits & _SIGN)).view(np.float64)


def _round_magnitudes(g: _Grid, mag: np.ndarray, drop: np.uint64 | np.ndarray,
                      direction: np.ndarray | None) -> np.ndarray:
    if np.ndim(drop) == 0 and drop == 0:
        return mag.copy()
    tie = (mag >> drop) & _ONE  # the lowest kept significand bit: ties go to even
    if np.ndim(drop) > 0:  # a kept part of just the hidden bit is odd; of nothing, even (zero)
        tie = np.where(drop == 52, (mag >> np.uint64(52)) != 0, tie).astype(np.uint64)
        tie = np.where(drop == _WIDEST, np.uint64(0), tie)
    if direction is not None:
        tie = np.where(direction > 0, _ONE, np.where(direction < 0, np.uint64(0), tie))
    half = (_ONE << drop) >> _ONE
    r = (mag + half - _ONE + tie) & ~((_ONE << drop) - _ONE)
    if np.ndim(drop) == 0:
        return r
    if g.drop == 0:  # 52 fraction bits: the normal range is float64's own
        r = np.where(drop == 0, mag, r)
    widest = drop == _WIDEST
    if widest.any():  # [0, q): zero or the smallest subnormal
        up = (mag > g.half_q) | ((mag == g.half_q) & (tie == _ONE))
        r = np.where(widest, np.where(up, g.q, np.uint64(0)), r)
    return r


def _flush(g: _Grid, mag: np.ndarray, r: np.ndarray, tininess: Tininess,
           direction: np.ndarray | None, below_normal: bool) -> np.ndarray:
    """Flush-to-zero: results tiny after rounding, or exact values tiny before it."""
    if tininess == "after":
        return np.where(r < g.min_normal, np.uint64(0), r) if below_normal else r
    tiny = mag < g.min_normal
    if direction is not None:  # x is the smallest normal, the exact value just below it
        tiny |= (mag == g.min_normal) & (direction < 0)
    return np.where(tiny, np.uint64(0), r)


def midpoints(fmt: FloatFormat, x: np.ndarray) -> np.ndarray:
    """Lanes where a finite ``x`` lies exactly halfway between two neighbours of ``fmt``'s grid
    (the largest finite value and 2**(emax+1) count as neighbours)."""
    a = np.asarray(x, dtype=np.float64)
    mag = a.view(np.uint64) & _ABS
    g = _grid(fmt.exp_bits, fmt.frac_bits)
    drop = _drops(g, mag)
    if np.ndim(drop) == 0 and drop == 0:
        return np.zeros(a.shape, dtype=bool)
    half = (_ONE << drop) >> _ONE
    on_half = ((mag & ((_ONE << drop) - _ONE)) == half) & (half != 0) & (mag < _INF)
    if np.ndim(drop) == 0:
        return on_half
    return np.where(drop == _WIDEST, mag == g.half_q, on_half)
