"""binvox voxel grids, read and written without a dense grid.

binvox voxels are ``(coords (k, 3), dim, translate (3,), scale)``; voxel ``(x, y, z)``
of a binvox grid has its centre at ``translate + (i + 0.5) / dim * scale`` per axis, the
same cell-centred convention as :mod:`rend3r.svo.voxelize`. binvox stores voxels with y
running fastest, then z, then x, as runs of (value, count <= 255) byte pairs after a
text header. A file's runs are checked before any voxel is made, and voxels are decoded
(and encoded) a batch at a time to and from Morton codes, the octree builder's input.
"""

from __future__ import annotations

import os
from collections.abc import Callable

import numpy as np

from ..errors import Rend3rError
from ..fileio import read_limited, write_atomic
from .mesh_io import MAX_MESH
from .octree import morton_decode, morton_encode, sorted_unique
from .voxelize import batches, expand_counts


def _binvox_index(coords: np.ndarray, dim: int) -> np.ndarray:
    return (coords[:, 0] * dim + coords[:, 2]) * dim + coords[:, 1]


def _binvox_header_bytes(dim: int, translate, scale: float) -> bytes:
    return (f"#binvox 1\ndim {dim} {dim} {dim}\ntranslate {translate[0]:.9g} {translate[1]:.9g} "
            f"{translate[2]:.9g}\nscale {scale:.9g}\ndata\n").encode()


def encode_binvox(coords: np.ndarray, dim: int, translate=(0.0, 0.0, 0.0), scale: float = 1.0) -> bytes:
    """binvox bytes for sparse voxels; runs are built from the sorted indices, never a dense grid."""
    idx = sorted_unique(_binvox_index(np.asarray(coords, dtype=np.int64).reshape(-1, 3), dim))
    return _binvox_header_bytes(dim, translate, scale) + b"".join(_run_bytes(idx, dim ** 3))


def encode_binvox_codes(codes: np.ndarray, depth: int, translate=(0.0, 0.0, 0.0), scale: float = 1.0) -> bytes:
    """binvox bytes of a ``2**depth`` grid for distinct Morton codes: their binvox indices
    (one 8-byte array, made in batches and sorted in place) and then runs, a block at a time."""
    dim = 1 << depth
    idx = np.empty(len(codes), dtype=np.int64)
    for a in range(0, len(codes), _VOXEL_BATCH):
        idx[a:a + _VOXEL_BATCH] = _binvox_index(morton_decode(codes[a:a + _VOXEL_BATCH], depth), dim)
    idx.sort()
    return _binvox_header_bytes(dim, translate, scale) + b"".join(_run_bytes(idx, dim ** 3))


def _runs(idx: np.ndarray):
    """(starts, ends) of the maximal runs of consecutive sorted distinct indices, block by block."""
    pending = None
    for a in range(0, len(idx), _VOXEL_BATCH):
        block = idx[a:a + _VOXEL_BATCH]
        brk = np.flatnonzero(np.diff(block) != 1)
        starts, ends = np.r_[block[0], block[brk + 1]], np.r_[block[brk] + 1, block[-1] + 1]
        if pending is not None and pending[1] == starts[0]:
            starts[0] = pending[0]  # the run goes on across the blocks
        elif pending is not None:
            yield pending[:1], pending[1:]
        pending = np.r_[starts[-1], ends[-1]]
        yield starts[:-1], ends[:-1]
    if pending is not None:
        yield pending[:1], pending[1:]


def _run_bytes(idx: np.ndarray, total: int):
    """binvox run pairs (value, count <= 255) of a grid of ``total`` voxels with ``idx`` solid."""
    done = 0
    for starts, ends in _runs(idx):
        # alternate runs of 0 and 1: the gap before each run of ones, then the ones
        gaps = starts - np.r_[done, ends[:-1]]
        yield _pairs(np.tile([0, 1], len(starts)), np.stack([gaps, ends - starts], 1).ravel())
        done = int(ends[-1]) if len(ends) else done
    yield _pairs(np.zeros(1, np.int64), np.array([total - done]))  # the empty tail


def _pairs(values: np.ndarray, lengths: np.ndarray) -> bytes:
    """Runs of ``values`` of any ``lengths`` (zero: none) as pairs of counts at most 255."""
    values, lengths = values[lengths > 0], lengths[lengths > 0]
    chunks = (lengths + 254) // 255
    v = np.repeat(values, chunks)
    first = np.cumsum(chunks) - chunks
    counts = np.full(int(chunks.sum()), 255, dtype=np.int64)
    counts[first + chunks - 1] = lengths - 255 * (chunks - 1)
    return np.stack([v, counts], 1).astype(np.uint8).tobytes()


_RUN_BLOCK = 1 << 16
"""Run pairs read per pass of the binvox decoder (its temporaries are a few per run)."""
_VOXEL_BATCH = 1 << 19
"""Voxels expanded at once from runs (a run stands for at most 255)."""
MAX_BINVOX_DIM = 1 << 16
"""Largest binvox grid side: the octree depth ``svo build --depth`` accepts (16)."""


