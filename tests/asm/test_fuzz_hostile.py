"""Hostile fuzzing of assembly sources (issue 13), with a fixed budget: mutated real
sources from ``asm/`` and ``programs/``, random bytes, deep nesting and long lines.

The only outcome allowed is an :class:`AssemblyResult` (words and diagnostics); any
exception is a bug. Time per case is not asserted here: ``fuzz/asm.py`` measures it on
the real CLI in child processes.
"""

from __future__ import annotations

from pathlib import Path

from click.testing import CliRunner
from hypothesis import HealthCheck, given, settings, strategies as st

from rend3r.asm.assembler import assemble_source
from rend3r.cli import main

ROOT = Path(__file__).resolve().parents[2]
SEEDS = sorted([*ROOT.glob("asm/*.asm"), *ROOT.glob("asm/include/*.inc"), *ROOT.glob("programs/*.asm")])
TEXTS = [p.read_bytes().decode("utf-8", "replace") for p in SEEDS]
HOME = ROOT / "asm" / "fuzz.asm"  # never written: the name only places .include lookups in asm/
INCLUDES = [ROOT / "asm" / "include"]

PIECES = ["-", "+", "*", "/", "(", ")", ",", "0", "1e4000", "1e-4000", "0x", "0h", "0b", "_", ".", "e", ";", "//",
          '"', "=", "A", "i", ".rept 3, i\n", ".rept 300\n", ".endr\n", '.include "consts.inc"\n',
          '.include "cycle_a.inc"\n', '.include "' + "n" * 300 + '"\n', ".isa_ext hybrid\n", "ts triangle\n",
          ".word ", "sp ", "lt 63, ", "cam xloc, ", "\t", " " * 64, "\x00", "\u00e9", "\ufeff", "\r", "\n"]

PER_CASE = settings(deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])


def check(text: str, max_errors: int = 20) -> None:
    """Assemble ``text`` as a file of ``asm/``: no exception, every error well formed."""
    result = assemble_source(text, str(HOME), INCLUDES, max_errors=max_errors)
    report = result.format_diagnostics()
    for d in result.errors:
        assert f"{d.file}:{d.line}:{d.col}: error: " in report or f"{d.file}: error: " in report
    if max_errors:
        assert len(result.errors) <= max_errors
        assert bool(result.stopped_at) == (len(result.errors) == max_errors)


@st.composite
def mutated(draw) -> str:
    """A real source with a few insertions, deletions, replacements, duplicated lines
    or a piece repeated many times."""
    text = draw(st.sampled_from(TEXTS))
    for _ in range(draw(st.integers(1, 6))):
        pos = draw(st.integers(0, len(text)))
        op = draw(st.sampled_from(["insert", "delete", "replace", "dup-line", "repeat"]))
        if op == "insert":
            text = text[:pos] + draw(st.sampled_from(PIECES)) + text[pos:]
        elif op == "delete":
            text = text[:pos] + text[pos + draw(st.integers(1, 40)):]
        elif op == "replace":
            text = text[:pos] + draw(st.sampled_from(PIECES)) + text[pos + 1:]
        elif op == "repeat":
            text = text[:pos] + draw(st.sampled_from(PIECES)) * draw(st.integers(2, 700)) + text[pos:]
        else:
            lines = text.split("\n")
            i = draw(st.integers(0, len(lines) - 1))
            lines[i:i] = [lines[i]] * draw(st.integers(1, 50))
            text = "\n".join(lines)
    return text


@st.composite
def nested(draw) -> str:
    """Nesting at, around and far past each depth limit."""
    n = draw(st.sampled_from([1, 63, 64, 65, 199, 200, 201, 1000, 5000]))
    kind = draw(st.sampled_from(["neg", "sum", "product", "parens", "pos", "rept", "mixed"]))
    if kind == "rept":
        return ".rept 1\n" * n + "nr\n" + ".endr\n" * n + "er\ner\n"
    operand = {"neg": "-" * n + "1", "sum": "+".join(["1"] * n), "product": "*".join(["1"] * n),
               "parens": "(" * n + "1" + ")" * n, "pos": "+" * n + "1",
               "mixed": "(-" * n + "1" + ")" * n}[kind]
    head = draw(st.sampled_from(["cam xloc, ", "A = ", ".word ", ".rept ", "lt 0, xloc, "]))
    return head + operand + "\n.endr\ner\ner\n"


@st.composite
def long_lines(draw) -> str:
    """Lines near and past the 4,096-character limit, made of one repeated piece."""
    piece = draw(st.sampled_from(["1,", " ", "(", "-", "a", "1", "+1", ";", "0h", '"', "\t", "1e9*"]))
    length = draw(st.sampled_from([4000, 4096, 4097, 20_000]))
    line = draw(st.sampled_from(["cam xloc, ", ".word ", "", "sp 0, xloc, yloc, "])) + piece * (length // len(piece))
    return line + draw(st.sampled_from(["", "(", " ; c", "1"])) + "\ner\ner\n"


@settings(PER_CASE, max_examples=100)
@given(mutated(), st.sampled_from([0, 1, 20]))
def test_mutated_real_sources(text, max_errors):
    check(text, max_errors)


@settings(PER_CASE, max_examples=60)
@given(nested())
def test_deep_nesting(text):
    check(text)


@settings(PER_CASE, max_examples=40)
@given(long_lines())
def test_long_lines(text):
    check(text)


@settings(PER_CASE, max_examples=60)
@given(st.binary(max_size=2000))
def test_random_bytes_via_cli(tmp_path_factory, data):
    d = tmp_path_factory.mktemp("bytes")
    src = d / "r.asm"
    src.write_bytes(data)
    r = CliRunner().invoke(main, ["asm", str(src), "-o", str(d / "r.mem")])
    assert r.exception is None or isinstance(r.exception, SystemExit), repr(r.exception)
    assert r.exit_code in (0, 1) and "Traceback" not in r.output
    assert (d / "r.mem").exists() == (r.exit_code == 0)
    if r.exit_code == 1:
        assert "error:" in r.stderr


@settings(PER_CASE, max_examples=25)
@given(mutated())
def test_mutated_sources_via_cli(tmp_path_factory, text):
    d = tmp_path_factory.mktemp("mut")
    src = d / "m.asm"
    src.write_text(text, encoding="utf-8", errors="surrogatepass")
    r = CliRunner().invoke(main, ["asm", str(src), "-I", str(INCLUDES[0]), "-o", str(d / "m.mem")])
    assert r.exception is None or isinstance(r.exception, SystemExit), repr(r.exception)
    assert r.exit_code in (0, 1) and "Traceback" not in r.output
    assert (d / "m.mem").exists() == (r.exit_code == 0)
