"""Consistent Overhead Byte Stuffing: frames without zero bytes, delimited by 0x00.

Encoding adds one byte per started block of 254 non-zero bytes, so a frame of n bytes costs
at most ``n // 254 + 1`` extra bytes plus the delimiter.
"""

from __future__ import annotations


class CobsError(ValueError):
    """Bytes that are not a valid COBS encoding."""


def encode(data: bytes) -> bytes:
    """COBS-encode ``data``; the result holds no zero byte (the delimiter is not added)."""
    out = bytearray()
    for segment in bytes(data).split(b"\0"):
        while len(segment) >= 254:
            out += b"\xff" + segment[:254]
            segment = segment[254:]
        out.append(len(segment) + 1)
        out += segment
    return bytes(out)


def decode(data: bytes) -> bytes:
    """Decode one COBS frame (without its delimiter); raise CobsError if it is invalid."""
    out = bytearray()
    i = 0
    n = len(data)
    while i < n:
        code = data[i]
        if code == 0:
            raise CobsError("zero byte inside a COBS frame")
        end = i + code
        if end > n:
            raise CobsError("COBS block runs past the end of the frame")
        block = data[i + 1:end]
        if 0 in block:
            raise CobsError("zero byte inside a COBS frame")
        out += block
        i = end
        if code != 255 and i < n:
            out.append(0)
    return bytes(out)
