"""A REND3R program's frames, their difference from fp64, and pixel histories, all from
the emulator's own functions (:func:`run_program`, :func:`raytrace_traces`,
:func:`raster_traces`): the view shows what ``rend3r emulate`` computes."""

from __future__ import annotations

import io
import warnings
from collections import OrderedDict
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import replace

import numpy as np

from ..emu.trace import SHAPE_STAGES, Trace, decimals
from ..recent import Recent
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
        self._traces: Recent[Trace] = Recent(size)

    def trace(self, version: int, words: Sequence[int], options, frame: int, x: int, y: int) -> Trace:
        return self._traces.get((version, options, frame, x, y), lambda: trace(words, options, frame, x, y))


def trace(words: Sequence[int], options, frame: int, x: int, y: int) -> Trace:
    """The trace whose records ``rend3r emulate --trace-pixel X,Y`` prints for frame ``frame``."""
    from ..emu.processor import execute
    from ..emu.trace import raster_traces, raytrace_traces

    if options.mode == "hybrid":
        raise RequestError("hybrid frames have no pixel trace (docs/trace.md)", 422)
    tracer = raster_traces if options.mode == "raster" else raytrace_traces
    out: list[Trace] = []

    def on_nf(scene, number: int) -> None:
        if number == frame:
            out.extend(tracer(scene, options, number, [(x, y)]))

    with quiet_numpy():
        execute(words, options, frame + 1, on_nf)
    if not out:
        raise RequestError(f"the program renders no frame {frame}", 422)
    return out[0]


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


_INTEGER = np.array([stage == "hit" for stage in SHAPE_STAGES])
_HIT, _SQ_DIST = SHAPE_STAGES.index("hit"), SHAPE_STAGES.index("sq_dist")


def _table_agreement(ar, work: Trace, ref: Trace) -> tuple[np.ndarray, np.ndarray]:
    """For each row of the working trace's table, the fp64 table's row of the same shape
    (-1: none), and whether each of its values agrees with that row's (as :func:`_agreement`
    judges)."""
    if np.array_equal(work.shapes, ref.shapes):
        pos = np.arange(len(work.shapes))
    elif len(ref.shapes):
        order = np.argsort(ref.shapes, kind="stable")
        at = order[np.searchsorted(ref.shapes, work.shapes, sorter=order).clip(0, len(order) - 1)]
        pos = np.where(ref.shapes[at] == work.shapes, at, -1)
    else:
        pos = np.full(len(work.shapes), -1)
    mine = work.values
    theirs = np.where((pos >= 0)[:, None], ref.values[pos.clip(0)] if len(ref.values) else np.nan, np.nan)
    with quiet_numpy():
        rounded = np.asarray(ar.round(theirs), dtype=np.float64)
    same_value = (mine == rounded) | (np.isnan(mine) & np.isnan(rounded))
    return pos, (pos >= 0)[:, None] & np.where(_INTEGER, mine == theirs, same_value)


#: How the shape shown is chosen: raytracing, then each raster visibility rule
#: (docs/emulator.md, docs/raster.md).
TIE_RULES = {"raytrace": "the smallest sq_dist wins; equal distances go to the lower shape index (docs/emulator.md)",
             "zbuffer": "the depth buffer keeps the earlier triangle on equal depth (docs/raster.md)",
             "painter": "painter's order by centroid distance, far to near; equal distances keep index order (docs/raster.md)",
             "index": "no depth order: later triangles paint over earlier ones (quirk raster-index-order)"}


def _hits(work: Trace, ref: Trace) -> list[dict]:
    """The shapes a raytraced pixel's ray hit, nearest first (ties in index order), with
    their squared distances in both runs."""
    def distances(t: Trace) -> dict[int, float | str]:
        hit = t.values[:, _HIT] == 1
        return dict(zip(t.shapes[hit].tolist(), decimals(t.values[hit, _SQ_DIST])))

    mine, theirs = distances(work), distances(ref)
    order = sorted(mine, key=lambda shape: (float(mine[shape]), shape))
    return [{"shape": shape, "sq_dist": mine[shape], "fp64_sq_dist": theirs.get(shape)} for shape in order]


def _hit_shapes(t: Trace) -> set:
    """The shapes a trace records as hit."""
    return set(t.shapes[t.values[:, _HIT] == 1].tolist()) | {
        r["shape"] for r in t.rest if r["stage"] == "hit" and r["dec"] == 1}


def _table_rows(work: Trace, ref: Trace, rows: np.ndarray, pos: np.ndarray, agree: np.ndarray) -> list[dict]:
    """The records of the working table's ``rows`` with the fp64 values of its rows ``pos``
    (-1: none) beside them (as :func:`_row`), and whether they diverge (not ``agree``)."""
    records = work.table_records(rows)  # made here, so extended in place
    fp64 = zip(*(zip(hexes, decs) for hexes, decs in ref.columns(pos[pos >= 0])))
    theirs = (value for p in pos.tolist() for value in (next(fp64) if p >= 0 else (None,) * len(SHAPE_STAGES)))
    for r, f, agrees in zip(records, theirs, agree.ravel().tolist()):
        r["fp64"] = None if f is None else {"hex": f[0], "dec": f[1]}
        r["diverges"] = not agrees
    return records


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
    pos, table_agree = _table_agreement(ar, work, ref)
    pairs, rest_agree, rest_integer = _agreement(ar, work.rest, ref.rest)
    width = len(SHAPE_STAGES)
    cut = table_agree.size  # the table's records come first, row by row
    agree = np.concatenate([table_agree.ravel(), rest_agree])
    integer = np.concatenate([np.broadcast_to(_INTEGER, table_agree.shape).ravel(), rest_integer])
    first = _first(~agree)
    decision = _first(~agree & integer)
    split = cut + next((i for i, r in enumerate(work.rest) if r["stage"] == "nearest"), len(work.rest))
    shapes = set(work.shapes.tolist()) | {r["shape"] for r in work.rest[: split - cut]}
    keep = shapes
    if len(shapes) > ALL_SHAPES_UP_TO and not all_shapes:
        keep = _hit_shapes(work) | _hit_shapes(ref)
        keep |= {r["dec"] for r in work.rest + ref.rest if r["stage"] == "nearest"}
        keep |= {int(work.shapes[i // width]) if i < cut else work.rest[i - cut]["shape"]
                 for i in (first, decision) if i is not None and i < split}
    rows = np.flatnonzero(np.isin(work.shapes, list(keep)))
    records = _table_rows(work, ref, rows, pos[rows], table_agree[rows])
    rest = [j for j, r in enumerate(work.rest) if cut + j >= split or r["shape"] in keep]
    records += [_row(work.rest[j], pairs[j], bool(rest_agree[j])) for j in rest]
    shown = np.concatenate([(rows[:, None] * width + np.arange(width)).ravel(), cut + np.array(rest, dtype=np.int64)])

    def place(i: int | None) -> int | None:
        return None if i is None else int(np.searchsorted(shown, i))

    return {"frame": frame, "pixel": [x, y], "precision": options.precision, "label": ar.label,
            "mode": options.mode, "shapes": len(shapes), "shapes_shown": len(keep & shapes), "records": records,
            "first_divergence": place(first), "first_decision": place(decision),
            "hits": _hits(work, ref) if options.mode == "raytrace" else None, "tie_rule": TIE_RULES["raytrace" if options.mode == "raytrace" else options.depth]}
