"""The raytracer: nearest hit per pixel, diffuse lighting, shadow rays, NaN accounting.

The frame is rendered in bands of rows, so memory stays bounded at any size, with the
compiled kernels of ``csrc/datapath.inc``; every pass splits over a team of ``--jobs``
threads (:mod:`.threads`; every pixel is computed the same way whatever the split, so the
image does not depend on it). Per band:

1. the primary directions' shortest and longest length (``directions`` stores a rotated
   camera's directions; a grid camera's come from its axes, once per frame);
2. the shape hierarchy's boxes for the primary rays, from the shapes' cull radii and
   depth floors (:mod:`.bvh`, :mod:`.bounds`; the tree itself is built once per frame,
   and for a grid camera these bounds too, shared by its bands);
3. the nearest hit of every pixel, its hit point and normal (``nearest``, packets of a
   row's pixels walking the tree nearest node first);
4. per light, the hierarchy's boxes for its shadow rays, then the light's colour with
   its shadow rays (``light_pass``);
5. colours, depth and provenance, packet by packet in the last light's pass (in the
   nearest-hit pass when there are no lights).

``docs/emulator.md`` sections 4-7 give the order of operations and why the hierarchy
never changes a pixel; :mod:`.reference` is the plain renderer the tests compare with.
"""

from __future__ import annotations

import itertools
import math
from ctypes import addressof, byref, pointer
from dataclasses import dataclass
from time import perf_counter
from typing import Callable

import numpy as np

from ..errors import Rend3rError
from ..isa import Table, lookup
from ..isa.tables import PROP_LIMIT, SHAPE_TYPE_CODES
from . import bounds, bvh, native, threads
from .native import address
from .arith import Arith
from .camera import camera_rays
from .frame import Frame
from .lights import POINT, Light, lights_from_scene
from .options import EmuOptions
from .scene import Scene, prop_index
from .stats import FrameStats

Progress = Callable[[float], None]
#: Pixels per band: bounds the per-pixel working arrays (about 100 bytes per pixel).
BAND_PIXELS = native.BAND_LIMIT
#: Smallest chunk of pixels handed to a thread, and the most chunks a pass takes per thread.
MIN_CHUNK = 1 << 12
CHUNKS_PER_JOB = 32
_CHANNELS = ((11, 31), (5, 63), (0, 31))  # RGB565: (shift, largest value) per channel


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
    bounded: np.ndarray  # uint8, 1 where the shape is bounded
    lights: list[Light]
    light_rows: np.ndarray
    jobs: int
    shapes: native.Shapes
    tree: bvh.Tree
    primary: _Primary | None  # a grid camera's primary bounds (None: each band measures its directions)

    def kernel(self, name: str):
        """The compiled kernel ``name`` for this frame's precision."""
        return native.kernel(name, self.ar)


