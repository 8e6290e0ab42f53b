"""Working arrays kept from frame to frame (rend3r/emu/workspace.py): memory is reused only
once nothing refers to it, and repeated frames neither grow it nor change a pixel."""

from __future__ import annotations

import sys
import threading
from pathlib import Path

import numpy as np

from rend3r.emu import workspace
from rend3r.emu.options import EmuOptions
from rend3r.emu.run import run_program

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


def test_a_buffer_comes_back_once_its_array_is_gone() -> None:
    _on_a_thread_of_its_own(_comes_back)


def _comes_back() -> None:
    first = workspace.empty(BIG // 8)
    at = first.ctypes.data
    del first
    again = workspace.empty((BIG // 16, 2))
    assert again.ctypes.data == at and again.shape == (BIG // 16, 2) and again.flags.c_contiguous


def test_an_array_or_view_alive_keeps_its_buffer() -> None:
    first = workspace.empty(BIG, np.uint8)
    view = first[10:20]
    del first
    second = workspace.empty(BIG, np.uint8)
    view[:] = 7
    second[:] = 1
    assert not np.shares_memory(view, second)
    assert (view == 7).all()


def test_small_arrays_and_arrays_past_the_cap_take_no_buffer() -> None:
    _on_a_thread_of_its_own(_past_the_cap)


def _past_the_cap() -> None:
    before = workspace.kept_bytes()
    small = workspace.empty(BIG // 8 - 1, np.uint8)
    assert workspace.kept_bytes() == before and small.size == BIG // 8 - 1
    alive = [workspace.empty(BIG, np.uint8) for _ in range(workspace.KEPT + 3)]
    assert len({a.ctypes.data for a in alive}) == len(alive)  # none shares memory
    assert workspace.kept_bytes() == workspace.KEPT * (BIG + BIG // 8)  # the first KEPT got one each


def test_a_free_buffer_too_small_is_replaced_not_kept_beside() -> None:
    _on_a_thread_of_its_own(_replaced)


def _replaced() -> None:
    a = workspace.empty(BIG, np.uint8)
    del a
    kept = workspace.kept_bytes()
    b = workspace.empty(4 * BIG, np.uint8)
    assert workspace.kept_bytes() - kept <= 4 * BIG + BIG // 2 - BIG  # the small one went
    del b


def test_each_thread_has_its_own_buffers() -> None:
    mine = workspace.empty(BIG, np.uint8)
    theirs = []
    t = threading.Thread(target=lambda: theirs.append(workspace.empty(BIG, np.uint8)))
    t.start()
    t.join()
    assert not np.shares_memory(mine, theirs[0])


def test_repeated_frames_keep_their_memory_and_their_pixels() -> None:
    """A wall of 4,096 spheres rendered again and again (on a thread of its own, whose
    buffers no other test touched): the kept bytes stop growing after a few runs (a
    buffer is only ever replaced by a larger one, up to the largest array asked for) and
    stay within twice the first run's, every frame is the same, and a frame kept from an
    earlier run is not touched by later ones (frames never come from the buffers)."""
    words = walls.wall(4096, lights=1).words
    options = EmuOptions(precision="fp32", width=96, height=64, jobs=1)
    kept: list[int] = []

    def runs() -> None:
        first = run_program(words, options).frames[0]
        copy = first.rgb565.copy(), first.depth.copy(), first.provenance.copy()
        kept.append(workspace.kept_bytes())
        for _ in range(6):
            again = run_program(words, options).frames[0]
            assert (again.rgb565 == copy[0]).all() and (again.provenance == copy[2]).all()
            assert not np.shares_memory(again.rgb565, first.rgb565)
            kept.append(workspace.kept_bytes())
        assert (first.rgb565 == copy[0]).all() and np.array_equal(first.depth, copy[1], equal_nan=True)

    _on_a_thread_of_its_own(runs)
    assert 0 < kept[0] and kept[-1] == kept[-2] == kept[-3] <= 2 * kept[0], kept