def _binvox_header(data: bytes, name: str) -> tuple[int, int, np.ndarray, float]:
    """(offset of the run data, dim, translate, scale) of a binvox file's text header."""
    pos = data.find(b"data\n")
    if not data.startswith(b"#binvox") or pos < 0:
        raise Rend3rError(f"{name}: not a binvox file")
    dim, translate, scale = None, np.zeros(3), 1.0
    at = 0
    for line in data[:pos].decode("ascii", "replace").split("\n")[1:]:
        at = data.index(b"\n", at) + 1
        p = line.split()
        try:
            if p and p[0] == "dim":
                dims = [int(x) if x.isdigit() and len(x) <= 6 else 0 for x in p[1:]]
                if len(dims) != 3 or len(set(dims)) != 1 or not 1 <= dims[0] <= MAX_BINVOX_DIM:
                    raise ValueError(f"needs a cubic 'dim' of 1..{MAX_BINVOX_DIM} (got {line[:60]!r})")
                dim = dims[0]
            elif p and p[0] == "translate":
                translate = np.array([float(x) for x in p[1:4]])
            elif p and p[0] == "scale":
                scale = float(p[1])
        except (ValueError, IndexError) as exc:
            raise Rend3rError(f"{name}: byte {at}: malformed binvox header line: {str(exc)[:100]}") from None
    if dim is None:
        raise Rend3rError(f"{name}: binvox needs a cubic 'dim'")
    return pos + 5, dim, translate, scale


def _run_pairs(data: bytes, start: int, dim: int, name: str) -> tuple[np.ndarray, np.ndarray, int]:
    """(values, counts) views of the run pairs and the number of solid voxels.

    The runs are checked in blocks before any voxel is made: they must cover the
    ``dim**3`` grid exactly; an error names the byte offset of the run at fault.
    """
    rle = np.frombuffer(data, np.uint8, offset=start)
    if len(rle) % 2:
        raise Rend3rError(f"{name}: byte {start + len(rle) - 1}: truncated binvox data (a run value "
                          "without its count)")
    values, counts = rle[0::2], rle[1::2]
    total, solid, cells = 0, 0, dim ** 3
    for a in range(0, len(counts), _RUN_BLOCK):
        run = np.cumsum(counts[a:a + _RUN_BLOCK], dtype=np.int64) + total
        if run[-1] > cells:
            over = a + int(np.searchsorted(run, cells, side="right"))
            raise Rend3rError(f"{name}: byte {start + 2 * over}: binvox runs overflow the {dim}^3 grid "
                              f"({cells:,} voxels)")
        total = int(run[-1])
        solid += int(counts[a:a + _RUN_BLOCK].sum(where=values[a:a + _RUN_BLOCK] != 0, dtype=np.int64))
    if total < cells:
        raise Rend3rError(f"{name}: byte {len(data)}: truncated binvox data (runs end at voxel {total:,} "
                          f"of {cells:,})")
    return values, counts, solid


def decode_binvox_codes(data: bytes, name: str = "<binvox>", budget: Callable[[int], None] | None = None,
                        ) -> tuple[np.ndarray, int, np.ndarray, float]:
    """A binvox file's voxels as sorted Morton codes: (codes, dim, translate, scale).

    The grid's depth is the smallest with ``2**depth >= dim``. The runs are checked
    first (:func:`_run_pairs`); ``budget(solid voxels)`` may then refuse the file
    before the codes (8 bytes a voxel, the only array as long as the voxels) are made,
    a batch of runs at a time.
    """
    start, dim, translate, scale = _binvox_header(data, name)
    values, counts, solid = _run_pairs(data, start, dim, name)
    if budget is not None:
        budget(solid)
    depth = max((dim - 1).bit_length(), 1)
    codes = np.empty(solid, dtype=np.int64)
    held, first = 0, 0
    for a in range(0, len(counts), _RUN_BLOCK):
        size = counts[a:a + _RUN_BLOCK].astype(np.int64)
        on = values[a:a + _RUN_BLOCK] != 0
        run_start, size = (np.cumsum(size) - size + first)[on], size[on]
        first += int(counts[a:a + _RUN_BLOCK].sum(dtype=np.int64))
        for part in batches(size, _VOXEL_BATCH):
            run, k = expand_counts(size[part])
            idx = run_start[part][run] + k
            x, rem = np.divmod(idx, dim * dim)
            batch = morton_encode(np.stack([x, rem % dim, rem // dim], 1), depth)
            codes[held:held + len(batch)] = batch
            held += len(batch)
    codes.sort()
    return codes, dim, translate, scale


def decode_binvox(data: bytes, name: str = "<binvox>") -> tuple[np.ndarray, int, np.ndarray, float]:
    """A binvox file's voxels as coordinates (k, 3) in Morton order: (coords, dim, translate, scale)."""
    codes, dim, translate, scale = decode_binvox_codes(data, name)
    return morton_decode(codes, max((dim - 1).bit_length(), 1)), dim, translate, scale


def read_binvox_codes(path: str | os.PathLike[str], budget: Callable[[int, int], None] | None = None):
    """:func:`decode_binvox_codes` of a file of at most :data:`MAX_MESH` bytes; ``budget``
    is called with (solid voxels, the file's size)."""
    data = read_limited(path, MAX_MESH, what="binvox file")
    check = None if budget is None else (lambda solid: budget(solid, len(data)))
    return decode_binvox_codes(data, str(path), check)


def read_binvox(path: str | os.PathLike[str]):
    """:func:`decode_binvox` of a file of at most :data:`MAX_MESH` bytes."""
    return decode_binvox(read_limited(path, MAX_MESH, what="binvox file"), str(path))


def write_binvox(path: str | os.PathLike[str], coords: np.ndarray, dim: int,
                 translate=(0.0, 0.0, 0.0), scale: float = 1.0) -> None:
    write_atomic(path, encode_binvox(coords, dim, translate, scale))
