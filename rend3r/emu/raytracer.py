"""The raytracer: nearest hit per pixel, diffuse lighting, shadow rays, NaN accounting.

Work is done on (pixel, shape) pairs in batches; :mod:`.cull` drops pairs that provably
cannot change a pixel. Colour arithmetic (after the float16 datapath): see
``docs/emulator.md``.
"""

from __future__ import annotations

from dataclasses import dataclass
from time import perf_counter
from typing import Callable, Iterator

import numpy as np

from .arith import Arith
from .camera import Rays, camera_rays
from .cull import (FINE, PAIR_CHUNK, Bounds, Rounding, Tiles, cone_keep, cone_keep_cells, depth_floor, grid_cones, pairs,
                   parallel_keep, parallel_rays, screen_children, screen_tiles, shape_blocks, shape_bounds, subset_tiles,
                   tile_boxes, tile_cones, tile_reduce)
from .frame import Frame
from .lighting import Recorder, diffuse
from .lights import POINT, Light, lights_from_scene
from .options import EmuOptions
from .scene import Scene
from .shapes import (Form, Shapes, direction_term, origin_term, shapes_from_scene, solve, squared_distance, surface,
                     to_object, transform_classes, uniform_form)
from .stats import FrameStats
from .vec import Vec, dot

Progress = Callable[[float], None]
_NONE = np.iinfo(np.int64).max


def _f64(v: Vec) -> np.ndarray:
    """(n, 3) float64 view of a vector for culling geometry."""
    return np.stack(np.broadcast_arrays(*[np.atleast_1d(np.asarray(c, np.float64)) for c in v]), axis=-1)


def _f64_rows(v: Vec, idx: np.ndarray) -> np.ndarray:
    """(len(idx), 3) float64 rows of a vector's entries ``idx`` (components may be scalars)."""
    out = np.empty((len(idx), 3))
    for k, c in enumerate(v):
        out[:, k] = np.take(c, idx) if np.ndim(c) else c
    return out


def _take(v: Vec, idx: np.ndarray) -> Vec:
    return tuple(c[idx] if np.ndim(c) else c for c in v)


def _rows(idx: np.ndarray) -> np.ndarray | slice:
    """Sorted, distinct indices as a slice when they form one run (views, not gathers)."""
    if len(idx) and idx[-1] - idx[0] + 1 == len(idx):
        return slice(int(idx[0]), int(idx[-1]) + 1)
    return idx


def _one(slots: np.ndarray) -> np.ndarray | int:
    """Shape positions, or the one position when all are the same (its values then enter
    as scalars, which broadcast)."""
    if len(slots) and (slots.strides == (0,) or (slots == slots[0]).all()):
        return int(slots[0])
    return slots


def _pick(mask: np.ndarray, *arrays: np.ndarray) -> tuple[np.ndarray, ...]:
    """Each array's entries where ``mask`` holds: one index pass, then gathers (boolean
    indexing is several times slower on irregular masks). A broadcast of one value stays
    a broadcast."""
    idx = np.flatnonzero(mask)
    return tuple(np.broadcast_to(a[0], idx.shape) if a.strides == (0,) and len(a) else np.take(a, idx)
                 for a in arrays)


class _Nearest:
    """Running nearest hit per pixel: smallest squared distance, ties to the lower index."""

    def __init__(self, n: int, dtype: type) -> None:
        self.sqd = np.full(n, np.inf, dtype=dtype)
        self.slot = np.full(n, _NONE, dtype=np.int64)
        self.t = np.full(n, np.nan, dtype=dtype)  # the winner's t
        self.any = False  # whether any hit was merged

    def update(self, pix: np.ndarray, slot: np.ndarray, sqd: np.ndarray, t: np.ndarray | None = None,
               distinct: bool = False, hit: np.ndarray | None = None) -> None:
        """Merge the pairs (those where ``hit`` holds, if given) as hits.

        ``distinct``: no pixel occurs twice in ``pix``, which allows a cheaper merge.
        """
        extra = () if t is None else (t,)
        if distinct:
            if not self.any:  # every hit beats no hit
                better = np.ones(len(pix), bool) if hit is None else hit
            else:
                now = np.take(self.sqd, pix)
                better = (sqd < now) | ((sqd == now) & (slot < np.take(self.slot, pix)))
                if hit is not None:
                    better &= hit
            won, sqd, slot, *extra = _pick(better, pix, sqd, slot, *extra)
            self.sqd[won], self.slot[won] = sqd, slot
            if t is not None:
                self.t[won] = extra[0]
            self.any |= len(won) > 0
            return
        if hit is not None:
            pix, slot, sqd, *extra = _pick(hit, pix, slot, sqd, *extra)
        self.any |= len(pix) > 0
        before = np.take(self.sqd, pix)
        np.minimum.at(self.sqd, pix, sqd)
        now = np.take(self.sqd, pix)
        self.slot[_pick(now < before, pix)[0]] = _NONE
        tie = sqd == now
        np.minimum.at(self.slot, *_pick(tie, pix, slot))
        if t is not None:
            won = tie & (np.take(self.slot, pix) == slot)
            won_pix, won_t = _pick(won, pix, extra[0])
            self.t[won_pix] = won_t


