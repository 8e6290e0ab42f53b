"""The raytracer: nearest hit per pixel, diffuse lighting, shadow rays, NaN accounting.

The frame is rendered in bands of rows, so memory stays bounded at any size, with the
compiled kernels of ``csrc/datapath.inc``; each band is one compiled call
(``csrc/band.c`` render_band), and every pass in it splits over a team of ``--jobs``
threads (:mod:`.threads`; every pixel is computed the same way whatever the split, so the
image does not depend on it). Per band:

1. the primary directions' shortest and longest length (``directions`` stores a rotated
   camera's directions; a grid camera's come from its axes, once per frame);
2. the shape hierarchy's boxes for the primary rays, from the shapes' cull radii and
   depth floors (:mod:`.bvh`, :mod:`.bounds`; the tree itself is built once per frame,
   or kept from the frame before when the shapes did not move, and for a grid camera
   these bounds too, shared by its bands);
3. the nearest hit of every pixel, its hit point and normal (``nearest``, packets of a
   row's pixels walking the tree nearest node first);
4. per light, the hierarchy's boxes for its shadow rays, from the box of the band's hit
   points, then the light's colour with its shadow rays (``light_pass``);
5. colours, depth and provenance, packet by packet in the last light's pass (in the
   nearest-hit pass when there are no lights, or one shape: a lone shape casts no
   shadow, so that pass applies the lights itself and keeps nothing per pixel).

``docs/emulator.md`` sections 4-7 give the order of operations and why the hierarchy
never changes a pixel; :mod:`.reference` is the plain renderer the tests compare with.
"""

from __future__ import annotations

import math
from ctypes import addressof, byref, pointer
from dataclasses import dataclass
from time import perf_counter
from typing import Callable

import numpy as np

from ..errors import Rend3rError
from ..isa import Table, lookup
from ..isa.tables import PROP_LIMIT, SHAPE_TYPE_CODES
from ..recent import Recent
from . import bounds, bvh, native, threads
from .native import address
from .arith import Arith
from .camera import Rays, camera_key, camera_rays
from .frame import Frame
from .lights import POINT, Light, lights_from_scene, lights_key
from .options import EmuOptions
from .scene import Scene, prop_index
from .stats import FrameStats
from .workspace import arrays, empty

Progress = Callable[[float], None]
#: Pixels per band at most: bounds the per-pixel working arrays (about 100 bytes per pixel).
BAND_PIXELS = native.BAND_LIMIT
#: Pixels per band at least, and per shape and bundle of rays more (_band_rows).
BAND_LEAST, BAND_PER_SHAPE = 1 << 14, 64
#: Smallest chunk of pixels handed to a thread (a quarter of it where a pass would give a
#: thread fewer than eight: csrc/band.c pixel_parts), and the most chunks a pass takes per thread.
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
    lights: tuple[Light, ...]
    light_rows: np.ndarray
    light_frames: np.ndarray
    scales: np.ndarray
    jobs: int
    shapes: native.Shapes
    tree: bvh.Tree
    primary: _Primary | None  # a grid camera's primary bounds (None: each band measures its directions)
    waiting: _Waiting | None  # the bundle of those bounds, whose subtrees may wait to be made (else None)

    def kernel(self, name: str):
        """The compiled kernel ``name`` for this frame's precision."""
        return native.kernel(name, self.ar)


