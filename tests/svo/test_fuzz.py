"""Hypothesis fuzzing of the SVO parsers with a fixed budget: mutated ``.svo`` files and
OBJ/PLY/STL meshes must load cleanly or fail with a Rend3rError, never anything else.

A mutated ``.svo`` that loads is traced with the numpy kernel, whose fancy indexing
raises IndexError on any out-of-bounds read: the oracle that the load-time check let
through nothing a kernel could read outside the words.
"""

from __future__ import annotations

import os

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rend3r.errors import Rend3rError
from rend3r.svo.fileformat import SvoModel, decode_svo, encode_svo
from rend3r.svo.mesh_io import format_obj, format_ply, format_stl, read_mesh
from rend3r.svo.models import make_model
from rend3r.svo.octree import build_octree, octree_to_voxels
from rend3r.svo.traverse import trace
from rend3r.svo.voxelize import voxelize

from .conftest import random_voxels

# a fixed budget in CI; REND3R_FUZZ_EXAMPLES=N runs N random examples per test instead
_LONG = int(os.environ.get("REND3R_FUZZ_EXAMPLES", "0"))
FUZZ = settings(max_examples=_LONG or 150, deadline=None, derandomize=not _LONG, database=None,
                suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
HEADER = 72


def _svo(ptr_bits: int) -> bytes:
    coords = random_voxels(4, 120, ptr_bits)
    return encode_svo(SvoModel(build_octree(coords, 4, ptr_bits), (-1.0, -1.0, -1.0, 1.0, 1.0, 1.0), len(coords)))


SVO_FILES = {bits: _svo(bits) for bits in (4, 15)}  # with and without far pointers
_RNG = np.random.default_rng(5)
RAYS = (_RNG.uniform(-3, 3, (64, 3)), _RNG.normal(size=(64, 3)))


def _mutate(data: bytes, flips: list[int], cut: int | None, pokes: list[tuple[int, int]]) -> bytes:
    out = bytearray(data)
    for bit in flips:
        out[bit // 8 % len(out)] ^= 1 << (bit % 8)
    for pos, value in pokes:
        out[pos % len(out)] = value
    return bytes(out[:cut] if cut is not None else out)


def _load_or_refuse(data: bytes) -> SvoModel | None:
    try:
        return decode_svo(data, "f.svo")
    except Rend3rError as exc:
        assert str(exc).startswith("f.svo: ")
        return None


@FUZZ
@given(bits=st.sampled_from([4, 15]),
       flips=st.lists(st.integers(0, 8 * 4096), max_size=4),
       cut=st.none() | st.integers(0, 4096),
       pokes=st.lists(st.tuples(st.integers(0, 4096), st.integers(0, 255)), max_size=3))
def test_mutated_svo_loads_and_traces_or_is_refused(bits, flips, cut, pokes):
    model = _load_or_refuse(_mutate(SVO_FILES[bits], flips, cut, pokes))
    if model is None:
        return
    octree_to_voxels(model.tree)
    for fixed in (True, False):
        r = trace(model.tree, *RAYS, stack_depth=2, fixed=fixed, kernel="numpy")
        assert np.all(r.voxel[r.hit] >= 0) and np.all(r.voxel[r.hit] < 16)


@FUZZ
@given(words=st.integers(1, 40), body=st.binary(max_size=160), depth=st.integers(1, 6))
def test_random_words_behind_a_valid_header(words, body, depth):
    header = bytearray(SVO_FILES[15][:HEADER])
    header[6:8] = depth.to_bytes(2, "little")
    header[12:16] = words.to_bytes(4, "little")
    model = _load_or_refuse(bytes(header) + body.ljust(4 * words, b"\0")[:4 * words])
    if model is not None:
        trace(model.tree, *RAYS, stack_depth=1, kernel="numpy")


def _mesh_bytes(kind: str) -> bytes:
    verts, faces = make_model("sphere", 4)
    return {"obj": format_obj(verts, faces), "ply": format_ply(verts, faces, True),
            "plya": format_ply(verts, faces, False), "stl": format_stl(verts, faces, True),
            "stla": format_stl(verts, faces, False)}[kind]


MESHES = {k: _mesh_bytes(k) for k in ("obj", "ply", "plya", "stl", "stla")}
HOSTILE_TOKENS = [b"nan", b"inf", b"-inf", b"1e308", b"-1e308", b"100000000000000000000", b"0", b"-1",
                  b"4294967296", b"\xff\xfe", b"f", b"v", b"element", b"list", b"\n", b" ", b"/"]


def _check_mesh(tmp_path, kind: str, data: bytes) -> None:
    path = tmp_path / f"m.{kind[:3]}"
    path.write_bytes(data)
    try:
        verts, faces = read_mesh(path)
    except Rend3rError as exc:
        assert str(exc).startswith(str(path)), exc
        return
    assert np.all(np.isfinite(verts)) and faces.min() >= 0 and faces.max() < len(verts)
    try:
        coords, _, _ = voxelize(verts, faces, 3, solid=True, budget=1 << 30)
    except Rend3rError:
        return
    assert len(coords) and coords.min() >= 0 and coords.max() < 8


@FUZZ
@given(kind=st.sampled_from(sorted(MESHES)), flips=st.lists(st.integers(0, 8 * 2000), max_size=6),
       cut=st.none() | st.integers(0, 2000),
       inserts=st.lists(st.tuples(st.integers(0, 2000), st.sampled_from(HOSTILE_TOKENS)), max_size=4))
def test_mutated_meshes_parse_or_are_refused(tmp_path, kind, flips, cut, inserts):
    data = bytearray(_mutate(MESHES[kind], flips, cut, []))
    for pos, token in inserts:
        pos %= len(data) + 1
        data[pos:pos] = token
    _check_mesh(tmp_path, kind, bytes(data))


@FUZZ
@given(kind=st.sampled_from(["obj", "ply", "stl"]), data=st.binary(max_size=400))
def test_binary_garbage_meshes(tmp_path, kind, data):
    _check_mesh(tmp_path, kind, data)


@FUZZ
@given(values=st.lists(st.sampled_from([0.0, 1.0, -1.0, 1e308, -1e308, 1e-320, float("nan"), float("inf"),
                                        1e150, 3.5]), min_size=9, max_size=9),
       index=st.sampled_from([1, 2, 3, 0, -1, -4, 4, 10 ** 20, -(10 ** 20)]))
def test_obj_extreme_values_and_indices(tmp_path, values, index):
    text = "".join(f"v {values[i]} {values[i + 1]} {values[i + 2]}\n" for i in (0, 3, 6))
    _check_mesh(tmp_path, "obj", (text + f"f 1 2 {index}\n").encode())


@pytest.mark.parametrize("kind", sorted(MESHES))
def test_unmutated_meshes_still_load(tmp_path, kind):
    verts, faces = read_mesh_bytes(tmp_path, kind)
    assert len(verts) and len(faces)


def read_mesh_bytes(tmp_path, kind):
    path = tmp_path / f"m.{kind[:3]}"
    path.write_bytes(MESHES[kind])
    return read_mesh(path)
