"""Pixel traces: the worked device vectors, agreement with the frame, the JSON schema."""

import io
import math

import numpy as np
import pytest

from rend3r.emu.arith import make_arith
from rend3r.emu.options import EmuOptions
from rend3r.emu.processor import execute
from rend3r.emu.raytracer import render_frame
from rend3r.emu.scene import Scene
from rend3r.emu.trace import encode, jsonl_sink, trace_raytrace
from rend3r.emu.trace_diff import first_divergence, parse_record

from .scenes import Prog

DEVICE = EmuOptions(camera="device", light_model="device")
WORKED = Prog().nr().sphere(0, loc=(0.0, 0.0, -2.0), col=0xFFFF).light(0, src=1, xfor=1, yfor=1, zfor=0).nf().er()


def _records(words, options, pixels):
    scene = Scene()
    execute(words, options, scene=scene)
    out = []
    trace_raytrace(scene, options, 0, pixels, out.append)
    return scene, out


def _stage(records, pixel, stage):
    (r,) = [r for r in records if r["pixel"] == list(pixel) and r["stage"] == stage]
    return r


def test_worked_vectors_bit_for_bit():
    _, recs = _records(WORKED.words, DEVICE, [(256, 192), (252, 188)])
    want = {
        (256, 192): dict(a2="0x4000", b="0xc400", c2="0x4600", disc="0x4400", sqrt="0x4000",
                         t1="0x3c00", t2="0x4200", t="0x3c00", sq_dist="0x3c00"),
        (252, 188): dict(a2="0x4009", b="0xc400", c2="0x4600", t="0x3c05", sq_dist="0x3c13"),
    }
    for pixel, stages in want.items():
        for stage, hx in stages.items():
            assert _stage(recs, pixel, stage)["hex"] == hx, (pixel, stage)
    assert _stage(recs, (252, 188), "L0.cos")["hex"] == "0x2e22"
    assert _stage(recs, (256, 192), "L0.cos")["dec"] < 0
    assert _stage(recs, (256, 192), "colour")["dec"] == 0  # I negative: black
    assert _stage(recs, (256, 192), "nearest")["dec"] == 0


def test_stage_order_follows_the_device():
    _, recs = _records(WORKED.words, DEVICE, [(252, 188)])
    stages = [r["stage"] for r in recs]
    per_shape = ["origin.x", "origin.y", "origin.z", "dir.x", "dir.y", "dir.z", "a2", "b", "c2", "disc", "sqrt",
                 "t1", "t2", "t", "hit", "sq_dist", "point.x", "point.y", "point.z", "normal.x", "normal.y", "normal.z"]
    assert stages[: len(per_shape)] == per_shape
    assert stages[len(per_shape)] == "nearest" and stages[-1] == "colour"
    assert stages.index("L0.cos") > stages.index("L0.n_dot_l")


def test_trace_colour_is_the_frame_pixel_with_shadows_lights_and_misses():
    prog = (Prog().nr().cam(xloc=0.3)
            .sphere(0, loc=(0.0, 0.0, -4.0), col=0xFFFF)
            .sphere(1, loc=(1.0, 1.2, -2.5), scale=(2.5, 2.5, 2.5), col=0x07E0)
            .shape(2, type=2, col=0x001F, xloc=-2.0, zloc=-5.0, rrot=1.0, xscl=2.0, yscl=2.0, zscl=1.0)
            .dir_light(0, forward=(-0.6, -0.8, -0.5)).dir_light(3, forward=(0.5, 0.1, -1.0), col=0xF81F, intensity=0.5)
            .nf().er())
    opts = EmuOptions(width=64, height=48)
    pixels = [(x, y) for x in range(0, 64, 9) for y in range(0, 48, 7)] + [(33, 21)]  # (33, 21) is in shadow
    scene, recs = _records(prog.words, opts, pixels)
    frame, _ = render_frame(scene, opts)
    for x, y in pixels:
        assert _stage(recs, (x, y), "colour")["dec"] == int(frame.rgb565[y, x]), (x, y)
        assert _stage(recs, (x, y), "nearest")["dec"] == int(frame.provenance[y, x]), (x, y)
    assert any(r["stage"].endswith(".shadow") and r["dec"] == 1 for r in recs)


def test_records_parse_with_the_diff_reader_and_self_compare_equal():
    _, recs = _records(WORKED.words, DEVICE, [(252, 188)])
    buf = io.StringIO()
    sink = jsonl_sink(buf)
    for r in recs:
        sink(r)
    lines = buf.getvalue().splitlines()
    parsed = [parse_record(line, "t", n) for n, line in enumerate(lines, 1)]
    assert first_divergence(parsed, parsed) is None
    for r in recs:
        assert set(r) == {"frame", "pixel", "shape", "stage", "hex", "dec"}
        if r["hex"].startswith("0x") and len(r["hex"]) == 6 and isinstance(r["dec"], float):
            assert np.array(int(r["hex"], 16), np.uint16).view(np.float16) == np.float16(r["dec"])


