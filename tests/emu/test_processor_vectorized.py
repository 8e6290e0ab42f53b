"""The vectorized processor against a plain per-word reference interpreter.

Random word streams (SE runs of odd and even length, SDs that look like instructions,
nr/nf/er/lr, TS words, unknown opcodes, a trailing SE) under random options must give the
same Execution or the same error message, and the same scene at every nf and at the end.
"""

from __future__ import annotations

from contextlib import contextmanager, nullcontext

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from rend3r.emu import workspace
from rend3r.emu.options import EmuOptions
from rend3r.emu.processor import Execution, execute
from rend3r.emu.scene import ObjectTable, Scene
from rend3r.errors import Rend3rError
from rend3r.isa import (
    CameraSet, FrameOp, Func, LightSet, ShapeSet, Table, TrailingSE, Unknown, ValueType, by_index, decode_word, encode,
)
from rend3r.isa.extensions import decode_table_select, table_select_word
from rend3r.isa.tables import OPCODE, UNUSED_OPCODES, Opcode

Objects = dict[int, tuple[int, ...]]  # index -> the 32 property words (0 where unwritten)
State = tuple[dict[int, int], dict[int, dict[int, int]], Objects, Objects]


def _null(table: Table, prop: int) -> bool:
    p = by_index(table).get(prop)
    return p is not None and p.vtype is ValueType.ZERO


def _dense(objects: dict[int, dict[int, int]]) -> Objects:
    return {i: tuple(props.get(p, 0) for p in range(32)) for i, props in objects.items()}


def _where(pc: int) -> str:
    return f"address {pc} (0x{pc:04x})"


def reference(words: list[int], options: EmuOptions, frames: int | None = None) -> tuple[Execution, list[State], State]:
    """One word at a time, as the device reads them: the Execution, the scene at each nf,
    the scene at the end (raises Rend3rError as the processor must)."""
    if frames is not None and frames < 1:
        raise Rend3rError(f"--frames must be at least 1, not {frames}")
    camera: dict[int, int] = {}
    lights: dict[int, dict[int, int]] = {}
    tables: dict[Table, dict[int, dict[int, int]]] = {Table.SHAPE: {}, Table.TRIANGLE: {}}
    table = Table.TRIANGLE if options.mode == "raster" else Table.SHAPE
    seen: list[State] = []

    def state() -> State:
        objects, triangles = tables[Table.SHAPE], tables[Table.TRIANGLE]  # outside hybrid mode all go to SHAPE
        return dict(camera), {i: dict(p) for i, p in lights.items()}, _dense(objects), _dense(triangles)

    pc = count = executed = 0
    frames_at_last_lr = -1
    while pc < len(words):
        word = words[pc]
        is_se = OPCODE.get(word) == Opcode.SE
        ins = decode_word(word, words[pc + 1] if pc + 1 < len(words) else None) if is_se else decode_word(word)
        executed += 1
        if isinstance(ins, TrailingSE):
            raise Rend3rError(f"{_where(pc)}: SE word 0x{word:08x} is the last word; its SD is missing")
        if isinstance(ins, Unknown):
            selected = decode_table_select(word)
            if options.mode == "hybrid" and selected is not None:
                table = selected
                pc += 1
                continue
            hint = "; it is a TS table-select word (docs/isa-extensions.md): run with --mode hybrid" if selected else ""
            raise Rend3rError(f"{_where(pc)}: unknown opcode 0b{OPCODE.get(word):03b} in word 0x{word:08x}{hint}")
        here, pc = pc, pc + (2 if is_se else 1)
        if isinstance(ins, CameraSet) and not _null(Table.CAMERA, ins.prop):
            camera[ins.prop] = ins.data
        elif isinstance(ins, LightSet) and not _null(Table.LIGHT, ins.prop):
            lights.setdefault(ins.index, {})[ins.prop] = ins.data
        elif isinstance(ins, ShapeSet):
            target = tables[table] if options.mode == "hybrid" else tables[Table.SHAPE]
            for prop, data in ((ins.prop, ins.data), (ins.prop2, ins.data2)):
                if not _null(table, prop):
                    target.setdefault(ins.index, {})[prop] = data
        elif isinstance(ins, FrameOp):
            if ins.func is Func.ER:
                if not options.er_needs_zero or pc >= len(words) or words[pc] == 0:
                    return Execution(count, executed, "er"), seen, state()
            elif ins.func is Func.NR:
                if options.clear_on_nr:
                    for state_dict in (camera, lights, *tables.values()):
                        state_dict.clear()
            elif ins.func is Func.NF:
                seen.append(state())
                count += 1
                if frames is not None and count >= frames:
                    return Execution(count, executed, "frames"), seen, state()
            else:
                if frames is None:
                    raise Rend3rError(f"{_where(here)}: the program loops (lr); pass --frames N to bound how many "
                                      "frames to render")
                if count == frames_at_last_lr:
                    raise Rend3rError(f"{_where(here)}: the program loops (lr) without rendering a frame (no nf in "
                                      "the loop)")
                frames_at_last_lr = count
                pc = options.lr_target
    return Execution(count, executed, "end"), seen, state()


