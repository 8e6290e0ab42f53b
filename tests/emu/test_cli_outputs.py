"""emulate's outputs: extensions checked before rendering, folders, atomic writes, option ranges."""

import subprocess
import sys

import numpy as np
import pytest
from click.testing import CliRunner
from PIL import Image

from rend3r.cli import main
from rend3r.errors import Rend3rError

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


def test_plain_name_in_a_missing_folder_creates_it(tmp_path):
    r = _run(_src(tmp_path), "-o", tmp_path / "new" / "f.png", "--size", "8x6")
    assert r.exit_code == 0, r.output
    assert Image.open(tmp_path / "new" / "f.png").size == (8, 6)


def test_output_under_a_file_is_refused_by_name_before_rendering(tmp_path):
    (tmp_path / "plain").write_text("x")
    target = tmp_path / "plain" / "sub" / "f.png"
    r = _run(_src(tmp_path), "-o", tmp_path / "f.png", "--depth-image", target, "--size", "8x6")
    assert r.exit_code == 1, r.output
    assert r.output == f"rend3r: error: cannot write {target}: {tmp_path / 'plain'} is not a folder\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["plain", "s.asm"]


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


def test_trace_file_under_a_file_is_refused_before_rendering(tmp_path):
    (tmp_path / "plain").write_text("x")
    r = _run(_src(tmp_path), "-o", tmp_path / "f.png", "--size", "8x6", "--trace-pixel", "1,1",
             "--trace", tmp_path / "plain" / "t.jsonl")
    assert r.exit_code == 1 and "is not a folder" in r.output
    assert not (tmp_path / "f.png").exists()


ANIM = ("nr\nsp 0, type, zloc, 1, -3\nsp 0, xscl, yscl, 1, 1\nsp 0, zscl, col, 1, 0xffff\nnf\n"
        "sp 0, xloc, zero, 1, 0\nnf\nsp 0, xloc, zero, 2, 0\nnf\ner\n")


def _anim(tmp_path):
    p = tmp_path / "anim.asm"
    p.write_text(ANIM)
    return p


@pytest.mark.parametrize("opt", ["-o", "--depth-image", "--provenance"])
@pytest.mark.parametrize("pattern, message", [
    ("f_{n[0]}.png", "field {n[0]}"),
    ("o/f_{n:999999999}.png", "wider than 32 digits"),
    ("f_{n:>9}.png", "zero-padded"),
    ("f_{n!r}.png", "field {n!r}"),
    ("f_{}.png", "field {}"),
    ("f_{n:{n}}.png", "field {n:{n}}"),
    ("f_{.png", "expected '}'"),
    ("f_{n:99999999999999999999999999999999999999999999999999999}.png", "wider than 32 digits"),
])
def test_bad_name_patterns_are_usage_errors_before_any_work(tmp_path, opt, pattern, message):
    out = ["-o", tmp_path / "f_{n}.png"] if opt != "-o" else []
    r = _run(_anim(tmp_path), *out, opt, tmp_path / pattern, "--size", "8x6")
    assert r.exit_code == 2 and message in r.output and "Traceback" not in r.output, r.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["anim.asm"]


def test_good_name_patterns(tmp_path):
    r = _run(_anim(tmp_path), "-o", tmp_path / "x{{y}}_{n:032}.png", "--depth-image", tmp_path / "d{n:3d}.npy",
             "--size", "8x6")
    assert r.exit_code == 0, r.output
    names = sorted(p.name for p in tmp_path.iterdir())
    assert names == ["anim.asm", "d  0.npy", "d  1.npy", "d  2.npy"] + [f"x{{y}}_{n:032}.png" for n in range(3)]


def test_two_outputs_with_one_name_are_refused(tmp_path):
    r = _run(_anim(tmp_path), "-o", tmp_path / "f{n}.png", "--provenance", tmp_path / "f{n:01}.png", "--size", "8x6")
    assert r.exit_code == 1 and "named by two outputs" in r.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["anim.asm"]


@pytest.mark.parametrize("opt, name", [("--gif", "taken.gif"), ("--depth-image", "taken.png"),
                                       ("--trace", "taken.jsonl")])
def test_a_failing_output_leaves_no_output_and_keeps_replaced_files(tmp_path, opt, name):
    (tmp_path / name).mkdir()
    (tmp_path / "out.png").write_bytes(b"old")
    extra = ["--trace-pixel", "1,1"] if opt == "--trace" else []
    r = _run(_src(tmp_path), "-o", tmp_path / "out.png", opt, tmp_path / name, *extra, "--size", "8x6")
    assert r.exit_code == 1 and "cannot write" in r.output and name in r.output, r.output
    assert (tmp_path / "out.png").read_bytes() == b"old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.png", "s.asm", name]


def test_frames_of_a_pattern_are_not_kept_when_the_animation_fails(tmp_path):
    (tmp_path / "a.gif").mkdir()
    r = _run(_anim(tmp_path), "-o", tmp_path / "fr" / "f_{n}.png", "--gif", tmp_path / "a.gif", "--size", "8x6")
    assert r.exit_code == 1 and "a.gif" in r.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.gif", "anim.asm"]  # no fr/ folder either


