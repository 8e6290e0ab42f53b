"""The voxeliser against trimesh (an independent implementation).

trimesh.voxel.creation.voxelize marks the voxels holding points of a finely subdivided
mesh; every such voxel overlaps the surface, so it must be in our exact triangle/box set
(our grid is aligned with trimesh's by shifting the mesh so that our voxel centres fall
on multiples of the pitch, trimesh's centre convention). Ours also holds voxels the
surface only clips at a corner or edge, which point sampling misses: up to 15% more,
each within half a voxel diagonal of the surface.
"""

import numpy as np
import pytest
import trimesh

from rend3r.errors import Rend3rError
from rend3r.svo.models import folded, sphere, torus
from rend3r.svo.voxelize import fit_bounds, voxelize


def _as_set(coords):
    return set(map(tuple, np.asarray(coords).tolist()))


@pytest.mark.parametrize("name,mesh", [("sphere", sphere(24)), ("torus", torus(32)), ("folded", folded(48))])
def test_surface_against_trimesh(name, mesh):
    v, f = mesh
    depth = 5
    ours, lo, h = voxelize(v, f, depth)
    shifted = trimesh.Trimesh(v - (lo + 0.5 * h), f)
    grid = trimesh.voxel.creation.voxelize(shifted, pitch=h)
    theirs = _as_set(np.rint(grid.points / h).astype(int))
    mine = _as_set(ours)
    assert theirs <= mine
    extra = np.array(sorted(mine - theirs))
    assert len(extra) <= 0.15 * len(mine)
    if len(extra):
        # distance to the surface, bounded by a dense vertex sampling (edges <= h/4)
        pts, _ = trimesh.remesh.subdivide_to_size(shifted.vertices, shifted.faces, h / 4)
        centres = extra[np.random.default_rng(0).permutation(len(extra))[:150]] * h
        nearest = np.min([np.linalg.norm(pts[None, i:i + 4096] - centres[:, None], axis=2).min(1)
                          for i in range(0, len(pts), 4096)], axis=0)
        assert np.all(nearest <= (np.sqrt(3) / 2 + 1 / 4) * h)


def _in_sphere(p):
    return np.linalg.norm(p, axis=1) < 1


def _in_torus(p):
    return (np.hypot(p[:, 0], p[:, 1]) - 1) ** 2 + p[:, 2] ** 2 < 0.35**2


@pytest.mark.parametrize("mesh,inside_fn", [(sphere(24), _in_sphere), (torus(32), _in_torus)])
def test_solid_against_trimesh_fill(mesh, inside_fn):
    v, f = mesh
    ours, lo, h = voxelize(v, f, 5, solid=True)
    grid = trimesh.voxel.creation.voxelize(trimesh.Trimesh(v - (lo + 0.5 * h), f), pitch=h).fill()
    theirs = _as_set(np.rint(grid.points / h).astype(int))
    mine = _as_set(ours)
    assert theirs <= mine
    assert len(mine - theirs) <= 0.03 * len(mine)
    # interior voxel centres are inside the mesh (inscribed in the analytic shape)
    inside = np.array(sorted(mine - _as_set(voxelize(v, f, 5)[0])))
    assert len(inside) > 100 and inside_fn(lo + (inside + 0.5) * h).all()


def test_padding_and_convention():
    v, f = sphere(16)
    for depth in (3, 6):
        coords, lo, h = voxelize(v, f, depth)
        n = 1 << depth
        assert coords.min() >= 1 and coords.max() <= n - 2
        # the cube is centred on the mesh and n voxels wide
        assert np.allclose(lo + n * h / 2, (v.min(0) + v.max(0)) / 2)
    lo, h = fit_bounds(v, 4)
    assert h == pytest.approx(2 / (16 - 2.5))


def test_single_triangle_exact():
    """One triangle in a 4^3 grid: compare with dense point sampling plus the SAT rule."""
    tri = np.array([[0.1, 0.2, 0.3], [0.9, 0.1, 0.7], [0.3, 0.8, 0.95]])
    v = np.concatenate([tri, [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]]])
    f = np.array([[0, 1, 2]])
    coords, lo, h = voxelize(v, f, 2)
    rng = np.random.default_rng(0)
    ab = rng.random((200000, 2))
    ab = np.where(ab.sum(1, keepdims=True) > 1, 1 - ab, ab)
    pts = tri[0] + ab[:, :1] * (tri[1] - tri[0]) + ab[:, 1:] * (tri[2] - tri[0])
    sampled = _as_set(np.floor((pts - lo) / h).astype(int))
    assert sampled <= _as_set(coords)
    assert len(_as_set(coords) - sampled) <= 2


def test_errors():
    with pytest.raises(Rend3rError):
        voxelize(np.zeros((3, 3)), np.zeros((0, 3), dtype=int), 3)
    with pytest.raises(Rend3rError):
        voxelize(np.zeros((3, 3)), np.array([[0, 1, 5]]), 3)
    with pytest.raises(Rend3rError):
        voxelize(np.array([[np.nan, 0, 0], [1, 0, 0], [0, 1, 0]]), np.array([[0, 1, 2]]), 3)


