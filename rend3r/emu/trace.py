"""Pixel traces: every working-precision intermediate of chosen pixels (``docs/trace.md``).

A raytraced pixel is computed by the compiled kernels' own functions (``trace_pixel`` in
``csrc/datapath.inc``: the same transform, solve, nearest-hit rule, lighting and shadow
test the frame uses, keeping every intermediate); a rasterized pixel by the
rasterizer's own functions with a recording hook. The trace shows what the frame
computed, not a re-derivation.
"""

from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass, replace
from typing import Callable, Iterable, Iterator, Sequence

import numpy as np

from ..precision.stages import VALUE_STAGES
from .arith import Arith
from .options import EmuOptions
from .scene import Scene

Emit = Callable[[dict], None]


def encode(ar: Arith, values, stage: str | None = None) -> tuple[list[str], list[float | str]]:
    """(hex bits in the format of ``stage``, the working format for None; decimal) of each
    working-precision value of an array, all at once."""
    arr = np.asarray(values).reshape(-1)
    bits, digits = ar.bits_array(arr, stage)
    hexes = [f"0x{b:0{digits}x}" for b in bits.tolist()]
    return hexes, decimals(arr)


def decimals(values: np.ndarray) -> list[float | str]:
    """The records' ``dec`` of working-precision values: floats, non-finite ones as text."""
    decs: list[float | str] = values.astype(np.float64).tolist()
    for i in np.flatnonzero(~np.isfinite(values)).tolist():
        decs[i] = "nan" if math.isnan(decs[i]) else ("inf" if decs[i] > 0 else "-inf")
    return decs


def _int_records(values) -> tuple[list[str], list[int]]:
    """(signed hex, value) of each integer or flag."""
    ints = [int(v) for v in values]
    return [f"-0x{-v:x}" if v < 0 else f"0x{v:x}" for v in ints], ints


def _column(ar: Arith, stage: str, values, integer: bool = False) -> tuple[list[str], list]:
    """(hexes, decimals) of one stage's values (e.g. one per shape)."""
    return _int_records(values) if integer else encode(ar, values, _value_stage(ar, stage))


class _Writer:
    """Turns (stage, values) into records for one pixel."""

    def __init__(self, ar: Arith, emit: Emit, frame: int, pixel: tuple[int, int]) -> None:
        self.ar, self.emit, self.frame, self.pixel = ar, emit, frame, pixel

    def rows(self, stages: Sequence[str], columns: Sequence[tuple[list[str], list]], shapes: Sequence[int | None]) -> None:
        """For each shape in order, a record of each stage: ``columns[k]`` holds stage k's
        (hexes, decimals), one per shape."""
        frame, (x, y), emit = self.frame, self.pixel, self.emit
        for n, shape in enumerate(shapes):
            for stage, (hexes, decs) in zip(stages, columns):
                emit({"frame": frame, "pixel": [x, y], "shape": shape, "stage": stage, "hex": hexes[n], "dec": decs[n]})

    def record(self, stage: str, shape: int | None, hx: str, dec) -> None:
        """One record of an encoded value."""
        self.emit({"frame": self.frame, "pixel": list(self.pixel), "shape": shape, "stage": stage, "hex": hx, "dec": dec})

    def put(self, stage: str, value, shape: int | None, integer: bool = False) -> None:
        """The record of one value."""
        (hx,), (dec,) = _column(self.ar, stage, [value], integer)
        self.record(stage, shape, hx, dec)


def _value_stage(ar: Arith, name: str) -> str | None:
    """The datapath stage of a traced value (per-stage maps; raster values: the base)."""
    return VALUE_STAGES.get(name.split(".", 1)[1] if name.startswith("L") else name) if ar.stages else None


_PIXEL = re.compile(r"\s*(-?[0-9]{1,9})\s*,\s*(-?[0-9]{1,9})\s*", re.ASCII)


def parse_pixel(text: str) -> tuple[int, int]:
    """``"X,Y"`` -> (x, y): decimal integers of at most 9 digits (the frame's range is checked later)."""
    m = _PIXEL.fullmatch(text)
    if not m:
        shown = text if len(text) <= 40 else text[:37] + "..."
        raise ValueError(f"expected X,Y such as 252,188, not {shown!r}")
    return int(m[1]), int(m[2])


#: The stages a raytraced pixel records for each shape, in order.
SHAPE_STAGES = ("origin.x", "origin.y", "origin.z", "dir.x", "dir.y", "dir.z", "a2", "b", "c2", "disc", "sqrt",
                "t1", "t2", "t", "hit", "sq_dist", "point.x", "point.y", "point.z", "normal.x", "normal.y", "normal.z")
_LIGHT_STAGES = ("l.x", "l.y", "l.z", "n_dot_l", "n_len", "l_len", "denom", "cos", "f")
_FIXED, _LIT, _SHADOW = 9, 10, 11


