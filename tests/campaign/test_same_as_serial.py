"""explore and render-all write the same bytes on the local Dask cluster as serially."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from click.testing import CliRunner

from rend3r.campaign.runner import dask_installed
from rend3r.cli import main

pytestmark = pytest.mark.skipif(not dask_installed(),
                                reason="Dask distributed is not installed (pip install 'rend3r[campaign]')")

PROGRAMS = Path(__file__).parents[2] / "programs"


def files(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir())}


def test_explore(tmp_path):
    args = [str(PROGRAMS / n) for n in ("sphere.asm", "tri_cube.asm", "hybrid.asm", "animation.asm")]
    outputs = {}
    for scheduler in ("none", "local"):
        r = CliRunner().invoke(main, ["explore", *args, "-o", str(tmp_path / scheduler), "--size", "24x18",
                                      "--formats", "e4m3,e5m6,bf16,fp32", "--scheduler", scheduler])
        assert r.exit_code == 0, r.output
        outputs[scheduler] = files(tmp_path / scheduler)
    assert list(outputs["local"]) == ["pareto.svg", "results.csv", "summary.md"]
    assert outputs["local"] == outputs["none"]


def test_render_all(tmp_path):
    src = tmp_path / "programs"
    src.mkdir()
    for name in ("sphere.asm", "animation.asm", "tri_overlap.asm", "lights.asm"):
        shutil.copy(PROGRAMS / name, src / name)
    (src / "broken.asm").write_text("; broken.asm\nsp 0, nosuchprop, 1\nnf\ner\n")
    outputs = {}
    for scheduler in ("none", "local"):
        r = CliRunner().invoke(main, ["render-all", str(src), "-o", str(tmp_path / scheduler), "--size", "40x30",
                                      "--scheduler", scheduler])
        assert r.exit_code == 1 and "[2/5] broken: FAILED" in r.output and "nosuchprop" in r.output, r.output
        outputs[scheduler] = files(tmp_path / scheduler)
    assert len(outputs["local"]) == 8 + 3
    assert outputs["local"] == outputs["none"]


def test_a_failing_task_writes_nothing(tmp_path):
    empty = tmp_path / "empty.asm"
    empty.write_text("nr\ner\ner\n")
    out = tmp_path / "o" / "deeper"
    r = CliRunner().invoke(main, ["explore", str(PROGRAMS / "sphere.asm"), str(empty), "-o", str(out),
                                  "--size", "8x6", "--formats", "e4m3", "--scheduler", "local"])
    assert (r.exit_code, r.output) == (1, ("rend3r: error: empty in fp64: empty: rendered no frame "
                                           "(no nf before the program ends)\n"))
    assert not (tmp_path / "o").exists()
