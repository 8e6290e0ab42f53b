"""Mesh file formats, parsed with numpy only: OBJ, PLY (ascii, binary little and big
endian) and STL (ascii and binary) read/write (binvox grids: :mod:`rend3r.svo.binvox`).

Meshes are ``(verts (n, 3) float64, faces (m, 3) int64)``; polygons are fanned into
triangles.
"""

from __future__ import annotations

import os
import struct
from pathlib import Path

import numpy as np

from ..errors import Rend3rError
from ..fileio import read_limited, write_atomic

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
