"""``rend3r compare`` on real files, through the CLI group."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from PIL import Image

from rend3r.cli import main


def _png(path: Path, rgb: np.ndarray) -> Path:
    Image.fromarray(rgb, mode="RGB").save(path)
    return path


def _raw(path: Path, fb: np.ndarray) -> Path:
    path.write_bytes(fb.astype("<u2").tobytes())
    return path


def test_identical_pngs_exit_0(tmp_path: Path) -> None:
    rgb = np.random.default_rng(1).integers(0, 256, (6, 8, 3), dtype=np.uint8)
    a, b = _png(tmp_path / "a.png", rgb), _png(tmp_path / "b.png", rgb)
    r = CliRunner().invoke(main, ["compare", str(a), str(b)])
    assert r.exit_code == 0, r.output
    assert "PSNR inf dB" in r.output and "within tolerance" in r.output


def test_difference_beyond_tolerance_exit_1_and_diff(tmp_path: Path) -> None:
    rgb = np.zeros((4, 4, 3), dtype=np.uint8)
    other = rgb.copy()
    other[2, 3] = (0, 40, 0)
    a, b = _png(tmp_path / "a.png", rgb), _png(tmp_path / "b.png", other)
    diff = tmp_path / "d.png"
    r = CliRunner().invoke(main, ["compare", str(a), str(b), "-o", str(diff)])
    assert r.exit_code == 1, r.output
    assert "max channel difference 40" in r.output and "NOT within tolerance" in r.output
    d = np.asarray(Image.open(diff))
    assert d.shape == (4, 4, 3) and d[2, 3, 0] > 0 and d[2, 3, 1] == 0 and d[0, 0].tolist() == [0, 0, 0]
    r = CliRunner().invoke(main, ["compare", str(a), str(b), "--max-channel", "40", "--max-share", "0.0625"])
    assert r.exit_code == 0, r.output
    r = CliRunner().invoke(main, ["compare", str(a), str(b), "--max-channel", "40", "--min-psnr", "40"])
    assert r.exit_code == 1, r.output


def test_raw_framebuffer_against_png(tmp_path: Path) -> None:
    fb = np.array([[0xF800, 0x07E0, 0x001F], [0xFFFF, 0, 0x8410]], dtype=np.uint16)
    raw = _raw(tmp_path / "fb.bin", fb)
    from rend3r.golden.metrics import rgb565_to_rgb888

    png = _png(tmp_path / "fb.png", rgb565_to_rgb888(fb))
    r = CliRunner().invoke(main, ["compare", str(raw), str(png), "--size", "3x2"])
    assert r.exit_code == 0, r.output


def test_raw_device_size_needs_no_size(tmp_path: Path) -> None:
    fb = np.zeros((384, 512), dtype=np.uint16)
    a = _raw(tmp_path / "a.bin", fb)
    fb[0, 0] = 1
    b = _raw(tmp_path / "b.bin", fb)
    r = CliRunner().invoke(main, ["compare", str(a), str(b)])
    assert r.exit_code == 1 and "differing pixels 1/196608" in r.output


def test_errors_exit_2_like_cmp(tmp_path: Path) -> None:
    odd = tmp_path / "odd.bin"
    odd.write_bytes(b"\x00" * 10)
    r = CliRunner().invoke(main, ["compare", str(odd), str(odd)])
    assert r.exit_code == 2 and "rend3r: error:" in r.output and "--size" in r.output
    r = CliRunner().invoke(main, ["compare", str(tmp_path / "missing.png"), str(odd)])
    assert r.exit_code == 2 and "cannot read" in r.output
    garbage = tmp_path / "garbage.png"
    garbage.write_bytes(b"\x89PNG\r\n\x1a\n" + b"junk" * 10)
    r = CliRunner().invoke(main, ["compare", str(garbage), str(garbage)])
    assert r.exit_code == 2 and "cannot read PNG" in r.output
    a = _png(tmp_path / "a.png", np.zeros((2, 2, 3), np.uint8))
    b = _png(tmp_path / "b.png", np.zeros((2, 3, 3), np.uint8))
    r = CliRunner().invoke(main, ["compare", str(a), str(b)])
    assert r.exit_code == 2 and "sizes differ" in r.output
    for size in ("3by2", "0x2", "100000x100000"):
        r = CliRunner().invoke(main, ["compare", str(a), str(b), "--size", size])
        assert r.exit_code == 2 and "--size" in r.output, (size, r.output)
    assert "2 on trouble" in " ".join(CliRunner().invoke(main, ["compare", "--help"]).output.split())


def test_min_psnr_nan_is_rejected(tmp_path: Path) -> None:
    a = _png(tmp_path / "a.png", np.zeros((2, 2, 3), np.uint8))
    r = CliRunner().invoke(main, ["compare", str(a), str(a), "--min-psnr", "nan"])
    assert r.exit_code == 2 and "nan" in r.output
    r = CliRunner().invoke(main, ["compare", str(a), str(a), "--min-psnr", "inf"])
    assert r.exit_code == 0, r.output


def test_diff_path_is_checked_before_comparing(tmp_path: Path) -> None:
    a = _png(tmp_path / "a.png", np.zeros((2, 2, 3), np.uint8))
    (tmp_path / "plain").write_text("x")
    for diff, why in ((tmp_path / "plain" / "d.png", f"cannot write {tmp_path / 'plain' / 'd.png'}: "
                                                     f"{tmp_path / 'plain'} is not a folder"),
                      (tmp_path / "d.txt", "unknown image type")):
        r = CliRunner().invoke(main, ["compare", str(a), str(a), "-o", str(diff), "--size", "1x1"])
        assert r.exit_code == 2 and why in r.output, r.output
        assert not diff.exists()


@pytest.mark.parametrize("option", ["-o", "--output", "--diff"])
def test_diff_folders_are_made(tmp_path: Path, option: str) -> None:
    a = _png(tmp_path / "a.png", np.zeros((2, 2, 3), np.uint8))
    r = CliRunner().invoke(main, ["compare", str(a), str(a), option, str(tmp_path / "x" / "y" / "d.png")])
    assert r.exit_code == 0, r.output
    assert Image.open(tmp_path / "x" / "y" / "d.png").size == (2, 2)


def test_two_spellings_of_the_diff_are_a_usage_error(tmp_path: Path) -> None:
    a = _png(tmp_path / "a.png", np.zeros((2, 2, 3), np.uint8))
    r = CliRunner().invoke(main, ["compare", str(a), str(a), "-o", str(tmp_path / "d.png"), "--diff",
                                  str(tmp_path / "e.png")])
    assert r.exit_code == 2 and "-o and --diff name the same output" in r.output


@pytest.mark.parametrize(("pos", "value"), [(11, 0), (36, 0), (20, 0xFF)])
def test_damaged_pngs_are_errors_not_tracebacks(tmp_path: Path, pos: int, value: int) -> None:
    """Pillow reports damage as OSError, ValueError (a short IHDR) or SyntaxError (a broken chunk)."""
    data = bytearray(_png(tmp_path / "good.png", np.zeros((4, 4, 3), np.uint8)).read_bytes())
    data[pos] = value
    bad = tmp_path / "bad.png"
    bad.write_bytes(bytes(data))
    r = CliRunner().invoke(main, ["compare", str(bad), str(tmp_path / "good.png")])
    assert r.exit_code == 2 and "cannot read PNG" in r.output, (r.output, repr(r.exception))
