"""The shape hierarchy: a bounding volume tree over the shapes, so a ray's cost grows with
log(shapes).

Built once per frame from the shapes' centres (``csrc/kernels.c`` bvh_build: splits along
a Morton curve of the centres, halving the longest side of a node's cell first, leaves of
at most 4 shapes), or found where the thread's last frame built it when the shapes did not
move (:func:`tree_room`); each bundle of rays then refits its
node bounds to the balls of its own cull radii, and its depth floors (bvh_refit): double
cones around the apex of lines through one point, boxes on the plane normal to parallel
lines. Shapes without a
finite bound stay outside the tree and every ray tests them. ``csrc/bvh.h`` explains why
skipping a node never changes the nearest hit.
"""

from __future__ import annotations

import threading
from ctypes import byref
from dataclasses import dataclass, field

import numpy as np

from . import bounds as shape_bounds, native, threads, workspace
from .native import address
from .workspace import arrays, empty


@dataclass(frozen=True)
class Tree:
    """A built hierarchy: nodes (2 ints each), shape slots leaf by leaf, the slots every ray
    tests, and per slot its row in a light's bounds (its place in items, or after them in
    always: ``csrc/kernels.h`` PASS_SHADOW)."""

    node: np.ndarray  # (nodes, 2) int32
    items: np.ndarray  # int32
    always: np.ndarray  # int32
    where: np.ndarray  # int32

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
        ``csrc/kernels.c`` refit_cones). Each shape's own bound is computed first, then
        joined node by node, on a team of ``jobs`` threads (``csrc/setup.c``
        bundle_bounds: ranges of items, the nodes' subtrees side by side, then the nodes
        above them)."""
        n = len(bnd)
        native.ptr(bnd, np.float64, (n, native.B_COLUMNS))
        radius = np.ascontiguousarray(radius, np.float64)
        native.ptr(radius, np.float64, (n,))
        if floor is not None:
            native.ptr(floor, np.float64, (n,))
        if keys is not None:  # parallel lines' stop keys, or a point light's behind terms
            native.ptr(keys, np.float64, (n, 3 if axes is not None else native.SK_COLUMNS))
            keys = np.ascontiguousarray(keys[self.items])  # the refit reads them in leaf order (a light's rows)
        block = native.Bundle()
        block.bnd, block.n, block.radius = address(bnd), n, address(radius)
        block.floor = None if floor is None else address(floor)
        block.keys, block.point = (None, None) if keys is None else \
            (address(keys), None) if axes is not None else (None, address(keys))
        return self._bundle(block, apex, axes, keys is not None, jobs)

    def fit(self, p: shape_bounds.Pass, *, apex: np.ndarray | None = None, axes: np.ndarray | None = None,
            jobs: int = 1) -> Bounds:
        """A bundle's per-shape pass ``p`` (bounds.py: its radii, floors and keys), then its
        node bounds as :meth:`refit` computes them, in one call."""
        return self._bundle(p.block, apex, axes, p.keys is not None, jobs)

    def _bundle(self, block: native.Bundle, apex: np.ndarray | None, axes: np.ndarray | None, keys: bool,
                jobs: int) -> Bounds:
        if (apex is None) == (axes is None):
            raise ValueError("refit: give the apex of the lines or the axes normal to them")
        bounds, own = self.bounds_for(block, apex, axes, self.nodes, keys, jobs)  # own: the call's scratch
        with threads.team(jobs) as team:
            native.library().bundle_bounds(byref(block), team)
        return bounds

    def bounds_for(self, block: native.Bundle, apex: np.ndarray | None, axes: np.ndarray | None, nodes: int,
                   keys: bool, jobs: int) -> tuple[Bounds, np.ndarray]:
        """Points ``block`` at this tree (``nodes`` nodes at most) and at new arrays for its
        bounds; returns the Bounds that holds them, and the shapes' own bounds (the block
        points at them until its call returns)."""
        kind = native.BVH_CONE if apex is not None else native.BVH_FLAT
        frame = np.zeros(6)
        frame[: 3 if apex is not None else 6] = np.ravel(apex if apex is not None else axes)
        # each shape's own cone (a scratch array) or box (kept: shadow packets test it), then the nodes'
        own, box, node_keys = arrays(((len(self.items), native.CI_COLUMNS if apex is not None else native.BX_COLUMNS),
                                      np.float64), ((nodes, native.BV_COLUMNS), np.float64),
                                     ((nodes if keys else 0, 3 if axes is not None else native.PK_COLUMNS), np.float64))
        bounds = Bounds(self, box, frame, own if axes is not None else None, node_keys if keys else None)
        block.kind, block.tree, block.items = kind, bounds.view, len(self.items)
        block.box, block.own = address(bounds.box), address(own)
        block.node_keys = None if bounds.keys is None else address(bounds.keys)
        block.jobs, block.isa, block.chunk = jobs, native.shape_isa(), shape_bounds.SHAPE_CHUNK
        return bounds, own


@dataclass(frozen=True)
class Bounds:
    """A tree's node bounds for one bundle of rays, and the bundle's apex or axes."""

    tree: Tree
    box: np.ndarray  # (nodes, BV_COLUMNS) float64
    frame: np.ndarray  # 6 float64
    item_box: np.ndarray | None = None  # parallel lines: (items, BX_COLUMNS), each shape's own box
    keys: np.ndarray | None = None  # stop keys (nodes, 3) or a point light's terms (nodes, PK_COLUMNS)
    view: native.Bvh = field(init=False, repr=False, compare=False)  # the kernels' view of the arrays above

    def __post_init__(self) -> None:
        object.__setattr__(self, "view", self._view())  # built once: the blocks copy it

    def _view(self) -> native.Bvh:
        """The kernels' view (the arrays must outlive it)."""
        t = self.tree
        return native.Bvh(address(t.node), address(t.items), address(self.box), tuple(self.frame.tolist()), t.nodes,
                          address(t.always), len(t.always),
                          None if self.item_box is None else address(self.item_box), address(t.where))


