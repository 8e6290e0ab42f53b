"""``rend3r disasm`` end to end: real files, the real CLI group, a real subprocess."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest
from click.testing import CliRunner

from rend3r.asm.formats import FORMATS, render
from rend3r.asm.program import Emitted, Program
from rend3r.cli import main

WORDS = [0x00000200, 0x0000182D, 0x3C000000, 0x00000004, 0x00000000, 0x00000000]
EXPECTED = [
    "nr",
    "sp 5, zloc, zero, 1.0, 0",
    ".word 0x00000004  ; reserved opcode 100 (shape init, never defined)",
    "er",
    "er",
]


def run(*args: str, stdin: bytes | None = None):
    return CliRunner().invoke(main, ["disasm", *args], input=stdin)


@pytest.fixture
def program():
    return Program([Emitted(i, (w,)) for i, w in enumerate(WORDS)])


@pytest.mark.parametrize("fmt", FORMATS)
def test_every_format_to_stdout(tmp_path, program, fmt):
    path = tmp_path / f"main{FORMATS[fmt].extension}"
    path.write_bytes(render(fmt, program))
    result = run(str(path))
    assert result.exit_code == 0, result.output
    assert result.output.splitlines()[1:] == EXPECTED


def test_output_file_mode_and_addresses(tmp_path, program):
    src = tmp_path / "main.mem"
    src.write_bytes(render("mem", program))
    out = tmp_path / "main.asm"
    result = run(str(src), "-o", str(out), "--mode", "raster", "--addresses")
    assert result.exit_code == 0 and result.output == ""
    lines = out.read_text().splitlines()
    assert lines[0].startswith("; rend3r disassembly: 6 words, raster mode")
    assert lines[2] == "tr 5, z1, zero, 1.0, 0                  ; @0001"
    assert sorted(os.listdir(tmp_path)) == ["main.asm", "main.mem"]


def test_format_and_byteorder_options(tmp_path, program):
    src = tmp_path / "image.dat"
    src.write_bytes(render("bin", program, "little"))
    result = run(str(src), "--format", "bin", "--byteorder", "little")
    assert result.exit_code == 0
    assert result.output.splitlines()[1:] == EXPECTED


def test_standard_input(program):
    result = run("-", stdin=render("ihex", program))
    assert result.exit_code == 0
    assert result.output.splitlines()[1:] == EXPECTED


@pytest.mark.parametrize(
    "content,name,message",
    [
        (None, "missing.mem", "rend3r: error: {dir}/missing.mem: cannot read: No such file or directory"),
        (b"0000000g\n", "bad.mem", "rend3r: error: {dir}/bad.mem:1:8: bad hex digit 'g'"),
        (b"\x01\x02\x03", "junk.bin", "rend3r: error: {dir}/junk.bin: 3 bytes is not a whole number of 32-bit words"),
        (b"", "empty.mem", "rend3r: error: {dir}/empty.mem: empty file: no words"),
    ],
)
def test_bad_input_is_one_clear_line(tmp_path, content, name, message):
    path = tmp_path / name
    if content is not None:
        path.write_bytes(content)
    out = tmp_path / "out.asm"
    result = run(str(path), "-o", str(out))
    assert result.exit_code == 1
    assert result.output.startswith(message.format(dir=tmp_path))
    assert "Traceback" not in result.output
    assert not out.exists()


def test_refuses_to_overwrite_its_input(tmp_path, program):
    src = tmp_path / "main.mem"
    src.write_bytes(render("mem", program))
    result = run(str(src), "-o", str(src))
    assert result.exit_code == 1 and "refusing to overwrite the input" in result.output
    assert src.read_bytes() == render("mem", program)


def test_help_has_an_example():
    result = run("--help")
    assert result.exit_code == 0
    assert "rend3r disasm main.mem" in result.output and "--mode [raytrace|raster]" in result.output


def test_real_process_exit_status_and_stderr(tmp_path):
    bad = tmp_path / "bad.coe"
    bad.write_text("memory_initialization_radix=16;\nmemory_initialization_vector=1,,2;\n")
    proc = subprocess.run([sys.executable, "-m", "rend3r", "disasm", str(bad)], capture_output=True, text=True)
    assert proc.returncode == 1
    assert proc.stdout == ""
    assert proc.stderr == f"rend3r: error: {bad}:2:32: empty value before ','\n"


@pytest.mark.parametrize("name, data, what", [
    ("x.png", b"\x89PNG\r\n\x1a\n" + bytes(20), "a PNG image"),
    ("x.bin", b"\xff\xd8\xff\xe0" + bytes(20), "a JPEG image"),
    ("x.gif", b"GIF87a" + bytes(22), "a GIF image"),
    ("x.mem", b"PK\x05\x06" + bytes(20), "a ZIP archive"),
    ("x.rdr", b"nr\ner\n", "assembly source, not a memory image"),
    ("x.asm", b"nr\ner\n", "assembly source, not a memory image"),
])
def test_what_is_not_a_memory_image_is_refused_by_name(tmp_path, name, data, what):
    (tmp_path / name).write_bytes(data)
    r = run(str(tmp_path / name))
    assert r.exit_code == 1 and r.output == f"rend3r: error: {tmp_path / name} is {what}" + (
        " (rend3r asm assembles it)\n" if "source" in what else ", not a REND3R program (source or memory image)\n")


def test_a_picture_on_standard_input_is_refused_and_a_given_format_reads_anything(tmp_path):
    png = b"\x89PNG\r\n\x1a\n" + bytes(8)
    r = run("-", stdin=png)
    assert r.exit_code == 1 and "<stdin> is a PNG image" in r.output
    r = run("-", "--format", "bin", stdin=png)
    assert r.exit_code == 0 and ".word 0x89504e47" in r.output, r.output


def test_output_folders_are_made(tmp_path):
    (tmp_path / "in.mem").write_text("00000200\n00000000\n00000000\n")
    r = run(str(tmp_path / "in.mem"), "-o", str(tmp_path / "a" / "b" / "out.asm"))
    assert r.exit_code == 0, r.output
    assert "\nnr\n" in (tmp_path / "a" / "b" / "out.asm").read_text()
