import io

import numpy as np
import pytest
import trimesh

from rend3r.errors import Rend3rError
from rend3r.svo.binvox import decode_binvox, encode_binvox, read_binvox, write_binvox
from rend3r.svo.mesh_io import read_mesh, write_mesh
from rend3r.svo.models import torus

from .conftest import random_voxels


def _same_triangles(v1, f1, v2, f2):
    a = np.sort(np.round(v1[f1], 5).reshape(-1, 9), axis=0)
    b = np.sort(np.round(v2[f2], 5).reshape(-1, 9), axis=0)
    return a.shape == b.shape and np.allclose(a, b, atol=1e-5)


@pytest.mark.parametrize("ext,binary", [(".obj", True), (".ply", True), (".ply", False),
                                        (".stl", True), (".stl", False)])
def test_write_read_round_trip_and_trimesh_reads_it(tmp_path, ext, binary):
    v, f = torus(12)
    path = tmp_path / f"m{ext}"
    write_mesh(path, v, f, binary)
    v2, f2 = read_mesh(path)
    assert _same_triangles(v, f, v2, f2)
    other = trimesh.load(path, process=False, force="mesh")
    assert _same_triangles(v, f, np.asarray(other.vertices), np.asarray(other.faces))


@pytest.mark.parametrize("file_type", ["ply", "stl", "stl_ascii", "obj"])
def test_reads_trimesh_output(tmp_path, file_type):
    v, f = torus(10)
    data = trimesh.Trimesh(v, f).export(file_type=file_type)
    ext = {"stl_ascii": "stl"}.get(file_type, file_type)
    path = tmp_path / f"t.{ext}"
    path.write_bytes(data.encode() if isinstance(data, str) else data)
    v2, f2 = read_mesh(path)
    assert _same_triangles(v, f, v2, f2)


def test_obj_polygons_negative_indices_and_slashes(tmp_path):
    path = tmp_path / "q.obj"
    path.write_text("# quad\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\n"
                    "f 1//1 2//1 3//1 4//1\nf -4/1/1 -2/1/1 -1/1/1\n")
    v, f = read_mesh(path)
    assert f.tolist() == [[0, 1, 2], [0, 2, 3], [0, 2, 3]]


def test_big_endian_ply(tmp_path):
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], dtype=">f4")
    header = (b"ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty float x\n"
              b"property float y\nproperty float z\nelement face 1\n"
              b"property list uchar int vertex_indices\nend_header\n")
    body = v.tobytes() + bytes([3]) + np.array([0, 1, 2], dtype=">i4").tobytes()
    (tmp_path / "b.ply").write_bytes(header + body)
    v2, f2 = read_mesh(tmp_path / "b.ply")
    assert np.array_equal(v2, v.astype(float)) and f2.tolist() == [[0, 1, 2]]


def test_binvox_round_trip_and_trimesh(tmp_path):
    coords = random_voxels(5, 700, 3)
    path = tmp_path / "v.binvox"
    write_binvox(path, coords, 32, (1.0, 2.0, 3.0), 4.0)
    back, dim, translate, scale = read_binvox(path)
    assert dim == 32 and translate.tolist() == [1, 2, 3] and scale == 4
    assert set(map(tuple, back.tolist())) == set(map(tuple, coords.tolist()))
    grid = trimesh.exchange.binvox.load_binvox(io.BytesIO(path.read_bytes()))
    assert grid.matrix.sum() == len(coords) and grid.matrix[tuple(coords.T)].all()
    # runs longer than 255 and an empty grid
    full = np.stack(np.meshgrid(*[np.arange(8)] * 3, indexing="ij"), -1).reshape(-1, 3)
    assert len(decode_binvox(encode_binvox(full, 8))[0]) == 512
    assert len(decode_binvox(encode_binvox(np.zeros((0, 3), int), 8))[0]) == 0


def test_errors(tmp_path):
    (tmp_path / "bad.obj").write_text("v 1 2\nf 1 2 3\n")
    (tmp_path / "bad.ply").write_bytes(b"ply\nformat weird 1.0\nend_header\n")
    (tmp_path / "bad.stl").write_bytes(b"nothing here")
    (tmp_path / "x.xyz").write_text("")
    for name in ("bad.obj", "bad.ply", "bad.stl", "x.xyz", "missing.obj"):
        with pytest.raises(Rend3rError):
            read_mesh(tmp_path / name)
    with pytest.raises(Rend3rError):
        decode_binvox(b"#binvox 1\ndim 4 4 4\ndata\n" + bytes([1, 10]))
