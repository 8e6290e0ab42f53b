"""The shape hierarchy: a bounding volume tree over the shapes, so a ray's cost grows with
log(shapes).

Built once per frame from the shapes' centres (``csrc/kernels.c`` bvh_build: splits along
a Morton curve of the centres, halving the longest side of a node's cell first, leaves of
at most 4 shapes); each bundle of rays then refits its
node bounds to the balls of its own cull radii, and its depth floors (bvh_refit): double
cones around the apex of lines through one point, boxes on the plane normal to parallel
lines. Shapes without a
finite bound stay outside the tree and every ray tests them. ``csrc/bvh.h`` explains why
skipping a node never changes the nearest hit.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from ..errors import Rend3rError
from . import native, threads
from .bounds import SHAPE_CHUNK
from .native import address


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

    def refit(self, bnd: np.ndarray, radius: np.ndarray, floor: np.ndarray | None = None, *,
              apex: np.ndarray | None = None, axes: np.ndarray | None = None,
              keys: np.ndarray | None = None, jobs: int = 1) -> Bounds:
        """One bundle's node bounds around the balls (centre, ``radius``) of their shapes,
        and their least ``floor`` (None: -inf): the double cones around ``apex`` (lines
        through it) or the boxes on the two unit ``axes`` (2, 3) normal to parallel lines,
        with each shape's own box for parallel lines, and per node the largest of its
        shapes' stop ``keys`` (n, 3; parallel lines) or the joined terms of a point light's
        behind test (``keys`` n x SK_COLUMNS, per node PK_COLUMNS; lines through the apex,
        ``csrc/kernels.c`` refit_cones). Each shape's own bound is
        computed first, four shapes at a time (csrc/shape_bounds.inc), then joined node by
        node; on ``jobs`` threads when there are many shapes (the nodes' subtrees side by
        side, then the nodes above them)."""
        n = len(bnd)
        native.ptr(bnd, np.float64, (n, native.B_COLUMNS))
        radius = np.ascontiguousarray(radius, np.float64)
        native.ptr(radius, np.float64, (n,))
        if floor is not None:
            native.ptr(floor, np.float64, (n,))
        if (apex is None) == (axes is None):
            raise ValueError("refit: give the apex of the lines or the axes normal to them")
        if keys is not None:  # parallel lines' stop keys, or a point light's behind terms
            native.ptr(keys, np.float64, (n, 3 if axes is not None else native.SK_COLUMNS))
        kind = native.BVH_CONE if apex is not None else native.BVH_FLAT
        frame = np.zeros(6)
        frame[: 3 if apex is not None else 6] = np.ravel(apex if apex is not None else axes)
        # each shape's own cone (a scratch array) or box (kept: shadow packets test it), then the nodes'
        own = np.empty((len(self.items), native.CI_COLUMNS if apex is not None else native.BX_COLUMNS))
        items = native.shape_pass("cone_items" if apex is not None else "flat_items")
        parts = threads.ranges(len(self.items), jobs, SHAPE_CHUNK)
        threads.split(jobs, parts, lambda a, b: items(address(self.items[a:]), b - a, address(bnd), address(radius),
                                                      address(frame), address(own[a:])))
        bounds = Bounds(self, np.empty((self.nodes, native.BV_COLUMNS)), frame, own if axes is not None else None,
                        None if keys is None else np.empty((self.nodes, 3 if axes is not None else native.PK_COLUMNS)))
        refit = functools.partial(native.library().bvh_refit, bounds.struct(),
                                  None if floor is None else address(floor), kind, address(bounds.box), address(own),
                                  None if keys is None else address(keys),
                                  None if keys is None else address(bounds.keys))
        below, above = self.subtrees(len(parts))
        threads.split(jobs, below, refit)
        for at in above:
            refit(at, at + 1)
        return bounds

    def subtrees(self, count: int) -> tuple[list[tuple[int, int]], list[int]]:
        """The node ranges of at least ``count`` disjoint subtrees (fewer when the tree
        has fewer leaves), largest first, and the nodes above them, children before their
        parents. Nodes are depth first: node ``at``'s left child is ``at + 1``, its right
        child ``node[at, 0]`` (when ``node[at, 1]``, its shape count, is 0)."""
        below, above = [(0, self.nodes)] if self.nodes else [], []
        while len(below) < count:
            inner = [r for r in below if self.node[r[0], 1] == 0 and r[1] - r[0] > 1]
            if not inner:
                break
            lo, hi = max(inner, key=lambda r: r[1] - r[0])
            right = int(self.node[lo, 0])
            below.remove((lo, hi))
            below += [(lo + 1, right), (right, hi)]
            above.append(lo)
        return sorted(below, key=lambda r: r[0] - r[1]), above[::-1]


@dataclass(frozen=True)
class Bounds:
    """A tree's node bounds for one bundle of rays, and the bundle's apex or axes."""

    tree: Tree
    box: np.ndarray  # (nodes, BV_COLUMNS) float64
    frame: np.ndarray  # 6 float64
    item_box: np.ndarray | None = None  # parallel lines: (items, BX_COLUMNS), each shape's own box
    keys: np.ndarray | None = None  # stop keys (nodes, 3) or a point light's terms (nodes, PK_COLUMNS)

    def struct(self) -> native.Bvh:
        """The kernels' view (the arrays must outlive it)."""
        t = self.tree
        return native.Bvh(address(t.node), address(t.items), address(self.box), (*self.frame,), t.nodes,
                          address(t.always), len(t.always),
                          None if self.item_box is None else address(self.item_box))


def build(bnd: np.ndarray, bounded: np.ndarray) -> Tree:
    """The hierarchy over the shapes of the bound table ``bnd`` (n, B_COLUMNS) that are
    ``bounded`` with a finite centre; the others go to the list every ray tests."""
    n = len(bnd)
    native.ptr(bnd, np.float64, (n, native.B_COLUMNS))
    ok = np.ascontiguousarray(bounded, np.uint8)  # 0 or 1 (bool or uint8 given)
    native.ptr(ok, np.uint8, (n,))
    items, always, node = np.empty(n, np.int32), np.empty(n, np.int32), np.empty((max(1, 2 * n), 2), np.int32)
    counts = np.zeros(2, np.int64)
    nodes = native.library().bvh_build(address(bnd), address(ok), n, address(items), address(always), address(node),
                                       address(counts))
    if nodes < 0:
        raise Rend3rError(f"not enough memory to build the shape hierarchy of {n:,} shapes")
    return Tree(node[:nodes], items[:counts[0]], always[:counts[1]])
