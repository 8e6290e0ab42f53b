"""rend3r emulate: --depth rules, --profile / --device-quirk, --trace-pixel / --trace."""

import json

import numpy as np
import pytest
from click.testing import CliRunner

from rend3r.cli import main

SPHERE = """\
nr
lt 0, src, 1
lt 0, xfor, 1
lt 0, yfor, 1
sp 0, type, col, 1, 0xFFFF
sp 0, zloc, rrot, -2, 1
sp 0, xscl, yscl, 1, 1
sp 0, zscl, zero, 1, 0
nf
er
er
"""

# Two crossing triangles: the z-buffer splits them, the painter paints the nearer centroid last.
TRIS = """\
nr
cam hfov, 0.2
cam vfov, 0.2
tr 0, x1, y1, -2, -1
tr 0, z1, x2, -3, 2
tr 0, y2, z2, -1, -5
tr 0, x3, y3, 0, 1.5
tr 0, z3, col, -4, 0xF800
tr 1, x1, y1, -2, -1
tr 1, z1, x2, -5, 2
tr 1, y2, z2, -1, -3
tr 1, x3, y3, 0, 1.5
tr 1, z3, col, -4.2, 0x07E0
nf
er
"""


def _run(*args):
    return CliRunner().invoke(main, ["emulate", *map(str, args)])


@pytest.fixture
def files(tmp_path):
    (tmp_path / "sphere.asm").write_text(SPHERE)
    (tmp_path / "tris.asm").write_text(TRIS)
    return tmp_path


def test_depth_rules_in_raster_mode(files):
    prov = {}
    for rule in ("zbuffer", "painter"):
        out = files / f"{rule}.npy"
        r = _run(files / "tris.asm", "-o", files / f"{rule}.png", "--depth", rule, "--provenance", out, "--size", "40x30")
        assert r.exit_code == 0, r.output
        prov[rule] = np.load(out)
    assert set(np.unique(prov["zbuffer"])) == {-1, 0, 1}
    assert (prov["painter"] != prov["zbuffer"]).any()


def test_depth_takes_only_a_visibility_rule(files):
    r = _run(files / "sphere.asm", "-o", files / "s.png", "--depth", files / "d.npy", "--size", "32x24")
    assert r.exit_code == 2 and "zbuffer" in r.output
    r = _run(files / "sphere.asm", "-o", files / "s.png", "--depth-image", files / "d.npy", "--size", "32x24")
    assert r.exit_code == 0, r.output
    assert np.isfinite(np.load(files / "d.npy")).any()


def test_profile_and_single_quirks(files):
    r = _run(files / "sphere.asm", "-o", files / "p.png", "--profile", "rend3r-2022", "--provenance", files / "p.npy")
    assert r.exit_code == 0, r.output
    prov = np.load(files / "p.npy")
    assert prov.shape == (384, 512) and prov[192, 256] == 0  # device camera sees the sphere at the centre
    r = _run(files / "sphere.asm", "-o", files / "q.png", "--device-quirk", "device-camera", "--device-quirk", "rgb444-display")
    assert r.exit_code == 0, r.output
    r = _run(files / "sphere.asm", "-o", files / "q.png", "--device-quirk", "warp-drive")
    assert r.exit_code == 1 and "unknown device quirk 'warp-drive'" in r.output and "Traceback" not in r.output


@pytest.mark.parametrize("args, says", [
    (["--profile", "rend3r-2022", "--subnormals", "ieee"],
     "--subnormals ieee contradicts --profile rend3r-2022 (quirk flush-subnormals)"),
    (["--device-quirk", "flush-subnormals", "--subnormals", "ieee"],
     "--subnormals ieee contradicts --device-quirk flush-subnormals"),
    (["--profile", "rend3r-2022", "--depth", "painter"],
     "--depth painter contradicts --profile rend3r-2022 (quirk raster-index-order)"),
    (["--device-quirk", "raster-index-order", "--depth", "zbuffer"],
     "--depth zbuffer contradicts --device-quirk raster-index-order"),
])
def test_an_explicit_option_contradicting_a_quirk_is_a_usage_error(files, args, says):
    r = _run(files / "sphere.asm", "-o", files / "c.png", "--size", "32x24", *args)
    assert r.exit_code == 2 and says in r.output, r.output
    assert not (files / "c.png").exists()


def test_explicit_options_that_agree_with_the_profile_run(files):
    r = _run(files / "sphere.asm", "-o", files / "a.png", "--size", "32x24", "--profile", "rend3r-2022",
             "--subnormals", "ftz", "--precision", "fp64")
    assert r.exit_code == 0, r.output


def test_trace_to_stdout_and_file_match_the_worked_vector(files):
    args = [files / "sphere.asm", "-o", files / "t.png", "--device-quirk", "device-camera",
            "--device-quirk", "light0-only", "--trace-pixel", "252,188"]
    r = _run(*args)
    assert r.exit_code == 0, r.output
    recs = [json.loads(line) for line in r.output.splitlines()]
    by_stage = {x["stage"]: x for x in recs}
    assert by_stage["a2"]["hex"] == "0x4009" and by_stage["L0.cos"]["hex"] == "0x2e22"
    r = _run(*args, "--trace", files / "t.jsonl", "--trace-pixel", "256,192")
    assert r.exit_code == 0 and r.output == ""
    lines = (files / "t.jsonl").read_text().splitlines()
    assert {tuple(json.loads(x)["pixel"]) for x in lines} == {(252, 188), (256, 192)}
    d = CliRunner().invoke(main, ["trace-diff", str(files / "t.jsonl"), str(files / "t.jsonl")])
    assert d.exit_code == 0


@pytest.mark.parametrize("args, message", [
    (["--trace-pixel", "600,10"], "outside the 512x384 frame"),
    (["--trace-pixel", "1;2"], "expected X,Y"),
    (["--trace", "x.jsonl"], "needs at least one --trace-pixel"),
    (["--trace-pixel", "1,2", "--mode", "hybrid"], "hybrid frames have no trace"),
])
def test_trace_option_errors(files, args, message):
    r = _run(files / "sphere.asm", "-o", files / "e.png", *args)
    assert r.exit_code == 1 and message in r.output, r.output


def test_raster_trace_lists_projection_steps_and_the_frame_pixel(files):
    r = _run(files / "tris.asm", "-o", files / "r.png", "--size", "40x30", "--trace-pixel", "20,15",
             "--provenance", files / "r.npy")
    assert r.exit_code == 0, r.output
    recs = [json.loads(line) for line in r.output.splitlines()]
    stages = [x["stage"] for x in recs if x["shape"] == 0]
    assert stages[:3] == ["cam.v1.x", "cam.v1.y", "cam.v1.z"] and "v3.px.y" in stages and "n.z" in stages
    last = {x["stage"]: x for x in recs if x["shape"] is None or x["stage"] in ("nearest", "colour", "depth")}
    assert last["nearest"]["dec"] == int(np.load(files / "r.npy")[15, 20])
    px = [x for x in recs if x["shape"] == 0 and x["stage"] == "v1.px.x"][0]
    # v1 = (-2, -1, -3): s = 1*(-2)/3, ndc = s/(10*0.2) + 0.5, px = ndc*40, each rounded to float16
    h = np.float16
    s = h(h(h(1) * h(-2)) / h(3))
    want = h(h(h(s / h(2.0)) + h(0.5)) * h(40))
    assert px["dec"] == float(want)
