"""The instruction processor: decode and execute a whole program with array operations.

Semantics (paper, section III): ``nr`` clears scene state and the frame buffer, ``nf``
renders the current scene into a frame, ``lr`` jumps to address 0, ``er`` halts. Running
past the last word halts as ``er`` does (memory beyond the program is zero, and a zero
word is ``er``). Device deviations are fields of :class:`EmuOptions`.

Execution has two steps. The control flow is planned first from the control words only
(nf, lr, halting er, TS, unknown opcodes, a trailing SE), so every error is raised before
``on_nf`` is first called. Then the data words between control words are applied to the
scene in bulk (the last write wins; an ``nr`` drops the writes before it) and ``on_nf``
is called at each nf. Without an lr, execution is one linear pass from address 0; with an
lr, the pass from ``lr_target`` to its first lr is one period, replayed until the frames
bound.
"""

from __future__ import annotations

import threading
from array import array
from ctypes import byref
from dataclasses import dataclass
from functools import cached_property
from typing import Callable, NamedTuple, Sequence

import numpy as np

from ..errors import Rend3rError
from ..isa import Table, ValueType, by_index
from ..isa.extensions import TS_CODES, decode_table_select, table_select_word
from ..isa.tables import (
    DATA, FUNC, LIGHT_INDEX, OPCODE, PROP, PROP_LIMIT, SD_DATA, SD_DATA2, SE_INDEX_HI, SE_INDEX_LO, SE_PROP2,
    SHAPE_INDEX_LIMIT, Field, Func, Opcode,
)
from . import native, threads
from .native import address
from .options import EmuOptions
from .scene import ObjectTable, Scene
from .workspace import empty

#: Called at each ``nf`` with the scene and the frame number (0-based).
RenderHook = Callable[[Scene, int], None]

_F, _C, _L, _SE = (int(o) for o in (Opcode.F, Opcode.C, Opcode.L, Opcode.SE))
#: Tables SE/SD pairs can write; a write's table code is its position + 1 (0: the table
#: in force when the pass started, i.e. no TS before it in the pass).
_TABLES = tuple(TS_CODES.values())
_CODE = {t: i + 1 for i, t in enumerate(_TABLES)}
_TS_WORDS = np.array([table_select_word(t) for t in _TABLES], dtype=np.uint32)
_NO_TS, _ENTRY_ONLY = np.empty(0, np.int64), np.zeros(1, np.int64)  # a stream without TS words


def _null_mask(table: Table) -> np.ndarray:
    """True for the property slots of ``table`` that are null (writing them stores nothing)
    (the camera's and lights' as uint8 flags for csrc/kernels.c word_writes)."""
    mask = np.zeros(PROP_LIMIT, dtype=bool)
    mask[[i for i, p in by_index(table).items() if p.vtype is ValueType.ZERO]] = True
    return mask


_CAMERA_NULL, _LIGHT_NULL = (_null_mask(t).astype(np.uint8) for t in (Table.CAMERA, Table.LIGHT))
_SE_NULL = np.stack([_null_mask(t) for t in _TABLES]).astype(np.uint8)  # row: table code - 1


@dataclass(frozen=True)
class Execution:
    """How a run ended."""

    frames: int  # number of nf executed
    instructions: int  # instructions executed (an SE/SD pair counts once)
    halt: str  # "er", "end" (ran past the last word) or "frames" (the --frames bound)


def _where(pc: int) -> str:
    return f"address {pc} (0x{pc:04x})"


class _Writes(NamedTuple):
    """Writes of one kind in program order: the writing instruction's address, the light
    or object index (0 for the camera), the property and the bits."""

    at: np.ndarray
    index: np.ndarray
    prop: np.ndarray
    bits: np.ndarray

    def between(self, lo: int, hi: int) -> _Writes:
        i, j = self.at.searchsorted((lo, hi)).tolist()
        if i == 0 and j == len(self.at):
            return self
        return _Writes(self.at[i:j], self.index[i:j], self.prop[i:j], self.bits[i:j])


class _Program:
    """The words (uint32), with the options that decide their meaning."""

    def __init__(self, words: Sequence[int], options: EmuOptions) -> None:
        if not isinstance(words, np.ndarray):  # array("I") converts a list fastest
            words = np.frombuffer(array("I", words), dtype=np.uintc)
        self.words = np.ascontiguousarray(words, np.uint32)
        self.options = options

    def opcode(self, at: int) -> int:
        """The opcode field of the word at ``at``."""
        return OPCODE.get(int(self.words[at]))


