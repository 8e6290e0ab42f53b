"""Mutated memory images, per format (fixed budget): bit flips, truncation, insertion of
hostile snippets (huge numbers, huge addresses, another radix, CRLF, NUL bytes, comment
openers, blank runs), deletion and duplication of valid images. The readers give words
or a ``Rend3rError`` naming the input, nothing else; what they accept is bounded by
``MAX_WORDS`` and its disassembly assembles back to the same words."""

from __future__ import annotations

import pytest
from hypothesis import HealthCheck, given, settings, strategies as st

from rend3r.asm import assembler
from rend3r.asm.disasm import disassemble
from rend3r.asm.formats import FORMATS, read_words, render
from rend3r.asm.formats.common import MAX_WORDS
from rend3r.errors import Rend3rError

from .strategies import programs

SNIPPETS = [
    b"\x00", b"\r\n", b"\r", b"\n", b"\t", b"\xff", b"\xef\xbb\xbf", b"\xe9",
    b"@ffffff", b"@fffff", b"@100000", b"@" + b"f" * 60, b"@3", b"@",
    b"9" * 5000, b"f" * 5000, b"1" * 40, b"100000000", b"-1", b"0x10", b"_", b"x", b"z",
    b"memory_initialization_radix=10;", b"memory_initialization_radix=2;", b"memory_initialization_radix=16;",
    b"memory_initialization_vector=", b";", b",", b",,", b"=",
    b":02000004FFFFFC\n", b":020000040010EA\n", b":020000021000EC\n", b":00000001FF\n", b":",
    b":10000000" + b"0" * 32 + b"F0\n", b":04FFFC0000000200FD\n",
    b"/*", b"*/", b"//", b"|", b" | ffff | ", b" | 0 | 1 2 3 ",
    b"\n" * 500, b" " * 500, b"\r\n" * 200,
]


@st.composite
def mutated(draw, fmt: str) -> bytes:
    """A valid image of a random program in ``fmt``, then one to four mutations."""
    program = draw(programs())
    if fmt == "ihex":
        data = render(fmt, program, draw(st.sampled_from(["big", "little"])),
                      ihex_record_bytes=draw(st.sampled_from([4, 16])))
    else:
        data = render(fmt, program)
    data = bytearray(data)
    for _ in range(draw(st.integers(1, 4))):
        at = draw(st.integers(0, len(data)))
        kind = draw(st.sampled_from(["flip", "truncate", "insert", "random", "delete", "duplicate", "crlf"]))
        if kind == "flip" and at < len(data):
            data[at] ^= 1 << draw(st.integers(0, 7))
        elif kind == "truncate":
            del data[at:]
        elif kind == "insert":
            data[at:at] = draw(st.sampled_from(SNIPPETS))
        elif kind == "random":
            data[at:at] = draw(st.binary(min_size=1, max_size=8))
        elif kind == "delete":
            del data[at:at + draw(st.integers(1, 16))]
        elif kind == "duplicate":
            data[at:at] = data[at:at + draw(st.integers(1, 64))]
        elif kind == "crlf":
            data = bytearray(data.replace(b"\n", b"\r\n"))
    return bytes(data)


def assemble(text: str) -> list[int]:
    result = assembler.assemble_source(text)
    assert result.ok, result.format_diagnostics()
    return result.program.words


def check(data: bytes, fmt: str | None) -> None:
    try:
        words = read_words(data, fmt, "x")
    except Rend3rError as exc:
        assert str(exc).startswith("x"), exc
        assert len(str(exc)) < 400, "a message must not echo the input"
        return
    assert 0 < len(words) <= MAX_WORDS
    assert all(type(w) is int and 0 <= w < 1 << 32 for w in words)
    sample = words[:2048]  # the round trip of a zero-filled megaword takes minutes to assemble
    assert assemble(disassemble(sample)) == sample


@pytest.mark.parametrize("fmt", list(FORMATS))
def test_mutated_images_give_words_or_a_clear_error(fmt):
    @settings(max_examples=70, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
    @given(data=mutated(fmt), detect=st.booleans())
    def run(data, detect):
        check(data, None if detect else fmt)

    run()
