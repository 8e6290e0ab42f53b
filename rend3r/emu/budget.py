"""What an ``emulate`` run will need in memory, estimated before it starts.

The figures are peak resident bytes per pixel measured with ``/usr/bin/time -v``: the
renderer's own working set per mode (its frame buffer, depth and provenance included),
one output being encoded beside the frame, and each frame an animation keeps until it is
written at the end.
"""

from __future__ import annotations

#: The interpreter, numpy, Pillow and the compiled kernels, before any frame.
BASE = 200 << 20
#: Renderer peak per pixel, by mode (measured at 8192x8192: 1.16 GB for programs/sphere.asm,
#: 3.26 GB for tri_cube.asm, 3.92 GB for hybrid_mix.asm; stress4096.asm at 4096x4096 0.37 GB).
ENGINE = {"raytrace": 18, "raster": 52, "hybrid": 62}
#: The frame's own arrays (RGB565, float32 depth, int32 provenance) held while outputs encode.
FRAME = 10
#: One output being encoded, per pixel: the RGB888 (or 16-bit grey) array, Pillow's copy
#: (4 bytes per RGB pixel) and the compressed bytes (at most about the raw size).
ENCODE = 14
#: Per pixel and frame kept for an animation: the RGB565 frame, and what the GIF encoder
#: (palette frames) or the APNG encoder holds until it writes (measured: 8 frames of
#: 2048x2048, 0.30 GB as GIF, 0.25 GB as APNG).
ANIMATION = {".gif": 7, ".png": 6, ".apng": 6}


def estimate_memory(mode: str, width: int, height: int, frames: int, outputs: list[str],
                    animation: str | None) -> tuple[int, str]:
    """(peak bytes, how they add up) for one run with these outputs."""
    pixels = width * height
    engine = ENGINE.get(mode, max(ENGINE.values())) * pixels
    encode = (FRAME + ENCODE) * pixels if outputs else 0
    kept = 0
    if animation:
        ext = animation[animation.rfind("."):].lower()
        kept = ANIMATION.get(ext, max(ANIMATION.values())) * pixels * frames
    need = BASE + max(engine, encode) + kept
    parts = f"interpreter {BASE / 2**30:.2f} GiB + renderer {engine / 2**30:.2f} GiB"
    if outputs:
        parts = f"interpreter {BASE / 2**30:.2f} GiB + the larger of renderer {engine / 2**30:.2f} GiB " \
                f"and encoding {encode / 2**30:.2f} GiB"
    if kept:
        parts += f" + {frames} animation frames {kept / 2**30:.2f} GiB"
    return need, parts
