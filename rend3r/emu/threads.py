"""The kernels' threads: work split into ranges on a team of threads.

Kernels release the GIL (they are called through ctypes), so ranges of pixels, packets,
shapes or pairs run in parallel on ``--jobs`` threads. Every range is computed the same
way whatever the split, so results never depend on the thread count.

The work runs on a :func:`team`: the calling thread leads it and takes part, and native
threads of the kernels' pool join it and wait spinning between the compiled calls
(``csrc/team.h``), so that a pass of a few tens of microseconds still splits, and for
200 us after the team ends, so that the next run's team needs no wake-up call; each thread
takes the next range not yet taken (the caller from the front, the pool's threads from
the back). (A caller that only waited while ``jobs`` helpers
worked left its core idle, and Linux woke the helpers onto one core: measured here, the
two helpers of a 65,536-sphere frame took turns on one CPU while the other idled.)
"""

from __future__ import annotations

import os
import threading

from . import native


def available_cores() -> int:
    """Cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not Linux
        return os.cpu_count() or 1


def parts(n: int, jobs: int, smallest: int) -> int:
    """How many ranges 0..n splits into on ``jobs`` threads, as every compiled pass splits
    (csrc/team.h parts_of, which says why, with up to four a thread): none shorter than
    ``smallest`` unless there is only one, a multiple of ``jobs`` when there are at least
    ``jobs`` (range k is n * k // parts .. n * (k + 1) // parts: team.h edge)."""
    return native.library().team_parts(n, jobs, smallest, 4)


_LED = threading.local()  # the team this thread leads, while it does


class team:  # noqa: N801 (used as a function: with threads.team(jobs) as at)
    """A team of threads for compiled calls (csrc/team.h): up to ``jobs - 1`` native
    threads of the kernels' pool join it while the block runs, and the address the block
    gets is passed to the calls that lead it. They never take the GIL: they join as they
    wake (the calls never wait for them), wait spinning between the calls, so that a call
    hands work over in a microsecond, and leave when the block ends. Inside a team this
    thread leads, the same team is given again; while another thread's team is open the
    pool serves that one, and this one's calls run on this thread alone."""

    def __init__(self, jobs: int) -> None:
        self.jobs, self.opened = jobs, []  # per entry of this object: the team it opened, or None

    def __enter__(self) -> int:
        led = getattr(_LED, "team", None)
        if led is not None:
            self.opened.append(None)
            return led
        at = native.library().team_open(self.jobs - 1)
        if not at:
            raise MemoryError("no memory for a team of threads")
        self.opened.append(at)
        _LED.team = at
        return at

    def __exit__(self, *_: object) -> None:
        at = self.opened.pop()
        if at is not None:
            _LED.team = None
            native.library().team_close(at)  # without waiting: the last member out frees it
