"""What one floating-point operator costs on the device's FPGA, per format: a stated model.

Anchors: the original REND3R build's half-precision operators (the vendor's Floating-Point
Operator IP, synthesised out of context for the board's Artix-7 xc7a100t at its maximum
latency; figures from the original public repository's build log, copied in
:data:`FP16_ANCHORS`). Every other format scales each anchor by the ratio of a stated
shape, ``figure(op, fmt) = anchor(op) * shape(op, fmt) / shape(op, e5m10)``, so e5m10
reproduces the anchors exactly. With ``p = M + 1`` significand bits and ``E`` exponent bits:

- add/sub: two shifters (align, normalise) and a leading-zero counter, each ``log2 p``
  levels deep with a register per level at maximum latency: latency ``8 + 3 log2(p/11)``;
  LUTs linear in the datapath, ``3p + 2E``; FFs that datapath times the latency.
- multiply: the significand product on 25x18 DSP48E1 tiles (unsigned 24x17 each),
  ``ceil(p/24) * ceil(p/17)`` DSPs, their partial products summed in the DSP cascade;
  latency ``6 + 2 ceil(log2 tiles)`` (two cycles per level of that sum); LUTs ``E + 2p``
  (exponent, normalisation and rounding in the fabric); FFs that times the latency.
- divide, square root: radix-2 digit recurrence, one result bit per stage: latency
  ``p + 4``; LUTs and FFs quadratic, ``p (p + 2)`` (one ``p+2``-bit adder and remainder
  register per stage), plus ``E`` LUTs and ``E (p + 4)`` FFs of exponent pipeline.
- compare: latency 2; LUTs and FFs linear in the word, ``1 + E + M``.
- convert (float to the device's 13-bit fixed point): one shifter over ``p + 13`` bits plus
  exponent logic: latency ``5 + log2((p + 13)/24)``; LUTs ``p + E + 13``; FFs times latency.

Latencies are rounded to whole cycles (at least 1), resources to whole units.
``docs/precision.md`` says how far to trust it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .formats import FloatFormat

OPERATORS = ("add", "sub", "mul", "div", "sqrt", "compare", "convert")
FIXED_BITS = 13  # the device's lighting converter: float to 13-bit fixed point


@dataclass(frozen=True)
class OperatorCost:
    """One pipelined operator: latency in cycles and its LUTs, flip-flops and DSP48E1 slices."""

    latency: int
    lut: int
    ff: int
    dsp: int


# Measured, e5m10 with the vendor IP on xc7a100t (original repository's build log).
FP16_ANCHORS: dict[str, OperatorCost] = {
    "add": OperatorCost(8, 185, 238, 0),
    "mul": OperatorCost(6, 54, 96, 1),
    "div": OperatorCost(15, 228, 381, 0),
    "sqrt": OperatorCost(15, 135, 259, 0),
    "compare": OperatorCost(2, 36, 12, 0),
    "convert": OperatorCost(5, 79, 101, 0),
}
_FP16 = FloatFormat(5, 10)


def _tiles(p: int) -> int:
    return math.ceil(p / 24) * math.ceil(p / 17)


def _shape(op: str, fmt: FloatFormat) -> tuple[float, float, float, float]:
    """Unscaled (latency, LUT, FF, DSP) of ``op`` in ``fmt``: the model's functional forms."""
    p, e = fmt.frac_bits + 1, fmt.exp_bits
    if op == "add":
        latency = 8 + 3 * math.log2(p / 11)
        datapath = 3 * p + 2 * e
        return latency, datapath, datapath * latency, 0
    if op == "mul":
        tiles = _tiles(p)
        latency = 6 + 2 * math.ceil(math.log2(tiles))
        logic = e + 2 * p
        return latency, logic, logic * latency, tiles
    if op in ("div", "sqrt"):
        stages = p * (p + 2)
        return p + 4, stages + e, stages + e * (p + 4), 0
    if op == "compare":
        return 2, fmt.bits, fmt.bits, 0
    if op == "convert":
        latency = 5 + math.log2((p + FIXED_BITS) / 24)
        logic = p + e + FIXED_BITS
        return latency, logic, logic * latency, 0
    raise ValueError(f"unknown operator {op!r}; expected one of {', '.join(OPERATORS)}")


def operator_cost(op: str, fmt: FloatFormat) -> OperatorCost:
    """The modelled cost of one ``op`` unit (see :data:`OPERATORS`) in format ``fmt``."""
    base = "add" if op == "sub" else op
    shape, anchor_shape = _shape(base, fmt), _shape(base, _FP16)
    anchor = FP16_ANCHORS[base]
    latency = max(1, round(shape[0]))
    lut, ff = (round(a * s / s0) for a, s, s0 in zip((anchor.lut, anchor.ff), shape[1:3], anchor_shape[1:3]))
    return OperatorCost(latency, lut, ff, int(shape[3]))
