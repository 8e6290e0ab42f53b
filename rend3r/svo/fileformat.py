"""The ``.svo`` file: a 72-byte little-endian header followed by the 32-bit node words.

Header (``struct`` format ``<4sHHHHIQ6d``): magic ``b"R3SV"``, version (1), depth,
pointer width in bits, reserved (0), word count (nodes plus far slots), voxel count, and
the world-space bounds ``min_x min_y min_z max_x max_y max_z`` of the cube the octree's
normalised [-1, 1]^3 maps to.

A file is untrusted: :func:`decode_svo` checks the header and then the whole node
structure (:mod:`rend3r.svo.validate`) before any kernel reads a word, and names the
byte offset of the first bad word.
"""

from __future__ import annotations

import os
import struct
from dataclasses import dataclass

import numpy as np

from ..errors import Rend3rError
from ..fileio import MAX_INPUT, read_limited, write_atomic
from .octree import MAX_DEPTH, Octree
from .validate import OctreeError, check_octree

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
    """Parse and validate a ``.svo`` file: header fields, sizes, bounds and every node."""
    if len(data) < _HEADER.size:
        raise Rend3rError(f"{name}: too short for an .svo header")
    magic, version, depth, ptr_bits, _, count, voxels, *bounds = _HEADER.unpack_from(data)
    if magic != MAGIC:
        raise Rend3rError(f"{name}: not an .svo file (bad magic)")
    if version != VERSION:
        raise Rend3rError(f"{name}: unsupported .svo version {version}")
    if not 1 <= depth <= MAX_DEPTH or not 4 <= ptr_bits <= 15:
        raise Rend3rError(f"{name}: bad header (depth {depth}, pointer bits {ptr_bits})")
    if count == 0:
        raise Rend3rError(f"{name}: byte 12: header claims 0 words (a root node is required)")
    if len(data) != _HEADER.size + 4 * count:
        raise Rend3rError(f"{name}: expected {count} words, file holds {(len(data) - _HEADER.size) / 4:g}")
    if not all(np.isfinite(bounds)) or any(bounds[i] >= bounds[i + 3] for i in range(3)):
        raise Rend3rError(f"{name}: bad bounds {bounds}")
    if not all(np.isfinite(np.subtract(bounds[3:], bounds[:3]))):
        raise Rend3rError(f"{name}: bounds {bounds} span more than a float can hold")
    words = np.frombuffer(data, dtype="<u4", offset=_HEADER.size).astype(np.uint32)
    tree = Octree(words, depth, ptr_bits)
    try:
        check_octree(tree)
    except OctreeError as exc:
        raise Rend3rError(f"{name}: byte {_HEADER.size + 4 * exc.index}: corrupt octree "
                          f"(word {exc.index}): {exc}") from None
    return SvoModel(tree, tuple(bounds), voxels)


def write_svo(path: str | os.PathLike[str], model: SvoModel) -> None:
    """Write a ``.svo`` file atomically."""
    write_atomic(path, encode_svo(model))


def read_svo(path: str | os.PathLike[str]) -> SvoModel:
    """Read and validate a ``.svo`` file (at most :data:`rend3r.fileio.MAX_INPUT` bytes)."""
    return decode_svo(read_limited(path, MAX_INPUT, what=".svo file"), str(path))
