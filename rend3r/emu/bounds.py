"""Conservative bounds of shapes, per frame (the formulas are in ``csrc/bounds.h``).

When a ray provably cannot hit a shape, or cannot hit it nearer than some distance, *as
the working-precision raycaster computes it* (not merely in exact arithmetic); derived in
``docs/emulator.md`` section 7. Only spheres with moderate maps (|q|^2 min|s_i| >= 2^-6,
|q|^2 max|s_i| <= 2^6, finite centre) are bounded (the shape tables mark them, see
``csrc/datapath.inc`` shape_tables); every other shape gets an infinite cull radius and a
zero depth floor, so every ray tests it.
"""

from __future__ import annotations

import numpy as np

from . import native, threads

SLACK = 1e-9
#: Shapes a thread takes at least.
SHAPE_CHUNK = 1 << 10


def cull_radii(table: np.ndarray, ok: np.ndarray, dist: np.ndarray, dmin: float, u: float, tiny: float,
               overflow: float, jobs: int = 1) -> np.ndarray:
    """Per shape, the world radius beyond which no ray line can hit (inf: no bound): rays
    whose origins lie within ``dist`` (per shape) of the centre, directions at least
    ``dmin`` long, unit roundoff ``u``, smallest normal ``tiny`` and overflow threshold
    ``overflow`` of the precision."""
    out = np.empty(len(table))
    table, flags, dist = _inputs(table, ok, dist)
    lib = native.library()
    threads.split(jobs, threads.ranges(len(out), jobs, SHAPE_CHUNK), lambda a, b: lib.bound_radii(
        table[a:].ctypes.data, flags[a:].ctypes.data, dist[a:].ctypes.data, b - a, dmin, u, tiny, overflow,
        out[a:].ctypes.data))
    return out


def depth_floors(table: np.ndarray, ok: np.ndarray, dist: np.ndarray, dmin: float, dmax: float, u: float,
                 tiny: float, jobs: int = 1) -> np.ndarray:
    """Per shape, a lower bound of the computed ``sq_dist`` of any hit by a ray from an apex
    ``dist`` (per shape) from the centre, directions between ``dmin`` and ``dmax`` long; 0:
    no bound claimed."""
    out = np.empty(len(table))
    table, flags, dist = _inputs(table, ok, dist)
    lib = native.library()
    threads.split(jobs, threads.ranges(len(out), jobs, SHAPE_CHUNK), lambda a, b: lib.bound_floors(
        table[a:].ctypes.data, flags[a:].ctypes.data, dist[a:].ctypes.data, b - a, dmin, dmax, u, tiny,
        out[a:].ctypes.data))
    return out


def _inputs(table: np.ndarray, ok: np.ndarray, dist: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The per-shape inputs as the kernels read them (checked table, uint8 flags, float64)."""
    n = len(table)
    native.ptr(table, np.float64, (n, native.B_COLUMNS))
    dist = np.ascontiguousarray(dist, np.float64)
    native.ptr(dist, np.float64, (n,))
    return table, np.ascontiguousarray(ok, np.uint8), dist


def reach(points: np.ndarray, centers: np.ndarray) -> np.ndarray:
    """An upper bound of the distance from each centre to any of the points (n, 3)."""
    lo, hi = points.min(axis=0), points.max(axis=0)
    mid, half = (lo + hi) / 2, np.linalg.norm(hi - lo) / 2
    return np.linalg.norm(centers - mid, axis=1) * (1 + SLACK) + half
