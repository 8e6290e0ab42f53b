"""Conservative bounds of shapes, per frame (the formulas are in ``csrc/bounds.h``).

When a ray provably cannot hit a shape, or cannot hit it nearer than some distance, *as
the working-precision raycaster computes it* (not merely in exact arithmetic); derived in
``docs/emulator.md`` section 7. Only spheres with moderate maps (|q|^2 min|s_i| >= 2^-6,
|q|^2 max|s_i| <= 2^6, finite centre) are bounded (the shape tables mark them, see
``csrc/datapath.inc`` shape_tables); every other shape gets an infinite cull radius and a
zero depth floor, so every ray tests it.

The frame's set-up runs :func:`primary` (csrc/setup.c); a band's shadow bundles are filled
in C from its hit points (csrc/band.c shadow_bounds).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import native
from .native import address
from .workspace import arrays, empty

#: Shapes or items a range of a set-up pass takes at least (csrc/setup.c): the passes take
#: about 30 ns a shape, and a team of threads hands a range over in about a microsecond.
SHAPE_CHUNK = 1 << 10
#: A frame's primary bounds over more shapes than this leave the largest subtrees of at
#: most this many items to be made when a packet first enters them (csrc/setup.c
#: bundle_lazy; 0: every subtree made up front).
LAZY_ITEMS = 256


@dataclass
class Pass:
    """A bundle of rays' per-shape pass, run with its refit in one call (bvh.Tree.fit):
    the kernels' block and the arrays it reads and fills."""

    block: native.Bundle
    table: np.ndarray  # the bound table (n, B_COLUMNS)
    flags: np.ndarray  # bounded per shape, as uint8
    radius: np.ndarray  # cull radius per shape (a shadow pass's, like behind and keys, per row: kernels.h PASS_SHADOW)
    floor: np.ndarray | None = None  # primary rays: depth floor per shape
    pc: np.ndarray | None = None  # primary rays: cull data per shape (PC_COLUMNS)
    pc32: np.ndarray | None = None  # and what float lanes read of it (P32_COLUMNS, float32)
    behind: np.ndarray | None = None  # a directional light's behind terms (n, 3)
    keys: np.ndarray | None = None  # its stop keys (n, 3), or a point light's behind-test terms (n, SK_COLUMNS)
    unit: np.ndarray | None = None  # a directional light's l / |l|


def primary(table: np.ndarray, ok: np.ndarray, apex: np.ndarray, dmin: float, dmax: float, u: float, tiny: float,
            overflow: float) -> Pass:
    """Per shape, for rays from ``apex`` with directions ``dmin``..``dmax`` long: the world
    radius beyond which no ray line can hit (inf: no bound), a lower bound of the computed
    ``sq_dist`` of any hit (0: none) and the cull data of the kernels' per-packet test
    (``csrc/kernels.h`` PC_COLUMNS, and P32_COLUMNS for float lanes); ``u``, ``tiny`` and
    ``overflow`` are the precision's unit roundoff, smallest normal and overflow threshold."""
    n = len(table)
    radius, floor, pc, pc32 = arrays((n, np.float64), (n, np.float64), ((n, native.PC_COLUMNS), np.float64),
                                     ((n, native.P32_COLUMNS), np.float32))
    p = shape_pass(table, ok, u, tiny, overflow, native.PASS_PRIMARY, radius=radius, floor=floor, pc=pc, pc32=pc32)
    p.block.apex[:] = [float(c) for c in apex]
    p.block.dmin, p.block.dmax = dmin, dmax
    p.block.floor, p.block.pc, p.block.pc32 = address(p.floor), address(p.pc), address(p.pc32)
    return p


def shape_pass(table: np.ndarray, ok: np.ndarray, u: float, tiny: float, overflow: float, kind: int,
               radius: np.ndarray | None = None, **others: np.ndarray) -> Pass:
    """A pass of ``kind`` (native.PASS_*): its block over the checked table and uint8 flags,
    with its radius array (None: a new one; ``others``: the Pass's other arrays)."""
    n = len(table)
    native.ptr(table, np.float64, (n, native.B_COLUMNS))
    flags = np.ascontiguousarray(ok, np.uint8)
    native.ptr(flags, np.uint8, (n,))
    p = Pass(native.Bundle(), table, flags, empty(n) if radius is None else radius, **others)
    b = p.block
    b.bnd, b.ok, b.n, b.radius, b.pass_ = address(table), address(flags), n, address(p.radius), kind
    b.u, b.tiny, b.overflow = u, tiny, overflow
    return p
