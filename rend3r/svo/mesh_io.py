"""Mesh and voxel file formats, parsed with numpy only: OBJ, PLY (ascii, binary little
and big endian), STL (ascii and binary) read/write, and binvox read/write.

Meshes are ``(verts (n, 3) float64, faces (m, 3) int64)``; polygons are fanned into
triangles. binvox voxels are ``(coords (k, 3), dim, translate (3,), scale)``; voxel
``(x, y, z)`` of a binvox grid has its centre at ``translate + (i + 0.5) / dim * scale``
per axis, the same cell-centred convention as :mod:`rend3r.svo.voxelize`. binvox stores
voxels with y running fastest, then z, then x.
"""

from __future__ import annotations

import os
import struct
from collections.abc import Callable
from pathlib import Path

import numpy as np

from ..errors import Rend3rError
from ..fileio import read_limited, write_atomic
from .octree import morton_decode, morton_encode, sorted_unique
from .voxelize import batches, expand_counts

Mesh = tuple[np.ndarray, np.ndarray]
MAX_MESH = 64 << 20
"""Largest mesh or binvox file read (64 MiB): parsing holds several times the file in memory."""


def _fan(polys: list[list[int]], name: str) -> np.ndarray:
    tris = [(p[0], p[i], p[i + 1]) for p in polys for i in range(1, len(p) - 1)]
    if not tris:
        raise Rend3rError(f"{name}: no faces")
    try:
        return np.array(tris, dtype=np.int64)
    except OverflowError:
        raise Rend3rError(f"{name}: face refers to a missing vertex (index beyond 64 bits)") from None


def _check(verts: np.ndarray, faces: np.ndarray, name: str) -> Mesh:
    """Vertices present and finite, every face index naming one of them."""
    if len(verts) == 0:
        raise Rend3rError(f"{name}: no vertices")
    bad = np.flatnonzero(~np.all(np.isfinite(verts), axis=1))
    if len(bad):
        raise Rend3rError(f"{name}: vertex {bad[0] + 1} has a non-finite coordinate {verts[bad[0]].tolist()}")
    wrong = np.flatnonzero(np.any((faces < 0) | (faces >= len(verts)), axis=1))
    if len(wrong):
        raise Rend3rError(f"{name}: triangle {wrong[0] + 1} refers to a missing vertex "
                          f"(indices {faces[wrong[0]].tolist()}, {len(verts)} vertices)")
    return verts, faces


def _count(text, what: str, limit: int, name: str) -> int:
    """A non-negative element or list count no larger than ``limit`` (what the data can hold)."""
    value = int(text)
    if not 0 <= value <= limit:
        raise Rend3rError(f"{name}: {what} count {value} is not in 0..{limit} (the file is {limit} bytes)")
    return value


def parse_obj(text: str, name: str = "<obj>") -> Mesh:
    """Wavefront OBJ: ``v`` and ``f`` lines (``i``, ``i/t``, ``i//n``, ``i/t/n``, negative)."""
    verts: list[list[float]] = []
    polys: list[list[int]] = []
    for lineno, line in enumerate(text.splitlines(), 1):
        parts = line.split("#", 1)[0].split()
        if not parts:
            continue
        try:
            if parts[0] == "v":
                verts.append([float(x) for x in parts[1:4]])
                if len(verts[-1]) != 3:
                    raise ValueError("vertex needs 3 coordinates")
            elif parts[0] == "f":
                idx = [int(p.split("/")[0]) for p in parts[1:]]
                if any(i == 0 or i < -len(verts) for i in idx):
                    raise ValueError(f"face index out of range (OBJ indices start at 1; "
                                     f"{len(verts)} vertices so far)")
                polys.append([i - 1 if i > 0 else len(verts) + i for i in idx])
        except ValueError as exc:
            raise Rend3rError(f"{name}:{lineno}: {exc}") from exc
    return _check(np.array(verts, dtype=np.float64).reshape(-1, 3), _fan(polys, name), name)


_PLY_TYPES = {"char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1", "short": "i2",
              "int16": "i2", "ushort": "u2", "uint16": "u2", "int": "i4", "int32": "i4",
              "uint": "u4", "uint32": "u4", "float": "f4", "float32": "f4",
              "double": "f8", "float64": "f8"}


