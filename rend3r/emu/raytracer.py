"""The raytracer: nearest hit per pixel, diffuse lighting, shadow rays, NaN accounting.

The frame is rendered in bands of rows, so memory stays bounded at any size; each band's
pixels are split into chunks that threads render with the compiled kernels of
``csrc/datapath.inc`` (``--jobs``; every pixel is computed the same way whatever the
split, so the image does not depend on it). Per band:

1. primary directions and their per-face (u, v) boxes (``directions``);
2. a grid of the shapes each primary ray must test, front to back by depth floor
   (:mod:`.grids`, :mod:`.bounds`);
3. the nearest hit of every pixel, its hit point and normal (``nearest``);
4. per light, a grid of the shapes each shadow ray must test, then the light's colour
   with its shadow rays (``light_pass``);
5. colours, depth and provenance (``finish``).

``docs/emulator.md`` sections 4-7 give the order of operations and why the grids never
change a pixel; :mod:`.reference` is the plain renderer the tests compare with.
"""

from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor
from ctypes import byref, pointer
from dataclasses import dataclass
from functools import lru_cache
from time import perf_counter
from typing import Callable

import numpy as np

from . import bounds, grids, native
from .arith import Arith
from .camera import camera_rays
from .frame import Frame
from .lights import POINT, Light, lights_from_scene
from .options import EmuOptions
from .scene import Scene
from .shapes import SPHERE, Shapes, shapes_from_scene
from .stats import FrameStats

Progress = Callable[[float], None]
#: Pixels per band: bounds the per-pixel working arrays (about 100 bytes per pixel).
BAND_PIXELS = 1 << 20
#: Smallest chunk of pixels handed to a thread.
MIN_CHUNK = 1 << 12
_CHANNELS = ((11, 31), (5, 63), (0, 31))  # RGB565: (shift, largest value) per channel


