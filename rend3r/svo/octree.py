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


def _level_nodes(codes: np.ndarray, depth: int, on_level: Callable[[int], None] = lambda n: None
                 ) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """Per level L = 0..depth-1: (node keys, valid masks, index of first child node);
    ``on_level(1)`` after each level."""
    levels = []
    child_codes = codes
    for _ in range(depth):
        parents = child_codes >> 3  # sorted, because child_codes are
        first = np.flatnonzero(np.r_[True, parents[1:] != parents[:-1]])
        keys = parents[first]
        bits = np.left_shift(np.uint8(1), (child_codes & 7).astype(np.uint8))  # 1 byte a child
        valid = np.bitwise_or.reduceat(bits, first) if len(first) else np.zeros(0, np.uint8)
        levels.append((keys, valid.astype(np.int64), first))
        child_codes = keys
        on_level(1)
    return levels[::-1]


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
    if not 1 <= depth <= MAX_DEPTH:
        raise Rend3rError(f"octree depth must be 1..{MAX_DEPTH}, got {depth}")
    if not 4 <= ptr_bits <= 15:
        raise Rend3rError(f"pointer width must be 4..15 bits, got {ptr_bits}")
    if len(codes) == 0:
        raise Rend3rError("no voxels to build an octree from")
    levels = _level_nodes(codes, depth, advance)
    n_levels = len(levels)
    counts = [len(k) for k, _, _ in levels]
    # Per level L >= 1: parent index of each node and its rank inside the parent's table.
    parent = []
    rank = []
    for lvl in range(1, n_levels):
        keys = levels[lvl][0]
        starts = levels[lvl - 1][2]  # first child of each parent (children sorted by parent)
        flags = np.zeros(len(keys), dtype=np.int64)
        flags[starts] = 1
        par = np.cumsum(flags) - 1
        parent.append(par)
        rank.append(np.arange(len(keys)) - starts[par])
    table_len = [np.bincount(parent[lvl - 1], minlength=counts[lvl - 1]) for lvl in range(1, n_levels)]
    max_ptr = (1 << ptr_bits) - 1
    far = [np.zeros(c, dtype=bool) for c in counts]
    while True:
        addr, region, table_start, slots_before = _layout(counts, parent, rank, table_len, far,
                                                          [lv[2] for lv in levels])
        changed = False
        for lvl in range(n_levels - 1):
            table_addr = region[lvl + 1] + table_start[lvl + 1]
            need = (table_addr - addr[lvl]) > max_ptr
            if np.any(need & ~far[lvl]):
                far[lvl] |= need
                changed = True
        if not changed:
            break
    total = int(region[n_levels - 1] + _region_size(counts, far, n_levels - 1))
    words = np.zeros(total, dtype=np.int64)
    for lvl in range(n_levels):
        valid = levels[lvl][1]
        leaf = valid if lvl == n_levels - 1 else np.zeros_like(valid)
        word = (valid << 8) | leaf
        if lvl < n_levels - 1:
            table_addr = region[lvl + 1] + table_start[lvl + 1]
            rel = table_addr - addr[lvl]
            is_far = far[lvl]
            ptr = rel
            if lvl > 0:  # the root's table is word 1: never far
                # far slots follow the node's own table, in rank order of the far nodes
                par = parent[lvl - 1]
                slot_addr = region[lvl] + table_start[lvl][par] + table_len[lvl - 1][par] + slots_before[lvl]
                ptr = np.where(is_far, slot_addr - addr[lvl], rel)
            word |= (ptr << PTR_SHIFT) | np.where(is_far, FAR_BIT, 0)
            if np.any(is_far):
                words[slot_addr[is_far]] = rel[is_far]
        words[addr[lvl]] = word
        advance(1)
    if words.max() >= 1 << 32:
        raise Rend3rError("octree too large: a far pointer exceeds 32 bits")
    return Octree(words.astype(np.uint32), depth, ptr_bits)


def _region_size(counts: list[int], far: list[np.ndarray], lvl: int) -> int:
    """Words in level ``lvl``'s region: its nodes plus the far slots they need."""
    return counts[lvl] + int(far[lvl].sum())


def _layout(counts: list[int], parent: list[np.ndarray], rank: list[np.ndarray],
            table_len: list[np.ndarray], far: list[np.ndarray], first_child: list[np.ndarray]):
    """Node addresses, region starts, table starts and far-slot ranks per level."""
    n_levels = len(counts)
    region = np.zeros(n_levels, dtype=np.int64)
    addr = [np.zeros(1, dtype=np.int64)]
    table_start = [np.zeros(1, dtype=np.int64)]
    slots_before = [np.zeros(1, dtype=np.int64)]
    for lvl in range(1, n_levels):
        region[lvl] = region[lvl - 1] + _region_size(counts, far, lvl - 1)
        par = parent[lvl - 1]
        n_par = counts[lvl - 1]
        far_per_table = np.bincount(par, weights=far[lvl].astype(np.int64), minlength=n_par).astype(np.int64)
        size = table_len[lvl - 1] + far_per_table
        start = np.concatenate(([0], np.cumsum(size)[:-1]))
        table_start.append(start)
        addr.append(region[lvl] + start[par] + rank[lvl - 1])
        # number of far nodes before this one in the same table
        cum_far = np.cumsum(far[lvl]) - far[lvl]
        first_in_table = cum_far[first_child[lvl - 1][par]]
        slots_before.append(cum_far - first_in_table)
    return addr, region, table_start, slots_before


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
