"""Frame images: RGB565 expanded to RGB888 by bit replication; PNG, GIF, APNG; depth and
provenance images."""

from __future__ import annotations

import io
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


#: File extension -> encoder format. ``.apng`` is a PNG file with several frames.
FORMATS = {".png": "PNG", ".apng": "PNG", ".gif": "GIF", ".npy": "NPY"}
#: The extensions each kind of output accepts.
FRAME_KINDS = (".png",)
DATA_KINDS = (".png", ".npy")
ANIMATION_KINDS = {"gif": (".gif",), "apng": (".png", ".apng")}


def check_output(path: PathLike, kinds: Sequence[str], *, make_parents: bool = False) -> str:
    """The lower-case extension of ``path`` if it is one of ``kinds`` and (unless
    ``make_parents``) its folder exists; Rend3rError otherwise. Lets a command refuse an
    output before it spends time rendering."""
    p = Path(path)
    ext = p.suffix.lower()
    if ext not in kinds:
        raise Rend3rError(f"{p}: unknown image type {ext or '(no extension)'!r}: use {' or '.join(kinds)}")
    if not make_parents and not p.parent.is_dir():
        raise Rend3rError(f"{p}: folder {p.parent} does not exist")
    return ext


def write_image(path: PathLike, image, kinds: Sequence[str] = FRAME_KINDS, *, make_parents: bool = False,
                **save_kwargs) -> None:
    """Encode ``image`` in memory by ``path``'s extension and write it atomically.

    ``image`` is a PIL image (``save_kwargs`` go to its encoder) or, for ``.npy``, a numpy
    array. The extension must be one of ``kinds``; the parent folder must exist unless
    ``make_parents`` (used for ``{n}`` output patterns). Every failure is a Rend3rError
    and leaves no partial file behind (:func:`rend3r.fileio.write_atomic`).
    """
    from ..fileio import write_atomic

    p = Path(path)
    ext = check_output(p, kinds, make_parents=make_parents)
    if make_parents:
        try:
            p.parent.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise Rend3rError(f"{p}: cannot create folder {p.parent}: {exc.strerror or exc}") from None
    buf = io.BytesIO()
    try:
        if FORMATS[ext] == "NPY":
            np.save(buf, np.asarray(image), allow_pickle=False)
        else:
            image.save(buf, format=FORMATS[ext], **save_kwargs)
    except (OSError, ValueError) as exc:
        raise Rend3rError(f"{p}: cannot encode image: {exc}") from None
    write_atomic(p, buf.getvalue())


def save_png(rgb565: np.ndarray, path: PathLike, *, make_parents: bool = False) -> None:
    """One frame as an 8-bit RGB PNG."""
    write_image(path, _image(rgb565), make_parents=make_parents)


def save_animation(frames: Sequence[np.ndarray], path: PathLike, kind: str, frame_ms: int = 100) -> None:
    """All frames as an animated ``gif`` (256 colours per frame, ``.gif``) or ``apng``
    (lossless, ``.png`` or ``.apng``)."""
    if not frames:
        raise Rend3rError(f"{path}: no frames to animate")
    images = [_image(f) for f in frames]
    kinds = ANIMATION_KINDS[kind]
    extra = {"disposal": 1} if kind == "gif" else {}
    write_image(path, images[0], kinds, save_all=True, append_images=images[1:], duration=frame_ms, loop=0,
                **extra)


def save_depth(depth: np.ndarray, path: PathLike, *, make_parents: bool = False) -> None:
    """``.npy``: the float32 distances; ``.png``: 16-bit grey, nearest white, misses black."""
    if str(path).lower().endswith(".npy"):
        write_image(path, depth.astype(np.float32), (".npy",), make_parents=make_parents)
        return
    from PIL import Image

    finite = np.isfinite(depth)
    grey = np.zeros(depth.shape, dtype=np.uint16)
    if finite.any():
        lo, hi = float(depth[finite].min()), float(depth[finite].max())
        span = hi - lo if hi > lo else 1.0
        grey[finite] = np.round(65535 - (depth[finite] - lo) / span * 65534).astype(np.uint16)
    write_image(path, Image.fromarray(grey), DATA_KINDS, make_parents=make_parents)


def save_provenance(provenance: np.ndarray, path: PathLike, *, make_parents: bool = False) -> None:
    """``.npy``: int32 shape indices (-1 none); ``.png``: one colour per shape."""
    if str(path).lower().endswith(".npy"):
        write_image(path, provenance.astype(np.int32), (".npy",), make_parents=make_parents)
        return
    from PIL import Image

    idx = provenance.astype(np.int64)
    h = (idx + 1) * 2654435761 & 0xFFFFFF  # Knuth's multiplicative hash: distinct neighbours
    rgb = np.stack([(h >> 16) & 0xFF, (h >> 8) & 0xFF, h & 0xFF], axis=-1) | 0x40
    rgb[idx < 0] = 0
    write_image(path, Image.fromarray(rgb.astype(np.uint8), "RGB"), DATA_KINDS, make_parents=make_parents)


def frame_path(pattern: str, number: int) -> str:
    """``out/frame_{n:03}.png`` with n = frame number; a plain name is returned as is."""
    try:
        return pattern.format(n=number)
    except (KeyError, IndexError, ValueError) as exc:
        raise Rend3rError(f"bad output pattern {pattern!r}: use {{n}} for the frame number ({exc})") from None


def is_pattern(path: str) -> bool:
    """Whether ``path`` is an output pattern with a ``{n}`` field (its folders are created)."""
    return "{" in path