#: The lists stream_scan sorts instructions into: unknown opcodes, C, L, SE, then the frame
#: control words by function (_FRAME + ER, NR, NF, LR); per opcode value its list (F: by
#: its function).
_UNKNOWN, _CAMERA, _LIGHT, _PAIR, _FRAME = range(5)
if FUNC.width != 2 or sorted(Func) != list(range(4)):
    raise ImportError("csrc/kernels.c stream_scan sorts four frame-control functions of a two-bit field")
_LISTS = _FRAME + 4
_KIND = np.full(1 << OPCODE.width, _UNKNOWN, np.uint8)
_KIND[[_F, _C, _L, _SE]] = _FRAME, _CAMERA, _LIGHT, _PAIR


class _Stream:
    """The instructions reached linearly from address ``start``, up to ``stop``: the first
    lr, halting er or error (``kind`` "lr", "er", "error"), or the end ("end")."""

    def __init__(self, prog: _Program, start: int) -> None:
        self.prog, self.start = prog, start
        room = max(0, len(prog.words) - start)
        lists, count = empty((_LISTS, room), np.int64), np.empty(_LISTS, np.int64)
        native.library().stream_scan(address(prog.words), len(prog.words), start, OPCODE.lo, OPCODE.width, FUNC.lo,
                                     address(_KIND), address(lists), room, address(count), native.avx2())
        # Addresses of the instructions per list (_KIND), in order; an SE's pair is one instruction.
        self.by_kind = [lists[k, :c] for k, c in enumerate(count.tolist())]
        self._find_stop()

    def _find_stop(self) -> None:
        """Where the stream stops and why (``stop``, ``kind``), the nfs before it, the nrs,
        the TS words."""
        prog, n = self.prog, len(self.prog.words)
        er, self.nr, nf, lr = (self.by_kind[_FRAME + int(f)] for f in (Func.ER, Func.NR, Func.NF, Func.LR))
        unknown = self.by_kind[_UNKNOWN]
        if prog.options.er_needs_zero:
            er = er[(er + 1 >= n) | (prog.words[np.minimum(er + 1, n - 1)] == 0)]
        if prog.options.mode == "hybrid":  # TS words select tables; elsewhere they are unknown opcodes
            words = prog.words[unknown]
            ts = np.isin(words, _TS_WORDS)
            self.ts_at = unknown[ts]
            # The table code after k TS words of the stream (k = 0: 0, the pass's entry table).
            self.ts_codes = np.append(0, 1 + np.argmax(words[ts][:, None] == _TS_WORDS, axis=1))
            errors = unknown[~ts]
        else:
            self.ts_at, self.ts_codes, errors = _NO_TS, _ENTRY_ONLY, unknown
        pairs = self.by_kind[_PAIR]
        ends = [(int(a[0]), kind) for a, kind in ((lr, "lr"), (er, "er"), (errors, "error")) if len(a)]
        if len(pairs) and pairs[-1] == n - 1:  # an SE in the last word
            ends.append((n - 1, "error"))
        self.stop, self.kind = min(ends, default=(n, "end"))
        self.nfs = nf[:nf.searchsorted(self.stop)]

    def executed_before(self, at: int) -> int:
        """Instructions of this stream that start before address ``at``."""
        return sum(int(a.searchsorted(at)) for a in self.by_kind if len(a))

    def error(self) -> Rend3rError:
        """The error at ``stop`` (kind "error")."""
        word = int(self.prog.words[self.stop])
        if self.prog.opcode(self.stop) == _SE:
            return Rend3rError(f"{_where(self.stop)}: SE word 0x{word:08x} is the last word; its SD is missing")
        hint = ("; it is a TS table-select word (docs/isa-extensions.md): run with --mode hybrid"
                if decode_table_select(word) is not None else "")
        return Rend3rError(f"{_where(self.stop)}: unknown opcode 0b{OPCODE.get(word):03b} in word 0x{word:08x}{hint}")

    def outcome(self, frames: int | None, count: int, executed: int) -> Execution | None:
        """How a pass over this stream ends after ``count`` frames and ``executed``
        instructions: an Execution, None at an lr (raises the pass's error)."""
        if frames is not None and len(self.nfs) >= frames - count:
            return Execution(frames, executed + self.executed_before(self.nfs[frames - count - 1]) + 1, "frames")
        if self.kind == "error":
            raise self.error()
        if self.kind == "lr":
            return None
        done = self.executed_before(self.stop) + (self.kind == "er")
        return Execution(count + len(self.nfs), executed + done, self.kind)

    def table_after(self, entry: int) -> int:
        """The table code in force at ``stop`` for a pass entered with ``entry``."""
        if not len(self.ts_at):
            return entry
        return int(self.ts_codes[self.ts_at.searchsorted(self.stop)]) or entry

    def _data(self, kind: int) -> np.ndarray:
        """Addresses of the instructions of ``kind`` (_KIND) before ``stop``."""
        at = self.by_kind[kind]
        return at[:at.searchsorted(self.stop)]

    @cached_property
    def camera(self) -> _Writes:
        return self._word_writes(self._data(_CAMERA), _CAMERA_NULL)

    @cached_property
    def lights(self) -> _Writes:
        return self._word_writes(self._data(_LIGHT), _LIGHT_NULL, LIGHT_INDEX)

    def _word_writes(self, at: np.ndarray, null: np.ndarray, index: Field | None = None) -> _Writes:
        """The writes of the C or L words at ``at`` whose property is not ``null`` (one
        compiled pass: numpy took a dozen calls of 1-3 us each on a frame's few words)."""
        n = len(at)
        fields = _WRITE_FIELDS[index]
        out = _Writes(np.empty(n, np.int64), np.empty(n, np.uint32), np.empty(n, np.uint32), np.empty(n, np.uint16))
        kept = native.library().word_writes(address(self.prog.words), native.ptr(at, np.int64, (n,)), n,
                                             address(fields), native.ptr(null, np.uint8, (PROP_LIMIT,)),
                                             *(address(a) for a in out))
        return out if kept == n else _Writes(*(a[:kept] for a in out))

    def pair_tables(self, at: np.ndarray) -> np.ndarray | None:
        """The table code in force at each SE address of ``at`` (0: the pass's entry
        table); None when the stream has no TS word."""
        if not len(self.ts_at):
            return None
        return np.ascontiguousarray(self.ts_codes[self.ts_at.searchsorted(at)], np.uint8)


