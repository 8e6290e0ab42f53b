"""``rend3r asm`` through click's runner and as a real process."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
from click.testing import CliRunner

from rend3r.cli import main

PROGRAM = "nr\ncam xloc, 1.5\nsp 1, xloc, yloc, 1, -2\ner\ner\n"
MEM = b"00000200\n3e000801\n0000088d\n3c00c000\n00000000\n00000000\n"


@pytest.fixture
def src(tmp_path: Path) -> Path:
    p = tmp_path / "scene.asm"
    p.write_text(PROGRAM)
    return p


def run(*args: str):
    return CliRunner().invoke(main, ["asm", *args], catch_exceptions=False)


def test_mem_to_stdout(src: Path):
    r = run(str(src))
    assert r.exit_code == 0 and r.stdout_bytes == MEM


def test_single_format_exact_path(src: Path, tmp_path: Path):
    out = tmp_path / "out.txt"
    r = run(str(src), "-o", str(out))
    assert r.exit_code == 0 and out.read_bytes() == MEM


def test_several_formats_use_a_stem(src: Path, tmp_path: Path):
    r = run(str(src), "-f", "mem", "-f", "bin", "-f", "lst", "-o", str(tmp_path / "build.mem"))
    assert r.exit_code == 0, r.output
    assert (tmp_path / "build.mem").read_bytes() == MEM
    assert (tmp_path / "build.bin").read_bytes() == b"".join(int(w, 16).to_bytes(4, "big") for w in MEM.split())
    assert (tmp_path / "build.lst").exists()


def test_several_formats_default_stem_beside_source(src: Path, tmp_path: Path):
    r = run(str(src), "-f", "coe", "-f", "ihex", "-f", "mem-annotated")
    assert r.exit_code == 0, r.output
    assert {p.name for p in tmp_path.iterdir()} == {"scene.asm", "scene.coe", "scene.hex", "scene.annotated.mem"}


def test_byteorder_little(src: Path, tmp_path: Path):
    out = tmp_path / "le.bin"
    assert run(str(src), "-f", "bin", "--byteorder", "little", "-o", str(out)).exit_code == 0
    assert out.read_bytes()[:4] == (0x200).to_bytes(4, "little")


def test_errors_exit_1_and_write_nothing(tmp_path: Path):
    bad = tmp_path / "bad.asm"
    bad.write_text("cam xloc, 1\ncam xlco, 1\nlt 64, xloc, 1\ner\ner\n")
    out = tmp_path / "bad.mem"
    r = run(str(bad), "-o", str(out), "-f", "mem")
    assert r.exit_code == 1
    assert "bad.asm:2:5: error: unknown camera property 'xlco'" in r.stderr
    assert "bad.asm:3:4: error: light index 64" in r.stderr
    assert "rend3r: error:" in r.stderr and "no output written" in r.stderr
    assert not out.exists() and sorted(p.name for p in tmp_path.iterdir()) == ["bad.asm"]


def test_existing_output_untouched_on_error(tmp_path: Path):
    bad = tmp_path / "bad.asm"
    bad.write_text("cam xloc, 1 / 0\ner\ner\n")
    out = tmp_path / "keep.mem"
    out.write_text("old\n")
    assert run(str(bad), "-o", str(out)).exit_code == 1
    assert out.read_text() == "old\n"


def test_warnings_and_werror(tmp_path: Path):
    w = tmp_path / "w.asm"
    w.write_text("cam xloc, 0x3c00\ner\ner\n")
    r = run(str(w))
    assert r.exit_code == 0 and "warning: 0x3c00 is the integer 15360" in r.stderr
    assert r.stdout_bytes == b"73800801\n00000000\n00000000\n"
    for flag in (["-W", "error"], ["--werror"]):  # --werror: the old spelling, hidden
        r = run(str(w), *flag, "-o", str(tmp_path / "w.mem"))
        assert r.exit_code == 1 and "error: 0x3c00" in r.stderr
        assert not (tmp_path / "w.mem").exists()


def test_target_warning(src: Path):
    r = run(str(src), "--target", "rend3r-raytracing")
    assert r.exit_code == 0 and r.stderr == ""
    src.write_text("sp 2, xloc, yloc, 1, 1\ner\ner\n")
    r = run(str(src), "--target", "rend3r-raytracing")
    assert "shape index 2 is beyond rend3r-raytracing's 2 shape slots" in r.stderr


def test_include_dir_option(tmp_path: Path):
    (tmp_path / "inc").mkdir()
    (tmp_path / "inc" / "c.inc").write_text("V = 2\n")
    s = tmp_path / "s.asm"
    s.write_text('.include "c.inc"\ncam xloc, V\ner\ner\n')
    assert run(str(s)).exit_code == 1
    r = run(str(s), "-I", str(tmp_path / "inc"))
    assert r.exit_code == 0 and r.stdout_bytes.startswith(b"40000801\n")


def test_missing_source_and_bad_options(tmp_path: Path, src: Path):
    r = run(str(tmp_path / "missing.asm"))
    assert r.exit_code == 1 and "cannot read" in r.stderr
    assert run(str(src), "-f", "elf").exit_code == 2
    r = run(str(src), "-f", "mem", "-f", "lst", "-o", "-")
    assert r.exit_code == 1 and "takes a single format" in r.stderr


def test_help_shows_an_example():
    r = run("--help")
    assert r.exit_code == 0 and "rend3r asm scene.asm -o main.mem" in r.output


def _rend3r(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONDONTWRITEBYTECODE": "1"}
    return subprocess.run([sys.executable, "-m", "rend3r", *args], cwd=cwd, capture_output=True, env=env, timeout=60)


def test_real_process(src: Path, tmp_path: Path):
    p = _rend3r("asm", src.name, "-o", "scene.mem", cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    assert (tmp_path / "scene.mem").read_bytes() == MEM
    (tmp_path / "bad.asm").write_bytes(b"\xff\xfe\x00garbage")
    p = _rend3r("asm", "bad.asm", cwd=tmp_path)
    assert p.returncode == 1 and b"Traceback" not in p.stderr and b"is not UTF-8 text" in p.stderr


def test_one_spelling_of_warnings_as_errors_is_documented():
    r = run("--help")
    assert "-W [error]" in r.stdout and "--werror" not in r.stdout


def test_isa_ext_is_a_choice(src: Path):
    r = CliRunner().invoke(main, ["asm", str(src), "--isa-ext", "hybrd"])
    assert r.exit_code == 2 and "'hybrd' is not 'hybrid'" in r.output, r.output
    assert run(str(src), "--isa-ext", "HYBRID").exit_code == 0


@pytest.mark.parametrize("name", ["scene.rdr", "scene.s"])
def test_every_source_suffix_assembles(tmp_path: Path, name: str):
    (tmp_path / name).write_text(PROGRAM)
    r = run(str(tmp_path / name))
    assert r.exit_code == 0 and r.stdout_bytes == MEM


@pytest.mark.parametrize("name, data, what", [
    ("x.png", b"\x89PNG\r\n\x1a\n" + bytes(20), "a PNG image"),
    ("x.jpg", b"\xff\xd8\xff\xe0" + bytes(20), "a JPEG image"),
    ("x.asm", b"GIF89a" + bytes(20), "a GIF image"),
    ("x.zip", b"PK\x03\x04" + bytes(20), "a ZIP archive"),
    ("x.mem", b"00000200\n", "a memory image, not assembly source"),
])
def test_what_is_not_source_is_refused_by_name(tmp_path: Path, name: str, data: bytes, what: str):
    (tmp_path / name).write_bytes(data)
    r = CliRunner().invoke(main, ["asm", str(tmp_path / name), "-o", str(tmp_path / "o.mem")])
    assert r.exit_code == 1 and r.output.startswith(f"rend3r: error: {tmp_path / name} is {what}"), r.output
    assert not (tmp_path / "o.mem").exists()


def test_outputs_make_their_folders_and_are_all_or_nothing(src: Path, tmp_path: Path):
    r = run(str(src), "-f", "mem", "-f", "lst", "-o", str(tmp_path / "build" / "deep" / "scene"))
    assert r.exit_code == 0
    assert sorted(p.name for p in (tmp_path / "build" / "deep").iterdir()) == ["scene.lst", "scene.mem"]
    (tmp_path / "taken.lst").mkdir()  # the second output cannot be written: the first is not either
    r = CliRunner().invoke(main, ["asm", str(src), "-f", "mem", "-f", "lst", "-o", str(tmp_path / "taken")])
    assert r.exit_code == 1 and r.output == f"rend3r: error: cannot write {tmp_path / 'taken.lst'}: it is a folder\n"
    assert not (tmp_path / "taken.mem").exists()
