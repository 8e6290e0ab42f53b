""".rept bodies' compiled instructions (rend3r/asm/compiled.py) agree with the general
path (``fast=False``) word for word and diagnostic for diagnostic, and are really taken."""

from __future__ import annotations

import time
from pathlib import Path

from hypothesis import given, settings, strategies as st

from rend3r.asm import assembler
from rend3r.asm.assembler import assemble_file, assemble_source
from rend3r.asm.compiled import compile_instruction
from rend3r.asm.parser import parse_line

PROGRAMS = Path(__file__).resolve().parents[2] / "programs"

_ATOMS = ["i", "j", "K", "R", "P", "U", "inf", "0", "-0", "1", "3", "0.5", "1e-9", "65520", "1e5",
          "0x8000", "0b1", "0h3c00", "1 / 3", "4096"]
_EXPR = st.recursive(
    st.sampled_from(_ATOMS),
    lambda inner: st.one_of(
        st.builds(lambda a, op, b: f"({a} {op} {b})", inner, st.sampled_from("+-*/"), inner),
        st.builds(lambda a: f"-{a}", inner),
    ),
    max_leaves=6,
)
_LINE = st.one_of(
    st.builds(lambda p, v: f"cam {p}, {v}", st.sampled_from(["xloc", "zero", "hfov", "bogus"]), _EXPR),
    st.builds(lambda i, p, v: f"lt {i}, {p}, {v}", _EXPR, st.sampled_from(["src", "col", "int", "zloc"]), _EXPR),
    st.builds(lambda m, i, p, q, v, w: f"{m} {i}, {p}, {q}, {v}, {w}", st.sampled_from(["sp", "tr", "SP"]), _EXPR,
              st.sampled_from(["xloc", "col", "mat", "zero", "a3"]), st.sampled_from(["yloc", "xloc", "col", "zero"]),
              _EXPR, _EXPR),
)


def _outcome(text: str, **kw) -> tuple[list[int], str]:
    result = assemble_source(text, "t.asm", **kw)
    return result.program.words, result.format_diagnostics()


@settings(max_examples=300, deadline=None)
@given(st.lists(_LINE, min_size=1, max_size=3), st.sampled_from([None, "rend3r-main"]))
def test_compiled_body_agrees_with_general_path(lines, target):
    text = ("K = 0.25\nR = 0h3c00\nP = 1 / 0\nU = 0x10\n.rept 3, j\n.rept 3, i\n" + "\n".join(lines)
            + "\n.endr\n.endr\ner\ner\n")
    assert _outcome(text, target=target) == _outcome(text, target=target, fast=False)


def test_stress4096_is_compiled_and_assembles_as_the_general_path_does():
    line = "sp 64 * (8 * J + I) + 2 * K + k, zloc, rrot, -5 - 2 * K - k, 1"
    words = compile_instruction(parse_line(line), None)
    assert words is not None
    assert words({"J": 1, "I": 2, "K": 3, "k": 1}) == tuple(
        assemble_source(f"J = 1\nI = 2\nK = 3\nk = 1\n{line}", fast=False).program.words)
    fast = assemble_file(PROGRAMS / "stress4096.asm")
    text = (PROGRAMS / "stress4096.asm").read_text()
    assert fast.ok and fast.program.words == assemble_source(text, fast=False).program.words


def test_a_zero_of_unknown_sign_or_an_undefined_name_takes_the_general_path():
    words = compile_instruction(parse_line("cam xloc, -i * 2"), None)
    assert words({"i": 1}) is not None
    assert words({"i": 0}) is None  # -0: 0x8000, which the general path gives
    assert words({}) is None
    result = assemble_source(".rept 2, i\ncam xloc, -i * 2\n.endr\ner\ner\n")
    assert [w >> 16 for w in result.program.words[:2]] == [0x8000, 0xC000]


def test_the_statement_cap_holds_for_compiled_bodies(monkeypatch):
    monkeypatch.setattr(assembler, "MAX_STATEMENTS", 10_000)
    t0 = time.perf_counter()
    result = assemble_source(".rept 100, j\n.rept 100, i\nsp i, xloc, yloc, i, j\n.endr\n.endr\ner\ner\n")
    assert time.perf_counter() - t0 < 5
    assert not result.ok
    assert "program too large: more than 10,000 statements" in result.format_diagnostics()
