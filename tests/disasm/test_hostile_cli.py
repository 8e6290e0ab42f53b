"""Hostile memory images through the real CLI (``python -m rend3r`` in a child whose
address space is capped): each defect of issue 13 in the readers is a clear error with
its position and the limit it broke, in bounded time and memory, never a traceback."""

from __future__ import annotations

import resource
import subprocess
import sys

import pytest

from rend3r.asm.formats import read_words
from rend3r.asm.formats.common import MAX_WORDS
from rend3r.errors import Rend3rError

CHILD_MEMORY = 2 << 30  # the old readers needed 3.7-4.2 GB for these inputs


def rend3r(*args: str, stdin=subprocess.DEVNULL, cwd=None, memory: int = CHILD_MEMORY) -> subprocess.CompletedProcess[str]:
    def limit() -> None:
        resource.setrlimit(resource.RLIMIT_AS, (memory, memory))

    return subprocess.run([sys.executable, "-m", "rend3r", *args], stdin=stdin, cwd=cwd, capture_output=True,
                          text=True, timeout=60, preexec_fn=limit)


def assert_error(result: subprocess.CompletedProcess[str], message: str) -> None:
    assert "Traceback" not in result.stderr, result.stderr
    assert result.returncode == 1, result.stderr
    assert result.stderr.strip() == f"rend3r: error: {message}"
    assert result.stdout == ""


def test_radix_10_coe_with_a_5000_digit_value(tmp_path):
    (tmp_path / "d.coe").write_text("memory_initialization_radix=10;\nmemory_initialization_vector=\n1,\n"
                                    + "7" * 5000 + ";\n")
    assert_error(rend3r("disasm", "d.coe", cwd=tmp_path),
                 "d.coe:4:1: value 777777777777777777777777... (5,000 characters) is over 32 bits")


def test_mem_address_far_beyond_the_limit_is_refused_not_zero_filled(tmp_path):
    (tmp_path / "far.mem").write_text("00000200\n@ffffff\n00000000\n")
    assert_error(rend3r("disasm", "far.mem", "-o", "out.asm", cwd=tmp_path),
                 "far.mem:2:1: address @ffffff is beyond the 1,048,576-word limit (@100000)")
    assert not (tmp_path / "out.asm").exists()


def test_ihex_extended_address_beyond_the_limit(tmp_path):
    (tmp_path / "far.hex").write_text(":02000004FFFFFC\n:0400000000000200FA\n:00000001FF\n")
    assert_error(rend3r("disasm", "far.hex", cwd=tmp_path),
                 "far.hex:2:1: data at byte address 0xffff0000 is beyond the 1,048,576-word limit "
                 "(byte address 0x400000)")


def test_sparse_gigabyte_bin_is_refused_by_its_size_before_reading(tmp_path):
    with open(tmp_path / "huge.bin", "wb") as fh:
        fh.truncate(1 << 30)
    assert_error(rend3r("emulate", "huge.bin", "--frames", "1", "-o", "x.png", cwd=tmp_path),
                 "huge.bin: bin image is 1,073,741,824 bytes; the limit is 4,194,304 bytes")
    assert not (tmp_path / "x.png").exists()


def test_sparse_file_without_an_image_suffix_is_not_handed_to_the_assembler(tmp_path):
    with open(tmp_path / "huge.img", "wb") as fh:
        fh.truncate(1 << 30)
    assert_error(rend3r("emulate", "huge.img", "-o", "x.png", cwd=tmp_path),
                 "huge.img: memory image is 1,073,741,824 bytes; the limit is 67,108,864 bytes")


def test_endless_standard_input_stops_at_the_limit():
    with open("/dev/zero", "rb") as zero:
        result = rend3r("disasm", "-", stdin=zero)
    assert_error(result, "<stdin>: memory image is larger than the limit of 67,108,864 bytes")


def test_send_refuses_an_oversized_address_too(tmp_path):
    (tmp_path / "far.mem").write_text("@fffffff 1\n")
    assert_error(rend3r("send", "far.mem", "--mem", "out.mem", cwd=tmp_path),
                 "far.mem:1:1: address @fffffff is beyond the 1,048,576-word limit (@100000)")
    assert not (tmp_path / "out.mem").exists()


def _ihex(body: bytes) -> bytes:
    return f":{body.hex().upper()}{(-sum(body)) & 0xFF:02X}\n".encode()


LAST_ADDRESS = MAX_WORDS * 4 - 4
LAST_WORD = {
    "mem": f"@{MAX_WORDS - 1:x} 00000200\n".encode(),
    "ihex": _ihex(bytes([2, 0, 0, 4]) + (LAST_ADDRESS >> 16).to_bytes(2, "big"))
    + _ihex(bytes([4]) + (LAST_ADDRESS & 0xFFFF).to_bytes(2, "big") + bytes([0, 0, 0, 2, 0]))
    + b":00000001FF\n",
}


@pytest.mark.parametrize("fmt", LAST_WORD)
def test_the_last_word_below_the_limit_is_accepted(fmt):
    words = read_words(LAST_WORD[fmt], fmt, "x")
    assert len(words) == MAX_WORDS and words[-1] == 0x200 and not any(words[:-1])


def test_one_word_past_the_limit_is_refused():
    with pytest.raises(Rend3rError, match=r"^x:1:1: address @100001 is beyond the 1,048,576-word limit"):
        read_words(f"@{MAX_WORDS + 1:x} 1\n".encode(), "mem", "x")
    with pytest.raises(Rend3rError, match=r"^x:1:9: more than 1,048,576 words$"):
        read_words(f"@{MAX_WORDS:x} 1\n".encode(), "mem", "x")


def test_one_long_line_costs_no_memory_per_character(tmp_path):
    """Detection and the listing's row pattern once held regex state per character or word."""
    (tmp_path / "zero.hex").write_bytes(b"0" * (40 << 20))  # detected as mem: one word, 0
    (tmp_path / "row.lst").write_bytes(b"  | 0 | " + b"1 " * (MAX_WORDS + 1) + b"\n")
    done = rend3r("disasm", "zero.hex", cwd=tmp_path, memory=1 << 30)
    assert done.returncode == 0 and "Traceback" not in done.stderr, done.stderr
    assert done.stdout.splitlines()[1:] == ["er"]
    assert_error(rend3r("disasm", "row.lst", cwd=tmp_path, memory=1 << 30),
                 f"row.lst:1:{8 + 2 * MAX_WORDS + 1}: more than 1,048,576 words")
