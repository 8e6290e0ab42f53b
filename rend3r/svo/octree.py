"""The thesis's SVO node format (Chapter 7.1) and a bottom-up builder from sparse voxels.

Each entry is one 32-bit word::

    bits 31..17  child_table_ptr  relative pointer (15 bits, or ``ptr_bits`` bits)
    bit  16      is_far           child_table_ptr points to a far slot
    bits 15..8   valid_mask       child i holds solid voxels
    bits  7..0   leaf_mask        child i is a solid voxel (set together with valid)

Child index ``i`` has bit 2 = X, bit 1 = Y, bit 0 = Z; a set bit means the high side of
the middle plane (the reading Algorithm 1 uses). A node's child table holds one entry per
*inner* child (valid and not leaf) in increasing child index, so child ``i`` sits at
``table + popcount(inner_mask & ((1 << i) - 1))``. The table address is the node's own
address plus ``child_table_ptr``; with ``is_far`` set, ``child_table_ptr`` instead points
(relative to the node) at a far slot whose unsigned 32-bit value is added to the node's
address.

Layout: the root is word 0; then level by level (breadth first), each parent's child
table followed directly by the far slots its entries need, so a far slot is at most 8
words from its node and every near pointer points forward.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from itertools import pairwise

import numpy as np

from ..errors import Rend3rError
from ..progress import ProgressFactory, hidden

PTR_SHIFT = 17
FAR_BIT = 1 << 16
MAX_DEPTH = 20
DEFAULT_PTR_BITS = 15

_POPCOUNT8 = np.array([bin(i).count("1") for i in range(256)], dtype=np.int64)


def popcount8(x: np.ndarray) -> np.ndarray:
    """Number of set bits of 8-bit values."""
    return _POPCOUNT8[np.asarray(x, dtype=np.int64) & 0xFF]


def sorted_unique(values: np.ndarray) -> np.ndarray:
    """The sorted distinct values of a 1-D array, as ``np.unique`` returns them.

    A sort and a mask: numpy 2.4's ``np.unique`` took 35 s for 11 M int64 keys on the
    project's machine, where this takes 0.5 s (and a Ctrl-C waits for the call to return).
    """
    values = np.sort(values)
    return values[np.r_[True, values[1:] != values[:-1]]] if len(values) else values


def morton_encode(coords: np.ndarray, depth: int) -> np.ndarray:
    """Interleave voxel coordinates (M, 3) into codes: per level the triple (x, y, z), x high."""
    c = np.asarray(coords, dtype=np.int64)
    code = np.zeros(len(c), dtype=np.int64)
    for bit in range(depth):
        for axis in range(3):
            code |= ((c[:, axis] >> bit) & 1) << (3 * bit + 2 - axis)
    return code


def morton_decode(codes: np.ndarray, depth: int) -> np.ndarray:
    """Inverse of :func:`morton_encode`."""
    codes = np.asarray(codes, dtype=np.int64)
    out = np.zeros((len(codes), 3), dtype=np.int64)
    for bit in range(depth):
        for axis in range(3):
            out[:, axis] |= ((codes >> (3 * bit + 2 - axis)) & 1) << bit
    return out


@dataclass(frozen=True)
class Octree:
    """A serialised octree: ``words`` (uint32) with the root at index 0."""

    words: np.ndarray
    depth: int
    ptr_bits: int = DEFAULT_PTR_BITS

    @property
    def resolution(self) -> int:
        """Voxels per axis (2**depth)."""
        return 1 << self.depth

    def far_count(self) -> int:
        """Number of nodes whose child-table pointer goes through a far slot.

        Far slots hold arbitrary data, so nodes are found by walking the tree, one array
        of node addresses per level (not one row of eight children per node).
        """
        words = self.words
        addr = np.zeros(1, dtype=np.int64)
        far = 0
        for _ in range(self.depth - 1):
            w = words[addr].astype(np.int64)
            inner = ((w >> 8) & 0xFF) & ~(w & 0xFF)
            far += int((((w >> 16) & 1) == 1)[inner != 0].sum())
            table, _ = child_table(words, addr)
            count = popcount8(inner)
            starts = np.cumsum(count) - count
            addr = np.repeat(table, count) + (np.arange(int(count.sum())) - np.repeat(starts, count))
        return far


_BLOCK = 1 << 22  # child codes per pass when deriving a level's nodes


def _blocks(children: np.ndarray) -> list[tuple[int, int]]:
    """Ranges of about ``_BLOCK`` sorted codes, each ending on a parent boundary."""
    bounds = [0]
    while bounds[-1] < len(children):
        stop = bounds[-1] + _BLOCK
        bounds.append(len(children) if stop >= len(children)
                      else int(np.searchsorted(children, (children[stop] >> 3) << 3)))
    return list(pairwise(bounds))


def _heads(children: np.ndarray) -> np.ndarray:
    """Index of the first of each run of codes with the same parent."""
    parents = children >> 3
    return np.flatnonzero(np.r_[True, parents[1:] != parents[:-1]])


def _parents(children: np.ndarray, with_first: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """(keys, valid masks (uint8), index of the first child or None) of the parents of
    sorted unique codes, block by block: no temporary as long as ``children``."""
    blocks = _blocks(children)
    total = sum(len(_heads(children[a:b])) for a, b in blocks)
    keys = np.empty(total, dtype=np.int64)
    valid = np.empty(total, dtype=np.uint8)
    first = np.empty(total, dtype=np.int64) if with_first else None
    at = 0
    for a, b in blocks:
        c = children[a:b]
        head = _heads(c)
        keys[at:at + len(head)] = c[head] >> 3
        valid[at:at + len(head)] = np.bitwise_or.reduceat(np.left_shift(np.uint8(1), (c & 7).astype(np.uint8)),
                                                          head)
        if first is not None:
            first[at:at + len(head)] = head + a
        at += len(head)
    return keys, valid, first


def build_octree(coords: np.ndarray, depth: int, ptr_bits: int = DEFAULT_PTR_BITS) -> Octree:
    """Build the node array from voxel coordinates (M, 3) in [0, 2**depth).

    Memory is proportional to the number of voxels and nodes: codes are sorted, each
    level's nodes come from the unique parent codes of the level below, and the layout is
    computed with prefix sums, iterating until the set of far pointers is stable (adding a
    far slot only moves later words further away, so the set only grows).
    """
    if not 1 <= depth <= MAX_DEPTH:
        raise Rend3rError(f"octree depth must be 1..{MAX_DEPTH}, got {depth}")
    coords = np.asarray(coords, dtype=np.int64).reshape(-1, 3)
    if len(coords) == 0:
        raise Rend3rError("no voxels to build an octree from")
    if coords.min() < 0 or coords.max() >= (1 << depth):
        raise Rend3rError(f"voxel coordinates outside [0, {1 << depth})")
    codes = np.sort(morton_encode(coords, depth))
    return build_octree_codes(codes[np.r_[True, codes[1:] != codes[:-1]]], depth, ptr_bits)


def build_octree_codes(codes: np.ndarray, depth: int, ptr_bits: int = DEFAULT_PTR_BITS,
                       progress: ProgressFactory = hidden) -> Octree:
    """:func:`build_octree` from sorted unique Morton codes (:func:`morton_encode`).

    ``progress``'s bar counts levels twice: deriving the nodes, then writing the words.
    """
    with progress(2 * depth, "building octree") as bar:
        return _build(codes, depth, ptr_bits, bar.advance)


def _build(codes: np.ndarray, depth: int, ptr_bits: int, advance: Callable[[int], None]) -> Octree:
    """Levels bottom up (masks and first-child indexes only), far flags bottom up, words top down.

    A level's pointers depend only on its own far slots and the level below's, so each
    level's far set is iterated to its (least) fixed point on that level's arrays alone:
    adding a far slot only moves later words further away, so the set only grows. The
    deepest level, the largest, holds no pointers: only its masks are kept.
    """
    if not 1 <= depth <= MAX_DEPTH:
        raise Rend3rError(f"octree depth must be 1..{MAX_DEPTH}, got {depth}")
    if not 4 <= ptr_bits <= 15:
        raise Rend3rError(f"pointer width must be 4..15 bits, got {ptr_bits}")
    if len(codes) == 0:
        raise Rend3rError("no voxels to build an octree from")
    valid: list[np.ndarray] = [np.empty(0, np.uint8)] * depth
    first: list[np.ndarray | None] = [None] * depth  # per level: index of each node's first child
    keys = codes
    for lvl in range(depth - 1, -1, -1):
        keys, valid[lvl], first[lvl] = _parents(keys, lvl < depth - 1)
        advance(1)
    del keys
    counts = [len(v) for v in valid]
    max_ptr = (1 << ptr_bits) - 1
    far = [np.zeros(c, dtype=bool) for c in counts]
    below = np.zeros(counts[-1] + 1, dtype=np.int64)  # far slots before each node of the level below
    for lvl in range(depth - 2, -1, -1):
        table = first[lvl] + below[first[lvl]]  # each table's offset in the region below
        group = _siblings(valid, first, lvl)[0]
        index = np.arange(counts[lvl])
        while True:
            before = _far_before(far[lvl])
            need = counts[lvl] + before[-1] + table - index - before[group] > max_ptr
            if not np.any(need & ~far[lvl]):
                break
            far[lvl] |= need
        below = before
    words = np.zeros(sum(counts) + sum(int(f.sum()) for f in far), dtype=np.uint32)
    region = 0
    for lvl in range(depth - 1):
        before = _far_before(far[lvl])
        below = _far_before(far[lvl + 1])
        group, end = _siblings(valid, first, lvl)
        addr = region + np.arange(counts[lvl]) + before[group]
        rel = region + counts[lvl] + before[-1] + first[lvl] + below[first[lvl]] - addr
        is_far = far[lvl]
        slot = region + end + before[:-1]  # far slots follow the node's own table, in rank order
        ptr = np.where(is_far, slot - addr, rel)
        if np.any(is_far) and int(rel[is_far].max()) >= 1 << 32:
            raise Rend3rError("octree too large: a far pointer exceeds 32 bits")
        words[addr] = (valid[lvl].astype(np.int64) << 8) | (ptr << PTR_SHIFT) | np.where(is_far, FAR_BIT, 0)
        words[slot[is_far]] = rel[is_far]
        region += counts[lvl] + int(before[-1])
        advance(1)
    words[region:] = valid[-1].astype(np.uint32) * 257  # the deepest level: leaf mask = valid mask, no pointer
    advance(1)
    return Octree(words, depth, ptr_bits)


def _far_before(far: np.ndarray) -> np.ndarray:
    """Far flags -> number of far nodes before each index (one more entry: the total)."""
    out = np.zeros(len(far) + 1, dtype=np.int64)
    np.cumsum(far, out=out[1:])
    return out


def _siblings(valid: list[np.ndarray], first: list[np.ndarray | None], lvl: int
              ) -> tuple[np.ndarray, np.ndarray]:
    """Per node of level ``lvl``: index of its first sibling and one past its last."""
    if lvl == 0:
        return np.zeros(1, dtype=np.int64), np.ones(1, dtype=np.int64)
    size = popcount8(valid[lvl - 1])
    start = first[lvl - 1]
    return np.repeat(start, size), np.repeat(start + size, size)


def split_word(word: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(child_table_ptr, is_far, valid_mask, leaf_mask) of node words."""
    w = np.asarray(word, dtype=np.int64)
    return w >> PTR_SHIFT, (w >> 16) & 1, (w >> 8) & 0xFF, w & 0xFF


