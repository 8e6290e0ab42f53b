"""A REND3R program's frames, their difference from fp64, and pixel histories, all from
the emulator's own functions (:func:`run_program`, :func:`trace_raytrace`,
:func:`trace_raster`): the view shows what ``rend3r emulate`` computes."""

from __future__ import annotations

import io
import warnings
from collections import OrderedDict
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import replace

import numpy as np

from .params import RequestError

#: Bytes of rendered frames kept for reuse (older option sets are dropped first).
CACHE_BYTES = 128 << 20
#: A pixel history lists every shape's stages up to this many shapes; beyond it, the
#: shapes that were hit (in either precision) unless all are asked for.
ALL_SHAPES_UP_TO = 64


@contextmanager
def quiet_numpy() -> Iterator[None]:
    """Extreme values are the renderer's documented input (``rend3r emulate`` hides numpy's
    warnings about them the same way)."""
    with np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        yield


def png(rgb888: np.ndarray) -> bytes:
    """An (H, W, 3) uint8 image as PNG bytes."""
    from PIL import Image

    buf = io.BytesIO()
    Image.fromarray(rgb888, "RGB").save(buf, format="PNG")
    return buf.getvalue()


def frame_count(words: Sequence[int], options, most: int) -> int:
    """Frames the program renders, at most ``most`` (a looping program: ``most``)."""
    from ..emu.processor import execute

    count = execute(words, options, most).frames
    if count == 0:
        raise RequestError("the program renders no frame (no nf is executed)", 422)
    return count


class FrameCache:
    """Rendered frames (RGB565) per (program version, options), least recently used dropped
    first beyond :data:`CACHE_BYTES`."""

    def __init__(self, budget: int = CACHE_BYTES) -> None:
        self.budget = budget
        self._frames: OrderedDict[tuple, list[np.ndarray]] = OrderedDict()

    def frame(self, version: int, words: Sequence[int], options, number: int) -> np.ndarray:
        """Frame ``number`` of the program (its frames up to it are rendered and kept)."""
        from ..emu.run import run_program

        key = (version, options)
        frames = self._frames.get(key)
        if frames is None or len(frames) <= number:
            frames = []
            with quiet_numpy():
                run_program(words, options, number + 1, lambda f: frames.append(f.rgb565), keep_frames=False)
            self._frames[key] = frames
        self._frames.move_to_end(key)
        while len(self._frames) > 1 and sum(f.nbytes for fs in self._frames.values() for f in fs) > self.budget:
            self._frames.popitem(last=False)
        return frames[number]


def reference(options):
    """The same options in fp64: the clean picture the scene describes."""
    return replace(options, precision="fp64")


