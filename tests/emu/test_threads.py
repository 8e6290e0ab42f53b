"""The kernels' threads: the calling thread works beside its helpers; order, progress and
errors as if the calls ran one after another."""

import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from rend3r.emu import threads

ROOT = Path(__file__).resolve().parents[2]


def test_results_and_progress_come_in_order_on_the_calling_thread():
    caller, ran, reported = threading.current_thread(), [], []

    def call(k):
        ran.append(threading.current_thread())
        time.sleep(0.002 * (k % 3))  # calls end out of order
        return k * k

    def done(k):
        assert threading.current_thread() is caller
        reported.append(k)

    out = threads.each(3, [lambda k=k: call(k) for k in range(12)], done)
    assert out == [k * k for k in range(12)]
    assert reported == list(range(12))
    assert caller in ran  # the caller took calls itself
    assert len(set(ran)) <= 3


def test_an_error_stops_new_calls_and_is_raised_after_the_running_ones():
    started, finished = [], []

    def call(k):
        started.append(k)
        if k == 1:
            raise ValueError("call 1")
        time.sleep(0.01)
        finished.append(k)

    with pytest.raises(ValueError, match="call 1"):
        threads.each(2, [lambda k=k: call(k) for k in range(50)])
    assert len(started) < 50  # the calls after the error never started
    assert sorted(finished) == sorted(k for k in started if k != 1)  # every call started has ended


@pytest.mark.parametrize("jobs", [1, 2, 5])
def test_one_call_or_one_job_runs_here(jobs):
    here = threading.current_thread()
    assert threads.each(jobs, [lambda: threading.current_thread()]) == [here]
    assert threads.each(1, [lambda: threading.current_thread()] * 3) == [here] * 3


def test_work_handed_out_from_a_helper_does_not_wait_for_itself():
    """A call that itself splits work over the threads (its helpers may all be busy,
    running it): the caller takes every call, and helpers that never started are dropped.
    In a process of its own, as a helper that waited for itself would hang this one."""
    code = ("from rend3r.emu import threads\n"
            "inner = lambda: threads.each(2, [lambda k=k: k for k in range(6)])\n"
            "assert threads.each(2, [inner, inner]) == [list(range(6))] * 2\n")
    subprocess.run([sys.executable, "-c", code], check=True, timeout=30)


def test_a_team_is_led_once_per_thread_and_ends_with_its_block():
    """Inside a team this thread leads, calls get the same team; another thread leads its
    own meanwhile (the pool serves the first, so the second's calls run alone). After an
    error in the block the team ends: the process exits, in a process of its own."""
    with threads.team(2) as outer:
        with threads.team(3) as inner:
            assert inner == outer
        seen: list[int] = []

        def lead() -> None:
            with threads.team(2) as own:
                seen.append(own)

        other = threading.Thread(target=lead)
        other.start()
        other.join()
        assert seen and seen[0] != outer
    code = ("from rend3r.emu import threads\n"
            "try:\n    with threads.team(2):\n        raise KeyError\nexcept KeyError:\n    pass\n")
    subprocess.run([sys.executable, "-c", code], check=True, timeout=30)


def test_a_forked_child_starts_its_own_team_threads():
    """The pool's threads do not survive a fork: a child that renders with two jobs starts
    its own, and gets the frames its parent gets with one."""
    code = (
        "import os, sys\n"
        "sys.path.insert(0, 'benchmarks')\n"
        "import walls\n"
        "from rend3r.emu.options import EmuOptions\n"
        "from rend3r.emu.run import run_program\n"
        "from rend3r.emu import bounds, raytracer\n"
        "raytracer.MIN_CHUNK, bounds.SHAPE_CHUNK = 16, 8  # every pass split\n"
        "w = walls.wall(256, 1)\n"
        "frame = lambda j: run_program(w.words, EmuOptions(precision='fp32', jobs=j, width=64, height=48)).frames[0]\n"
        "one = frame(1).rgb565.tobytes()\n"
        "assert frame(2).rgb565.tobytes() == one\n"
        "pid = os.fork()\n"
        "if pid == 0:\n"
        "    os._exit(0 if frame(2).rgb565.tobytes() == one else 1)\n"
        "assert os.waitstatus_to_exitcode(os.waitpid(pid, 0)[1]) == 0\n")
    subprocess.run([sys.executable, "-c", code], check=True, timeout=60, cwd=ROOT)