def render_frame(
    scene: Scene, options: EmuOptions, number: int = 0, progress: Progress | None = None
) -> tuple[Frame, FrameStats]:
    """Render the scene as the raytracer sees it; returns the frame and its stats."""
    start = perf_counter()
    ar = options.arith
    w, h, n_pix = options.width, options.height, options.pixels
    rays = camera_rays(scene, options, ar)
    shapes = shapes_from_scene(scene, ar)
    lights = lights_from_scene(scene, ar, options.light_model)
    st = FrameStats(number=number, pixels=n_pix, shapes=len(shapes), lights=len(lights), rays=n_pix)
    rgb = np.full(n_pix, options.background, dtype=np.uint16)
    depth = np.full(n_pix, np.inf, dtype=np.float32)
    prov = np.full(n_pix, -1, dtype=np.int32)
    nan_pixel = np.zeros(n_pix, dtype=bool)
    if len(shapes):
        bounds = shape_bounds(shapes)
        dd = _squared_lengths(ar, rays)
        near, tables, S_shape = _primary(ar, options, rays, dd, shapes, bounds, st, nan_pixel, progress)
        hp = np.flatnonzero(near.slot != _NONE)
        slot = near.slot[hp]

        def hit_surface(job):
            lo, hi = job
            px, sl = _rows(hp[lo:hi]), _one(slot[lo:hi])
            D = tuple(c[px] for c in rays.direction)
            if not lights:  # unlit: whether the point is finite is all that matters
                point, _ = surface(ar, None, None, None, near.t[px], rays.origin, D, normals=False)
                return np.isfinite(point[0]) & np.isfinite(point[1]) & np.isfinite(point[2])
            if tables is None:
                s = shapes.take(sl)
                _, Dh = to_object(ar, s, None, D)
            else:  # one transform class: its parameters broadcast, nothing to gather per hit
                s = shapes.take(int(tables.first[0]) if tables.single else sl)
                Dh, _ = tables.read(sl, px)
            return surface(ar, s, _take(S_shape, sl), Dh, near.t[px], rays.origin, D)

        parts = [hit_surface((lo, lo + PAIR_CHUNK)) for lo in range(0, len(hp), PAIR_CHUNK)]
        if lights:
            empty = (np.zeros(0, ar.dtype),) * 3
            point, normal = (tuple(np.concatenate([p[k][a] for p in parts]) if parts else empty[a] for a in range(3))
                             for k in range(2))
            color, bad = shade_hits(ar, options, shapes, bounds, lights, hp, slot, point, normal, st, nan_pixel)
        else:  # unlit: the shape's colour where the hit point is finite
            color, bad = shapes.color[slot], ~np.concatenate(parts) if parts else np.zeros(0, bool)
        if bad.any():
            nan_pixel[hp[bad]] = True
            hp, slot, color = hp[~bad], slot[~bad], color[~bad]
        st.hits = len(hp)
        hp = _rows(hp)
        rgb[hp] = color
        prov[hp] = shapes.index[slot]
        np.copyto(depth, np.sqrt(near.sqd, dtype=np.float64), where=prov >= 0)
    st.nan_rays = int(nan_pixel.sum())
    st.seconds = perf_counter() - start
    frame = Frame(number, rgb.reshape(h, w), depth.reshape(h, w), prov.reshape(h, w))
    return frame, st


