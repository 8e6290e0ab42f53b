"""Encode and decode REND3R instructions to and from 32-bit words.

Field layouts come from :mod:`rend3r.isa.tables`. ``decode_stream`` follows the device:
an SE word always takes the next word as its SD, whatever that word is.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Iterable, Iterator, Union

from .tables import (
    C_ZERO_MASK,
    DATA,
    F_ZERO_MASK,
    FUNC,
    L_ZERO_MASK,
    LIGHT_INDEX,
    OPCODE,
    PROP,
    SD_DATA,
    SD_DATA2,
    SE_INDEX_HI,
    SE_INDEX_LO,
    SE_PROP2,
    Func,
    Opcode,
)


@dataclass(frozen=True, slots=True)
class FrameOp:
    """F-type: er, nr, nf, lr."""

    func: Func


@dataclass(frozen=True, slots=True)
class CameraSet:
    """C-type: camera[prop] = data."""

    prop: int
    data: int


@dataclass(frozen=True, slots=True)
class LightSet:
    """L-type: light[index][prop] = data."""

    index: int
    prop: int
    data: int


@dataclass(frozen=True, slots=True)
class ShapeSet:
    """SE/SD pair: shape or triangle [index]: prop = data, then prop2 = data2."""

    index: int
    prop: int
    prop2: int
    data: int
    data2: int


@dataclass(frozen=True, slots=True)
class Unknown:
    """A word with an opcode the device does not execute (010, 100, 110, 111)."""

    word: int


@dataclass(frozen=True, slots=True)
class TrailingSE:
    """An SE word at the end of the stream, with no SD after it."""

    word: int


Instruction = Union[FrameOp, CameraSet, LightSet, ShapeSet]
Decoded = Union[FrameOp, CameraSet, LightSet, ShapeSet, Unknown, TrailingSE]


def encode(ins: Instruction) -> tuple[int, ...]:
    """The word(s) of one instruction: one word, or SE then SD for ShapeSet."""
    if isinstance(ins, FrameOp):
        return (FUNC.put(int(ins.func)) | OPCODE.put(Opcode.F),)
    if isinstance(ins, CameraSet):
        return (DATA.put(ins.data) | PROP.put(ins.prop) | OPCODE.put(Opcode.C),)
    if isinstance(ins, LightSet):
        return (DATA.put(ins.data) | PROP.put(ins.prop) | LIGHT_INDEX.put(ins.index) | OPCODE.put(Opcode.L),)
    if isinstance(ins, ShapeSet):
        se = (
            SE_INDEX_HI.put(ins.index >> 3)
            | PROP.put(ins.prop)
            | SE_PROP2.put(ins.prop2)
            | SE_INDEX_LO.put(ins.index & 7)
            | OPCODE.put(Opcode.SE)
        )
        return se, SD_DATA.put(ins.data) | SD_DATA2.put(ins.data2)
    raise TypeError(f"cannot encode {ins!r}")


def decode_word(word: int, sd: int | None = None) -> Decoded:
    """Decode one word as the device does (reserved bits ignored).

    For an SE word, ``sd`` is the following word; None makes it a TrailingSE.
    """
    op = OPCODE.get(word)
    if op == _SE:
        if sd is None:
            return TrailingSE(word)
        index = (SE_INDEX_HI.get(word) << 3) | SE_INDEX_LO.get(word)
        return ShapeSet(index, PROP.get(word), SE_PROP2.get(word), SD_DATA.get(sd), SD_DATA2.get(sd))
    if op == _F:
        return FrameOp(Func(FUNC.get(word)))
    if op == _C:
        return CameraSet(PROP.get(word), DATA.get(word))
    if op == _L:
        return LightSet(LIGHT_INDEX.get(word), PROP.get(word), DATA.get(word))
    return Unknown(word)


_F, _C, _L, _SE = (int(o) for o in (Opcode.F, Opcode.C, Opcode.L, Opcode.SE))  # plain ints: cheaper compares


def decode_stream(words: Iterable[int]) -> Iterator[tuple[int, Decoded]]:
    """Yield ``(address, instruction)`` for a word stream; an SE takes the next word as SD."""
    ws = list(words)
    addr = 0
    while addr < len(ws):
        word = ws[addr]
        if OPCODE.get(word) == Opcode.SE:
            sd = ws[addr + 1] if addr + 1 < len(ws) else None
            yield addr, decode_word(word, sd)
            addr += 2
        else:
            yield addr, decode_word(word)
            addr += 1


def is_canonical(word: int) -> bool:
    """True when the word's reserved bits are zero (what the assembler would write)."""
    op = OPCODE.get(word)
    if op == Opcode.F:
        return word & F_ZERO_MASK == 0
    if op == Opcode.C:
        return word & C_ZERO_MASK == 0
    if op == Opcode.L:
        return word & L_ZERO_MASK == 0
    return op == Opcode.SE
