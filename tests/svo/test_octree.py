import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from rend3r.errors import Rend3rError
from rend3r.svo.fileformat import SvoModel, decode_svo, encode_svo, read_svo, write_svo
from rend3r.svo.octree import (build_octree, child_table, morton_decode, morton_encode,
                               octree_to_voxels, split_word)

from .conftest import random_voxels


def _sorted(c, depth):
    return c[np.argsort(morton_encode(c, depth))]


@settings(max_examples=40)
@given(depth=st.integers(1, 6), count=st.integers(1, 400), seed=st.integers(0, 2**31),
       ptr_bits=st.sampled_from([4, 5, 8, 15]))
def test_round_trip(depth, count, seed, ptr_bits):
    coords = random_voxels(depth, count, seed)
    tree = build_octree(coords, depth, ptr_bits)
    assert np.array_equal(octree_to_voxels(tree), _sorted(coords, depth))


def test_morton_round_trip():
    c = random_voxels(10, 1000, 3)
    assert np.array_equal(morton_decode(morton_encode(c, 10), 10), c)
    # bit 2 of each triple is x: voxel (1, 0, 0) is child 4 of the root
    assert morton_encode(np.array([[1, 0, 0], [0, 1, 0], [0, 0, 1]]), 1).tolist() == [4, 2, 1]


def test_far_pointers_forced_by_narrow_pointers():
    coords = random_voxels(6, 3000, 1)
    near = build_octree(coords, 6, 15)
    far = build_octree(coords, 6, 4)
    assert near.far_count() == 0
    assert far.far_count() > 100
    assert len(far.words) == len(near.words) + far.far_count()
    assert np.array_equal(octree_to_voxels(far), octree_to_voxels(near))
    # every far node's slot is within reach of the narrow pointer and resolves forward
    w = far.words.astype(np.int64)
    ptr, is_far, valid, leaf = split_word(w)
    for addr in np.flatnonzero(is_far)[:50]:
        assert 0 < ptr[addr] <= 15
        table, used_far = child_table(far.words, np.array([addr]))
        assert used_far[0] and table[0] > addr


def test_far_pointers_from_width():
    """A wide tree at depth 8 needs far pointers with the thesis's 15-bit pointers."""
    rng = np.random.default_rng(5)
    coords = np.unique(rng.integers(0, 256, (120000, 3)), axis=0)
    tree = build_octree(coords, 8)
    assert tree.far_count() > 0
    assert np.array_equal(octree_to_voxels(tree), _sorted(coords, 8))


def test_node_word_layout():
    tree = build_octree(np.array([[0, 0, 0], [1, 1, 1]]), 1)
    assert tree.words.tolist() == [(0b10000001 << 8) | 0b10000001]
    tree = build_octree(np.array([[3, 3, 3]]), 2)
    ptr, is_far, valid, leaf = split_word(tree.words.astype(np.int64))
    assert ptr[0] == 1 and is_far[0] == 0 and valid[0] == 0x80 and leaf[0] == 0
    assert valid[1] == 0x80 and leaf[1] == 0x80


def test_build_errors():
    with pytest.raises(Rend3rError):
        build_octree(np.zeros((0, 3)), 3)
    with pytest.raises(Rend3rError):
        build_octree(np.array([[8, 0, 0]]), 3)
    with pytest.raises(Rend3rError):
        build_octree(np.array([[0, 0, 0]]), 3, ptr_bits=3)


def test_file_round_trip_and_errors(tmp_path):
    coords = random_voxels(4, 50, 2)
    model = SvoModel(build_octree(coords, 4, 5), (-1.0, -2.0, -3.0, 1.0, 2.0, 3.0), len(coords))
    path = tmp_path / "m.svo"
    write_svo(path, model)
    back = read_svo(path)
    assert np.array_equal(back.tree.words, model.tree.words)
    assert back.tree.depth == 4 and back.tree.ptr_bits == 5
    assert back.bounds == model.bounds and back.voxel_count == len(coords)
    data = encode_svo(model)
    for bad, msg in [(b"XXXX" + data[4:], "magic"), (data[:-4], "words"), (data[:10], "short")]:
        with pytest.raises(Rend3rError, match=msg):
            decode_svo(bad)
    with pytest.raises(Rend3rError, match="cannot read"):
        read_svo(tmp_path / "missing.svo")


def test_deep_sparse_tree_needs_no_dense_grid():
    """Depth 16 (65536^3 voxels) with a few thousand voxels builds in proportion to them."""
    coords = random_voxels(16, 3000, 9)
    tree = build_octree(coords, 16)
    assert len(tree.words) < 16 * len(coords)
    assert np.array_equal(octree_to_voxels(tree), _sorted(coords, 16))
