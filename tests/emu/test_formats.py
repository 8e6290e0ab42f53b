"""Working precisions beyond fp16, fp32 and fp64: any binary format eEmM, from the command
line to the format kernels (csrc/fformat.h) and traces. The kernels' pixels are compared
with the reference renderer in test_engine_vs_reference.py."""

from __future__ import annotations

import json

import numpy as np
import pytest
from click.testing import CliRunner

from rend3r.cli import main
from rend3r.emu.arith import make_arith, precision_name
from rend3r.emu.loader import load_program
from rend3r.emu.options import EmuOptions
from rend3r.emu.run import run_program

from .scenes import ONE_SPHERE


@pytest.mark.parametrize("name, canonical", [("fp16", "fp16"), ("e5m10", "fp16"), ("E8M23", "fp32"), ("e11m52", "fp64"),
                                             ("bf16", "e8m7"), ("tf32", "e8m10"), ("fp24", "e7m16"), ("e4m3", "e4m3")])
def test_precision_names_are_canonical(name, canonical):
    """fp16, fp32 and fp64 keep their own kernels under any spelling; aliases become eEmM."""
    assert precision_name(name) == canonical


@pytest.mark.parametrize("name", ["e1m3", "e12m3", "e5m0", "e5m53", "fp8", "e5m10-ieee", "", "e" + "9" * 5000 + "m3"])
def test_bad_precision_names_say_what_is_wrong(name):
    with pytest.raises(ValueError) as err:
        precision_name(name)
    assert len(str(err.value)) < 300  # a hostile name is quoted short, never converted to a huge int


def test_bits_are_the_format_encoding():
    bf16 = make_arith("bf16", "ieee")
    assert [bf16.bits(v)[0] for v in (1.0, -2.0, 3.0, 2.0**-133, np.inf, np.nan)] == [
        0x3F80, 0xC000, 0x4040, 0x0001, 0x7F80, 0x7FC0]
    e4m3 = make_arith("e4m3", "ieee")
    assert e4m3.bits(240.0) == (0x77, 2) and e4m3.bits(-0.0) == (0x80, 2) and e4m3.bits(2.0**-9) == (0x01, 2)
    assert make_arith("fp16").bits(1.0) == (0x3C00, 4)


def test_formats_round_inputs_and_results():
    """bf16 keeps 8 significant bits: the scene's float16 values and every result round."""
    ar = make_arith("bf16")
    assert float(ar.from_bits(0x3C01)) == 1.0  # 1 + 2**-10 in float16
    assert float(ar.add(ar.const(1.0), ar.const(2.0**-8))) == 1.0  # a tie: to even
    assert float(ar.add(ar.const(1.0), ar.const(3 * 2.0**-9))) == 1.0078125


def test_a_format_renders_differently_from_fp16_and_fp32(tmp_path):
    """A lit sphere in e4m3 (3 fraction bits): bands of shading neither fp16 nor fp32 draws."""
    src = tmp_path / "s.asm"
    src.write_text(ONE_SPHERE)
    words = load_program(str(src)).words
    frames = {p: run_program(words, EmuOptions(precision=p, width=64, height=48)).frames[0].rgb565
              for p in ("e4m3", "fp16", "fp32")}
    assert not (frames["e4m3"] == frames["fp16"]).all() and not (frames["e4m3"] == frames["fp32"]).all()
    assert len(np.unique(frames["e4m3"])) < len(np.unique(frames["fp32"]))


def test_the_command_line_takes_formats(tmp_path):
    src = tmp_path / "s.asm"
    src.write_text(ONE_SPHERE)
    out = tmp_path / "s.png"
    run = CliRunner().invoke(main, ["emulate", str(src), "-o", str(out), "--precision", "bf16", "--size", "32x24",
                                    "--trace-pixel", "16,12"])
    assert run.exit_code == 0, run.output
    assert out.exists()
    values = [r for r in map(json.loads, run.output.splitlines()) if isinstance(r["dec"], float)]  # not counts
    assert values and all(len(r["hex"]) == 6 for r in values)  # 0x + four digits: 16-bit bf16
    bad = CliRunner().invoke(main, ["emulate", str(src), "-o", str(out), "--precision", "e1m3"])
    assert bad.exit_code == 2 and "exponent bits 1" in bad.output


def test_tininess_before_rounding_flushes_the_boundary():
    """(2^-7 - 2^-18) * 2^-7 = 2^-14 - 2^-25: rounds up to 2^-14 (0400) judged after rounding,
    flushes (0000) judged before, the device quirk tiny-before-rounding."""
    a, b = 2.0**-7 - 2.0**-18, 2.0**-7
    after, before = make_arith("fp16", "ftz"), make_arith("fp16", "ftz", "before")
    assert after.bits(after.mul(after.const(a), after.const(b)))[0] == 0x0400
    assert before.bits(before.mul(before.const(a), before.const(b)))[0] == 0x0000
    assert after.native and not before.native and make_arith("fp16", "ieee", "before").native


def test_the_quirk_is_named_but_not_in_the_profile(tmp_path):
    from rend3r.emu.quirks import PROFILES, QUIRKS

    assert "tiny-before-rounding" in QUIRKS and "tiny-before-rounding" not in PROFILES["rend3r-2022"]
    src = tmp_path / "s.asm"
    src.write_text(ONE_SPHERE)
    run = CliRunner().invoke(main, ["emulate", str(src), "-o", str(tmp_path / "s.png"), "--size", "32x24",
                                    "--device-quirk", "tiny-before-rounding"])
    assert run.exit_code == 0, run.output
