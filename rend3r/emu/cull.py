"""Conservative culling: which (pixel tile, shape) tests can be skipped without effect.

A shape test is skipped only when it provably cannot change a pixel *as the
working-precision raycaster computes it* (not merely in exact arithmetic); the bounds are
derived in ``docs/emulator.md``, section 7. Off the line: in the shape's normal space the
ray line stays farther than ``sqrt(1 + 24 u (1 + M^2)) + 16 u M (1 + k)`` from the origin,
where ``u`` is the working precision's unit roundoff (with an underflow term), ``M``
bounds |S| in normal space and ``k`` is the condition number of the shape's linear map;
then the computed discriminant is negative. Behind: a shadow ray's shape lies behind its
origin, or a primary ray already has a hit nearer than the shape's depth floor (a lower
bound of any computed hit distance). Only spheres with moderate scales and rotations are
culled; every other shape is tested against every pixel.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import Iterator

import numpy as np

from .arith import Arith
from .shapes import SPHERE, Shapes

TILE = 16  # pixels per tile side
FINE = 8  # side of the finer tiles primary rays are culled in, inside TILE tiles
PAIR_CHUNK = 1 << 16  # pixel-shape pairs per batch: temporaries stay cache-sized

@dataclass(frozen=True)
class Rounding:
    """What the bounds need of the working precision: unit roundoff, smallest normal
    number (the largest absolute error of a flush or an underflow), and whether float16's
    overflow limit applies."""

    u: float
    tiny: float
    fp16: bool

    @classmethod
    def of(cls, ar: Arith) -> "Rounding":
        return cls(ar.unit_roundoff, ar.tiny, ar.precision == "fp16")

_SLACK = 1e-9
#: A finite float16 a2*c2 is below 65520; with the coefficients' rounding error allowed for,
#: |D|^2 (|S|^2 - 1) stays below 16380 * 1.02.
F16_PRODUCT_LIMIT = 16380.0 * 1.02 / (1.0 - 2.0**-6) ** 2


@dataclass(frozen=True)
class Tiles:
    """Active pixels grouped by screen tile."""

    order: np.ndarray  # positions into the active-pixel array, tile by tile
    start: np.ndarray  # per tile: offset into order
    count: np.ndarray  # per tile: number of active pixels
    of_pixel: np.ndarray  # per active pixel (in order): its tile number
    size: int = TILE  # pixels per tile side

    def __len__(self) -> int:
        return len(self.count)


@lru_cache(maxsize=8)
def screen_tiles(pixels: int, width: int, size: int = TILE) -> Tiles:
    """The tiles of a whole frame (they depend on its size only)."""
    tiles = make_tiles(np.arange(pixels), width, size)
    for a in (tiles.order, tiles.start, tiles.count, tiles.of_pixel):
        a.flags.writeable = False
    return tiles


def subset_tiles(screen: Tiles, pixels: np.ndarray) -> Tiles:
    """:func:`make_tiles` of some pixels of a whole frame (distinct flat indices, in
    increasing order), read off the frame's tiles instead of sorted again."""
    position = np.full(len(screen.order), -1, dtype=np.int64)  # of each pixel in ``pixels``
    position[pixels] = np.arange(len(pixels))
    in_order = np.take(position, screen.order)
    inside = in_order >= 0
    order = np.take(in_order, np.flatnonzero(inside))
    count = np.add.reduceat(inside, screen.start, dtype=np.int64)
    count = count[count > 0]
    start = np.concatenate(([0], np.cumsum(count)[:-1]))
    return Tiles(order, start, count, np.repeat(np.arange(len(count)), count), screen.size)


