"""``rend3r trace-diff A B``: the first divergence between two pixel traces.

Traces are JSON lines as ``docs/trace.md`` defines (one value per line). Records are
matched by (pixel, shape, stage, occurrence), so field order and the interleaving of
pixels do not matter; values must agree exactly (bits, and the decimal's value), except
that any two NaNs are equal unless ``nan_bits="exact"`` (the device's NaN bits are unknown).
"""

from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

import click

from ..errors import Rend3rError

Key = tuple[int, tuple[int, int], int | None, str, int]
NanBits = Literal["any", "exact"]


@dataclass(frozen=True, slots=True)
class Record:
    """One traced value, with where it came from (file line)."""

    frame: int
    pixel: tuple[int, int]
    shape: int | None
    stage: str
    bits: int
    dec: float
    line: int

    def describe(self) -> str:
        where = f"frame {self.frame} pixel ({self.pixel[0]},{self.pixel[1]})"
        if self.shape is not None:
            where += f" shape {self.shape}"
        return f"{where} stage {self.stage}"


def _decimal(v: object, where: str) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float, str)):
        raise Rend3rError(f"{where}: 'dec' must be a number or 'nan'/'inf'/'-inf'")
    if isinstance(v, str) and len(v) > 64:
        raise Rend3rError(f"{where}: 'dec' is a string of {len(v):,} characters, not a number")
    try:
        return float(v)
    except ValueError:
        raise Rend3rError(f"{where}: 'dec' {v!r} is not a number") from None


#: Largest trace file read (32 MiB: ~350,000 emulator records, ~300 MB and ~10 s once parsed).
MAX_TRACE = 32 << 20
#: Deepest JSON nesting a line may have (a record needs 2: the object and its pixel list).
MAX_DEPTH = 16
#: Most digits a JSON integer or a ``hex`` value may have (a 64-bit value needs 20 or 16).
MAX_DIGITS = 24
#: Longest stage name (the emulator's longest is under 20 characters).
MAX_STAGE = 200
_HEX = re.compile(r"-?0[xX][0-9a-fA-F]{1,%d}" % MAX_DIGITS, re.ASCII)
#: A line that is not blank (lines end at newlines only; U+2028 may sit inside a string).
_LINE = re.compile(r"^[^\S\n]*+\S[^\n]*", re.MULTILINE)
_BRACKETS = re.compile(r'"(?:[^"\\]|\\.)*"?|[\[\]{}]')


class _TooLong(ValueError):
    """A JSON integer with more than :data:`MAX_DIGITS` digits."""


def _int(text: str) -> int:
    if len(text.lstrip("-")) > MAX_DIGITS:
        raise _TooLong(f"an integer of {len(text.lstrip('-')):,} digits (at most {MAX_DIGITS})")
    return int(text)


_DECODER = json.JSONDecoder(parse_int=_int)


def _check_depth(text: str, where: str) -> None:
    """Refuse nesting deeper than :data:`MAX_DEPTH` before the JSON parser recurses into it
    (linear in the line: strings are skipped whole)."""
    if text.count("[") + text.count("{") <= MAX_DEPTH:
        return
    depth = 0
    for m in _BRACKETS.finditer(text):
        c = m[0]
        if c in "[{":
            depth += 1
            if depth > MAX_DEPTH:
                raise Rend3rError(f"{where}:{m.start() + 1}: JSON nested deeper than {MAX_DEPTH} levels: not a trace")
        elif c in "]}":
            depth -= 1


def _integer(obj: dict, key: str, where: str, default: object = None, *, nullable: bool = False,
             minimum: int | None = None) -> int | None:
    v = obj.get(key, default)
    if v is None and nullable:
        return None
    if not isinstance(v, int) or isinstance(v, bool) or (minimum is not None and v < minimum):
        kind = "a non-negative integer" if minimum == 0 else "an integer"
        raise Rend3rError(f"{where}: {key!r} must be {kind}{' or null' if nullable else ''}")
    return v