def child_table(words: np.ndarray, addr: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Child-table addresses of the nodes at ``addr`` and whether a far slot was read."""
    addr = np.asarray(addr, dtype=np.int64)
    ptr, is_far, _, _ = split_word(words[addr])
    far_value = words[np.where(is_far == 1, addr + ptr, 0)].astype(np.int64)
    return np.where(is_far == 1, addr + far_value, addr + ptr), is_far == 1


def _walk_levels(tree: Octree):
    """Per node level: (far flags of its nodes, Morton codes of its leaf children)."""
    words = tree.words
    addr = np.zeros(1, dtype=np.int64)
    keys = np.zeros(1, dtype=np.int64)
    children = np.arange(8)
    for _ in range(tree.depth):
        _, _, valid, leaf = split_word(words[addr])
        table, far = child_table(words, addr)
        inner = valid & ~leaf
        has = (valid[:, None] >> children) & 1
        is_leaf = (leaf[:, None] >> children) & 1
        child_key = (keys[:, None] << 3) | children
        yield far & (inner != 0), child_key[(has & is_leaf) == 1]
        rank = popcount8(inner[:, None] & ((1 << children) - 1))
        sel = (has & (1 - is_leaf)) == 1
        addr = (table[:, None] + rank)[sel]
        keys = child_key[sel]


def octree_to_voxels(tree: Octree) -> np.ndarray:
    """All solid voxel coordinates (M, 3), sorted by Morton code."""
    codes = np.sort(np.concatenate([leaves for _, leaves in _walk_levels(tree)]))
    return morton_decode(codes, tree.depth)
