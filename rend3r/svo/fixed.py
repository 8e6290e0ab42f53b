"""16.16 fixed-point helpers (the thesis's number format, Chapter 6.2).

Values are held in numpy integer arrays (int32 for the traversal state, int64 where a
product or a sum could leave the int32 range). ``ONE`` is 1.0.
"""

from __future__ import annotations

import numpy as np

FRAC_BITS = 16
ONE = 1 << FRAC_BITS
INT32_MIN = -(1 << 31)
INT32_MAX = (1 << 31) - 1
#: Direction components are clamped to at least this magnitude (Chapter 6.2).
MIN_DIR = 2.0**-10


def to_fixed(x: np.ndarray | float) -> np.ndarray:
    """Round float values to the nearest 16.16 value; raise if any leaves the int32 range."""
    scaled = np.rint(np.asarray(x, dtype=np.float64) * ONE)
    if not np.all(np.isfinite(scaled)):
        raise OverflowError("non-finite value cannot be converted to 16.16")
    if scaled.size and (scaled.min() < INT32_MIN or scaled.max() > INT32_MAX):
        raise OverflowError("value outside the 16.16 range [-32768, 32768)")
    return scaled.astype(np.int32)


def half(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Arithmetic shift right by one: (x >> 1, the discarded low bit) as in the hardware."""
    return x >> 1, x & 1


def clamp_direction(d: np.ndarray) -> np.ndarray:
    """Clamp each component to |d| >= 2^-10 keeping its sign (0 counts as positive)."""
    d = np.asarray(d, dtype=np.float64)
    sign = np.where(d < 0, -1.0, 1.0)
    return np.where(np.abs(d) < MIN_DIR, sign * MIN_DIR, d)
