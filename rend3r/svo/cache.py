"""The thesis's software cache model (Chapter 7.5), vectorised.

A cache of ``size`` 32-bit words in blocks of ``block`` words, ``ways``-way set
associative with LRU replacement (``ways = 1``: direct mapped; ``ways = size/block``:
fully associative). ``max_level`` (the "cache only levels <= N" option) lets accesses
to deeper node levels bypass the cache: they always miss and neither fill nor touch it.

The LRU rule is evaluated without a per-access loop: an access hits exactly when its
block was accessed before in the same set and fewer than ``ways`` *other* distinct
blocks of that set were accessed since. Consecutive repeats within a set always hit;
after removing them, the distinct blocks since the previous use are counted by scanning
backwards, all pending accesses at once, until ``ways`` distinct blocks are found (miss)
or the previous use is reached (hit).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class CacheConfig:
    """Size and block in words; ``ways`` 1 = direct mapped; ``max_level`` None = all."""

    size: int
    block: int = 1
    ways: int = 1
    max_level: int | None = None

    def __post_init__(self) -> None:
        if self.size < 0 or self.block < 1 or self.ways < 1:
            raise ValueError("cache size, block and ways must be positive")
        if self.size and (self.size % (self.block * self.ways)):
            raise ValueError(f"cache of {self.size} words cannot hold {self.ways} ways of {self.block}-word blocks")

    @property
    def sets(self) -> int:
        return self.size // (self.block * self.ways)


def simulate(addr: np.ndarray, level: np.ndarray | None, cfg: CacheConfig) -> np.ndarray:
    """Hit (True) or miss of every access, in the order given."""
    addr = np.asarray(addr, dtype=np.int64)
    hits = np.zeros(len(addr), dtype=bool)
    if cfg.size == 0 or len(addr) == 0:
        return hits
    use = np.ones(len(addr), dtype=bool) if cfg.max_level is None or level is None \
        else np.asarray(level) <= cfg.max_level
    pos = np.flatnonzero(use)
    if len(pos) == 0:
        return hits
    blk = addr[pos] // cfg.block
    sets = blk % cfg.sets
    order = np.argsort(sets, kind="stable")
    pos, blk, sets = pos[order], blk[order], sets[order]
    same_set = np.r_[False, sets[1:] == sets[:-1]]
    repeat = same_set & np.r_[False, blk[1:] == blk[:-1]]
    hits[pos[repeat]] = True
    keep = ~repeat
    pos, blk, sets = pos[keep], blk[keep], sets[keep]
    n = len(blk)
    # previous / next use of the same block in the compressed set stream
    by_block = np.lexsort((np.arange(n), blk))  # sets are a function of blocks
    same = np.r_[False, blk[by_block][1:] == blk[by_block][:-1]]
    prev = np.full(n, -1, dtype=np.int64)
    prev[by_block[same]] = by_block[np.flatnonzero(same) - 1]
    nxt = np.full(n, n, dtype=np.int64)
    nxt[prev[prev >= 0]] = np.flatnonzero(prev >= 0)
    pending = np.flatnonzero(prev >= 0)
    gap = pending - prev[pending] - 1
    sure = gap < cfg.ways
    hits[pos[pending[sure]]] = True
    pending = pending[~sure]
    count = np.zeros(len(pending), dtype=np.int64)
    offset = 1
    while len(pending):
        m = pending - offset
        reached = m == prev[pending]
        count += (~reached) & (nxt[np.maximum(m, 0)] >= pending)
        hit_now = reached
        miss_now = count >= cfg.ways
        hits[pos[pending[hit_now]]] = True
        alive = ~(hit_now | miss_now)
        pending, count = pending[alive], count[alive]
        offset += 1
    return hits


def miss_rate(addr: np.ndarray, level: np.ndarray | None, cfg: CacheConfig) -> float:
    """Misses per access (bypassed accesses count as misses)."""
    if len(addr) == 0:
        return 0.0
    return 1.0 - float(simulate(addr, level, cfg).mean())
