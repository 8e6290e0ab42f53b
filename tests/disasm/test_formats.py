"""Memory-image formats: exact output, write-then-read of every format, detection."""

from __future__ import annotations

import pytest
from hypothesis import assume, given, settings, strategies as st

from rend3r.asm.formats import FORMATS, detect_format, read_file, read_words, render
from rend3r.asm.formats.common import is_text
from rend3r.asm.program import Emitted, Program, SourceLoc
from rend3r.errors import Rend3rError

from .strategies import programs

#: The reader detection picks for each format's output.
DETECTED = {"mem": "mem", "mem-annotated": "mem", "bin": "bin", "coe": "coe", "ihex": "ihex", "lst": "lst"}

SAMPLE = Program(
    [
        Emitted(0, (0x00000200,), SourceLoc("scene.asm", 3), "nr"),
        Emitted(1, (0x0000182D, 0x3C000000), SourceLoc("scene.asm", 4), "  sp 0, zloc, zero, 1, 0  ; ball"),
        Emitted(3, (0x00000005, 0x00000007, 0x00000009), SourceLoc("lib/x.asm", 12), ".word 5, 7, 9"),
        Emitted(6, (0x00000000, 0x00000000), None, "er"),
    ]
)


def words_of(*words: int) -> Program:
    return Program([Emitted(i, (w,)) for i, w in enumerate(words)])


def test_format_table():
    assert list(FORMATS) == ["mem", "mem-annotated", "bin", "coe", "ihex", "lst"]
    assert {f.extension for f in FORMATS.values()} == {".mem", ".annotated.mem", ".bin", ".coe", ".hex", ".lst"}
    assert [f.name for f in FORMATS.values() if f.binary] == ["bin"]


def test_mem_is_the_original_assemblers_output():
    assert render("mem", words_of(0x200, 0xABCDEF01, 0)) == b"00000200\nabcdef01\n00000000\n"


def test_mem_annotated_comments():
    lines = render("mem-annotated", SAMPLE).decode().splitlines()
    assert lines == [
        "00000200 // @0000 scene.asm:3: nr",
        "0000182d // @0001 scene.asm:4: sp 0, zloc, zero, 1, 0  ; ball",
        "3c000000 // @0002 (SD)",
        "00000005 // @0003 lib/x.asm:12: .word 5, 7, 9",
        "00000007 // @0004 (SD)",  # the device reads the word after an SE as its SD
        "00000009 // @0005 lib/x.asm:12: (continued)",
        "00000000 // @0006 er",
        "00000000 // @0007 (continued)",
    ]


def test_bin_byte_orders():
    p = words_of(0x01020304, 0xA0B0C0D0)
    assert render("bin", p) == bytes.fromhex("01020304a0b0c0d0")
    assert render("bin", p, "little") == bytes.fromhex("04030201d0c0b0a0")
    assert read_words(bytes.fromhex("04030201"), "bin", byteorder="little") == [0x01020304]


def test_coe_layout():
    assert render("coe", words_of(0x200, 0)).decode() == (
        "; rend3r: 2 words of 32 bits\n"
        "memory_initialization_radix=16;\n"
        "memory_initialization_vector=\n"
        "00000200,\n"
        "00000000;\n"
    )


def test_ihex_records_and_checksums():
    assert render("ihex", words_of(0x00000200)).decode() == ":0400000000000200FA\n:00000001FF\n"
    text = render("ihex", words_of(*range(5)), ihex_record_bytes=4).decode().splitlines()
    assert len(text) == 6 and text[1] == ":0400040000000001F7"
    assert render("ihex", words_of(0x01020304), "little").decode().startswith(":0400000004030201F2")


def test_ihex_extended_linear_address_above_64k():
    p = words_of(*range(0x4000 + 8))  # 64 KiB + 32 bytes
    text = render("ihex", p).decode().splitlines()
    assert ":020000040001F9" in text
    assert text.index(":020000040001F9") == 0x10000 // 16
    assert read_words(render("ihex", p)) == p.words


def test_lst_layout():
    assert render("lst", SAMPLE).decode().splitlines() == [
        "; rend3r listing of scene.asm: 8 words",
        ";       line | addr | word(s)           | source",
        "           3 | 0000 | 00000200          | nr",
        "           4 | 0001 | 0000182d 3c000000 | sp 0, zloc, zero, 1, 0  ; ball",
        "lib/x.asm:12 | 0003 | 00000005 00000007 | .word 5, 7, 9",
        "             | 0005 | 00000009          |",
        "             | 0006 | 00000000 00000000 | er",
    ]


@pytest.mark.parametrize("program", [SAMPLE, Program([Emitted(0, (0x200,), SourceLoc("a.asm", 1), "nr")]), words_of(1, 2)])
def test_lst_columns_line_up(program):
    rows = render("lst", program).decode().splitlines()
    bars = {tuple(i for i, c in enumerate(row) if c == "|")[:3] for row in rows[1:]}
    assert len(bars) == 1


def test_lst_labels():
    rows = render("lst", SAMPLE).decode().splitlines()
    assert rows[0] == "; rend3r listing of scene.asm: 8 words"
    assert rows[3].split("|")[0].strip() == "4" and rows[4].split("|")[0].strip() == "lib/x.asm:12"
    assert rows[5].split("|")[1:3] == [" 0005 ", " 00000009          "]


