"""Large working arrays, their memory kept from one frame (or program) to the next.

A frame's working arrays (the shape tables, the hierarchy, the bundles' bounds, the bands'
per-pixel arrays) and the processor's instruction lists and tables grow with the scene
(a 65,536-sphere run at 512x384 keeps buffers of 135 MB, 47 MB of it instruction lists
whose pages are mostly never touched). Allocated afresh each time, glibc gives them back
to the kernel when they are freed (it trims the heap's top and unmaps large blocks), and
the next run pays a page fault and a zeroed page for every 4 KiB it touches again: on
this project's machine that was more than half of a 65,536-sphere run
(``docs/performance.md``, "Working memory"). :func:`empty` hands out arrays in buffers
it keeps, per thread, instead.

A buffer is handed out again only once nothing refers to it: every array made from it
holds it (numpy's ``base``), so an array that is kept, or a view of it, keeps its buffer
out of use, and whatever lives on never shares memory with a later array. Arrays below
``SMALLEST`` bytes come from ``np.empty`` (the heap serves them without faults).
"""

from __future__ import annotations

import math
import sys
import threading
from bisect import bisect_left

import numpy as np

#: Bytes below which an array is not worth a buffer.
SMALLEST = 1 << 16
#: Buffers a thread keeps at most (more arrays alive at once come from np.empty).
KEPT = 64
#: A buffer made for an array gets this much more room, so that a scene that grows a
#: little from frame to frame does not make a new one each time.
_SLACK = 1 / 8


class _Buffers(threading.local):
    """A thread's buffers (uint8), by size, and their sizes."""

    def __init__(self) -> None:
        self.kept: list[np.ndarray] = []
        self.sizes: list[int] = []


_buffers = _Buffers()


def _refs(buffers: list[np.ndarray], i: int) -> int:
    return sys.getrefcount(buffers[i])


#: What _refs gives for a buffer that only the list holds (measured: the interpreter's own
#: references depend on its version).
_FREE = _refs([np.empty(0, np.uint8)], 0)


def empty(shape: int | tuple[int, ...], dtype: np.dtype | type = np.float64) -> np.ndarray:
    """An uninitialized C-contiguous array, as ``np.empty(shape, dtype)`` gives, in the
    smallest free buffer of this thread that holds it (a new one when none does)."""
    dtype = np.dtype(dtype)
    shape = (shape,) if isinstance(shape, int) else tuple(shape)
    need = math.prod(shape) * dtype.itemsize
    if need < SMALLEST:
        return np.empty(shape, dtype)
    b = _buffers
    kept, sizes = b.kept, b.sizes
    start = bisect_left(sizes, need)
    found = next((i for i in range(start, len(kept)) if _refs(kept, i) == _FREE), -1)
    if found < 0:  # a new buffer, in place of the largest free one too small for it
        smaller = [i for i in range(start) if _refs(kept, i) == _FREE]
        if not smaller and len(kept) >= KEPT:
            return np.empty(shape, dtype)
        if smaller:
            del kept[smaller[-1]], sizes[smaller[-1]]
        size = need + int(need * _SLACK)
        found = bisect_left(sizes, size)
        kept.insert(found, np.empty(size, np.uint8))
        sizes.insert(found, size)
    return kept[found][:need].view(dtype).reshape(shape)


def kept_bytes() -> int:
    """The bytes this thread's buffers hold."""
    return sum(_buffers.sizes)
