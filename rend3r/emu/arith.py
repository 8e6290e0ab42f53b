"""Working-precision arithmetic for the emulator's datapaths.

One :class:`Arith` per precision; the raytracer and rasterizer are written once against it.
Every operation rounds its result to the working format, as one hardware unit would:

- ``fp16``: each result is computed in float32 and rounded to float16 (nearest even).
  float32 carries 24 >= 2*11 + 2 significand bits, so for + - * / and sqrt this double
  rounding is innocuous (Figueroa 1995): the result equals a correctly rounded float16
  operation. With ``ftz`` (the vendor IP's treatment) subnormal results and loaded
  subnormal values become signed zero, so no operation ever sees a subnormal input.
- ``fp32`` / ``fp64``: native numpy arithmetic in that format (``ftz`` does not apply).

Arrays are held as float32 for fp16 and fp32 (fp16 values are exact in float32), float64
for fp64. Overflow gives infinities and invalid operations NaN, silently here: callers
decide what a non-finite value means (the raytracer counts such rays as misses).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

Precision = Literal["fp16", "fp32", "fp64"]
PRECISIONS: tuple[Precision, ...] = ("fp16", "fp32", "fp64")
_FP16_MIN_NORMAL = np.float32(2.0**-14)


@dataclass(frozen=True)
class Arith:
    """Rounded arithmetic in one working precision."""

    precision: Precision = "fp16"
    ftz: bool = True

    @property
    def dtype(self) -> type[np.floating]:
        return np.float64 if self.precision == "fp64" else np.float32

    @property
    def unit_roundoff(self) -> float:
        """Half an ulp of 1: the largest relative error of one rounding (normal range)."""
        return {"fp16": 2.0**-11, "fp32": 2.0**-24, "fp64": 2.0**-53}[self.precision]

    @property
    def tiny(self) -> float:
        """The smallest normal number: below it results flush or lose relative precision."""
        return {"fp16": 2.0**-14, "fp32": 2.0**-126, "fp64": 2.0**-1022}[self.precision]

    @property
    def label(self) -> str:
        if self.precision == "fp16":
            return f"fp16-{'ftz' if self.ftz else 'ieee'}"
        return self.precision

    def round(self, x: np.ndarray | float) -> np.ndarray:
        """Round values (already in or above working precision) to the working format."""
        if self.precision != "fp16":
            return np.asarray(x, dtype=self.dtype)
        a = np.asarray(x)
        if a.dtype == np.float32 and a.size and a.ndim:
            return _round16_f32(a, self.ftz)
        with np.errstate(over="ignore", invalid="ignore"):
            r = a.astype(np.float16).astype(np.float32)  # direct, so no double rounding
        if self.ftz:
            r = np.where(np.abs(r) < _FP16_MIN_NORMAL, np.copysign(np.float32(0), r), r)
        return r

    def const(self, value: float) -> np.ndarray:
        """A scalar constant in working precision (0-d array)."""
        return self.round(np.float64(value))

    def add(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        with np.errstate(all="ignore"):
            return self.round(np.add(a, b, dtype=self.dtype))

    def sub(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        with np.errstate(all="ignore"):
            return self.round(np.subtract(a, b, dtype=self.dtype))

    def mul(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        with np.errstate(all="ignore"):
            return self.round(np.multiply(a, b, dtype=self.dtype))

    def div(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        with np.errstate(all="ignore"):
            return self.round(np.divide(a, b, dtype=self.dtype))

    def sqrt(self, a: np.ndarray) -> np.ndarray:
        with np.errstate(all="ignore"):
            return self.round(np.sqrt(np.asarray(a, dtype=self.dtype)))

    def neg(self, a: np.ndarray) -> np.ndarray:
        """Negation flips the sign bit: exact in every format."""
        return np.negative(np.asarray(a, dtype=self.dtype))

    def from_bits(self, bits: np.ndarray | int) -> np.ndarray:
        """float16 bit patterns (as stored by the ISA) to working-precision values."""
        h = np.asarray(bits, dtype=np.uint16).view(np.float16)
        return self.round(h.astype(self.dtype))


_SIGN = np.uint32(0x80000000)
_MIN_NORMAL_BITS = 0x38800000  # 2**-14 as float32 bits
_FTZ_UP_BITS = 0x387FE000  # 2**-14 - 2**-25: the subnormal grid rounds it up to 2**-14
_OVERFLOW_BITS = 0x477FF000  # 65520: rounds to infinity
_INF_BITS = 0x7F800000
_OVERFLOW_VALUE = np.float32(65520.0)


def _round16_f32(a: np.ndarray, ftz: bool) -> np.ndarray:
    """float32 -> nearest-even float16 value, held in float32, by integer operations.

    Rounds the significand to 11 bits in place (normal float16 range), then fixes the rare
    lanes that overflow, are NaN, or fall in the subnormal range. Equal, bit for bit, to
    converting through numpy's float16 (tested exhaustively in the sign/exponent bands).
    """
    b = a.view(np.uint32)
    r = np.right_shift(b, np.uint32(13))
    r &= np.uint32(1)
    r += np.uint32(0xFFF)
    r += b
    r &= np.uint32(0xFFFFE000)
    with np.errstate(invalid="ignore"):
        hi, lo = a.max(), a.min()  # NaN propagates into both
    if not (-_OVERFLOW_VALUE < lo and hi < _OVERFLOW_VALUE):
        ab = b & np.uint32(0x7FFFFFFF)
        big = (ab >= _OVERFLOW_BITS) & (ab <= _INF_BITS)
        r[big] = (b[big] & _SIGN) | np.uint32(_INF_BITS)
        nan = ab > _INF_BITS
        r[nan] = b[nan]
    mag = np.left_shift(r, np.uint32(1))  # sign dropped; zero wraps to the top below
    mag -= np.uint32(1)
    if mag.min() < np.uint32((_MIN_NORMAL_BITS << 1) - 1):  # some nonzero result below 2**-14
        ab = b & np.uint32(0x7FFFFFFF)
        small = (ab - np.uint32(1)) < np.uint32(_MIN_NORMAL_BITS - 1)
        if ftz:
            tiny = small & (ab < _FTZ_UP_BITS)
            np.copyto(r, b & _SIGN, where=tiny)
            up = small & ~tiny
            if up.any():
                r[up] = (b[up] & _SIGN) | np.uint32(_MIN_NORMAL_BITS)
        else:
            m16 = np.abs(a[small]).astype(np.float16).astype(np.float32)
            r[small] = m16.view(np.uint32) | (b[small] & _SIGN)
    return r.view(np.float32)


def make_arith(precision: Precision = "fp16", subnormals: Literal["ftz", "ieee"] = "ftz") -> Arith:
    """The arithmetic for a ``--precision`` / ``--subnormals`` pair."""
    if precision not in PRECISIONS:
        raise ValueError(f"unknown precision {precision!r}; expected one of {', '.join(PRECISIONS)}")
    return Arith(precision, subnormals == "ftz")
