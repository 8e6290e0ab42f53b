from collections import OrderedDict

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from rend3r.svo.cache import CacheConfig, miss_rate, simulate


def _reference(addr, level, cfg):
    """Straightforward per-access LRU cache."""
    if cfg.size == 0:
        return [False] * len(addr)
    sets = [OrderedDict() for _ in range(cfg.sets)]
    out = []
    for a, lv in zip(addr, level):
        if cfg.max_level is not None and lv > cfg.max_level:
            out.append(False)
            continue
        b = a // cfg.block
        s = sets[b % cfg.sets]
        if b in s:
            s.move_to_end(b)
            out.append(True)
        else:
            out.append(False)
            s[b] = True
            if len(s) > cfg.ways:
                s.popitem(last=False)
    return out


def test_hand_worked_direct_mapped():
    # 4 words, block 1, direct mapped: 0 and 4 share set 0
    cfg = CacheConfig(4, 1, 1)
    assert simulate([0, 4, 0, 1, 1, 5, 1], None, cfg).tolist() == [False, False, False, False, True, False, False]


def test_hand_worked_blocks_and_two_way():
    # block 2: words 0 and 1 share a block; 8 words 2-way = 2 sets of 2 blocks
    cfg = CacheConfig(8, 2, 2)
    seq = [0, 1, 4, 8, 0, 12, 4, 0]
    # blocks: 0 0 2 4 0 6 2 0; sets (block % 2): all set 0
    # LRU: [0] [0] [0,2] [2,4] miss 0 -> [4,0] 6 -> [0,6] 2 miss -> [6,2] 0 miss
    assert simulate(seq, None, cfg).tolist() == [False, True, False, False, False, False, False, False]
    assert simulate(seq, None, CacheConfig(8, 2, 4)).tolist() == [False, True, False, False, True, False, True, True]


def test_level_limit_bypasses():
    cfg = CacheConfig(8, 1, 2, max_level=1)
    assert simulate([5, 5, 5, 5], [2, 2, 1, 1], cfg).tolist() == [False, False, False, True]
    assert miss_rate([5, 5], [0, 0], CacheConfig(0)) == 1.0


@settings(max_examples=150)
@given(addr=st.lists(st.integers(0, 63), min_size=1, max_size=200), size=st.sampled_from([0, 8, 16, 32]),
       block=st.sampled_from([1, 2, 4]), ways=st.sampled_from([1, 2, 4]),
       max_level=st.one_of(st.none(), st.integers(0, 3)), seed=st.integers(0, 1000))
def test_matches_reference(addr, size, block, ways, max_level, seed):
    if size and size % (block * ways):
        return
    cfg = CacheConfig(size, block, ways, max_level)
    level = np.random.default_rng(seed).integers(0, 4, len(addr))
    assert simulate(addr, level, cfg).tolist() == _reference(addr, level, cfg)


def test_bad_configs():
    with pytest.raises(ValueError):
        CacheConfig(12, 8, 1)
    with pytest.raises(ValueError):
        CacheConfig(16, 0, 1)
