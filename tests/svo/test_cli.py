import csv

import numpy as np
from click.testing import CliRunner
from PIL import Image

from rend3r.cli import main
from rend3r.svo.fileformat import read_svo
from rend3r.svo.octree import octree_to_voxels


def _run(*args):
    return CliRunner().invoke(main, ["svo", *args], catch_exceptions=False)


def test_model_build_render_sweep(tmp_path):
    mesh, svo, png, cost = (str(tmp_path / n) for n in ("t.stl", "t.svo", "t.png", "c.png"))
    r = _run("model", "torus", "-o", mesh, "--detail", "16")
    assert r.exit_code == 0, r.output
    r = _run("build", mesh, "-o", svo, "--depth", "5", "--ptr-bits", "4", "--binvox", str(tmp_path / "t.binvox"))
    assert r.exit_code == 0 and "far pointers" in r.output
    model = read_svo(svo)
    assert model.tree.depth == 5 and model.tree.far_count() > 0
    r = _run("build", str(tmp_path / "t.binvox"), "-o", str(tmp_path / "b.svo"))
    assert r.exit_code == 0, r.output
    assert np.array_equal(octree_to_voxels(read_svo(str(tmp_path / "b.svo")).tree), octree_to_voxels(model.tree))
    r = _run("render", svo, "-o", png, "--size", "32x24", "--cost", cost, "--stats", "--stack", "0")
    assert r.exit_code == 0 and '"restarts"' in r.output
    img = np.asarray(Image.open(png))
    assert img.shape == (24, 32, 3) and img.any()
    assert np.asarray(Image.open(cost)).max() == 255
    r = _run("sweep", svo, "-o", str(tmp_path / "sw"), "--size", "16x12", "--jobs", "2")
    assert r.exit_code == 0, r.output
    rows = list(csv.DictReader(open(tmp_path / "sw.csv")))
    assert len(rows) > 100 and {"miss_rate", "frame_ms"} <= set(rows[0])
    md = (tmp_path / "sw.md").read_text()
    assert "### 7.1 two-way" in md and "### 8.2 E" in md


def test_hybrid_render(tmp_path):
    mesh, svo, png = (str(tmp_path / n) for n in ("s.obj", "s.svo", "h.png"))
    assert _run("model", "sphere", "-o", mesh, "--detail", "8").exit_code == 0
    assert _run("build", mesh, "-o", svo, "--depth", "4").exit_code == 0
    r = _run("render", svo, "-o", png, "--size", "32x24", "--with-program", "programs/sphere.asm",
             "--place", "0.8,0,-3,0.7")
    assert r.exit_code == 0, r.output
    assert np.asarray(Image.open(png)).shape == (24, 32, 3)


def test_errors(tmp_path):
    bad = tmp_path / "bad.svo"
    bad.write_bytes(b"nope")
    for args in (["render", str(bad), "-o", str(tmp_path / "x.png")],
                 ["build", str(tmp_path / "missing.obj"), "-o", str(tmp_path / "x.svo"), "--depth", "3"],
                 ["render", str(bad), "-o", "x.png", "--place", "0,0,0,1"]):
        r = CliRunner().invoke(main, ["svo", *args])
        assert r.exit_code == 1 and "rend3r: error:" in r.output and "Traceback" not in r.output
    r = CliRunner().invoke(main, ["svo", "render", str(bad), "-o", "x.png", "--size", "0x5"])
    assert r.exit_code == 2


def test_help_has_examples_and_whole_summaries():
    listing = _run("--help").output
    for name in ("model", "build", "render", "sweep"):
        row = next(line for line in listing.splitlines() if line.strip().startswith(name + " "))
        assert not row.endswith("..."), row
        page = _run(name, "--help").output
        assert "Example:\n" in page and f"rend3r svo {name} " in page, name
        assert "-q, --quiet" in page, name
        assert ("-o, --output STEM" if name == "sweep" else "-o, --output FILE") in page, name
    assert "Required for a mesh" in _run("build", "--help").output
    assert "Writes STEM.csv and STEM.md" in _run("sweep", "--help").output


def test_quiet_drops_the_summary_but_not_the_stats(tmp_path):
    mesh, svo = str(tmp_path / "s.obj"), str(tmp_path / "s.svo")
    r = _run("model", "sphere", "-o", mesh, "--detail", "8", "-q")
    assert r.exit_code == 0 and r.output == ""
    r = _run("build", mesh, "-o", svo, "--depth", "4", "--quiet")
    assert r.exit_code == 0 and r.output == "" and read_svo(svo).tree.depth == 4
    r = _run("render", svo, "-o", str(tmp_path / "s.png"), "--size", "8x6", "-q", "--kernel", "numpy")
    assert r.exit_code == 0 and r.output == ""
    r = _run("render", svo, "-o", str(tmp_path / "s.png"), "--size", "8x6", "-q", "--kernel", "numpy", "--stats")
    assert r.exit_code == 0 and '"rays": 48' in r.output