def render_frame(scene: Scene, options: EmuOptions, number: int = 0,
                 progress: Progress | None = None) -> tuple[Frame, FrameStats]:
    """Render the scene as the raytracer sees it; returns the frame and its stats."""
    start = perf_counter()
    with threads.team(options.jobs or threads.available_cores()) as team:  # the frame's every pass splits over it
        fr = set_up(scene, options)
        w, h, n_pix = options.width, options.height, options.pixels
        st = FrameStats(number=number, pixels=n_pix, shapes=len(fr.sf), lights=len(fr.lights), rays=n_pix)
        rgb, depth, prov = np.empty(n_pix, np.uint16), np.empty(n_pix, np.float32), np.empty(n_pix, np.int32)
        if not len(fr.sf):  # else every band's finish pass sets every pixel
            rgb[:], depth[:], prov[:] = options.background, np.inf, -1
        else:
            rows, at = _band_rows(fr, w), (address(rgb), address(depth), address(prov))
            bands, _arrays = _bands(fr, options, min(rows, h))  # _arrays: what the block points into
            for row0 in range(0, h, rows):
                row1 = min(h, row0 + rows)
                if native.library().render_band(byref(bands), row0, row1, at[0] + 2 * row0 * w,
                                                 at[1] + 4 * row0 * w, at[2] + 4 * row0 * w, team) < 0:
                    raise Rend3rError(f"rows {row0}..{row1} of a {w}x{h} frame need more working memory than "
                                      f"its bands were given ({bands.memory_bytes:,} bytes)")
                if progress is not None:
                    progress(row1 / h)
            for name, count in zip(_BAND_COUNTS, bands.counts):
                setattr(st, name, count)
    st.seconds = perf_counter() - start
    return Frame(number, rgb.reshape(h, w), depth.reshape(h, w), prov.reshape(h, w)), st