def parse_record(text: str, where: str, line: int) -> Record:
    """One JSON line -> Record (Rend3rError naming ``where`` when malformed)."""
    _check_depth(text, where)
    try:
        obj = _DECODER.decode(text)
    except json.JSONDecodeError as exc:
        raise Rend3rError(f"{where}:{exc.colno}: not JSON ({exc.msg})") from None
    except _TooLong as exc:
        raise Rend3rError(f"{where}: not a trace value: {exc}") from None
    if not isinstance(obj, dict):
        raise Rend3rError(f"{where}: a trace line must be a JSON object")
    missing = [k for k in ("pixel", "stage", "hex", "dec") if k not in obj]
    if missing:
        raise Rend3rError(f"{where}: missing field(s) {', '.join(missing)}")
    px = obj["pixel"]
    if not (isinstance(px, list) and len(px) == 2
            and all(isinstance(c, int) and not isinstance(c, bool) and c >= 0 for c in px)):
        raise Rend3rError(f"{where}: 'pixel' must be [x, y] non-negative integers")
    shape = _integer(obj, "shape", where, nullable=True)
    frame = _integer(obj, "frame", where, 0, minimum=0)
    if not isinstance(obj["stage"], str) or not 0 < len(obj["stage"]) <= MAX_STAGE:
        raise Rend3rError(f"{where}: 'stage' must be a name of 1 to {MAX_STAGE} characters")
    hx = obj["hex"]
    if not (isinstance(hx, str) and _HEX.fullmatch(hx)):
        shown = repr(hx) if len(repr(hx)) <= 40 else repr(hx)[:37] + "..."
        raise Rend3rError(f"{where}: 'hex' must be a string like \"0x3c00\" (at most {MAX_DIGITS} digits), "
                          f"not {shown}")
    return Record(frame, (px[0], px[1]), shape, obj["stage"], int(hx, 16), _decimal(obj["dec"], where), line)


def read_trace(path: Path) -> list[Record]:
    """All records of a trace file, in file order (blank lines are skipped)."""
    from ..fileio import read_limited

    data = read_limited(path, MAX_TRACE, what="trace")
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data[: exc.start].count(b"\n") + 1
        raise Rend3rError(f"{path}:{line}: not UTF-8 text (byte 0x{data[exc.start]:02x}): not a trace") from None
    del data
    records, line, last = [], 1, 0
    for m in _LINE.finditer(text):
        line += text.count("\n", last, m.start())
        last = m.start()
        records.append(parse_record(m[0], f"{path}:{line}", line))
    return records


def _keyed(records: list[Record]) -> dict[Key, Record]:
    seen: dict[tuple, int] = {}
    out: dict[Key, Record] = {}
    for r in records:
        base = (r.frame, r.pixel, r.shape, r.stage)
        k = seen.get(base, 0)
        seen[base] = k + 1
        out[(*base, k)] = r
    return out


def _same(a: Record, b: Record, nan_bits: NanBits) -> bool:
    """Equal bits and value; two NaNs (by ``dec``) are equal whatever their bits unless ``nan_bits`` is "exact"."""
    both_nan = math.isnan(a.dec) and math.isnan(b.dec)
    if both_nan and nan_bits == "any":
        return True
    return a.bits == b.bits and (both_nan or a.dec == b.dec)


def first_divergence(a: list[Record], b: list[Record], nan_bits: NanBits = "any") -> str | None:
    """A message for the first record (in A's order, then B's extras) that differs, or None.

    ``nan_bits="any"``: a NaN equals any NaN (sign and payload ignored); "exact": bit for bit.
    """
    ka, kb = _keyed(a), _keyed(b)
    for key, ra in ka.items():
        rb = kb.get(key)
        if rb is None:
            return f"{ra.describe()}: only in A (line {ra.line})"
        if not _same(ra, rb, nan_bits):
            return (
                f"{ra.describe()}: A 0x{ra.bits:04x} ({ra.dec!r}, line {ra.line}) "
                f"!= B 0x{rb.bits:04x} ({rb.dec!r}, line {rb.line})"
            )
    for key, rb in kb.items():
        if key not in ka:
            return f"{rb.describe()}: only in B (line {rb.line})"
    return None


@click.command("trace-diff")
@click.argument("a", type=click.Path(dir_okay=False, path_type=Path))
@click.argument("b", type=click.Path(dir_okay=False, path_type=Path))
@click.option("--nan-bits", type=click.Choice(["any", "exact"]), default="any", show_default=True,
              help="any: every NaN equals every NaN (the device's NaN bits are unknown); exact: NaNs must "
                   "agree bit for bit.")
def trace_diff_command(a: Path, b: Path, nan_bits: NanBits) -> None:
    """Compare two pixel traces (docs/trace.md) and report the first divergence.

    Exit status, as cmp and diff: 0 when the traces agree, 1 when they differ, 2 on
    trouble (a missing, unreadable or malformed file). Any two NaNs are equal unless
    --nan-bits exact.

    \b
    Example:
      rend3r emulate scene.asm -o f.png --trace-pixel 252,188 --trace emu.jsonl
      rend3r trace-diff emu.jsonl rtl.jsonl
      rend3r trace-diff emu.jsonl softfloat.jsonl --nan-bits exact
    """
    try:
        ra, rb = read_trace(a), read_trace(b)
    except Rend3rError as exc:
        raise Rend3rError(str(exc), exit_code=2) from None
    msg = first_divergence(ra, rb, nan_bits)
    if msg is None:
        click.echo(f"traces agree: {len(ra)} values")
        return
    click.echo(f"first divergence: {msg}")
    click.get_current_context().exit(1)
