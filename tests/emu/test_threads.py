"""The kernels' threads (threads.py, csrc/team.c): a team per thread that leads one, the
splits, and the pool's threads across errors and forks."""

import os
import subprocess
import sys
import threading
from pathlib import Path

import pytest

from rend3r.emu import native, threads

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize(("n", "jobs", "smallest", "want"), [
    (100, 1, 1, 1), (100, 2, 1, 8), (100, 2, 30, 2), (5, 3, 10, 1), (0, 2, 1, 1), (10**6, 3, 10, 12),
    (20480, 2, 4096, 4), (100, 3, 20, 3), (100, 3, 50, 2)])
def test_parts_are_a_few_per_thread_and_never_too_short(n, jobs, smallest, want):
    """Up to four a thread, a multiple of the threads when there are at least as many."""
    assert threads.parts(n, jobs, smallest) == want


def test_parts_keep_their_rules_over_a_grid():
    """At most four a thread, a multiple of the threads when there are at least as many,
    none shorter than smallest unless there is only one (smallest 0 counts as 1)."""
    for jobs in range(0, 10):
        for smallest in (0, 1, 2, 3, 7, 40, 4096):
            for n in (0, 1, 5, 17, 64, 100, 599, 20480, 10**6):
                k = threads.parts(n, jobs, smallest)
                assert 1 <= k <= max(1, 4 * jobs), (n, jobs, smallest, k)
                assert k == 1 or n // k >= max(1, smallest), (n, jobs, smallest, k)
                assert jobs <= 1 or k < jobs or k % jobs == 0, (n, jobs, smallest, k)
                if jobs > 1 and n // max(1, smallest) >= jobs:
                    assert k >= jobs, (n, jobs, smallest, k)


def test_a_team_is_led_once_per_thread_and_ends_with_its_block():
    """Inside a team this thread leads, calls get the same team; another thread leads its
    own meanwhile (the pool serves the first, so the second's calls run alone). After an
    error in the block the team ends, and one team object entered twice closes its team
    once: the process exits, in a process of its own."""
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
            "try:\n    with threads.team(2):\n        raise KeyError\nexcept KeyError:\n    pass\n"
            "same = threads.team(2)  # one object entered twice: its outer entry opens and closes the team\n"
            "for _ in range(100):\n    with same as first, same as again:\n        assert first == again\n")
    subprocess.run([sys.executable, "-c", code], check=True, timeout=30)


def test_teams_opened_and_closed_in_quick_succession_on_two_threads():
    """A team's memory goes with its last reference, the leader's close or a member's
    leaving, whichever comes last: thousands of teams opened and closed at once from two
    threads (only one has the pool's threads at a time), half of them rendering a frame,
    in a process of its own so that a fault shows as its exit status."""
    code = (
        "import sys, threading\n"
        "sys.path.insert(0, 'benchmarks')\n"
        "import walls\n"
        "from rend3r.emu import bounds, raytracer, threads\n"
        "from rend3r.emu.options import EmuOptions\n"
        "from rend3r.emu.run import run_program\n"
        "raytracer.MIN_CHUNK, bounds.SHAPE_CHUNK = 16, 8  # every pass split\n"
        "w = walls.wall(16, 1)\n"
        "frame = lambda j: run_program(w.words, EmuOptions(precision='fp32', jobs=j, width=16, height=12)).frames[0]\n"
        "one = frame(1).rgb565.tobytes()\n"
        "bad = []\n"
        "def churn():\n"
        "    for k in range(1500):\n"
        "        with threads.team(2):\n"
        "            pass\n"
        "        if frame(2).rgb565.tobytes() != one:  # its team closes as the member spins in it\n"
        "            bad.append(k)\n"
        "ts = [threading.Thread(target=churn) for _ in range(2)]\n"
        "[t.start() for t in ts]\n"
        "[t.join() for t in ts]\n"
        "sys.exit(1 if bad else 0)\n")
    subprocess.run([sys.executable, "-c", code], check=True, timeout=120, cwd=ROOT)


#: The start of a script run in a process of its own: the 256-sphere wall ``w``, every pass
#: of its frames split over the team.
_SPLIT_WALL = (
    "import os, sys\n"
    "sys.path.insert(0, 'benchmarks')\n"
    "import walls\n"
    "from rend3r.emu.options import EmuOptions\n"
    "from rend3r.emu.run import run_program\n"
    "from rend3r.emu import bounds, raytracer\n"
    "raytracer.MIN_CHUNK, bounds.SHAPE_CHUNK = 16, 8  # every pass split\n"
    "w = walls.wall(256, 1)\n")


def test_a_forked_child_starts_its_own_team_threads():
    """The pool's threads do not survive a fork: a child that renders with two jobs starts
    its own, and gets the frames its parent gets with one; the parent's pool serves it
    after the fork as before (a fork holds the pool's lock while it copies the process)."""
    code = _SPLIT_WALL + (
        "frame = lambda j: run_program(w.words, EmuOptions(precision='fp32', jobs=j, width=64, height=48)).frames[0]\n"
        "one = frame(1).rgb565.tobytes()\n"
        "assert frame(2).rgb565.tobytes() == one\n"
        "pid = os.fork()\n"
        "if pid == 0:\n"
        "    os._exit(0 if frame(2).rgb565.tobytes() == one else 1)\n"
        "assert os.waitstatus_to_exitcode(os.waitpid(pid, 0)[1]) == 0\n"
        "assert frame(2).rgb565.tobytes() == one\n")
    subprocess.run([sys.executable, "-c", code], check=True, timeout=60, cwd=ROOT)


@pytest.mark.skipif(not hasattr(os, "sched_setaffinity") or len(os.sched_getaffinity(0)) < 2,
                    reason="needs Linux CPU affinity and two CPUs")
