"""``rend3r trace-diff A B``: the first divergence between two pixel traces.

Traces are JSON lines as ``docs/trace.md`` defines (one value per line). Records are
matched by (pixel, shape, stage, occurrence), so field order and the interleaving of
pixels do not matter; values must agree exactly (bits, and the decimal's value).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import click

from ..errors import Rend3rError

Key = tuple[int, tuple[int, int], int | None, str, int]


@dataclass(frozen=True)
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
    try:
        return float(v)
    except ValueError:
        raise Rend3rError(f"{where}: 'dec' {v!r} is not a number") from None


def parse_record(text: str, where: str, line: int) -> Record:
    """One JSON line -> Record (Rend3rError naming ``where`` when malformed)."""
    try:
        obj = json.loads(text)
    except json.JSONDecodeError as exc:
        raise Rend3rError(f"{where}: not JSON ({exc.msg})") from None
    if not isinstance(obj, dict):
        raise Rend3rError(f"{where}: a trace line must be a JSON object")
    missing = [k for k in ("pixel", "stage", "hex", "dec") if k not in obj]
    if missing:
        raise Rend3rError(f"{where}: missing field(s) {', '.join(missing)}")
    px = obj["pixel"]
    if not (isinstance(px, list) and len(px) == 2 and all(isinstance(c, int) and not isinstance(c, bool) for c in px)):
        raise Rend3rError(f"{where}: 'pixel' must be [x, y] integers")
    shape = obj.get("shape")
    if shape is not None and (not isinstance(shape, int) or isinstance(shape, bool)):
        raise Rend3rError(f"{where}: 'shape' must be an integer or null")
    frame = obj.get("frame", 0)
    if not isinstance(frame, int) or isinstance(frame, bool):
        raise Rend3rError(f"{where}: 'frame' must be an integer")
    if not isinstance(obj["stage"], str):
        raise Rend3rError(f"{where}: 'stage' must be a string")
    try:
        bits = int(str(obj["hex"]), 16)
    except ValueError:
        raise Rend3rError(f"{where}: 'hex' {obj['hex']!r} is not hexadecimal") from None
    return Record(frame, (px[0], px[1]), shape, obj["stage"], bits, _decimal(obj["dec"], where), line)


def read_trace(path: Path) -> list[Record]:
    """All records of a trace file, in file order (blank lines are skipped)."""
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise Rend3rError(f"cannot read {path}: {exc.strerror or exc}") from None
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data[: exc.start].count(b"\n") + 1
        raise Rend3rError(f"{path}:{line}: not UTF-8 text (byte 0x{data[exc.start]:02x}): not a trace") from None
    return [
        parse_record(line, f"{path}:{n}", n) for n, line in enumerate(text.splitlines(), 1) if line.strip()
    ]


def _keyed(records: list[Record]) -> dict[Key, Record]:
    seen: dict[tuple, int] = {}
    out: dict[Key, Record] = {}
    for r in records:
        base = (r.frame, r.pixel, r.shape, r.stage)
        k = seen.get(base, 0)
        seen[base] = k + 1
        out[(*base, k)] = r
    return out


def _same(a: Record, b: Record) -> bool:
    both_nan = math.isnan(a.dec) and math.isnan(b.dec)
    return a.bits == b.bits and (both_nan or a.dec == b.dec)


def first_divergence(a: list[Record], b: list[Record]) -> str | None:
    """A message for the first record (in A's order, then B's extras) that differs, or None."""
    ka, kb = _keyed(a), _keyed(b)
    for key, ra in ka.items():
        rb = kb.get(key)
        if rb is None:
            return f"{ra.describe()}: only in A (line {ra.line})"
        if not _same(ra, rb):
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
def trace_diff_command(a: Path, b: Path) -> None:
    """Compare two pixel traces (docs/trace.md) and report the first divergence.

    Exit status, as cmp and diff: 0 when the traces agree, 1 when they differ, 2 on
    trouble (a missing, unreadable or malformed file).

    \b
    Example:
      rend3r emulate scene.asm -o f.png --trace-pixel 252,188 --trace emu.jsonl
      rend3r trace-diff emu.jsonl rtl.jsonl
    """
    try:
        ra, rb = read_trace(a), read_trace(b)
    except Rend3rError as exc:
        raise Rend3rError(str(exc), exit_code=2) from None
    msg = first_divergence(ra, rb)
    if msg is None:
        click.echo(f"traces agree: {len(ra)} values")
        return
    click.echo(f"first divergence: {msg}")
    click.get_current_context().exit(1)