def parse_ply(data: bytes, name: str = "<ply>") -> Mesh:
    """PLY with a ``vertex`` element (x, y, z) and a ``face`` list element."""
    end = data.find(b"end_header")
    if not data.startswith(b"ply") or end < 0:
        raise Rend3rError(f"{name}: not a PLY file")
    body_start = data.index(b"\n", end) + 1
    header = data[:end].decode("ascii", "replace").splitlines()
    fmt = None
    elements: list[tuple[str, int, list]] = []
    for line in header[1:]:
        p = line.split()
        if not p or p[0] in ("comment", "obj_info"):
            continue
        if p[0] == "format":
            fmt = p[1]
        elif p[0] == "element":
            elements.append((p[1], _count(p[2], f"element {p[1]!r}", len(data), name), []))
        elif p[0] == "property" and elements:
            if p[1] == "list":
                elements[-1][2].append((p[4], "list", _PLY_TYPES[p[2]], _PLY_TYPES[p[3]]))
            else:
                elements[-1][2].append((p[2], _PLY_TYPES[p[1]]))
    if fmt not in ("ascii", "binary_little_endian", "binary_big_endian"):
        raise Rend3rError(f"{name}: unsupported PLY format {fmt}")
    verts = None
    faces = None
    if fmt == "ascii":
        tokens = data[body_start:].split()
        pos = 0
        for el, count, props in elements:
            if all(len(p) == 2 for p in props):
                n = len(props)
                vals = np.array(tokens[pos:pos + n * count], dtype=np.float64).reshape(count, n)
                pos += n * count
                if el == "vertex":
                    names = [p[0] for p in props]
                    verts = vals[:, [names.index(a) for a in "xyz"]]
            else:
                polys = []
                for _ in range(count):
                    row = []
                    for prop in props:
                        if len(prop) == 2:
                            row.append(tokens[pos]); pos += 1
                        else:
                            k = _count(tokens[pos], "list", len(tokens) - pos - 1, name); pos += 1
                            items = [int(t) for t in tokens[pos:pos + k]]; pos += k
                            if el == "face" and prop[0] in ("vertex_indices", "vertex_index"):
                                polys.append(items)
                if el == "face":
                    faces = _fan(polys, name)
    else:
        end_ch = "<" if fmt == "binary_little_endian" else ">"
        buf = memoryview(data)[body_start:]
        pos = 0
        for el, count, props in elements:
            if all(len(p) == 2 for p in props):
                dt = np.dtype([(p[0], end_ch + p[1]) for p in props])
                arr = np.frombuffer(buf, dtype=dt, count=count, offset=pos)
                pos += dt.itemsize * count
                if el == "vertex":
                    verts = np.stack([arr[a].astype(np.float64) for a in "xyz"], 1)
            else:
                polys = []
                for _ in range(count):
                    for prop in props:
                        if len(prop) == 2:
                            pos += np.dtype(prop[1]).itemsize
                            continue
                        ct, it = np.dtype(end_ch + prop[2]), np.dtype(end_ch + prop[3])
                        if ct.kind == "f" or it.kind == "f":
                            raise Rend3rError(f"{name}: list property {prop[0]!r} needs integer types")
                        k = _count(np.frombuffer(buf, ct, 1, pos)[0], "list", len(buf), name)
                        pos += ct.itemsize
                        items = np.frombuffer(buf, it, k, pos).astype(np.int64).tolist()
                        pos += it.itemsize * k
                        if el == "face" and prop[0] in ("vertex_indices", "vertex_index"):
                            polys.append(items)
                if el == "face":
                    faces = _fan(polys, name)
    if verts is None or faces is None:
        raise Rend3rError(f"{name}: PLY needs vertex and face elements")
    return _check(verts, faces, name)


def parse_stl(data: bytes, name: str = "<stl>") -> Mesh:
    """STL, ascii or binary; coincident vertices are merged."""
    if len(data) >= 84:
        (count,) = struct.unpack_from("<I", data, 80)
        if len(data) == 84 + 50 * count:
            rec = np.frombuffer(data, np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")]),
                                count, 84)
            return _merge(rec["v"].astype(np.float64).reshape(-1, 3), name)
    text = data.decode("ascii", "replace")
    if not text.lstrip().startswith("solid"):
        raise Rend3rError(f"{name}: not an STL file")
    vals = [line.split()[1:4] for line in text.splitlines() if line.strip().startswith("vertex")]
    if not vals or len(vals) % 3:
        raise Rend3rError(f"{name}: STL facets need three vertices each")
    try:
        pts = np.array(vals, dtype=np.float64)
    except ValueError as exc:
        raise Rend3rError(f"{name}: bad STL vertex: {exc}") from exc
    return _merge(pts, name)


