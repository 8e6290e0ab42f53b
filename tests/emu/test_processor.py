"""Instruction processor: nr/nf/er/lr semantics, --frames, errors with addresses, sparse state."""

import pytest

from rend3r.emu.options import EmuOptions
from rend3r.emu.processor import execute
from rend3r.emu.scene import Scene, prop_index
from rend3r.errors import Rend3rError
from rend3r.isa import Table
from rend3r.isa.encoding import encode, ShapeSet

from .scenes import Prog, f16

SPEC = EmuOptions()


def _frames(words, options=SPEC, frames=None):
    seen = []
    ex = execute(words, options, frames, lambda scene, n: seen.append((n, len(scene.objects))))
    return ex, seen


def test_nf_renders_er_halts_and_words_after_er_are_ignored():
    words = Prog().nr().sphere(0).nf().nf().er().words + [0x00000002]  # unknown opcode never reached
    ex, seen = _frames(words)
    assert (ex.frames, ex.halt) == (2, "er")
    assert seen == [(0, 1), (1, 1)]


def test_running_past_the_end_halts():
    ex, _ = _frames(Prog().nr().nf().words)
    assert (ex.frames, ex.halt) == (1, "end")


def test_nr_clears_scene_by_default_and_not_with_device_option():
    words = Prog().nr().sphere(0).nf().nr().nf().er().words
    _, seen = _frames(words)
    assert seen == [(0, 1), (1, 0)]
    _, seen = _frames(words, EmuOptions(clear_on_nr=False))
    assert seen == [(0, 1), (1, 1)]


def test_loop_needs_a_frames_bound():
    words = Prog().nr().sphere(0).nf().lr().words
    at = len(words) - 1
    with pytest.raises(Rend3rError, match=rf"address {at} \(0x{at:04x}\): the program loops.*--frames"):
        _frames(words)
    ex, seen = _frames(words, frames=5)
    assert (ex.frames, ex.halt) == (5, "frames")
    assert [n for n, _ in seen] == [0, 1, 2, 3, 4]


def test_lr_target_one_skips_the_first_word():
    # nr at 0 clears; looping to 1 (the device) keeps the shape from the first pass.
    words = Prog().nr().nf().sphere(0).lr().words
    _, seen = _frames(words, frames=2)
    assert seen == [(0, 0), (1, 0)]
    _, seen = _frames(words, EmuOptions(lr_target=1), frames=2)
    assert seen == [(0, 0), (1, 1)]


def test_loop_without_nf_is_an_error_even_with_a_bound():
    with pytest.raises(Rend3rError, match="without rendering"):
        _frames(Prog().nr().sphere(0).lr().words, frames=3)


def test_unknown_opcode_and_trailing_se_report_their_address():
    with pytest.raises(Rend3rError, match=r"address 1 \(0x0001\): unknown opcode 0b110 in word 0x00000006"):
        _frames(Prog().nr().words + [0x6])
    se = encode(ShapeSet(0, 1, 2, 0, 0))[0]
    with pytest.raises(Rend3rError, match=r"address 1 .*SE word .* SD is missing"):
        _frames(Prog().nr().words + [se])


def test_se_takes_the_next_word_as_sd_even_when_it_is_zero_or_looks_like_er():
    words = Prog().nr().words + list(encode(ShapeSet(5, prop_index(Table.SHAPE, "type"), 0, 0, 0))) + Prog().nf().words
    scene = Scene()
    ex = execute(words, SPEC, scene=scene)
    assert ex.frames == 1
    assert scene.objects.index.tolist() == [5] and scene.objects.row(5) == {}  # touched, type 0


def test_prop2_wins_when_both_name_the_same_property_and_zero_prop_writes_nothing():
    x = prop_index(Table.SHAPE, "xloc")
    words = Prog().words + list(encode(ShapeSet(3, x, x, f16(1.0), f16(2.0)))) + list(encode(ShapeSet(4, 0, 0, 7, 7)))
    scene = Scene()
    execute(words, SPEC, scene=scene)
    assert scene.objects.index.tolist() == [3] and scene.objects.row(3) == {x: f16(2.0)}


def test_scene_is_sparse_for_huge_indices():
    scene = Scene()
    execute(Prog().sphere((1 << 19) - 1).words, SPEC, scene=scene)
    assert scene.objects.index.tolist() == [(1 << 19) - 1]


def test_frames_bound_must_be_positive():
    with pytest.raises(Rend3rError, match="at least 1"):
        _frames(Prog().nf().words, frames=0)


def test_device_er_halts_only_before_a_zero_word():
    words = Prog().nr().er().nf().er().er().words  # er, nf: the device skips the first er
    ex, seen = _frames(words, EmuOptions(er_needs_zero=True))
    assert (ex.frames, ex.halt) == (1, "er")
    ex, _ = _frames(words)
    assert ex.frames == 0


def test_rgb444_display_widens_the_low_12_bits():
    import numpy as np

    from rend3r.emu.run import rgb444_display

    got = rgb444_display(np.array([0xF800, 0x0FFF, 0x0123], np.uint16))
    assert got.tolist() == [(17 << 11), 0xFFFF, (2 << 11) | (8 << 5) | 6]
