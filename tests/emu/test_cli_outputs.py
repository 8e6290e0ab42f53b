"""emulate's outputs: extensions checked before rendering, folders, atomic writes, option ranges."""

import numpy as np
from click.testing import CliRunner
from PIL import Image

from rend3r.cli import main

from .test_cli import SRC


def _run(*args):
    return CliRunner().invoke(main, ["emulate", *map(str, args)])


def _src(tmp_path):
    p = tmp_path / "s.asm"
    p.write_text(SRC)
    return p


def test_unknown_extension_is_an_error_not_a_silent_png(tmp_path):
    r = _run(_src(tmp_path), "-o", tmp_path / "x.txt", "--size", "8x6")
    assert r.exit_code == 1 and "unknown image type '.txt'" in r.output and ".png" in r.output
    assert r.exception is None or isinstance(r.exception, SystemExit)
    assert not (tmp_path / "x.txt").exists()


def test_wrong_extension_for_each_output_kind(tmp_path):
    src = _src(tmp_path)
    for opt, name in (("--gif", "a.png"), ("--apng", "a.gif"), ("--depth-image", "d.jpg"), ("--provenance", "p")):
        r = _run(src, "-o", tmp_path / "f.png", opt, tmp_path / name, "--size", "8x6")
        assert r.exit_code == 1 and "unknown image type" in r.output, (opt, r.output)
    assert not (tmp_path / "f.png").exists()  # refused before rendering


def test_plain_name_in_a_missing_folder_is_refused(tmp_path):
    r = _run(_src(tmp_path), "-o", tmp_path / "nope" / "f.png", "--size", "8x6")
    assert r.exit_code == 1 and "does not exist" in r.output
    assert not (tmp_path / "nope").exists()


def test_pattern_creates_its_folders(tmp_path):
    r = _run(_src(tmp_path), "-o", tmp_path / "a" / "b" / "f_{n}.png", "--depth-image", tmp_path / "d" / "z_{n}.npy",
             "--size", "8x6")
    assert r.exit_code == 0, r.output
    assert Image.open(tmp_path / "a" / "b" / "f_0.png").size == (8, 6)
    assert np.load(tmp_path / "d" / "z_0.npy").shape == (6, 8)


def test_unwritable_target_is_an_error_and_leaves_no_temporary_file(tmp_path):
    (tmp_path / "taken.png").mkdir()
    r = _run(_src(tmp_path), "-o", tmp_path / "taken.png", "--size", "8x6")
    assert r.exit_code == 1 and "cannot write" in r.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.asm", "taken.png"]


def test_apng_accepts_the_apng_extension(tmp_path):
    r = _run(_src(tmp_path), "--apng", tmp_path / "a.apng", "--size", "8x6")
    assert r.exit_code == 0, r.output
    assert Image.open(tmp_path / "a.apng").format == "PNG"


def test_frames_zero_and_huge_sizes_are_usage_errors(tmp_path):
    src = _src(tmp_path)
    r = _run(src, "-o", tmp_path / "f.png", "--frames", 0)
    assert r.exit_code == 2 and "--frames" in r.output
    for size in ("100000x100000", "0x5", "axb"):
        r = _run(src, "-o", tmp_path / "f.png", "--size", size)
        assert r.exit_code == 2 and "--size" in r.output, (size, r.output)


def test_trace_file_in_a_missing_folder_is_refused_before_rendering(tmp_path):
    r = _run(_src(tmp_path), "-o", tmp_path / "f.png", "--size", "8x6", "--trace-pixel", "1,1",
             "--trace", tmp_path / "nope" / "t.jsonl")
    assert r.exit_code == 1 and "does not exist" in r.output
    assert not (tmp_path / "f.png").exists()
