"""The assembler API: results, diagnostics format, includes, limits, files."""

from __future__ import annotations

from pathlib import Path

import pytest

from rend3r.asm import assembler
from rend3r.asm.assembler import assemble_file, assemble_or_raise, assemble_source
from rend3r.asm.formats import render
from rend3r.errors import Rend3rError


def test_result_program_and_mnemonics():
    r = assemble_source("nr\ncam xloc, 1\ntr 0, x1, y1, 1, 2\ner\ner\n", "p.asm")
    assert r.ok and not r.diagnostics
    assert r.program.words == [0x200, 0x3C000801, 0x00000885, 0x3C004000, 0, 0]
    assert r.mnemonics_used == {"nr", "cam", "tr", "er"}
    e = r.program.entries[2]
    assert (e.address, e.loc.file, e.loc.line, e.loc.col, e.text) == (2, "p.asm", 3, 1, "tr 0, x1, y1, 1, 2")


@pytest.mark.parametrize("source, mode", [("nr\ncam xloc, 1\n", "raytrace"), ("nr\ntr 0, x1, y1, 1, 2\n", "raster"),
                                          (".isa_ext hybrid\nts triangle\ntr 0, x1, y1, 1, 2\n", "hybrid")])
def test_mode_follows_the_mnemonics_used(source, mode):
    assert assemble_source(source + "er\ner\n").mode == mode


def test_files_read_in_order_resolved_and_a_missing_include_where_it_was_looked_for(tmp_path: Path):
    (tmp_path / "lib").mkdir()
    (tmp_path / "lib" / "a.inc").write_text('.include "b.inc"\n.include "gone.inc"\n')
    (tmp_path / "lib" / "b.inc").write_text("B = 1\n")
    main = tmp_path / "main.asm"
    main.write_text('.rept 3\n.include "lib/../lib/a.inc"\n.endr\ner\ner\n')
    r = assemble_file(main)
    assert r.files == [main.resolve(), tmp_path.resolve() / "lib" / "a.inc", tmp_path.resolve() / "lib" / "b.inc",
                       tmp_path / "lib" / "gone.inc"]
    assert assemble_file(tmp_path / "none.asm").files == [tmp_path / "none.asm"]
    assert assemble_source("nr\ner\ner\n").files == []


def test_mem_output_is_the_original_format():
    r = assemble_source("nr\nsp 3, xloc, yloc, 0.5, -0\ner\ner")
    assert render("mem", r.program) == b"00000200\n0000089d\n38008000\n00000000\n00000000\n"


def test_diagnostic_format_with_caret_and_summary():
    r = assemble_source("cam xloc, 1\n  sp 0, xlco, yloc, 1, 2\n\tlt 99, xloc, 1\ner\ner\n", "m.asm")
    text = r.format_diagnostics()
    assert not r.ok
    assert (
        "m.asm:2:9: error: unknown shape property 'xlco'; did you mean 'xloc'?\n"
        "      sp 0, xlco, yloc, 1, 2\n"
        "            ^~~~\n"
    ) in text
    # a tab before the span is kept in the caret line so it lines up
    assert "m.asm:3:5: error: light index 99 is out of range (0..63)\n    \tlt 99, xloc, 1\n    \t   ^~\n" in text
    assert text.endswith("2 errors generated.")


def test_all_errors_reported_and_lines_after_errors_assemble():
    src = "\n".join(["cam bad, 1", "cam xloc, 2", "lt 64, xloc, 1", "foo", "cam yloc, 3", "er", "er"])
    r = assemble_source(src)
    assert [d.line for d in r.errors] == [1, 3, 4]
    assert [e.loc.line for e in r.program.entries] == [2, 5, 6, 7]


def test_rept_context_and_dedup():
    r = assemble_source(".rept 3, i\ncam xloc, 1 / (i - 1)\n.endr\ner\ner", "r.asm")
    (d,) = r.errors
    assert d.message == "division by zero" and d.context == ("in .rept iteration i=1 (r.asm:1)",)
    assert "    in .rept iteration i=1 (r.asm:1)" in d.format()
    assert len(r.program.entries) == 4  # two good iterations and two er


