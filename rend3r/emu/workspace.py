"""Large working arrays, their memory kept from one frame (or program) to the next.

A frame's working arrays (the shape tables, the hierarchy, the bundles' bounds, the bands'
per-pixel arrays) and the processor's instruction lists and tables grow with the scene
(a 65,536-sphere run at 512x384 keeps buffers of 115 MiB, 45 MiB of it instruction
lists whose pages are mostly never touched). Allocated afresh each time, glibc with its
default thresholds gives them back to the kernel when they are freed (it trims the
heap's top and unmaps large blocks), and the next run pays a page fault and a zeroed
page for every 4 KiB it touches again: more than half of a 65,536-sphere run
(``docs/performance-history.md``, "Working memory kept"). The ``rend3r`` command, the benchmarks
and Dask workers raise those thresholds for the whole process (``rend3r/memory.py``), a
choice a library must not make for the program that imports it; :func:`empty` keeps
these arrays' memory in buffers of its own, per thread, so ``run_program`` called from
any program is as fast as under the command.

A buffer is handed out again only once nothing refers to it: every array made from it
holds it (numpy's ``base``), so an array that is kept, or a view of it, keeps its buffer
out of use, and whatever lives on never shares memory with a later array. Arrays below
``SMALLEST`` bytes come from ``np.empty`` (the heap serves them without faults). A thread
keeps its buffers as long as it lives: at most KEPT of them, about the working set of
the largest frame it rendered (the worker threads of frames side by side end with their
run; the main thread's stay for the next run).
"""

from __future__ import annotations

import math
import sys
import threading
from bisect import bisect_left, bisect_right
from functools import lru_cache

import numpy as np

from .native import address

#: Bytes below which an array is not worth a buffer.
SMALLEST = 1 << 16
#: Buffers a thread keeps at most (more arrays alive at once come from np.empty).
KEPT = 64
#: A buffer made for an array gets this much more room, so that a scene that grows a
#: little from frame to frame does not make a new one each time.
_SLACK = 1 / 8
#: An array takes a free buffer at most this many times its size (a small array that
#: lives long, a scene's table, would otherwise pin a frame's largest buffer).
_LOOSEST = 2


class _Buffers(threading.local):
    """A thread's buffers (uint8), smallest first (one list: nothing to fall out of step)."""

    def __init__(self) -> None:
        self.kept: list[np.ndarray] = []


_buffers = _Buffers()


def _refs(buffers: list[np.ndarray], i: int) -> int:
    return sys.getrefcount(buffers[i])


def unshared(kept: list[np.ndarray]) -> bool:
    """Whether the list alone refers to each array of ``kept`` (no array made from one
    lives); False when that cannot be told."""
    return _FREE is not None and all(_refs(kept, i) == _FREE for i in range(len(kept)))


def _calibrate() -> int | None:
    """What _refs gives for a buffer that only the list holds (the interpreter's own
    references depend on its version), checked against a buffer with a view alive; None
    when they do not tell the two apart (then nothing is pooled)."""
    kept = [np.empty(8, np.uint8)]
    free = _refs(kept, 0)
    view = kept[0][:4].view(np.int32)
    held = _refs(kept, 0)
    del view
    return free if held > free and _refs(kept, 0) == free else None


_FREE = _calibrate()


def _shape(shape: int | tuple[int, ...]) -> tuple[int, ...]:
    """A shape as a tuple of Python ints (numpy integers accepted)."""
    return (int(shape),) if isinstance(shape, (int, np.integer)) else tuple(map(int, shape))


def empty(shape: int | tuple[int, ...], dtype: np.dtype | type = np.float64) -> np.ndarray:
    """An uninitialized C-contiguous array, as ``np.empty(shape, dtype)`` gives, in the
    smallest free buffer of this thread that holds it (a new one when none does)."""
    dtype, shape = np.dtype(dtype), _shape(shape)
    need = math.prod(shape) * dtype.itemsize
    if need < SMALLEST or _FREE is None:
        return np.empty(shape, dtype)
    kept = _buffers.kept
    start, stop = bisect_left(kept, need, key=len), bisect_right(kept, _LOOSEST * need + SMALLEST, key=len)
    for i in range(start, stop):
        if _refs(kept, i) == _FREE:
            return np.ndarray(shape, dtype, kept[i])  # its base is the buffer: held while it lives
    # a new buffer, in place of the largest free one too small for it
    smaller = [i for i in range(start) if _refs(kept, i) == _FREE]
    if not smaller and len(kept) >= KEPT:
        return np.empty(shape, dtype)
    buf = np.empty(need + int(need * _SLACK), np.uint8)
    if smaller:
        del kept[smaller[-1]]
    kept.insert(bisect_left(kept, len(buf), key=len), buf)
    return np.ndarray(shape, dtype, buf)


#: Where each array of :func:`arrays` starts: at a cache line of its own.
_LINE = 64


def arrays(*specs: tuple[int | tuple[int, ...], np.dtype | type]) -> tuple[np.ndarray, ...]:
    """Uninitialized C-contiguous arrays of the (shape, dtype) ``specs`` (shapes as ints or
    tuples: the layouts are kept by them), each starting at a cache line (so that rows of
    32 or 64 bytes never straddle two) in one buffer of :func:`empty`: one buffer to find
    for a frame set-up's dozen arrays. The buffer is held while any of them lives."""
    size, laid = _layout(specs)
    buf, view = empty(size + _LINE, np.uint8), np.ndarray  # the heap aligns to 16 bytes only
    start = -address(buf) % _LINE
    return tuple(view(shape, dtype, buf, start + offset) for shape, dtype, offset in laid)


@lru_cache(maxsize=64)
def _layout(specs: tuple[tuple[int | tuple[int, ...], np.dtype | type], ...]) -> tuple[int, tuple]:
    """The bytes :func:`arrays` lays ``specs`` out in, and each array's (shape, dtype,
    offset); kept, as a frame's set-up asks for the same few layouts frame after frame
    (working them out again took 7 of a ten-array call's 12 us, warm)."""
    laid, at = [], 0
    for shape, dtype in specs:
        shape = _shape(shape)
        laid.append((shape, dtype, at))
        at += -(-math.prod(shape) * np.dtype(dtype).itemsize // _LINE) * _LINE
    return max(at, 1), tuple(laid)


def kept_bytes() -> int:
    """The bytes this thread's buffers hold."""
    return sum(len(b) for b in _buffers.kept)
