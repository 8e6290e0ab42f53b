"""``svo sweep`` as a campaign: the same tables serially and on the local cluster's worker
processes, and its options."""

from __future__ import annotations

import pytest
from click.testing import CliRunner

from rend3r.campaign.runner import Campaign, dask_installed
from rend3r.cli import main
from rend3r.svo.fileformat import SvoModel
from rend3r.svo.octree import build_octree
from rend3r.svo.sweep import DesignPoint, run_sweep, thesis_points

from .conftest import random_voxels

needs_dask = pytest.mark.skipif(not dask_installed(), reason="Dask distributed is not installed (pip install 'rend3r[campaign]')")


@pytest.fixture(scope="module")
def svo_file(tmp_path_factory):
    d = tmp_path_factory.mktemp("sweep")
    run = CliRunner().invoke
    assert run(main, ["svo", "model", "torus", "-o", str(d / "t.ply"), "--detail", "24"]).exit_code == 0
    assert run(main, ["svo", "build", str(d / "t.ply"), "-o", str(d / "t.svo"), "--depth", "5"]).exit_code == 0
    return d / "t.svo"


class Bars:
    """A progress factory that records each bar's label, total and the units it was told."""

    def __init__(self) -> None:
        self.seen: list[list] = []

    def __call__(self, total: int, label: str) -> Bars:
        self.seen.append([label, total, 0])
        return self

    def __enter__(self) -> Bars:
        return self

    def __exit__(self, *exc) -> None:
        pass

    def advance(self, units: int) -> None:
        self.seen[-1][2] += units


def test_serial_rows_and_progress():
    coords = random_voxels(5, 400, 3)
    model = SvoModel(build_octree(coords, 5), (-1.0, -1.0, -1.0, 1.0, 1.0, 1.0), len(coords))
    points = [DesignPoint(s, c, 1, 1, None, cores) for s in (0, 8) for c in (0, 32) for cores in (1, 2)]
    bars = Bars()
    with Campaign("none") as campaign:
        rows = run_sweep(model, points, campaign, 16, 12, views=2, progress=bars, kernel="numpy")
    assert [(r["stack"], r["cache"], r["cores"]) for r in rows] == [(p.stack, p.cache, p.cores) for p in points]
    assert all(r["miss_rate"] == 1.0 for r in rows if r["cache"] == 0)
    # a task per stack depth, then one per (stack, cache) pair: each pair's two core counts in one task
    assert bars.seen == [["tracing", 2, 2], ["simulating", 4, 4]]


@needs_dask
def test_the_local_cluster_writes_the_same_tables_as_serial(svo_file, tmp_path):
    outputs = {}
    for scheduler in ("none", "local"):
        r = CliRunner().invoke(main, ["svo", "sweep", str(svo_file), "-o", str(tmp_path / scheduler), "--size", "20x16",
                                      "--views", "2", "--kernel", "numpy", "--jobs", "2", "--scheduler", scheduler])
        assert r.exit_code == 0, r.output
        assert f"{len(thesis_points())} design points" in r.output
        outputs[scheduler] = [(tmp_path / f"{scheduler}.{ext}").read_bytes() for ext in ("csv", "md")]
    assert outputs["local"] == outputs["none"]


@pytest.mark.parametrize("args, message", [(["--scheduler", "bogus"], "expected local, none or tcp://HOST:PORT"),
                                           (["--jobs", "-1"], "-1 is not in the range 0<=x<=64")])
def test_bad_campaign_options_exit_2(svo_file, tmp_path, args, message):
    r = CliRunner().invoke(main, ["svo", "sweep", str(svo_file), "-o", str(tmp_path / "s"), *args])
    assert r.exit_code == 2 and message in r.output, r.output
    assert not list(tmp_path.iterdir())


def test_sweep_help_names_the_campaign_options():
    page = CliRunner().invoke(main, ["svo", "sweep", "--help"]).output
    assert "--scheduler ADDRESS" in page and "Worker processes of the local cluster" in page
