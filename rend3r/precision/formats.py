"""Binary floating-point formats ``eEmM``: E exponent bits, M fraction bits, IEEE 754 layout.

A :class:`FloatFormat` names a format the way the vendor's floating-point IP is configured
(any exponent width 2..11 and fraction width 1..52 here, so every value is a float64) and how
it treats subnormal numbers: ``ieee`` keeps them (gradual underflow), ``ftz`` reads
subnormal inputs as signed zero and flushes tiny results to signed zero, as the device's
half-precision units do. Values are held in float64 arrays; :meth:`FloatFormat.round`
rounds float64 values to the format (:mod:`rend3r.precision.rounding`).

>>> f = parse("e5m10-ftz")
>>> f.name, f.max, f.min_normal, f.bits
('e5m10', 65504.0, 6.103515625e-05, 16)
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Literal

import numpy as np

Subnormals = Literal["ftz", "ieee"]
Tininess = Literal["after", "before"]
SUBNORMAL_MODES: tuple[Subnormals, ...] = ("ftz", "ieee")
EXP_BITS = range(2, 12)
FRAC_BITS = range(1, 53)
ALIASES: dict[str, tuple[int, int]] = {
    "fp16": (5, 10),
    "bf16": (8, 7),
    "tf32": (8, 10),
    "fp24": (7, 16),
    "fp32": (8, 23),
    "fp64": (11, 52),
}
_SPEC = re.compile(r"e(?P<e>\d{1,4})m(?P<m>\d{1,4})")  # widths checked below; few digits: no huge ints


class FormatError(ValueError):
    """A format string or width that names no supported format."""


@dataclass(frozen=True)
class FloatFormat:
    """A binary floating-point format: 1 sign bit, ``exp_bits`` exponent bits, ``frac_bits``
    stored fraction bits (the significand has ``frac_bits + 1``), and a subnormal mode."""

    exp_bits: int
    frac_bits: int
    subnormals: Subnormals = "ieee"

    def __post_init__(self) -> None:
        if self.exp_bits not in EXP_BITS:
            raise FormatError(f"exponent bits {self.exp_bits} out of range {EXP_BITS[0]}..{EXP_BITS[-1]}")
        if self.frac_bits not in FRAC_BITS:
            raise FormatError(f"fraction bits {self.frac_bits} out of range {FRAC_BITS[0]}..{FRAC_BITS[-1]}")
        if self.subnormals not in SUBNORMAL_MODES:
            raise FormatError(f"subnormal mode {self.subnormals!r} must be ftz or ieee")

    @property
    def name(self) -> str:
        """``eEmM``, without the subnormal mode."""
        return f"e{self.exp_bits}m{self.frac_bits}"

    def __str__(self) -> str:
        return f"{self.name}-{self.subnormals}"

    @property
    def ftz(self) -> bool:
        return self.subnormals == "ftz"

    @property
    def bits(self) -> int:
        """Storage width: sign, exponent and fraction."""
        return 1 + self.exp_bits + self.frac_bits

    @property
    def bias(self) -> int:
        return (1 << (self.exp_bits - 1)) - 1

    @property
    def emax(self) -> int:
        """Exponent of the largest binade."""
        return self.bias

    @property
    def emin(self) -> int:
        """Exponent of the smallest normal binade."""
        return 1 - self.bias

    @property
    def max(self) -> float:
        """The largest finite value."""
        return float(np.ldexp(2.0 - 2.0**-self.frac_bits, self.emax))

    @property
    def overflow(self) -> float:
        """The overflow threshold: the least magnitude that rounds to infinity, the largest
        finite value plus half its ulp (inf where float64 cannot hold it)."""
        with np.errstate(over="ignore"):
            return float(np.ldexp(2.0 - 2.0**-(self.frac_bits + 1), self.emax))

    @property
    def min_normal(self) -> float:
        return float(np.ldexp(1.0, self.emin))

    @property
    def min_subnormal(self) -> float:
        """The smallest subnormal of the encoding (an ftz format flushes it to zero)."""
        return float(np.ldexp(1.0, self.emin - self.frac_bits))

    @property
    def unit_roundoff(self) -> float:
        """Half an ulp of 1: the largest relative error of one rounding in the normal range."""
        return float(np.ldexp(1.0, -self.frac_bits - 1))

    def round(self, x: np.ndarray | float, tininess: Tininess = "after") -> np.ndarray:
        """float64 values rounded to this format, nearest even, as float64.

        Overflow gives signed infinity, NaN stays a (quiet) NaN. With ``ftz``, results below
        the smallest normal become signed zero: judged on the value rounded to the format's
        grid (``tininess="after"``) or on the value before rounding (``"before"``).
        """
        from .rounding import round_to_format

        return round_to_format(self, x, tininess=tininess)


def parse(text: str, subnormals: Subnormals = "ieee") -> FloatFormat:
    """A format from ``eEmM`` or an alias (``fp16`` ``bf16`` ``tf32`` ``fp24`` ``fp32`` ``fp64``),
    optionally suffixed ``-ftz`` or ``-ieee`` (which overrides ``subnormals``).

    Raises :class:`FormatError` naming the part that is wrong and the allowed values.
    """
    spec = text.strip().lower()
    shown = repr(text if len(text) <= 40 else text[:37] + "...")  # what errors quote of it
    base, _, mode = spec.partition("-")
    if mode:
        if mode not in SUBNORMAL_MODES:
            raise FormatError(f"bad format {shown}: subnormal mode {mode[:12]!r} must be ftz or ieee")
        subnormals = mode  # type: ignore[assignment]
    if base in ALIASES:
        e, m = ALIASES[base]
    else:
        match = _SPEC.fullmatch(base)
        if match is None:
            raise FormatError(
                f"bad format {shown}: expected eEmM (E exponent bits {EXP_BITS[0]}..{EXP_BITS[-1]}, "
                f"M fraction bits {FRAC_BITS[0]}..{FRAC_BITS[-1]}, e.g. e5m10) or one of "
                f"{', '.join(ALIASES)}, optionally with -ftz or -ieee"
            )
        e, m = int(match["e"]), int(match["m"])
    try:
        return FloatFormat(e, m, subnormals)
    except FormatError as err:
        raise FormatError(f"bad format {shown}: {err}") from None
