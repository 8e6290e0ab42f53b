"""The kernels' threads: work split into ranges, run by the calling thread and helpers.

Kernels release the GIL (they are called through ctypes), so ranges of pixels, packets
or shapes run in parallel on ``--jobs`` threads. Every range is computed the same way
whatever the split, so results never depend on the thread count.

A frame's passes run on a :func:`team`: native threads of the kernels' pool that join
it and wait spinning between the compiled calls (``csrc/team.h``), so that a pass of a
few tens of microseconds still splits. Other work splits over Python threads with
:func:`each`. In both the calling thread takes part: with ``jobs`` threads it works
beside ``jobs - 1`` others, each thread taking the next range or call not yet taken. A
caller that only waited while ``jobs`` helpers worked left its core idle, and Linux woke
the helpers onto one core (measured here: the two helpers of a 65,536-sphere frame took
turns on one CPU while the other idled, and two threads ran no faster than one).
"""

from __future__ import annotations

import os
import threading
from concurrent.futures import ThreadPoolExecutor
from contextlib import contextmanager
from functools import lru_cache
from typing import Callable, Iterator, TypeVar

import numpy as np

from . import native

T = TypeVar("T")


def available_cores() -> int:
    """Cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not Linux
        return os.cpu_count() or 1


@lru_cache(maxsize=4)
def _helpers(count: int) -> ThreadPoolExecutor:
    return ThreadPoolExecutor(max_workers=count, thread_name_prefix="rend3r")


def ranges(n: int, jobs: int, smallest: int) -> list[tuple[int, int]]:
    """0..n in a few ranges per thread (so that uneven work evens out), none shorter than
    ``smallest`` unless there is only one; a single range with one job."""
    parts = 1 if jobs <= 1 else max(1, min(4 * jobs, n // smallest))
    edges = [n * k // parts for k in range(parts + 1)]
    return [(a, b) for a, b in zip(edges, edges[1:]) if b > a]


def each(jobs: int, calls: list[Callable[[], T]], done: Callable[[int], None] | None = None) -> list[T]:
    """Run ``calls`` on this thread and ``jobs - 1`` helpers, each thread taking the next
    call not yet taken; returns their results in order. ``done(k)`` is called on this
    thread for k = 0, 1, ... in order, once calls 0..k have returned. After an error no
    call is started, the calls running are waited for, and the first error is raised."""
    results: list = [None] * len(calls)
    if jobs <= 1 or len(calls) <= 1:
        for k, call in enumerate(calls):
            results[k] = call()
            if done is not None:
                done(k)
        return results
    lock, state = threading.Lock(), {"next": 0}
    finished = [False] * len(calls)

    def take() -> int | None:
        with lock:
            k = state["next"]
            state["next"] = k + 1
        return k if k < len(calls) else None

    def drain() -> None:
        try:
            while (k := take()) is not None:
                results[k] = calls[k]()
                finished[k] = True
                if done is not None and threading.current_thread() is caller:
                    report()
        except BaseException:
            with lock:
                state["next"] = len(calls)  # no call starts after an error
            raise

    reported = 0

    def report() -> None:
        nonlocal reported
        while reported < len(calls) and finished[reported]:
            done(reported)
            reported += 1

    caller = threading.current_thread()
    futures = [_helpers(jobs - 1).submit(drain) for _ in range(min(jobs, len(calls)) - 1)]
    try:
        drain()
    finally:  # the helpers' calls may write into the caller's arrays: wait for them. A helper
        # that has not started has nothing left to take (and may never start, when the
        # caller is itself a helper): it is cancelled
        for future in futures:
            if not future.cancel():
                future.exception()
    for future in futures:
        if not future.cancelled():
            future.result()
    if done is not None:
        report()
    return results


_LED = threading.local()  # the team this thread leads, while it does


@contextmanager
def team(jobs: int) -> Iterator[int]:
    """A team of threads for compiled calls (csrc/team.h): up to ``jobs - 1`` native
    threads of the kernels' pool join it while the block runs, and the address yielded is
    passed to the calls that lead it. They never take the GIL: they join as they wake (the
    calls never wait for them), wait spinning between the calls, so that a call hands work
    over in a microsecond, and leave when the block ends. Inside a team this thread leads,
    the same team is yielded again; while another thread's team is open the pool serves
    that one, and this one's calls run on this thread alone."""
    led = getattr(_LED, "team", None)
    if led is not None:
        yield led
        return
    lib = native.library()
    state = np.zeros(_team_bytes(), np.uint8)
    at = _LED.team = native.address(state)
    lib.team_open(at, jobs - 1)
    try:
        yield at
    finally:
        _LED.team = None
        lib.team_close(at)  # returns once no member is inside it: then state may go


@lru_cache(maxsize=1)
def _team_bytes() -> int:
    return native.library().team_bytes()
