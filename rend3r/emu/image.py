"""Frame images: RGB565 expanded to RGB888 by bit replication; PNG, GIF, APNG; depth and
provenance images."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Sequence

import numpy as np

from ..errors import Rend3rError

PathLike = str | os.PathLike[str]


def rgb565_to_rgb888(rgb565: np.ndarray) -> np.ndarray:
    """(H, W) uint16 -> (H, W, 3) uint8; each channel's top bits fill its low bits."""
    c = rgb565.astype(np.uint16)
    r, g, b = c >> 11, (c >> 5) & 0x3F, c & 0x1F
    out = np.stack([(r << 3) | (r >> 2), (g << 2) | (g >> 4), (b << 3) | (b >> 2)], axis=-1)
    return out.astype(np.uint8)


def _image(rgb565: np.ndarray):
    from PIL import Image

    return Image.fromarray(rgb565_to_rgb888(rgb565), "RGB")


def _save(img, path: PathLike, **kwargs) -> None:
    p = Path(path)
    try:
        if p.parent and not p.parent.exists():
            p.parent.mkdir(parents=True, exist_ok=True)
        img.save(p, **kwargs)
    except (OSError, ValueError) as exc:
        raise Rend3rError(f"{p}: cannot write image: {exc}") from None


def save_png(rgb565: np.ndarray, path: PathLike) -> None:
    """One frame as an 8-bit RGB PNG."""
    _save(_image(rgb565), path, format="PNG")


def save_animation(frames: Sequence[np.ndarray], path: PathLike, kind: str, frame_ms: int = 100) -> None:
    """All frames as an animated ``gif`` (256 colours per frame) or ``apng`` (lossless)."""
    if not frames:
        raise Rend3rError(f"{path}: no frames to animate")
    images = [_image(f) for f in frames]
    fmt = {"gif": "GIF", "apng": "PNG"}[kind]
    extra = {"disposal": 1} if kind == "gif" else {}
    _save(images[0], path, format=fmt, save_all=True, append_images=images[1:], duration=frame_ms, loop=0, **extra)


def save_depth(depth: np.ndarray, path: PathLike) -> None:
    """``.npy``: the float32 distances; otherwise a 16-bit grey PNG, nearest white, misses black."""
    if str(path).lower().endswith(".npy"):
        _save_npy(depth.astype(np.float32), path)
        return
    from PIL import Image

    finite = np.isfinite(depth)
    grey = np.zeros(depth.shape, dtype=np.uint16)
    if finite.any():
        lo, hi = float(depth[finite].min()), float(depth[finite].max())
        span = hi - lo if hi > lo else 1.0
        grey[finite] = np.round(65535 - (depth[finite] - lo) / span * 65534).astype(np.uint16)
    _save(Image.fromarray(grey), path, format="PNG")


def save_provenance(provenance: np.ndarray, path: PathLike) -> None:
    """``.npy``: int32 shape indices (-1 none); otherwise a PNG with one colour per shape."""
    if str(path).lower().endswith(".npy"):
        _save_npy(provenance.astype(np.int32), path)
        return
    from PIL import Image

    idx = provenance.astype(np.int64)
    h = (idx + 1) * 2654435761 & 0xFFFFFF  # Knuth's multiplicative hash: distinct neighbours
    rgb = np.stack([(h >> 16) & 0xFF, (h >> 8) & 0xFF, h & 0xFF], axis=-1) | 0x40
    rgb[idx < 0] = 0
    _save(Image.fromarray(rgb.astype(np.uint8), "RGB"), path, format="PNG")


def _save_npy(array: np.ndarray, path: PathLike) -> None:
    try:
        Path(path).parent.mkdir(parents=True, exist_ok=True)
        np.save(path, array)
    except OSError as exc:
        raise Rend3rError(f"{path}: cannot write: {exc.strerror or exc}") from None


def frame_path(pattern: str, number: int) -> str:
    """``out/frame_{n:03}.png`` with n = frame number; a plain name is returned as is."""
    try:
        return pattern.format(n=number)
    except (KeyError, IndexError, ValueError) as exc:
        raise Rend3rError(f"bad output pattern {pattern!r}: use {{n}} for the frame number ({exc})") from None


def is_pattern(path: str) -> bool:
    return "{" in path
