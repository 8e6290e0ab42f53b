"""The campaign runner: input order, named failures, Ctrl-C, the serial fallback."""

from __future__ import annotations

import operator
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest
from click.testing import CliRunner

from rend3r.campaign import runner
from rend3r.campaign.runner import Campaign, TaskFailed, parse_scheduler
from rend3r.cli import main
from rend3r.errors import Rend3rError

PROGRAMS = Path(__file__).parents[2] / "programs"

needs_dask = pytest.mark.skipif(not runner.dask_installed(),
                                reason="Dask distributed is not installed (pip install 'rend3r[campaign]')")


class Counter:
    """A progress bar that counts the units it is told about, and may act on the n-th."""

    def __init__(self, on=None) -> None:
        self.done = 0
        self.on = on

    def advance(self, units: int) -> None:
        self.done += units
        if self.on is not None:
            self.on(self.done)


def slow_square(x: int) -> int:
    time.sleep(0.01 * (x % 3))  # finish out of order
    return x * x


def fail_on_three(x: int) -> int:
    if x == 3:
        raise Rend3rError("three is not allowed")
    if x == 4:
        return 1 // 0
    return x


@pytest.mark.parametrize("text, value", [("none", "none"), ("LOCAL", "local"),
                                         ("tcp://127.0.0.1:8786", "tcp://127.0.0.1:8786"),
                                         ("tcp://[::1]:8786", "tcp://[::1]:8786")])
def test_scheduler_addresses(text, value):
    assert parse_scheduler(text) == value


@pytest.mark.parametrize("text", ["tcp://host", "tcp://:8786", "tcp://host:0", "tcp://host:70000", "host:8786",
                                  "threads"])
def test_bad_scheduler_addresses(text):
    with pytest.raises(ValueError, match="expected local, none or tcp://HOST:PORT"):
        parse_scheduler(text)


def test_a_bad_scheduler_option_exits_2(tmp_path):
    r = CliRunner().invoke(main, ["render-all", str(tmp_path), "-o", str(tmp_path / "o"), "--scheduler", "bogus"])
    assert r.exit_code == 2 and "--scheduler" in r.output and "tcp://HOST:PORT" in r.output


@pytest.mark.parametrize("scheduler", ["none", pytest.param("local", marks=needs_dask)])
def test_results_come_back_in_input_order(scheduler):
    inputs = [(x,) for x in range(12)]
    bar = Counter()
    with Campaign(scheduler) as campaign:
        assert campaign.distributed == (scheduler == "local")
        assert campaign.map(slow_square, inputs, [str(x) for x in range(12)], bar) == [x * x for x in range(12)]
        assert campaign.map(operator.add, [(1, 2), (3, 4)], ["a", "b"], bar) == [3, 7]
    assert bar.done == 14


@pytest.mark.parametrize("scheduler", ["none", pytest.param("local", marks=needs_dask)])
@pytest.mark.parametrize("inputs, message", [([1, 2, 3], "task 3: three is not allowed"),
                                             ([1, 4], "task 4: ZeroDivisionError: integer division or modulo by zero")])
def test_a_failing_task_is_named_with_its_error(scheduler, inputs, message):
    with Campaign(scheduler) as campaign, pytest.raises(TaskFailed) as info:
        campaign.map(fail_on_three, [(x,) for x in inputs], [f"task {x}" for x in inputs], Counter())
    assert str(info.value) == message


def test_without_dask_local_runs_serially_with_a_note(monkeypatch):
    monkeypatch.setattr(runner, "dask_installed", lambda: False)
    notes = []
    with Campaign("local", note=notes.append) as campaign:
        assert not campaign.distributed
        assert campaign.map(slow_square, [(2,), (3,)], ["a", "b"], Counter()) == [4, 9]
    assert notes == [("rend3r: note: Dask is not installed, running serially "
                      "(pip install 'rend3r[campaign]' to use every core)")]
    with pytest.raises(Rend3rError, match="--scheduler tcp://127.0.0.1:8786 needs Dask distributed"):
        Campaign("tcp://127.0.0.1:8786").__enter__()


started: list[int] = []


def sleep_and_record(x: int) -> int:
    started.append(x)
    time.sleep(0.2)
    return x


@needs_dask
def test_ctrl_c_cancels_the_tasks_in_flight():
    def interrupt(done: int) -> None:
        raise KeyboardInterrupt

    started.clear()
    with Campaign("local") as campaign:
        with pytest.raises(KeyboardInterrupt):
            campaign.map(sleep_and_record, [(x,) for x in range(40)], [str(x) for x in range(40)], Counter(interrupt))
        time.sleep(1.0)  # the tasks left would run now, were they not cancelled
        assert len(started) < 10
        assert not any(campaign._client.processing().values())


@needs_dask
def test_an_unreachable_scheduler_is_a_clean_error(tmp_path, monkeypatch):
    import socket

    monkeypatch.setattr(runner, "CONNECT_TIMEOUT", "1s")

    with socket.socket() as s:  # a port nothing listens on
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    (tmp_path / "sphere.asm").write_text("nr\nnf\ner\ner\n")
    r = CliRunner().invoke(main, ["render-all", str(tmp_path), "-o", str(tmp_path / "o"), "--size", "8x6",
                                  "--scheduler", f"tcp://127.0.0.1:{port}"])
    assert r.exit_code == 1
    assert r.output.startswith(f"rend3r: error: cannot reach the Dask scheduler at tcp://127.0.0.1:{port}: ")


