"""Ctrl-C during a campaign on the local cluster: exit 130, nothing written.

That the queued tasks are cancelled rather than run is checked by counting the tasks that
ran (tests/campaign/test_runner.py), not by timing this process: Ctrl-C waits for the renders
already running, seconds each here, longer on a loaded machine."""

from __future__ import annotations

import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from rend3r.campaign.runner import dask_installed

PROGRAMS = Path(__file__).parents[2] / "programs"


@pytest.mark.skipif(not dask_installed(), reason="Dask distributed is not installed (pip install 'rend3r[campaign]')")
def test_ctrl_c_exits_130_and_writes_nothing(tmp_path):
    out = tmp_path / "out" / "explore"
    # formats too coarse for the culling bounds: stress4096 tests every shape at every pixel,
    # a few seconds a render (each its own task), so the campaign runs far beyond the signal
    coarse = "e4m3,e5m2,e3m6,e4m4,e3m4,e2m5,e4m2,e3m3,e2m3,e3m2,e5m1,e2m6"
    command = [sys.executable, "-m", "rend3r", "explore", *map(str, sorted(PROGRAMS.glob("*.asm"))),
               "-o", str(out), "--size", "256x192", "--formats", coarse, "--scheduler", "local"]
    run = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(5)  # the cluster is up and rendering: the whole campaign takes far longer
    assert run.poll() is None, run.communicate()
    run.send_signal(signal.SIGINT)
    _, err = run.communicate(timeout=60)
    assert run.returncode == 130, err
    assert err.endswith("rend3r: interrupted\n")
    assert not (tmp_path / "out").exists()
