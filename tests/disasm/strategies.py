"""Hypothesis strategies shared by the disassembler and format tests."""

from __future__ import annotations

from hypothesis import strategies as st

from rend3r.asm.program import Emitted, Program, SourceLoc
from rend3r.isa import CameraSet, FrameOp, Func, LightSet, ShapeSet, Table, encode
from rend3r.isa.tables import LIGHT_INDEX_LIMIT, PROPERTIES, SHAPE_INDEX_LIMIT

any_word = st.integers(0, 2**32 - 1)
field16 = st.one_of(st.integers(0, 0xFFFF), st.sampled_from([0, 0x3C00, 0x8000, 0x7C00, 0x7E00, 0xFC00, 0x0001]))


def _props(table: Table) -> st.SearchStrategy[int]:
    return st.sampled_from([p.index for p in PROPERTIES[table]])


def instructions(shape_table: Table = Table.SHAPE) -> st.SearchStrategy[tuple[int, ...]]:
    """The word(s) of one well-formed instruction (properties the tables define)."""
    return st.one_of(
        st.sampled_from(list(Func)).map(lambda f: encode(FrameOp(f))),
        st.builds(CameraSet, _props(Table.CAMERA), field16).map(encode),
        st.builds(LightSet, st.integers(0, LIGHT_INDEX_LIMIT - 1), _props(Table.LIGHT), field16).map(encode),
        st.builds(
            ShapeSet,
            st.one_of(st.integers(0, SHAPE_INDEX_LIMIT - 1), st.sampled_from([0, 7, 8, SHAPE_INDEX_LIMIT - 1])),
            _props(shape_table),
            _props(shape_table),
            field16,
            field16,
        ).map(encode),
    )


def word_streams(shape_table: Table = Table.SHAPE, max_size: int = 30) -> st.SearchStrategy[list[int]]:
    """Mixed streams: random words and well-formed instructions, in any order."""
    chunk = st.one_of(any_word.map(lambda w: (w,)), instructions(shape_table))
    return st.lists(chunk, max_size=max_size).map(lambda chunks: [w for c in chunks for w in c])


@st.composite
def programs(draw, min_words: int = 1, max_entries: int = 12) -> Program:
    """Programs as the assembler builds them: entries of 1-4 words, with or without
    source positions, from the main file or an included one."""
    entries = []
    address = 0
    count = draw(st.integers(1 if min_words else 0, max_entries))
    for _ in range(count):
        words = tuple(draw(st.lists(any_word, min_size=1, max_size=4)))
        loc = draw(st.one_of(st.none(), st.builds(SourceLoc, st.sampled_from(["main.asm", "inc/part.asm"]), st.integers(1, 9999))))
        text = draw(st.text(st.characters(min_codepoint=32, max_codepoint=0x2FF, exclude_characters="\x7f"), max_size=30))
        entries.append(Emitted(address, words, loc, text))
        address += len(words)
    return Program(entries)