def test_deep_grid_small_triangle():
    """Depth 16: a small triangle in a 65536^3 grid voxelises without a dense grid."""
    v = np.array([[0.0, 0.0, 0.0], [1.0, 1.0, 1.0],  # these two only set the bounds
                  [0.5, 0.5, 0.5], [0.5005, 0.5001, 0.5], [0.5, 0.5004, 0.5003]])
    coords, lo, h = voxelize(v, np.array([[2, 3, 4]]), 16)
    assert 200 < len(coords) < 20000
    centre = (np.array([0.5, 0.5, 0.5]) - lo) / h
    assert np.all(np.abs(coords - centre) < 60)


def test_large_triangles_are_split_without_changing_the_result(monkeypatch):
    from rend3r.svo import voxelize as vox
    v, f = sphere(6)
    coords, lo, h = voxelize(v, f, 6)
    monkeypatch.setattr(vox, "_CHUNK", 64)  # forces every triangle to be split many times
    split, _, _ = voxelize(v, f, 6)
    assert _as_set(split) == _as_set(coords)


@pytest.mark.parametrize("solid", [False, True])
@pytest.mark.parametrize("verts", [[[1, 2, 3]] * 3, [[0, 0, 0], [1, 1, 1], [3, 3, 3]]], ids=["equal", "collinear"])
def test_degenerate_mesh_has_no_area(verts, solid):
    with pytest.raises(Rend3rError, match="has no area"):
        voxelize(np.array(verts, float), np.array([[0, 1, 2]]), 3, solid=solid)


def test_degenerate_triangles_are_skipped_beside_real_ones():
    v = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0.5, 0.5, 0.5]])  # all vertices set the bounds
    good, _, _ = voxelize(v, np.array([[0, 1, 2]]), 4)
    mixed, _, _ = voxelize(v, np.array([[0, 1, 2], [3, 3, 3], [0, 3, 3], [0, 1, 1]]), 4)
    assert len(good) and _as_set(mixed) == _as_set(good)


def test_edge_on_triangle_fills_no_column():
    """Seen from +z this wall has no area: the solid fill adds nothing, without warnings."""
    wall = np.array([[0.0, 0, 0], [1, 0, 0], [0, 0, 1]])
    with np.errstate(all="raise"):
        solid, _, _ = voxelize(wall, np.array([[0, 1, 2]]), 3, solid=True)
    surface, _, _ = voxelize(wall, np.array([[0, 1, 2]]), 3)
    assert len(surface) and _as_set(solid) == _as_set(surface)


def test_svo_build_of_a_degenerate_obj_is_a_clean_error(tmp_path):
    from click.testing import CliRunner

    from rend3r.cli import main

    obj = tmp_path / "flat.obj"
    obj.write_text("v 0 0 0\nv 0 0 0\nv 0 0 0\nf 1 2 3\n")
    r = CliRunner().invoke(main, ["svo", "build", str(obj), "-o", str(tmp_path / "x.svo"), "--depth", "3"])
    assert r.exit_code == 1 and f"{obj}: mesh has no area" in r.output, r.output
    assert not (tmp_path / "x.svo").exists()


# (voxels, words, first 16 hex digits of the words' SHA-256) of the builder before the
# depth-12 memory work (commit c4e3241): the lean builder writes the same bytes
_BEFORE = {
    ("torus", 8, False, 15): (174936, 65029, "3cdb8044f9c8c28c"),
    ("torus", 8, False, 4): (174936, 74176, "65968755929e4089"),
    ("folded", 7, False, 15): (84440, 27255, "64faf83a26474610"),
    ("folded", 7, False, 4): (84440, 33735, "95b9827985324430"),
    ("sphere", 6, True, 15): (130480, 20505, "26b684512bf56567"),
    ("sphere", 6, True, 4): (130480, 23456, "d7057282f0e25cee"),
}


@pytest.mark.parametrize("block", [1 << 22, 61], ids=["one-block", "many-blocks"])
@pytest.mark.parametrize("key", list(_BEFORE), ids=lambda k: "-".join(map(str, k)))
def test_octree_bytes_unchanged_by_the_memory_work(key, block, monkeypatch):
    import hashlib

    from rend3r.svo import octree
    from rend3r.svo.models import make_model
    from rend3r.svo.octree import build_octree_codes

    monkeypatch.setattr(octree, "_BLOCK", block)  # levels derived in blocks ending on parent boundaries
    from rend3r.svo.voxelize import voxelize_codes

    name, depth, solid, ptr_bits = key
    codes, _, _ = voxelize_codes(*make_model(name), depth, solid)
    words = build_octree_codes(codes, depth, ptr_bits).words
    digest = hashlib.sha256(words.astype("<u4").tobytes()).hexdigest()[:16]
    assert (len(codes), len(words), digest) == _BEFORE[key]


def test_budget_deduplication_mid_stream_keeps_the_result(monkeypatch):
    """A voxel limit just above the count deduplicates the growing buffer between batches."""
    from rend3r.svo import voxelize as vox
    from rend3r.svo.voxelize import voxelize_surface

    v, f = torus(32)
    lo, h = fit_bounds(v, 6)
    tri = (v[f] - lo) / h
    whole = voxelize_surface(tri, 64)
    monkeypatch.setattr(vox, "_CHUNK", 256)  # many small batches: keys repeat between them
    calls = []
    dedupe = vox._dedupe
    monkeypatch.setattr(vox, "_dedupe", lambda values, count: calls.append(count) or dedupe(values, count))
    assert np.array_equal(voxelize_surface(tri, 64, max_voxels=len(whole)), whole)
    assert len(calls) > 1
    with pytest.raises(Rend3rError, match="more than"):
        voxelize_surface(tri, 64, max_voxels=len(whole) - 1)
