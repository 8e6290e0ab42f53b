"""Campaigns on an existing cluster: a real ``dask scheduler`` and two ``dask worker``
processes on 127.0.0.1, one of them killed in the middle of a campaign (explore's renders,
svo sweep's traces and simulations)."""

from __future__ import annotations

import re
import shutil
import signal
import subprocess
import sys
import time
from functools import partial
from pathlib import Path

import pytest
from click.testing import CliRunner

from rend3r.campaign.runner import Campaign, dask_installed
from rend3r.cli import main
from rend3r.errors import Rend3rError

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
from dask_cluster import localhost_cluster  # noqa: E402

pytestmark = [
    pytest.mark.skipif(not dask_installed(), reason="Dask distributed is not installed (pip install 'rend3r[campaign]')"),
    pytest.mark.skipif(shutil.which("dask") is None, reason="the dask command (dask scheduler, dask worker) is not on PATH"),
]

PROGRAMS = Path(__file__).parents[2] / "programs"
NAMES = ("sphere.asm", "shadow.asm", "tri_cube.asm", "lights.asm")


@pytest.fixture
def cluster():
    """``(address, processes)``: a scheduler and two one-thread workers without nannies (a
    killed worker stays dead), all stopped at the end."""
    with localhost_cluster(str(Path(__file__).parents[2]), nanny=False) as found:
        yield found


def explore(out: Path, scheduler: str):
    return CliRunner().invoke(main, ["explore", *(str(PROGRAMS / n) for n in NAMES), "-o", str(out),
                                     "--size", "24x18", "--formats", "e4m3,bf16,fp32", "--scheduler", scheduler])


def test_explore_on_an_existing_cluster_matches_serial(tmp_path, cluster):
    address, _ = cluster
    for out, scheduler in ((tmp_path / "serial", "none"), (tmp_path / "tcp", address)):
        r = explore(out, scheduler)
        assert r.exit_code == 0, r.output
    for name in ("results.csv", "pareto.svg", "summary.md"):
        assert (tmp_path / "tcp" / name).read_bytes() == (tmp_path / "serial" / name).read_bytes()


class KillOnce:
    """A progress bar that kills ``process`` when the ``at``-th task has come back."""

    def __init__(self, process: subprocess.Popen, at: int) -> None:
        self.process, self.at, self.done = process, at, 0

    def advance(self, units: int) -> None:
        self.done += units
        if self.done == self.at:
            self.process.send_signal(signal.SIGKILL)
            self.process.wait(timeout=10)


def test_a_worker_killed_mid_campaign_has_its_tasks_rerun(cluster):
    from rend3r.explore.campaign import REFERENCE, render_and_score, render_design
    from rend3r.explore.cli import load_spec

    address, (_, *workers) = cluster
    specs = [load_spec(PROGRAMS / n) for n in NAMES]
    options = {"subnormals": "ftz", "width": 48, "height": 36, "jobs": 1}
    references = [render_design(s, REFERENCE, **options) for s in specs]
    inputs = [(s, f, r) for s, r in zip(specs, references) for f in ("e4m3", "e5m6", "bf16", "e6m9", "fp24", "fp32")]
    names = [f"{s.name} in {f}" for s, f, _ in inputs]
    task = partial(render_and_score, **options)
    serial = [task(*args) for args in inputs]

    bar = KillOnce(workers[0], at=3)
    with Campaign(address) as campaign:
        found = campaign.map(task, inputs, names, bar)
    assert workers[0].returncode == -signal.SIGKILL and workers[1].poll() is None
    assert bar.done == len(inputs)
    assert found == serial


class KillOnceBars(KillOnce):
    """:class:`KillOnce` as the progress factory of a sweep: its bars count on from one to the next."""

    def __call__(self, total: int, label: str) -> KillOnceBars:
        return self

    def __enter__(self) -> KillOnceBars:
        return self

    def __exit__(self, *exc) -> None:
        pass


def test_a_worker_killed_mid_sweep_has_its_tasks_and_traces_recomputed(cluster):
    from rend3r.svo.fileformat import SvoModel
    from rend3r.svo.models import make_model
    from rend3r.svo.octree import build_octree_codes
    from rend3r.svo.sweep import run_sweep, thesis_points
    from rend3r.svo.voxelize import voxelize_codes

    address, (_, *workers) = cluster
    codes, lo, h = voxelize_codes(*make_model("torus", 24), 5, False, 1 << 30)
    model = SvoModel(build_octree_codes(codes, 5), tuple(lo) + tuple(lo + 32 * h), len(codes))
    points = thesis_points()
    with Campaign("none") as campaign:
        serial = run_sweep(model, points, campaign, 24, 18, views=2, kernel="numpy")

    # 5 stack depths traced, then the third simulation back: the killed worker held traces
    bars = KillOnceBars(workers[0], at=5 + 3)
    with Campaign(address) as campaign:
        found = run_sweep(model, points, campaign, 24, 18, views=2, progress=bars, kernel="numpy")
    assert workers[0].returncode == -signal.SIGKILL and workers[1].poll() is None
    assert bars.done == 5 + 76
    assert found == serial


def test_render_all_on_an_existing_cluster_matches_serial(tmp_path, cluster):
    address, _ = cluster
    src = tmp_path / "programs"
    src.mkdir()
    for name in ("sphere.asm", "animation.asm", "tri_overlap.asm"):
        shutil.copy(PROGRAMS / name, src / name)
    pngs = {}
    for scheduler in ("none", address):
        out = tmp_path / scheduler.replace(":", "_").replace("/", "_")
        r = CliRunner().invoke(main, ["render-all", str(src), "-o", str(out), "--size", "40x30", "--scheduler", scheduler])
        assert r.exit_code == 0, r.output
        pngs[scheduler] = {p.name: p.read_bytes() for p in sorted(out.iterdir())}
    assert len(pngs[address]) == 8 + 2
    assert pngs[address] == pngs["none"]


def test_a_scheduler_that_goes_away_fails_the_run_by_task_name(cluster):
    address, (scheduler, *_) = cluster
    with Campaign(address) as campaign, pytest.raises(Rend3rError) as info:
        campaign.map(time.sleep, [(0.2,)] * 20, [f"nap {i}" for i in range(20)], KillOnce(scheduler, at=2))
    assert re.fullmatch(r"nap ([2-9]|1[0-9]): cancelled: the Dask scheduler went away or gave up on it", str(info.value))
