"""Rays traced in chunks (so Ctrl-C and progress are seen between them) give the same
results as one call over every ray, request trace included."""

import importlib.util

import numpy as np
import pytest

from rend3r.svo import traverse
from rend3r.svo.octree import build_octree
from rend3r.svo.traverse import trace

from .conftest import random_voxels

FIELDS = ("hit", "t", "axis", "voxel", "requests", "steps", "descents", "pops", "restarts",
          "max_level", "max_stack", "trace_ray", "trace_addr", "trace_level")
KERNELS = ["numpy"] + (["numba"] if importlib.util.find_spec("numba") else [])


@pytest.fixture(scope="module")
def scene():
    tree = build_octree(random_voxels(4, 300, 3), 4)
    rng = np.random.default_rng(5)
    origin = rng.uniform(-3, 3, (300, 3))
    direction = rng.uniform(-1, 1, (300, 3)) - origin * 0.3
    return tree, origin, direction


@pytest.mark.parametrize("kernel", KERNELS)
def test_chunks_match_one_call(scene, kernel, monkeypatch):
    tree, o, d = scene
    whole = trace(tree, o, d, 2, True, record=True, kernel=kernel)
    assert whole.hit.any() and not whole.hit.all()
    monkeypatch.setitem(traverse.CHUNK_RAYS, kernel, 7)  # 43 chunks, the last one short
    counts: list[int] = []
    parts = trace(tree, o, d, 2, True, record=True, kernel=kernel, on_rays=counts.append)
    assert counts == [7] * 42 + [6]
    for name in FIELDS:
        x, y = getattr(whole, name), getattr(parts, name)
        assert x.dtype == y.dtype and np.array_equal(x, y), name


@pytest.mark.parametrize("kernel", KERNELS)
def test_no_rays_and_bad_rays(scene, kernel, monkeypatch):
    tree, o, d = scene
    assert len(trace(tree, o[:0], d[:0], kernel=kernel).hit) == 0
    monkeypatch.setitem(traverse.CHUNK_RAYS, kernel, 7)
    d = d.copy()
    d[[3, 250]] = 0.0  # in two different chunks: the error counts both
    with pytest.raises(ValueError, match="^2 rays have"):
        trace(tree, o, d, kernel=kernel)
