"""Option parsing shared by the commands: image sizes ``WxH``, working precisions, thread counts,
memory budgets."""

from __future__ import annotations

import importlib
import os
import re

import click

#: Largest width or height any command renders or reads (bounds memory: 8192x8192 RGB565).
MAX_SIDE = 8192

def finite(lo: float, hi: float):
    """A click callback refusing NaN, infinities and values outside [lo, hi] (click's
    FloatRange lets NaN through: every comparison with it is false)."""

    def check(ctx, param, value: float | None) -> float | None:
        if value is not None and not lo <= value <= hi:  # also False for NaN
            raise click.BadParameter(f"{value} is not in the range {lo:g}..{hi:g}")
        return value

    return check


_SIZE = re.compile(r"\s*([0-9]+)\s*[xX]\s*([0-9]+)\s*", re.ASCII)


def parse_size(text: str, max_side: int = MAX_SIDE) -> tuple[int, int]:
    """``"WxH"`` -> (W, H), each side 1..``max_side``; ValueError with a clear reason otherwise."""
    m = _SIZE.fullmatch(text)
    if not m:
        raise ValueError(f"expected WIDTHxHEIGHT such as 512x384, not {text!r}")
    w, h = int(m[1]), int(m[2])
    if not (1 <= w <= max_side and 1 <= h <= max_side):
        raise ValueError(f"width and height must be 1..{max_side}, not {text!r}")
    return w, h


class SizeType(click.ParamType):
    """A click parameter type for ``WxH`` image sizes, each side 1..``max_side`` (bad values
    exit 2, as bad options do)."""

    name = "WxH"

    def __init__(self, max_side: int = MAX_SIDE) -> None:
        self.max_side = max_side

    def get_metavar(self, param, ctx=None) -> str:  # click < 8.2 passes no ctx
        return "WxH"

    def convert(self, value, param, ctx) -> tuple[int, int]:
        if isinstance(value, tuple):
            return value
        try:
            return parse_size(str(value), self.max_side)
        except ValueError as exc:
            self.fail(str(exc), param, ctx)


#: The shared instance: ``@click.option("--size", type=SIZE, default="512x384")``.
SIZE = SizeType()

#: The device's frame size, the default ``--size`` of every command that renders.
DEVICE_SIZE = "512x384"


class CheckedType(click.ParamType):
    """A value checked and made canonical by ``"module:function"`` (ValueError: the value is
    bad, exit 2), imported only when a value is converted, so ``--help`` stays fast."""

    def __init__(self, name: str, checker: str) -> None:
        self.name, self._checker = name, checker

    def convert(self, value, param, ctx) -> str:
        module, function = self._checker.split(":")
        check = getattr(importlib.import_module(module), function)
        try:
            return check(str(value))
        except ValueError as exc:
            self.fail(str(exc), param, ctx)


#: ``--precision FORMAT``: the emulator's working precision.
PRECISION = click.option(
    "--precision", type=CheckedType("FORMAT", "rend3r.emu.arith:precision_name"), default="fp16", show_default=True,
    help="Working precision: fp16 (the device), fp32, fp64, or any binary format eEmM (E exponent bits 2..11, "
         "M fraction bits 1..52) or alias bf16, tf32, fp24 (docs/precision.md).")

#: ``--stage-precision STAGE=FORMAT[,...]``: a format per stage of the raytrace datapath.
STAGE_PRECISION = click.option(
    "--stage-precision", type=CheckedType("STAGE=FORMAT,...", "rend3r.precision.stages:parse_stage_map"),
    default=None, metavar="STAGE=FORMAT,...",
    help="Formats of single stages of the raytrace datapath (the others use --precision): camera, transform, "
         "quadratic, discriminant, sqrt, distance, hit, lighting, colour; e.g. discriminant=e8m15,lighting=fp16 "
         "(docs/precision.md).")


#: ``--jobs N``: rendering threads (0, the default: every core this process may use).
JOBS = click.option("--jobs", type=click.IntRange(0, 256), default=0, show_default=True, metavar="N",
                    help="Rendering threads, 0 for every core: one frame each when a run has a frame "
                         "for every thread, else each frame split between them. The images do not depend on it.")


_BYTES = re.compile(r"\s*([0-9]{1,12}(?:\.[0-9]{1,6})?)\s*([KMGT]?)(?:i?B)?\s*", re.ASCII | re.IGNORECASE)
_UNITS = {"": 1, "K": 1 << 10, "M": 1 << 20, "G": 1 << 30, "T": 1 << 40}


def parse_bytes(text: str) -> int:
    """``"512M"``, ``"4G"``, ``"1.5GiB"``, ``"100000"`` -> bytes (binary units); ValueError otherwise."""
    m = _BYTES.fullmatch(text)
    if not m:
        raise ValueError(f"expected a size such as 512M or 4G, not {text!r}")
    value = int(float(m[1]) * _UNITS[m[2].upper()])
    if value < 1 << 20:
        raise ValueError(f"a memory budget below 1M cannot run anything, not {text!r}")
    return value


def default_memory() -> int:
    """Half of this machine's memory, and no more than this process's address-space limit
    allows (less 1 GiB for the interpreter, libraries and thread stacks)."""
    import resource

    try:
        physical = os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError):
        physical = 8 << 30
    budget = physical // 2
    soft, _ = resource.getrlimit(resource.RLIMIT_AS)
    if soft != resource.RLIM_INFINITY:
        budget = min(budget, max(soft - (1 << 30), soft // 4))
    return budget


class BytesType(click.ParamType):
    """A click parameter type for memory sizes (bad values exit 2)."""

    name = "SIZE"

    def convert(self, value, param, ctx) -> int:
        if isinstance(value, int):
            return value
        try:
            return parse_bytes(str(value))
        except ValueError as exc:
            self.fail(str(exc), param, ctx)


#: ``--max-memory SIZE``: refuse up front what would need more (None: :func:`default_memory`).
MAX_MEMORY = click.option("--max-memory", type=BytesType(), metavar="SIZE",
                          help="Refuse, before any work, a run estimated to need more memory than this "
                               "(e.g. 2G; default: half of this machine's memory).")
