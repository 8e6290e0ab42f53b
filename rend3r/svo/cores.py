"""Multi-core frame-time model of the thesis's ray casting module (Chapter 8).

Scheduler: for each pixel in order it loads the ray's 7 words (dir-mask, root t0, t1)
in one burst, hands the ray to a core (round-robin: core k mod n, waiting for it;
first-available: whichever core frees first) and writes pixels back in 6-word bursts per
8 pixels (24-bit colour). Cores: one cycle per state of Algorithm 4 (INIT, CALC-T and
FIRST-IDX per node entered, NEXT-EVAL, CALC-CHILD-T and EVAL per child evaluated, CALC-T
per pop), one cycle per cache hit; a miss stalls the core for the bus latency, the
critical word and the wait for the shared bus.

Memory: one bus at ``bandwidth`` bytes/s shared by the scheduler and all cores; a burst
of k words occupies it for ``latency + k * 4 * clock / bandwidth`` cycles (Wishbone
classic cycles hold the bus for the whole access). The scheduler's sequential bursts use
``latency`` = 6 cycles, which reproduces the thesis's 130 ms for loading 640x480 rays'
data at 95 MB/s and 50 MHz; a core's cache miss is a random access and uses
``miss_latency`` = 20 cycles, chosen so that, as in Table 8.2D, a design without a cache
is bus-bound already with one or two cores. Bus contention is modelled, not simulated cycle by cycle: a miss waits
``rho * s / (2 (1 - rho))`` cycles on average (an M/D/1 queue with the bus utilisation
``rho`` and mean service time ``s``), solved self-consistently with the frame time. The
cache sees the requests in pixel order (the cores work on neighbouring pixels at once).
"""

from __future__ import annotations

import heapq
from dataclasses import dataclass

import numpy as np

RAY_WORDS = 7
PIXEL_BURST_WORDS = 6
PIXELS_PER_BURST = 8


@dataclass(frozen=True)
class Platform:
    """The thesis's platform: Spartan-6 at 50 MHz with 95 MB/s to memory."""

    clock_hz: float = 50e6
    bandwidth: float = 95e6
    latency: float = 6.0
    miss_latency: float = 20.0

    @property
    def cycles_per_word(self) -> float:
        return 4 * self.clock_hz / self.bandwidth

    def burst(self, words: float, latency: float | None = None) -> float:
        """Bus cycles of one burst of ``words`` words (sequential latency by default)."""
        return (self.latency if latency is None else latency) + words * self.cycles_per_word


def compute_cycles(steps, descents, pops, restarts, requests) -> np.ndarray:
    """Cycles of Algorithm 4's states for each ray, memory waits excluded."""
    entries = 1 + np.asarray(descents) + np.asarray(restarts)
    return (1 + np.asarray(restarts) + 2 * entries + 3 * np.asarray(steps) + np.asarray(pops)
            + np.asarray(requests)).astype(np.float64)


def _schedule(load: float, times: list[float], cores: int, policy: str) -> float:
    """Finish time of the last ray; the scheduler issues one ray per ``load`` cycles."""
    issue = 0.0
    if policy == "round-robin":
        free = [0.0] * cores
        k = 0
        for t in times:
            issue = max(issue + load, free[k])
            free[k] = issue + t
            k = (k + 1) % cores
        return max(free)
    if policy == "first-available":
        heap = [0.0] * cores
        for t in times:
            issue = max(issue + load, heap[0])
            heapq.heapreplace(heap, issue + t)
        return max(heap)
    raise ValueError(f"unknown scheduling policy {policy!r}")


def frame_time(compute: np.ndarray, misses: np.ndarray, block: int, cores: int,
               policy: str = "round-robin", platform: Platform = Platform()) -> dict[str, float]:
    """Estimated frame time (seconds) and bus utilisation for one frame.

    ``compute`` and ``misses`` are per ray (pixel order); rays that miss the root still
    cost the scheduler's load and write.
    """
    n = len(compute)
    miss_bus = platform.burst(block, platform.miss_latency)
    stall = platform.miss_latency + platform.cycles_per_word
    load = platform.burst(RAY_WORDS)
    writes = (n / PIXELS_PER_BURST) * platform.burst(PIXEL_BURST_WORDS)
    bus_busy = n * load + writes + float(misses.sum()) * miss_bus
    n_bus = n + n / PIXELS_PER_BURST + float(misses.sum())
    service = bus_busy / max(n_bus, 1.0)
    base = compute + misses * stall
    wait, frame = 0.0, 0.0
    lo_w, hi_w = 0.0, None
    # frame(W) grows with W while rho(frame) shrinks: bisect W until consistent.
    for _ in range(40):
        times = (base + misses * wait).tolist()
        frame = max(_schedule(load, times, cores, policy) + writes / max(n, 1), bus_busy)
        rho = min(bus_busy / frame, 0.995)
        target = rho * service / (2 * (1 - rho))
        if abs(target - wait) <= 1e-3 * max(service, 1.0):
            break
        if target > wait:
            lo_w = wait
        else:
            hi_w = wait
        wait = (lo_w + hi_w) / 2 if hi_w is not None else max(target, 2 * wait, 1.0)
    return {"frame_s": frame / platform.clock_hz, "bus_utilisation": bus_busy / frame,
            "wait_cycles": wait, "rays_per_s": n / (frame / platform.clock_hz)}