def render_frame(scene: Scene, options: EmuOptions, number: int = 0,
                 progress: Progress | None = None) -> tuple[Frame, FrameStats]:
    """Render the scene as the raytracer sees it; returns the frame and its stats."""
    start = perf_counter()
    with threads.team(options.jobs or threads.available_cores()):  # the frame's every pass splits over it
        fr = set_up(scene, options)
        w, h, n_pix = options.width, options.height, options.pixels
        st = FrameStats(number=number, pixels=n_pix, shapes=len(fr.sf), lights=len(fr.lights), rays=n_pix)
        rgb, depth, prov = np.empty(n_pix, np.uint16), np.empty(n_pix, np.float32), np.empty(n_pix, np.int32)
        if not len(fr.sf):  # else every band's finish pass sets every pixel
            rgb[:], depth[:], prov[:] = options.background, np.inf, -1
        else:
            rows = max(1, BAND_PIXELS // w)
            for row0 in range(0, h, rows):
                row1 = min(h, row0 + rows)
                _add(st, _band(fr, options, row0, row1, rgb[row0 * w:row1 * w], depth[row0 * w:row1 * w],
                               prov[row0 * w:row1 * w], fr.primary))
                if progress is not None:
                    progress(row1 / h)
    st.seconds = perf_counter() - start
    return Frame(number, rgb.reshape(h, w), depth.reshape(h, w), prov.reshape(h, w)), st


def set_up(scene: Scene, options: EmuOptions) -> _Frame:
    """What every band of the frame shares: camera, shape and light tables, the shape
    hierarchy and, for a grid camera, the primary rays' bounds."""
    ar = options.arith
    dtype = native.dtype(ar)
    rays = camera_rays(scene, options, ar)
    cam = np.zeros(native.CAM_COLUMNS, dtype)
    cam[native.CAM_ORIGIN:native.CAM_ORIGIN + 3] = [np.asarray(c, dtype) for c in rays.origin]
    cam[native.CAM_TMIN], cam[native.CAM_TMAX], cam[native.CAM_Z] = rays.tmin, rays.tmax, rays.z
    if rays.rotation is not None:  # the kernel turns (x[col], y[row], z) per pixel
        cam[native.CAM_ROT:native.CAM_ROT + 4] = [np.asarray(c, dtype) for c in rays.rotation]
    xs, ys = np.ascontiguousarray(rays.xs, dtype), np.ascontiguousarray(rays.ys, dtype)
    fmt = None if ar.native else native.Format.of(ar)
    jobs = options.jobs or threads.available_cores()
    extent = _extent(cam, xs, ys, rays.rotation is not None)
    sf, si, bnd, bounded, index, tree, primary = _shapes(scene, ar, fmt, cam, extent, jobs)
    lights = lights_from_scene(scene, ar, options.light_model)
    n = len(sf)
    view = native.Shapes(native.ptr(sf, dtype, (n, native.SF_COLUMNS)), native.ptr(si, np.int64, (n, native.SI_COLUMNS)),
                         native.ptr(bnd, np.float64, (n, native.B_COLUMNS)), n, ar.unit_roundoff, ar.tiny, fmt)
    return _Frame(ar, dtype, cam, xs, ys, rays.rotation is not None, sf, si, index, bnd, bounded, lights,
                  _light_rows(lights, dtype), jobs, view, tree, primary)


#: The shape table's columns the kernels read, and the type codes of the normal forms.
_SHAPE_PROPS = np.array([prop_index(Table.SHAPE, name) for name in (
    "xloc", "yloc", "zloc", "rrot", "irot", "jrot", "krot", "xscl", "yscl", "zscl", "col", "type")], np.int32)
_KINDS = np.array([SHAPE_TYPE_CODES["sphere"], SHAPE_TYPE_CODES["cylinder"], SHAPE_TYPE_CODES["cone"],
                   lookup(Table.SHAPE, "type").value_mask], np.int32)


def _shapes(scene: Scene, ar: Arith, fmt, cam: np.ndarray, extent: tuple[float, float] | None,
            jobs: int) -> tuple:
    """The shapes that are on, as the kernels' tables (csrc/datapath.inc shape_tables, with
    the camera origin ``cam`` in each shape's normal space): (floats, ints, bounds,
    bounded, program index) in index order, then the hierarchy over them and, given the
    primary directions' ``extent``, the primary rays' bounds; in one call on a team of
    ``jobs`` threads (csrc/setup.c frame_setup). Spheres with moderate maps are bounded
    (culled, csrc/bounds.h) in every format: a test that overflows is a miss, and a format
    too coarse for the bounds (docs/emulator.md section 7) gets infinite cull radii from
    them."""
    table = scene.objects
    values = np.ascontiguousarray(table.values, np.uint16)
    index = np.ascontiguousarray(table.index, np.int64)
    rows = len(index)
    dtype = native.dtype(ar)
    s = native.Setup(native.function_address(native.kernel("shape_tables", ar)),
                     native.ptr(values, np.uint16, (rows, PROP_LIMIT)), address(index), rows, address(_SHAPE_PROPS),
                     address(_KINDS), native.ptr(cam, dtype, (native.CAM_COLUMNS,)), ar.tiny, fmt)
    sf = np.empty((rows, native.SF_COLUMNS), dtype)  # frame_setup fills them
    si, bnd = np.empty((rows, native.SI_COLUMNS), np.int64), np.empty((rows, native.B_COLUMNS))
    bounded, out = np.empty(rows, np.uint8), np.empty(rows, np.int32)
    s.sf, s.sf_row, s.si, s.bnd, s.bounded, s.index_out = (address(sf), sf.strides[0], address(si), address(bnd),
                                                           address(bounded), address(out))
    room = bvh.Tree(np.empty((max(1, 2 * rows), 2), np.int32), np.empty(rows, np.int32), np.empty(rows, np.int32))
    s.node, s.items, s.always = address(room.node), address(room.items), address(room.always)
    s.jobs, s.chunk = jobs, bounds.SHAPE_CHUNK
    first = None
    if extent is not None:  # the primary bounds in the same call, around the camera origin
        apex = cam[native.CAM_ORIGIN:native.CAM_ORIGIN + 3].astype(np.float64)  # at infinity: nothing is bounded
        first = bounds.primary(bnd, bounded, apex, *extent, ar.unit_roundoff, ar.tiny, ar.overflow)
        fitted, own = room.bounds_for(first.block, apex, None, room.nodes, False, jobs)  # own: the call's scratch
    with threads.team(jobs) as team:
        n = native.library().frame_setup(byref(s), None if first is None else byref(first.block), team)
    if n < 0:
        raise Rend3rError(f"not enough memory to build the shape hierarchy of {rows:,} shapes")
    tree = bvh.Tree(room.node[:s.nodes], room.items[:s.counts[0]], room.always[:s.counts[1]])
    primary = None if first is None else \
        (bvh.Bounds(tree, fitted.box[:s.nodes], fitted.frame), first.floor[:n], first.pc[:n])
    return sf[:n], si[:n], bnd[:n], bounded[:n], out[:n], tree, primary


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
                       int(fr.rotated), int(bool(fr.lights)), options.width, y, native.row_magic(options.width))
    scales = np.array([[((lt.color >> shift) & top) / top for shift, top in _CHANNELS] for lt in fr.lights]).reshape(-1, 3)
    shape_out = np.zeros((n, native.TRACE_SHAPE_VALUES))
    light_out = np.zeros((nl, native.TRACE_LIGHT_VALUES))
    nearest = np.zeros(1, np.int64)
    colour = fr.kernel("trace_pixel")(byref(band), int(options.intensity_fixed), int(n > 1), address(fr.light_rows),
                                      address(scales), nl, x, y, address(shape_out), address(light_out),
                                      address(nearest))
    return PixelTrace(shape_out, light_out, int(nearest[0]), None if colour < 0 else int(colour))