def _table(t: ObjectTable) -> Objects:
    return {int(i): tuple(int(v) for v in row) for i, row in zip(t.index, t.values)}


def _state(scene: Scene) -> State:
    return (dict(scene.camera), {i: dict(p) for i, p in scene.lights.items()}, _table(scene.objects),
            _table(scene.triangles))


def vectorized(words: list[int], options: EmuOptions, frames: int | None = None) -> tuple[Execution, list[State], State]:
    seen: list[State] = []
    scene = Scene()
    ex = execute(words, options, frames, lambda s, n: seen.append(_state(s)), scene)
    return ex, seen, _state(scene)


def _outcome(run, words, options, frames):
    try:
        return run(words, options, frames)
    except Rend3rError as e:
        return str(e)


def _f(func: Func) -> int:
    return encode(FrameOp(func))[0]


_PROP = st.integers(0, 31)
_DATA = st.one_of(st.sampled_from([0, 0x3C00, 0xFFFF, 1, 2, 3]), st.integers(0, 0xFFFF))
_INDEX = st.one_of(st.integers(0, 5), st.integers(0, (1 << 19) - 1))
_SE_WORD = st.integers(0, 2**29 - 1).map(lambda w: w << 3 | int(Opcode.SE))
_TS_WORD = st.sampled_from([Table.SHAPE, Table.TRIANGLE]).map(table_select_word)
_CAMERA = st.builds(lambda p, d: list(encode(CameraSet(p, d))), _PROP, _DATA)
_LIGHT = st.builds(lambda i, p, d: list(encode(LightSet(i, p, d))), st.integers(0, 3) | st.integers(0, 63), _PROP, _DATA)
#: An SD that looks like an instruction (or anything at all).
_SD = st.one_of(st.integers(0, 2**32 - 1), st.just(0), st.sampled_from(Func).map(_f), _SE_WORD, _TS_WORD)
_PAIR = st.builds(lambda i, p, q, sd: [encode(ShapeSet(i, p, q, 0, 0))[0], sd], _INDEX, _PROP, _PROP, _SD)
#: A run of SE-opcode words (odd or even length): boundaries depend on where reading starts.
_SE_RUN = st.lists(_SE_WORD, min_size=1, max_size=5)
_UNKNOWN = st.builds(lambda op, w: w << 3 | op, st.sampled_from(UNUSED_OPCODES), st.integers(0, 2**29 - 1))


def _words(*funcs: Func) -> st.SearchStrategy[list[int]]:
    return st.sampled_from(funcs).map(lambda f: [_f(f)])


def programs(hybrid: bool) -> st.SearchStrategy[list[int]]:
    """Mostly data words and nfs; TS words in hybrid mode; half of them with one bad word
    (unknown opcode, TS, SE) somewhere, reached or not."""
    items = [_words(Func.NF), _words(Func.NF), _words(Func.NR), _words(Func.ER, Func.LR), _CAMERA, _LIGHT,
             _PAIR, _PAIR, _PAIR, _SE_RUN] + [_TS_WORD.map(lambda w: [w])] * (3 * hybrid)
    clean = st.lists(st.one_of(items), max_size=40).map(lambda parts: [w for part in parts for w in part])
    bad = st.none() | st.tuples(st.integers(0, 2**16), st.one_of(_UNKNOWN, _TS_WORD, _SE_WORD))

    def insert(words: list[int], at_word) -> list[int]:
        if at_word is None:
            return words
        at, word = at_word
        at %= len(words) + 1
        return words[:at] + [word] + words[at:]

    return st.builds(insert, clean, bad)


