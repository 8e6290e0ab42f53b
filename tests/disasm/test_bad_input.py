"""Malformed, empty, unreadable and random memory images: a positioned Rend3rError,
never another exception."""

from __future__ import annotations

import os

import pytest
from hypothesis import given, settings, strategies as st

from rend3r.asm.formats import FORMATS, read_file, read_words, render
from rend3r.errors import Rend3rError

from .strategies import programs

RADIX16 = b"memory_initialization_radix=16;\n"

MALFORMED = [
    # mem
    (b"00000200\n0000000g\n", "mem", r"^x:2:8: bad hex digit 'g'$"),
    (b"0000000x\n", "mem", r"^x:1:8: bad hex digit 'x'$"),
    (b"00000200 #\n", "mem", r"^x:1:10: unexpected character '#'"),
    (b"00000200\n123456789\n", "mem", r"^x:2:1: word 123456789 is over 32 bits$"),
    (b"1\n/* open\n2\n", "mem", r"^x:2:1: unterminated /\* comment$"),
    (b"@ 1\n", "mem", r"^x:1:1: '@' must be followed by a hex address$"),
    (b"1\n2\n@1 3\n", "mem", r"^x:3:1: address @1 goes back over words already read \(next address is @2\)$"),
    (b"@ffffffff 1\n", "mem", r"^x:1:1: address @ffffffff is beyond the 1,048,576-word limit \(@100000\)$"),
    (b"", "mem", r"^x:1:1: empty file: no words$"),
    (b"  \n// only a comment\n", "mem", r"^x:1:1: no words in file$"),
    (b"\x00\x00\x02\x00", "mem", r"^x: not a text file \(control character 0x00 at character 0\)"),
    (b"caf\xe9\n", "mem", r"^x: not a text file \(byte 0xe9 at offset 3 is not UTF-8\)"),
    # bin
    (b"", "bin", r"^x: empty file: no words$"),
    (b"\x00\x00\x02\x00\x00", "bin", r"^x: 5 bytes is not a whole number of 32-bit words \(1 byte\(s\) left over at offset 4\)$"),
    # coe
    (RADIX16 + b"memory_initialization_vector=1,,2;", "coe", r"^x:2:32: empty value before ','$"),
    (RADIX16 + b"memory_initialization_vector=1,2g;", "coe", r"^x:2:33: bad radix-16 digit 'g'$"),
    (RADIX16 + b"memory_initialization_vector=1,2,;", "coe", r"^x:2:33: trailing ',' before ';'$"),
    (RADIX16 + b"memory_initialization_vector=1,2", "coe", r"^x:2:1: statement not ended by ';'$"),
    (RADIX16 + b"memory_initialization_vector=;", "coe", r"^x:2:30: empty memory_initialization_vector$"),
    (RADIX16 + b"memory_initialization_vector=100000000;", "coe", r"^x:2:30: value 100000000 is over 32 bits$"),
    (b"memory_initialization_radix=8;\n", "coe", r"^x:1:29: unsupported radix '8'"),
    (b"memory_initialization_vector=1;\n", "coe", r"^x:1:1: memory_initialization_vector before memory_initialization_radix$"),
    (RADIX16 + b"radix=16;\n", "coe", r"^x:2:1: unknown keyword 'radix'"),
    (RADIX16 + RADIX16, "coe", r"^x:2:1: memory_initialization_radix given twice$"),
    (RADIX16, "coe", r"^x:2:1: no memory_initialization_vector$"),
    (b"memory_initialization_radix=2;\nmemory_initialization_vector=0102;", "coe", r"^x:2:33: bad radix-2 digit '2'$"),
    (b"; comment\njunk;\n", "coe", r"^x:2:1: expected 'keyword=value;'$"),
    # ihex
    (b":0400000000000200FB\n:00000001FF\n", "ihex", r"^x:1:18: wrong record checksum FB \(computed FA\)$"),
    (b"0400000000000200FA\n", "ihex", r"^x:1:1: an Intel HEX record starts with ':'$"),
    (b":04000000000002G0FA\n", "ihex", r"^x:1:16: bad hex digit 'G'$"),
    (b":0400000000000200F\n", "ihex", r"^x:1:1: record has an odd number of hex digits$"),
    (b":000001\n", "ihex", r"^x:1:1: record too short"),
    (b":0500000000000200FA\n", "ihex", r"^x:1:2: byte count field says 5 but the record holds 4 data bytes$"),
    (b":0400000000000200FA\n", "ihex", r"^x:2:1: no end-of-file record"),
    (b":00000001FF\n:0400000000000200FA\n", "ihex", r"^x:2:1: record after the end-of-file record$"),
    (b":00000001FF\n", "ihex", r"^x:1:1: no data records: empty image$"),
    (b":0400000600000200F4\n:00000001FF\n", "ihex", r"^x:1:8: unknown record type 06$"),
    (b":03000000000002FB\n:00000001FF\n", "ihex", r"^x:1:1: data from byte address 0x0 to 0x3 covers only part of the 32-bit word at 0x0$"),
    (b":0400000000000200FA\n:0400020000000200F8\n:00000001FF\n", "ihex", r"^x:2:1: data at byte address 0x2 overlaps an earlier record$"),
    (b":03000004000100F8\n:00000001FF\n", "ihex", r"^x:1:2: record type 04 must carry 2 bytes, not 3$"),
    (b":02000004FFFFFC\n:0400000000000200FA\n:00000001FF\n", "ihex", r"^x:2:1: data at byte address 0xffff0000 is beyond the 1,048,576-word limit \(byte address 0x400000\)$"),
    # lst
    (b"   1 | 0001 | 00000200 | nr\n", "lst", r"^x:1:7: address 1 out of sequence \(expected 0\)$"),
    (b"   1 | 0000 | 0000020x | nr\n", "lst", r"^x:1:22: bad hex digit 'x' in word$"),
    (b"   1 | 0000 | 100000000 | nr\n", "lst", r"^x:1:15: word 100000000 is over 32 bits$"),
    (b"   1 | 00g0 | 00000200 | nr\n", "lst", r"^x:1:10: bad hex digit 'g' in address$"),
    (b"   1 |      | 00000200 | nr\n", "lst", r"^x:1:7: missing address$"),
    (b"; header only\n", "lst", r"^x:1:1: no words in listing$"),
    (b"00000200\n", "lst", r"^x:1:1: expected 'line \| address \| word\(s\) \| source'$"),
]


