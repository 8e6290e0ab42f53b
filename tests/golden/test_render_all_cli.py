"""``rend3r render-all`` on real program files."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from PIL import Image

from rend3r.cli import main

PROGRAMS_DIR = Path(__file__).resolve().parents[2] / "programs"


def test_renders_every_program_and_frame(tmp_path: Path) -> None:
    src = tmp_path / "progs"
    src.mkdir()
    for name in ("sphere.asm", "animation.asm"):
        shutil.copy(PROGRAMS_DIR / name, src / name)
    out = tmp_path / "out"
    r = CliRunner().invoke(main, ["render-all", str(src), "-o", str(out), "--size", "32x24", "--precision", "fp32"])
    assert r.exit_code == 0, r.output
    assert "[1/2] animation: 8 frames 32x24 fp32" in r.output and "[2/2] sphere: 1 frame 32x24 fp32" in r.output
    names = sorted(p.name for p in out.iterdir())
    assert names == [f"animation.{i:03d}.png" for i in range(8)] + ["sphere.png"]
    sphere = np.asarray(Image.open(out / "sphere.png"))
    assert sphere.shape == (24, 32, 3) and sphere[..., 0].max() > 100  # the red sphere is there
    frames = [np.asarray(Image.open(out / f"animation.{i:03d}.png")) for i in range(8)]
    assert not np.array_equal(frames[0], frames[2])  # it moves


def test_failing_program_is_reported_and_others_still_render(tmp_path: Path) -> None:
    (tmp_path / "bad.asm").write_text("; bad.asm: broken\nsp 0, nosuchprop, type, 1, 1\n", encoding="utf-8")
    shutil.copy(PROGRAMS_DIR / "sphere.asm", tmp_path / "sphere.asm")
    out = tmp_path / "out"
    r = CliRunner().invoke(main, ["render-all", str(tmp_path), "-o", str(out), "--size", "16x12"])
    assert r.exit_code == 1
    assert "[1/2] bad: FAILED" in r.output and "nosuchprop" in r.output
    assert "1 program(s) failed: bad" in r.output
    assert (out / "sphere.png").exists() and not (out / "bad.png").exists()


def test_empty_or_missing_folder(tmp_path: Path) -> None:
    r = CliRunner().invoke(main, ["render-all", str(tmp_path), "-o", str(tmp_path / "o")])
    assert r.exit_code == 1 and "no *.asm programs" in r.output
    r = CliRunner().invoke(main, ["render-all", str(tmp_path / "missing"), "-o", str(tmp_path / "o")])
    assert r.exit_code == 1 and "is not a folder" in r.output


@pytest.mark.parametrize(
    ("header", "why"),
    [
        ("; frames: abc\n", "bad.asm:2: frames: expected a whole number"),
        ("; frames: 0\n", "bad.asm:2: frames: expected a whole number"),
        ("; test-size: abc\n", "bad.asm:2: test-size: expected WIDTHxHEIGHT"),
        ("; test-size: 100000x1\n", "bad.asm:2: test-size: width and height must be 1..8192"),
        ("; mode: bogus\n", "bad.asm:2: mode: expected raytrace, raster, hybrid"),
    ],
)
def test_bad_header_fails_that_program_only(tmp_path: Path, header: str, why: str) -> None:
    (tmp_path / "bad.asm").write_text("; bad.asm\n" + header + "nr\nnf\ner\n", encoding="utf-8")
    shutil.copy(PROGRAMS_DIR / "sphere.asm", tmp_path / "sphere.asm")
    out = tmp_path / "out"
    r = CliRunner().invoke(main, ["render-all", str(tmp_path), "-o", str(out), "--size", "8x6"])
    assert r.exit_code == 1, r.output
    assert "[1/2] bad: FAILED" in r.output and why in r.output, r.output
    assert (out / "sphere.png").exists()


def test_binary_program_fails_cleanly(tmp_path: Path) -> None:
    (tmp_path / "bin.asm").write_bytes(b"; ok\n\xff\xfe\x00binary")
    r = CliRunner().invoke(main, ["render-all", str(tmp_path), "-o", str(tmp_path / "o"), "--size", "8x6"])
    assert r.exit_code == 1 and "bin.asm:2: not UTF-8 text (byte 0xff)" in r.output, r.output


def test_huge_size_is_a_usage_error(tmp_path: Path) -> None:
    shutil.copy(PROGRAMS_DIR / "sphere.asm", tmp_path / "sphere.asm")
    r = CliRunner().invoke(main, ["render-all", str(tmp_path), "-o", str(tmp_path / "o"), "--size", "100000x100000"])
    assert r.exit_code == 2 and "1..8192" in r.output
    assert not (tmp_path / "o").exists()


def test_output_folder_and_its_parents_are_made(tmp_path: Path) -> None:
    shutil.copy(PROGRAMS_DIR / "sphere.asm", tmp_path / "sphere.asm")
    out = tmp_path / "a" / "b"
    r = CliRunner().invoke(main, ["render-all", str(tmp_path), "--output", str(out), "--size", "8x6"])
    assert r.exit_code == 0, r.output
    assert Image.open(out / "sphere.png").size == (8, 6)


def test_output_under_a_file_is_a_clean_error(tmp_path: Path) -> None:
    shutil.copy(PROGRAMS_DIR / "sphere.asm", tmp_path / "sphere.asm")
    (tmp_path / "plain").write_text("x")
    for out, why in ((tmp_path / "plain", "it is a file, not a folder"),
                     (tmp_path / "plain" / "sub", f"{tmp_path / 'plain'} is not a folder")):
        r = CliRunner().invoke(main, ["render-all", str(tmp_path), "-o", str(out), "--size", "8x6"])
        assert (r.exit_code, r.output) == (1, f"rend3r: error: cannot write {out}: {why}\n")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["plain", "sphere.asm"]
