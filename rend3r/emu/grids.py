"""Ray-space grids: which shapes each ray must test, found in O(1) per ray.

A bundle of rays either passes through one apex (primary rays through the camera; point
light shadow rays, up to rounding, through the light) or is parallel (directional shadow
rays). Each ray's *line* gets 2D coordinates (u, v):

- perspective (apex A): the axis k of the direction's largest component picks one of
  three faces, and (u, v) are the other two components over it (the same for d and -d,
  so lines, not half-lines, as the cull radius is a statement about lines);
- parallel (direction l): the ray's origin projected on two unit vectors normal to l.

Over the rays' (u, v) bounding box per face lies a regular grid of about
:data:`RAYS_PER_CELL` rays per cell. A shape with cull radius R (``docs/emulator.md`` 7.1)
can only be hit by lines passing within R of its centre; their (u, v) lie in a box
computed exactly (ratios of the intervals of the ball's bounding cube seen from the apex,
extreme at corners; for a parallel bundle the centre's projection plus or minus R),
widened for float64 rounding, and the shape is listed in every cell that box touches.
Shapes without a finite radius, and the largest footprints when the lists would exceed
their budget, go to one global list every ray tests. Lists keep the order given (front to
back for primary rays, so a ray can stop at the first shape behind its nearest hit).

A ray whose (u, v) falls outside the grid (only a ray the grid was not built from) or is
not finite has cell -1 and tests every shape. The kernels are in ``csrc/grids.h`` and
``csrc/kernels.c``.
"""

from __future__ import annotations

import math
from ctypes import byref
from dataclasses import dataclass, replace

import numpy as np

from . import native, threads

RAYS_PER_CELL = 8
#: Entries the cell lists may hold: this many per cell, within [MIN_BUDGET, MAX_BUDGET].
ENTRIES_PER_CELL, MIN_BUDGET, MAX_BUDGET = 32, 1 << 22, 1 << 26
MAX_CELLS_PER_AXIS = 4096
#: A pixel grid's lists hold at most this many entries per pixel, else its blocks grow (up
#: to MAX_BLOCK columns x rows): deep scenes list every shape behind a pixel.
PIXEL_ENTRIES, MAX_BLOCK = 2, (64, 16)
#: Per face: u0, u1, v0, v1, rays, shortest and longest direction (as the kernels fill it).
#: Entries of the cell lists (work of filling or reaching them), and shapes, a thread
#: takes at least.
CELL_CHUNK, SHAPE_CHUNK = 1 << 14, 1 << 9
EMPTY_BOXES = np.tile(np.array([np.inf, -np.inf, np.inf, -np.inf, 0.0, np.inf, -np.inf]), (3, 1))


@dataclass(frozen=True)
class PixelLayout:
    """Cells of a grid camera: blocks of ``block`` columns by ``block_rows`` rows. ``u``
    holds each column's u = x/z and ``v`` each row's v = y/z (both monotonic), as the rays'
    lines have them on face 2."""

    u: np.ndarray
    v: np.ndarray
    block: int = 8
    block_rows: int = 1

    @classmethod
    def of(cls, u: np.ndarray, v: np.ndarray) -> "PixelLayout | None":
        """The layout, or None when u or v is not finite and monotonic."""
        for a in (u, v):
            if not (np.isfinite(a).all() and ((np.diff(a) >= 0).all() or (np.diff(a) <= 0).all())):
                return None
        return cls(u, v)

    @property
    def pixels(self) -> int:
        return len(self.u) * len(self.v)

    def coarser(self) -> "PixelLayout":
        """Blocks twice as large: wider first, then taller, up to MAX_BLOCK."""
        if self.block <= self.block_rows * 4 and self.block < MAX_BLOCK[0]:
            return replace(self, block=self.block * 2)
        return replace(self, block_rows=min(self.block_rows * 2, MAX_BLOCK[1]))

    @staticmethod
    def oriented(a: np.ndarray) -> tuple[np.ndarray, float]:
        """(sign * a ascending, sign)."""
        sign = 1.0 if len(a) < 2 or a[-1] >= a[0] else -1.0
        return np.ascontiguousarray(sign * a), sign