def test_render_copes_with_entries_without_source():
    p = Program([Emitted(0, (0x200,)), Emitted(1, (0, 0), None, "er")])
    assert render("lst", p).decode().splitlines()[0] == "; rend3r listing: 3 words"
    assert render("mem-annotated", p).decode().splitlines()[0] == "00000200 // @0000"


def test_render_rejects_unknown_format_and_byteorder():
    with pytest.raises(Rend3rError, match="unknown format 'elf'"):
        render("elf", SAMPLE)
    with pytest.raises(Rend3rError, match="byte order"):
        render("bin", SAMPLE, "middle")
    with pytest.raises(Rend3rError, match="record size"):
        render("ihex", SAMPLE, ihex_record_bytes=8)


def test_empty_coe_is_refused():
    with pytest.raises(Rend3rError, match="cannot be empty"):
        render("coe", Program())


@pytest.mark.parametrize("fmt", FORMATS)
def test_sample_round_trips_and_is_detected(fmt):
    data = render(fmt, SAMPLE)
    assert read_words(data, fmt) == SAMPLE.words
    assert detect_format(data) == DETECTED[fmt]
    assert read_words(data) == SAMPLE.words


@settings(max_examples=60)
@given(programs(), st.sampled_from(list(FORMATS)), st.sampled_from(["big", "little"]), st.sampled_from([4, 16]))
def test_every_format_reads_back(program, fmt, byteorder, record):
    data = render(fmt, program, byteorder, ihex_record_bytes=record)
    assert read_words(data, fmt, byteorder=byteorder) == program.words
    if fmt != "bin" or not is_text(data):  # a bin image may happen to be valid text
        assert read_words(data, byteorder=byteorder) == program.words


@settings(max_examples=30)
@given(programs())
def test_bin_with_any_non_text_byte_is_detected_as_bin(program):
    data = render("bin", program)
    assume(not is_text(data))
    assert detect_format(data) == "bin"


@pytest.mark.parametrize("fmt", FORMATS)
def test_read_file_detects_by_default_extension(tmp_path, fmt):
    path = tmp_path / f"image{FORMATS[fmt].extension}"
    path.write_bytes(render(fmt, SAMPLE))
    assert read_file(path) == SAMPLE.words


def test_extension_beats_content(tmp_path):
    # Eight ASCII bytes are valid mem text by content, but .bin says raw words.
    path = tmp_path / "ascii.bin"
    path.write_bytes(b"00000200")
    assert read_file(path) == [0x30303030, 0x30323030]
    # .mem insists on text: binary content is a clear error, not a guess.
    path = tmp_path / "raw.mem"
    path.write_bytes(b"\x00\x00\x02\x00")
    with pytest.raises(Rend3rError, match=r"raw\.mem: not a text file .*--format bin"):
        read_file(path)


@pytest.mark.parametrize(
    "content,words",
    [(b"00000200\n00000000\n", [0x200, 0]), (b":0400000000000200FA\n:00000001FF\n", [0x200])],
)
def test_hex_extension_is_decided_by_content(tmp_path, content, words):
    path = tmp_path / "main.hex"
    path.write_bytes(content)
    assert read_file(path) == words


def test_explicit_format_overrides_detection(tmp_path):
    path = tmp_path / "image.mem"
    path.write_bytes(b"\x00\x00\x02\x00")
    assert read_file(path, "bin") == [0x200]
    assert read_file(path, "bin", "little") == [0x20000]


@given(st.lists(st.integers(0, 2**32 - 1), min_size=1, max_size=50), st.sampled_from(["\n", "\r\n"]))
def test_mem_plain_and_commented_files_read_alike(words, newline):
    plain = "".join(f"{w:x}{newline}" for w in words)
    commented = "// header\n" + plain.replace(newline, f" /* c */{newline}", 1)
    assert read_words(plain.encode(), "mem") == words
    assert read_words(plain.rstrip().encode(), "mem") == words
    assert read_words(commented.encode(), "mem") == words


def test_mem_reader_features():
    text = b"// c\nDEAD_BEEF /* two\nlines */ 1\n@4 2 // jump\n@6\n3"
    assert read_words(text, "mem") == [0xDEADBEEF, 1, 0, 0, 2, 0, 3]


def test_coe_other_radixes_and_comments():
    text = b"; c\n  ; indented comment\nMEMORY_INITIALIZATION_RADIX = 10 ;\nmemory_initialization_vector = 512 0,\n 4294967295;;\n"
    assert read_words(text, "coe") == [512, 0, 2**32 - 1]
    assert read_words(b"memory_initialization_radix=2;\nmemory_initialization_vector=1000000000,1;", "coe") == [512, 1]


def test_ihex_segment_and_start_records_and_gaps():
    # segment base 0x1000 (byte 0x10000 = word 0x4000) and a start-address record.
    text = b":020000021000EC\n:0400000000000200FA\n:0400000500000000F7\n:00000001ff\n"
    words = read_words(text, "ihex")
    assert len(words) == 0x4001 and words[0x4000] == 0x200 and not any(words[:0x4000])


@pytest.mark.parametrize("fmt", ["mem", "coe", "ihex", "lst"])
def test_utf8_bom_and_crlf_are_accepted(fmt):
    text = render(fmt, SAMPLE).decode().replace("\n", "\r\n")
    data = "\ufeff".encode() + text.encode()
    assert detect_format(data) == fmt
    assert read_words(data) == SAMPLE.words
