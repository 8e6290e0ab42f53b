"""Fuzzing: random and mutated sources always give clean diagnostics, never a traceback;
and the regex fast path agrees with the full Lark grammar line for line."""

from __future__ import annotations

from fractions import Fraction

from click.testing import CliRunner
from hypothesis import example, given, settings, strategies as st

from rend3r.asm.assembler import assemble_source
from rend3r.asm.fastpath import _round
from rend3r.cli import main
from rend3r.isa.float16 import round_literal
from rend3r.isa.tables import PROPERTIES, Table

SEED = """\
// seed program
K = 0.5
RED = 0b11111_000000_00000
nr
cam xloc, 1.5
cam irot, -K * 2
lt 0, col, RED
lt 63, src, 1
.rept 3, i
  sp i, xloc, a2, i * K, -0
.endr
tr 7, x1, z3, 0h3c00, 1e-3
.word 0xdeadbeef
sp 524287, type, mat, 1, 3
er
er
"""

_PIECES = list("0123456789abcxhe_.,-+*/()=;\"@ \t\n") + ["0h", "0x", "0b", ".rept", ".endr", ".include", "er", "sp", "xloc", "//",
                                                  ".isa_ext hybrid\n", "ts shape\n", "ts triangle", "ts "]


@st.composite
def mutated(draw) -> str:
    text = SEED
    for _ in range(draw(st.integers(1, 4))):
        pos = draw(st.integers(0, len(text)))
        op = draw(st.sampled_from(["insert", "delete", "replace", "dup-line"]))
        if op == "insert":
            text = text[:pos] + draw(st.sampled_from(_PIECES)) + text[pos:]
        elif op == "delete":
            text = text[:pos] + text[pos + draw(st.integers(1, 5)) :]
        elif op == "replace":
            text = text[:pos] + draw(st.sampled_from(_PIECES)) + text[pos + 1 :]
        else:
            lines = text.split("\n")
            i = draw(st.integers(0, len(lines) - 1))
            lines.insert(draw(st.integers(0, len(lines))), lines[i])
            text = "\n".join(lines)
    return text


def _check(text: str) -> None:
    result = assemble_source(text, "fuzz.asm")
    report = result.format_diagnostics()
    for d in result.errors:
        assert report.count(f"{d.file}:{d.line}:{d.col}: error: ") >= 1


@settings(max_examples=200)
@given(mutated())
def test_mutated_programs_never_crash(text):
    _check(text)


@settings(max_examples=200)
@given(st.text(max_size=200))
def test_random_text_never_crashes(text):
    _check(text)


@settings(max_examples=40)
@given(mutated())
def test_cli_on_mutated_programs(tmp_path_factory, text):
    d = tmp_path_factory.mktemp("fuzz")
    src = d / "m.asm"
    src.write_text(text, encoding="utf-8")
    out = d / "m.mem"
    r = CliRunner().invoke(main, ["asm", str(src), "-o", str(out)])
    assert r.exception is None or isinstance(r.exception, SystemExit)
    assert "Traceback" not in r.output
    ok = assemble_source(text, str(src)).ok
    assert r.exit_code == (0 if ok else 1)
    assert out.exists() == ok


@settings(max_examples=100)
@given(st.binary(max_size=300))
def test_binary_garbage_via_cli(tmp_path_factory, data):
    src = tmp_path_factory.mktemp("bin") / "g.asm"
    src.write_bytes(data)
    r = CliRunner().invoke(main, ["asm", str(src)])
    assert r.exception is None or isinstance(r.exception, SystemExit)
    assert r.exit_code in (0, 1)


# -- fast path against the full grammar ------------------------------------------------

_NAMES = {m: sorted({n for p in PROPERTIES[t] for n in p.names} | {"bogus", "a10", "a14"}) for m, t in
          (("cam", Table.CAMERA), ("lt", Table.LIGHT), ("sp", Table.SHAPE), ("tr", Table.TRIANGLE))}