def _merge(points: np.ndarray, name: str) -> Mesh:
    verts, inverse = np.unique(points, axis=0, return_inverse=True)
    return _check(verts, inverse.reshape(-1, 3).astype(np.int64), name)


def format_obj(verts: np.ndarray, faces: np.ndarray) -> bytes:
    lines = [f"v {x:.9g} {y:.9g} {z:.9g}" for x, y, z in verts]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in faces]
    return ("\n".join(lines) + "\n").encode()


def format_ply(verts: np.ndarray, faces: np.ndarray, binary: bool = True) -> bytes:
    fmt = "binary_little_endian" if binary else "ascii"
    header = (f"ply\nformat {fmt} 1.0\nelement vertex {len(verts)}\nproperty float x\n"
              f"property float y\nproperty float z\nelement face {len(faces)}\n"
              "property list uchar int vertex_indices\nend_header\n").encode()
    if not binary:
        body = "".join(f"{x:.9g} {y:.9g} {z:.9g}\n" for x, y, z in verts)
        body += "".join(f"3 {a} {b} {c}\n" for a, b, c in faces)
        return header + body.encode()
    fdt = np.dtype([("n", "u1"), ("i", "<i4", 3)])
    frec = np.zeros(len(faces), fdt)
    frec["n"], frec["i"] = 3, faces
    return header + verts.astype("<f4").tobytes() + frec.tobytes()


def format_stl(verts: np.ndarray, faces: np.ndarray, binary: bool = True) -> bytes:
    tri = verts[faces]
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    normal /= np.maximum(np.linalg.norm(normal, axis=1, keepdims=True), 1e-30)
    if not binary:
        out = ["solid rend3r"]
        for nrm, t in zip(normal, tri):
            out.append(f" facet normal {nrm[0]:.9g} {nrm[1]:.9g} {nrm[2]:.9g}\n  outer loop")
            out += [f"   vertex {x:.9g} {y:.9g} {z:.9g}" for x, y, z in t]
            out.append("  endloop\n endfacet")
        out.append("endsolid rend3r\n")
        return "\n".join(out).encode()
    rec = np.zeros(len(faces), np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")]))
    rec["n"], rec["v"] = normal, tri
    return b"rend3r".ljust(80, b" ") + struct.pack("<I", len(faces)) + rec.tobytes()


def read_mesh(path: str | os.PathLike[str]) -> Mesh:
    """Read an OBJ, PLY or STL mesh chosen by file extension."""
    p = Path(path)
    ext = p.suffix.lower()
    if ext not in (".obj", ".ply", ".stl"):
        raise Rend3rError(f"{p}: unknown mesh format (use .obj, .ply, .stl or .binvox)")
    data = read_limited(p, MAX_MESH, what="mesh")
    try:
        if ext == ".obj":
            return parse_obj(data.decode("utf-8", "replace"), str(p))
        if ext == ".ply":
            return parse_ply(data, str(p))
        if ext == ".stl":
            return parse_stl(data, str(p))
    except (KeyError, IndexError, ValueError, OverflowError, struct.error) as exc:
        raise Rend3rError(f"{p}: malformed {ext[1:].upper()} file: {exc}") from None
    raise AssertionError(ext)  # every extension above returns


def encode_mesh(path: str | os.PathLike[str], verts: np.ndarray, faces: np.ndarray,
                binary: bool = True) -> bytes:
    """A mesh's bytes as OBJ, PLY or STL by ``path``'s extension (PLY/STL binary unless
    ``binary=False``); Rend3rError for any other extension."""
    ext = Path(path).suffix.lower()
    formats = {".obj": lambda: format_obj(verts, faces), ".ply": lambda: format_ply(verts, faces, binary),
               ".stl": lambda: format_stl(verts, faces, binary)}
    if ext not in formats:
        raise Rend3rError(f"{path}: unknown mesh format (use .obj, .ply or .stl)")
    return formats[ext]()


def write_mesh(path: str | os.PathLike[str], verts: np.ndarray, faces: np.ndarray,
               binary: bool = True) -> None:
    """Write a mesh atomically (:func:`encode_mesh`)."""
    write_atomic(path, encode_mesh(path, verts, faces, binary))


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