def _light_rows(lights: list[Light], dtype: np.dtype) -> np.ndarray:
    rows = np.zeros((len(lights), native.LT_COLUMNS), dtype)
    for n, light in enumerate(lights):
        rows[n, native.LT_KIND] = native.LIGHT_POINT if light.kind == POINT else native.LIGHT_DIRECTIONAL
        rows[n, native.LT_LOC:native.LT_LOC + 3] = [np.asarray(c, dtype) for c in light.location]
        rows[n, native.LT_DIR:native.LT_DIR + 3] = [np.negative(np.asarray(c, dtype)) for c in light.forward]
        rows[n, native.LT_INTENSITY] = light.intensity
    return rows


def _run(jobs: int, n: int, fn: Callable[..., object], block: object, last: np.ndarray,
         smallest: int | None = None) -> np.ndarray:
    """The pixel kernel ``fn(block, k0, k1, out)`` over chunks of 0..n (``smallest`` long at
    least, MIN_CHUNK if None; at most CHUNKS_PER_JOB a thread) on a team of ``jobs``
    threads (csrc/setup.c team_chunks; a thread takes the next chunk in a microsecond, so
    many small chunks even out uneven ones), each chunk adding to its own copy of the
    report row ``last``; returns the copies stacked."""
    outs = _own_lines(last, threads.parts(n, jobs, smallest or MIN_CHUNK, CHUNKS_PER_JOB))
    with threads.team(jobs) as team:
        native.library().team_chunks(team, native.function_address(fn), addressof(block), n, len(outs),
                                     address(outs[0]), outs.strides[0])
    return outs


#: Cache lines (bytes) and the doubles a report row is padded to: two lines, as neighbouring
#: lines may be fetched together.
_LINE, _ROW = 64, 16