#: (lo, width) of the property, index (none for the camera) and data fields of a C or L
#: word (csrc/kernels.c word_writes: a flag per property value, data of at most 16 bits).
_WRITE_FIELDS = {index: np.array([PROP.lo, PROP.width, *((0, 0) if index is None else (index.lo, index.width)),
                                  DATA.lo, DATA.width], np.int32) for index in (None, LIGHT_INDEX)}
if 1 << PROP.width != PROP_LIMIT or DATA.width > 16 or LIGHT_INDEX.width > 31:
    raise ImportError("the C and L fields outgrow csrc/kernels.c word_writes")

#: (lo, width) of the fields the pair kernels read, in their order (csrc/kernels.c Pairs).
_PAIR_FIELDS = np.array([(f.lo, f.width) for f in (SE_INDEX_HI, SE_INDEX_LO, PROP, SE_PROP2, SD_DATA, SD_DATA2)],
                        np.int64)
#: What a decoded pair's record holds (csrc/kernels.c pair_record): the index in 20 bits,
#: properties in 5, data in 16.
if SE_INDEX_HI.width + SE_INDEX_LO.width > 20 or max(PROP.width, SE_PROP2.width) > 5 or \
        max(SD_DATA.width, SD_DATA2.width) > 16:
    raise ImportError("the SE/SD fields outgrow csrc/kernels.c pair_record")
#: The scene's tables pairs go to, each with 1 per table code it takes: in hybrid mode
#: those aimed at the triangle table go to ``triangles``, else all go to ``objects``.
_TRIANGLE_CODE = (np.arange(len(_TABLES) + 1) == _CODE[Table.TRIANGLE]).astype(np.uint8)
_WANTED = {True: (("objects", 1 - _TRIANGLE_CODE), ("triangles", _TRIANGLE_CODE)),
           False: (("objects", np.ones(len(_TABLES) + 1, np.uint8)),)}


class _Scratch(threading.local):
    """A thread's arrays for the pair writes, kept for the next write (zeroing half a
    megabyte for each pass cost more than the pass): a flag per index a shape can have (all
    zero between writes), a row per index, and the indices of a merged table."""

    def __init__(self) -> None:
        self.mark = np.zeros(SHAPE_INDEX_LIMIT, np.uint8)
        self.row_of = np.empty(SHAPE_INDEX_LIMIT, np.int32)
        self.merged = np.empty(SHAPE_INDEX_LIMIT, np.int64)