class _Room(threading.local):
    """This thread's tree arrays (node, items, always, where) and the shapes its builds
    were given, with the kernels' memo of them (``csrc/kernels.h`` TreeMemo)."""

    def __init__(self) -> None:
        self.arrays: list[np.ndarray] = []
        self.block = native.TreeMemo()


_room = _Room()


def tree_room(rows: int) -> tuple[native.TreeMemo, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """This thread's memo and the arrays to build a tree of ``rows`` shapes in: (memo,
    node, items, always, where), each with room for ``rows`` (node for 2 ``rows``).
    ``csrc/kernels.c`` bvh_build given them finds there the tree of its last build, and
    builds nothing, when the shapes' centres and which are bounded are that build's, as a
    renderer keeps a scene's hierarchy between frames. They are this thread's from frame
    to frame while no array made from them lives (else new ones are made) and grow with the
    largest frame: 60 bytes a shape."""
    room = _room
    if not room.arrays or room.block.capacity < rows or not workspace.unshared(room.arrays):
        cap = max(1, rows + rows // 8)  # a scene that grows a little keeps its room
        room.arrays = [np.empty((2 * cap, 2), np.int32), np.empty(cap, np.int32), np.empty(cap, np.int32),
                       np.empty(cap, np.int32), np.empty(2 * cap * native.BUILD_ITEM_BYTES, np.uint8)]
        room.block = native.TreeMemo(capacity=cap, given=address(room.arrays[4]))
    node, items, always, where, _ = room.arrays
    return room.block, node, items, always, where


def forget() -> None:
    """Drops the tree this thread's room keeps: its next frame builds one, as a program's
    first frame does (benchmarks time such frames so)."""
    _room.block.valid = 0


def build(bnd: np.ndarray, bounded: np.ndarray, kept: bool = False) -> Tree:
    """The hierarchy over the shapes of the bound table ``bnd`` (n, B_COLUMNS) that are
    ``bounded`` with a finite centre; the others go to the list every ray tests. With
    ``kept``, built in this thread's :func:`tree_room` (and copied out of it)."""
    n = len(bnd)
    native.ptr(bnd, np.float64, (n, native.B_COLUMNS))
    ok = np.ascontiguousarray(bounded, np.uint8)  # 0 or 1 (bool or uint8 given)
    native.ptr(ok, np.uint8, (n,))
    if kept:
        memo, node, items, always, where = tree_room(n)
    else:
        memo, node, items, always, where = None, np.empty((max(1, 2 * n), 2), np.int32), np.empty(n, np.int32), \
            np.empty(n, np.int32), np.empty(n, np.int32)
    counts, room = np.zeros(2, np.int64), empty(n * native.BUILD_BYTES // 8, np.uint64)
    nodes = native.library().bvh_build(address(bnd), address(ok), n, address(items), address(always), address(where),
                                       address(node), address(counts), address(room), 0,
                                       None if memo is None else byref(memo), native.shape_isa())
    tree = Tree(node[:nodes], items[:counts[0]], always[:counts[1]], where[:n])
    return Tree(*(a.copy() for a in (tree.node, tree.items, tree.always, tree.where))) if kept else tree
