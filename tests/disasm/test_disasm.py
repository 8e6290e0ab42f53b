"""Disassembler output: the canonical form of syntax.md, and .word for everything else."""

from __future__ import annotations

import pytest
from hypothesis import given, settings, strategies as st

from rend3r.asm.disasm import LOSS_WARNING, disassemble, disassemble_lines, disassemble_program, float_operand, format_value
from rend3r.asm.formats import FORMATS, read_words, render
from rend3r.isa import CameraSet, LightSet, ShapeSet, Table, encode, lookup
from rend3r.isa.float16 import round_literal, shortest_repr

from .strategies import word_streams


def body(words: list[int], mode: str = "raytrace") -> list[str]:
    """The disassembly without its header line."""
    return disassemble(words, mode).splitlines()[1:]


def test_header_and_frame_ops():
    text = disassemble([0x200, 0x400, 0x600, 0, 0])
    assert text == (
        "; rend3r disassembly: 5 words, raytrace mode (sp names shape properties)\n"
        "nr\nnf\nlr\ner\ner\n"
    )


@pytest.mark.parametrize(
    "ins,line",
    [
        (CameraSet(3, 0xC000), "cam zloc, -2.0"),
        (CameraSet(5, 0x3555), "cam irot, 0.3333"),
        (CameraSet(11, 0x0001), "cam vfov, 6.0e-08"),
        (CameraSet(1, 0x8000), "cam xloc, -0.0"),
        (CameraSet(1, 0x7BFF), "cam xloc, 65500.0"),
        (CameraSet(1, 0x7C00), "cam xloc, 0h7c00"),
        (CameraSet(1, 0xFE01), "cam xloc, 0hfe01"),
        (CameraSet(0, 0), "cam zero, 0"),
        (CameraSet(0, 0xBEEF), "cam zero, 0hbeef"),
        (LightSet(63, 0, 1), "lt 63, src, 1"),
        (LightSet(0, 0, 4), "lt 0, src, 0h0004"),
        (LightSet(2, 7, 0xF81F), "lt 2, col, 0b11111_000000_11111"),
        (LightSet(2, 7, 0), "lt 2, col, 0b00000_000000_00000"),
        (LightSet(1, 8, 0x3C00), "lt 1, int, 1.0"),
        (ShapeSet(0, 13, 12, 3, 2), "sp 0, type, mat, 3, 2"),
        (ShapeSet(2**19 - 1, 13, 12, 16, 4), "sp 524287, type, mat, 0h0010, 0h0004"),
        (ShapeSet(9, 11, 0, 0x07E0, 0), "sp 9, col, zero, 0b00000_111111_00000, 0"),
        (ShapeSet(8, 1, 1, 0x3C00, 0x4000), "sp 8, xloc, xloc, 1.0, 2.0"),
    ],
)
def test_canonical_instructions(ins, line):
    assert body(list(encode(ins))) == [line]


def test_raster_mode_uses_tr_and_triangle_names():
    words = list(encode(ShapeSet(4, 9, 11, 0x3800, 0x001F)))
    assert body(words, "raster") == ["tr 4, z3, col, 0.5, 0b00000_000000_11111"]
    assert body(words, "raytrace") == ["sp 4, yscl, col, 0.5, 0b00000_000000_11111"]
    assert disassemble(words, "raster").startswith("; rend3r disassembly: 2 words, raster mode (tr names triangle")


@pytest.mark.parametrize(
    "words,lines",
    [
        ([0x00000004], [".word 0x00000004  ; reserved opcode 100 (shape init, never defined)"]),
        ([0x00000002], [".word 0x00000002  ; unused opcode 010"]),
        ([0xFFFFFFFE], [".word 0xfffffffe  ; unused opcode 110"]),
        ([0x00000007], [".word 0x00000007  ; unused opcode 111"]),
        ([0x00000800], [".word 0x00000800  ; F-type with nonzero reserved bits"]),
        ([0x3C000009], [".word 0x3c000009  ; C-type with nonzero reserved bits 10:3"]),
        ([0x00006001], [".word 0x00006001  ; camera property 12 does not exist"]),
        ([0x0000020B], [".word 0x0000020b  ; L-type with nonzero reserved bits 10:9"]),
        ([0x0000480B], [".word 0x0000480b  ; light property 9 does not exist"]),
        ([0x00000205], [".word 0x00000205  ; SE with no SD at the end"]),
        (
            [0x0000700D, 0x12345678],
            [
                ".word 0x0000700d  ; SE names shape property 14, which does not exist",
                ".word 0x12345678  ; SD of the SE above",
            ],
        ),
    ],
)
def test_words_that_decode_to_nothing(words, lines):
    assert body(words) == lines


