"""Pixel traces: every working-precision intermediate of chosen pixels (``docs/trace.md``).

The traced pixel is run through the renderer's own functions on a batch that holds it
once per shape (the raycaster's ``to_object``, ``origin_term``, ``solve``,
``squared_distance``, ``surface``; the raytracer's nearest-hit rule and shading with a
recording hook), so the trace shows what the frame computed, not a re-derivation.
"""

from __future__ import annotations

import json
import math
from typing import Callable, Iterable

import numpy as np

from .arith import Arith
from .camera import camera_rays
from .options import EmuOptions
from .scene import Scene
from .shapes import origin_term, shapes_from_scene, solve, squared_distance, surface, to_object
from .vec import dot

Emit = Callable[[dict], None]
_BITS = {"fp16": (np.float16, np.uint16, 4), "fp32": (np.float32, np.uint32, 8), "fp64": (np.float64, np.uint64, 16)}


def encode_value(ar: Arith, value: float) -> tuple[str, float | str]:
    """(hex bits in the working format, decimal) of one working-precision value."""
    ftype, itype, digits = _BITS[ar.precision]
    bits = int(np.asarray(value, dtype=ftype).view(itype))
    v = float(value)
    dec: float | str = v if math.isfinite(v) else ("nan" if math.isnan(v) else ("inf" if v > 0 else "-inf"))
    return f"0x{bits:0{digits}x}", dec


def _int_record(value: int) -> tuple[str, int]:
    return (f"-0x{-value:x}" if value < 0 else f"0x{value:x}"), value


class _Writer:
    """Turns (stage, values) into records for one pixel; arrays hold one value per shape."""

    def __init__(self, ar: Arith, emit: Emit, frame: int, pixel: tuple[int, int]) -> None:
        self.ar, self.emit, self.frame, self.pixel = ar, emit, frame, pixel

    def put(self, stage: str, value, shape: int | None, integer: bool = False) -> None:
        hx, dec = _int_record(int(value)) if integer else encode_value(self.ar, value)
        self.emit({"frame": self.frame, "pixel": list(self.pixel), "shape": shape, "stage": stage, "hex": hx, "dec": dec})


def parse_pixel(text: str) -> tuple[int, int]:
    """``"X,Y"`` -> (x, y)."""
    try:
        x, y = (int(v) for v in text.split(","))
    except ValueError:
        raise ValueError(f"expected X,Y such as 252,188, not {text!r}") from None
    return x, y


def trace_raytrace(scene: Scene, options: EmuOptions, frame: int, pixels: Iterable[tuple[int, int]], emit: Emit) -> None:
    """Emit the records of each pixel of one raytraced frame (``docs/trace.md`` order)."""
    from .raytracer import _Nearest, shade_hits
    from .cull import shape_bounds
    from .lights import lights_from_scene
    from .stats import FrameStats

    ar = options.arith
    rays = camera_rays(scene, options, ar)
    shapes = shapes_from_scene(scene, ar)
    lights = lights_from_scene(scene, ar, options.light_model)
    n = len(shapes)
    slots = np.arange(n)
    for x, y in pixels:
        w = _Writer(ar, emit, frame, (x, y))
        p = y * options.width + x
        D1 = tuple(np.broadcast_to(d, (options.pixels,))[p : p + 1] for d in rays.direction)
        D = tuple(np.repeat(c, n) for c in D1)
        S, Dh = to_object(ar, shapes, rays.origin, D)
        c2 = origin_term(ar, shapes, S)
        sol = solve(ar, shapes, S, Dh, c2, rays.tmin, rays.tmax)
        sqd = squared_distance(ar, dot(ar, D1, D1), sol.t)
        point, normal = surface(ar, shapes, S, Dh, sol.t, rays.origin, D)
        hit = sol.hit & np.isfinite(sqd)
        for k in range(n):
            idx = int(shapes.index[k])
            for axis in range(3):
                w.put(f"origin.{'xyz'[axis]}", S[axis][k], idx)
            for axis in range(3):
                w.put(f"dir.{'xyz'[axis]}", Dh[axis][k], idx)
            for stage, arr in (("a2", sol.a2), ("b", sol.b), ("c2", c2), ("disc", sol.disc), ("sqrt", sol.root),
                               ("t1", sol.t1), ("t2", sol.t2), ("t", sol.t)):
                w.put(stage, arr[k], idx)
            w.put("hit", int(hit[k]), idx, integer=True)
            w.put("sq_dist", sqd[k], idx)
            for axis in range(3):
                w.put(f"point.{'xyz'[axis]}", np.broadcast_to(point[axis], (n,))[k], idx)
            for axis in range(3):
                w.put(f"normal.{'xyz'[axis]}", normal[axis][k], idx)
        near = _Nearest(1, ar.dtype)
        near.update(np.zeros(int(hit.sum()), dtype=np.int64), slots[hit], sqd[hit])
        best = int(near.slot[0]) if near.slot[0] != np.iinfo(np.int64).max else -1
        shown = int(shapes.index[best]) if best >= 0 else None
        w.put("nearest", -1 if shown is None else shown, shown, integer=True)
        colour = options.background
        if best >= 0:
            one = np.array([best])
            pt = tuple(np.broadcast_to(c, (n,))[one] for c in point)
            nm = tuple(c[one] for c in normal)
            rgb, bad = shade_hits(
                ar, options, shapes, shape_bounds(shapes), lights, np.array([p]), one, pt, nm,
                FrameStats(), np.zeros(options.pixels, dtype=bool),
                record=lambda stage, v: _put_all(w, stage, v, shown),
            )
            if not bad[0]:
                colour = int(rgb[0])
        w.put("colour", colour, shown, integer=True)


