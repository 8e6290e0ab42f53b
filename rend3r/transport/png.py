"""A PNG encoder that can be abandoned between bands of rows.

The virtual device writes each rendered frame as a PNG; at 4096x4096 encoding takes
seconds (up to ~15 s for noise), longer than a render band. Encoding here runs in bands of
about :data:`BAND_BYTES` of pixel data and calls ``check`` between them, so a newer commit
can cancel the write as promptly as it cancels the render (``check`` raises).
"""

from __future__ import annotations

import struct
import zlib
from collections.abc import Callable

import numpy as np

SIGNATURE = b"\x89PNG\r\n\x1a\n"
#: Raw (filtered) bytes compressed between two calls of ``check``: 3 MiB, ~0.3 s of noise.
BAND_BYTES = 3 << 20


def _chunk(kind: bytes, data: bytes) -> bytes:
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))


def encode_rgb565(rgb565: np.ndarray, check: Callable[[], None] = lambda: None, level: int = 6) -> bytes:
    """An 8-bit RGB PNG of an (H, W) RGB565 frame, calling ``check`` between bands.

    Pixels are widened band by band, so the encoder holds one band beside the frame.
    """
    from ..emu.image import rgb565_to_rgb888

    height, width = rgb565.shape
    rows = max(1, BAND_BYTES // (3 * width + 1))
    z = zlib.compressobj(level)
    parts = [SIGNATURE, _chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))]
    idat = []
    for row0 in range(0, height, rows):
        check()
        band = rgb565_to_rgb888(rgb565[row0:row0 + rows]).reshape(-1, 3 * width)
        filtered = np.zeros((len(band), 3 * width + 1), np.uint8)  # filter type 0 per row
        filtered[:, 1:] = band
        idat.append(z.compress(filtered.tobytes()))
    idat.append(z.flush())
    parts += [_chunk(b"IDAT", b"".join(idat)), _chunk(b"IEND", b"")]
    return b"".join(parts)
