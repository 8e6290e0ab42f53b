"""Shared helpers for the SVO tests: small random octrees and a brute-force tracer."""

from __future__ import annotations

import os

import numpy as np
import pytest

from rend3r.svo.fixed import clamp_direction
from rend3r.svo.octree import build_octree


def random_voxels(depth: int, count: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return np.unique(rng.integers(0, 1 << depth, (count, 3)), axis=0)


def brute_force(coords: np.ndarray, depth: int, origin: np.ndarray, direction: np.ndarray):
    """Nearest voxel box (closed) each ray enters with positive length: (t, voxel index)."""
    n = 1 << depth
    lo = -1 + 2 * coords / n
    hi = lo + 2 / n
    scale = np.linalg.norm(direction, axis=1)
    dn = clamp_direction(direction / scale[:, None])
    ta = (lo[None] - origin[:, None]) / dn[:, None]
    tb = (hi[None] - origin[:, None]) / dn[:, None]
    te = np.minimum(ta, tb).max(2)
    tx = np.maximum(ta, tb).min(2)
    ok = (te < tx) & (tx > 0)
    t = np.where(ok, np.maximum(te, 0), np.inf)
    best = t.argmin(1)
    return t[np.arange(len(t)), best] / scale, best


@pytest.fixture(scope="module")
def small_tree():
    coords = random_voxels(5, 600, 7)
    return coords, build_octree(coords, 5)


# compile the numba kernel in memory only: the tests write nothing next to the package
os.environ.setdefault("REND3R_JIT_CACHE", "0")