#: Per-class direction tables are built when classes * pixels stays below this.
_CLASS_TABLE_LIMIT = 1 << 23


@dataclass(frozen=True)
class _DirectionTables:
    """Normal-space directions (x, y, z) and a2 per (transform class, pixel)."""

    first: np.ndarray  # a representative shape of each class
    cls: np.ndarray  # class of each shape
    single: bool  # one class: rows are pixels
    n: int  # pixels
    columns: list[np.ndarray]

    def read(self, slot: np.ndarray, pix: np.ndarray | slice) -> tuple[Vec, np.ndarray]:
        if self.single:
            row = pix
        else:
            row = self.cls[slot] * self.n + (np.arange(pix.start, pix.stop) if isinstance(pix, slice) else pix)
        c = self.columns
        return (c[0][row], c[1][row], c[2][row]), c[3][row]


def _direction_tables(ar: Arith, shapes: Shapes, rays: Rays) -> _DirectionTables | None:
    """The direction tables, or None when classes * pixels is too large.

    A pair then reads its class's row instead of repeating the rotation: bit-identical,
    since it is the same sequence of operations on the same values.
    """
    first, cls = transform_classes(shapes)
    n = len(rays.direction[0])
    if len(first) * n > _CLASS_TABLE_LIMIT:
        return None
    columns = [np.empty(len(first) * n, ar.dtype) for _ in range(4)]
    for k, rep in enumerate(first):
        s = shapes.take(int(rep))  # scalars: they broadcast cheaper than one-element arrays
        for lo, hi, shape, d in _direction_chunks(rays):
            _, Dh = to_object(ar, s, None, d)
            for column, value in zip(columns, (*Dh, direction_term(ar, s, Dh))):
                column[k * n + lo:k * n + hi].reshape(shape)[...] = value
    return _DirectionTables(first, cls, len(first) == 1, n, columns)


def _longest(rays: Rays) -> float:
    """An upper bound of the primary directions' lengths."""
    if rays.grid is not None:
        x, y, z = (np.abs(np.asarray(c, np.float64)).max(initial=0.0) for c in rays.grid)
        return float(np.sqrt(x * x + y * y + z * z)) * (1 + 1e-9)
    d = _f64(rays.direction)
    return float(np.sqrt(np.einsum("ij,ij->i", d, d).max(initial=0.0))) * (1 + 1e-9)


def _squared_lengths(ar: Arith, rays: Rays) -> np.ndarray:
    """|d|^2 of every primary ray (from a grid camera, products once per column and row)."""
    if rays.grid is None:
        return dot(ar, rays.direction, rays.direction)
    x, y, z = rays.grid
    d = (x[None, :], y[:, None], z)
    return np.broadcast_to(dot(ar, d, d), (len(y), len(x))).ravel()