def test_a_name_too_long_is_refused_before_rendering(tmp_path):
    r = _run(_anim(tmp_path), "-o", tmp_path / ("f" * 254 + "{n}.png"), "--size", "8x6")
    assert r.exit_code == 1 and "longer than 255 bytes" in r.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["anim.asm"]


def test_a_run_over_the_memory_budget_is_refused_with_its_estimate(tmp_path):
    r = _run(_anim(tmp_path), "--gif", tmp_path / "a.gif", "--size", "8192x8192", "--max-memory", "2G")
    assert r.exit_code == 1 and "memory budget is 2.00 GiB" in r.output and "3 animation frames" in r.output, r.output
    assert "needs about" in r.output and "--max-memory" in r.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["anim.asm"]
    r = _run(_anim(tmp_path), "--gif", tmp_path / "a.gif", "--size", "8x6", "--max-memory", "2x")
    assert r.exit_code == 2 and "512M or 4G" in r.output


EXTREME = """nr
cam xloc, 65504
cam yloc, -65504
cam zloc, 0.00000006
cam rrot, 65504
cam hfov, 65504
cam vfov, 0.00000006
cam nclip, 0.00000006
cam fclip, 65504
lt 0, src, 1
lt 0, zfor, -65504
lt 0, int, 65504
lt 1, src, 2
lt 1, xloc, 65504
sp 0, type, zloc, 1, -65504
sp 0, xscl, yscl, 65504, 0.00006
sp 0, zscl, col, 65504, 0xffff
sp 1, type, zloc, 2, -0.00000006
sp 1, xscl, yscl, 0.00000006, 65504
sp 1, rrot, irot, 65504, 65504
tr 0, x1, y1, 65504, -65504
tr 0, z1, x2, -3, 0.00000006
tr 0, y2, z2, 65504, -65504
tr 0, x3, y3, 0.00000006, 1
tr 0, z3, col, -65504, 0x07e0
nf
er
er
"""


@pytest.mark.parametrize("special", ["7c00", "7e00"])  # inf or NaN where the source has 65504
def test_no_numpy_warning_reaches_the_terminal_with_extreme_values(tmp_path, special):
    """A real child process (pytest would swallow warnings in-process), warnings switched on."""
    src = tmp_path / "x.asm"
    src.write_text(EXTREME)
    rend3r = [sys.executable, "-W", "default", "-m", "rend3r"]
    mem = tmp_path / "x.mem"
    subprocess.run([*rend3r, "asm", src, "-o", mem], check=True, capture_output=True)
    mem.write_text(mem.read_text().replace("7bff", special).replace("fbff", "8001"))  # and -65504: -subnormal
    for mode, precision in (("raytrace", "fp16"), ("raster", "fp32"), ("hybrid", "fp64")):
        trace = ["--trace-pixel", "3,3"] if mode != "hybrid" else []
        r = subprocess.run([*rend3r, "emulate", mem, "-o", tmp_path / "f.png", "--depth-image", tmp_path / "d.png",
                            "--provenance", tmp_path / "p.png", "--size", "16x12", "--mode", mode,
                            "--precision", precision, *trace], capture_output=True, text=True, timeout=120)
        assert r.returncode == 0, r.stderr
        assert "Warning" not in r.stderr and "Traceback" not in r.stderr, r.stderr


def test_outputs_commit_all_or_roll_back_every_one(tmp_path):
    from rend3r.fileio import Outputs

    (tmp_path / "old.png").write_bytes(b"old")
    out = Outputs()
    for name in ("old.png", "new.png", "sub/deep/x.png", "late.png"):
        out.reserve(tmp_path / name)
    out.write(tmp_path / "old.png", b"new content")
    out.write(tmp_path / "new.png", b"n")
    out.write(tmp_path / "sub" / "deep" / "x.png", b"x")
    out.write(tmp_path / "late.png", b"l")
    assert (tmp_path / "old.png").read_bytes() == b"old" and not (tmp_path / "new.png").exists()
    (tmp_path / "late.png").mkdir()  # the last rename fails after the others were done
    with pytest.raises(Rend3rError, match="cannot write .*late.png: "):
        out.commit()
    assert (tmp_path / "old.png").read_bytes() == b"old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["late.png", "old.png"]  # sub/ removed, no stray file
    (tmp_path / "late.png").rmdir()
    with Outputs() as out:
        out.write(tmp_path / "old.png", b"new content")
        out.write(tmp_path / "a" / "b.png", b"b")
        out.commit()
    assert (tmp_path / "old.png").read_bytes() == b"new content" and (tmp_path / "a" / "b.png").read_bytes() == b"b"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a", "old.png"]


def test_outputs_abort_on_an_exception_inside_the_run(tmp_path):
    from rend3r.fileio import Outputs

    with pytest.raises(KeyboardInterrupt):
        with Outputs() as out:
            out.write(tmp_path / "f" / "a.png", b"a")
            raise KeyboardInterrupt
    assert list(tmp_path.iterdir()) == []
