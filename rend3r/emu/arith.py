"""Working-precision arithmetic for the emulator's datapaths.

One :class:`Arith` per precision; the raytracer and rasterizer are written once against it.
Every operation rounds its result to the working format, as one hardware unit would:

- ``fp16``: each result is computed in float32 and rounded to float16 (nearest even).
  float32 carries 24 >= 2*11 + 2 significand bits, so for + - * / and sqrt this double
  rounding is innocuous (Figueroa 1995): the result equals a correctly rounded float16
  operation. With ``ftz`` (the vendor IP's treatment) subnormal results and loaded
  subnormal values become signed zero, so no operation ever sees a subnormal input.
- ``fp32`` / ``fp64``: native numpy arithmetic in that format (``ftz`` does not apply).
- any other format ``eEmM`` (:mod:`rend3r.precision`): values held in float64, each
  operation correctly rounded to the format (:mod:`rend3r.precision.ops`), ``ftz``
  flushing results below the smallest normal number (tininess after rounding, as fp16).
  ``e5m10``, ``e8m23`` and ``e11m52`` are fp16, fp32 and fp64 themselves. ``tininess``
  ``"before"`` (a device quirk) flushes results whose unrounded value is below the
  smallest normal, so fp16 then runs as such a format too.
- per stage (``stages``, :mod:`rend3r.precision.stages`): each stage of the raytrace
  datapath in its own format, the base precision for the others. An operation rounds its
  operands to its stage's format (the converter a value crosses between stages), then
  computes correctly rounded in it; scene values stay exact float16 until an operation
  reads them. Values are held in float64.

Arrays are held as float32 for fp16 and fp32 (fp16 values are exact in float32), float64
otherwise. Overflow gives infinities and invalid operations NaN, silently here: callers
decide what a non-finite value means (the raytracer counts such rays as misses).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property, lru_cache
from typing import Literal

import numpy as np

from ..precision import ops
from ..precision.formats import FloatFormat, FormatError, Tininess, parse
from ..precision.stages import current_stage, stage_text

#: A working precision: "fp16", "fp32", "fp64" or another format's name ("e8m7").
Precision = str
#: The precisions with kernels of their own; any other format runs the format kernels.
PRECISIONS: tuple[Precision, ...] = ("fp16", "fp32", "fp64")
_NATIVE = {(5, 10): "fp16", (8, 23): "fp32", (11, 52): "fp64"}
_NATIVE_BITS = {"fp16": (np.float16, np.uint16), "fp32": (np.float32, np.uint32), "fp64": (np.float64, np.uint64)}
_FP16_MIN_NORMAL = np.float32(2.0**-14)


def precision_name(text: str) -> Precision:
    """The canonical name of a ``--precision`` value: an alias or ``eEmM``; fp16, fp32 and
    fp64 for their own formats. ValueError naming what is wrong otherwise."""
    if "-" in text:
        raise ValueError(f"bad precision {text!r}: give the subnormal mode with --subnormals, not in the name")
    try:
        fmt = parse(text)
    except FormatError as exc:
        raise ValueError(str(exc)) from None
    return _NATIVE.get((fmt.exp_bits, fmt.frac_bits), fmt.name)


@dataclass(frozen=True)
class Arith:
    """Rounded arithmetic in one working precision."""

    precision: Precision = "fp16"
    ftz: bool = True
    tininess: Tininess = "after"  # with ftz: a result is tiny judged after rounding, or before
    stages: tuple[tuple[str, Precision], ...] = ()  # (stage, precision) differing from the base (make_arith)

    @cached_property
    def format(self) -> FloatFormat:
        """The working format (fp32 and fp64 never flush); the base format when staged."""
        return self._format_of(self.precision)

    def _format_of(self, precision: Precision) -> FloatFormat:
        ftz = self.ftz and precision not in ("fp32", "fp64")
        return parse(precision, "ftz" if ftz else "ieee")

    @cached_property
    def stage_formats(self) -> dict[str, FloatFormat]:
        """Each listed stage's format (the others use :attr:`format`)."""
        return {stage: self._format_of(p) for stage, p in self.stages}

    def stage_precision(self, stage: str | None) -> Precision:
        """The precision of a stage (None: outside the stages, the base)."""
        return dict(self.stages).get(stage or "", self.precision)

    @cached_property
    def native(self) -> bool:
        """fp16, fp32 or fp64 as the device's IP rounds them: kernels of their own, float32
        or float64 arrays (fp16 judging tininess before rounding runs as any other format,
        and so does any per-stage map)."""
        return (not self.stages and self.precision in PRECISIONS
                and (self.tininess == "after" or not self.format.ftz))

    def _here(self) -> FloatFormat:
        """The format of the stage the current operation is made in."""
        return self.stage_formats.get(current_stage(3) or "", self.format)

    @cached_property
    def dtype(self) -> type[np.floating]:
        return np.float32 if self.native and self.precision != "fp64" else np.float64

    @cached_property
    def unit_roundoff(self) -> float:
        """Half an ulp of 1: the largest relative error of one rounding (normal range), as
        the culling bounds use it. Per stage: 4 times the largest of the formats', since an
        operation may round both operands on entering its stage and then its result
        ((1 + u)**3 - 1 < 4u)."""
        if not self.stages:
            return self.format.unit_roundoff
        return 4 * max(f.unit_roundoff for f in (self.format, *self.stage_formats.values()))

    @cached_property
    def tiny(self) -> float:
        """The smallest normal number (per stage: the largest of the formats'): below it
        results flush or lose relative precision."""
        return max(f.min_normal for f in (self.format, *self.stage_formats.values()))

    @cached_property
    def overflow(self) -> float:
        """The overflow threshold (per stage: the largest of the formats'), which the
        culling bounds take as a limit of any finite product."""
        return max(f.overflow for f in (self.format, *self.stage_formats.values()))

    @property
    def label(self) -> str:
        extra = f" [{stage_text(self.stages)}]" if self.stages else ""
        if self.precision in ("fp32", "fp64"):
            return self.precision + extra
        if self.ftz and self.tininess == "before":
            return f"{self.precision}-ftz-before{extra}"
        return f"{self.precision}-{'ftz' if self.ftz else 'ieee'}{extra}"

    def bits(self, value: float, stage: str | None = None) -> tuple[int, int]:
        """A working-precision value's bit pattern in the format of its stage (None: the
        working format; NaN: the quiet NaN of its sign, fp32 and fp64 as they hold it),
        and the pattern's width in hex digits."""
        precision = self.stage_precision(stage)
        if precision in _NATIVE_BITS:
            ftype, itype = _NATIVE_BITS[precision]
            return int(np.asarray(value, dtype=ftype).view(itype)), np.dtype(itype).itemsize * 2
        f, v = self.stage_formats.get(stage or "", self.format), float(value)
        top = (1 << f.exp_bits) - 1
        if math.isnan(v):
            e, m = top, 1 << (f.frac_bits - 1)
        elif math.isinf(v):
            e, m = top, 0
        elif abs(v) >= f.min_normal:
            mant, exp = math.frexp(abs(v))  # |v| = mant * 2**exp, mant in [0.5, 1)
            e, m = exp - 1 + f.bias, int(math.ldexp(mant * 2 - 1, f.frac_bits))
        else:  # zero or subnormal: multiples of the least subnormal
            e, m = 0, int(math.ldexp(abs(v), f.frac_bits - f.emin))
        return (int(math.copysign(1, v) < 0) << (f.bits - 1)) | (e << f.frac_bits) | m, -(-f.bits // 4)

    def bits_array(self, values: np.ndarray, stage: str | None = None) -> tuple[np.ndarray, int]:
        """:meth:`bits` of every value of an array at once: the patterns (uint64, flattened)
        and their width in hex digits."""
        precision = self.stage_precision(stage)
        v = np.asarray(values).reshape(-1)
        if precision in _NATIVE_BITS:
            ftype, itype = _NATIVE_BITS[precision]
            with np.errstate(all="ignore"):
                return v.astype(ftype).view(itype).astype(np.uint64), np.dtype(itype).itemsize * 2
        f = self.stage_formats.get(stage or "", self.format)
        a = np.abs(v.astype(np.float64))
        with np.errstate(all="ignore"):
            mant, exp = np.frexp(a)  # a = mant * 2**exp, mant in [0.5, 1)
            normal = a >= f.min_normal
            # zero and subnormals: multiples of the least subnormal
            m = np.where(normal, np.ldexp(mant * 2 - 1, f.frac_bits), np.ldexp(a, f.frac_bits - f.emin))
        e = np.where(normal, exp - 1 + f.bias, 0)
        special = ~np.isfinite(a)
        e[special], m[special] = (1 << f.exp_bits) - 1, 0
        m[np.isnan(a)] = 1 << (f.frac_bits - 1)
        sign = np.signbit(v).astype(np.uint64) << np.uint64(f.bits - 1)
        return sign | (e.astype(np.uint64) << np.uint64(f.frac_bits)) | m.astype(np.uint64), -(-f.bits // 4)

    def round(self, x: np.ndarray | float) -> np.ndarray:
        """Round values (already in or above working precision) to the working format (the
        current stage's, when staged)."""
        if self.stages:
            return self._here().round(np.asarray(x, dtype=np.float64), tininess=self.tininess)
        if not self.native:
            return self.format.round(np.asarray(x, dtype=np.float64), tininess=self.tininess)
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
        if not self.native:
            return self._binary(ops.add, a, b)
        with np.errstate(all="ignore"):
            return self.round(np.add(a, b, dtype=self.dtype))

    def sub(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        if not self.native:
            return self._binary(ops.sub, a, b)
        with np.errstate(all="ignore"):
            return self.round(np.subtract(a, b, dtype=self.dtype))

    def mul(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        if not self.native:
            return self._binary(ops.mul, a, b)
        with np.errstate(all="ignore"):
            return self.round(np.multiply(a, b, dtype=self.dtype))

    def div(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        if not self.native:
            return self._binary(ops.div, a, b)
        with np.errstate(all="ignore"):
            return self.round(np.divide(a, b, dtype=self.dtype))

    def sqrt(self, a: np.ndarray) -> np.ndarray:
        if not self.native:
            f = self._here() if self.stages else self.format
            return ops.sqrt(f, self._enter(f, a), tininess=self.tininess)
        with np.errstate(all="ignore"):
            return self.round(np.sqrt(np.asarray(a, dtype=self.dtype)))

    def _binary(self, op, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        if not self.stages:
            return op(self.format, a, b, tininess=self.tininess)
        f = self._here()
        return op(f, self._enter(f, a), self._enter(f, b), tininess=self.tininess)

    def _enter(self, f: FloatFormat, a: np.ndarray) -> np.ndarray:
        """An operand through the converter into the stage's format (staged only)."""
        return f.round(np.asarray(a, dtype=np.float64), tininess=self.tininess) if self.stages else a

    def neg(self, a: np.ndarray) -> np.ndarray:
        """Negation flips the sign bit: exact in every format."""
        return np.negative(np.asarray(a, dtype=self.dtype))

    def from_bits(self, bits: np.ndarray | int) -> np.ndarray:
        """float16 bit patterns (as stored by the ISA) to working-precision values."""
        h = np.asarray(bits, dtype=np.uint16).view(np.float16)
        if self.stages:  # exact: each operation converts what it reads
            return h.astype(np.float64)
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


@lru_cache(maxsize=64)
def make_arith(precision: Precision = "fp16", subnormals: Literal["ftz", "ieee"] = "ftz",
               tininess: Tininess = "after", stages: tuple[tuple[str, Precision], ...] = ()) -> Arith:
    """The arithmetic for a ``--precision`` / ``--subnormals`` pair and a per-stage map
    (``--stage-precision``; stages in the base precision are dropped, so a uniform map is
    the plain working precision). ValueError for a bad name. The same arguments give the
    same (immutable) object, so what it caches outlives a frame."""
    base = precision_name(precision)
    differing = tuple((s, p) for s, p in ((s, precision_name(p)) for s, p in stages) if p != base)
    return Arith(base, subnormals == "ftz", tininess, differing)