def test_include_context_and_search_path(tmp_path: Path):
    (tmp_path / "lib").mkdir()
    (tmp_path / "lib" / "defs.inc").write_text("R = 2\ncam xloc, nope\n")
    main = tmp_path / "main.asm"
    main.write_text("nr\n.include \"defs.inc\"\ncam yloc, R\ner\ner\n")
    r = assemble_file(main, include_paths=[tmp_path / "lib"])
    (d,) = r.errors
    assert d.file.endswith("defs.inc") and d.line == 2
    assert d.context == (f"included from {main}:2",)
    assert r.program.words[-3] == 0x40001001
    missing = assemble_file(main)
    assert "cannot find include file 'defs.inc'" in missing.format_diagnostics()


def test_include_cycle_of_main_file(tmp_path: Path):
    main = tmp_path / "self.asm"
    main.write_text('.include "self.asm"\ner\ner\n')
    r = assemble_file(main)
    assert [d.message for d in r.errors] == ["include cycle: self.asm -> self.asm"]


def test_missing_unreadable_and_binary_files(tmp_path: Path):
    r = assemble_file(tmp_path / "nope.asm")
    assert not r.ok and "cannot read" in r.format_diagnostics()
    (tmp_path / "bin.asm").write_bytes(b"\x00\xff\xfe garbage")
    assert "is not UTF-8 text" in assemble_file(tmp_path / "bin.asm").format_diagnostics()
    (tmp_path / "dir.asm").mkdir()
    assert "cannot read" in assemble_file(tmp_path / "dir.asm").format_diagnostics()


def test_nul_and_control_characters_are_clean_errors():
    r = assemble_source("cam xloc, 1\x00\ncam\x07 xloc, 1\ner\ner")
    assert [d.message for d in r.errors] == ["unexpected character U+0000", "unexpected character U+0007"]


def test_assemble_or_raise(tmp_path: Path):
    good = tmp_path / "g.asm"
    good.write_text("nr\ner\ner\n")
    assert assemble_or_raise(good).program.words == [0x200, 0, 0]
    bad = tmp_path / "b.asm"
    bad.write_text("cam q, 1\nlt 70, xloc, 1\ner\ner\n")
    with pytest.raises(Rend3rError) as exc:
        assemble_or_raise(bad)
    assert "b.asm:1:5: error" in str(exc.value) and "b.asm:2:4: error" in str(exc.value)


def test_werror_promotes_warnings():
    r = assemble_source("cam xloc, 1e-9\ner\ner", werror=True)
    assert not r.ok and r.errors[0].message.endswith("[-W error]")
    assert assemble_source("cam xloc, 1e-9\ner\ner").ok


def test_unknown_target_is_a_user_error():
    with pytest.raises(Rend3rError, match="unknown target 'nope'"):
        assemble_source("er\ner", target="nope")


def test_statement_limit(monkeypatch):
    monkeypatch.setattr(assembler, "MAX_STATEMENTS", 50)
    r = assemble_source(".rept 10, i\n.rept 10, j\nnr\n.endr\n.endr\ner\ner")
    assert [d.message for d in r.errors] == [
        "program too large: more than 50 statements after .rept expansion "
        "(each operand, operator and line read by .include counts as one)"]


def test_huge_literals_are_bounded():
    r = assemble_source("cam xloc, " + "9" * 2000 + "\ncam xloc, 1e-99999\ner\ner")
    assert [d.message.split(" (")[0] for d in r.errors] == [
        "number '99999999999999999999...' has too many digits",
        "exponent of '1e-99999' is out of range",
    ]


def test_empty_program_warns():
    r = assemble_source("// nothing\n", "e.asm")
    assert r.ok and [d.message for d in r.warnings] == [
        "program does not end with two 'er' (the device stops at an er followed by a zero word)"
    ]


def test_crlf_and_bom(tmp_path: Path):
    p = tmp_path / "w.asm"
    p.write_bytes(b"\xef\xbb\xbfnr\r\ncam xloc, 1 ; c\r\ner\r\ner\r\n")
    r = assemble_file(p)
    assert r.ok and r.program.words == [0x200, 0x3C000801, 0, 0]
    assert r.program.entries[1].text == "cam xloc, 1 ; c"