def difference(work: np.ndarray, ref: np.ndarray) -> tuple[np.ndarray, dict]:
    """A heatmap of two RGB888 frames (black: equal; dark red to yellow: the largest channel
    difference, 1 to 255) and its figures."""
    d = np.abs(work.astype(np.int16) - ref.astype(np.int16)).max(axis=2)
    heat = np.zeros(work.shape, dtype=np.uint8)
    differs = d > 0
    heat[..., 0] = np.where(differs, 96 + d * 159 // 255, 0)
    heat[..., 1] = np.clip(2 * d - 255, 0, 255)
    return heat, {"differing_pixels": int(differs.sum()), "max_difference": int(d.max(initial=0)),
                  "pixels": int(d.size)}


class TraceCache:
    """The last few pixel traces per (program version, options, frame, pixel): changing the
    working precision at one pixel traces fp64 once."""

    def __init__(self, size: int = 8) -> None:
        self.size = size
        self._traces: OrderedDict[tuple, list[dict]] = OrderedDict()

    def trace(self, version: int, words: Sequence[int], options, frame: int, x: int, y: int) -> list[dict]:
        key = (version, options, frame, x, y)
        if key not in self._traces:
            self._traces[key] = trace(words, options, frame, x, y)
            while len(self._traces) > self.size:
                self._traces.popitem(last=False)
        self._traces.move_to_end(key)
        return self._traces[key]


def trace(words: Sequence[int], options, frame: int, x: int, y: int) -> list[dict]:
    """The records ``rend3r emulate --trace-pixel X,Y`` prints for frame ``frame``."""
    from ..emu.processor import execute
    from ..emu.trace import trace_raster, trace_raytrace

    if options.mode == "hybrid":
        raise RequestError("hybrid frames have no pixel trace (docs/trace.md)", 422)
    tracer = trace_raster if options.mode == "raster" else trace_raytrace
    out: list[dict] = []

    def on_nf(scene, number: int) -> None:
        if number == frame:
            tracer(scene, options, number, [(x, y)], out.append)

    with quiet_numpy():
        execute(words, options, frame + 1, on_nf)
    return out


def _occurrences(records: list[dict]) -> Iterator[tuple]:
    """(shape, stage, occurrence) of each record, as ``rend3r trace-diff`` matches them."""
    seen: dict[tuple, int] = {}
    for r in records:
        k = (r["shape"], r["stage"])
        seen[k] = seen.get(k, -1) + 1
        yield (*k, seen[k])


def _agreement(ar, work: list[dict], ref: list[dict]) -> tuple[list[dict | None], np.ndarray, np.ndarray]:
    """Each working record's fp64 record (matched by shape, stage and occurrence, as
    ``rend3r trace-diff`` matches), whether the two agree (integers and flags equal, values
    equal to the fp64 value rounded to the working format, NaN to NaN), and which records
    are integers or flags."""
    keys = [(r["shape"], r["stage"]) for r in work]
    if keys == [(r["shape"], r["stage"]) for r in ref]:  # the same path: records pair in order
        pairs: list[dict | None] = list(ref)
    else:
        by_key = dict(zip(_occurrences(ref), ref))
        pairs = [by_key.get(key) for key in _occurrences(work)]
    n = len(work)
    integer = np.fromiter((type(r["dec"]) is int for r in work), dtype=bool, count=n)
    paired = np.fromiter((f is not None for f in pairs), dtype=bool, count=n)
    # "nan", "inf" and "-inf" read as themselves; integers (at most 64-bit flags, colours,
    # indices) compare exactly as floats below 2**53, as every one of them is
    mine = np.array([float(r["dec"]) for r in work], dtype=np.float64)
    theirs = np.array([float(f["dec"]) if f is not None else np.nan for f in pairs], dtype=np.float64)
    with quiet_numpy():
        rounded = np.asarray(ar.round(theirs), dtype=np.float64)
    same_value = (mine == rounded) | (np.isnan(mine) & np.isnan(rounded))
    return pairs, paired & np.where(integer, mine == theirs, same_value), integer


#: How the shape shown is chosen: raytracing, then each raster visibility rule
#: (docs/emulator.md, docs/raster.md).
TIE_RULES = {"raytrace": "the smallest sq_dist wins; equal distances go to the lower shape index (docs/emulator.md)",
             "zbuffer": "the depth buffer keeps the earlier triangle on equal depth (docs/raster.md)",
             "painter": "painter's order by centroid distance, far to near; equal distances keep index order (docs/raster.md)",
             "index": "no depth order: later triangles paint over earlier ones (quirk raster-index-order)"}


def _hits(work: list[dict], ref: list[dict]) -> list[dict]:
    """The shapes a raytraced pixel's ray hit, nearest first (ties in index order), with
    their squared distances in both runs."""
    def distances(records: list[dict]) -> dict[int, object]:
        hit = {r["shape"] for r in records if r["stage"] == "hit" and r["dec"] == 1}
        return {r["shape"]: r["dec"] for r in records if r["stage"] == "sq_dist" and r["shape"] in hit}

    mine, theirs = distances(work), distances(ref)
    order = sorted(mine, key=lambda shape: (float(mine[shape]), shape))
    return [{"shape": shape, "sq_dist": mine[shape], "fp64_sq_dist": theirs.get(shape)} for shape in order]


def _first(flags: np.ndarray) -> int | None:
    """The index of the first true flag, None when there is none."""
    where = np.flatnonzero(flags)
    return int(where[0]) if len(where) else None


def _row(record: dict, ref: dict | None, agrees: bool) -> dict:
    """A trace record with its fp64 value beside it."""
    return {**record, "fp64": None if ref is None else {"hex": ref["hex"], "dec": ref["dec"]}, "diverges": not agrees}


def history(words: Sequence[int], options, frame: int, x: int, y: int, all_shapes: bool,
            traces: TraceCache | None = None, version: int = 0) -> dict:
    """A pixel's trace records, each with its fp64 record beside it and whether the two
    disagree; the first disagreeing value and the first disagreeing decision (an integer
    or flag: hit, nearest, shadow, colour) are marked; a raytraced pixel's hits are listed
    nearest first. ``traces`` keeps traces between
    calls (for the program's ``version``)."""
    if not (0 <= x < options.width and 0 <= y < options.height):
        raise RequestError(f"pixel {x},{y} is outside the {options.width}x{options.height} frame")
    traces = traces or TraceCache()
    work = traces.trace(version, words, options, frame, x, y)
    ref = traces.trace(version, words, reference(options), frame, x, y)
    ar = options.arith
    pairs, agree, integer = _agreement(ar, work, ref)
    first = _first(~agree)
    decision = _first(~agree & integer)
    split = next((i for i, r in enumerate(work) if r["stage"] == "nearest"), len(work))
    shapes = {r["shape"] for r in work[:split]}
    keep = shapes
    if len(shapes) > ALL_SHAPES_UP_TO and not all_shapes:
        keep = {r["shape"] for r in work + ref if r["stage"] == "hit" and r["dec"] == 1}
        keep |= {r["dec"] for r in work + ref if r["stage"] == "nearest"}
        keep |= {work[i]["shape"] for i in (first, decision) if i is not None and i < split}
    shown = [i for i in range(len(work)) if i >= split or work[i]["shape"] in keep]
    index = {i: n for n, i in enumerate(shown)}
    records = [_row(work[i], pairs[i], bool(agree[i])) for i in shown]
    return {"frame": frame, "pixel": [x, y], "precision": options.precision, "label": ar.label,
            "mode": options.mode, "shapes": len(shapes), "shapes_shown": len(keep & shapes), "records": records,
            "first_divergence": None if first is None else index[first],
            "first_decision": None if decision is None else index[decision],
            "hits": _hits(work, ref) if options.mode == "raytrace" else None, "tie_rule": TIE_RULES["raytrace" if options.mode == "raytrace" else options.depth]}