def test_parse_pixel_takes_bounded_decimal_pairs_only():
    from rend3r.emu.trace import parse_pixel

    assert parse_pixel(" 252 , 188 ") == (252, 188) and parse_pixel("-1,5") == (-1, 5)
    for bad in ("1;2", "1,2,3", "", "1" * 5000 + ",1", "١٢,3", "0x10,1", "1e3,1"):
        with pytest.raises(ValueError, match="expected X,Y") as info:
            parse_pixel(bad)
        assert len(str(info.value)) < 100


def test_nearest_is_minus_one_where_lighting_is_not_finite_as_in_the_frame():
    # Radius 200 under ftz: the normal's components (about 1/200) square to subnormals,
    # n.n flushes to 0 and I = n.l / 0 is infinite, so the frame draws the background.
    big = (Prog().nr().cam(nclip=100.0, hfov=0.3, vfov=0.3)
           .sphere(0, loc=(0.0, 0.0, -320.0), scale=(0.005, 0.005, 0.005), col=0xF800)
           .dir_light(0, forward=(0.0, 0.0, -1.0)).nf().er())
    opts = EmuOptions(width=16, height=12)
    pixel = (8, 6)
    scene, recs = _records(big.words, opts, [pixel])
    frame, _ = render_frame(scene, opts)
    assert _stage(recs, pixel, "hit")["dec"] == 1 and _stage(recs, pixel, "L0.n_len")["dec"] == 0
    assert _stage(recs, pixel, "L0.cos")["dec"] == "inf"
    assert frame.provenance[pixel[1], pixel[0]] == -1
    nearest = _stage(recs, pixel, "nearest")
    assert nearest["dec"] == -1 and nearest["shape"] is None
    assert _stage(recs, pixel, "L0.cos")["shape"] == 0  # the light stages still show why
    assert _stage(recs, pixel, "colour")["dec"] == int(frame.rgb565[pixel[1], pixel[0]]) == 0
    ieee, _ = render_frame(scene, EmuOptions(width=16, height=12, subnormals="ieee"))
    assert ieee.provenance[pixel[1], pixel[0]] == 0  # with gradual underflow the sphere is lit


def _encode_one(ar, value, stage):
    """The per-value encoding the bulk one replaced: the oracle."""
    bits, digits = ar.bits(value, stage)
    v = float(value)
    dec = v if math.isfinite(v) else ("nan" if math.isnan(v) else ("inf" if v > 0 else "-inf"))
    return f"0x{bits:0{digits}x}", dec


@pytest.mark.parametrize("ar, stage", [
    (make_arith("fp16"), None), (make_arith("fp16", "ieee"), None), (make_arith("fp32"), None),
    (make_arith("fp64"), None), (make_arith("e8m7"), None), (make_arith("e4m3", "ieee"), None),
    (make_arith("e11m40", "ieee"), None),
    *[(make_arith("fp16", stages=(("quadratic", "e8m7"), ("sqrt", "fp32"), ("hit", "e3m2"))), s)
      for s in (None, "quadratic", "sqrt", "hit", "lighting")],
])
def test_bulk_encoding_equals_the_per_value_one(ar, stage):
    fmt = ar.stage_formats.get(stage or "", ar.format)
    rng = np.random.default_rng(7)
    wide = rng.choice([-1.0, 1.0], 2000) * rng.random(2000) * np.exp2(rng.integers(-1100, 1000, 2000).astype(float))
    near = np.concatenate([wide, rng.normal(0, 4, 500), rng.random(300) * fmt.min_normal * 3])
    special = [np.nan, -np.nan, np.inf, -np.inf, 0.0, -0.0, fmt.min_normal, -fmt.min_normal,
               fmt.min_normal / 2 ** fmt.frac_bits, fmt.max, -fmt.max]
    with np.errstate(all="ignore"):
        values = np.concatenate([fmt.round(near), special])
    arrays = [values] + ([values.astype(np.float32)] if ar.native and ar.precision != "fp64" else [])
    for arr in arrays:
        hexes, decs = encode(ar, arr, stage)
        want = [_encode_one(ar, v, stage) for v in arr]
        assert list(zip(hexes, decs)) == want
        assert decs[-11:-7] == ["nan", "nan", "inf", "-inf"] and int(hexes[-6], 16) == 1 << (fmt.bits - 1)  # -0
