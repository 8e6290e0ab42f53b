"""Conservative bounds of shapes, per frame (the formulas are in ``csrc/bounds.h``).

When a ray provably cannot hit a shape, or cannot hit it nearer than some distance, *as
the working-precision raycaster computes it* (not merely in exact arithmetic); derived in
``docs/emulator.md`` section 7. Only spheres with moderate maps (|q|^2 min|s_i| >= 2^-6,
|q|^2 max|s_i| <= 2^6, finite centre) are bounded (the shape tables mark them, see
``csrc/datapath.inc`` shape_tables); every other shape gets an infinite cull radius and a
zero depth floor, so every ray tests it.
"""

from __future__ import annotations

import math

import numpy as np

from . import native, threads
from .native import address

#: Shapes a thread takes at least (the passes take about 30 ns a shape with AVX2: below this
#: handing a range to another thread costs more than it saves).
SHAPE_CHUNK = 1 << 14


def primary(table: np.ndarray, ok: np.ndarray, apex: np.ndarray, dmin: float, dmax: float, u: float, tiny: float,
            overflow: float, jobs: int = 1) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per shape, for rays from ``apex`` with directions ``dmin``..``dmax`` long: the world
    radius beyond which no ray line can hit (inf: no bound), a lower bound of the computed
    ``sq_dist`` of any hit (0: none) and the cull data of the kernels' per-packet test
    (``csrc/kernels.h`` PC_COLUMNS); ``u``, ``tiny`` and ``overflow`` are the precision's
    unit roundoff, smallest normal and overflow threshold."""
    n = len(table)
    table, flags = _inputs(table, ok)
    apex = np.ascontiguousarray(apex, np.float64)
    native.ptr(apex, np.float64, (3,))
    radius, floor, pc = np.empty(n), np.empty(n), np.empty((n, native.PC_COLUMNS))
    kernel = native.shape_pass("primary_shapes")
    threads.split(jobs, threads.ranges(n, jobs, SHAPE_CHUNK), lambda a, b: kernel(
        address(table[a:]), address(flags[a:]), b - a, address(apex), dmin, dmax, u, tiny, overflow,
        address(radius[a:]), address(floor[a:]), address(pc[a:])))
    return radius, floor, pc


def shadow(table: np.ndarray, ok: np.ndarray, lo: np.ndarray, hi: np.ndarray, dmin: float, u: float, tiny: float,
           overflow: float, *, chord: float = np.nan, unit: np.ndarray | None = None, length: float = 0.0,
           jobs: int = 1) -> tuple[np.ndarray, np.ndarray | None, np.ndarray | None]:
    """Per shape, the cull radius of shadow rays from origins in the box ``lo``..``hi``
    with directions at least ``dmin`` long, widened by the origins' rounding and, for a
    point light, by ``chord`` (the largest turn of a rounded l off the line to the light);
    for a directional light along the unit vector ``unit`` (|l| = ``length``), also the
    behind terms and stop keys (n, 3 each) of the light pass's per-packet test
    (``csrc/kernels.h`` LightPass.behind, ``csrc/shape_bounds.inc`` shadow_shapes); for a
    point light (``chord`` given) None and the terms of its per-node behind test (n,
    SK_COLUMNS: ``csrc/cull.h`` point_behind4); else None and None."""
    n = len(table)
    table, flags = _inputs(table, ok)
    lo3, hi3 = [float(c) for c in lo], [float(c) for c in hi]  # 3-vectors: plain arithmetic
    mid = np.array([(a + b) / 2 for a, b in zip(lo3, hi3)])
    half = math.sqrt(sum((b - a) * (b - a) for a, b in zip(lo3, hi3))) / 2
    magnitude = max(abs(c) for c in lo3 + hi3)  # of any origin's coordinates
    if unit is not None:
        unit = np.ascontiguousarray(unit, np.float64)
        native.ptr(unit, np.float64, (3,))
    radius = np.empty(n)
    behind, keys = (None, None) if unit is None else (np.empty((n, 3)), np.empty((n, 3)))
    point = np.empty((n, native.SK_COLUMNS)) if unit is None and chord == chord else None
    kernel = native.shape_pass("shadow_shapes")
    threads.split(jobs, threads.ranges(n, jobs, SHAPE_CHUNK), lambda a, b: kernel(
        address(table[a:]), address(flags[a:]), b - a, address(mid), half, magnitude, dmin, chord, u, tiny,
        overflow, None if unit is None else address(unit), length, address(radius[a:]),
        None if behind is None else address(behind[a:]), None if keys is None else address(keys[a:]),
        None if point is None else address(point[a:])))
    return radius, behind, keys if point is None else point


def _inputs(table: np.ndarray, ok: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The per-shape inputs as the kernels read them (checked table, uint8 flags)."""
    n = len(table)
    native.ptr(table, np.float64, (n, native.B_COLUMNS))
    flags = np.ascontiguousarray(ok, np.uint8)
    native.ptr(flags, np.uint8, (n,))
    return table, flags
