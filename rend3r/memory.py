"""Allocator tuning for the renderers' array temporaries.

A frame allocates and frees thousands of short-lived arrays of a few hundred KiB. With
glibc's default thresholds each of them is mapped from the kernel and unmapped again (or
the heap top trimmed), so every temporary pays page faults and zeroing: measured here,
that doubles the cost of a chain of float32 operations. Raising the mmap and trim
thresholds lets freed blocks be reused instead. The process then keeps up to
``TRIM_BYTES`` of freed memory for reuse, so this is a choice for the program, not for a
library: the ``rend3r`` command makes it (as do the benchmarks, to measure what it runs);
code that imports rend3r may call :func:`reuse_freed_memory` itself. Elsewhere than glibc
this does nothing. The raytracer's large working arrays do not depend on it: they live in
buffers kept per thread (``rend3r/emu/workspace.py``).

Dask workers are processes of their own: this module is a Dask preload (``dask worker
ADDRESS --preload rend3r.memory``; the local cluster's worker processes get it from
``rend3r.campaign``). A task of ``rend3r explore`` (the 20 example programs at 256x192)
took 4-10% longer in a process left untuned, with some 60 page faults a frame.
"""

from __future__ import annotations

import ctypes
import ctypes.util
from functools import lru_cache

M_TRIM_THRESHOLD, M_MMAP_THRESHOLD = -1, -3  # glibc's mallopt parameters
MMAP_BYTES = 64 << 20  # blocks below this come from the heap
TRIM_BYTES = 256 << 20  # free memory kept at the heap top before it is returned


@lru_cache(maxsize=1)
def reuse_freed_memory() -> bool:
    """Tune glibc's allocator once per process; True if it was tuned."""
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
        mallopt = libc.mallopt
    except (OSError, AttributeError):
        return False
    return bool(mallopt(M_MMAP_THRESHOLD, MMAP_BYTES)) and bool(mallopt(M_TRIM_THRESHOLD, TRIM_BYTES))


def dask_setup(worker: object) -> None:
    """Dask's preload hook: a worker process started with ``--preload rend3r.memory``
    tunes its allocator as the ``rend3r`` command does."""
    reuse_freed_memory()