OPTIONS = st.builds(
    EmuOptions, mode=st.sampled_from(["raytrace", "raster", "hybrid"]), clear_on_nr=st.booleans(),
    lr_target=st.sampled_from([0, 1]), er_needs_zero=st.booleans(),
)
CASES = OPTIONS.flatmap(lambda o: st.tuples(programs(o.mode == "hybrid"), st.just(o), st.none() | st.integers(1, 12)))


@settings(max_examples=600)
@given(CASES)
def test_same_execution_error_and_scenes_as_the_reference(case):
    words, options, frames = case
    assert _outcome(vectorized, words, options, frames) == _outcome(reference, words, options, frames)


@settings(max_examples=200)
@given(CASES)
def test_without_a_hook_only_the_execution_is_computed(case):
    words, options, frames = case
    want = _outcome(reference, words, options, frames)
    try:
        got = execute(words, options, frames)
    except Rend3rError as e:
        got = str(e)
    assert got == (want if isinstance(want, str) else want[0])


def _check(words, options=EmuOptions(), frames=None):
    got = _outcome(vectorized, words, options, frames)
    assert got == _outcome(reference, words, options, frames)
    return got


NR, NF, ER, LR = (_f(f) for f in (Func.NR, Func.NF, Func.ER, Func.LR))
SE = encode(ShapeSet(0, 1, 2, 0, 0))[0]


def test_errors_name_their_address():
    assert _check([NR, 0x6]) == "address 1 (0x0001): unknown opcode 0b110 in word 0x00000006"
    ts = table_select_word(Table.TRIANGLE)
    assert _check([NR, NF, ts]) == (f"address 2 (0x0002): unknown opcode 0b010 in word 0x{ts:08x}; it is a TS "
                                    "table-select word (docs/isa-extensions.md): run with --mode hybrid")
    assert _check([NR, SE]) == f"address 1 (0x0001): SE word 0x{SE:08x} is the last word; its SD is missing"
    assert _check([NR, NF, LR]) == ("address 2 (0x0002): the program loops (lr); pass --frames N to bound how many "
                                    "frames to render")
    assert _check([NR, NF, LR, NR, LR], EmuOptions(lr_target=3), 5) == (
        "address 4 (0x0004): the program loops (lr) without rendering a frame (no nf in the loop)")
    assert _check([NF], frames=0) == "--frames must be at least 1, not 0"


def test_errors_come_before_the_first_frame():
    calls = []
    with pytest.raises(Rend3rError, match="unknown opcode"):
        execute([NF, NF, 0x7], EmuOptions(), on_nf=lambda s, n: calls.append(n))
    assert calls == []


def test_the_frames_bound_wins_over_a_later_error():
    ex, seen, _ = _check([NF, NF, 0x7], frames=2)
    assert ex == Execution(2, 2, "frames") and len(seen) == 2


def test_lr_target_one_reads_the_sd_at_address_1_as_an_instruction():
    # From 0: SE/SD pair (its SD is an nf word), lr. From 1: nf, lr.
    words = [SE, NF, LR]
    ex, seen, _ = _check(words, EmuOptions(lr_target=1), frames=3)
    assert ex == Execution(3, 2 + 2 * 2 + 1, "frames") and len(seen) == 3
    assert "without rendering" in _check(words, EmuOptions(lr_target=0), frames=3)


def test_se_runs_pair_differently_from_address_1():
    # From 0: (SE, SE) pair, then NF. From 1: (SE, NF) pair, then LR again: no frame in the loop.
    words = [SE, SE, NF, LR]
    assert "without rendering" in _check(words, EmuOptions(lr_target=1), frames=2)
    ex, _, _ = _check([SE, SE, SE, NF, NF, LR], EmuOptions(lr_target=1), frames=4)
    assert ex.frames == 4


