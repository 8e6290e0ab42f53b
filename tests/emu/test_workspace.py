"""Working arrays kept from frame to frame (rend3r/emu/workspace.py): memory is reused only
once nothing refers to it, and repeated frames neither grow it nor change a pixel."""

from __future__ import annotations

import sys
import threading
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from rend3r.emu import bvh, native, workspace
from rend3r.emu.options import EmuOptions
from rend3r.emu.run import run_program
from rend3r.isa import FrameOp, Func, ShapeSet, Table, encode, lookup
from rend3r.isa.float16 import float_to_bits

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
import walls  # noqa: E402

BIG = workspace.SMALLEST  # bytes: the smallest array that gets a buffer


def _on_a_thread_of_its_own(fn) -> None:
    """fn on a new thread, whose buffers no other test touched; its exception raised here."""
    errors: list[BaseException] = []

    def run() -> None:
        try:
            fn()
        except BaseException as e:  # noqa: BLE001 - reported by the test's own thread
            errors.append(e)

    t = threading.Thread(target=run)
    t.start()
    t.join()
    if errors:
        raise errors[0]


def test_the_interpreter_tells_a_free_buffer_from_a_held_one() -> None:
    assert workspace._FREE is not None


def test_a_buffer_comes_back_once_its_array_is_gone() -> None:
    _on_a_thread_of_its_own(_comes_back)