def _direction_chunks(rays: Rays) -> Iterator[tuple[int, int, tuple[int, ...], Vec]]:
    """The primary directions in cache-sized pieces: (first pixel, end, shape, directions).

    From a grid camera the pieces are rows, with directions as (1, w), (rows, 1) and 0-d
    arrays: products of one coordinate are then computed once per column or row, and only
    the sums that mix them per pixel (the same operations on the same values).
    """
    n = len(rays.direction[0])
    if rays.grid is None:
        for lo in range(0, n, PAIR_CHUNK):
            hi = min(n, lo + PAIR_CHUNK)
            yield lo, hi, (hi - lo,), tuple(c[lo:hi] for c in rays.direction)
        return
    x, y, z = rays.grid
    w = len(x)
    step = max(1, PAIR_CHUNK // w)
    for r in range(0, len(y), step):
        rows = y[r:r + step]
        yield r * w, (r + len(rows)) * w, (len(rows), w), (x[None, :], rows[:, None], z)


def _primary(ar: Arith, options: EmuOptions, rays, dd, shapes: Shapes, bounds: Bounds,
             st: FrameStats, nan_pixel: np.ndarray, progress: Progress | None):
    """Nearest hit of every primary ray; origin terms are per shape, direction terms per
    transform class and pixel. Returns the nearest hits, the direction tables (or None)
    and the per-shape normal-space origins."""
    n_pix = options.pixels
    near = _Nearest(n_pix, ar.dtype)
    S_shape, _ = to_object(ar, shapes, rays.origin, None)
    c2_shape = origin_term(ar, shapes, S_shape)
    tables = _direction_tables(ar, shapes, rays)
    form = uniform_form(shapes)
    coarse, tiles = screen_tiles(n_pix, options.width), screen_tiles(n_pix, options.width, FINE)
    rnd = Rounding.of(ar)
    apex = _f64(rays.origin)[0]
    floor = order = None
    if options.cull:  # cones of the coarse tiles, then of the fine tiles inside the kept ones
        children = screen_children(n_pix, options.width)
        if rays.grid is not None:
            cones, fine_cones = (grid_cones(*rays.grid, t, options.width) for t in (coarse, tiles))
        else:
            cones, fine_cones = (tile_cones(t, _f64_rows(rays.direction, t.order)) for t in (coarse, tiles))
        floor = depth_floor(bounds, apex, float(cones.dmin.min()), _longest(rays), rnd)
        order = np.argsort(floor, kind="stable")  # front to back: near hits then skip far shapes
    blocks = list(shape_blocks(len(shapes), len(coarse), order))
    def test(batch, reached):
        pix, slot = batch
        if reached is not None:
            pix, slot = _pick(np.take(floor, slot) <= np.take(reached, pix), pix, slot)
        if tables is None:
            s = shapes.take(slot)
            _, Dh = to_object(ar, s, None, _take(rays.direction, pix))
            a2 = None
        else:
            s = form or Form(shapes.zsign[slot])
            Dh, a2 = tables.read(slot, pix)
        one = _one(slot)  # a batch on one shape: its values broadcast
        sol = solve(ar, s, _take(S_shape, one), Dh, c2_shape[one], rays.tmin, rays.tmax, a2)
        sqd = squared_distance(ar, dd[pix], sol.t)
        bad = sol.bad | (sol.hit & ~np.isfinite(sqd))
        return pix, slot, sqd, sol.t, sol.hit & ~bad, bad

    for done, sel in enumerate(blocks):
        if options.cull:
            ci, si = np.nonzero(cone_keep(cones, apex, None, bounds, sel, rnd))
            fi, si = children[ci].ravel(), np.repeat(si, children.shape[1])
            fi, si = _pick(fi >= 0, fi, si)
            fi, si = _pick(cone_keep_cells(fine_cones, fi, apex, bounds, sel[si], rnd), fi, si)
            passes = _depth_passes(tiles, len(sel), fi, si, floor[sel[si]], near)
        else:
            passes = [(np.ones((len(tiles), len(sel)), bool), None)]
        for keep, reached in passes:
            for batch in pairs(tiles, keep, sel, distinct=True):
                pix, slot, sqd, t, hit, bad = test(batch, reached)
                st.tests += len(pix)
                st.nan_tests += int(bad.sum())
                nan_pixel[_pick(bad, pix)[0]] = True
                near.update(pix, slot, sqd, t, distinct=True, hit=hit)
        if progress is not None:
            progress((done + 1) / len(blocks))
    st.skipped += n_pix * len(shapes) - st.tests
    return near, tables, S_shape


def _depth_passes(tiles: Tiles, n_sel: int, fi: np.ndarray, si: np.ndarray, low: np.ndarray,
                  near: _Nearest) -> list[tuple[np.ndarray, np.ndarray | None]]:
    """The kept cells (fine tile ``fi``, shape ``si`` of the block, depth floor ``low``) as
    passes of (keep matrix, nearest hits to check pairs against, or None).

    A shape whose every hit is farther than a pixel's nearest hit so far cannot win it:
    cells whose floor is at most every nearest hit in their tile are tested unchecked,
    cells whose floor exceeds some of them pair by pair, cells whose floor exceeds all of
    them not at all.
    """
    def matrix(cells: np.ndarray) -> np.ndarray:
        keep = np.zeros((len(tiles), n_sel), bool)
        keep[_pick(cells, fi, si)] = True
        return keep

    if not near.any:
        return [(matrix(np.ones(len(fi), bool)), None)]
    reached = near.sqd.copy()
    in_tiles = reached[tiles.order]
    sure = low <= tile_reduce(tiles, in_tiles, np.minimum)[fi]
    check = ~sure & (low <= tile_reduce(tiles, in_tiles, np.maximum)[fi])
    return [(matrix(sure), None), (matrix(check), reached)]


def shade_hits(ar: Arith, options: EmuOptions, shapes: Shapes, bounds: Bounds, lights: list[Light], hp: np.ndarray,
               slot: np.ndarray, point: Vec, normal: Vec, st: FrameStats, nan_pixel: np.ndarray,
               record: Recorder | None = None) -> tuple[np.ndarray, np.ndarray]:
    """RGB565 per hit pixel and a mask of pixels whose shading met NaN or infinity.

    ``hp`` are the pixels, ``slot`` their shapes' positions, ``point``/``normal`` the world
    hit points and normals. Lighting is :func:`.lighting.diffuse` (shared with the
    rasterizer) with shadow rays as its occlusion test; ``record`` sees every stage.
    """
    def occluded(light: Light, lit: np.ndarray, l_lit: Vec) -> np.ndarray:
        if len(shapes) < 2:  # nothing else to cast a shadow
            st.shadow_rays += len(lit)
            return np.zeros(len(lit), dtype=bool)
        return _shadowed(ar, options, shapes, bounds, light, _take(point, lit), l_lit, hp[lit], slot[lit], st, nan_pixel)

    return diffuse(ar, shapes.color[slot], normal, point, lights, occluded, options.intensity_fixed, record)


def _shadowed(ar: Arith, options: EmuOptions, shapes: Shapes, bounds: Bounds, light: Light, origin: Vec,
              direction: Vec, pix: np.ndarray, own: np.ndarray, st: FrameStats, nan_pixel: np.ndarray) -> np.ndarray:
    """Whether another shape lies on each shadow ray (t > 0; before the light if a point)."""
    n = len(pix)
    blocked = np.zeros(n, dtype=bool)
    st.shadow_rays += n
    if n == 0:
        return blocked
    tmax = ar.const(1.0 if light.kind == POINT else np.inf)
    tmin = ar.const(0.0)
    tiles = subset_tiles(screen_tiles(options.pixels, options.width), pix)  # pix: sorted hit pixels
    rnd = Rounding.of(ar)
    before = st.tests
    if options.cull:
        org = _f64_rows(origin, tiles.order)
        if light.kind == POINT:
            apex = _f64(light.location)[0]
            cones = tile_cones(tiles, _f64_rows(direction, tiles.order))
            boxes = tile_boxes(tiles, org)
        else:
            bundle = parallel_rays(tiles, _f64(direction)[0], org)
    per_shape = None
    if light.kind != POINT:  # one direction for every shadow ray: its normal-space terms per shape
        _, D_shape = to_object(ar, shapes, None, direction)
        per_shape = D_shape, direction_term(ar, shapes, D_shape)
    for sel in shape_blocks(len(shapes), len(tiles)):
        open_ = None
        if not options.cull:
            keep = np.ones((len(tiles), len(sel)), bool)
        else:
            keep = (cone_keep(cones, apex, boxes, bounds, sel, rnd) if light.kind == POINT
                    else parallel_keep(bundle, bounds, sel, rnd))
            if blocked.any():  # a ray already blocked needs no more tests
                open_ = ~blocked
                keep &= tile_reduce(tiles, open_[tiles.order], np.logical_or)[:, None]

        def test(batch):
            pos, slot = batch
            other = slot != own[pos] if open_ is None else (slot != own[pos]) & open_[pos]
            pos, slot = _pick(other, pos, slot)
            s = shapes.take(slot)
            if per_shape is None:
                S, D = to_object(ar, s, _take(origin, pos), _take(direction, pos))
                a2 = None
            else:
                S, _ = to_object(ar, s, _take(origin, pos), None)
                D, a2 = _take(per_shape[0], slot), per_shape[1][slot]
            sol = solve(ar, s, S, D, origin_term(ar, s, S), tmin, tmax, a2)
            return pos, sol.hit, sol.bad

        for pos, hit, bad in map(test, pairs(tiles, keep, sel)):
            st.tests += len(pos)
            st.nan_tests += int(bad.sum())
            nan_pixel[pix[_pick(bad, pos)[0]]] = True
            blocked[_pick(hit, pos)[0]] = True
    st.skipped += n * (len(shapes) - 1) - (st.tests - before)
    return blocked
