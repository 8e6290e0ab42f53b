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
_SLAB = 1 << 16  # (x, y) columns per slab of the solid fill
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


class _KeyBuffer:
    """One growing buffer of int64 keys, sorted and deduplicated in place: 8 bytes a key
    and no second array of all of them (growing it in place maps more pages instead of
    copying). Beyond ``limit`` keys it is deduplicated, and still beyond it refused."""

    def __init__(self, limit: int | None) -> None:
        self.keys = np.empty(0, dtype=np.int64)
        self.held = 0
        self.limit = limit

    def add(self, batch: np.ndarray, what: str) -> None:
        """Append ``batch``; a Rend3rError names ``what`` when the distinct keys pass the limit."""
        if self.held + len(batch) > len(self.keys):
            self.keys.resize(max(self.held + len(batch), len(self.keys) * 3 // 2), refcheck=False)
        self.keys[self.held:self.held + len(batch)] = batch
        self.held += len(batch)
        if self.limit is not None and self.held > self.limit and self.dedupe() > self.limit:
            raise Rend3rError(f"the {what} holds more than {self.limit:,} voxels, the most the memory "
                              "budget allows (--max-memory; use a smaller --depth)")

    def dedupe(self) -> int:
        """Sort and deduplicate the keys held; their number."""
        self.held = _dedupe(self.keys, self.held)
        return self.held

    def result(self) -> np.ndarray:
        """The sorted distinct keys (the buffer itself, trimmed)."""
        self.keys.resize(self.dedupe(), refcheck=False)
        return self.keys


def voxelize_surface(tri_grid: np.ndarray, n: int, max_voxels: int | None = None) -> np.ndarray:
    """Unique voxels (M, 3) overlapped by triangles given in grid units (voxel i = [i, i+1]).

    Degenerate triangles (equal or collinear vertices: zero area) cover no surface and
    are skipped; M is 0 when every triangle is degenerate. With ``max_voxels``, more
    voxels than that are refused with a Rend3rError as soon as the batches hold them.
    """
    keys = _KeyBuffer(max_voxels)
    _surface_keys(tri_grid, n, lambda c: _keys(c, n), keys)
    return _rows(keys.result(), n)


def _surface_keys(tri_grid: np.ndarray, n: int, key, keys: _KeyBuffer, progress: ProgressFactory = hidden) -> None:
    """Add ``key(coords)`` of the voxels the triangles overlap to ``keys``, batch by batch
    (``progress``'s bar counts candidate voxels)."""
    tri_grid = tri_grid[np.any(np.cross(tri_grid[:, 1] - tri_grid[:, 0], tri_grid[:, 2] - tri_grid[:, 0]), axis=1)]
    tri_grid = _split_large(tri_grid, n)
    weight = _weight(tri_grid, n)
    with progress(int(weight.sum()), "voxelising") as bar:
        for s in batches(weight, _CHUNK):
            keys.add(sorted_unique(key(_surface_chunk(tri_grid[s], n))), "surface")
            bar.advance(int(weight[s].sum()))


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


def _fill_keys(tri_grid: np.ndarray, n: int, key, keys: _KeyBuffer, progress: ProgressFactory = hidden) -> None:
    """Add ``key(coords)`` of the voxels whose centre has a non-zero winding number
    (counted along +z columns) to ``keys``.

    Slab by slab of about ``_SLAB`` columns along x: each slab's crossings are found in
    batches of triangles and its spans expanded in batches of voxels, so memory holds one
    slab's crossings and one batch, whatever the size of the fill (``progress``'s bar
    counts columns of x).
    """
    p = tri_grid[:, :, :2]
    lo = np.clip(np.floor(p.min(1) - 0.5).astype(np.int64), 0, n - 1)
    hi = np.clip(np.ceil(p.max(1) - 0.5).astype(np.int64), 0, n - 1)
    width = max(_SLAB // n, 1)
    with progress(n, "filling") as bar:
        for x0 in range(0, n, width):
            x1 = min(x0 + width, n) - 1
            here = (lo[:, 0] <= x1) & (hi[:, 0] >= x0)
            slab_lo, slab_hi = lo[here], hi[here]
            slab_lo[:, 0] = np.maximum(slab_lo[:, 0], x0)
            slab_hi[:, 0] = np.minimum(slab_hi[:, 0], x1)
            for coords in _spans(*_crossings(tri_grid[here], slab_lo, slab_hi, n), n):
                keys.add(key(coords), "solid fill")
            bar.advance(x1 - x0 + 1)


def _crossings(tri: np.ndarray, lo: np.ndarray, hi: np.ndarray, n: int
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(column ix*n + iy, z, sign) where triangles cross the column centres of their
    (x, y) boxes ``lo``..``hi``, sorted by column then z; sign -1 where the surface
    faces up (an exit)."""
    cols = (hi[:, 0] - lo[:, 0] + 1) * (hi[:, 1] - lo[:, 1] + 1)
    parts = [_column_hits(tri[s], lo[s], hi[s], cols[s], n) for s in batches(cols, _CHUNK)]
    if not parts:
        return np.empty(0, np.int64), np.empty(0), np.empty(0, np.int64)
    col, z, sign = (np.concatenate(x) for x in zip(*parts))
    order = np.lexsort((z, col))
    return col[order], z[order], sign[order]


def _column_hits(tri: np.ndarray, lo: np.ndarray, hi: np.ndarray, cols: np.ndarray, n: int
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`_crossings` of a batch of triangles, unsorted."""
    t, pos = expand_counts(cols)
    ny = hi[t, 1] - lo[t, 1] + 1
    ix, iy = lo[t, 0] + pos // ny, lo[t, 1] + pos % ny
    # column centres, nudged off exact edges by an irrational offset far below voxel size
    qx, qy = ix + 0.5 + 1e-7 * np.sqrt(2), iy + 0.5 + 1e-7 * np.sqrt(3)
    a, b, c = tri[t, 0], tri[t, 1], tri[t, 2]

    def edge(u, v):
        return (v[:, 0] - u[:, 0]) * (qy - u[:, 1]) - (v[:, 1] - u[:, 1]) * (qx - u[:, 0])

    w0, w1, w2 = edge(b, c), edge(c, a), edge(a, b)
    area = w0 + w1 + w2
    inside = (area != 0) & (((w0 > 0) & (w1 > 0) & (w2 > 0)) | ((w0 < 0) & (w1 < 0) & (w2 < 0)))
    z = (w0 * a[:, 2] + w1 * b[:, 2] + w2 * c[:, 2])[inside] / area[inside]
    sign = np.where(area[inside] > 0, -1, 1)  # counter-clockwise seen from +z faces up: an exit
    return (ix * n + iy)[inside], z, sign


def _spans(col: np.ndarray, z: np.ndarray, sign: np.ndarray, n: int):
    """Voxel coordinates (k, 3) between consecutive crossings of a column where the
    winding number is not zero, in batches of about ``_CHUNK``."""
    if not len(col):
        return
    starts = np.flatnonzero(np.r_[True, col[1:] != col[:-1]])
    wind = np.cumsum(sign)
    wind -= np.repeat(wind[starts] - sign[starts], np.diff(np.r_[starts, len(col)]))
    span = np.r_[col[1:] == col[:-1], False] & (wind != 0)
    k0 = np.clip(np.ceil(z[span] - 0.5).astype(np.int64), 0, n)
    k1 = np.clip(np.floor(z[np.flatnonzero(span) + 1] - 0.5).astype(np.int64), -1, n - 1)
    runs = np.maximum(k1 - k0 + 1, 0)
    column = col[span]
    for part in batches(runs, _CHUNK):
        run, k = expand_counts(runs[part])
        c = column[part][run]
        yield np.stack([c // n, c % n, k0[part][run] + k], 1)


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
    estimate (:mod:`rend3r.svo.budget`) exceeds it, and again when the distinct codes the
    surface and fill batches have made pass what the budget holds. ``progress(total,
    label)`` makes the bars of the surface batches and of the fill's slabs.
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
    keys = _KeyBuffer(limit)
    _surface_keys(tri, n, lambda c: morton_encode(c, depth), keys, progress)
    surface = keys.dedupe()
    if surface == 0:
        raise Rend3rError("mesh has no area: every triangle has equal or collinear vertices")
    if solid:
        if budget is not None:
            keys.limit = surface + voxel_limit(budget - SURFACE_BYTES * surface, FILL_BYTES)
        _fill_keys(tri, n, lambda c: morton_encode(c, depth), keys, progress)
    return keys.result(), lo, h
