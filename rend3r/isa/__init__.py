"""The REND3R instruction set: tables (single source of truth), encoding, float16 literals."""

from .encoding import (
    CameraSet,
    Decoded,
    FrameOp,
    Instruction,
    LightSet,
    ShapeSet,
    TrailingSE,
    Unknown,
    decode_stream,
    decode_word,
    encode,
    is_canonical,
)
from .tables import PROPERTIES, Func, Opcode, Property, Table, ValueType, by_index, lookup

__all__ = [
    "CameraSet",
    "Decoded",
    "FrameOp",
    "Func",
    "Instruction",
    "LightSet",
    "Opcode",
    "PROPERTIES",
    "Property",
    "ShapeSet",
    "Table",
    "TrailingSE",
    "Unknown",
    "ValueType",
    "by_index",
    "decode_stream",
    "decode_word",
    "encode",
    "is_canonical",
    "lookup",
]
