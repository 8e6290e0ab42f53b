"""Memory budget of ``svo build``: an estimate made before voxelising, and the limit.

The estimate counts voxels from the mesh itself: a surface crosses about
``SURFACE_FACTOR`` voxels per unit of area (in voxel units: the closed-overlap test keeps
every voxel a triangle touches; measured 1.45 on the bundled torus and sphere at depths
5-10) plus three per unit of each triangle's longest edge (a sliver of no area still
crosses a line of voxels), and a solid fill adds the enclosed volume (the absolute signed volume of the
mesh, in voxels; measured within 13-26% of the fill). Peak memory is
``SURFACE_BYTES`` per surface voxel plus a fixed ``BASE`` (the interpreter, numpy, the
mesh and one voxelising batch). The voxeliser holds 8 bytes a voxel (its sorted codes)
and the octree builder, the peak, adds the masks and first-child indexes of the levels
and the 4-byte words: peak RSS measured 20 bytes a voxel above a 35 MiB interpreter at
depths 11-12, and ``BASE + SURFACE_BYTES * estimate`` came within +4% of the peak at
depth 12 (torus 902 MiB, folded 1,714 MiB), +31% at depth 11 and +2% to +23% at depths
8-10 (the estimate counts more voxels than there are). A solid fill adds ``FILL_BYTES``
per fill voxel: it is made slab by slab into the same 8-byte codes, and the octree's
levels above a solid are an eighth as long as it (12.3 bytes a voxel measured on the
torus at depth 10, 130 M voxels, 1,573 MiB, and 11.4 on the sphere, 558 M voxels,
6,194 MiB; the estimate is 2-6% over at depth 10). A binvox input adds its file's
bytes, and its voxels count as surface voxels.
"""

from __future__ import annotations

import os
import re

import numpy as np

from ..errors import Rend3rError

SURFACE_FACTOR = 1.6
SURFACE_BYTES = 16
FILL_BYTES = 12
BASE = 125 << 20
_UNITS = {"": 1, "K": 1 << 10, "M": 1 << 20, "G": 1 << 30, "T": 1 << 40}
_SIZE = re.compile(r"\s*([0-9]+(?:\.[0-9]*)?)\s*([KMGT]?)(?:I?B)?\s*", re.IGNORECASE)


def parse_bytes(text: str) -> int:
    """``"2G"``, ``"512M"``, ``"1.5GiB"`` or a plain byte count -> bytes (ValueError otherwise)."""
    m = _SIZE.fullmatch(text)
    if not m:
        raise ValueError(f"expected a size such as 2G or 512M, not {text!r}")
    value = int(float(m[1]) * _UNITS[m[2].upper()])
    if value <= 0:
        raise ValueError(f"the size must be positive, not {text!r}")
    return value


def default_budget() -> int:
    """Half of the machine's physical memory (4 GiB where the system does not say)."""
    try:
        return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") // 2
    except (ValueError, OSError, AttributeError):
        return 4 << 30


def estimate_voxels(tri_grid: np.ndarray, n: int, solid: bool) -> tuple[int, int]:
    """Expected (surface, solid fill) voxel counts of triangles (m, 3, 3) in voxel units of an n^3 grid."""
    a, b, c = tri_grid[:, 0], tri_grid[:, 1], tri_grid[:, 2]
    cross = np.cross(b - a, c - a)
    area = 0.5 * float(np.sqrt((cross * cross).sum(1)).sum())
    edges = np.sqrt((np.stack([b - a, c - b, a - c]) ** 2).sum(-1)).max(0)
    surface = SURFACE_FACTOR * area + 3.0 * float(edges.sum())  # slivers cover their length
    fill = abs(float((cross * a).sum())) / 6.0 if solid else 0.0
    cap = float(n) ** 3
    return int(min(surface, cap)), int(min(fill, cap))


def check_budget(voxels: tuple[int, int], budget: int, what: str, held: int = 0) -> None:
    """Refuse, with the estimate, a build of (surface, fill) voxels that would exceed ``budget``
    bytes (``held``: bytes kept besides, such as a binvox file's)."""
    surface, fill = voxels
    need = BASE + held + SURFACE_BYTES * surface + FILL_BYTES * fill
    if need > budget:
        raise Rend3rError(f"{what}: about {surface + fill:,} voxels need an estimated {need / 2**30:.2f} GiB at peak, "
                          f"over the memory budget of {budget / 2**30:.1f} GiB (--max-memory; "
                          "use a smaller --depth)")


def max_voxels(budget: int, per_voxel: int = SURFACE_BYTES) -> int:
    """Most voxels a build may hold within ``budget`` bytes at ``per_voxel`` bytes each."""
    return max((budget - BASE) // per_voxel, 0)