@dataclass(frozen=True)
class Trace:
    """One pixel's records (``docs/trace.md``): first a table of :data:`SHAPE_STAGES`, one
    row per shape (raytracing; values kept as arrays, made records when asked), then the
    other records."""

    ar: Arith
    frame: int
    pixel: tuple[int, int]
    shapes: np.ndarray  # (rows,) the table's shape indices
    values: np.ndarray  # (rows, len(SHAPE_STAGES)) working-precision values
    rest: list[dict]

    def columns(self, rows: np.ndarray | None = None) -> list[tuple[list[str], list]]:
        """Each stage's (hexes, decimals) over the table's ``rows`` (all: None)."""
        values = self.values if rows is None else self.values[rows]
        return [_column(self.ar, stage, values[:, k], integer=stage == "hit") for k, stage in enumerate(SHAPE_STAGES)]

    def table_records(self, rows: np.ndarray | None = None) -> list[dict]:
        """The records of the table's ``rows`` (all: None), row by row."""
        out: list[dict] = []
        shapes = self.shapes if rows is None else self.shapes[rows]
        _Writer(self.ar, out.append, self.frame, self.pixel).rows(SHAPE_STAGES, self.columns(rows), shapes.tolist())
        return out

    def records(self) -> list[dict]:
        """Every record, in order."""
        return self.table_records() + self.rest


def trace_raytrace(scene: Scene, options: EmuOptions, frame: int, pixels: Iterable[tuple[int, int]], emit: Emit) -> None:
    """Emit the records of each pixel of one raytraced frame (``docs/trace.md`` order)."""
    for t in raytrace_traces(scene, options, frame, pixels):
        for record in t.records():
            emit(record)


def raytrace_traces(scene: Scene, options: EmuOptions, frame: int, pixels: Iterable[tuple[int, int]]) -> Iterator[Trace]:
    """The trace of each pixel of one raytraced frame."""
    from .raytracer import set_up, trace_pixel

    ar = options.arith
    fr = set_up(scene, options)
    for x, y in pixels:
        rest: list[dict] = []
        w = _Writer(ar, rest.append, frame, (x, y))
        t = trace_pixel(fr, options, x, y)
        winner = int(fr.index[t.nearest]) if t.nearest >= 0 else None
        # A winner whose hit point or lighting is not finite is a miss in the frame
        # (background, provenance -1): nearest says so too; its light stages show why.
        shown = None if t.colour is None else winner
        w.put("nearest", -1 if shown is None else shown, shown, integer=True)
        if winner is not None:
            for light, values in zip(fr.lights, t.lights):
                tag = f"L{light.index}."
                for stage, value in zip(_LIGHT_STAGES, values):
                    w.put(tag + stage, value, winner)
                if options.intensity_fixed:
                    w.put(tag + "fixed", int(values[_FIXED]), winner, integer=True)
                if values[_LIT]:
                    w.put(tag + "shadow", int(values[_SHADOW]), winner, integer=True)
        w.put("colour", options.background if t.colour is None else t.colour, shown, integer=True)
        yield Trace(ar, frame, (x, y), fr.index[: len(t.shapes)].copy(), t.shapes, rest)


def trace_raster(scene: Scene, options: EmuOptions, frame: int, pixels: Iterable[tuple[int, int]], emit: Emit) -> None:
    """Emit the records of each pixel of one rasterized frame (``docs/trace.md``)."""
    for t in raster_traces(scene, options, frame, pixels):
        for record in t.records():
            emit(record)


def raster_traces(scene: Scene, options: EmuOptions, frame: int, pixels: Iterable[tuple[int, int]]) -> Iterator[Trace]:
    """The trace of each pixel of one rasterized frame (no table: every record is a rest).

    Per triangle (index order): its camera-space vertices, their projection steps (for a
    triangle the near plane or guard band clips, the unclipped vertices' projection, with
    ``clipped`` = 1), its normal and lighting; then per pixel the frame's ``nearest``,
    ``depth`` and ``colour``, from the rasterizer's own render of the frame.
    """
    from .lights import lights_from_scene
    from .raster import clip_planes_for, frame_view, render_frame, to_camera, triangles_from_scene, project
    from .raster_clip import clip_triangles
    from .raster_shade import flat_colours

    ar = replace(options.arith, stages=())  # the rasterizer works in the base precision
    index, tris, colours = triangles_from_scene(scene, ar, options.raster_next_triangle)
    lights = lights_from_scene(scene, ar, options.light_model)
    view = frame_view(scene, options)
    result, _ = render_frame(scene, options, frame)
    for x, y in pixels:
        rest: list[dict] = []
        w = _Writer(ar, rest.append, frame, (x, y))
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
        yield Trace(ar, frame, (x, y), np.zeros(0, np.int64), np.zeros((0, len(SHAPE_STAGES))), rest)


def _put_all(w: _Writer, stage: str, values, shape: int | None) -> None:
    """Record a lighting stage (0-d, or one value per traced point; empty: not reached)."""
    arr = np.asarray(values).reshape(-1)
    for hx, dec in zip(*_column(w.ar, stage, arr, integer=arr.dtype.kind in "biu")):
        w.record(stage, shape, hx, dec)


def jsonl_sink(stream) -> Emit:
    """An Emit that writes one compact JSON object per line to ``stream``."""
    encode = json.JSONEncoder(separators=(", ", ": ")).encode  # made once: json.dumps makes one per call
    return lambda record: stream.write(encode(record) + "\n")
