"""Hybrid frames: the TS extension word routes SE/SD pairs; shapes and triangles merge by depth."""

import numpy as np
import pytest

from rend3r.emu.hybrid import TRIANGLE_BASE
from rend3r.isa.extensions import decode_table_select, table_select_word
from rend3r.emu.options import EmuOptions
from rend3r.emu.run import run_program
from rend3r.errors import Rend3rError
from rend3r.isa import ShapeSet, Table, encode, lookup

from .scenes import Prog, f16

W, H = 48, 36


def _tri_words(index, verts, col):
    names = ("x1", "y1", "z1", "x2", "y2", "z2", "x3", "y3", "z3")
    vals = [f16(v) for v in np.ravel(verts)] + [col]
    props = [lookup(Table.TRIANGLE, n).index for n in names] + [lookup(Table.TRIANGLE, "col").index]
    words = []
    for a in range(0, 10, 2):
        words += encode(ShapeSet(index, props[a], props[a + 1], vals[a], vals[a + 1]))
    return words


def _program():
    p = Prog().nr().cam(hfov=0.3, vfov=0.3).sphere(0, loc=(0.0, 0.0, -4.0), col=0xF800)
    p.words += [table_select_word(Table.TRIANGLE)]
    p.words += _tri_words(0, [(-9, -9, -6), (9, -9, -6), (0, 9, -6)], 0x07E0)  # wall behind the sphere
    p.words += _tri_words(1, [(0.2, 0.2, -2), (2, 0.2, -2), (0.2, 2, -2)], 0x001F)  # in front, upper right
    p.words += [table_select_word(Table.SHAPE)]
    p.sphere(1, loc=(-0.9, -0.9, -3.0), scale=(3.0, 3.0, 3.0), col=0xFFE0)
    return p.nf().er()


def test_table_select_words_round_trip_and_reject_noncanonical_words():
    for t in (Table.SHAPE, Table.TRIANGLE):
        assert decode_table_select(table_select_word(t)) is t
    assert table_select_word(Table.SHAPE) == 0x0000000A and table_select_word(Table.TRIANGLE) == 0x00000012
    assert decode_table_select(0x0000001A) is None  # code 0b11 is reserved
    assert decode_table_select(0x0000002A) is None  # a non-zero bit outside 4:3
    assert decode_table_select(0x00000002) is None  # code 0: no table


def test_hybrid_frame_merges_shapes_and_triangles_by_depth():
    (frame,) = run_program(_program().words, EmuOptions(mode="hybrid", width=W, height=H)).frames
    prov = frame.provenance
    assert prov[H // 2, W // 2] == 0  # the sphere in front of the wall
    assert prov[2, W // 2] == TRIANGLE_BASE + 0  # the wall around it
    assert (prov == TRIANGLE_BASE + 1).any() and (prov == 1).any()  # the near triangle and shape 1
    # Depth decides: the near triangle (at most 2.84 from the eye) shows over the sphere
    # (nearest point 3 away), which shows over the wall (6 away).
    near_tri = prov == TRIANGLE_BASE + 1
    assert (frame.depth[near_tri] < 2.9).all()
    assert (frame.depth[prov == 0] >= 2.99).all() and (frame.depth[prov == TRIANGLE_BASE] > 5.9).all()
    assert np.isfinite(frame.depth[prov >= 0]).all()


def test_base_modes_reject_the_extension_word():
    with pytest.raises(Rend3rError, match="unknown opcode 0b010"):
        run_program(_program().words, EmuOptions(width=W, height=H))


def test_hybrid_without_select_words_equals_raytrace_mode():
    words = Prog().nr().sphere(0, loc=(0.0, 0.0, -4.0)).dir_light(0).nf().er().words
    a = run_program(words, EmuOptions(mode="hybrid", width=W, height=H)).frames[0]
    b = run_program(words, EmuOptions(width=W, height=H)).frames[0]
    assert np.array_equal(a.rgb565, b.rgb565) and np.array_equal(a.provenance, b.provenance)


def test_ts_word_outside_hybrid_mode_names_the_fix():
    with pytest.raises(Rend3rError, match="--mode hybrid"):
        run_program([table_select_word(Table.TRIANGLE), 0, 0], options=EmuOptions(mode="raytrace"))
