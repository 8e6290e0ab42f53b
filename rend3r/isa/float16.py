"""IEEE 754 binary16 conversions used by the encoder, assembler and disassembler.

Decimal literals are rounded to float16 *exactly* (round to nearest, ties to even) from
their decimal value, not through a float64 first, so no double rounding can occur.
"""

from __future__ import annotations

import functools
import math
import struct
from dataclasses import dataclass
from fractions import Fraction

MAX_FINITE = 65504.0
MIN_NORMAL = 2.0**-14
MIN_SUBNORMAL = 2.0**-24
#: Values at or above this magnitude round to infinity (halfway between 65504 and 65536).
OVERFLOW_THRESHOLD = 65520.0

_HALF_ULP_CACHE: dict[int, float] = {}


@dataclass(frozen=True)
class Rounded:
    """The float16 nearest to a literal, and what the rounding did to it."""

    bits: int
    value: float  # the float16's value (inf when it overflowed)
    overflow: bool  # |value| >= 65520: rounds to infinity
    underflow: bool  # nonzero literal rounded to (signed) zero
    relative_error: float  # |rounded - exact| / |exact|; 0 for an exact zero


def bits_to_float(bits: int) -> float:
    """The value of a float16 bit pattern (NaN and infinities included)."""
    return struct.unpack("<e", struct.pack("<H", bits & 0xFFFF))[0]


def float_to_bits(value: float) -> int:
    """Round a Python float to float16 (nearest even) and return the bit pattern.

    Rounding a float64 is exact except when the float64 itself came from rounding a
    decimal; use :func:`round_literal` for source literals.
    """
    try:
        return struct.unpack("<H", struct.pack("<e", value))[0]
    except OverflowError:  # |value| >= 65520 rounds to infinity
        return 0xFC00 if value < 0 else 0x7C00


def round_literal(text: str | Fraction | int | float, negative: bool = False) -> Rounded:
    """Round a numeric literal to float16, correctly, ties to even.

    ``text`` is a decimal or exponent literal (``"1.5e-3"``, ``"1_000.25"``), an exact
    Fraction or an int; ``negative`` negates it (so ``-0`` gives 0x8000).
    """
    exact = Fraction(text.replace("_", "")) if isinstance(text, str) else Fraction(text)
    if negative:
        exact = -exact
    neg = exact < 0 or (exact == 0 and negative)
    mag = abs(exact)
    if mag == 0:
        bits = 0x8000 if neg else 0
        return Rounded(bits, bits_to_float(bits), False, False, 0.0)
    approx = float(mag) if mag < 1e300 else math.inf
    if approx != math.inf and not _may_be_tie(approx):
        # float(mag) is correctly rounded to float64; since float16 ties are float64
        # values, the exact value and its float64 lie on the same side of every tie.
        bits = float_to_bits(approx)
    else:
        bits = _round_fraction(mag)
    if neg:
        bits |= 0x8000
    value = bits_to_float(bits)
    overflow = math.isinf(value)
    underflow = value == 0.0
    rel = 1.0 if (overflow or underflow) else float(abs(Fraction(abs(value)) - mag) / mag)
    return Rounded(bits, value, overflow, underflow, rel)


def _may_be_tie(x: float) -> bool:
    """True when x is exactly halfway between two float16 values (or at the overflow tie)."""
    m, e = math.frexp(x)  # x = m * 2**e, 0.5 <= m < 1
    # float16 spacing at x: 2**(e-11) for normals, 2**-24 in the subnormal range.
    ulp_exp = max(e - 11, -24)
    scaled = x / 2.0 ** (ulp_exp - 1)  # exact: power-of-two scaling
    return scaled == int(scaled) and int(scaled) % 2 == 1


def _round_fraction(mag: Fraction) -> int:
    """Round a positive Fraction to float16 bits, ties to even, with overflow to inf."""
    if mag >= Fraction(int(OVERFLOW_THRESHOLD)):
        return 0x7C00
    e = mag.numerator.bit_length() - mag.denominator.bit_length()
    if Fraction(2) ** e > mag:
        e -= 1
    ulp_exp = max(e - 10, -24)
    q = mag / Fraction(2) ** ulp_exp
    n = q.numerator // q.denominator
    rem = q - n
    if rem > Fraction(1, 2) or (rem == Fraction(1, 2) and n % 2 == 1):
        n += 1
    value = Fraction(n) * Fraction(2) ** ulp_exp
    if value >= 65536:
        return 0x7C00
    return float_to_bits(float(value))


def is_nan(bits: int) -> bool:
    return (bits & 0x7C00) == 0x7C00 and (bits & 0x03FF) != 0


def is_inf(bits: int) -> bool:
    return (bits & 0x7FFF) == 0x7C00


def is_subnormal(bits: int) -> bool:
    return (bits & 0x7C00) == 0 and (bits & 0x03FF) != 0


@functools.lru_cache(maxsize=None)  # 65,536 possible arguments
def shortest_repr(bits: int) -> str | None:
    """Shortest decimal that rounds back to ``bits``; None for NaN and infinities.

    Positional (``0.25``, ``65504.0``) unless scientific (``5.96e-08``) is shorter.
    """
    if is_nan(bits) or is_inf(bits):
        return None
    value = bits_to_float(bits)
    sign = "-" if bits & 0x8000 else ""
    if value == 0:
        return sign + "0.0"
    for places in range(5):  # float16 needs at most 5 significant digits
        found = _round_tripping(abs(value), places, bits & 0x7FFF)
        if found:
            mantissa, exp = found
            break
    digits, e10 = mantissa.replace(".", "").rstrip("0") or "0", int(exp)
    if e10 >= 0:
        whole = digits[: e10 + 1].ljust(e10 + 1, "0")
        positional = f"{whole}.{digits[e10 + 1:] or '0'}"
    else:
        positional = f"0.{'0' * (-e10 - 1)}{digits}"
    scientific = f"{digits[0]}.{digits[1:] or '0'}e{'-' if e10 < 0 else '+'}{abs(e10):02d}"
    if len(scientific) < len(positional):
        return sign + scientific.replace("e+", "e")
    return sign + positional


def _round_tripping(value: float, places: int, bits: int) -> tuple[str, str] | None:
    """The (mantissa, exponent) with ``places`` decimals nearest ``value`` that rounds to
    ``bits``: the correctly rounded one (Python's formatting rounds exactly, ties to even),
    else the nearer round-tripping neighbour (the float16 rounding interval is lopsided at
    powers of two)."""
    mantissa, exp = f"{value:.{places}e}".split("e")
    if _rounds_to(mantissa, exp, bits):
        return mantissa, exp
    n = int(mantissa.replace(".", ""))
    fits = [c for c in (n - 1, n + 1) if 10**places <= c < 10 ** (places + 1)]
    texts = [t for t in (_digits(c, places) for c in fits) if _rounds_to(t, exp, bits)]
    if not texts:
        return None
    exact = Fraction(value)
    return min(texts, key=lambda t: abs(Fraction(f"{t}e{exp}") - exact)), exp


def _digits(n: int, places: int) -> str:
    text = str(n)
    return text[0] + ("." + text[1:] if places else "")


def _rounds_to(mantissa: str, exp: str, bits: int) -> bool:
    approx = float(f"{mantissa}e{exp}")
    if _may_be_tie(approx):
        return round_literal(f"{mantissa}e{exp}").bits == bits
    return float_to_bits(approx) == bits
