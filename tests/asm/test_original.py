"""Lines the original device's assembler accepted assemble to its words: checked against
its own algorithm (Python ``float()``, else a 16-bit int read as signed, then numpy's
float16), on both assembler paths."""

from __future__ import annotations

import numpy as np
import pytest

from rend3r.asm.assembler import assemble_source


def original_bits(text: str) -> int:
    """The float16 bits the original assembler wrote for a float property's operand."""
    try:
        value = float(text)
    except ValueError:
        n = int(text, 0)
        value = float(n - 0x10000 if n >= 0x8000 else n)
    with np.errstate(over="ignore"):  # numpy rounds to infinity, as the original did
        return int(np.array(value, dtype=np.float16).view(np.uint16))


def words(source: str, fast: bool) -> list[int]:
    r = assemble_source(source + "\ner\ner\n", "o.asm", fast=fast)
    assert r.ok, r.format_diagnostics()
    return r.program.words[:-2]


INT_LITERALS = [f"0x{n:04x}" for n in range(0, 0x10000, 0x00FF)] + [
    "0x7fff", "0x8000", "0x8001", "0xbc00", "0xFFFF", "0XFF_FF", "0b1000000000000001", "0b0111_1111_1111_1111",
    "0b1111_1111_1111_1111", "0b1",
]
FLOAT_LITERALS = [
    "1e5", "-1e5", "65520", "-65520", "65519.99", "65504", "1e300", "inf", "-inf", "+inf", "INF", "Infinity",
    "-infinity", "nan", "-nan", "NaN", "+3", ".5", "5.", "1_000.5", "-0", "0.1", "2.5e-8",
]


@pytest.mark.parametrize("fast", [True, False])
def test_float_operands_give_the_original_words(fast: bool):
    texts = INT_LITERALS + FLOAT_LITERALS
    got = words("\n".join(f"cam xloc, {t}" for t in texts), fast)
    assert [w >> 16 for w in got] == [original_bits(t) for t in texts]


@pytest.mark.parametrize("fast", [True, False])
def test_every_signed_int_literal_in_a_shape_pair(fast: bool):
    texts = [f"0x{n:04x}" for n in range(0x7F00, 0x10000, 0x101)]
    got = words("\n".join(f"sp 1, xscl, yscl, {t}, {t}" for t in texts), fast)
    assert [(w >> 16, w & 0xFFFF) for w in got[1::2]] == [(original_bits(t), original_bits(t)) for t in texts]


def test_what_the_original_did_silently_warns():
    r = assemble_source("cam xloc, 0xbc00\ncam xloc, 1e5\ncam xloc, -65520\ncam xloc, inf\ner\ner\n")
    assert r.ok
    assert [(d.line, d.message.split(" (")[0]) for d in r.warnings] == [
        (1, "0xbc00 is read as the signed 16-bit integer -17408 for float16 property 'xloc'"),
        (2, "1e5 overflows float16 to infinity"),
        (3, "-65520 overflows float16 to -infinity"),
    ]
    assert not assemble_source("cam xloc, 1e5\ner\ner\n", werror=True).ok


def test_none_names_triangle_slot_10_only():
    r = assemble_source("tr 3, none, x1, 1, 2\ntr 3, NONE, a1, 1, 2\ner\ner\n")
    assert r.ok and not r.diagnostics
    assert r.program.words[:4] == [0x0000505D, 0x3C004000, 0x0000505D, 0x3C004000]
    for line in ("sp 3, none, xloc, 1, 2", "cam none, 1", "lt 0, none, 1", "tr 3, a10, x1, 1, 2"):
        assert not assemble_source(line + "\ner\ner\n").ok, line
    a10 = assemble_source("tr 3, a10, x1, 1, 2\ner\ner\n").errors[0].message
    assert a10 == "the triangle table has no property 10 (its unused slot 10 is named 'none')"


def test_inf_and_nan_are_values_only_where_no_constant_is():
    r = assemble_source("inf = 2\ncam xloc, inf\ncam xloc, -Inf\ner\ner\n")
    assert r.ok and [w >> 16 for w in r.program.words[:2]] == [0x4000, 0xFC00]
    bad = assemble_source("cam xloc, inf * 1\ncam xloc, nan - 0\nlt 0, col, nan\n.rept inf\n.endr\ner\ner\n")
    assert [d.line for d in bad.errors] == [1, 2, 3, 4]