def test_missing_property_depends_on_mode():
    words = list(encode(ShapeSet(1, 10, 0, 0x3C00, 0)))  # zscl in the shape table; a gap in the triangle table
    assert body(words) == ["sp 1, zscl, zero, 1.0, 0"]
    assert body(words, "raster")[0] == ".word 0x0000500d  ; SE names triangle property 10, which does not exist"


def test_sd_is_taken_whatever_it_looks_like():
    # The device reads the word after an SE as SD even when it looks like er or nr.
    assert body([0x0000000D, 0x00000200, 0, 0]) == ["sp 1, zero, zero, 0, 0h0200", "er", "er"]


def test_addresses_as_trailing_comments():
    lines = disassemble([0x200, 0x0000000D, 0, 0x4], addresses=True).splitlines()[1:]
    assert lines == [
        "nr                                      ; @0000",
        "sp 1, zero, zero, 0, 0                  ; @0001",
        ".word 0x00000004                        ; @0003 reserved opcode 100 (shape init, never defined)",
    ]


def test_format_value_by_property_type():
    assert format_value(lookup(Table.SHAPE, "type"), 3) == "3"
    assert format_value(lookup(Table.SHAPE, "mat"), 4) == "0h0004"
    assert format_value(lookup(Table.LIGHT, "col"), 0x8410) == "0b10000_100000_10000"
    assert format_value(lookup(Table.TRIANGLE, "x1"), 0x3E00) == "1.5"


def test_bad_mode_and_words_are_programming_errors():
    with pytest.raises(ValueError, match="unknown mode"):
        disassemble([0], "wireframe")
    with pytest.raises(ValueError, match="not a 32-bit value"):
        disassemble([2**32])


@given(word_streams(max_size=40), st.sampled_from(["raytrace", "raster"]))
def test_lines_cover_every_word_once(words, mode):
    lines = disassemble_lines(words, mode)
    assert [w for line in lines for w in line.words] == words
    assert [line.address for line in lines] == [sum(len(x.words) for x in lines[:i]) for i in range(len(lines))]
    text = disassemble(words, mode).splitlines()
    assert len(text) == 1 + len(lines)
    assert all(line == line.strip() and "\t" not in line for line in text)


@settings(max_examples=30)
@given(word_streams(max_size=20).filter(bool), st.sampled_from(list(FORMATS)))
def test_disassembled_program_renders_in_every_format(words, fmt):
    program = disassemble_program(words)
    assert program.words == words
    data = render(fmt, program)
    assert read_words(data, fmt) == words
    if fmt == "lst":
        rows = data.decode().splitlines()[2:]
        sources = [row.split("|", 3)[3].strip() for row in rows if row.split("|", 3)[3].strip()]
        assert sources == [e.text for e in program.entries]


#: Every subnormal of both signs (the only values where the shortest decimal can be more
#: than 1% off: for normals it is within half an ulp, under 0.05%), plus a spread of the rest.
SUBNORMALS = [*range(0x0000, 0x0400), *range(0x8000, 0x8400)]
SAMPLED_BITS = sorted(set(SUBNORMALS) | set(range(0x0400, 0x10000, 37)))


def test_float16_operands_round_back_without_a_precision_warning():
    longer = 0
    for bits in SAMPLED_BITS:
        text = float_operand(bits)
        if text.startswith("0h"):
            assert shortest_repr(bits) is None
            continue
        rounded = round_literal(text.lstrip("-"), negative=text.startswith("-"))
        assert rounded.bits == bits and rounded.relative_error <= LOSS_WARNING, (hex(bits), text)
        longer += text != shortest_repr(bits)
    assert longer == 24  # 12 small subnormals, each sign: 0x0002 is 1.19e-07, not 1.0e-07


def test_small_subnormal_keeps_enough_digits():
    assert float_operand(0x0002) == "1.19e-07"
    assert float_operand(0x8001) == "-6.0e-08"