@needs_dask
def test_the_local_cluster_is_closed_with_the_run():
    with Campaign("local") as campaign:
        client = campaign._client
        scheduler = client.cluster.scheduler
        assert campaign.map(slow_square, [(1,)], ["one"], Counter()) == [1]
    assert client.status == "closed" and scheduler.status.name == "closed"
    assert not campaign.distributed


def test_dask_is_imported_only_when_a_cluster_is_used(tmp_path):
    script = f"""
import sys
from click.testing import CliRunner
from rend3r.cli import main
for args in (["explore", "--help"], ["render-all", "--help"],
             ["explore", {str(PROGRAMS / 'sphere.asm')!r}, "-o", {str(tmp_path)!r}, "--size", "8x6",
              "--formats", "e4m3", "--scheduler", "none"]):
    r = CliRunner().invoke(main, args)
    assert r.exit_code == 0, r.output
print(sorted(m for m in sys.modules if m.split(".")[0] in ("dask", "distributed")))
"""
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120, check=False)
    assert (done.returncode, done.stdout) == (0, "[]\n"), done.stderr


@pytest.mark.parametrize("scheduler, processes", [("none", False), pytest.param("local", False, marks=needs_dask),
                                                  pytest.param("local", True, marks=needs_dask)])
def test_kept_results_are_passed_to_a_later_map(scheduler, processes):
    # functions the worker processes can import (this module is not on their path)
    with Campaign(scheduler, workers=2, processes=processes) as campaign:
        kept = campaign.map(pow, [(x, 2) for x in range(6)], [str(x) for x in range(6)], Counter(), keep=True)
        assert (kept == [x * x for x in range(6)]) == (scheduler == "none")  # handles on a cluster
        found = campaign.map(operator.add, [(k, 1) for k in kept], [str(x) for x in range(6)], Counter())
    assert found == [x * x + 1 for x in range(6)]


@needs_dask
def test_local_worker_processes_one_thread_each():
    with Campaign("local", workers=2, processes=True) as campaign:
        workers = campaign._client.scheduler_info()["workers"].values()
        assert sorted(w["nthreads"] for w in workers) == [1, 1]
        pids = campaign.map(os.getpid, [()] * 4, ["pid"] * 4, Counter())
    assert os.getpid() not in pids


def test_a_local_cluster_needs_a_worker():
    with pytest.raises(ValueError, match="at least one worker"):
        Campaign("local", workers=0)


@needs_dask
def test_ctrl_c_stops_the_local_worker_processes_at_once():
    def interrupt(done: int) -> None:
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        with Campaign("local", workers=2, processes=True) as campaign:
            pids = list(campaign._client.run(os.getpid).values())
            campaign.map(time.sleep, [(0.0,)] + [(30.0,)] * 3, ["nap"] * 4, Counter(interrupt))
            assert False, "not interrupted"
    stopped = time.monotonic()
    while any(os.path.exists(f"/proc/{pid}") and "zombie" not in open(f"/proc/{pid}/status").read()
              for pid in pids) and time.monotonic() - stopped < 1:
        time.sleep(0.05)
    assert all(not os.path.exists(f"/proc/{pid}") or "zombie" in open(f"/proc/{pid}/status").read() for pid in pids)


@needs_dask
@pytest.mark.parametrize("processes", [False, True])
def test_two_local_clusters_at_once_say_nothing(processes):
    import warnings

    # another campaign on this machine: its scheduler holds the HTTP port a cluster takes by default
    with Campaign("local", workers=1) as first, warnings.catch_warnings():
        warnings.simplefilter("error")
        with Campaign("local", workers=1, processes=processes) as second:
            assert second.map(abs, [(-3,)], ["abs"], Counter()) == [3]
        assert first.map(abs, [(-2,)], ["abs"], Counter()) == [2]


@needs_dask
def test_local_worker_processes_tune_their_allocator():
    from rend3r.memory import reuse_freed_memory

    with Campaign("local", workers=2, processes=True) as campaign:  # the preload has called it once in each
        calls = campaign._client.run(reuse_freed_memory.cache_info)
    assert [info.currsize for info in calls.values()] == [1, 1]


@needs_dask
def test_the_users_worker_preloads_still_run(tmp_path, monkeypatch):
    import dask

    (tmp_path / "users_preload.py").write_text(
        "import os\n\n\ndef dask_setup(worker):\n"
        "    open(os.path.join(os.environ['PRELOAD_MARKS'], str(os.getpid())), 'w').close()\n")
    marks = tmp_path / "marks"
    marks.mkdir()
    monkeypatch.syspath_prepend(str(tmp_path))  # spawned workers get this process's sys.path
    monkeypatch.setenv("PRELOAD_MARKS", str(marks))
    with dask.config.set({"distributed.worker.preload": ["users_preload"]}):
        with Campaign("local", workers=2, processes=True) as campaign:
            pids = set(campaign._client.run(os.getpid).values())
    assert {int(p.name) for p in marks.iterdir()} == pids