def test_a_member_woken_onto_its_leaders_cpu_moves_to_another():
    """A scheduler that packs threads onto few CPUs (a VM guest's) may leave the pool's
    thread on its leader's CPU, where the two take turns: as it joins or at the next phase
    the member moves to another of its CPUs, then gets all of them back (csrc/team.c
    team_apart). Emulated by pinning every native thread to the leader's CPU, in a
    process of its own (the pool's thread restores the CPUs it started with); the frames
    stay the same."""
    code = _SPLIT_WALL + (
        "import threading\n"
        "frame = lambda: run_program(w.words, EmuOptions(precision='fp32', jobs=2, width=256, height=192)).frames[0]\n"
        "want = frame().rgb565.tobytes()\n"
        "native = [int(t) for t in os.listdir('/proc/self/task')\n"
        "          if int(t) not in {t.native_id for t in threading.enumerate()}]\n"
        "cpus = os.sched_getaffinity(0)\n"
        "cpu = min(cpus)\n"
        "os.sched_setaffinity(0, {cpu})\n"
        "for tid in native:\n"
        "    os.sched_setaffinity(tid, {cpu})\n"
        "assert all(frame().rgb565.tobytes() == want for _ in range(10))\n"
        "moved = [tid for tid in native if os.sched_getaffinity(tid) == cpus]  # moved, then given its CPUs back\n"
        "assert moved, [os.sched_getaffinity(tid) for tid in native]\n")
    subprocess.run([sys.executable, "-c", code], check=True, timeout=60, cwd=ROOT)


#: Runs thousands of phases on a team of sys.argv[1] threads through the test-only
#: team_check_runs (csrc/team.c) until members have taken tasks in a hundred small phases,
#: checking every round that each task ran once and that members ran none of a phase the
#: leader runs alone.
_CHECK_RUNS = """
import sys
import numpy as np
from rend3r.emu import native, threads
lib = native.library()
pattern = [0, 1, 2, 3, 5, 7, 16, 64, 2, 1, 2, 3]
tasks = np.array(pattern * 500 + [0xFFFF, 0x10000] + pattern * 500, dtype=np.int64)
phase_of = np.repeat(np.arange(len(tasks)), tasks)
alone = (tasks <= 1) | (tasks > 0xFFFF)
contended = 0
for _ in range(50):
    runs = np.zeros(int(tasks.sum()), dtype=np.int32)
    with threads.team(int(sys.argv[1])) as at:
        lib.team_check_runs(at, native.address(tasks), len(tasks), native.address(runs))
    wrong = np.flatnonzero(runs % 256 != 1)
    assert not len(wrong), f"task {wrong[0]} of the list ran {runs[wrong[0]] % 256} times"
    by_member = runs >= 256
    assert not by_member[alone[phase_of]].any(), "a member ran a task of a phase the leader runs alone"
    contended += len(np.unique(phase_of[by_member & (tasks[phase_of] <= 64)]))
    if contended >= 100:
        break
assert contended >= 100, f"members took tasks in only {contended} small phases"
"""


@pytest.mark.skipif(threads.available_cores() < 2, reason="needs two CPUs for the members to contend")
@pytest.mark.parametrize("jobs", [2, 3, 8])
def test_every_task_of_every_phase_runs_once_on_a_team(jobs):
    """The claims (csrc/team.c team_take): thousands of phases released back to back on a
    team, the leader taking tasks from the front and the members from the back, every
    count a phase may have (none, one, a few, as many as a claim holds, one more, which
    the leader runs alone), each phase with a context of its own while the ring of phase
    slots is reused; each task runs exactly once. In a process of its own, so that a
    hang (a task counted in the wrong phase's slot) shows as a timeout."""
    subprocess.run([sys.executable, "-c", _CHECK_RUNS, str(jobs)], check=True, timeout=120, cwd=ROOT)


#: Teams of sys.argv[1] threads, each opened a pause after the last one closed, running
#: phases through team_check_runs until members have taken tasks in ten teams of each
#: pause: within the time a pool thread waits spinning after a team (csrc/team.c
#: POOL_LINGER_NS), and past it, when it sleeps and team_open must wake it.
_TEAMS_AFTER_PAUSES = """
import sys, time
import numpy as np
from rend3r.emu import native, threads
lib = native.library()
tasks = np.array([64] * 50, dtype=np.int64)
for pause in (0.0, 0.00005, 0.005):
    joined = 0
    for _ in range(2000):
        time.sleep(pause)
        runs = np.zeros(int(tasks.sum()), dtype=np.int32)
        with threads.team(int(sys.argv[1])) as at:
            lib.team_check_runs(at, native.address(tasks), len(tasks), native.address(runs))
        assert (runs % 256 == 1).all(), "a task ran more or less than once"
        joined += bool((runs >= 256).any())
        if joined == 10:
            break
    assert joined == 10, f"members joined only {joined} teams opened {pause * 1e3} ms after the last"
"""


@pytest.mark.skipif(threads.available_cores() < 2, reason="needs two CPUs for the members to take tasks")
@pytest.mark.parametrize("jobs", [2, 3])
def test_members_join_teams_opened_at_once_or_after_they_sleep(jobs):
    """A pool thread that leaves a team waits spinning for the next one, then sleeps: a
    team opened as the last closes, a little later, or long after (team_open then wakes
    the thread) gets its members, and each task runs once. In a process of its own, so
    that a lost wake-up shows as a failure, not as a pool stuck for later tests."""
    subprocess.run([sys.executable, "-c", _TEAMS_AFTER_PAUSES, str(jobs)], check=True, timeout=120, cwd=ROOT)