def _band_rows(fr: _Frame, width: int) -> int:
    """Rows per band. A lit frame of several shapes keeps per pixel what the nearest-hit pass
    found for the light passes (some 44 bytes a pixel in fp32): its bands stay near
    BAND_LEAST pixels, where those arrays stay in the cores' caches (a 16- or 256-sphere
    frame took an eighth to a quarter less than in one band), unless the bounds each band
    fits to its own rays (every light's shadow bundle, and for a turned camera the primary
    one: a pass over the shapes each, some 20 ns a shape) would take more than a small part
    of its work. Other frames keep nothing per pixel: bands of BAND_PIXELS. Never by the
    thread count: what each band's bounds skip shows in the stats' test counts, which must
    not depend on it."""
    pixels = BAND_PIXELS
    if fr.lights and len(fr.sf) > 1:
        bundles = len(fr.lights) + (fr.primary is None)
        pixels = min(pixels, max(BAND_LEAST, BAND_PER_SHAPE * len(fr.sf) * bundles))
    return max(1, pixels // width)


def set_up(scene: Scene, options: EmuOptions) -> _Frame:
    """What every band of the frame shares: camera, shape and light tables, the shape
    hierarchy and, for a grid camera, the primary rays' bounds."""
    ar = options.arith
    dtype = native.dtype(ar)
    cam = _CAMERAS.get(camera_key(scene, options, ar), lambda: _Camera.of(camera_rays(scene, options, ar), dtype))
    fmt = None if ar.native else native.Format.of(ar)
    jobs = options.jobs or threads.available_cores()
    sf, si, bnd, bounded, index, tree, primary, waiting = _shapes(scene, ar, fmt, cam.block, cam.extent, jobs)
    lit = _LIGHTS.get(lights_key(scene, ar, options.light_model),
                      lambda: _Lights.of(lights_from_scene(scene, ar, options.light_model), dtype))
    n = len(sf)
    view = native.Shapes(native.ptr(sf, dtype, (n, native.SF_COLUMNS)), native.ptr(si, np.int64, (n, native.SI_COLUMNS)),
                         native.ptr(bnd, np.float64, (n, native.B_COLUMNS)), n, ar.unit_roundoff, ar.tiny, fmt)
    return _Frame(ar, dtype, cam.block, cam.xs, cam.ys, cam.rotated, sf, si, index, bnd, bounded, lit.lights, lit.rows,
                  lit.frames, lit.scales, jobs, view, tree, primary, waiting)


@dataclass(frozen=True, eq=False)
class _Camera:
    """A camera as the kernels take it (read-only arrays): the block (csrc/kernels.h CAM_*),
    the axes, whether the directions are turned, and the primary directions' extent."""

    block: np.ndarray
    xs: np.ndarray
    ys: np.ndarray
    rotated: bool
    extent: tuple[float, float] | None

    @classmethod
    def of(cls, rays: Rays, dtype: np.dtype) -> _Camera:
        cam = np.zeros(native.CAM_COLUMNS, dtype)
        cam[native.CAM_ORIGIN:native.CAM_ORIGIN + 3] = [np.asarray(c, dtype) for c in rays.origin]
        cam[native.CAM_TMIN], cam[native.CAM_TMAX], cam[native.CAM_Z] = rays.tmin, rays.tmax, rays.z
        if rays.rotation is not None:  # the kernel turns (x[col], y[row], z) per pixel
            cam[native.CAM_ROT:native.CAM_ROT + 4] = [np.asarray(c, dtype) for c in rays.rotation]
        xs, ys = np.ascontiguousarray(rays.xs, dtype), np.ascontiguousarray(rays.ys, dtype)
        for a in (cam, xs, ys):
            a.flags.writeable = False
        rotated = rays.rotation is not None
        return cls(cam, xs, ys, rotated, _extent(cam, xs, ys, rotated))


@dataclass(frozen=True, eq=False)
class _Lights:
    """The lights that are on and their tables (read-only arrays, the lights' values too):
    the kernels' rows (csrc/kernels.h LT_*), what their shadow rays' bounds need (LF_*) and
    the colour scales."""

    lights: tuple[Light, ...]
    rows: np.ndarray
    frames: np.ndarray
    scales: np.ndarray

    @classmethod
    def of(cls, lights: list[Light], dtype: np.dtype) -> _Lights:
        rows = _light_rows(lights, dtype)
        out = cls(tuple(lights), rows, _light_frames(rows), _scales(lights))
        values = [v for lt in lights for v in (*lt.location, *lt.forward, lt.intensity) if isinstance(v, np.ndarray)]
        for a in (out.rows, out.frames, out.scales, *values):
            a.flags.writeable = False
        return out


#: The last few cameras and light sets set up, by what they are made of (camera_key,
#: lights_key): animation frames and repeated runs mostly keep them.
_CAMERAS: Recent[_Camera] = Recent(8)
_LIGHTS: Recent[_Lights] = Recent(8)


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
    primary directions' ``extent``, the primary rays' bounds and their bundle (whose
    subtrees may wait for the bands to make them); in one call on a team of
    ``jobs`` threads (csrc/setup.c frame_setup). Spheres with moderate maps are bounded
    (culled, csrc/bounds.h) in every format: a test that overflows is a miss, and a format
    too coarse for the bounds (docs/emulator.md section 7) gets infinite cull radii from
    them."""
    table = scene.objects
    values = np.ascontiguousarray(table.values, np.uint16)
    index = np.ascontiguousarray(table.index, np.int64)
    rows = len(index)
    dtype = native.dtype(ar)
    s = native.Setup(native.kernel_address("shape_tables", ar),
                     native.ptr(values, np.uint16, (rows, PROP_LIMIT)), address(index), rows, address(_SHAPE_PROPS),
                     address(_KINDS), native.ptr(cam, dtype, (native.CAM_COLUMNS,)), ar.tiny, fmt)
    sf, si, bnd, bounded, out, build = arrays(  # frame_setup fills them; build: its working copies
        ((rows, native.SF_COLUMNS), dtype), ((rows, native.SI_COLUMNS), np.int64),
        ((rows, native.B_COLUMNS), np.float64), (rows, np.uint8), (rows, np.int32),
        (rows * native.BUILD_BYTES // 8, np.uint64))
    memo, node, items, always, where = bvh.tree_room(rows)  # the tree: this thread's, from frame to frame
    s.sf, s.sf_row, s.si, s.bnd, s.bounded, s.index_out = (address(sf), sf.strides[0], address(si), address(bnd),
                                                           address(bounded), address(out))
    room = bvh.Tree(node[:max(1, 2 * rows)], items[:rows], always[:rows], where[:rows])
    s.node, s.items, s.always, s.where = address(room.node), address(room.items), address(room.always), address(where)
    s.room, s.memo = address(build), addressof(memo)
    s.jobs, s.isa, s.chunk = jobs, native.shape_isa(), bounds.SHAPE_CHUNK
    first = waiting = None
    if extent is not None:  # the primary bounds in the same call, around the camera origin
        apex = cam[native.CAM_ORIGIN:native.CAM_ORIGIN + 3].astype(np.float64)  # at infinity: nothing is bounded
        first = bounds.primary(bnd, bounded, apex, *extent, ar.unit_roundoff, ar.tiny, ar.overflow)
        fitted, own = room.bounds_for(first.block, apex, None, room.nodes, False, jobs)
        waiting = _Waiting(first, own, empty(room.nodes, np.uint8))  # the bands may make its subtrees
        first.block.lazy, first.block.lazy_items = address(waiting.state), bounds.LAZY_ITEMS
    with threads.team(jobs) as team:
        n = native.library().frame_setup(byref(s), None if first is None else byref(first.block), team)
    tree = bvh.Tree(room.node[:s.nodes], room.items[:s.counts[0]], room.always[:s.counts[1]], room.where[:n])
    primary = None if first is None else \
        (bvh.Bounds(tree, fitted.box[:s.nodes], fitted.frame), first.floor[:n], first.pc[:n],
         first.pc32[:n])
    return sf[:n], si[:n], bnd[:n], bounded[:n], out[:n], tree, primary, waiting


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
    n, nl = len(fr.sf), len(fr.lights)
    band = _band_block(fr, options)
    band.row0 = y
    shape_out = np.zeros((n, native.TRACE_SHAPE_VALUES))
    light_out = np.zeros((nl, native.TRACE_LIGHT_VALUES))
    nearest = np.zeros(1, np.int64)
    colour = fr.kernel("trace_pixel")(byref(band), int(options.intensity_fixed), int(n > 1), address(fr.light_rows),
                                      address(fr.scales), nl, x, y, address(shape_out), address(light_out),
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


def _band_block(fr: _Frame, options: EmuOptions) -> native.Band:
    """The kernels' Band block with the frame's fields (the arrays of ``fr`` back it)."""
    dtype = fr.dtype
    return native.Band(pointer(fr.shapes), native.ptr(fr.cam, dtype, (native.CAM_COLUMNS,)),
                       native.ptr(fr.xs, dtype, (options.width,)), native.ptr(fr.ys, dtype, (options.height,)),
                       int(fr.rotated), int(bool(fr.lights)), options.width, 0, native.row_magic(options.width))


def _scales(lights: list[Light]) -> np.ndarray:
    """Each light's colour channels over their largest value (lights, 3)."""
    return np.array([[((lt.color >> shift) & top) / top for shift, top in _CHANNELS] for lt in lights]).reshape(-1, 3)


def _bands(fr: _Frame, options: EmuOptions, rows: int) -> tuple[native.Bands, list]:
    """The block csrc/band.c render_band renders each band of the frame with (bands of
    ``rows`` rows at most, and their working memory), and the arrays it points into (they
    must outlive it)."""
    band, keep = _band_block(fr, options), []
    primary = fr.primary
    b = native.Bands(pointer(band))
    if primary is None:  # directions per pixel: each band fits this bundle to its own
        apex = fr.cam[native.CAM_ORIGIN:native.CAM_ORIGIN + 3].astype(np.float64)  # at infinity: nothing is bounded
        p = bounds.primary(fr.bnd, fr.bounded, apex, 0.0, 0.0, fr.ar.unit_roundoff, fr.ar.tiny, fr.ar.overflow)
        fitted, own = fr.tree.bounds_for(p.block, apex, None, fr.tree.nodes, False, fr.jobs)
        primary = (fitted, p.floor, p.pc, p.pc32)
        b.primary = pointer(p.block)
        keep += [p, own]
    elif fr.waiting is not None:  # the frame's bundle: the bands make its waiting subtrees
        band.lazy = addressof(fr.waiting.made.block)
    tree, floor, pc, pc32 = primary
    band.pc, band.pc32, band.floor, band.tree = address(pc), address(pc32), address(floor), tree.view
    band.index, band.background = address(fr.index), options.background
    keep.append(primary)
    for name in ("directions", "nearest", "light_pass", "shadow_origins"):
        setattr(b, name, native.kernel_address(name, fr.ar))
    b.light_rows, b.light_row, b.lights = address(fr.light_rows), fr.light_rows.strides[0], len(fr.lights)
    b.light_frames, b.scales = address(fr.light_frames), address(fr.scales)
    b.fixed, b.item, b.bounded, b.items = int(options.intensity_fixed), fr.dtype.itemsize, address(fr.bounded), \
        len(fr.tree.items)
    b.overflow, b.jobs, b.isa, b.chunk = fr.ar.overflow, fr.jobs, native.shape_isa(), bounds.SHAPE_CHUNK
    b.min_chunk, b.chunks_per_job = MIN_CHUNK, CHUNKS_PER_JOB
    b.memory_bytes = native.library().band_bytes(byref(b), rows * options.width)
    memory = empty(b.memory_bytes, np.uint8)
    b.memory = address(memory)
    keep.append(memory)
    return b, keep


#: What render_band counts (csrc/kernels.h BC_*, in this order).
_BAND_COUNTS = ("tests", "skipped", "nan_tests", "nan_rays", "hits", "shadow_rays")


@dataclass(frozen=True)
class _Waiting:
    """A frame's primary bundle, whose subtrees may wait to be made until a packet first
    enters them (``csrc/setup.c`` bundle_lazy, lazy_refine): what the bands then need.
    Until a band makes a subtree, its shapes' floors and cull data and the nodes below its
    root hold nothing."""

    made: bounds.Pass  # the bundle's block and the arrays it points at
    own: np.ndarray  # its items' cones (csrc/kernels.h CI_COLUMNS)
    state: np.ndarray  # per node, csrc/kernels.h LAZY_*


#: A frame's (or band's) primary bounds: the hierarchy's, and per shape its depth floor
#: and cull data, double and float (set_up, or _bands for a camera whose directions are
#: measured per pixel).
_Primary = tuple[bvh.Bounds, np.ndarray, np.ndarray, np.ndarray]


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


def _light_frames(rows: np.ndarray) -> np.ndarray:
    """Per light, what its shadow rays' bounds need (lights, LF_COLUMNS; csrc/kernels.h
    LF_*): whether it is directional, a point light's location, a directional light's
    l / |l|, |l| and two unit axes normal to l."""
    out = np.zeros((len(rows), native.LF_COLUMNS))
    for row, light in zip(out, rows.tolist()):  # Python floats: numpy takes microseconds a call on 3-vectors
        length, unit = _unit(light[native.LT_DIR:native.LT_DIR + 3])
        axes = _normal_plane(unit) if 0 < length < math.inf else (0.0,) * 6
        row[:] = (light[native.LT_KIND] != native.LIGHT_POINT, *light[native.LT_LOC:native.LT_LOC + 3], *unit, length,
                  *axes)
    return out


def _unit(v: list[float]) -> tuple[float, tuple[float, ...]]:
    """(|v|, v/|v|) in float64 (|v| is 0 or not finite where v/|v| means nothing)."""
    x, y, z = v
    length = math.sqrt(x * x + y * y + z * z)
    if not 0 < length < math.inf:
        return length, (math.nan,) * 3
    return length, (x / length, y / length, z / length)


def _normal_plane(d: tuple[float, ...]) -> tuple[float, ...]:
    """Two orthonormal vectors normal to the unit vector d, one after the other."""
    x, y, z = d
    e = (0.0, z, -y) if abs(x) < 0.9 else (-z, 0.0, x)  # d x (1, 0, 0) or d x (0, 1, 0)
    norm = math.sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2])
    e = (e[0] / norm, e[1] / norm, e[2] / norm)
    return (*e, y * e[2] - z * e[1], z * e[0] - x * e[2], x * e[1] - y * e[0])
