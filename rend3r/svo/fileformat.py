"""The ``.svo`` file: a 72-byte little-endian header followed by the 32-bit node words.

Header (``struct`` format ``<4sHHHHIQ6d``): magic ``b"R3SV"``, version (1), depth,
pointer width in bits, reserved (0), word count (nodes plus far slots), voxel count, and
the world-space bounds ``min_x min_y min_z max_x max_y max_z`` of the cube the octree's
normalised [-1, 1]^3 maps to.
"""

from __future__ import annotations

import os
import struct
from dataclasses import dataclass

import numpy as np

from ..errors import Rend3rError
from ..fileio import write_atomic
from .octree import MAX_DEPTH, Octree

MAGIC = b"R3SV"
VERSION = 1
_HEADER = struct.Struct("<4sHHHHIQ6d")


@dataclass(frozen=True)
class SvoModel:
    """An octree plus where it sits in the world."""

    tree: Octree
    bounds: tuple[float, float, float, float, float, float]
    voxel_count: int


def encode_svo(model: SvoModel) -> bytes:
    """The bytes of a ``.svo`` file."""
    tree = model.tree
    header = _HEADER.pack(MAGIC, VERSION, tree.depth, tree.ptr_bits, 0, len(tree.words),
                          model.voxel_count, *model.bounds)
    return header + tree.words.astype("<u4").tobytes()


def decode_svo(data: bytes, name: str = "<svo>") -> SvoModel:
    """Parse a ``.svo`` file, checking magic, version, sizes and the depth."""
    if len(data) < _HEADER.size:
        raise Rend3rError(f"{name}: too short for an .svo header")
    magic, version, depth, ptr_bits, _, count, voxels, *bounds = _HEADER.unpack_from(data)
    if magic != MAGIC:
        raise Rend3rError(f"{name}: not an .svo file (bad magic)")
    if version != VERSION:
        raise Rend3rError(f"{name}: unsupported .svo version {version}")
    if not 1 <= depth <= MAX_DEPTH or not 4 <= ptr_bits <= 15:
        raise Rend3rError(f"{name}: bad header (depth {depth}, pointer bits {ptr_bits})")
    if len(data) != _HEADER.size + 4 * count:
        raise Rend3rError(f"{name}: expected {count} words, file holds {(len(data) - _HEADER.size) / 4:g}")
    if not all(np.isfinite(bounds)) or any(bounds[i] >= bounds[i + 3] for i in range(3)):
        raise Rend3rError(f"{name}: bad bounds {bounds}")
    words = np.frombuffer(data, dtype="<u4", offset=_HEADER.size).astype(np.uint32)
    return SvoModel(Octree(words, depth, ptr_bits), tuple(bounds), voxels)


def write_svo(path: str | os.PathLike[str], model: SvoModel) -> None:
    """Write a ``.svo`` file atomically."""
    write_atomic(path, encode_svo(model))


def read_svo(path: str | os.PathLike[str]) -> SvoModel:
    """Read a ``.svo`` file."""
    try:
        with open(path, "rb") as fh:
            data = fh.read()
    except OSError as exc:
        raise Rend3rError(f"{path}: cannot read: {exc.strerror or exc}") from exc
    return decode_svo(data, str(path))
