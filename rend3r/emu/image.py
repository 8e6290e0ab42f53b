"""Frame images: RGB565 expanded to RGB888 by bit replication; PNG, GIF, APNG; depth and
provenance images."""

from __future__ import annotations

import io
import os
import re
import string
from pathlib import Path
from typing import Callable, Sequence

import numpy as np

from ..errors import Rend3rError

PathLike = str | os.PathLike[str]


#: Pixels converted per step by the image encoders: their temporaries stay a few MiB
#: whatever the frame size (an 8192x8192 frame is 64 M pixels).
BAND_PIXELS = 1 << 20


def _steps(count: int):
    """Slices of at most :data:`BAND_PIXELS` covering ``range(count)``."""
    return (slice(i, min(i + BAND_PIXELS, count)) for i in range(0, count, BAND_PIXELS))


def rgb565_to_rgb888(rgb565: np.ndarray) -> np.ndarray:
    """(H, W) uint16 -> (H, W, 3) uint8; each channel's top bits fill its low bits."""
    rgb565 = np.asarray(rgb565)
    flat = rgb565.reshape(-1)
    out = np.empty((flat.size, 3), dtype=np.uint8)
    for part in _steps(flat.size):
        c = flat[part].astype(np.uint16)
        r, g, b = c >> 11, (c >> 5) & 0x3F, c & 0x1F
        out[part, 0] = (r << 3) | (r >> 2)
        out[part, 1] = (g << 2) | (g >> 4)
        out[part, 2] = (b << 3) | (b >> 2)
    return out.reshape(*rgb565.shape, 3)


def _image(rgb565: np.ndarray):
    from PIL import Image

    return Image.fromarray(rgb565_to_rgb888(rgb565), "RGB")


#: File extension -> encoder format. ``.apng`` is a PNG file with several frames.
FORMATS = {".png": "PNG", ".apng": "PNG", ".gif": "GIF", ".npy": "NPY"}
#: The extensions each kind of output accepts.
FRAME_KINDS = (".png",)
DATA_KINDS = (".png", ".npy")
ANIMATION_KINDS = {"gif": (".gif",), "apng": (".png", ".apng")}


def check_output(path: PathLike, kinds: Sequence[str]) -> str:
    """The lower-case extension of ``path`` if it is one of ``kinds``; Rend3rError
    otherwise. Lets a command refuse an output before it spends time rendering (folders
    are made, or refused, by :mod:`rend3r.fileio`)."""
    p = Path(path)
    ext = p.suffix.lower()
    if ext not in kinds:
        raise Rend3rError(f"{p}: unknown image type {ext or '(no extension)'!r}: use {' or '.join(kinds)}")
    return ext


#: Where encoded bytes go instead of an atomic write of their own (an output batch).
Sink = Callable[[Path, bytes], None]


def write_image(path: PathLike, image, kinds: Sequence[str] = FRAME_KINDS, *, sink: Sink | None = None,
                **save_kwargs) -> None:
    """Encode ``image`` in memory by ``path``'s extension and write it atomically.

    ``image`` is a PIL image (``save_kwargs`` go to its encoder) or, for ``.npy``, a numpy
    array. The extension must be one of ``kinds``; a ``sink`` (:meth:`rend3r.fileio.Outputs.write`)
    may take the bytes instead. Missing folders are made; every failure is a Rend3rError and
    leaves no partial file behind (:func:`rend3r.fileio.write_atomic`).
    """
    from ..fileio import write_atomic

    p = Path(path)
    ext = check_output(p, kinds)
    buf = io.BytesIO()
    try:
        if FORMATS[ext] == "NPY":
            np.save(buf, np.asarray(image), allow_pickle=False)
        else:
            image.save(buf, format=FORMATS[ext], **save_kwargs)
    except (OSError, ValueError) as exc:
        raise Rend3rError(f"{p}: cannot encode image: {exc}") from None
    if sink is not None:
        sink(p, buf.getbuffer())
        return
    write_atomic(p, buf.getbuffer())


def save_png(rgb565: np.ndarray, path: PathLike, *, sink: Sink | None = None) -> None:
    """One frame as an 8-bit RGB PNG."""
    write_image(path, _image(rgb565), sink=sink)


def save_animation(frames: Sequence[np.ndarray], path: PathLike, kind: str, frame_ms: int = 100, *,
                   sink: Sink | None = None) -> None:
    """All frames as an animated ``gif`` (256 colours per frame, ``.gif``) or ``apng``
    (lossless, ``.png`` or ``.apng``)."""
    if not frames:
        raise Rend3rError(f"{path}: no frames to animate")
    images = (_image(f) for f in frames[1:])  # the encoders take them one at a time
    kinds = ANIMATION_KINDS[kind]
    extra = {"disposal": 1} if kind == "gif" else {}
    write_image(path, _image(frames[0]), kinds, sink=sink, save_all=True, append_images=images, duration=frame_ms,
                loop=0, **extra)


