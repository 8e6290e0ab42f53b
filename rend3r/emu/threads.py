"""The kernels' threads: one pool per thread count, and work split into ranges.

Kernels release the GIL (they are called through ctypes), so ranges of pixels, packets
or shapes run in parallel on ``--jobs`` threads. Every range is computed the same way
whatever the split, so results never depend on the thread count.
"""

from __future__ import annotations

import os
from concurrent.futures import Future, ThreadPoolExecutor
from functools import lru_cache
from typing import Callable


def available_cores() -> int:
    """Cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not Linux
        return os.cpu_count() or 1


@lru_cache(maxsize=4)
def _pool(jobs: int) -> ThreadPoolExecutor:
    return ThreadPoolExecutor(max_workers=jobs, thread_name_prefix="rend3r")


def ranges(n: int, jobs: int, smallest: int) -> list[tuple[int, int]]:
    """0..n in a few ranges per thread (so that uneven work evens out), none shorter than
    ``smallest`` unless there is only one; a single range with one job."""
    parts = 1 if jobs <= 1 else max(1, min(4 * jobs, n // smallest))
    edges = [n * k // parts for k in range(parts + 1)]
    return [(a, b) for a, b in zip(edges, edges[1:]) if b > a]


def submit(jobs: int, fn: Callable[..., object], *args: object) -> Future:
    """``fn(*args)`` on the pool of ``jobs`` threads."""
    return _pool(jobs).submit(fn, *args)


def each(jobs: int, calls: list[Callable[[], object]]) -> None:
    """Run ``calls`` on ``jobs`` threads (in this thread with one job or one call)."""
    if jobs <= 1 or len(calls) <= 1:
        for call in calls:
            call()
    else:
        for future in [_pool(jobs).submit(call) for call in calls]:
            future.result()


def split(jobs: int, parts: list[tuple[int, int]], fn: Callable[[int, int], object]) -> None:
    """``fn(a, b)`` over the ranges ``parts`` on ``jobs`` threads."""
    each(jobs, [lambda a=a, b=b: fn(a, b) for a, b in parts])
