"""Structural check of an untrusted octree before any traversal kernel reads it.

The traversal kernels (numpy and numba) index the word array with child pointers, far
slots and table ranks taken from the words themselves; a corrupted file must be refused
here, never reach them. The check walks the tree level by level with array operations
(one pass per level, no per-node Python loop) and requires exactly what
:func:`rend3r.svo.octree.build_octree` writes:

* every node above the last level has inner children only (``valid != 0``, no leaf
  bits); every node of the last level has leaf children only (``leaf == valid != 0``)
  and a zero pointer field;
* every child table and far slot lies inside the word array;
* every word is used exactly once, as a node or a far slot (no sharing, no cycles, no
  unreachable words), so the walk visits at most as many nodes as there are words.

A violation raises :class:`OctreeError` with the index of the offending word.
"""

from __future__ import annotations

import numpy as np

from .octree import FAR_BIT, PTR_SHIFT, Octree, popcount8


class OctreeError(ValueError):
    """A structural fault at word ``index`` of an octree's word array."""

    def __init__(self, index: int, message: str) -> None:
        super().__init__(message)
        self.index = index


def check_octree(tree: Octree) -> int:
    """Raise :class:`OctreeError` unless ``tree`` is well formed; return its leaf count."""
    words = np.asarray(tree.words)
    total = len(words)
    if total == 0:
        raise OctreeError(0, "the octree holds no words (a root node is required)")
    uses = np.full(total, -1, dtype=np.int32)  # per word: -1 unclaimed, else its claim's stamp
    addr = np.zeros(1, dtype=np.int64)
    leaves = 0
    for level in range(tree.depth):
        w = words[addr].astype(np.int64)
        valid, leaf = (w >> 8) & 0xFF, w & 0xFF
        last = level == tree.depth - 1
        _require(addr, valid == 0, "node has no children")
        if last:
            _require(addr, leaf != valid, f"node of the last level {level} has a non-leaf child")
            _require(addr, (w >> 16) != 0, "node of the last level has a child pointer")
            leaves += int(popcount8(leaf).sum())
        else:
            _require(addr, leaf != 0, f"node of level {level} has a leaf child (leaves are at level {tree.depth - 1})")
        _claim(uses, addr)
        if last:
            break
        ptr, far = w >> PTR_SHIFT, (w & FAR_BIT) != 0
        slot = addr + ptr
        _require(addr, far & (slot >= total), "far pointer slot lies outside the file")
        if far.any():
            _claim(uses, slot[far])
        table = slot.copy()
        table[far] = addr[far] + words[slot[far]].astype(np.int64)
        count = popcount8(valid)
        _require(addr, table + count > total, "child table lies outside the file")
        # children in table order: table + 0 .. table + count - 1 of every node
        n_children = int(count.sum())
        if n_children > total:
            raise OctreeError(int(addr[0]), f"level {level + 1} claims {n_children} nodes; the file holds {total} words")
        starts = np.cumsum(count) - count
        addr = np.repeat(table, count) + (np.arange(n_children) - np.repeat(starts, count))
    unused = np.flatnonzero(uses < 0)
    if len(unused):
        raise OctreeError(int(unused[0]), "word is not part of the tree (or the tree is cut short)")
    return leaves


def _require(addr: np.ndarray, bad: np.ndarray, message: str) -> None:
    """Raise at the first node of ``addr`` where ``bad`` holds."""
    if bad.any():
        raise OctreeError(int(addr[np.argmax(bad)]), message)


def _claim(uses: np.ndarray, index: np.ndarray) -> None:
    """Claim the words in ``index``; a word claimed twice (now or before) is a fault.

    Each claim writes its position in ``index``; a position that does not read back was
    overwritten by a later duplicate (linear time, no sort).
    """
    already = uses[index] >= 0
    if already.any():
        raise OctreeError(int(index[np.argmax(already)]), "word is reached twice (shared or cyclic pointers)")
    stamp = np.arange(len(index), dtype=np.int32)
    uses[index] = stamp
    dup = uses[index] != stamp
    if dup.any():
        raise OctreeError(int(index[np.argmax(dup)]), "word is reached twice (shared or cyclic pointers)")