@pytest.mark.parametrize("data,fmt,message", MALFORMED)
def test_malformed_input_is_a_positioned_error(data, fmt, message):
    with pytest.raises(Rend3rError, match=message):
        read_words(data, fmt, name="x")


def test_empty_input_without_format():
    with pytest.raises(Rend3rError, match=r"^x: empty file: no words$"):
        read_words(b"", name="x")


def test_unknown_format_and_byte_order():
    with pytest.raises(Rend3rError, match="unknown format 'hex'; choose from mem, mem-annotated"):
        read_words(b"0", "hex")
    with pytest.raises(Rend3rError, match="unknown byte order"):
        read_words(b"0000", "bin", byteorder="pdp")


def test_missing_and_unreadable_files(tmp_path):
    with pytest.raises(Rend3rError, match=r"nope\.mem: cannot read: No such file or directory"):
        read_file(tmp_path / "nope.mem")
    with pytest.raises(Rend3rError, match="cannot read: Is a directory"):
        read_file(tmp_path)
    empty = tmp_path / "empty.hex"
    empty.write_bytes(b"")
    with pytest.raises(Rend3rError, match=r"empty\.hex: empty file"):
        read_file(empty)


@pytest.mark.skipif(os.geteuid() == 0, reason="root reads any file")
def test_permission_denied(tmp_path):
    path = tmp_path / "locked.mem"
    path.write_text("00000000\n")
    path.chmod(0)
    with pytest.raises(Rend3rError, match="cannot read: Permission denied"):
        read_file(path)


def _read_or_error(data: bytes, fmt: str | None) -> None:
    try:
        words = read_words(data, fmt, name="fuzz")
    except Rend3rError as exc:
        assert str(exc).startswith("fuzz")
    else:
        assert words and all(0 <= w < 2**32 for w in words)


@settings(max_examples=200)
@given(st.binary(max_size=64), st.sampled_from([None, *FORMATS]))
def test_binary_garbage(data, fmt):
    _read_or_error(data, fmt)


@settings(max_examples=200)
@given(st.text(alphabet=":;@/*|=,_ \n0123456789abcdefgxzABCDEF_memory_initialization_radixvector", max_size=80),
       st.sampled_from([None, *FORMATS]))
def test_text_garbage(text, fmt):
    _read_or_error(text.encode(), fmt)


@settings(max_examples=150)
@given(programs(max_entries=4), st.sampled_from(list(FORMATS)), st.data())
def test_mutated_images(program, fmt, data):
    image = bytearray(render(fmt, program))
    for _ in range(data.draw(st.integers(1, 3))):
        op = data.draw(st.sampled_from(["flip", "delete", "insert"]))
        at = data.draw(st.integers(0, max(len(image) - 1, 0)))
        if op == "flip" and image:
            image[at] ^= 1 << data.draw(st.integers(0, 7))
        elif op == "delete" and image:
            del image[at]
        else:
            image.insert(at, data.draw(st.integers(0, 255)))
    _read_or_error(bytes(image), data.draw(st.sampled_from([None, fmt])))