@dataclass(frozen=True)
class Grid:
    """A built grid: per-face tables, CSR cell lists, the global list, and for a grid
    camera its pixel layout."""

    faces: np.ndarray  # (3, GF_COLUMNS) float64
    shape: np.ndarray  # (3, GS_COLUMNS) int64
    start: np.ndarray  # (cells + 1,) int64
    entries: np.ndarray  # int32 shape positions
    glob: np.ndarray  # int32 shape positions every ray tests
    layout: tuple | None = None  # a pixel grid's (u_at, u_sign, v_at, v_sign, block, block_rows)
    reach: np.ndarray | None = None  # float32 cones at every fourth entry: see csrc/kernels.h Grid.reach

    def struct(self) -> native.Grid:
        """The kernels' view (the arrays must outlive it)."""
        view = native.Grid(
            native.ptr(self.faces, np.float64, (3, native.GF_COLUMNS)),
            native.ptr(self.shape, np.int64, (3, native.GS_COLUMNS)), native.ptr(self.start, np.int64, (None,)),
            len(self.start), native.ptr(self.entries, np.int32, (None,)), native.ptr(self.glob, np.int32, (None,)),
            len(self.glob))
        if self.layout is not None:
            u_at, view.u_sign, v_at, view.v_sign, view.block, view.block_rows = self.layout
            view.u_at, view.v_at = native.ptr(u_at, np.float64, (None,)), native.ptr(v_at, np.float64, (None,))
            view.n_u, view.n_v = len(u_at), len(v_at)
        if self.reach is not None:
            view.reach = native.ptr(self.reach, np.float32, (-(-len(self.entries) // 4) * 4,))
        return view

    @property
    def cells(self) -> int:
        return len(self.start) - 1


#: The grid of no rays: every lookup gives cell -1.
EMPTY = Grid(np.zeros((3, native.GF_COLUMNS)), np.zeros((3, native.GS_COLUMNS), np.int64), np.zeros(1, np.int64),
             np.zeros(0, np.int32), np.zeros(0, np.int32))


def merge_boxes(boxes: np.ndarray) -> np.ndarray:
    """Face boxes (k, 3, BOX_COLUMNS) of several chunks of rays merged into one (3, BOX_COLUMNS)."""
    out = EMPTY_BOXES.copy()
    for col, op in ((0, np.min), (1, np.max), (2, np.min), (3, np.max), (4, np.sum), (5, np.min), (6, np.max)):
        out[:, col] = op(boxes[:, :, col], axis=0)
    return out


def _layout(boxes: np.ndarray, cells: float) -> tuple[np.ndarray, np.ndarray]:
    """Face tables for about ``cells`` cells over the faces' boxes, shared by ray counts."""
    faces = np.zeros((3, native.GF_COLUMNS))
    shape = np.zeros((3, native.GS_COLUMNS), np.int64)
    rays = boxes[:, 4]
    first = 0
    for k in np.flatnonzero(rays > 0):
        u0, u1, v0, v1 = boxes[k, :4]
        n = max(1.0, cells * rays[k] / rays.sum())
        wu, wv = u1 - u0, v1 - v0
        if wu > 0 and wv > 0:
            nu = max(1, round(math.sqrt(n * wu / wv)))
            nv = max(1, math.ceil(n / nu))
        else:
            nu, nv = (max(1, round(n)), 1) if wu > 0 else (1, max(1, round(n)) if wv > 0 else 1)
        nu, nv = min(nu, MAX_CELLS_PER_AXIS), min(nv, MAX_CELLS_PER_AXIS)
        faces[k] = (u0, u1, v0, v1, nu / wu if wu > 0 else 0.0, nv / wv if wv > 0 else 0.0)
        shape[k] = (nu, nv, first)
        first += nu * nv
    return faces, shape


def _pixel_faces(pixels: PixelLayout) -> tuple[np.ndarray, np.ndarray, tuple]:
    """Face tables and the kernels' layout tuple of a grid camera's pixel grid (face 2)."""
    faces = np.zeros((3, native.GF_COLUMNS))
    shape = np.zeros((3, native.GS_COLUMNS), np.int64)
    faces[2, :4] = pixels.u.min(), pixels.u.max(), pixels.v.min(), pixels.v.max()
    shape[2] = (-(-len(pixels.u) // pixels.block), -(-len(pixels.v) // pixels.block_rows), 0)
    u_at, u_sign = PixelLayout.oriented(pixels.u)
    v_at, v_sign = PixelLayout.oriented(pixels.v)
    return faces, shape, (u_at, u_sign, v_at, v_sign, pixels.block, pixels.block_rows)


def _sizes(rects: np.ndarray) -> np.ndarray:
    """Per shape, the cells of its rectangles (n x 3 x 4); -1 for a shape without a radius."""
    w = np.maximum(rects[:, :, 1] - rects[:, :, 0] + 1, 0)
    h = np.maximum(rects[:, :, 3] - rects[:, :, 2] + 1, 0)
    sizes = (w * h).sum(axis=1)
    sizes[rects[:, 0, 0] < 0] = -1
    return sizes


def _footprints(faces: np.ndarray, shape: np.ndarray, layout: tuple | None, parallel: bool, centers: np.ndarray,
                radii: np.ndarray, rects: np.ndarray, jobs: int) -> None:
    """Fill ``rects`` (n, 3, 4) with each shape's cell rectangle per face on a grid of
    these face tables (csrc/kernels.c grid_footprints), shapes split over ``jobs`` threads."""
    empty = Grid(faces, shape, np.zeros(1, np.int64), np.zeros(0, np.int32), np.zeros(0, np.int32), layout)
    view, lib = empty.struct(), native.library()
    threads.split(jobs, threads.ranges(len(radii), jobs, SHAPE_CHUNK), lambda a, b: lib.grid_footprints(
        byref(view), int(parallel), centers[a:].ctypes.data, radii[a:].ctypes.data, b - a, rects[a:].ctypes.data))


def _blocks(pixels: PixelLayout, px: np.ndarray) -> PixelLayout:
    """The finest blocks, from ``pixels``' own through PixelLayout.coarser's to MAX_BLOCK,
    whose lists hold the shapes' pixel rectangles ``px`` (n, 4: c0, c1, r0, r1) in at most
    PIXEL_ENTRIES entries per pixel; else the coarsest. Blocks double, so a rectangle's
    block count never grows as they coarsen, and a binary search finds them."""
    layouts = [pixels]
    while (layouts[-1].block, layouts[-1].block_rows) != MAX_BLOCK:
        layouts.append(layouts[-1].coarser())
    c0, c1, r0, r1 = px.T.astype(np.int32)  # pixel indices: at most 8192

    def fits(p: PixelLayout) -> bool:
        u, v = p.block.bit_length() - 1, p.block_rows.bit_length() - 1  # powers of two
        counts = ((c1 >> u) - (c0 >> u) + 1) * ((r1 >> v) - (r0 >> v) + 1)
        return int(counts.sum(dtype=np.int64)) <= PIXEL_ENTRIES * p.pixels

    lo, hi = 0, len(layouts) - 1
    while lo < hi:
        mid = (lo + hi) // 2
        lo, hi = (lo, mid) if fits(layouts[mid]) else (mid + 1, hi)
    return layouts[lo]


def _fill(rects: np.ndarray, shape: np.ndarray, order: np.ndarray, listed: np.ndarray, sizes: np.ndarray,
          cells: int, jobs: int) -> tuple[np.ndarray, np.ndarray]:
    """The cell lists (start, entries) of the ``listed`` shapes in ``order`` (``sizes``:
    each shape's cells): each thread counts, then writes, a range of ``order`` at the
    places the earlier ranges leave it, so the lists are the same for any split
    (csrc/kernels.c grid_fill)."""
    lib, flags = native.library(), listed.astype(np.uint8)
    work = np.zeros(len(order) + 1, np.int64)
    np.cumsum(np.where(listed, sizes, 0)[order] + 1, out=work[1:])
    parts = threads.balanced(work, jobs, CELL_CHUNK)
    counts = np.zeros((len(parts), cells), np.int64)

    def run(pos: np.ndarray, entries: np.ndarray | None) -> None:
        threads.each(jobs, [lambda t=t, a=a, b=b: lib.grid_fill(
            rects.ctypes.data, shape.ctypes.data, order[a:].ctypes.data, b - a, flags.ctypes.data, pos[t].ctypes.data,
            None if entries is None else entries.ctypes.data, int(entries is not None))
            for t, (a, b) in enumerate(parts)])

    run(counts, None)
    start = np.zeros(cells + 1, np.int64)
    np.cumsum(counts.sum(axis=0), out=start[1:])
    pos = start[:-1] + np.cumsum(counts, axis=0) - counts  # where each range's entries of a cell begin
    entries = np.empty(int(start[-1]), np.int32)
    run(pos, entries)
    return start, entries


def build(boxes: np.ndarray, parallel: bool, centers: np.ndarray, radii: np.ndarray, order: np.ndarray,
          pixels: PixelLayout | None = None, rays_per_cell: int = RAYS_PER_CELL, reach: bool = False,
          jobs: int = 1) -> Grid:
    """A grid over the rays' per-face ``boxes`` ((3, BOX_COLUMNS): u0, u1, v0, v1, rays, ...;
    no rays: an unused face) listing shapes: ``centers`` (n, 3) relative to the apex, or
    projected (u, v, 0) for a parallel bundle, cull ``radii``, listed in ``order``. With
    ``pixels`` (a grid camera), the cells are blocks of its pixels; else about
    ``rays_per_cell`` rays share a cell. The lists may hold a few entries per ray: coarser
    cells when they would hold more, then the largest footprints go to the global list.
    With ``reach`` (a perspective bundle), every fourth entry gets the cone of lines the
    rest of its list may hit. ``jobs`` threads share the per-cell work."""
    n = len(radii)
    centers = np.ascontiguousarray(centers, np.float64)
    radii = np.ascontiguousarray(radii, np.float64)
    order = np.ascontiguousarray(order, np.int32)
    if len(order) != n or (n and not (0 <= order.min() and order.max() < n)) or centers.shape != (n, 3):
        raise ValueError("grid: order must be a permutation of the shapes, centers (n, 3)")
    lib = native.library()
    rects = np.empty((n, 3, 4), np.int64)
    if pixels is not None:  # pixel rectangles once; blocks by integer division
        one = replace(pixels, block=1, block_rows=1)
        faces, shape, layout = _pixel_faces(one)
        _footprints(faces, shape, layout, False, centers, radii, rects, jobs)
        px, none = rects[:, 2].copy(), rects[:, 2, 0] > rects[:, 2, 1]
        pixels = _blocks(pixels, px[(rects[:, 0, 0] >= 0) & ~none])
        rects[:, 2] = px // [pixels.block, pixels.block, pixels.block_rows, pixels.block_rows]
        rects[none, 2] = (1, 0, 0, 0)
        sizes = _sizes(rects)
        total = int(sizes[sizes >= 0].sum())
        faces, shape, layout = _pixel_faces(pixels)
        budget = MAX_BUDGET
    else:
        cells = max(1.0, float(boxes[:, 4].sum()) / rays_per_cell)
        while True:
            faces, shape = _layout(boxes, cells)
            _footprints(faces, shape, None, parallel, centers, radii, rects, jobs)
            sizes = _sizes(rects)
            total = int(sizes[sizes >= 0].sum())
            budget = min(MAX_BUDGET, max(MIN_BUDGET, ENTRIES_PER_CELL * int((shape[:, 0] * shape[:, 1]).sum())))
            if total <= budget or cells <= 1.0:
                break
            cells /= 4.0  # coarser cells: footprints shrink about as much
        layout = None
    listed = sizes >= 0
    if total > budget:  # the largest footprints go to the global list
        big = np.argsort(-sizes, kind="stable")[: int(listed.sum())]
        left = total - np.cumsum(sizes[big])
        listed[big[: int(np.searchsorted(-left, -budget)) + 1]] = False
    n_cells = int((shape[:, 0] * shape[:, 1]).sum())
    start, entries = _fill(rects, shape, order, listed, sizes, n_cells, jobs)
    cones = None
    if reach and not parallel:  # the lines the rest of each list may hit, for packets to stop early
        cones = np.empty(-(-len(entries) // 4) * 4, np.float32)
        balls = np.empty((n, native.CONE_COLUMNS))
        lib.cone_balls(centers.ctypes.data, radii.ctypes.data, n, balls.ctypes.data)
        threads.split(jobs, threads.balanced(start + np.arange(n_cells + 1), jobs, CELL_CHUNK),
                      lambda a, b: lib.cone_reach(balls.ctypes.data, start.ctypes.data, a, b, entries.ctypes.data,
                                                  cones.ctypes.data))
    return Grid(faces, shape, start, entries, order[~listed[order]], layout, cones)
