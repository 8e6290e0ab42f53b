"""The hybrid ISA extension in the assembler: opt-in by keyword, flag or directive; the
TS words come from rend3r.isa.extensions; base programs are unchanged by the opt-in."""

from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner
from hypothesis import given, settings, strategies as st

from rend3r.asm.assembler import assemble_file, assemble_or_raise, assemble_source
from rend3r.cli import main
from rend3r.errors import Rend3rError
from rend3r.isa.extensions import decode_table_select, table_select_word
from rend3r.isa.tables import Table

from .test_fuzz import simple_lines

PROGRAMS = sorted((Path(__file__).resolve().parents[2] / "programs").glob("*.asm"))
TS_SHAPE, TS_TRIANGLE = table_select_word(Table.SHAPE), table_select_word(Table.TRIANGLE)
MIXED = "nr\nts triangle\ntr 0, x1, y1, 1, 2\nts shape\nsp 0, xloc, yloc, 1, 2\nnf\ner\ner\n"


def test_ts_words_are_the_extension_encoding():
    r = assemble_source(MIXED, isa_ext="hybrid")
    assert r.ok and not r.diagnostics, r.format_diagnostics()
    ts = [w for w in r.program.words if decode_table_select(w) is not None]
    assert ts == [TS_TRIANGLE, TS_SHAPE] == [0x12, 0x0A]
    assert r.mnemonics_used == {"nr", "ts", "tr", "sp", "nf", "er"}


@pytest.mark.parametrize("isa_ext", ["hybrid", "HYBRID", ("hybrid",), ["hybrid", "hybrid"], {"Hybrid"}])
def test_keyword_accepts_a_name_or_several(isa_ext):
    assert assemble_source(MIXED, isa_ext=isa_ext).ok


@pytest.mark.parametrize("isa_ext", ["hybrd", ("hybrid", "vector"), [""]])
def test_unknown_extension_is_a_rend3r_error(isa_ext):
    with pytest.raises(Rend3rError, match="unknown ISA extension .* \\(known: hybrid\\)"):
        assemble_source(MIXED, isa_ext=isa_ext)


def test_off_by_default_with_a_message_that_says_how():
    for r in (assemble_source(MIXED), assemble_source(MIXED, isa_ext=None), assemble_source(MIXED, isa_ext=())):
        assert [d.line for d in r.errors] == [2, 4]
        assert "enable it with '.isa_ext hybrid' in the source (or --isa-ext hybrid)" in r.errors[0].message
        assert "ts" not in r.mnemonics_used


def test_directive_is_the_same_as_the_keyword():
    by_directive = assemble_source(".isa_ext hybrid\n" + MIXED)
    by_keyword = assemble_source(MIXED, isa_ext="hybrid")
    assert by_directive.ok and by_directive.program.words == by_keyword.program.words
    assert by_directive.mnemonics_used == by_keyword.mnemonics_used


def test_file_functions_take_the_keyword(tmp_path: Path):
    src = tmp_path / "mix.asm"
    src.write_text(MIXED)
    assert assemble_file(src, isa_ext="hybrid").ok and not assemble_file(src).ok
    assert "ts" in assemble_or_raise(src, isa_ext="hybrid").mnemonics_used
    with pytest.raises(Rend3rError, match="belongs to the hybrid ISA extension"):
        assemble_or_raise(src)
    with pytest.raises(Rend3rError, match="unknown ISA extension"):
        assemble_file(tmp_path / "missing.asm", isa_ext="nope")


def test_selection_warning_names_the_line_and_the_fix():
    r = assemble_source("nr\ntr 0, x1, y1, 1, 2\ntr 1, x1, y1, 1, 2\ner\ner\n", "t.asm", isa_ext="hybrid")
    (w,) = r.warnings
    assert (w.line, w.col, w.end) == (2, 1, 3)
    assert w.message == ("'tr' writes the shape table here (a hybrid program starts with it selected); "
                         "put 'ts triangle' before it")


def test_selection_warning_in_a_rept_names_the_iteration():
    src = ".isa_ext hybrid\n.rept 2, i\n  sp i, xloc, yloc, 1, 2\n  ts triangle\n.endr\ner\ner\n"
    (w,) = assemble_source(src, "r.asm").warnings
    assert w.line == 3 and w.context == ("in .rept iteration i=1 (r.asm:2)",)


@pytest.mark.parametrize("program", PROGRAMS, ids=[p.name for p in PROGRAMS])
def test_programs_assemble_to_the_same_words_with_the_extension_on(program: Path):
    base = assemble_file(program)
    hybrid = assemble_file(program, isa_ext="hybrid")
    assert base.ok and hybrid.ok
    assert hybrid.program.words == base.program.words


_TS_LINES = st.sampled_from(["ts shape", "ts triangle", "TS Triangle ; c", "\tts\tshape // c", "ts shapes", "ts"])


@settings(max_examples=150)
@given(st.lists(st.one_of(simple_lines(), _TS_LINES), min_size=1, max_size=8), st.booleans())
def test_fast_path_agrees_with_grammar_under_the_extension(lines, in_rept):
    text = "\n".join([".rept 2, i", *lines, ".endr"] if in_rept else lines)
    fast = assemble_source(text, "f.asm", isa_ext="hybrid")
    slow = assemble_source(text, "f.asm", isa_ext="hybrid", fast=False)
    assert fast.program.entries == slow.program.entries
    assert fast.diagnostics == slow.diagnostics
    assert fast.mnemonics_used == slow.mnemonics_used


# -- rend3r asm --isa-ext ----------------------------------------------------------------


def _asm(*args: str):
    return CliRunner().invoke(main, ["asm", *args], catch_exceptions=False)


def test_cli_flag(tmp_path: Path):
    src = tmp_path / "mix.asm"
    src.write_text(MIXED)
    r = _asm(str(src), "--isa-ext", "hybrid")
    assert r.exit_code == 0 and r.stderr == ""
    assert r.stdout_bytes.split(b"\n")[1:2] == [b"00000012"]
    out = tmp_path / "mix.mem"
    r = _asm(str(src), "-o", str(out))
    assert r.exit_code == 1 and not out.exists()
    assert "mix.asm:2:1: error: unknown mnemonic 'ts'" in r.stderr and "--isa-ext hybrid" in r.stderr
    r = _asm(str(src), "--isa-ext", "vector")  # a choice, as in disasm: a usage error
    assert r.exit_code == 2 and "Invalid value for '--isa-ext': 'vector' is not 'hybrid'" in r.stderr


def test_cli_help_mentions_the_flag():
    r = _asm("--help")
    assert "--isa-ext [hybrid]" in r.output and "rend3r asm mix.asm --isa-ext hybrid" in r.output
