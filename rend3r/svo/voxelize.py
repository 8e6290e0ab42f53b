"""Surface voxelisation by exact triangle/box overlap, plus optional solid fill.

Convention (one for the whole package): a grid of ``n = 2**depth`` voxels per axis
covers the cube ``[lo, lo + n*h]^3``; voxel ``i`` covers ``[lo + i*h, lo + (i+1)*h]``
and its centre is ``lo + (i + 0.5)*h``. The octree's normalised ``[-1, 1]^3`` is that
same cube. :func:`fit_bounds` centres the mesh and leaves at least one empty voxel on
every side, so no surface touches the border.

A voxel is in the surface set when the closed triangle and the closed voxel box
intersect (the separating-axis test of Akenine-Moller: 3 box axes, the triangle normal,
9 edge cross products); touching counts. Solid fill adds every voxel whose centre has a
non-zero winding number, counted along +z columns through voxel centres.
"""

from __future__ import annotations

import numpy as np

from ..errors import Rend3rError
from ..progress import ProgressFactory, hidden
from .budget import FILL_BYTES, SURFACE_BYTES, check_budget, estimate_voxels
from .budget import max_voxels as voxel_limit
from .octree import morton_decode, morton_encode, sorted_unique

_CHUNK = 1 << 19  # candidate (triangle, voxel) pairs per vectorised batch
MAX_COORD = 1e150
"""Largest vertex coordinate and extent: products of two coordinates stay finite."""
MIN_VOXEL = 1e-150
"""Smallest voxel size: grid units (coordinate / voxel size) stay finite."""


def fit_bounds(verts: np.ndarray, depth: int) -> tuple[np.ndarray, float]:
    """(lo corner, voxel size h) of a cube holding the mesh with one voxel of padding."""
    verts = np.asarray(verts, dtype=np.float64)
    if len(verts) == 0 or not np.all(np.isfinite(verts)):
        raise Rend3rError("mesh has no vertices or non-finite coordinates")
    vmin, vmax = verts.min(0), verts.max(0)
    n = 1 << depth
    with np.errstate(all="ignore"):
        extent = float((vmax - vmin).max()) or 1.0
        h = extent / (n - 2.5) if n > 2 else extent
        centre = vmin / 2 + vmax / 2
        lo = centre - h * n / 2
    # the grid must hold every vertex with room to spare: |coordinate| and extent within
    # MAX_COORD, and a voxel size a float resolves at that magnitude
    if not (extent <= MAX_COORD and np.all(np.abs(verts) <= MAX_COORD) and h >= MIN_VOXEL):
        raise Rend3rError(f"mesh coordinates must lie within +-{MAX_COORD:g} and span at least "
                          f"{MIN_VOXEL * n:g} (extent {extent:g})")
    return lo, h


