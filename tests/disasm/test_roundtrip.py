"""Round trips through the assembler: asm(disasm(W)) == W for any word stream W, and
asm(disasm(asm(P))) == asm(P) for valid programs P."""

from __future__ import annotations

import pytest
from hypothesis import given, settings, strategies as st

from rend3r.asm.disasm import disassemble
from rend3r.asm.formats import FORMATS, read_words, render
from rend3r.isa import CameraSet, LightSet, encode
from rend3r.isa.tables import LIGHT_INDEX_LIMIT, MNEMONIC_TABLE, PROPERTIES, SHAPE_INDEX_LIMIT, Table, ValueType

from rend3r.asm import assembler

from .strategies import instructions, word_streams

MODES = ["raytrace", "raster"]


def assemble(text: str) -> list[int]:
    result = assembler.assemble_source(text)
    assert result.ok, result.format_diagnostics()
    return result.program.words


@settings(max_examples=150)
@given(word_streams(max_size=30), st.sampled_from(MODES))
def test_any_word_stream_round_trips(words, mode):
    assert assemble(disassemble(words, mode)) == words


@settings(max_examples=60)
@given(st.lists(st.integers(0, 2**32 - 1), max_size=12), st.sampled_from(MODES))
def test_random_words_round_trip_with_addresses(words, mode):
    assert assemble(disassemble(words, mode, addresses=True)) == words


@settings(max_examples=100)
@given(st.sampled_from(MODES).flatmap(lambda m: st.tuples(st.just(m), instructions(_table(m)))))
def test_well_formed_instructions_print_as_instructions(mode_and_words):
    mode, words = mode_and_words
    text = disassemble(list(words), mode)
    assert ".word" not in text
    assert assemble(text) == list(words)


def test_field_values_assemble_back_without_diagnostics():
    """Every subnormal and a spread of other float16 values, and a spread of colours,
    printed canonically, assemble to the same words with no warning at all."""
    floats = [*range(0x0000, 0x0400), *range(0x8000, 0x8400), *range(0x0400, 0x10000, 37)]
    words = [encode(CameraSet(1, b))[0] for b in floats]
    words += [encode(LightSet(b % 64, 7, b))[0] for b in range(0, 0x10000, 29)] + [0, 0]
    result = assembler.assemble_source(disassemble(words))
    assert result.ok and result.diagnostics == [], result.format_diagnostics()[:2000]
    assert result.program.words == words


def _table(mode: str) -> Table:
    return Table.SHAPE if mode == "raytrace" else Table.TRIANGLE


# --- valid programs written the way people write them -------------------------------


def _spelling(prop) -> st.SearchStrategy[str]:
    """Any accepted name of a property, in any case."""
    return st.sampled_from(prop.names).flatmap(
        lambda name: st.sampled_from([name, name.upper(), name.capitalize()])
    )


_float_literal = st.one_of(
    st.integers(-65504, 65504).map(str),
    st.floats(-65000, 65000, allow_nan=False).map(lambda x: f"{x:.6g}"),
    st.floats(1e-7, 1.0).map(lambda x: f"{x:.3e}"),
    st.sampled_from(["-0", "0.1", "1_000.5", "(1 + 2) * 0.25", "-(3 / 4)", "65504", "6e-8", "R * 2"]),
    st.integers(0, 0xFFFF).map(lambda b: f"0h{b:x}"),
)


def _int_literal(bits: int) -> st.SearchStrategy[str]:
    top = (1 << bits) - 1
    return st.one_of(
        st.integers(0, top).map(str),
        st.integers(0, top).map(hex),
        st.integers(0, top).map(bin),
        st.integers(0, 0xFFFF).map(lambda b: f"0h{b:04X}"),
        st.just("N" if bits >= 2 else "0"),
    )


def _value(prop) -> st.SearchStrategy[str]:
    if prop.vtype is ValueType.FLOAT16:
        return _float_literal
    if prop.vtype is ValueType.INT:
        return _int_literal(prop.bits)
    return st.one_of(st.just("0"), st.integers(0, 0xFFFF).map(str), st.integers(0, 0xFFFF).map(lambda b: f"0h{b:x}"))


def _operand(table: Table) -> st.SearchStrategy[tuple[str, str]]:
    return st.sampled_from(PROPERTIES[table]).flatmap(lambda p: st.tuples(_spelling(p), _value(p)))


@st.composite
def _statement(draw, shape_mnemonic: str) -> str:
    kind = draw(st.sampled_from(["f", "cam", "lt", "shape", "shape", "word"]))
    if kind == "f":
        return draw(st.sampled_from(["nr", "nf", "er", "lr", "NR", "Er"]))
    if kind == "cam":
        name, value = draw(_operand(Table.CAMERA))
        return f"cam {name}, {value}"
    if kind == "lt":
        name, value = draw(_operand(Table.LIGHT))
        return f"lt {draw(st.integers(0, LIGHT_INDEX_LIMIT - 1))},{name} ,{value}"
    if kind == "word":
        return f".word {draw(st.integers(0, 2**32 - 1)):#x}, {draw(st.integers(0, 2**32 - 1))}"
    table = MNEMONIC_TABLE[shape_mnemonic]
    index = draw(st.one_of(st.integers(0, SHAPE_INDEX_LIMIT - 1), st.sampled_from(["{I}", "{I} + 1", "0", "524287"])))
    (n1, v1), (n2, v2) = draw(_operand(table)), draw(_operand(table))
    return f"{shape_mnemonic}\t{index}, {n1}, {n2}, {v1}, {v2}   // comment"


@st.composite
def source_programs(draw) -> tuple[str, str]:
    """(mode, source) using constants, a .rept block, comments, and odd spacing."""
    mode = draw(st.sampled_from(MODES))
    mnemonic = "sp" if mode == "raytrace" else "tr"
    body = draw(st.lists(_statement(mnemonic), min_size=1, max_size=8))
    rept = draw(st.lists(_statement(mnemonic), max_size=3))
    lines = ["; generated", "R = 1.5", "N = 1", "I = 3", "", *[s.replace("{I}", "I") for s in body]]
    if rept:
        lines += [f".rept {draw(st.integers(1, 3))}, k", *[s.replace("{I}", "(I + k)") for s in rept], ".endr"]
    lines += ["er", "er"]
    return mode, "\n".join(lines) + "\n"


@settings(max_examples=120)
@given(source_programs())
def test_valid_programs_round_trip(mode_and_source):
    mode, source = mode_and_source
    words = assemble(source)
    assert assemble(disassemble(words, mode)) == words
    assert assemble(disassemble(words, "raster" if mode == "raytrace" else "raytrace")) == words


@pytest.mark.parametrize("fmt", FORMATS)
def test_assembled_program_through_every_format(fmt):
    source = "nr\ncam zloc, 2\nlt 0, src, 1\nlt 0, col, 0b11111_000000_00000\nsp 1, xloc, type, -1.5, 1\nnf\ner\ner\n"
    result = assembler.assemble_source(source, "scene.asm")
    assert result.ok, result.format_diagnostics()
    words = read_words(render(fmt, result.program), fmt)
    assert words == result.program.words
    assert disassemble(words).splitlines()[1:] == [
        "nr",
        "cam zloc, 2.0",
        "lt 0, src, 1",
        "lt 0, col, 0b11111_000000_00000",
        "sp 1, xloc, type, -1.5, 1",
        "nf",
        "er",
        "er",
    ]