def make_tiles(pixels: np.ndarray, width: int, size: int = TILE) -> Tiles:
    """Group active pixels (flat indices) into size x size screen tiles (empty ones dropped)."""
    tx, ty = (pixels % width) // size, (pixels // width) // size
    key = ty * ((width + size - 1) // size) + tx
    order = np.argsort(key, kind="stable")
    key = key[order]
    uniq, start, count = np.unique(key, return_index=True, return_counts=True)
    return Tiles(order, start, count, np.repeat(np.arange(len(uniq)), count), size)


@lru_cache(maxsize=8)
def screen_children(pixels: int, width: int) -> np.ndarray:
    """(TILE tiles, k): the FINE tiles inside each TILE tile of a whole frame (-1 pads)."""
    coarse, fine = screen_tiles(pixels, width), screen_tiles(pixels, width, FINE)
    tile_of = np.empty(pixels, np.int64)
    tile_of[coarse.order] = coarse.of_pixel
    parent = tile_of[fine.order[fine.start]]  # the coarse tile of each fine tile's first pixel
    order = np.argsort(parent, kind="stable")
    parent = parent[order]
    children = np.full((len(coarse), (TILE // FINE) ** 2), -1, dtype=np.int64)
    children[parent, np.arange(len(parent)) - np.searchsorted(parent, parent)] = order
    children.flags.writeable = False
    return children


@dataclass(frozen=True)
class Bounds:
    """Per shape: centre, the smallest and largest singular value of its map, cullable."""

    center: np.ndarray  # (n, 3) float64
    smin: np.ndarray
    smax: np.ndarray
    cullable: np.ndarray


def shape_bounds(shapes: Shapes) -> Bounds:
    """The world-to-normal-space map is |q|^2 * diag(s) * R^T: singular values |q|^2 |s_i|."""
    with np.errstate(all="ignore"):  # inf * 0 in degenerate shapes: not cullable below
        q2 = sum(np.asarray(c, np.float64) ** 2 for c in shapes.rot)
        s = np.abs(np.stack([np.asarray(c, np.float64) for c in shapes.inv_scale], axis=1))
        center = np.stack([np.asarray(c, np.float64) for c in shapes.loc], axis=1)
        smin, smax = q2 * s.min(axis=1), q2 * s.max(axis=1)
        ok = (shapes.kind == SPHERE) & np.isfinite(center).all(axis=1) & (smin >= 2.0**-6) & (smax <= 2.0**6)
    return Bounds(center, smin, smax, ok)


def cull_radius(b: Bounds, sel: np.ndarray, dist: np.ndarray, dmin: np.ndarray, rnd: Rounding) -> np.ndarray:
    """World radius beyond which no ray line can hit, for shapes ``sel``.

    ``dist`` bounds the distance from ray origins to the centre, ``dmin`` the direction
    lengths (both broadcast against ``sel``). In float16 a finite hit needs a2*c2, about
    4 |D|^2 (|S|^2 - 1), below 65520, which caps the |S| that can still hit.
    """
    with np.errstate(all="ignore"):
        smin, smax = b.smin[sel], b.smax[sel]
        dhat = smin * dmin  # |D| in normal space, at least
        u = rnd.u + rnd.tiny / np.minimum(1.0, dhat * dhat)
        m = smax * dist
        if rnd.fp16:
            m = np.minimum(m, np.sqrt(1.0 + F16_PRODUCT_LIMIT / (dhat * dhat)))
        h = np.sqrt(1.0 + 24.0 * u * (1.0 + m * m)) + 16.0 * u * m * (1.0 + smax / smin)
        r = h / smin * (1.0 + _SLACK) + _SLACK
        return np.where(b.cullable[sel] & (dhat >= 2.0**-4), r, np.inf)


def _unit(v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    n = np.linalg.norm(v, axis=-1)
    with np.errstate(all="ignore"):
        return v / n[..., None], n


def tile_reduce(tiles: Tiles, values: np.ndarray, op: np.ufunc) -> np.ndarray:
    """Reduce per-pixel values (in tile order) to one value per tile."""
    return op.reduceat(values, tiles.start, axis=0)


@dataclass(frozen=True)
class Cones:
    """Per tile, a double cone holding its rays' directions, and their shortest length."""

    axis: np.ndarray  # (tiles, 3) unit axis
    half: np.ndarray  # (tiles,) half-angle
    dmin: np.ndarray  # (tiles, 1) shortest direction


def tile_cones(tiles: Tiles, dirs: np.ndarray) -> Cones:
    """The cones of rays with directions ``dirs`` (per active pixel, in tile order)."""
    unit, length = _unit(dirs)
    axis, _ = _unit(tile_reduce(tiles, unit, np.add))
    cos = np.einsum("ij,ij->i", unit, axis[tiles.of_pixel])
    half = np.arccos(np.clip(tile_reduce(tiles, cos, np.minimum), -1.0, 1.0)) + 1e-7
    half = np.where(np.isfinite(axis).all(axis=1), half, np.pi)
    return Cones(axis, half, tile_reduce(tiles, length, np.minimum)[:, None])


def grid_cones(x: np.ndarray, y: np.ndarray, z: np.ndarray, tiles: Tiles, width: int) -> Cones:
    """:func:`tile_cones` of screen tiles whose directions are the grid (x[column], y[row], z).

    A tile's directions lie in the rectangle spanned by its x and y ranges at height z, so
    the cone through the rectangle's corners holds them all (a cone of half-angle below
    pi/2 is convex), and the rectangle's point nearest the axis bounds their length.
    """
    first = tiles.order[tiles.start]  # each tile's first (top-left) pixel
    z = float(z)
    size = tiles.size

    def span(v: np.ndarray, lo: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        v = np.asarray(v, np.float64)
        blocks = np.pad(v, (0, -len(v) % size), mode="edge").reshape(-1, size)
        return blocks.min(axis=1)[lo // size], blocks.max(axis=1)[lo // size]

    (xlo, xhi), (ylo, yhi) = span(x, first % width), span(y, first // width)
    with np.errstate(all="ignore"):  # a zero or non-finite direction gives NaN: half-angle pi below
        units = []
        for cx, cy in ((cx, cy) for cx in (xlo, xhi) for cy in (ylo, yhi)):
            n = np.sqrt(cx * cx + cy * cy + z * z)
            units.append((cx / n, cy / n, z / n))
        ax, ay, az = (sum(u[k] for u in units) for k in range(3))
        n = np.sqrt(ax * ax + ay * ay + az * az)
        ax, ay, az = ax / n, ay / n, az / n
        cos = np.minimum.reduce([u[0] * ax + u[1] * ay + u[2] * az for u in units])
        half = np.arccos(np.clip(cos, -1.0, 1.0)) + 1e-7
    axis = np.stack([ax, ay, az], axis=1)
    half = np.where(np.isfinite(axis).all(axis=1) & (half < np.pi / 2), half, np.pi)
    nx, ny = np.clip(0.0, xlo, xhi), np.clip(0.0, ylo, yhi)
    return Cones(axis, half, np.sqrt(nx * nx + ny * ny + z * z)[:, None])


def cone_keep(cones: Cones, apex: np.ndarray, origins: Boxes | None,
              b: Bounds, sel: np.ndarray, rnd: Rounding) -> np.ndarray:
    """(tiles, len(sel)) mask: rays through ``apex`` within the tiles' cones may hit.

    ``origins`` bounds the rays' origins per tile (None: the apex itself).
    """
    vunit, vlen = _unit(b.center[sel] - apex)
    if origins is None:  # one bound per shape: the shortest direction of all tiles is the worst case
        r = cull_radius(b, sel, vlen[None, :], cones.dmin.min(), rnd)
    else:
        r = cull_radius(b, sel, origins.reach(b.center[sel]), cones.dmin, rnd)
    return _in_cone(cones.axis @ vunit.T, cones.half[:, None], vlen[None, :], r)


def cone_keep_cells(cones: Cones, tile: np.ndarray, apex: np.ndarray, b: Bounds, shape: np.ndarray,
                    rnd: Rounding) -> np.ndarray:
    """:func:`cone_keep` (rays from the apex) for the cells (tile[i], shape[i]) only."""
    vunit, vlen = _unit(b.center[shape] - apex)
    r = cull_radius(b, shape, vlen, cones.dmin.min(), rnd)
    return _in_cone(np.einsum("ij,ij->i", cones.axis[tile], vunit), cones.half[tile], vlen, r)


def _in_cone(cos_axis: np.ndarray, half: np.ndarray, vlen: np.ndarray, r: np.ndarray) -> np.ndarray:
    """Whether a ball of radius r at distance vlen, at angle acos(cos_axis) from a cone's
    axis, may meet the double cone of half-angle ``half`` (all broadcast)."""
    with np.errstate(all="ignore"):
        spread = np.arcsin(np.clip(r / vlen, 0.0, 1.0)) + 1e-7
    # angle(axis, centre line) <= half + spread, for lines (not half-lines), compared as
    # |cos angle| >= cos(half + spread) = cos(half) cos(spread) - sin(half) sin(spread)
    reach = np.cos(half) * np.cos(spread) - np.sin(half) * np.sin(spread)
    return (np.abs(cos_axis) >= reach) | (half + spread >= np.pi / 2) | (vlen <= r) | ~np.isfinite(r)


def depth_floor(b: Bounds, apex: np.ndarray, dmin: float, dmax: float, rnd: Rounding) -> np.ndarray:
    """Per shape, a lower bound of the computed ``sq_dist`` of any hit by a ray from ``apex``.

    0 where no bound is claimed (shapes that are not cullable spheres, apex inside or near
    the shape). ``dmin`` and ``dmax`` bound the rays' direction lengths. Derivation:
    ``docs/emulator.md`` section 7.
    """
    tiny = rnd.tiny
    with np.errstate(all="ignore"):
        smin, smax = b.smin, b.smax
        dlo = smin * dmin
        uu = rnd.u + tiny / np.minimum(1.0, np.minimum(dlo * dlo, dmin * dmin))
        e = 32.0 * uu * (1.0 + smax / smin)  # transform error, relative (twice section 7's)
        dist = np.linalg.norm(b.center - apex, axis=1)
        s_lo, s_hi = smin * dist * (1.0 - _SLACK) * (1.0 - e), smax * dist * (1.0 + _SLACK) * (1.0 + e)
        # coefficients per unit |D~| (b scales with it, a2 with its square, c2 not at all)
        b_max = 2.0 * s_hi * (1.0 + 4.0 * uu)
        a_lo, a_hi = 2.0 * (1.0 - 4.0 * uu), 2.0 * (1.0 + 4.0 * uu)
        c_lo = 2.0 * (s_lo**2 - 1.0) - 8.0 * uu * (s_hi**2 + 1.0)
        alpha, beta = (1.0 + uu) ** 4, (1.0 - uu) ** 4
        ac = a_lo * c_lo
        d_lo = dlo * (1.0 - e)  # |D~| at least
        b_min = np.sqrt(np.maximum(0.0, ((1.0 - uu) * ac - tiny / d_lo**2) / (1.0 + uu)))  # else disc < 0
        def num(bb):  # B - sqrt(alpha B^2 - beta a c): rises, then falls, with B
            return bb - np.sqrt(np.maximum(0.0, alpha * bb * bb - beta * ac))
        # t~ >= t_unit / |D~|, and |D~| <= smax (1 + e) |d|: t~ >= t_lo / |d|
        t_lo = (1.0 - uu) ** 2 * np.minimum(num(b_min), num(b_max)) / a_hi / (smax * (1.0 + e))
        floor = (1.0 - uu) ** 6 * (1.0 - 4.0 * uu) * t_lo**2 * (1.0 - _SLACK)
        # the actual t is t_lo / |d| at least; 2 sqrt(tiny) keeps t and t*t clear of underflow
        ok = b.cullable & (dlo >= 2.0**-4) & (e < 0.25) & (c_lo > 0) & (b_min > 0) & (t_lo >= 2.0 * np.sqrt(tiny) * dmax)
        return np.where(ok & np.isfinite(floor), floor, 0.0)


@dataclass(frozen=True)
class Boxes:
    """Per tile, the bounding box of some points (e.g. its rays' origins): (tiles, k) arrays.

    Queries take points (n, k) and return (tiles, n) for every tile and point, or (n,)
    when ``tiles`` names one tile per point.
    """

    lo: np.ndarray
    hi: np.ndarray

    def _sides(self, tiles: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
        return (self.lo[:, None], self.hi[:, None]) if tiles is None else (self.lo[tiles], self.hi[tiles])

    def gap2(self, pts: np.ndarray, tiles: np.ndarray | None = None) -> np.ndarray:
        """Squared distance from the points to the boxes (0 inside)."""
        lo, hi = self._sides(tiles)
        total = 0.0
        for k in range(pts.shape[1]):
            g = np.maximum(lo[..., k] - pts[..., k], pts[..., k] - hi[..., k])
            np.maximum(g, 0.0, out=g)
            total = total + g * g
        return total

    def reach(self, pts: np.ndarray, tiles: np.ndarray | None = None) -> np.ndarray:
        """An upper bound of the distance from the points to any point of the boxes."""
        lo, hi = self._sides(tiles)
        mid, half = (lo + hi) / 2, np.linalg.norm(hi - lo, axis=-1) / 2
        total = 0.0
        for k in range(pts.shape[1]):
            g = pts[..., k] - mid[..., k]
            total = total + g * g
        return np.sqrt(total) * (1.0 + _SLACK) + half


def tile_boxes(tiles: Tiles, points: np.ndarray) -> Boxes:
    """The boxes of ``points`` (per active pixel, in tile order) over each tile."""
    return Boxes(tile_reduce(tiles, points, np.minimum), tile_reduce(tiles, points, np.maximum))


@dataclass(frozen=True)
class ParallelRays:
    """Rays sharing one direction, from per-pixel origins, summarised per tile."""

    unit: np.ndarray  # the direction, normalised
    length: float  # |direction|
    basis: np.ndarray  # (3, 2): the plane normal to the direction
    plane: Boxes  # origins projected onto that plane
    space: Boxes  # origins
    lead: np.ndarray  # (tiles,) min of origin . unit


def parallel_rays(tiles: Tiles, direction: np.ndarray, origins: np.ndarray) -> ParallelRays:
    """Summarise rays along ``direction`` from ``origins`` (per active pixel, tile order)."""
    d, dlen = _unit(direction)
    e1 = np.cross(d, [1.0, 0.0, 0.0] if abs(d[0]) < 0.9 else [0.0, 1.0, 0.0])
    e1 /= np.linalg.norm(e1)
    basis = np.stack([e1, np.cross(d, e1)], axis=1)
    return ParallelRays(d, float(dlen), basis, tile_boxes(tiles, origins @ basis), tile_boxes(tiles, origins),
                        tile_reduce(tiles, origins @ d, np.minimum))


def parallel_keep(rays: ParallelRays, b: Bounds, sel: np.ndarray, rnd: Rounding) -> np.ndarray:
    """(tiles, len(sel)) mask: the tiles' parallel rays (t > 0) may hit the shapes.

    A shape is skipped when it is off every ray line (as in :func:`cone_keep`), or when it
    lies behind every origin: then the computed b = 2 D.S is positive and c2 too, so
    ``sqrt(b*b - a2*c2) <= b`` (sqrt(fl(b*b)) = |b| in round-to-nearest) and neither root
    is positive. First every tile is tested with one radius per shape (from a distance
    bound over all origins), then the remaining pairs with their tile's own bounds; each
    test alone is sound, so skipping on either is.
    """
    centers = b.center[sel]
    flat = centers @ rays.basis
    dlen = np.array([[rays.length]])
    whole = Boxes(rays.space.lo.min(axis=0, keepdims=True), rays.space.hi.max(axis=0, keepdims=True))
    with np.errstate(all="ignore"):
        r = cull_radius(b, sel, whole.reach(centers), dlen, rnd)
        keep = (rays.plane.gap2(flat) <= r * r) | ~np.isfinite(r)
        ti, si = np.nonzero(keep)
        shape = sel[si]
        dist = rays.space.reach(centers[si], ti)
        r = cull_radius(b, shape, dist, rays.length, rnd)
        near = (rays.plane.gap2(flat[si], ti) <= r * r) | ~np.isfinite(r)
        # behind: min over the tile of (origin - centre).d, and the nearest origin's distance
        ahead = rays.lead[ti] - centers[si] @ rays.unit
        smin, smax = b.smin[shape], b.smax[shape]
        u = rnd.u + rnd.tiny / np.minimum(1.0, (smin * rays.length) ** 2)
        mean2, spread2 = (smax**2 + smin**2) / 2, (smax**2 - smin**2) / 2
        ds_low = rays.length * (mean2 * ahead - (spread2 + 64.0 * u * smax**2) * dist)  # computed D.S stays above
        behind = (ds_low > 2.0**-6) & (rays.space.gap2(centers[si], ti) > r * r) & np.isfinite(r)
    drop = ~near | behind
    keep[ti[drop], si[drop]] = False
    return keep


def pairs(tiles: Tiles, keep: np.ndarray, sel: np.ndarray,
          distinct: bool = False) -> Iterator[tuple[np.ndarray, np.ndarray]]:
    """(active position, shape position) pairs of the kept (tile, shape) cells, in batches.

    ``distinct``: no batch holds a position twice. Cells then go by rank within their
    tile (each tile's first cell, then each tile's second cell, ...) and batches do not
    mix ranks; otherwise they go tile by tile.
    """
    ti, si = np.nonzero(keep)
    if not len(ti):
        return
    bounds = np.array([len(ti)])
    if distinct:
        idx = np.arange(len(ti))
        rank = idx - np.maximum.accumulate(np.where(np.r_[True, ti[1:] != ti[:-1]], idx, 0))
        order = np.argsort(rank, kind="stable")
        ti, si, rank = ti[order], si[order], rank[order]
        bounds = np.r_[np.flatnonzero(rank[1:] != rank[:-1]) + 1, len(ti)]
    counts = tiles.count[ti]
    ends = np.cumsum(counts)
    lo = 0
    while lo < len(ti):
        stop = int(bounds[np.searchsorted(bounds, lo, side="right")])
        hi = int(np.searchsorted(ends, (ends[lo - 1] if lo else 0) + PAIR_CHUNK, side="right"))
        hi = min(max(hi, lo + 1), stop)
        c = counts[lo:hi]
        cells, shapes = ti[lo:hi], si[lo:hi]
        if (np.diff(cells) == 1).all():  # consecutive tiles: their positions are one run
            begin = int(tiles.start[cells[0]])
            pos = tiles.order[begin:begin + int(c.sum())]
        else:
            first = np.repeat(tiles.start[cells] - np.concatenate(([0], np.cumsum(c)[:-1])), c)
            pos = tiles.order[first + np.arange(int(c.sum()))]
        if (shapes == shapes[0]).all():  # one shape: a read-only broadcast, not a copy
            yield pos, np.broadcast_to(sel[shapes[0]], pos.shape)
        else:
            yield pos, np.repeat(sel[shapes], c)
        lo = hi


def shape_blocks(n: int, tiles: int, order: np.ndarray | None = None) -> Iterator[np.ndarray]:
    """Shape positions (in ``order`` if given) in blocks that keep a (tiles, block) matrix
    modest, and that are small enough for depth culling to act between blocks."""
    step = max(1, min((1 << 21) // max(1, tiles), max(256, -(-n // 16))))
    for lo in range(0, n, step):
        yield np.arange(lo, min(n, lo + step)) if order is None else order[lo:lo + step]
