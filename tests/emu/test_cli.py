"""rend3r emulate end to end: real files in, real images out (CliRunner)."""

from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from PIL import Image

from rend3r.cli import main
from rend3r.emu.image import rgb565_to_rgb888
from rend3r.emu.options import EmuOptions
from rend3r.emu.run import run_program

from .scenes import ONE_SPHERE as SRC, Prog



def _run(*args, **kw):
    result = CliRunner().invoke(main, ["emulate", *map(str, args)], **kw)
    return result


@pytest.fixture
def src(tmp_path):
    p = tmp_path / "s.asm"
    p.write_text(SRC)
    return p


def test_png_is_the_frame_buffer_with_bit_replication(tmp_path, src):
    out = tmp_path / "f.png"
    r = _run(src, "-o", out, "--size", "40x30")
    assert r.exit_code == 0, r.output
    from rend3r.emu.loader import load_program

    frame = run_program(load_program(src).words, EmuOptions(width=40, height=30)).frames[0]
    img = np.asarray(Image.open(out).convert("RGB"))
    assert img.shape == (30, 40, 3)
    assert (img == rgb565_to_rgb888(frame.rgb565)).all()
    assert (frame.rgb565 != 0).any()


def test_memory_image_input_and_background(tmp_path):
    mem = tmp_path / "p.mem"
    words = Prog().nr().sphere(0).nf().er().words
    mem.write_text("".join(f"{w:08x}\n" for w in words))
    out = tmp_path / "f.png"
    r = _run(mem, "-o", out, "--size", "16x12", "--background", "0x001F")
    assert r.exit_code == 0, r.output
    assert tuple(np.asarray(Image.open(out).convert("RGB"))[0, 0]) == (0, 0, 255)


def test_several_frames_need_a_pattern_then_write_each_and_a_gif(tmp_path):
    src = tmp_path / "loop.asm"
    src.write_text("nr\nsp 0, type, zloc, 1, -3\nsp 0, xscl, yscl, 1, 1\nsp 0, zscl, col, 1, 0xffff\nnf\nlr\n")
    r = _run(src, "-o", tmp_path / "x.png", "--size", "16x12")
    assert r.exit_code == 1 and "loops" in r.output and "--frames" in r.output
    r = _run(src, "--frames", 3, "-o", tmp_path / "x.png", "--size", "16x12")
    assert r.exit_code == 1 and "pattern" in r.output
    anim = tmp_path / "anim.asm"
    anim.write_text("nr\nsp 0, type, zloc, 1, -3\nsp 0, xscl, yscl, 1, 1\nsp 0, zscl, col, 1, 0xffff\nnf\n"
                    "sp 0, xloc, zero, 1, 0\nnf\nsp 0, xloc, zero, 2, 0\nnf\ner\n")
    r = _run(anim, "-o", tmp_path / "out" / "f_{n:02}.png", "--gif", tmp_path / "a.gif",
             "--depth-image", tmp_path / "d_{n}.npy", "--provenance", tmp_path / "p_{n}.png", "--size", "16x12")
    assert r.exit_code == 0, r.output
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["f_00.png", "f_01.png", "f_02.png"]
    gif = Image.open(tmp_path / "a.gif")
    assert gif.n_frames == 3
    depth = np.load(tmp_path / "d_1.npy")
    assert depth.dtype == np.float32 and depth.shape == (12, 16) and np.isfinite(depth).any()
    assert Image.open(tmp_path / "p_2.png").size == (16, 12)


def test_apng_depth_png_and_stats(tmp_path, src):
    r = _run(src, "--apng", tmp_path / "a.png", "--depth-image", tmp_path / "d.png", "--provenance",
             tmp_path / "p.npy", "--stats", "--size", "32x24", "--precision", "fp32")
    assert r.exit_code == 0, r.output
    assert "device estimate" in r.output and "rays 768" in r.output
    from rend3r.emu import native

    assert f"kernels: the {native.isa()} build" in r.output
    d = np.asarray(Image.open(tmp_path / "d.png"))
    assert d.dtype.kind in "iu" and d.max() == 65535 and d.min() == 0
    prov = np.load(tmp_path / "p.npy")
    assert set(np.unique(prov)) == {-1, 0}


def test_nan_rays_are_reported_on_stderr(tmp_path):
    src = tmp_path / "bad.asm"
    src.write_text("nr\nsp 0, type, zloc, 1, -3\nnf\ner\n")  # inverse scales left at zero
    r = _run(src, "-o", tmp_path / "f.png", "--size", "8x6")
    assert r.exit_code == 0
    assert "warning: 48 rays met NaN or infinity" in r.stderr


@pytest.mark.parametrize("args, message", [
    (["--size", "12"], "WIDTHxHEIGHT"),
    (["--background", "0x10000"], "16 bits"),
    (["--gif", "a.gif", "--apng", "b.png"], "exclusive"),
    ([], "nothing to write"),
])
def test_argument_errors(tmp_path, src, args, message):
    r = _run(src, *args)
    assert r.exit_code != 0 and message in r.output


def test_errors_in_the_program_name_the_file_and_the_address(tmp_path):
    mem = tmp_path / "p.mem"
    mem.write_text("00000200\n00000006\n")
    r = _run(mem, "-o", tmp_path / "f.png")
    assert r.exit_code == 1 and f"rend3r: error: {mem}: address 1 (0x0001): unknown opcode" in r.output
    assert not (tmp_path / "f.png").exists()