def _comes_back() -> None:
    first = workspace.empty(np.int64(BIG // 8))
    at = first.ctypes.data
    del first
    again = workspace.empty((BIG // 16, 2))
    assert again.ctypes.data == at and again.shape == (BIG // 16, 2) and again.flags.c_contiguous


def test_an_array_or_view_alive_keeps_its_buffer() -> None:
    _on_a_thread_of_its_own(_kept_by_a_view)


def _kept_by_a_view() -> None:
    first = workspace.empty(BIG, np.uint8)
    view = first[10:20].view(np.int16).reshape(5, 1)
    del first
    second = workspace.empty(BIG, np.uint8)
    view[:] = 7
    second[:] = 1
    assert not np.shares_memory(view, second)
    assert (view == 7).all()


def test_small_arrays_and_arrays_past_the_cap_take_no_buffer() -> None:
    _on_a_thread_of_its_own(_past_the_cap)


def _past_the_cap() -> None:
    small = workspace.empty(BIG - 1, np.uint8)
    assert workspace.kept_bytes() == 0 and small.size == BIG - 1
    alive = [workspace.empty(BIG, np.uint8) for _ in range(workspace.KEPT + 3)]
    assert len({a.ctypes.data for a in alive}) == len(alive)  # none shares memory
    assert workspace.kept_bytes() == workspace.KEPT * (BIG + BIG // 8)  # the first KEPT got one each


def test_a_free_buffer_too_small_is_replaced_not_kept_beside() -> None:
    _on_a_thread_of_its_own(_replaced)


def _replaced() -> None:
    a = workspace.empty(BIG, np.uint8)
    del a
    b = workspace.empty(4 * BIG, np.uint8)
    assert workspace.kept_bytes() == 4 * BIG + BIG // 2  # the small one went
    del b


def test_a_small_array_does_not_take_a_much_larger_free_buffer() -> None:
    _on_a_thread_of_its_own(_not_too_loose)


def _not_too_loose() -> None:
    large = workspace.empty(16 * BIG, np.uint8)
    at = large.ctypes.data
    del large
    small = workspace.empty(BIG, np.uint8)  # long-lived, like a scene's table
    assert small.ctypes.data != at
    again = workspace.empty(16 * BIG, np.uint8)
    assert again.ctypes.data == at


def test_arrays_share_a_buffer_held_while_any_of_them_lives() -> None:
    _on_a_thread_of_its_own(_arrays_in_one_buffer)


def _arrays_in_one_buffer() -> None:
    specs = (((BIG // 8, 3), np.float64), (np.int64(5), np.uint8), (0, np.int32), ((7, np.int32(2)), np.int64),
             (BIG, np.uint16))
    got = workspace.arrays(*specs)
    assert [(a.shape, a.dtype) for a in got] == [((BIG // 8, 3), np.float64), ((5,), np.uint8), ((0,), np.int32),
                                                 ((7, 2), np.int64), ((BIG,), np.uint16)]
    assert all(a.flags.c_contiguous and a.flags.writeable for a in got)
    base = got[0].ctypes.data
    spans = sorted((a.ctypes.data - base, a.ctypes.data - base + a.nbytes) for a in got if a.nbytes)
    assert all(start % 64 == 0 for start, _ in spans)
    assert all(end <= start for (_, end), (start, _) in zip(spans, spans[1:]))  # none overlaps the next
    for a, value in zip(got, range(1, 6)):
        a[...] = value
    assert [int(a.max(initial=0)) for a in got] == [1, 2, 0, 4, 5]  # each kept its own values
    kept = got[3]
    del got, a
    again = workspace.arrays(*specs)
    second = again[0].ctypes.data
    assert second != base  # the small array alive holds the whole buffer
    del kept, again
    assert workspace.arrays(*specs)[0].ctypes.data in (base, second)  # both buffers free again


def test_each_thread_has_its_own_buffers() -> None:
    """A buffer freed on one thread, which stays alive, is not handed to another."""
    freed, done = threading.Event(), threading.Event()
    at: list[int] = []

    def first() -> None:
        a = workspace.empty(BIG, np.uint8)
        at.append(a.ctypes.data)
        del a
        freed.set()
        done.wait(10)

    t = threading.Thread(target=first)
    t.start()
    try:
        assert freed.wait(10)
        other: list[int] = []
        _on_a_thread_of_its_own(lambda: other.append(workspace.empty(BIG, np.uint8).ctypes.data))
        mine = workspace.empty(BIG, np.uint8)
        assert at[0] not in (other[0], mine.ctypes.data)
    finally:
        done.set()
        t.join()


@pytest.mark.parametrize("precision", ["fp32", "fp16"])
def test_repeated_frames_keep_their_memory_and_their_pixels(precision: str, monkeypatch) -> None:
    """A wall of 4,096 spheres rendered again and again (on a thread of its own, whose
    buffers no other test touched), each time in buffers holding the last run's values:
    every frame equals the one rendered with fresh arrays (np.empty for every array), the
    kept bytes stop growing after a few runs (a buffer is only ever replaced by a larger
    one) and stay within twice the first run's, and a frame kept from an earlier run is
    not touched by later ones (frames never come from the buffers)."""
    words = walls.wall(4096, lights=1).words
    options = EmuOptions(precision=precision, width=96, height=64, jobs=1)
    with monkeypatch.context() as m:
        m.setattr(workspace, "SMALLEST", 1 << 62)  # no array takes a buffer
        m.setattr(bvh, "tree_room", _fresh_tree)  # nor is a tree kept
        fresh = run_program(words, options).frames[0]
    kept: list[int] = []

    def runs() -> None:
        first = run_program(words, options).frames[0]
        kept.append(workspace.kept_bytes())
        for _ in range(6):
            again = run_program(words, options).frames[0]
            for a, b in zip((again.rgb565, again.depth, again.provenance),
                            (fresh.rgb565, fresh.depth, fresh.provenance)):
                assert np.array_equal(a.view(np.uint16 if a.itemsize == 2 else np.uint32),
                                      b.view(np.uint16 if b.itemsize == 2 else np.uint32))
            assert not np.shares_memory(again.rgb565, first.rgb565)
            kept.append(workspace.kept_bytes())
        assert np.array_equal(first.rgb565, fresh.rgb565) and np.array_equal(first.provenance, fresh.provenance)

    _on_a_thread_of_its_own(runs)
    assert 0 < kept[0] and kept[-1] == kept[-2] == kept[-3] <= 2 * kept[0], kept


def _fresh_tree(rows: int) -> tuple:
    """bvh.tree_room's arrays made afresh, with a memo of no capacity: no tree kept."""
    cap = max(1, rows)
    return native.TreeMemo(), np.empty((2 * cap, 2), np.int32), *(np.empty(cap, np.int32) for _ in range(3))


@pytest.mark.parametrize("jobs", [1, 2])
def test_frames_whose_shapes_move_overwrite_the_rows_they_change(jobs: int, monkeypatch) -> None:
    """Frames of one run in the same buffers, the shapes moving between them (every other
    sphere, then every 64th the other way, so that most vectors of rows are left alone and some
    rewritten in one frame, then none): on a team of threads the bound table
    and the tree are written only where they differ (csrc/datapath.inc shape_tables,
    csrc/kernels.c bvh_build), so each frame's set-up finds the last frame's rows in
    place, and the last frame's tree where no shape moved (bvh.tree_room). Every frame and
    its counts of tests equal those rendered with fresh arrays and no tree kept (a stale
    bound would cull a moved sphere, or test every one)."""
    wall = walls.wall(4096, lights=1)
    words = list(wall.words[:-2])  # without nf, er
    xloc, yloc = (lookup(Table.SHAPE, name).index for name in ("xloc", "yloc"))
    nf, er = list(encode(FrameOp(Func.NF))), list(encode(FrameOp(Func.ER)))
    for moved, step in ((range(0, 4096, 2), 0.25), (range(0, 4096, 64), -0.25), (range(0), 0.0)):
        words += nf
        for s in moved:
            x, y = wall.centers[s, :2] + step
            words += encode(ShapeSet(s, xloc, yloc, float_to_bits(x), float_to_bits(y)))
    words = np.array(words + nf + er, np.uint32)
    options = EmuOptions(precision="fp32", width=96, height=64, jobs=jobs)
    with monkeypatch.context() as m:  # one thread (every row written) into fresh arrays
        m.setattr(workspace, "SMALLEST", 1 << 62)  # no array takes a buffer
        m.setattr(bvh, "tree_room", _fresh_tree)  # no tree kept from the frame before
        fresh = run_program(words, replace(options, jobs=1), memory=0)
    got: list = []  # memory=0: the frames one after another, each on the whole team
    _on_a_thread_of_its_own(lambda: got.append(run_program(words, options, memory=0)))
    assert len(got[0].frames) == len(fresh.frames) == 4
    for a, b, sa, sb in zip(got[0].frames, fresh.frames, got[0].stats.frames, fresh.stats.frames):
        assert a.rgb565.tobytes() == b.rgb565.tobytes() and a.depth.tobytes() == b.depth.tobytes()
        assert a.provenance.tobytes() == b.provenance.tobytes()
        assert (sa.tests, sa.skipped, sa.shadow_rays) == (sb.tests, sb.skipped, sb.shadow_rays)
    assert got[0].frames[1].rgb565.tobytes() != got[0].frames[0].rgb565.tobytes()  # the shapes did move
