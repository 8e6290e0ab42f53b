"""Binary floating-point formats of any width, their correctly rounded arithmetic, and what
their operators cost in FPGA hardware.

- :mod:`.formats`: ``FloatFormat`` and ``parse("e5m10-ftz")``; aliases fp16 bf16 tf32 fp24 fp32 fp64.
- :mod:`.rounding`: float64 values to a format, vectorised on the bit pattern.
- :mod:`.ops`: + - * / sqrt of values in a format, correctly rounded for every format.
- :mod:`.cost`: latency, LUT, FF and DSP per operator and format, anchored on the device's
  measured half-precision units (``docs/precision.md``).
"""

from .formats import ALIASES, FloatFormat, FormatError, parse

__all__ = ["ALIASES", "FloatFormat", "FormatError", "parse"]