def save_depth(depth: np.ndarray, path: PathLike, *, sink: Sink | None = None) -> None:
    """``.npy``: the float32 distances; ``.png``: 16-bit grey, nearest white, misses black."""
    image = depth_image(depth, str(path).lower().endswith(".npy"))
    write_image(path, image, DATA_KINDS, sink=sink)


def depth_image(depth: np.ndarray, npy: bool):
    """What :func:`save_depth` writes: float32 distances, or a 16-bit grey PIL image."""
    if npy:
        return depth.astype(np.float32)
    from PIL import Image

    flat = np.asarray(depth).reshape(-1)
    lo, hi = np.inf, -np.inf
    for part in _steps(flat.size):
        band = flat[part]
        band = band[np.isfinite(band)]
        if band.size:
            lo, hi = min(lo, float(band.min())), max(hi, float(band.max()))
    grey = np.zeros(flat.size, dtype=np.uint16)
    if lo <= hi:
        span = hi - lo if hi > lo else 1.0  # float64: no overflow even for +-1e308
        for part in _steps(flat.size):
            band = flat[part].astype(np.float64)
            finite = np.isfinite(band)
            grey[part][finite] = np.round(65535 - (band[finite] - lo) / span * 65534).astype(np.uint16)
    return Image.fromarray(grey.reshape(np.shape(depth)))


def save_provenance(provenance: np.ndarray, path: PathLike, *, sink: Sink | None = None) -> None:
    """``.npy``: int32 shape indices (-1 none); ``.png``: one colour per shape."""
    image = provenance_image(provenance, str(path).lower().endswith(".npy"))
    write_image(path, image, DATA_KINDS, sink=sink)


def provenance_image(provenance: np.ndarray, npy: bool):
    """What :func:`save_provenance` writes: int32 indices, or an RGB PIL image."""
    if npy:
        return provenance.astype(np.int32)
    from PIL import Image

    flat = np.asarray(provenance).reshape(-1)
    rgb = np.zeros((flat.size, 3), dtype=np.uint8)
    for part in _steps(flat.size):
        idx = flat[part].astype(np.int64)
        h = (idx + 1) * 2654435761 & 0xFFFFFF  # Knuth's multiplicative hash: distinct neighbours
        band = rgb[part]
        for channel, shift in enumerate((16, 8, 0)):
            band[:, channel] = ((h >> shift) & 0xFF) | 0x40
        band[idx < 0] = 0
    return Image.fromarray(rgb.reshape(*np.shape(provenance), 3), "RGB")


#: Widest zero-padded frame number a name pattern may ask for (``{n:032}``).
MAX_PATTERN_WIDTH = 32
_SPEC = re.compile(r"(0?)([0-9]*)d?", re.ASCII)
PATTERN_HELP = "use {n} for the frame number, optionally zero-padded as {n:03}"


def check_pattern(pattern: str) -> bool:
    """Whether ``pattern`` names several files (it has ``{n}`` fields).

    A name is a ``str.format`` pattern whose only field is ``n``, with no conversion and
    at most a zero-padded width (``{n}``, ``{n:03}``, ``{n:3d}``, up to
    :data:`MAX_PATTERN_WIDTH`); literal braces are doubled (``{{``). Anything else is a
    ValueError with the reason, raised before any frame is rendered.
    """
    try:
        fields = [(name, spec, conv) for _, name, spec, conv in string.Formatter().parse(pattern) if name is not None]
    except ValueError as exc:
        raise ValueError(f"bad name pattern {pattern!r}: {exc}; {PATTERN_HELP}") from None
    for name, spec, conv in fields:
        field = "{" + name + ("!" + conv if conv else "") + (":" + spec if spec else "") + "}"
        m = _SPEC.fullmatch(spec or "")
        if name != "n" or conv or not m:
            raise ValueError(f"bad name pattern {pattern!r}: field {field}: {PATTERN_HELP}")
        if m[2] and (len(m[2]) > 3 or int(m[2]) > MAX_PATTERN_WIDTH):
            raise ValueError(f"bad name pattern {pattern!r}: field {field} is wider than {MAX_PATTERN_WIDTH} digits")
    return bool(fields)


def frame_path(pattern: str, number: int) -> str:
    """``out/frame_{n:03}.png`` with n = frame number (``pattern`` passed :func:`check_pattern`)."""
    try:
        check_pattern(pattern)
    except ValueError as exc:
        raise Rend3rError(str(exc)) from None
    return pattern.format(n=number)


def is_pattern(path: str) -> bool:
    """Whether ``path`` is a valid output pattern with a ``{n}`` field (its folders are created)."""
    try:
        return check_pattern(path)
    except ValueError:
        return False
