"""Hostile sources through the real CLI (issue 13): every one ends with a clear
``error:`` naming the limit and exit 1, never a traceback, a hang or unbounded memory."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
from click.testing import CliRunner

from rend3r.asm import assembler
from rend3r.cli import main


def _asm(tmp_path: Path, text: str, *args: str, name: str = "h.asm") -> tuple[int, str, Path]:
    src = tmp_path / name
    src.write_text(text, encoding="utf-8")
    out = tmp_path / "h.mem"
    r = CliRunner().invoke(main, ["asm", str(src), "-o", str(out), *args])
    assert r.exception is None or isinstance(r.exception, SystemExit), r.exception
    assert "Traceback" not in r.output
    return r.exit_code, r.stderr, out


def _fails_with(tmp_path: Path, text: str, message: str, *args: str) -> str:
    code, err, out = _asm(tmp_path, text, *args)
    assert code == 1 and message in err and not out.exists(), err[-2000:]
    return err


@pytest.mark.parametrize("operand", ["-" * 990 + "1", "+".join(["0"] * 1000), "(" * 300 + "-" * 300 + "1" + ")" * 300])
def test_deep_expressions(tmp_path: Path, operand: str):
    _fails_with(tmp_path, f"cam xloc, {operand}\ner\ner\n", "expression nested too deeply (more than 200 levels")
    _fails_with(tmp_path, f"A = {operand}\ner\ner\n", "expression nested too deeply (more than 200 levels")
    _fails_with(tmp_path, f".rept 2\n.word {operand}\n.endr\ner\ner\n", "expression nested too deeply")


def test_include_chain_250_deep(tmp_path: Path):
    for i in range(250):
        (tmp_path / f"f{i}.inc").write_text(f'.include "f{i + 1}.inc"\n' if i < 249 else "nr\n")
    _fails_with(tmp_path, '.include "f0.inc"\ner\ner\n', ".include nested too deeply (more than 32 levels)")


def test_rept_nested_500_deep(tmp_path: Path):
    _fails_with(tmp_path, ".rept 1\n" * 500 + "nr\n" + ".endr\n" * 500 + "er\ner\n",
                ".rept blocks nested too deeply (more than 64 levels)")


def test_limits_fit_together_under_the_default_recursion_limit(tmp_path: Path):
    """The deepest of everything at once (includes, .rept inside them, the deepest
    expression) assembles in a plain process: the limits leave the stack room."""
    depth = assembler.MAX_INCLUDE_DEPTH
    for i in range(depth - 1):
        (tmp_path / f"f{i}.inc").write_text(f'.include "f{i + 1}.inc"\n')
    deep = "1" + "+0" * 199
    (tmp_path / f"f{depth - 1}.inc").write_text(".rept 1\n" * 63 + f"cam xloc, {deep}\n" + ".endr\n" * 63)
    src = tmp_path / "top.asm"
    src.write_text(f".rept 1\n.include \"f0.inc\"\n.endr\ncam yloc, {'-' * 200}1\ner\ner\n")
    p = subprocess.run([sys.executable, "-m", "rend3r", "asm", str(src)], capture_output=True, timeout=120)
    assert p.returncode == 0, p.stderr.decode()[-3000:]
    assert p.stdout.decode().split() == ["3c000801", "3c001001", "00000000", "00000000"]


@pytest.mark.parametrize("line", ["lt 0, col, 1e4000*1e4000", ".word 1e4000*1e4000", "cam xloc, 1e4000*1e4000",
                                  ".rept 1e4000*1e4000\n.endr"])
def test_huge_products_are_out_of_range(tmp_path: Path, line: str):
    _fails_with(tmp_path, line + "\ner\ner\n", "exact arithmetic is limited to 13,300-bit numerators")


def test_repeated_squaring_is_bounded(tmp_path: Path):
    text = "A0 = 1e3999\n" + "".join(f"A{i + 1} = A{i} * A{i}\n" for i in range(12)) + "cam xloc, A12\ner\ner\n"
    err = _fails_with(tmp_path, text, "h.asm:2:6: error: result out of range")
    assert err.count("error:") == 2  # A1's definition, and the summary; A2..A12 are not reported again


def test_huge_literals_in_messages_are_cut(tmp_path: Path):
    err = _fails_with(tmp_path, "cam xloc, 1e" + "7" * 3000 + "\n.word 0x" + "f" * 900 + "\ner\ner\n",
                      "exponent of '1e77777777777777777777777777777777777...' is out of range")
    assert "is out of range (0..4294967295)" in err and "about 5.104e+1083" in err


def test_long_include_name(tmp_path: Path):
    _fails_with(tmp_path, '.include "' + "a" * 300 + '.asm"\ner\ner\n', "File name too long")


def test_quadratic_regex_case_is_linear(tmp_path: Path):
    err = _fails_with(tmp_path, "cam xloc, 1" + " " * 4000 + "(\ner\ner\n", "unexpected '('")
    assert max(len(line) for line in err.splitlines()) < 400  # the line is shown as a window


def test_megabyte_line_is_refused(tmp_path: Path):
    err = _fails_with(tmp_path, "cam xloc, 1" + " " * (1 << 20) + "(\ner\ner\n",
                      "h.asm:1:4097: error: line is 1,048,588 characters long; the limit is 4,096")
    assert len(err) < 2000


def test_max_errors_stops_the_run(tmp_path: Path):
    text = ".rept 1048000, i\nlt i + 64, xloc, 1\n.endr\ner\ner\n"
    err = _fails_with(tmp_path, text, "stopped after 20 errors")
    assert err.count(": error: light index") == 20
    err = _fails_with(tmp_path, text, "stopped after 3 errors", "--max-errors", "3")
    assert err.count(": error: light index") == 3
    err = _fails_with(tmp_path, ".rept 50, i\nlt i + 64, xloc, 1\n.endr\ner\ner\n", "50 errors generated",
                      "--max-errors", "0")
    assert "stopped" not in err
    code, err, _ = _asm(tmp_path, "er\ner\n", "--max-errors", "-1")
    assert code == 2 and "--max-errors" in err


def test_max_errors_counts_promoted_warnings(tmp_path: Path):
    err = _fails_with(tmp_path, ".rept 30, i\nlt i, xloc, 1\n.endr\ner\ner\n", "stopped after 4 errors",
                      "--target", "rend3r-main", "-W", "error", "--max-errors", "4")
    assert err.count("[-W error]") == 4


def test_statement_cap_counts_operands_and_operators(tmp_path: Path, monkeypatch):
    monkeypatch.setattr(assembler, "MAX_STATEMENTS", 1000)
    # 60 statements of 20 nodes: the old count (one per statement) let any body run
    _fails_with(tmp_path, ".rept 60, i\nA = " + "+".join(["i"] * 10) + "\n.endr\ner\ner\n",
                "program too large: more than 1,000 statements")
    code, _, _ = _asm(tmp_path, ".rept 40, i\nA = " + "+".join(["i"] * 10) + "\n.endr\ner\ner\n")
    assert code == 0


def test_include_in_a_rept_counts_its_lines(tmp_path: Path, monkeypatch):
    monkeypatch.setattr(assembler, "MAX_STATEMENTS", 1000)
    (tmp_path / "blank.inc").write_text("\n" * 100)
    _fails_with(tmp_path, '.rept 20\n.include "blank.inc"\n.endr\ner\ner\n', "program too large")


def test_total_reading_is_capped(tmp_path: Path, monkeypatch):
    monkeypatch.setattr(assembler, "MAX_READ", 10_000)
    (tmp_path / "c.inc").write_text("; comment\n" * 100)
    _fails_with(tmp_path, '.rept 20\n.include "c.inc"\n.endr\ner\ner\n', "sources too large: more than")


def test_dev_zero_is_refused_at_the_cap(tmp_path: Path, monkeypatch):
    monkeypatch.setattr(assembler, "MAX_SOURCE", 1 << 20)
    r = CliRunner().invoke(main, ["asm", "/dev/zero", "-o", str(tmp_path / "z.mem")])
    assert r.exit_code == 1 and "larger than the limit of 1,048,576 bytes" in r.stderr
    assert not (tmp_path / "z.mem").exists()


def test_dev_zero_in_a_real_process():
    p = subprocess.run([sys.executable, "-m", "rend3r", "asm", "/dev/zero"], capture_output=True, timeout=120)
    assert p.returncode == 1 and b"larger than the limit of 33,554,432 bytes" in p.stderr
    assert b"Traceback" not in p.stderr


def test_full_parser_work_is_capped(tmp_path: Path, monkeypatch):
    monkeypatch.setattr(assembler, "MAX_PARSED", 10_000)
    (tmp_path / "c.inc").write_text("A = 1 + 2 ; a constant\n" * 10)
    _fails_with(tmp_path, '.rept 100\n.include "c.inc"\n.endr\ner\ner\n', "sources too complex: more than 10,000")
    _fails_with(tmp_path, "cam xloc, 1 +\n" * 1000 + "er\ner\n", "sources too complex", "--max-errors", "0")
