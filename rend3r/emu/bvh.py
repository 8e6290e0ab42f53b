"""The shape hierarchy: a bounding volume tree over the shapes, so a ray's cost grows with
log(shapes).

Built once per frame from the shapes' centres (``csrc/kernels.c`` bvh_build: median splits
across the longest side, leaves of at most 4 shapes); each bundle of rays then refits its
boxes to the balls of its own cull radii and its depth floors (bvh_refit). Shapes without a
finite bound stay outside the tree and every ray tests them. ``csrc/bvh.h`` explains why
skipping a node never changes the nearest hit.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import native


@dataclass(frozen=True)
class Tree:
    """A built hierarchy: nodes (2 ints each), shape slots leaf by leaf, and the slots every
    ray tests."""

    node: np.ndarray  # (nodes, 2) int32
    items: np.ndarray  # int32
    always: np.ndarray  # int32

    @property
    def nodes(self) -> int:
        return len(self.node)

    def struct(self, box: np.ndarray) -> native.Bvh:
        """The kernels' view with one bundle's node boxes (the arrays must outlive it)."""
        native.ptr(box, np.float64, (self.nodes, native.BV_COLUMNS))
        return native.Bvh(self.node.ctypes.data, self.items.ctypes.data, box.ctypes.data, self.nodes,
                          self.always.ctypes.data, len(self.always))

    def refit(self, bnd: np.ndarray, radius: np.ndarray, floor: np.ndarray | None = None) -> np.ndarray:
        """Node boxes (nodes, BV_COLUMNS) holding the balls (centre, ``radius``) of their
        shapes, padded outwards, and their least ``floor`` (None: -inf)."""
        n = len(bnd)
        native.ptr(bnd, np.float64, (n, native.B_COLUMNS))
        radius = np.ascontiguousarray(radius, np.float64)
        native.ptr(radius, np.float64, (n,))
        if floor is not None:
            native.ptr(floor, np.float64, (n,))
        box = np.empty((self.nodes, native.BV_COLUMNS))
        native.library().bvh_refit(self.struct(box), bnd.ctypes.data, radius.ctypes.data,
                                   None if floor is None else floor.ctypes.data, box.ctypes.data)
        return box


def build(bnd: np.ndarray, bounded: np.ndarray) -> Tree:
    """The hierarchy over the shapes of the bound table ``bnd`` (n, B_COLUMNS) that are
    ``bounded`` with a finite centre; the others go to the list every ray tests."""
    n = len(bnd)
    native.ptr(bnd, np.float64, (n, native.B_COLUMNS))
    inside = np.asarray(bounded, bool) & np.isfinite(bnd[:, :3]).all(axis=1)
    items = np.flatnonzero(inside).astype(np.int32)
    node = np.empty((max(1, 2 * len(items)), 2), np.int32)
    count = native.library().bvh_build(bnd.ctypes.data, items.ctypes.data, len(items), node.ctypes.data)
    return Tree(np.ascontiguousarray(node[:count]), items, np.flatnonzero(~inside).astype(np.int32))