def test_ts_at_address_0_is_skipped_by_lr_1_but_its_table_persists():
    ts_tri, ts_shape = (table_select_word(t) for t in (Table.TRIANGLE, Table.SHAPE))
    pair = list(encode(ShapeSet(1, 1, 2, 3, 4)))
    hybrid = EmuOptions(mode="hybrid", lr_target=1)
    _, seen, _ = _check([ts_tri, *pair, NF, LR], hybrid, frames=3)
    assert all(list(objects) == [] and list(triangles) == [1] for _, _, objects, triangles in seen)
    _, seen, _ = _check([ts_tri, *pair, NF, ts_shape, *encode(ShapeSet(2, 1, 2, 3, 4)), LR], hybrid, frames=3)
    tables = [(list(objects), list(triangles)) for _, _, objects, triangles in seen]
    assert tables == [([], [1]), ([1, 2], [1]), ([1, 2], [1])]  # from 1 the pair goes to the shape table


def test_many_periods_are_replayed_not_expanded():
    words = [NR, *encode(ShapeSet(7, 1, 2, 3, 4)), NF, LR]
    frames = 100_000
    ex = execute(words, EmuOptions(), frames)
    assert ex == Execution(frames, 4 * (frames - 1) + 3, "frames")
    _check(words, frames=50)


def test_last_write_wins_across_many_words():
    rng = np.random.default_rng(1)
    words = [NR]
    for i, p, q, d in zip(rng.integers(0, 40, 3000), rng.integers(0, 32, 3000), rng.integers(0, 32, 3000),
                          rng.integers(0, 2**32, 3000)):
        words += [encode(ShapeSet(int(i), int(p), int(q), 0, 0))[0], int(d)]
    words += [*(w for k in range(500) for w in encode(LightSet(k % 7, k % 9, k))), *encode(CameraSet(3, 9)), NF]
    for mode in ("raytrace", "raster", "hybrid"):
        _check(words, EmuOptions(mode=mode))


def test_new_indices_merge_into_the_table_in_index_order():
    """A later frame's pairs add indices below, between and above the table's (rows move
    with their values), write in place when no index is new, and a pair that stores
    nothing adds no row; the scenes are the reference's."""
    a, b = [p for p in range(32) if not _null(Table.SHAPE, p)][:2]
    null = next(p for p in range(32) if _null(Table.SHAPE, p))

    def pair(index: int, prop: int, data: int) -> list[int]:
        return list(encode(ShapeSet(index, prop, prop, data, data)))

    words = [NR, *pair(5, a, 30), *pair(2, b, 20), NF, *pair(3, a, 1), *pair(5, b, 7), *pair(9, a, 4), NF,
             *pair(5, a, 8), NF, *pair(1, null, 6), NF]
    _, seen, _ = vectorized(words, EmuOptions())
    assert [list(state[2]) for state in seen] == [[2, 5], [2, 3, 5, 9], [2, 3, 5, 9], [2, 3, 5, 9]]
    assert seen[1][2][5][a] == 30 and seen[1][2][5][b] == 7 and seen[1][2][3][a] == 1 and seen[1][2][2][b] == 20
    assert seen[2][2][5][a] == 8 and seen[2][2][2][b] == 20
    _check(words)
    table = Scene().objects
    execute(words, EmuOptions(), scene=Scene(objects=table))
    assert table.row(5) == {a: 8, b: 7} and len(table) == 4
    with pytest.raises(KeyError):
        table.row(4)
    table.clear()
    assert len(table) == 0


def test_a_grown_table_holds_memory_for_its_rows_only():
    """A table that grew keeps arrays of its own size (a kept buffer at most twice it, as
    any array of the workspace), not the pass's room for every pair or its decoded pairs:
    a scene kept for a whole run would hold them."""
    words = [NR] + [w for i in range(3000) for p in range(8) for w in encode(ShapeSet(i, p, p, i, i))] + [NF]
    scene = Scene()
    execute(words, EmuOptions(), scene=scene)
    t = scene.objects
    assert len(t) == 3000
    for a in (t.index, t.values):
        held = a.base.nbytes if a.base is not None else a.nbytes
        assert held <= 2 * a.nbytes + workspace.SMALLEST


def test_a_read_only_table_is_written_in_a_copy():
    """A table whose values are read-only (a caller's, say from a file mapped read-only)
    gets its writes in a copy: the caller's array is never written through."""
    values = np.zeros((2, 32), np.uint16)
    values[0, 1] = 5
    values.flags.writeable = False
    table = Scene().objects
    table.index, table.values = np.array([3, 7], np.int64), values
    execute([*encode(ShapeSet(7, 1, 2, 9, 9)), NF], EmuOptions(), scene=Scene(objects=table))
    assert values[1].tolist() == [0] * 32 and table.row(7) == {1: 9, 2: 9} and table.row(3) == {1: 5}