def test_a_looping_program_without_frames_names_its_file(tmp_path):
    animation = Path(__file__).resolve().parents[2] / "programs" / "animation.asm"
    r = _run(animation, "-o", tmp_path / "f.png")
    assert r.exit_code == 1 and r.output.startswith(
        f"rend3r: error: {animation}: address 52 (0x0034): the program loops (lr); pass --frames N"), r.output


@pytest.mark.parametrize("name", ["s.rdr", "s.s", "s.r3"])
def test_source_is_recognised_by_every_source_suffix(tmp_path, name):
    (tmp_path / name).write_text(SRC)
    r = _run(tmp_path / name, "-o", tmp_path / "f.png", "--size", "8x6")
    assert r.exit_code == 0, r.output


@pytest.mark.parametrize("name, data, what", [
    ("x.png", b"\x89PNG\r\n\x1a\n" + bytes(20), "a PNG image"),
    ("x.mem", b"\xff\xd8\xff\xdb" + bytes(20), "a JPEG image"),
    ("x", b"GIF89a" + bytes(20), "a GIF image"),
    ("x.asm", b"PK\x03\x04" + bytes(20), "a ZIP archive"),
])
def test_pictures_and_archives_are_refused_by_name(tmp_path, name, data, what):
    (tmp_path / name).write_bytes(data)
    r = _run(tmp_path / name, "-o", tmp_path / "f.png", "--size", "8x6")
    assert r.exit_code == 1 and r.output == (f"rend3r: error: {tmp_path / name} is {what}, "
                                             "not a REND3R program (source or memory image)\n")


def test_program_without_nf(tmp_path):
    src = tmp_path / "n.asm"
    src.write_text("nr\ner\n")
    r = _run(src, "-o", tmp_path / "f.png")
    assert r.exit_code == 1 and "no frame" in r.output


def test_help_shows_an_example():
    r = _run("--help")
    assert r.exit_code == 0 and "rend3r emulate programs/sphere.asm -o sphere.png" in r.output


# --- hypothesis: emulate's command-line values (fixed budget) ---

from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from rend3r.cliutil import parse_size  # noqa: E402

SMALL = st.integers(0, 40).map(str)
HUGE = st.sampled_from(["8193", "99999999999999999999", "1" * 5000, "-1", "0x10", "1e3", "１２", ""])
PUNCT = st.sampled_from(list("{}[]:!.,x/\\ %~$*"))
SIZES = st.one_of(st.builds(lambda w, s, h: w + s + h, SMALL | HUGE, st.sampled_from(["x", "X", " x ", ",", ""]),
                            SMALL | HUGE), st.text(max_size=12))
PATTERNS = st.lists(st.sampled_from(["f", "_", "{n}", "{n:03}", "{n:032}", "{n:033}", "{n[0]}", "{n:999999999}",
                                     "{}", "{0}", "{{", "}}", "{n!r}", "{n:>9}", "{n.real}", "{", "}", "sub/", "..",
                                     "f" * 120, "\x00", "é"]) | PUNCT, min_size=1, max_size=6).map("".join)
PIXELS = st.builds(lambda x, s, y: x + s + y, SMALL | HUGE, st.sampled_from([",", ";", ", ", ",,"]), SMALL | HUGE)
COLOURS = st.one_of(st.integers(-5, 0x1FFFF).map(hex), st.text(max_size=8), HUGE)


def _small_enough(size: str) -> bool:
    try:
        w, h = parse_size(size)
    except ValueError:
        return True  # refused before any work
    return w * h <= 4096


OPTIONS = {"--size": SIZES, "-o": PATTERNS, "--depth-image": PATTERNS, "--provenance": PATTERNS,
           "--trace-pixel": PIXELS, "--background": COLOURS}


@settings(max_examples=100, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.data(), which=st.sampled_from(sorted(OPTIONS)))
def test_fuzz_option_values_exit_0_1_or_2_and_leave_nothing_on_failure(tmp_path, data, which):
    """One option takes a hostile value, the others a valid one."""
    value = data.draw(OPTIONS[which])
    src = tmp_path / "s.asm"
    src.write_text(SRC)
    root = tmp_path / "w"  # a pattern climbs out of out at most three levels ("../../..")
    out = root / "x" / "y" / "out"
    for old in sorted(root.rglob("*"), reverse=True):
        old.unlink() if old.is_file() else old.rmdir()
    out.mkdir(parents=True)
    if which in ("-o", "--depth-image", "--provenance"):
        value = f"{out}/{value}{'.npy' if which == '--depth-image' else '.png'}"
    if which == "--size" and not _small_enough(value):
        value = "8x6"
    given_ = {"-o": f"{out}/f.png", "--size": "8x6", "--trace-pixel": "1,1", "--background": "0x001F", which: value}
    args = [x for opt, v in given_.items() for x in (opt, v)]
    r = _run(src, *args, "--trace", out / "t.jsonl", "--frames", 1)
    assert r.exception is None or isinstance(r.exception, SystemExit), repr(r.exception)
    assert r.exit_code in (0, 1, 2)
    written = [p for p in root.rglob("*") if p.is_file()]
    if r.exit_code:
        assert "rend3r: error: " in r.output or "Error: " in r.output, r.output
        assert written == [] and list(out.iterdir()) == [], written
    else:
        assert len(written) >= 2 and not [p for p in written if p.name.startswith(".rend3r-")]