_SCRATCH = _Scratch()

#: Pairs a thread takes at least (pair_marks takes about 2 ns a pair: a range of these is
#: about ten times what a team takes to hand it over).
PAIR_CHUNK = 1 << 12


def _write_pairs(words: np.ndarray, at: np.ndarray, tables: np.ndarray | None, entry: int, wanted: np.ndarray,
                 table: ObjectTable, jobs: int) -> None:
    """Apply the SE/SD pairs at ``at`` (each writes prop then prop2; a write to a null
    property stores nothing) that ``wanted`` takes to ``table``, in compiled passes
    (csrc/kernels.c pairs_rows, pairs_grow): over their words, the indices written and
    each pair decoded (in ranges of pairs on a team of ``jobs`` threads when there are
    many), the table's rows for them, then over the decoded pairs the writes: each range
    of pairs most likely on the thread that decoded it while the ranges write their
    indices in order, else all in order on one thread (threads that each took a range of
    rows spent nearly as long reading every pair as one thread writing them all). A new
    index gets a new table, its rows in index order, of the size it needs: the second call
    comes only then."""
    scratch, had, index = _SCRATCH, len(table.index), table.index
    if had and not (0 <= index[0] and index[-1] < SHAPE_INDEX_LIMIT):
        raise ValueError(f"object table indices must lie in 0..{SHAPE_INDEX_LIMIT - 1}")
    records = empty(len(at), np.uint64)  # each pair decoded once, by pair_marks for pair_apply
    pairs = native.Pairs(address(words), len(words), address(at), len(at), address(_PAIR_FIELDS),
                         None if tables is None else address(tables), entry, address(wanted), address(_SE_NULL),
                         address(records), native.avx2())
    count = threads.parts(len(at), jobs, PAIR_CHUNK)
    tops = np.empty(count, np.int64)
    if had and not table.values.flags.writeable:  # the writes may go in place: into a copy of a read-only table
        table.values = table.values.copy()
    lib, old = native.library(), (native.ptr(index, np.int64, (had,)), had,
                                  native.ptr(table.values, np.uint16, (had, PROP_LIMIT)))
    with threads.team(jobs if count > 1 else 1) as team:
        rows = lib.pairs_rows(team, byref(pairs), count, address(scratch.mark), address(tops),
                              address(scratch.row_of), address(scratch.merged), *old)
        if rows > had:
            new_index, values = empty(rows, np.int64), empty((rows, PROP_LIMIT), np.uint16)
            lib.pairs_grow(team, byref(pairs), count, address(tops), address(scratch.mark), address(scratch.row_of),
                           address(scratch.merged), rows, *old, address(new_index), address(values))
            table.index, table.values = new_index, values
    if rows < 0:
        scratch.mark[:] = 0
        if rows == -2:
            raise ValueError("object table indices must be sorted and unique")
        # the first pair without its SD: range k starts at len(at) * k // count (csrc/kernels.c pair_range)
        bad = [len(at) * k // count - 1 - t for k, t in enumerate(tops.tolist()) if t < 0]
        raise Rend3rError(f"{_where(int(at[bad[0]]))}: an SE word without its SD")


@dataclass(frozen=True)
class _Plan:
    """The validated control flow: the first pass from address 0, and the stream an lr
    jumps into (None when the first pass does not end at an lr)."""

    execution: Execution
    first: _Stream
    loop: _Stream | None


def _plan(prog: _Program, frames: int | None) -> _Plan:
    """Follow the control flow (raising every error) without touching the scene."""
    first = _Stream(prog, 0)
    done = first.outcome(frames, 0, 0)
    if done is not None:
        return _Plan(done, first, None)
    if frames is None:
        raise Rend3rError(
            f"{_where(first.stop)}: the program loops (lr); pass --frames N to bound how many frames to render")
    target = prog.options.lr_target
    loop = first if target == 0 else _Stream(prog, target)
    count, executed = len(first.nfs), first.executed_before(first.stop) + 1
    done = loop.outcome(frames, count, executed)
    if done is not None:
        return _Plan(done, first, loop)
    if not len(loop.nfs):
        raise Rend3rError(f"{_where(loop.stop)}: the program loops (lr) without rendering a frame (no nf in the loop)")
    periods, last = divmod(frames - count - 1, len(loop.nfs))
    period = loop.executed_before(loop.stop) + 1
    total = executed + periods * period + loop.executed_before(loop.nfs[last]) + 1
    return _Plan(Execution(frames, total, "frames"), first, loop)


def _apply(stream: _Stream, lo: int, hi: int, scene: Scene, entry: int) -> None:
    """Apply the writes of addresses [lo, hi) of ``stream`` (``entry``: the table code in
    force when the pass started)."""
    if lo >= hi:  # e.g. an nf followed by er: nothing in between
        return
    if stream.prog.options.clear_on_nr:
        i, j = stream.nr.searchsorted((lo, hi))
        if j > i:
            scene.clear()
            lo = int(stream.nr[j - 1]) + 1
    camera, lights = stream.camera.between(lo, hi), stream.lights.between(lo, hi)
    if len(camera.at):
        scene.write_camera(camera.prop, camera.bits)
    if len(lights.at):
        scene.write_lights(lights.index, lights.prop, lights.bits)
    pairs = stream.by_kind[_PAIR]
    at = pairs[pairs.searchsorted(lo):pairs.searchsorted(hi)]  # hi <= stop
    if len(at):
        tables = stream.pair_tables(at)
        jobs = stream.prog.options.jobs or threads.available_cores()
        for table, wanted in _WANTED[stream.prog.options.mode == "hybrid"]:
            _write_pairs(stream.prog.words, at, tables, entry, wanted, getattr(scene, table), jobs)


def _run_pass(stream: _Stream, scene: Scene, on_nf: RenderHook | None, count: int, frames: int | None,
              entry: int) -> tuple[int, int]:
    """One pass over ``stream``, calling ``on_nf`` at each nf until the frames bound.

    Returns the frame count and the table code in force at the end of the pass.
    """
    lo = stream.start
    for at in stream.nfs.tolist():
        _apply(stream, lo, at, scene, entry)
        if on_nf is not None:
            on_nf(scene, count)
        count += 1
        if count == frames:
            return count, entry
        lo = at + 1
    _apply(stream, lo, stream.stop, scene, entry)
    return count, stream.table_after(entry)


def _replay(plan: _Plan, scene: Scene, on_nf: RenderHook | None, frames: int | None, entry: int) -> None:
    """Apply the planned passes to ``scene``: the first, then the loop until the frames bound."""
    stream = plan.first
    count, entry = _run_pass(stream, scene, on_nf, 0, frames, entry)
    while stream.kind == "lr" and count != frames and plan.loop is not None:
        stream = plan.loop
        count, entry = _run_pass(stream, scene, on_nf, count, frames, entry)


@dataclass(frozen=True)
class Planned:
    """A program whose control flow is validated: how it will run, and :meth:`replay`."""

    execution: Execution
    plan: _Plan
    options: EmuOptions
    frames: int | None

    def replay(self, on_nf: RenderHook | None = None, scene: Scene | None = None) -> None:
        """Apply the writes to ``scene`` (a new one if None), calling ``on_nf`` at each nf."""
        entry = _CODE[Table.TRIANGLE if self.options.mode == "raster" else Table.SHAPE]
        _replay(self.plan, scene if scene is not None else Scene(), on_nf, self.frames, entry)


def plan(words: Sequence[int], options: EmuOptions, frames: int | None = None) -> Planned:
    """Follow the control flow of ``words`` up to ``er``, the end, or ``frames`` frames.

    Raises Rend3rError for an unknown opcode or trailing SE (with its address), for a
    looping program without a ``frames`` bound, and for a loop that renders nothing.
    """
    if frames is not None and frames < 1:
        raise Rend3rError(f"--frames must be at least 1, not {frames}")
    flow = _plan(_Program(words, options), frames)
    return Planned(flow.execution, flow, options, frames)


def execute(
    words: Sequence[int],
    options: EmuOptions,
    frames: int | None = None,
    on_nf: RenderHook | None = None,
    scene: Scene | None = None,
) -> Execution:
    """Run ``words`` until ``er``, the end, or ``frames`` frames; call ``on_nf`` at each nf.

    Every error of :func:`plan` is raised before ``on_nf`` is first called. ``scene`` (if
    given) is left as the run left it. Without ``on_nf`` and ``scene`` only the control
    flow is followed.
    """
    planned = plan(words, options, frames)
    if on_nf is not None or scene is not None:
        planned.replay(on_nf, scene)
    return planned.execution