def expand_counts(counts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For items with ``counts``: (item index, position 0..count-1) of every expanded row."""
    item = np.repeat(np.arange(len(counts)), counts)
    starts = np.cumsum(counts) - counts
    return item, np.arange(int(counts.sum())) - starts[item]


def _sat_overlap(tri: np.ndarray, centre: np.ndarray) -> np.ndarray:
    """Closed overlap of triangles (k, 3, 3) with unit boxes centred at ``centre`` (k, 3).

    Component arrays instead of small reductions: the 13 axis tests are elementwise.
    """
    v = [[tri[:, i, a] - centre[:, a] for a in range(3)] for i in range(3)]
    keep = np.ones(len(tri), dtype=bool)
    for a in range(3):
        keep &= (np.minimum(np.minimum(v[0][a], v[1][a]), v[2][a]) <= 0.5)
        keep &= (np.maximum(np.maximum(v[0][a], v[1][a]), v[2][a]) >= -0.5)
    e = [[v[(i + 1) % 3][a] - v[i][a] for a in range(3)] for i in range(3)]
    normal = [e[0][(a + 1) % 3] * e[1][(a + 2) % 3] - e[0][(a + 2) % 3] * e[1][(a + 1) % 3]
              for a in range(3)]
    dist = normal[0] * v[0][0] + normal[1] * v[0][1] + normal[2] * v[0][2]
    keep &= np.abs(dist) <= 0.5 * (np.abs(normal[0]) + np.abs(normal[1]) + np.abs(normal[2]))
    for i in range(3):
        other = (i + 2) % 3  # the vertex not on edge i; edge i's two vertices project equally
        for a in range(3):
            b, c = (a + 1) % 3, (a + 2) % 3
            # axis = unit_a x e_i = (0 at a, -e_c at b, e_b at c)
            p_edge = e[i][b] * v[i][c] - e[i][c] * v[i][b]
            p_other = e[i][b] * v[other][c] - e[i][c] * v[other][b]
            r = 0.5 * (np.abs(e[i][b]) + np.abs(e[i][c]))
            keep &= (np.minimum(p_edge, p_other) <= r) & (np.maximum(p_edge, p_other) >= -r)
    return keep


def _surface_chunk(tri: np.ndarray, n: int) -> np.ndarray:
    """Voxel coordinates overlapped by triangles ``tri`` (m, 3, 3) in grid units."""
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    a = np.abs(normal).argmax(1)
    b, c = (a + 1) % 3, (a + 2) % 3
    lo = np.clip(np.ceil(tri.min(1)).astype(np.int64) - 1, 0, n - 1)
    hi = np.clip(np.floor(tri.max(1)).astype(np.int64), 0, n - 1)
    rows = np.arange(len(tri))
    nb, nc = hi[rows, b] - lo[rows, b] + 1, hi[rows, c] - lo[rows, c] + 1
    t, pos = expand_counts(nb * nc)
    xb = lo[t, b[t]] + pos // nc[t]
    xc = lo[t, c[t]] + pos % nc[t]
    # range of the triangle's plane along the dominant axis over each column square
    nt, at, bt, ct = normal[t], a[t], b[t], c[t]
    r = np.arange(len(t))
    d = np.einsum("ij,ij->i", nt, tri[t, 0])
    na, nbv, ncv = nt[r, at], nt[r, bt], nt[r, ct]
    corners = [(d - nbv * (xb + i) - ncv * (xc + j)) / na for i in (0, 1) for j in (0, 1)]
    zlo = np.maximum(np.ceil(np.minimum.reduce(corners)).astype(np.int64) - 1, lo[t, at])
    zhi = np.minimum(np.floor(np.maximum.reduce(corners)).astype(np.int64), hi[t, at])
    col, k = expand_counts(np.maximum(zhi - zlo + 1, 0))
    coords = np.empty((len(col), 3), dtype=np.int64)
    rr = np.arange(len(col))
    coords[rr, at[col]] = zlo[col] + k
    coords[rr, bt[col]] = xb[col]
    coords[rr, ct[col]] = xc[col]
    hit = _sat_overlap(tri[t[col]], coords + 0.5)
    return coords[hit]


def batches(weights: np.ndarray, limit: int):
    """Slices of consecutive items whose summed weight stays near ``limit``."""
    start = 0
    cum = np.cumsum(weights)
    while start < len(weights):
        base = cum[start - 1] if start else 0
        stop = max(int(np.searchsorted(cum, base + limit, side="right")), start + 1)
        yield slice(start, stop)
        start = stop


def _keys(coords: np.ndarray, n: int) -> np.ndarray:
    """Sorted unique linear keys ``(x*n + y)*n + z`` of voxel coordinates."""
    return sorted_unique((coords[:, 0] * n + coords[:, 1]) * n + coords[:, 2])


def _rows(keys: np.ndarray, n: int) -> np.ndarray:
    return np.stack([keys // (n * n), (keys // n) % n, keys % n], 1)


def _unique_rows(coords: np.ndarray, n: int) -> np.ndarray:
    return _rows(_keys(coords, n), n)


def _weight(tri: np.ndarray, n: int) -> np.ndarray:
    """Upper bound of the candidate voxels of each triangle (columns x 3)."""
    span = np.clip(np.ceil(tri.max(1) - tri.min(1)) + 2, 1, n)
    return np.sort(span, axis=1)[:, 1:].prod(1).astype(np.int64) * 3


def _split_large(tri: np.ndarray, n: int) -> np.ndarray:
    """Split triangles with more candidates than a batch into four, until none has.

    The pieces cover the same points, so the overlapped voxels do not change; only the
    memory of one batch stays bounded.
    """
    done = [tri[:0]]
    while len(tri):
        big = _weight(tri, n) > _CHUNK
        done.append(tri[~big])
        a, b, c = tri[big, 0], tri[big, 1], tri[big, 2]
        ab, bc, ca = (a + b) / 2, (b + c) / 2, (c + a) / 2
        tri = np.concatenate([np.stack(p, 1) for p in ((a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca))])
    return np.concatenate(done)


def voxelize_surface(tri_grid: np.ndarray, n: int, max_voxels: int | None = None) -> np.ndarray:
    """Unique voxels (M, 3) overlapped by triangles given in grid units (voxel i = [i, i+1]).

    Degenerate triangles (equal or collinear vertices: zero area) cover no surface and
    are skipped; M is 0 when every triangle is degenerate. With ``max_voxels``, more
    voxels than that are refused with a Rend3rError as soon as the batches hold them.
    """
    return _rows(_surface_keys(tri_grid, n, lambda c: _keys(c, n), max_voxels), n)


def _surface_keys(tri_grid: np.ndarray, n: int, key, max_voxels: int | None,
                  progress: ProgressFactory = hidden) -> np.ndarray:
    """Sorted unique ``key(coords)`` of the voxels the triangles overlap, batch by batch
    (``progress``'s bar counts candidate voxels).

    Each batch's unique keys are appended to one growing buffer (8 bytes a key: growing
    it in place maps more pages instead of copying), which is sorted and deduplicated in
    place at the end: no second array of all the keys.
    """
    tri_grid = tri_grid[np.any(np.cross(tri_grid[:, 1] - tri_grid[:, 0], tri_grid[:, 2] - tri_grid[:, 0]), axis=1)]
    tri_grid = _split_large(tri_grid, n)
    weight = _weight(tri_grid, n)
    keys = np.empty(0, dtype=np.int64)
    held = 0
    with progress(int(weight.sum()), "voxelising") as bar:
        for s in batches(weight, _CHUNK):
            batch = sorted_unique(key(_surface_chunk(tri_grid[s], n)))
            bar.advance(int(weight[s].sum()))
            if held + len(batch) > len(keys):
                keys.resize(max(held + len(batch), len(keys) * 3 // 2), refcheck=False)
            keys[held:held + len(batch)] = batch
            held += len(batch)
            del batch
            if max_voxels is not None and held > max_voxels:
                held = _dedupe(keys, held)
                if held > max_voxels:
                    raise Rend3rError(f"the surface holds more than {max_voxels:,} voxels, the most the memory "
                                      "budget allows (--max-memory; use a smaller --depth)")
    keys.resize(_dedupe(keys, held), refcheck=False)
    return keys


def _dedupe(values: np.ndarray, count: int) -> int:
    """Sort ``values[:count]`` in place and move its distinct values to the front; their number."""
    values[:count].sort()
    kept = 0
    last = None
    for start in range(0, count, _CHUNK):
        block = values[start:min(start + _CHUNK, count)]
        keep = np.r_[block[0] != last if last is not None else True, block[1:] != block[:-1]]
        last = block[-1]
        unique = block[keep]
        values[kept:kept + len(unique)] = unique
        kept += len(unique)
    return kept


def fill_solid(tri_grid: np.ndarray, n: int, max_voxels: int | None = None) -> np.ndarray:
    """Voxels whose centre has a non-zero winding number (winding counted along +z).

    With ``max_voxels`` the exact count is checked before the voxels are made, and a
    larger fill is refused with a Rend3rError.
    """
    p = tri_grid[:, :, :2]
    lo = np.clip(np.floor(p.min(1) - 0.5).astype(np.int64), 0, n - 1)
    hi = np.clip(np.ceil(p.max(1) - 0.5).astype(np.int64), 0, n - 1)
    t, pos = expand_counts((hi[:, 0] - lo[:, 0] + 1) * (hi[:, 1] - lo[:, 1] + 1))
    ny = hi[t, 1] - lo[t, 1] + 1
    ix, iy = lo[t, 0] + pos // ny, lo[t, 1] + pos % ny
    # column centres, nudged off exact edges by an irrational offset far below voxel size
    qx, qy = ix + 0.5 + 1e-7 * np.sqrt(2), iy + 0.5 + 1e-7 * np.sqrt(3)
    a, b, c = tri_grid[t, 0], tri_grid[t, 1], tri_grid[t, 2]
    def edge(u, v):
        return (v[:, 0] - u[:, 0]) * (qy - u[:, 1]) - (v[:, 1] - u[:, 1]) * (qx - u[:, 0])
    w0, w1, w2 = edge(b, c), edge(c, a), edge(a, b)
    area = w0 + w1 + w2
    inside = (area != 0) & (((w0 > 0) & (w1 > 0) & (w2 > 0)) | ((w0 < 0) & (w1 < 0) & (w2 < 0)))
    if not inside.any():  # no triangle covers a column centre seen from +z
        return np.empty((0, 3), dtype=np.int64)
    z = (w0 * a[:, 2] + w1 * b[:, 2] + w2 * c[:, 2])[inside] / area[inside]
    sign = np.where(area[inside] > 0, -1, 1)  # counter-clockwise seen from +z faces up: an exit
    col = (ix * n + iy)[inside]
    order = np.lexsort((z, col))
    col, z, sign = col[order], z[order], sign[order]
    starts = np.flatnonzero(np.r_[True, col[1:] != col[:-1]])
    wind = np.cumsum(sign)
    wind -= np.repeat(wind[starts] - sign[starts], np.diff(np.r_[starts, len(col)]))
    same_next = np.r_[col[1:] == col[:-1], False]
    span = same_next & (wind != 0)
    k0 = np.clip(np.ceil(z[span] - 0.5).astype(np.int64), 0, n)
    k1 = np.clip(np.floor(z[np.flatnonzero(span) + 1] - 0.5).astype(np.int64), -1, n - 1)
    runs = np.maximum(k1 - k0 + 1, 0)
    if max_voxels is not None and int(runs.sum()) > max_voxels:
        raise Rend3rError(f"the solid fill holds {int(runs.sum()):,} voxels, over the {max_voxels:,} "
                          "the memory budget allows (--max-memory; use a smaller --depth)")
    run, k = expand_counts(runs)
    c = col[span][run]
    return np.stack([c // n, c % n, k0[run] + k], 1)


def voxelize(verts: np.ndarray, faces: np.ndarray, depth: int, solid: bool = False,
             budget: int | None = None) -> tuple[np.ndarray, np.ndarray, float]:
    """Voxelise a triangle mesh: (voxel coords (M, 3) sorted by x, y, z; lo corner; voxel size h).

    See :func:`voxelize_codes`, which this decodes.
    """
    codes, lo, h = voxelize_codes(verts, faces, depth, solid, budget)
    return _unique_rows(morton_decode(codes, depth), 1 << depth), lo, h


def voxelize_codes(verts: np.ndarray, faces: np.ndarray, depth: int, solid: bool = False,
                   budget: int | None = None, progress: ProgressFactory = hidden
                   ) -> tuple[np.ndarray, np.ndarray, float]:
    """Voxelise a triangle mesh: (sorted unique Morton codes (M,), lo corner, voxel size h).

    Codes (8 bytes a voxel) are what the octree builder sorts; coordinates are never held
    for the whole mesh. With ``budget`` (bytes) the build is refused up front when its
    estimate (:mod:`rend3r.svo.budget`) exceeds it, and again on the exact counts of the
    surface batches and the solid fill before they are expanded. ``progress(total, label)``
    makes the bar of the surface batches.
    """
    faces = np.asarray(faces, dtype=np.int64)
    if faces.ndim != 2 or faces.shape[1] != 3 or len(faces) == 0:
        raise Rend3rError("mesh has no triangles")
    if faces.min() < 0 or faces.max() >= len(verts):
        raise Rend3rError("mesh face refers to a missing vertex")
    lo, h = fit_bounds(verts, depth)
    n = 1 << depth
    tri = (np.asarray(verts, dtype=np.float64)[faces] - lo) / h
    limit = None
    if budget is not None:
        check_budget(estimate_voxels(tri, n, solid), budget, f"depth {depth}{' solid' if solid else ''}")
        limit = voxel_limit(budget)
    codes = _surface_keys(tri, n, lambda c: morton_encode(c, depth), limit, progress)
    if len(codes) == 0:
        raise Rend3rError("mesh has no area: every triangle has equal or collinear vertices")
    if solid:
        room = None if budget is None else voxel_limit(budget - SURFACE_BYTES * len(codes), FILL_BYTES)
        fill = fill_solid(tri, n, room)
        codes = sorted_unique(np.concatenate([codes, morton_encode(fill, depth)]))
    return codes, lo, h
