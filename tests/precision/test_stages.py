"""Per-stage formats: the stage map, the compiled format kernels against the Python reference
(random scenes, random formats per stage), the converter between stages against exact
arithmetic, and traces in each stage's format."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rend3r.emu.arith import make_arith
from rend3r.emu.options import EmuOptions
from rend3r.emu.raytracer import render_frame
from rend3r.emu.trace import trace_raytrace
from rend3r.precision.formats import parse
from rend3r.precision.stages import STAGES, VALUE_STAGES, parse_stage_map
from tests.emu.test_engine_vs_reference import (
    assert_same,
    check,
    program,
    scene_args,
    scene_of,
)
from tests.precision.reference import round_exact, rounder

ROOT = Path(__file__).resolve().parents[2]
#: Formats a stage may take: the native three, and format-kernel formats with narrow and
#: wide exponents and fractions both sides of the double-rounding limit.
STAGE_FORMATS = ["fp16", "fp32", "fp64", "bf16", "e4m3", "e5m7", "e6m9", "tf32", "fp24", "e8m30", "e11m51"]
stage_map = st.dictionaries(st.sampled_from(STAGES), st.sampled_from(STAGE_FORMATS), min_size=1, max_size=5)


def staged(base: str, stages: dict[str, str], subnormals: str = "ftz", **kw) -> EmuOptions:
    order = tuple((s, stages[s]) for s in STAGES if s in stages)
    return EmuOptions(precision=base, stage_precision=order, subnormals=subnormals, width=24, height=18, **kw)


def test_the_kernels_stage_enum_is_the_stage_list():
    header = (ROOT / "rend3r/emu/csrc/fformat.h").read_text()
    names = re.search(r"enum \{ (STAGE_CAMERA.*?) \};", header, re.DOTALL)[1].replace("\n", " ").split(",")
    assert [n.strip() for n in names] == [f"STAGE_{s.upper()}" for s in STAGES] + ["STAGE_COUNT"]
    assert set(VALUE_STAGES.values()) == set(STAGES) - {"camera"}  # camera values are not traced


def test_stage_map_parsing():
    assert parse_stage_map("lighting=fp16, discriminant=e8m15") == (("discriminant", "e8m15"), ("lighting", "fp16"))
    assert parse_stage_map("sqrt=e5m10,hit=e8m23") == (("sqrt", "fp16"), ("hit", "fp32"))
    for text, message in [("disc=fp16", "unknown stage 'disc'"), ("sqrt", "expected STAGE=FORMAT"),
                          ("sqrt=fp16,sqrt=fp32", "given twice"), ("sqrt=e12m3", "exponent bits 12"),
                          ("sqrt=fp16-ieee", "--subnormals"), (",", "expected STAGE=FORMAT"),
                          ("x" * 1000, "at most 400")]:
        with pytest.raises(ValueError, match=re.escape(message)):
            parse_stage_map(text)


def test_a_uniform_map_is_the_working_precision():
    every = tuple((s, "fp16") for s in STAGES)
    assert make_arith("fp16", "ftz", "after", every) == make_arith("fp16")
    assert make_arith("fp16", "ftz", "after", every).native
    assert make_arith("fp32", "ftz", "after", (("sqrt", "e8m23"),)) == make_arith("fp32")
    assert make_arith("fp16", "ftz", "after", (("sqrt", "fp32"),)).stages == (("sqrt", "fp32"),)


@settings(max_examples=100, derandomize=True, deadline=None)
@given(*scene_args[:-1], st.sampled_from(STAGE_FORMATS), stage_map, st.sampled_from(["ftz", "ieee"]))
def test_random_scenes_with_random_stage_formats(cam, lights, shapes, ties, base, stages, subnormals):
    """The format kernels (per-stage map) against the reference's staged numpy: the same
    pixels, depth bits and provenance, on one thread and on several bands."""
    options = staged(base, stages, subnormals)
    check(program(cam, lights, shapes, ties, options), options)


#: formats of few and many exponent bits: shapes are culled in every one
CULLED = ["fp16", "e6m9", "fp24", "fp32", "fp64", "bf16", "tf32", "e8m16", "e8m30", "e11m51"]


@settings(max_examples=60, derandomize=True, deadline=None)
@given(st.integers(2, 5), st.integers(1, 3), st.floats(0.03, 0.12), st.floats(2, 12), st.sampled_from(CULLED),
       st.dictionaries(st.sampled_from(STAGES), st.sampled_from(CULLED), min_size=1, max_size=9))
def test_culled_walls_with_stage_formats(g, k, size, distance, base, stages):
    """Many spheres in front of each other, culled (bounds with the staged unit roundoff,
    smallest normal and overflow threshold): still the reference's frame,
    with tests skipped where the bounds apply (bf16's staged roundoff is too coarse)."""
    cam = {"xloc": 0, "yloc": 0, "zloc": 0, "rot": (0, 0, 0, 0), "hfov": 0x3666, "vfov": 0x3666, "nclip": 0, "fclip": 0}
    lights = [{"src": 2, "xloc": 0x4000, "yloc": 0x4000, "zloc": 0x3C00, "int": 0x3C00}]
    shapes = [{"type": 1, "col": 0x1234 * (i + 1) & 0xFFFF, "rot": (0x3C00, 0, 0, 0), "stretch": (1.0, 1.0, 1.0),
               "special": None, "aim": (0.5 + ((i % g) - (g - 1) / 2) / (g + 1),
                                        0.5 + ((i // g % g) - (g - 1) / 2) / (g + 1),
                                        distance * (1 + 0.15 * (i // (g * g))), size)} for i in range(g * g * k)]
    options = staged(base, stages)
    words = program(cam, lights, shapes, [], options)
    check(words, options)
    if options.arith.stages and options.arith.unit_roundoff <= 2.0**-12:
        _, stats = render_frame(scene_of(words, options), options)
        assert stats.skipped > 0


@settings(max_examples=30, derandomize=True, deadline=None)
@given(*scene_args[:-1], st.sampled_from([("fp32", "fp16"), ("fp64", "fp32"), ("fp16", "bf16"), ("e6m9", "fp64")]))
def test_every_stage_in_one_format_is_that_format(cam, lights, shapes, ties, formats):
    """A map that puts every stage in another format than the base renders as that format
    uniformly (its own kernels for fp16, fp32, fp64): every operation has its stage, and
    converting scene values at each use equals rounding them once on loading."""
    base, every = formats
    options = staged(base, dict.fromkeys(STAGES, every))
    assert options.arith.stages  # the map differs from the base: the staged path runs
    scene = scene_of(program(cam, lights, shapes, ties, options), options)
    uniform, _ = render_frame(scene, replace(options, precision=every, stage_precision=()))
    engine, _ = render_frame(scene, options)
    assert_same(uniform, engine)


def _records(options: EmuOptions, cam, lights, shapes) -> list[dict]:
    scene = scene_of(program(cam, lights, shapes, [], options), options)
    out: list[dict] = []
    trace_raytrace(scene, options, 0, [(12, 9)], out.append)
    return out


@settings(max_examples=60, derandomize=True, deadline=None)
@given(scene_args[0], scene_args[1], scene_args[2], st.sampled_from(STAGE_FORMATS),
       st.sampled_from(STAGE_FORMATS), st.sampled_from(["ftz", "ieee"]))
def test_converter_and_discriminant_against_exact_arithmetic(cam, lights, shapes, quad, disc, subnormals):
    """disc = b*b - a2*c2 of the compiled kernels' trace, with b, a2, c2 computed in the
    quadratic stage's format and converted into the discriminant stage's: each operand
    rounded once to the discriminant's format, each operation exact and rounded once
    (Python integers, tests/precision/reference.py)."""
    options = staged("fp64", {"quadratic": quad, "discriminant": disc}, subnormals)
    fmt = options.arith.stage_formats.get("discriminant", options.arith.format)
    rnd = rounder(fmt)

    def rounded(n: int, d: int, negative: bool) -> float:  # n/d (d > 0) rounded once
        v = round_exact(fmt, rnd, abs(n), d, negative)
        return v if abs(v) <= fmt.max else np.copysign(np.inf, v)  # the reference's 2**(emax+1) is infinity

    def rn(x: float) -> float:  # the converter
        return rounded(*abs(x).as_integer_ratio(), bool(np.signbit(x)))

    def op(a: float, b: float, f) -> float:
        (na, da), (nb, db) = a.as_integer_ratio(), b.as_integer_ratio()
        n, d = f(na, da, nb, db)
        return rounded(n, d, n < 0)

    mul = lambda na, da, nb, db: (na * nb, da * db)  # noqa: E731
    sub = lambda na, da, nb, db: (na * db - nb * da, da * db)  # noqa: E731
    values: dict[tuple, float] = {}
    for r in _records(options, cam, lights, shapes):
        if r["shape"] is not None and r["stage"] in ("a2", "b", "c2", "disc"):
            values[r["shape"], r["stage"]] = float(r["dec"])
    for shape in {k[0] for k in values}:
        ins = [values[shape, n] for n in ("a2", "b", "c2")]
        if not all(np.isfinite(ins)):
            continue
        a2, b, c2 = (rn(v) for v in ins)
        m1, m2 = (op(b, b, mul), op(a2, c2, mul)) if np.isfinite([a2, b, c2]).all() else (np.inf, np.inf)
        if np.isfinite(m1) and np.isfinite(m2):
            assert values[shape, "disc"] == op(m1, m2, sub), (shape, values[shape, "disc"], op(m1, m2, sub))


def test_trace_shows_each_value_in_its_stage_format(tmp_path):
    trace = tmp_path / "t.jsonl"
    done = subprocess.run([sys.executable, "-m", "rend3r", "emulate", str(ROOT / "programs/shadow.asm"),
                           "-o", str(tmp_path / "f.png"), "--size", "64x48", "--stage-precision",
                           "discriminant=fp32,lighting=fp64", "--trace-pixel", "32,24", "--trace", str(trace)],
                          capture_output=True, text=True, timeout=120, cwd=ROOT, check=False)
    assert done.returncode == 0, done.stderr
    widths = {}
    for line in trace.read_text().splitlines():
        r = json.loads(line)
        if r["stage"] in ("b", "disc", "sq_dist") or r["stage"].endswith(".cos"):
            widths[r["stage"].split(".")[-1]] = len(r["hex"]) - 2
    assert widths == {"b": 4, "disc": 8, "sq_dist": 4, "cos": 16}


def test_bad_stage_precision_is_a_usage_error(tmp_path):
    done = subprocess.run([sys.executable, "-m", "rend3r", "emulate", str(ROOT / "programs/shadow.asm"),
                           "-o", str(tmp_path / "f.png"), "--stage-precision", "shading=fp16"],
                          capture_output=True, text=True, timeout=60, cwd=ROOT, check=False)
    assert done.returncode == 2
    assert "unknown stage 'shading'" in done.stderr and "Traceback" not in done.stderr


def test_every_stage_is_costed_from_its_own_counts():
    from rend3r.precision.datapath import raytrace_counts

    counts = raytrace_counts()
    assert set(counts.stages) == set(STAGES)
    fp16 = parse("fp16")
    for stage in STAGES:
        assert counts.cost(fp16, {stage: parse("fp32")}).lut > counts.cost(fp16).lut, stage


def test_render_all_takes_stage_formats(tmp_path):
    """render-all renders with the map: the same PNG as emulate with it, another than without."""
    from click.testing import CliRunner

    from rend3r.cli import main

    src = tmp_path / "src"
    src.mkdir()
    (src / "shadow.asm").write_text((ROOT / "programs/shadow.asm").read_text())
    runs = {}
    for name, extra in (("staged", ["--stage-precision", "discriminant=e5m3,hit=e4m3"]), ("plain", [])):
        r = CliRunner().invoke(main, ["render-all", str(src), "-o", str(tmp_path / name), "--size", "32x24",
                                      "--scheduler", "none", "--quiet", *extra])
        assert r.exit_code == 0, r.output
        runs[name] = (tmp_path / name / "shadow.png").read_bytes()
    r = CliRunner().invoke(main, ["emulate", str(src / "shadow.asm"), "-o", str(tmp_path / "e.png"), "--size", "32x24",
                                  "--stage-precision", "discriminant=e5m3,hit=e4m3", "--quiet"])
    assert r.exit_code == 0, r.output
    assert runs["staged"] == (tmp_path / "e.png").read_bytes() != runs["plain"]