@pytest.mark.parametrize(("index", "message"), [([3, 3, 9], "sorted and unique"), ([9, 3], "sorted and unique"),
                                                ([-1, 4], "must lie in"), ([4, 1 << 19], "must lie in")])
def test_a_table_with_bad_indices_is_refused_and_left_as_it_was(index, message):
    """The compiled writes trust a table's indices: one that is not sorted and unique, or
    lies outside the indices a shape can have, is refused before anything is written."""
    table = Scene().objects
    table.index = np.array(index, np.int64)
    table.values = np.zeros((len(index), 32), np.uint16)
    with pytest.raises(ValueError, match=message):
        execute([NR, *encode(ShapeSet(5, 1, 2, 7, 7)), NF], EmuOptions(clear_on_nr=False), scene=Scene(objects=table))
    assert table.index.tolist() == index and not table.values.any()
    after = Scene()  # the marks were cleared: the next write marks only its own index
    execute([NR, *encode(ShapeSet(5, 1, 2, 7, 7)), NF], EmuOptions(), scene=after)
    assert after.objects.index.tolist() == [5]


@settings(max_examples=300)
@given(CASES, st.integers(2, 4))
def test_pairs_split_over_threads_give_the_same_scenes(case, jobs):
    """Ranges of pairs marked on several threads: the same executions, errors (the first
    pair without its SD) and scenes (small ranges force splits)."""
    from dataclasses import replace

    import rend3r.emu.processor as processor

    words, options, frames = case
    chunk, processor.PAIR_CHUNK = processor.PAIR_CHUNK, 2
    try:
        got = _outcome(vectorized, words, replace(options, jobs=jobs), frames)
    finally:
        processor.PAIR_CHUNK = chunk
    assert got == _outcome(reference, words, options, frames)


