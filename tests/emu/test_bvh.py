"""The shape hierarchy (rend3r/emu/bvh.py): every bounded shape in exactly one leaf, boxes
that hold their shapes' balls, floors that are the least below, depth within the
traversal stacks' room; the nearest hits it leads to are checked against the reference
renderer in test_engine_vs_reference.py."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from rend3r.emu import bvh, native

STACK = 64  # csrc/bvh.h BVH_STACK


def table(centers: np.ndarray) -> np.ndarray:
    bnd = np.zeros((len(centers), native.B_COLUMNS))
    bnd[:, :3] = centers
    bnd[:, 3:] = 1.0
    return bnd


def walk(tree: bvh.Tree) -> list[tuple[int, int]]:
    """(node, depth) of every node reached from the root, checking the links."""
    seen, todo = [], [(0, 0)] if tree.nodes else []
    while todo:
        at, depth = todo.pop()
        seen.append((at, depth))
        first, count = (int(v) for v in tree.node[at])
        if count == 0:
            assert at + 1 < tree.nodes and at + 1 < first < tree.nodes
            todo += [(at + 1, depth + 1), (first, depth + 1)]
    return seen


@settings(max_examples=60, derandomize=True)
@given(st.integers(0, 3000), st.integers(0, 2**32 - 1), st.booleans())
def test_every_bounded_shape_is_in_exactly_one_leaf(n, seed, clustered):
    rng = np.random.default_rng(seed)
    centers = rng.normal(size=(n, 3)) * (rng.random((n, 1)) < 0.5 if clustered else 1.0)  # many equal centres
    bounded = rng.random(n) < 0.9
    if n:
        centers[rng.integers(0, n)] = np.inf  # a shape at infinity stays outside
    bnd = table(centers)
    tree = bvh.build(bnd, bounded)
    inside = bounded & np.isfinite(centers).all(axis=1)
    assert sorted(tree.items.tolist()) == np.flatnonzero(inside).tolist()
    assert tree.always.tolist() == np.flatnonzero(~inside).tolist()
    nodes = walk(tree)
    assert sorted(at for at, _ in nodes) == list(range(tree.nodes))
    leaves = [tree.node[at] for at, _ in nodes if tree.node[at][1] > 0]
    covered = sorted(i for first, count in leaves for i in range(first, first + count))
    assert covered == list(range(len(tree.items)))
    assert all(count <= 4 for _, count in leaves)
    assert max((d for _, d in nodes), default=0) + 2 < STACK


@settings(max_examples=40, derandomize=True)
@given(st.integers(1, 500), st.integers(0, 2**32 - 1))
def test_boxes_hold_the_balls_and_floors_are_the_least(n, seed):
    rng = np.random.default_rng(seed)
    bnd = table(rng.normal(size=(n, 3)) * 10.0 ** rng.integers(-3, 4, size=(n, 1)))
    radius = rng.random(n) * 10.0 ** rng.integers(-3, 3, size=n)
    radius[rng.random(n) < 0.05] = np.inf
    floor = rng.random(n)
    tree = bvh.build(bnd, np.ones(n, bool))
    box = tree.refit(bnd, radius, floor)
    for at, _ in walk(tree):
        first, count = (int(v) for v in tree.node[at])
        below = tree.items[first:first + count] if count else None
        if below is None:  # the union of the children
            left, right = box[at + 1], box[first]
            assert (box[at, :3] == np.minimum(left[:3], right[:3])).all()
            assert (box[at, 3:6] == np.maximum(left[3:6], right[3:6])).all()
            assert box[at, native.BV_FLOOR] == min(left[native.BV_FLOOR], right[native.BV_FLOOR])
            continue
        c, r = bnd[below, :3], radius[below, None]
        assert (box[at, :3] <= c - r).all() and (box[at, 3:6] >= c + r).all()
        assert box[at, native.BV_FLOOR] == floor[below].min()


def test_a_nan_radius_gives_an_infinite_box():
    bnd = table(np.zeros((2, 3)))
    tree = bvh.build(bnd, np.ones(2, bool))
    box = tree.refit(bnd, np.array([1.0, np.nan]))
    assert (box[0, :3] == -np.inf).all() and (box[0, 3:6] == np.inf).all()
    assert box[0, native.BV_FLOOR] == -np.inf  # no floors given


def test_refit_checks_its_arrays():
    bnd = table(np.zeros((3, 3)))
    tree = bvh.build(bnd, np.ones(3, bool))
    with pytest.raises(TypeError):
        tree.refit(bnd, np.ones(2))