def _own_lines(last: np.ndarray, count: int) -> np.ndarray:
    """``count`` copies of the float64 row ``last`` (count, len(last)), each on cache lines
    no other array or row uses: the kernels add to their report per packet, and rows that
    share a line with another thread's (two bands' reports, or chunks of one) made every
    kernel about a quarter slower on two threads (false sharing)."""
    if len(last) > _ROW:
        raise ValueError(f"a report row holds at most {_ROW} values")
    buf = np.empty((count + 2) * _ROW + _LINE // 8)
    start = (-address(buf) % _LINE) // 8 + _ROW  # aligned, one padding row before
    rows = buf[start:start + count * _ROW].reshape(count, _ROW)[:, :len(last)]
    rows[:] = last
    return rows


#: A kernel's report per chunk (csrc/kernels.h OUT_*): counts, then the hit points' box.
_OUT = np.zeros(native.OUT_COLUMNS)
_OUT[native.OUT_LO:native.OUT_LO + 3], _OUT[native.OUT_HI:native.OUT_HI + 3] = np.inf, -np.inf


def _report(outs: np.ndarray) -> np.ndarray:
    """Chunks' reports merged: counts summed, boxes joined."""
    if len(outs) == 1:
        return outs[0]
    out = outs.sum(axis=0)
    out[native.OUT_LO:native.OUT_LO + 3] = outs[:, native.OUT_LO:native.OUT_LO + 3].min(axis=0)
    out[native.OUT_HI:native.OUT_HI + 3] = outs[:, native.OUT_HI:native.OUT_HI + 3].max(axis=0)
    return out


def _add(total: FrameStats, band: FrameStats) -> None:
    """A band's counts added to the frame's."""
    for name in _BAND_COUNTS:
        setattr(total, name, getattr(total, name) + getattr(band, name))


#: What _band counts.
_BAND_COUNTS = ("tests", "skipped", "nan_tests", "nan_rays", "hits", "shadow_rays")


def _band(fr: _Frame, options: EmuOptions, row0: int, row1: int, rgb: np.ndarray, depth: np.ndarray,
          prov: np.ndarray, primary: _Primary | None = None) -> FrameStats:
    """Render rows row0..row1 into the band's slices of the frame; returns its counts.
    ``primary``: the frame's primary bounds (None: the band measures its directions)."""
    st = FrameStats()
    w, n_pix, n, dtype = options.width, (row1 - row0) * options.width, len(fr.sf), fr.dtype
    lit = bool(fr.lights)
    kept = n_pix if lit else 0  # without lights, the nearest-hit pass finishes the pixels itself
    a = {  # the band's arrays; the Band block points into them; nearest sets every pixel's
        "slot": np.empty(kept, np.int32), "sqd": np.empty(kept, dtype), "pt": np.empty((3, kept), dtype),
        "nm": np.empty((3, kept), dtype), "bad": np.empty(kept, np.uint8), "nan_px": np.empty(kept, np.uint8),
        # colour sums per channel between lights (the first light's pass sets them, the last reads them)
        "acc": np.empty((3, n_pix if len(fr.lights) > 1 else 0)),
    }
    band = native.Band(pointer(fr.shapes), native.ptr(fr.cam, dtype, (native.CAM_COLUMNS,)),
                       native.ptr(fr.xs, dtype, (w,)), native.ptr(fr.ys, dtype, (options.height,)),
                       int(fr.rotated), int(lit), w, row0, native.row_magic(w))
    band.npix = n_pix
    if primary is None:  # a rotated camera (or not finite): directions per pixel, kept for the nearest-hit pass
        a["dirs"] = np.empty((n_pix, 4), dtype)
        band.dirs = address(a["dirs"])
        parts = _run(fr.jobs, n_pix, fr.kernel("directions"), band, np.array([0.0, np.inf, 0.0]))
        extent = (float(parts[:, 1].min()), float(parts[:, 2].max())) if parts[:, 0].sum() else (0.0, 0.0)
        primary = _primary_tree(fr, *extent)
    tree, floor, pc = primary
    band.pc, band.floor, band.tree = address(pc), address(floor), tree.view
    for name in ("slot", "sqd", "pt", "nm", "bad", "nan_px", "acc"):
        setattr(band, name, address(a[name]))
    band.index, band.background = address(fr.index), options.background
    band.rgb, band.depth = native.ptr(rgb, np.uint16, (n_pix,)), native.ptr(depth, np.float32, (n_pix,))
    band.prov = native.ptr(prov, np.int32, (n_pix,))
    c = _report(_run(fr.jobs, row1 - row0, fr.kernel("nearest"), band, _OUT, max(1, MIN_CHUNK // w)))
    st.tests += int(c[native.OUT_TESTS])
    st.nan_tests += int(c[native.OUT_NAN_TESTS])
    st.skipped += n_pix * n - int(c[native.OUT_TESTS])
    done = c  # the pixels are finished by the nearest-hit pass without lights, else by the last light's
    for k in range(len(fr.lights)):
        done = _light(fr, options, k, band, c, n_pix, st)
    st.hits += int(done[native.OUT_SHOWN])
    st.nan_rays += int(done[native.OUT_NAN_RAYS])
    return st


#: A frame's (or band's) primary bounds: the hierarchy's, and per shape its depth floor
#: and cull data (_primary_tree).
_Primary = tuple[bvh.Bounds, np.ndarray, np.ndarray]


def _extent(cam: np.ndarray, xs: np.ndarray, ys: np.ndarray, rotated: bool) -> tuple[float, float] | None:
    """The shortest and longest primary direction of the frame for a camera whose
    directions are (x[col], y[row], z), all finite and z not zero; None for other cameras
    (each band measures its directions as the kernels compute them)."""
    z = float(cam[native.CAM_Z])
    if rotated or not (z != 0 and math.isfinite(z)):
        return None
    xx, yy = np.square(xs, dtype=np.float64), np.square(ys, dtype=np.float64)
    x0, x1, y0, y1 = float(xx.min()), float(xx.max()), float(yy.min()), float(yy.max())
    if not (math.isfinite(x1) and math.isfinite(y1)):  # an infinite or NaN direction (NaN propagates)
        return None
    return math.sqrt(x0 + y0 + z * z), math.sqrt(x1 + y1 + z * z)


def _primary_tree(fr: _Frame, dmin: float, dmax: float) -> _Primary:
    """The hierarchy's bounds for the primary rays (directions dmin..dmax long), and per
    shape its depth floor and cull data."""
    apex = fr.cam[native.CAM_ORIGIN:native.CAM_ORIGIN + 3].astype(np.float64)  # at infinity: nothing is bounded
    p = bounds.primary(fr.bnd, fr.bounded, apex, dmin, dmax, fr.ar.unit_roundoff, fr.ar.tiny, fr.ar.overflow)
    return fr.tree.fit(p, apex=apex, jobs=fr.jobs), p.floor, p.pc


def _light(fr: _Frame, options: EmuOptions, k: int, band: native.Band, hits: np.ndarray, n_pix: int,
           st: FrameStats) -> np.ndarray:
    """Add light ``k`` to the band's colour sums, with its shadow rays (``hits``: the
    nearest-hit pass's report, with the box of the band's hit points); returns the pass's
    report (the last light's finishes the pixels)."""
    light = fr.light_rows[k]
    colour = fr.lights[k].color
    n = len(fr.sf)
    shadows = n > 1
    point = light[native.LT_KIND] == native.LIGHT_POINT
    lp = native.LightPass(pointer(fr.shapes), pointer(band), native.ptr(light, fr.dtype, (native.LT_COLUMNS,)),
                          (*[((colour >> shift) & top) / top for shift, top in _CHANNELS],))
    lp.fixed, lp.shadows, lp.parallel = int(options.intensity_fixed), int(shadows), int(not point)
    lp.first, lp.last = int(k == 0), int(k == len(fr.lights) - 1)
    lp.serial = next(_LIGHT_PASSES)  # its chunks' caches are kept per thread
    if shadows:  # lp points into the arrays of sb: they live until the pass is done
        sb = _shadow_bounds(fr, lp, light, hits, n_pix)
        lp.tree, lp.radius = sb.bounds.view, address(sb.radius)
        if point and sb.bounds.keys is not None:  # the terms of its per-node behind test
            lp.point_keys = address(sb.bounds.keys)
        if sb.behind is not None:
            lp.behind, lp.keys = address(sb.behind), address(sb.bounds.keys)
            lp.l_len, lp.l_hat[:] = sb.l_len, sb.l_hat
    c = _report(_run(fr.jobs, n_pix, fr.kernel("light_pass"), lp, _OUT))
    st.shadow_rays += int(c[native.OUT_SHADOW_RAYS])
    st.tests += int(c[native.OUT_TESTS])
    st.nan_tests += int(c[native.OUT_NAN_TESTS])
    if shadows:
        st.skipped += int(c[native.OUT_SHADOW_RAYS]) * (n - 1) - int(c[native.OUT_TESTS])
    return c


#: Numbers light passes (LightPass.serial) in the process.
_LIGHT_PASSES = itertools.count(1)

#: shadow_origins' output: bounding box of the points, largest magnitude, largest chord,
#: points with a finite non-zero l, shortest |l|.
_ORIGINS = np.array([np.inf] * 3 + [-np.inf] * 3 + [0.0, 0.0, 0.0, np.inf])


@dataclass
class _ShadowBounds:
    """A light's shadow rays over one band: the per-shape arrays the light pass reads
    (csrc/kernels.h LightPass) and the hierarchy's boxes for these rays."""

    radius: np.ndarray  # cull radius per shape
    bounds: bvh.Bounds  # the hierarchy's bounds for these rays
    behind: np.ndarray | None = None  # a directional light's behind terms per shape
    l_len: float = 0.0  # ... and |l| and l / |l| in double
    l_hat: np.ndarray | None = None


def _shadow_bounds(fr: _Frame, lp: native.LightPass, light: np.ndarray, hits: np.ndarray,
                   n_pix: int) -> _ShadowBounds:
    """Cull radii and node boxes for a light's shadow rays from the band's hit points; a
    directional light's also get the behind terms and stop keys, so a packet skips whole
    subtrees lying behind its origins."""
    if not hits[native.OUT_HITS]:
        return _unbounded(fr, lp)
    lo, hi = hits[native.OUT_LO:native.OUT_LO + 3], hits[native.OUT_HI:native.OUT_HI + 3]
    limits = (fr.ar.unit_roundoff, fr.ar.tiny, fr.ar.overflow)
    if not lp.parallel:  # a point light: the rounding of l turns each ray off the line to the light
        apex = light[native.LT_LOC:native.LT_LOC + 3].astype(np.float64)
        origins = _report_origins(_run(fr.jobs, n_pix, fr.kernel("shadow_origins"), lp, _ORIGINS))
        if not origins[8]:
            return _unbounded(fr, lp)
        bounded = fr.bounded & bool(np.isfinite(apex).all())
        p = bounds.shadow(fr.bnd, bounded, lo, hi, float(origins[9]), *limits, chord=float(origins[7]))
        return _ShadowBounds(p.radius, fr.tree.fit(p, apex=apex, jobs=fr.jobs))
    length, unit = _unit(light[native.LT_DIR:native.LT_DIR + 3])
    if not 0 < length < np.inf:  # cos is not finite at any point: no shadow ray
        return _unbounded(fr, lp)
    p = bounds.shadow(fr.bnd, fr.bounded, lo, hi, length, *limits, unit=unit, length=length)
    flat = fr.tree.fit(p, axes=_normal_plane(unit), jobs=fr.jobs)
    return _ShadowBounds(p.radius, flat, p.behind, length, unit)


def _unbounded(fr: _Frame, lp: native.LightPass) -> _ShadowBounds:
    """Bounds of infinite radii: every shadow ray tests every shape."""
    none = np.full(len(fr.sf), np.inf)
    everywhere = {"axes": np.eye(3)[:2]} if lp.parallel else {"apex": np.zeros(3)}
    return _ShadowBounds(none, fr.tree.refit(fr.bnd, none, **everywhere, jobs=fr.jobs))


def _unit(v: np.ndarray) -> tuple[float, np.ndarray]:
    """(|v|, v/|v|) in float64 (|v| is 0 or not finite where v/|v| means nothing; plain
    arithmetic, as numpy costs microseconds a call on 3-vectors)."""
    x, y, z = (float(c) for c in v)
    length = math.sqrt(x * x + y * y + z * z)
    if not 0 < length < math.inf:
        return length, np.full(3, math.nan)
    return length, np.array([x / length, y / length, z / length])


def _report_origins(outs: np.ndarray) -> np.ndarray:
    """shadow_origins' chunks merged: boxes joined, counts summed, extremes kept."""
    out = _ORIGINS.copy()
    out[:3], out[3:6], out[6:8] = outs[:, :3].min(axis=0), outs[:, 3:6].max(axis=0), outs[:, 6:8].max(axis=0)
    out[8], out[9] = outs[:, 8].sum(), outs[:, 9].min()
    return out


def _normal_plane(d: np.ndarray) -> np.ndarray:
    """Two orthonormal vectors (2, 3) normal to the unit vector d (plain arithmetic:
    numpy's cross product costs tens of microseconds on 3-vectors)."""
    x, y, z = (float(c) for c in d)
    e = (0.0, z, -y) if abs(x) < 0.9 else (-z, 0.0, x)  # d x (1, 0, 0) or d x (0, 1, 0)
    norm = math.sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2])
    e = (e[0] / norm, e[1] / norm, e[2] / norm)
    return np.array([e, (y * e[2] - z * e[1], z * e[0] - x * e[2], x * e[1] - y * e[0])])
