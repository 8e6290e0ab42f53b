"""The hybrid ISA extension in the disassembler: TS words as ``ts``, pairs named by the
table they select, ``.isa_ext hybrid`` on top; round trips in both modes."""

from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner
from hypothesis import given, settings, strategies as st

from rend3r.asm import assembler
from rend3r.asm.disasm import disassemble, disassemble_lines, disassemble_program
from rend3r.asm.formats import render
from rend3r.cli import main
from rend3r.isa import ShapeSet, encode
from rend3r.isa.extensions import TS_OPCODE, decode_table_select, table_select_word
from rend3r.isa.tables import Table

from .strategies import any_word, instructions
from .test_roundtrip import _statement

TS = {t: table_select_word(t) for t in (Table.SHAPE, Table.TRIANGLE)}
PAIR = encode(ShapeSet(0, 1, 2, 0x3C00, 0x4000))
WORDS = [0x200, *PAIR, TS[Table.TRIANGLE], *PAIR, 0x1A, 0x2A, 0x02, TS[Table.SHAPE], *PAIR, 0, 0]
HYBRID_MIX = Path(__file__).resolve().parents[2] / "programs" / "hybrid_mix.asm"


def assemble(text: str) -> assembler.AssemblyResult:
    result = assembler.assemble_source(text)
    assert result.ok, result.format_diagnostics()
    return result


def test_ts_words_select_the_pair_names():
    assert disassemble(WORDS, isa_ext="hybrid").splitlines() == [
        "; rend3r disassembly: 14 words, hybrid ISA extension (ts selects the table: sp names shape properties, "
        "tr triangle ones)",
        ".isa_ext hybrid",
        "nr",
        "sp 0, xloc, yloc, 1.0, 2.0",
        "ts triangle",
        "tr 0, x1, y1, 1.0, 2.0",
        ".word 0x0000001a  ; opcode 010 with reserved table code 11 (not a TS word)",
        ".word 0x0000002a  ; opcode 010 with nonzero bits 31:5 (not a TS word)",
        ".word 0x00000002  ; opcode 010 with reserved table code 00 (not a TS word)",
        "ts shape",
        "sp 0, xloc, yloc, 1.0, 2.0",
        "er",
        "er",
    ]


def test_without_the_extension_ts_words_stay_words():
    text = disassemble(WORDS)
    assert ".isa_ext" not in text and "ts " not in text
    assert ".word 0x00000012  ; unused opcode 010" in text and ".word 0x0000000a  ; unused opcode 010" in text
    assert "tr " not in text


def test_a_missing_property_follows_the_selected_table():
    se, sd = encode(ShapeSet(0, 10, 1, 0, 0))  # shape property 10 exists, triangle property 10 does not
    lines = disassemble_lines([TS[Table.TRIANGLE], se, sd, TS[Table.SHAPE], se, sd], isa_ext="hybrid")
    assert [line.text.split()[0] for line in lines] == ["ts", ".word", ".word", "ts", "sp"]
    assert lines[1].note == "SE names triangle property 10, which does not exist"


def test_addresses_and_program_and_keyword_forms():
    text = disassemble(WORDS, addresses=True, isa_ext=("HYBRID",))
    assert text.splitlines()[1] == ".isa_ext hybrid"
    assert "ts triangle                             ; @0003" in text
    program = disassemble_program(WORDS, isa_ext={"hybrid"})
    assert program.words == WORDS and program.entries[2].text == "ts triangle"
    assert render("lst", program)


def test_bad_arguments_are_programming_errors():
    with pytest.raises(ValueError, match="unknown ISA extension 'vector'"):
        disassemble(WORDS, isa_ext="vector")
    with pytest.raises(ValueError, match="raster mode does not apply with the hybrid extension"):
        disassemble(WORDS, "raster", isa_ext="hybrid")


# -- round trips -----------------------------------------------------------------------

_ts_like = st.one_of(
    st.sampled_from(list(TS.values())).map(lambda w: (w,)),
    st.integers(0, 2**29 - 1).map(lambda w: ((w << 3) | TS_OPCODE,)),  # opcode 010, any other bits
)