def available_cores() -> int:
    """Cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not Linux
        return os.cpu_count() or 1


@lru_cache(maxsize=4)
def _pool(jobs: int) -> ThreadPoolExecutor:
    return ThreadPoolExecutor(max_workers=jobs, thread_name_prefix="rend3r")


@dataclass
class _Frame:
    """What every band of a frame shares (the arrays back the kernels' pointers)."""

    ar: Arith
    dtype: np.dtype
    cam: np.ndarray
    xs: np.ndarray
    ys: np.ndarray
    rotated: bool
    sf: np.ndarray
    si: np.ndarray
    index: np.ndarray
    bnd: np.ndarray
    bounded: np.ndarray
    lights: list[Light]
    light_rows: np.ndarray
    jobs: int
    shapes: native.Shapes

    @property
    def fp16(self) -> bool:
        return self.ar.precision == "fp16"

    def kernel(self, name: str):
        """The compiled kernel ``name`` for this frame's precision."""
        return native.kernel(name, self.ar.precision, self.ar.ftz)


def render_frame(scene: Scene, options: EmuOptions, number: int = 0,
                 progress: Progress | None = None) -> tuple[Frame, FrameStats]:
    """Render the scene as the raytracer sees it; returns the frame and its stats."""
    start = perf_counter()
    fr = set_up(scene, options)
    w, h, n_pix = options.width, options.height, options.pixels
    st = FrameStats(number=number, pixels=n_pix, shapes=len(fr.sf), lights=len(fr.lights), rays=n_pix)
    rgb = np.full(n_pix, options.background, dtype=np.uint16)
    depth = np.full(n_pix, np.inf, dtype=np.float32)
    prov = np.full(n_pix, -1, dtype=np.int32)
    if len(fr.sf):
        rows = max(1, BAND_PIXELS // w)
        for row0 in range(0, h, rows):
            row1 = min(h, row0 + rows)
            _band(fr, options, row0, row1, st, rgb[row0 * w:row1 * w], depth[row0 * w:row1 * w],
                  prov[row0 * w:row1 * w])
            if progress is not None:
                progress(row1 / h)
    st.seconds = perf_counter() - start
    return Frame(number, rgb.reshape(h, w), depth.reshape(h, w), prov.reshape(h, w)), st


def set_up(scene: Scene, options: EmuOptions) -> _Frame:
    """What every band of the frame shares: camera, shape and light tables."""
    ar = options.arith
    dtype = np.dtype(ar.dtype)
    rays = camera_rays(scene, options, ar)
    cam = np.zeros(native.CAM_COLUMNS, dtype)
    cam[native.CAM_ORIGIN:native.CAM_ORIGIN + 3] = [np.asarray(c, dtype) for c in rays.origin]
    cam[native.CAM_TMIN], cam[native.CAM_TMAX], cam[native.CAM_Z] = rays.tmin, rays.tmax, rays.z
    if rays.rotation is not None:  # the kernel turns (x[col], y[row], z) per pixel
        cam[native.CAM_ROT:native.CAM_ROT + 4] = [np.asarray(c, dtype) for c in rays.rotation]
    shapes = shapes_from_scene(scene, ar)
    sf, si = _shape_tables(shapes, dtype)
    bnd, bounded = bounds.shape_bounds(sf[:, native.SF_LOC:native.SF_LOC + 3], sf[:, native.SF_ROT:native.SF_ROT + 4],
                                       sf[:, native.SF_INV:native.SF_INV + 3], shapes.kind == SPHERE)
    lights = lights_from_scene(scene, ar, options.light_model)
    n = len(sf)
    view = native.Shapes(native.ptr(sf, dtype, (n, native.SF_COLUMNS)), native.ptr(si, np.int64, (n, native.SI_COLUMNS)),
                         native.ptr(bnd, np.float64, (n, native.B_COLUMNS)), n, ar.unit_roundoff, ar.tiny)
    if n:
        native.kernel("origin_terms", ar.precision, ar.ftz)(byref(view), native.ptr(cam, dtype, (native.CAM_COLUMNS,)))
    return _Frame(ar, dtype, cam, np.ascontiguousarray(rays.xs, dtype), np.ascontiguousarray(rays.ys, dtype),
                  rays.rotation is not None, sf, si, shapes.index.astype(np.int32), bnd, bounded, lights,
                  _light_rows(lights, dtype), options.jobs or available_cores(), view)


def _shape_tables(s: Shapes, dtype: np.dtype) -> tuple[np.ndarray, np.ndarray]:
    """The kernels' shape tables: floats (SF_COLUMNS, working dtype) and ints (SI_COLUMNS)."""
    sf = np.zeros((len(s), native.SF_COLUMNS), dtype)
    for base, values in ((native.SF_LOC, s.loc), (native.SF_ROT, s.rot), (native.SF_INV, s.inv_scale)):
        for k, v in enumerate(values):
            sf[:, base + k] = v
    sf[:, native.SF_ZSIGN], sf[:, native.SF_ONE] = s.zsign, s.one
    si = np.zeros((len(s), native.SI_COLUMNS), np.int64)
    r, i, j, k = (sf[:, native.SF_ROT + c] for c in range(4))
    si[:, native.SI_IDENT] = (r == 1) & (i == 0) & (j == 0) & (k == 0) & ~(np.signbit(i) | np.signbit(j) | np.signbit(k))
    si[:, native.SI_COLOUR] = s.color
    return sf, si


@dataclass(frozen=True)
class PixelTrace:
    """Every intermediate of one pixel (``docs/trace.md``), in working-precision values."""

    shapes: np.ndarray  # (shapes, TRACE_SHAPE_VALUES): S, D, a2, b, c2, disc, sqrt, t1, t2, t, hit, sq_dist, point, normal
    lights: np.ndarray  # (lights, TRACE_LIGHT_VALUES): l, n.l, n_len, l_len, denom, cos, f, fixed, lit, shadow
    nearest: int  # position of the shape shown in the shape table, -1 none
    colour: int | None  # RGB565, None: the background


def trace_pixel(fr: _Frame, options: EmuOptions, x: int, y: int) -> PixelTrace:
    """Pixel (x, y) computed by the kernels' own functions, keeping every intermediate
    (shadow rays test every shape)."""
    n, nl, dtype = len(fr.sf), len(fr.lights), fr.dtype
    band = native.Band(pointer(fr.shapes), native.ptr(fr.cam, dtype, (native.CAM_COLUMNS,)),
                       native.ptr(fr.xs, dtype, (options.width,)), native.ptr(fr.ys, dtype, (options.height,)),
                       int(fr.rotated), int(bool(fr.lights)), options.width, 0)
    radius = np.full(n, np.inf)
    lp = native.LightPass(pointer(fr.shapes), pointer(band), None, (0.0, 0.0, 0.0), (0.0,) * 6,
                          int(options.intensity_fixed), int(n > 1), 0, None, radius.ctypes.data, grids.EMPTY.struct())
    scales = np.array([[((lt.color >> shift) & top) / top for shift, top in _CHANNELS] for lt in fr.lights]).reshape(-1, 3)
    shape_out = np.zeros((n, native.TRACE_SHAPE_VALUES))
    light_out = np.zeros((nl, native.TRACE_LIGHT_VALUES))
    nearest = np.zeros(1, np.int64)
    colour = fr.kernel("trace_pixel")(byref(band), byref(lp), fr.light_rows.ctypes.data, scales.ctypes.data,
                                                nl, x, y, shape_out.ctypes.data, light_out.ctypes.data,
                                                nearest.ctypes.data)
    return PixelTrace(shape_out, light_out, int(nearest[0]), None if colour < 0 else int(colour))


def _light_rows(lights: list[Light], dtype: np.dtype) -> np.ndarray:
    rows = np.zeros((len(lights), native.LT_COLUMNS), dtype)
    for n, light in enumerate(lights):
        rows[n, native.LT_KIND] = native.LIGHT_POINT if light.kind == POINT else native.LIGHT_DIRECTIONAL
        rows[n, native.LT_LOC:native.LT_LOC + 3] = [np.asarray(c, dtype) for c in light.location]
        rows[n, native.LT_DIR:native.LT_DIR + 3] = [np.negative(np.asarray(c, dtype)) for c in light.forward]
        rows[n, native.LT_INTENSITY] = light.intensity
    return rows


def _chunks(n: int, jobs: int) -> list[tuple[int, int]]:
    """Pixel ranges for the threads: a few per thread, so that uneven work evens out."""
    parts = 1 if jobs == 1 else max(1, min(4 * jobs, n // MIN_CHUNK))
    edges = [n * k // parts for k in range(parts + 1)]
    return [(a, b) for a, b in zip(edges, edges[1:]) if b > a]


def _run(jobs: int, n: int, fn: Callable[..., object], block: object, out: np.ndarray) -> np.ndarray:
    """``fn(block, p0, p1, out_k)`` over chunks of 0..n on ``jobs`` threads, each chunk with
    its own copy of ``out``; returns them stacked."""
    chunks = _chunks(n, jobs)
    outs = np.stack([out.copy() for _ in chunks])
    ref = byref(block)
    if jobs == 1 or len(chunks) == 1:
        for k, (a, b) in enumerate(chunks):
            fn(ref, a, b, outs[k].ctypes.data)
    else:
        futures = [_pool(jobs).submit(fn, ref, a, b, outs[k].ctypes.data) for k, (a, b) in enumerate(chunks)]
        for future in futures:
            future.result()
    return outs


_COUNTERS = np.zeros(3, np.int64)


def _band(fr: _Frame, options: EmuOptions, row0: int, row1: int, st: FrameStats,
          rgb: np.ndarray, depth: np.ndarray, prov: np.ndarray) -> None:
    """Render rows row0..row1 into the band's slices of the frame."""
    w, n_pix, n, dtype = options.width, (row1 - row0) * options.width, len(fr.sf), fr.dtype
    lit = bool(fr.lights)
    a = {  # the band's arrays; the Band block points into them
        "slot": np.empty(n_pix, np.int32), "sqd": np.empty(n_pix, dtype),
        "pt": np.empty((n_pix if lit else 0, 3), dtype), "nm": np.empty((n_pix if lit else 0, 3), dtype),
        "bad": np.zeros(n_pix, np.uint8), "nan_px": np.zeros(n_pix, np.uint8),
    }
    band = native.Band(pointer(fr.shapes), native.ptr(fr.cam, dtype, (native.CAM_COLUMNS,)),
                       native.ptr(fr.xs, dtype, (w,)), native.ptr(fr.ys, dtype, (options.height,)),
                       int(fr.rotated), int(lit), w, row0)
    tables = _grid_camera(fr, row0, row1)
    if tables is None:  # a rotated camera: directions per pixel, kept for the nearest-hit pass
        a["dirs"] = np.empty((n_pix, 4), dtype)
        band.dirs = a["dirs"].ctypes.data
        boxes = grids.merge_boxes(_run(fr.jobs, n_pix, fr.kernel("directions"), band, grids.EMPTY_BOXES))
    else:
        u, v, boxes = tables
    grid, floor, pc = _primary_grid(fr, boxes)
    if tables is not None:
        a["col_cell"], a["row_cell"] = _cells(grid, u, 2), _cells(grid, v, 2, rows=True)
        band.col_cell, band.row_cell = a["col_cell"].ctypes.data, a["row_cell"].ctypes.data
    band.pc, band.floor, band.grid = pc.ctypes.data, floor.ctypes.data, grid.struct()
    for name in ("slot", "sqd", "pt", "nm", "bad", "nan_px"):
        setattr(band, name, a[name].ctypes.data)
    c = _run(fr.jobs, n_pix, fr.kernel("nearest"), band, _COUNTERS).sum(axis=0)
    st.tests += int(c[native.C_TESTS])
    st.nan_tests += int(c[native.C_NAN_TESTS])
    st.skipped += n_pix * n - int(c[native.C_TESTS])
    acc = np.zeros((n_pix if lit else 0, 3))
    for k in range(len(fr.lights)):
        _light(fr, options, k, band, a, acc, st)
    st.hits += fr.kernel("finish")(byref(band), acc.ctypes.data, fr.index.ctypes.data, options.background, 0, n_pix,
                                   native.ptr(rgb, np.uint16, (n_pix,)), native.ptr(depth, np.float32, (n_pix,)),
                                   native.ptr(prov, np.int32, (n_pix,)))
    st.nan_rays += int(a["nan_px"].sum())


def _grid_camera(fr: _Frame, row0: int, row1: int) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """For a camera whose directions are (x[col], y[row], z), z finite and not zero: each
    column's u = x/z and each row's v = y/z (their lines' coordinates on face 2, shared
    by the grid and the lookups) and the face boxes; else None."""
    z = float(fr.cam[native.CAM_Z])
    if fr.rotated or not (z != 0 and np.isfinite(z)):
        return None
    xs, ys = fr.xs.astype(np.float64), fr.ys[row0:row1].astype(np.float64)
    u, v = xs / z, ys / z
    boxes = grids.EMPTY_BOXES.copy()
    fu, fv = u[np.isfinite(u)], v[np.isfinite(v)]
    if len(fu) and len(fv):
        shortest = np.sqrt(np.min(xs[np.isfinite(u)] ** 2) + np.min(ys[np.isfinite(v)] ** 2) + z * z)
        longest = np.sqrt(np.max(xs[np.isfinite(u)] ** 2) + np.max(ys[np.isfinite(v)] ** 2) + z * z)
        boxes[2] = (fu.min(), fu.max(), fv.min(), fv.max(), len(fu) * len(fv), shortest, longest)
    return u, v, boxes


def _cells(grid: grids.Grid, coords: np.ndarray, face: int, rows: bool = False) -> np.ndarray:
    """Per column (u) or row (v) of a grid camera, its part of the cell index on ``face``,
    as the kernels' cell_of computes it; -1 outside the grid."""
    nu, nv, first = (int(c) for c in grid.shape[face])
    lo, hi, scale = (grid.faces[face, k] for k in ((2, 3, 5) if rows else (0, 1, 4)))
    count = nv if rows else nu
    inside = (lo <= coords) & (coords <= hi) & (count > 0)
    index = np.minimum(((np.where(inside, coords, lo) - lo) * scale).astype(np.int64), count - 1)
    return np.where(inside, first + index * nu if rows else index, -1).astype(np.int64)


def _primary_grid(fr: _Frame, boxes: np.ndarray) -> tuple[grids.Grid, np.ndarray, np.ndarray]:
    """The primary rays' grid, and per shape its depth floor and cull data."""
    used = boxes[:, 4] > 0
    dmin = float(boxes[used, 5].min()) if used.any() else 0.0
    dmax = float(boxes[used, 6].max()) if used.any() else 0.0
    apex = fr.cam[native.CAM_ORIGIN:native.CAM_ORIGIN + 3].astype(np.float64)
    bounded = fr.bounded & bool(np.isfinite(apex).all())
    with np.errstate(all="ignore"):  # a camera at infinity: nothing is bounded
        centers = fr.bnd[:, :3] - apex
        dist = np.linalg.norm(centers, axis=1)
    u, tiny = fr.ar.unit_roundoff, fr.ar.tiny
    radius = bounds.cull_radii(fr.bnd, bounded, dist, dmin, u, tiny, fr.fp16)
    floor = bounds.depth_floors(fr.bnd, bounded, dist, dmin, dmax, u, tiny)
    pc = np.empty((len(radius), native.PC_COLUMNS))
    native.library().bound_primary(fr.bnd.ctypes.data, radius.ctypes.data, len(radius), apex.ctypes.data, dmin, u,
                                   tiny, pc.ctypes.data)
    order = np.argsort(floor, kind="stable").astype(np.int32)
    return grids.build(boxes, False, centers, radius, order), floor, pc


#: shadow_origins' output: bounding box of the points, largest magnitude, largest chord,
#: then the face boxes.
_ORIGINS = np.concatenate([[np.inf] * 3 + [-np.inf] * 3 + [0.0, 0.0], grids.EMPTY_BOXES.ravel()])


def _light(fr: _Frame, options: EmuOptions, k: int, band: native.Band, a: dict[str, np.ndarray], acc: np.ndarray,
           st: FrameStats) -> None:
    """Add light ``k`` to the band's colour sums, with its shadow rays."""
    light = fr.light_rows[k]
    colour = fr.lights[k].color
    n_pix, n = len(a["slot"]), len(fr.sf)
    shadows = n > 1
    point = light[native.LT_KIND] == native.LIGHT_POINT
    lp = native.LightPass(pointer(fr.shapes), pointer(band), native.ptr(light, fr.dtype, (native.LT_COLUMNS,)),
                          (*[((colour >> shift) & top) / top for shift, top in _CHANNELS],))
    lp.fixed, lp.shadows, lp.parallel, lp.acc = int(options.intensity_fixed), int(shadows), int(not point), acc.ctypes.data
    if shadows:  # the block points into grid, radius and along: they live until the pass is done
        grid, radius, along = _shadow_grid(fr, lp, light, n_pix)
        lp.grid, lp.radius, lp.along = grid.struct(), radius.ctypes.data, along.ctypes.data
    c = _run(fr.jobs, n_pix, fr.kernel("light_pass"), lp, _COUNTERS).sum(axis=0)
    st.shadow_rays += int(c[native.C_SHADOW_RAYS])
    st.tests += int(c[native.C_TESTS])
    st.nan_tests += int(c[native.C_NAN_TESTS])
    if shadows:
        st.skipped += int(c[native.C_SHADOW_RAYS]) * (n - 1) - int(c[native.C_TESTS])


def _shadow_grid(fr: _Frame, lp: native.LightPass, light: np.ndarray,
                 n_pix: int) -> tuple[grids.Grid, np.ndarray, np.ndarray]:
    """The grid of a light's shadow rays from the band's hit points (``lp`` gets its
    frame): (grid, cull radii, per-shape terms along a directional light's l)."""
    n = len(fr.sf)
    centers = fr.bnd[:, :3]
    along = np.zeros((0, 4), fr.dtype)
    point = not lp.parallel
    if point:
        apex = light[native.LT_LOC:native.LT_LOC + 3].astype(np.float64)
        lp.frame[:3] = apex
    else:
        l = light[native.LT_DIR:native.LT_DIR + 3].astype(np.float64)
        length = float(np.sqrt(l @ l)) if np.isfinite(l).all() else 0.0
        if not 0 < length < np.inf:  # cos is not finite at any point: no shadow ray
            return grids.EMPTY, np.full(n, np.inf), along
        axes = _normal_plane(l / length)
        lp.frame[:] = axes.ravel()
    out = _run(fr.jobs, n_pix, fr.kernel("shadow_origins"), lp, _ORIGINS)
    lo, hi = out[:, :3].min(axis=0), out[:, 3:6].max(axis=0)
    magnitude, chord = out[:, 6].max(), out[:, 7].max()
    boxes = grids.merge_boxes(out[:, 8:].reshape(len(out), 3, native.BOX_COLUMNS))
    if not boxes[:, 4].any():  # no hit point: no shadow ray
        return grids.EMPTY, np.full(n, np.inf), along
    with np.errstate(all="ignore"):
        mid, half = (lo + hi) / 2, np.sqrt(((hi - lo) ** 2).sum()) / 2
        far = np.sqrt(((centers - mid) ** 2).sum(axis=1)) * (1 + bounds.SLACK) + half  # to any origin, at most
        slack = 1e-12 * (np.sqrt((centers ** 2).sum(axis=1)) + magnitude)
    u, tiny = fr.ar.unit_roundoff, fr.ar.tiny
    if point:
        bounded = fr.bounded & bool(np.isfinite(apex).all())
        radius = bounds.cull_radii(fr.bnd, bounded, far, float(boxes[:, 5].min()), u, tiny, fr.fp16)
        radius += far * (chord * (1 + bounds.SLACK) + 1e-15) + slack
        return grids.build(boxes, False, centers - apex, radius, np.arange(n, dtype=np.int32)), radius, along
    radius = bounds.cull_radii(fr.bnd, fr.bounded, far, length, u, tiny, fr.fp16) + slack
    flat = np.zeros((n, 3))
    with np.errstate(all="ignore"):  # unbounded shapes (infinite centres) have an infinite radius
        flat[:, :2] = _project(centers, axes)
    along = np.empty((n, 4), fr.dtype)
    fr.kernel("shadow_directions")(byref(fr.shapes), light.ctypes.data, along.ctypes.data)
    return grids.build(boxes, True, flat, radius, np.arange(n, dtype=np.int32)), radius, along


def _project(points: np.ndarray, axes: np.ndarray) -> np.ndarray:
    """Points (n, 3) projected on axes (k, 3): (n, k), element-wise (BLAS would start
    its own spinning threads for a product this small)."""
    return np.stack([points[:, 0] * a[0] + points[:, 1] * a[1] + points[:, 2] * a[2] for a in axes], axis=1)


def _normal_plane(d: np.ndarray) -> np.ndarray:
    """Two orthonormal vectors (2, 3) normal to the unit vector d."""
    e1 = np.cross(d, [1.0, 0.0, 0.0] if abs(d[0]) < 0.9 else [0.0, 1.0, 0.0])
    e1 /= np.linalg.norm(e1)
    return np.stack([e1, np.cross(d, e1)])