def trace_raster(scene: Scene, options: EmuOptions, frame: int, pixels: Iterable[tuple[int, int]], emit: Emit) -> None:
    """Emit the records of each pixel of one rasterized frame (``docs/trace.md``).

    Per triangle (index order): its camera-space vertices, their projection steps (for a
    triangle the near plane or guard band clips, the unclipped vertices' projection, with
    ``clipped`` = 1), its normal and lighting; then per pixel the frame's ``nearest``,
    ``depth`` and ``colour``, from the rasterizer's own render of the frame.
    """
    from .lights import lights_from_scene
    from .raster import clip_planes_for, frame_view, render_frame, to_camera, triangles_from_scene, project
    from .raster_clip import clip_triangles
    from .raster_shade import flat_colours

    ar = options.arith
    index, tris, colours = triangles_from_scene(scene, ar, options.raster_next_triangle)
    lights = lights_from_scene(scene, ar, options.light_model)
    view = frame_view(scene, options)
    result, _ = render_frame(scene, options, frame)
    for x, y in pixels:
        w = _Writer(ar, emit, frame, (x, y))
        for k in range(len(index)):
            idx = int(index[k])
            one = tris[k : k + 1]
            cam = to_camera(ar, one, view)
            for v in range(3):
                for axis in range(3):
                    w.put(f"cam.v{v + 1}.{'xyz'[axis]}", cam[0, v, axis], idx)
            clipped = clip_triangles(ar, cam, clip_planes_for(ar, view, options.width, options.height)).clipped
            w.put("clipped", clipped, idx, integer=True)
            for v in range(3):
                project(ar, cam[0, v : v + 1], view, options.width, options.height,
                        record=lambda stage, value, v=v: w.put(f"v{v + 1}.{stage}", np.reshape(value, -1)[0], idx))
            if options.raster_shading:
                flat_colours(ar, one, colours[k : k + 1], lights, options.intensity_fixed,
                             record=lambda stage, value: _put_all(w, stage, value, idx))
        shown = int(result.provenance[y, x])
        tri = None if shown < 0 else shown
        w.put("nearest", shown, tri, integer=True)
        w.put("depth", ar.round(result.depth[y, x]), tri)
        w.put("colour", int(result.rgb565[y, x]), tri, integer=True)


def _put_all(w: _Writer, stage: str, values, shape: int | None) -> None:
    """Record a lighting stage (0-d, or one value per traced point; empty: not reached)."""
    arr = np.asarray(values).reshape(-1)
    integer = arr.dtype.kind in "biu"
    for v in arr:
        w.put(stage, int(v) if integer else v, shape, integer=integer)


def jsonl_sink(stream) -> Emit:
    """An Emit that writes one compact JSON object per line to ``stream``."""
    return lambda record: stream.write(json.dumps(record, separators=(", ", ": ")) + "\n")