def test_pairs_split_over_threads_keep_each_pairs_table():
    """Hybrid mode: TS words switch tables between ranges of pairs; each range reads the
    tables of its own pairs."""
    from dataclasses import replace

    import rend3r.emu.processor as processor

    ts = [table_select_word(t) for t in (Table.SHAPE, Table.TRIANGLE)]
    words = [NR]
    for k in range(60):
        words += [ts[k // 7 % 2], *encode(ShapeSet(k, 1, 2, k, k + 1))]
    words += [NF]
    options = EmuOptions(mode="hybrid")
    chunk, processor.PAIR_CHUNK = processor.PAIR_CHUNK, 4
    try:
        got = _outcome(vectorized, words, replace(options, jobs=3), None)
    finally:
        processor.PAIR_CHUNK = chunk
    assert got == _outcome(reference, words, options, None)


#: Runs of pairs back to back, as programs write shapes: a shape's pairs share its index,
#: some write null properties only (they store nothing), and runs break at other words.
_SHAPE_RUN = st.builds(
    lambda index, pairs: [w for p, q, sd in pairs for w in (encode(ShapeSet(index, p, q, 0, 0))[0], sd)],
    _INDEX, st.lists(st.tuples(_PROP, _PROP, _SD), min_size=1, max_size=12))
_BREAK = st.one_of(_CAMERA, _LIGHT, _words(Func.NF), _SE_RUN, st.just([]))


@pytest.mark.parametrize("instruction_set", ["base", "avx2"])
@settings(max_examples=300)
@given(st.lists(st.tuples(st.lists(_SHAPE_RUN, min_size=1, max_size=8), _BREAK), min_size=1, max_size=6),
       st.sampled_from(["raytrace", "hybrid"]), st.integers(1, 4))
def test_pairs_back_to_back_decode_alike_on_both_instruction_sets(instruction_set, runs, mode, jobs):
    """Long runs of pairs, which the scan and the decoding take eight at a time where they
    lie back to back (csrc/kernels.c stream_scan, with AVX2 scan_pairs8 and marks8), broken
    by other words at any pair, in ranges of a few blocks on 1-4 threads: the scenes of the
    reference interpreter with the baseline's loops and with the AVX2 blocks."""
    from rend3r.emu import native

    if not native.runs(instruction_set):
        pytest.skip("this processor has no AVX2")
    import rend3r.emu.processor as processor

    words = [NR] + [w for shapes, gap in runs for w in (*(w for shape in shapes for w in shape), *gap)] + [NF]
    options = EmuOptions(mode=mode, jobs=jobs)
    chunk = processor.PAIR_CHUNK
    native.choose(instruction_set)  # (the scan and the pairs' decoding have no AVX-512 copy: avx2 covers both)
    processor.PAIR_CHUNK = 12  # ranges of a block or two on each thread
    try:
        got = _outcome(vectorized, words, options, None)
    finally:
        native.choose(None)
        processor.PAIR_CHUNK = chunk
    assert got == _outcome(reference, words, options, None)


#: Shapes in index order, as programs set them up: each index a step (0: the same index
#: again, in a run of its own) above the one before, with its pairs (half of them write
#: property 0 twice, the shape table's null property: they store nothing).
_STORES_NOTHING = st.builds(lambda sd: (0, 0, sd), _SD)
_ORDERED_SHAPES = st.lists(st.tuples(st.integers(0, 2),
                                     st.lists(st.tuples(_PROP, _PROP, _SD) | _STORES_NOTHING, min_size=1, max_size=9),
                                     st.booleans()), min_size=1, max_size=40)


def _ordered_words(first: int, shapes: list, gap: list[int], back: tuple[int, int] | None) -> list[int]:
    """The shapes' pairs from index first on, the index going back by back[1] at shape
    back[0] (None: never)."""
    words, index = [], first
    for k, (step, pairs, broken) in enumerate(shapes):
        index = max(0, index - back[1]) if back is not None and k == back[0] % len(shapes) else index + step
        words += [w for p, q, sd in pairs for w in (encode(ShapeSet(index, p, q, 0, 0))[0], sd)]
        words += gap if broken else []
    return words


@contextmanager
def _teams_backwards():
    """The processor's teams replaced by one whose leader alone runs each phase's tasks last
    first (csrc/team.c team_open_backwards): the order that members taking every range
    from the back would give, which a real team gives only now and then."""
    from rend3r.emu import native, threads

    @contextmanager
    def backwards(jobs: int):
        at = native.library().team_open_backwards()
        try:
            yield at
        finally:
            native.library().team_close(at)

    real, threads.team = threads.team, backwards
    try:
        yield
    finally:
        threads.team = real


@pytest.mark.parametrize("order", ["team", "backwards"])
@pytest.mark.parametrize("instruction_set", ["base", "avx2"])
@settings(max_examples=300)
@given(st.integers(0, 1000), _ORDERED_SHAPES, _ORDERED_SHAPES, st.sampled_from([[], list(encode(CameraSet(1, 7)))]),
       st.none() | st.tuples(st.integers(0, 40), st.integers(1, 2)), st.integers(2, 4))
def test_pairs_in_index_order_are_written_by_each_range_in_order(order, instruction_set, first, shapes, again, gap,
                                                                 back, jobs):
    """Pairs that write their indices in order are written range by range on several
    threads (csrc/kernels.c pair_apply_team), the writes to an index that ranges share
    (a shape whose pairs a range edge splits, or a range of one shape's pairs only) made in
    program order: the scenes of the reference interpreter, for a new table (pairs_grow) and
    for a second frame that writes, in order, to rows the table has (in place), with each
    range's indices found a pair at a time and eight at a time (marks8), on a team and with
    the ranges run last first. An index that goes back by one or two lands, in some
    examples, below the largest index the ranges before its own marked: that range stops,
    and one thread writes every pair again, in order, over what the ranges wrote."""
    from rend3r.emu import native

    if not native.runs(instruction_set):
        pytest.skip("this processor has no AVX2")
    import rend3r.emu.processor as processor

    words = [NR, *_ordered_words(first, shapes, gap, back), NF, *_ordered_words(first, again, gap, back), NF]
    options = EmuOptions(jobs=jobs)
    chunk, processor.PAIR_CHUNK = processor.PAIR_CHUNK, 2  # a few pairs a range: edges inside shapes
    native.choose(instruction_set)
    try:
        with _teams_backwards() if order == "backwards" else nullcontext():
            got = _outcome(vectorized, words, options, None)
    finally:
        native.choose(None)
        processor.PAIR_CHUNK = chunk
    assert got == _outcome(reference, words, options, None)
