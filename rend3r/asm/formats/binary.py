"""``bin``: raw 32-bit words, 4 bytes each, big-endian unless told otherwise."""

from __future__ import annotations

from ...errors import Rend3rError
from ..program import Program
from .common import MAX_WORDS, pack_words, unpack_words


def render_bin(program: Program, byteorder: str = "big") -> bytes:
    return pack_words(program.words, byteorder)


def read_bin(data: bytes, name: str, byteorder: str = "big") -> list[int]:
    """Words of a raw image; its length must be a non-zero multiple of 4 bytes."""
    if not data:
        raise Rend3rError(f"{name}: empty file: no words")
    if len(data) % 4:
        raise Rend3rError(
            f"{name}: {len(data)} bytes is not a whole number of 32-bit words "
            f"({len(data) % 4} byte(s) left over at offset {len(data) - len(data) % 4})"
        )
    if len(data) // 4 > MAX_WORDS:
        raise Rend3rError(f"{name}: {len(data):,} bytes is more than the {MAX_WORDS:,}-word limit "
                          f"({MAX_WORDS * 4:,} bytes)")
    return unpack_words(data, byteorder)