values = st.one_of(
    st.integers(-70000, 70000).map(str),
    st.floats(-70000, 70000, allow_nan=False).map(repr),
    st.floats(-1e-3, 1e-3, allow_nan=False).map(lambda x: f"{x:.6e}"),
    st.decimals(-70000, 70000, places=6, allow_nan=False, allow_infinity=False).map(str),
    st.integers(0, 0x1FFFF).map(hex),
    st.integers(0, 0x1FFFF).map(bin),
    st.integers(0, 0xFFFF).map(lambda v: f"0h{v:x}"),
    st.sampled_from(["-0", "0", "65504", "65519.99", "65520", "2049", "2051", "1.00048828125", "5.96e-8",
                     "2.98023223876953125e-8", "1e-7", ".5", "1.", "1E+3", "0X1F", "0B101", "0H7C00", "0x3c00"]),
    # expressions take the operand-by-operand parser (parse_instruction)
    st.sampled_from(["1 + 2", "-(3) * 0.5", "K * 2", "(1", "1)", "0x1e+1", "1__0 * 2", "6 / 3", "1 / 0", "-0 * 1",
                     "0h3c00 + 1", "(1 + 2) * (3 - 4) / 5", "a b", "1 // 2", "1 / 2", "@"]),
)


@st.composite
def simple_lines(draw) -> str:
    mn = draw(st.sampled_from(["cam", "lt", "sp", "tr", "nr", "er"]))
    case = draw(st.sampled_from([str.lower, str.upper, str.title]))
    sep = draw(st.sampled_from([", ", ",", " ,\t"]))
    if mn in ("nr", "er"):
        ops = []
    else:
        names = [draw(st.sampled_from(_NAMES[mn])) for _ in range(2)]
        names = [case(n) if n not in ("a10", "a14") else n for n in names]
        if mn == "cam":
            ops = [names[0], draw(values)]
        elif mn == "lt":
            ops = [str(draw(st.integers(0, 70))), names[0], draw(values)]
        else:
            idx = draw(st.sampled_from([0, 1, 7, 8, 524287, 524288, 3000000]))
            ops = [str(idx), names[0], names[1], draw(values), draw(values)]
    comment = draw(st.sampled_from(["", " ; c", "// c", "\t", " ; a, b", ' "s"']))
    lead = draw(st.sampled_from(["", "  ", "\t"]))
    return lead + case(mn) + (" " + sep.join(ops) if ops else "") + comment


@settings(max_examples=400)
@given(simple_lines(), st.sampled_from([None, "rend3r-raytracing", "rend3r-main"]))
@example("sp 1, xloc, xloc, 1, 2", None)
@example("cam xloc, 1.000488281250000000000001", None)
def test_fast_path_agrees_with_grammar(line, target):
    fast = assemble_source(line, "f.asm", target=target)
    slow = assemble_source(line, "f.asm", target=target, fast=False)
    assert fast.program.entries == slow.program.entries
    assert fast.diagnostics == slow.diagnostics
    assert fast.mnemonics_used == slow.mnemonics_used


@settings(max_examples=1000)
@given(st.decimals(0, 70000, allow_nan=False, allow_infinity=False).map(str) | st.floats(0, 7e4).map(repr))
@example("1.000488281250000000000001")
@example("2049")
def test_fast_rounding_is_exact(text):
    got = _round(float(text), text)
    r = round_literal(Fraction(text))
    if got is not None:
        assert got == r.bits and not (r.overflow or r.underflow or r.relative_error > 0.01)
    else:
        assert r.overflow or r.underflow or r.relative_error > 0.0099


@settings(max_examples=200)
@given(st.integers(0, 1 << 33), st.sampled_from(["{:#x}", "{:#010x}", "{:d}", "{:#X}", "{:_x}"]),
       st.sampled_from(["", " ; c", "\t// c"]))
def test_fast_word_agrees_with_grammar(value, form, comment):
    text = f".word {form.format(value)}{comment}\ner\ner"
    fast, slow = assemble_source(text), assemble_source(text, fast=False)
    assert fast.program.entries == slow.program.entries and fast.diagnostics == slow.diagnostics