@st.composite
def hybrid_streams(draw) -> list[int]:
    """Random words, well-formed instructions of either table and TS(-like) words."""
    chunks = draw(st.lists(st.one_of(any_word.map(lambda w: (w,)), instructions(Table.SHAPE),
                                     instructions(Table.TRIANGLE), _ts_like), max_size=30))
    return [w for c in chunks for w in c]


@settings(max_examples=150)
@given(hybrid_streams(), st.booleans())
def test_any_word_stream_round_trips_in_both_modes(words, addresses):
    hybrid = assemble(disassemble(words, addresses=addresses, isa_ext="hybrid"))
    assert hybrid.program.words == words
    assert not [d for d in hybrid.warnings if "table here" in d.message]
    assert assemble(disassemble(words, addresses=addresses)).program.words == words


@st.composite
def well_formed_hybrid(draw) -> list[int]:
    """Instructions only, each pair of the table the last TS word selected."""
    words, table = [], Table.SHAPE
    for _ in range(draw(st.integers(0, 12))):
        if draw(st.integers(0, 3)) == 0:
            table = draw(st.sampled_from(list(TS)))
            words.append(TS[table])
        else:
            words.extend(draw(instructions(table)))
    return words


@settings(max_examples=100)
@given(well_formed_hybrid())
def test_well_formed_hybrid_words_print_as_instructions(words):
    text = disassemble(words, isa_ext="hybrid")
    assert ".word" not in text
    result = assemble(text)
    assert result.program.words == words
    assert not [d for d in result.warnings if "table here" in d.message]


@st.composite
def hybrid_sources(draw) -> str:
    lines = [".isa_ext hybrid", "R = 1.5", "N = 1", "I = 3"]
    for _ in range(draw(st.integers(1, 4))):
        mnemonic = draw(st.sampled_from(["sp", "tr"]))
        lines.append("ts " + draw(st.sampled_from(["shape", "SHAPE"] if mnemonic == "sp" else ["triangle", "Triangle"])))
        lines += [s.replace("{I}", "I") for s in draw(st.lists(_statement(mnemonic), min_size=1, max_size=4))]
    return "\n".join([*lines, "er", "er"]) + "\n"


@settings(max_examples=80)
@given(hybrid_sources())
def test_valid_hybrid_programs_round_trip(source):
    result = assemble(source)
    words = result.program.words
    assert "ts" in result.mnemonics_used
    assert assemble(disassemble(words, isa_ext="hybrid")).program.words == words
    assert assemble(disassemble(words)).program.words == words


# -- rend3r disasm --isa-ext -----------------------------------------------------------


def _disasm(*args: str):
    return CliRunner().invoke(main, ["disasm", *args])


def test_cli_flag_and_hybrid_mix_round_trip(tmp_path: Path):
    program = assembler.assemble_file(HYBRID_MIX).program
    mem = tmp_path / "mix.mem"
    mem.write_bytes(render("mem", program))
    r = _disasm(str(mem), "--isa-ext", "hybrid")
    assert r.exit_code == 0, r.output
    lines = r.output.splitlines()
    assert lines[1] == ".isa_ext hybrid" and "ts shape" in lines and "ts triangle" in lines
    assert [decode_table_select(w) for w in program.words if decode_table_select(w)] == [Table.SHAPE, Table.TRIANGLE]
    assert assemble(r.output).program.words == program.words
    plain = _disasm(str(mem))
    assert plain.exit_code == 0 and "ts " not in plain.output and assemble(plain.output).program.words == program.words


def test_cli_rejects_raster_with_the_extension_and_unknown_names(tmp_path: Path):
    mem = tmp_path / "w.mem"
    mem.write_text("00000012\n")
    r = _disasm(str(mem), "--isa-ext", "hybrid", "--mode", "raster")
    assert r.exit_code == 1 and "--mode raster does not apply with --isa-ext hybrid" in r.output
    assert _disasm(str(mem), "--isa-ext", "vector").exit_code == 2
