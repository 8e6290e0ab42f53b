"""Ctrl-C stops every svo command at once: exit 130, one line, no traceback, no output.

Each test starts the real CLI in its own process group with stderr on a pseudo-terminal
(so the progress bar shows), waits for the bar of the stage it means to interrupt, and
sends SIGINT to the whole group, as a terminal's Ctrl-C does (sweep's local worker
processes get it too, ignore it, and are stopped by the command).
"""

import os
import pty
import re
import select
import signal
import subprocess
import sys
import threading
import time

import pytest
from click.testing import CliRunner

from rend3r.cli import INTERRUPTED, main
from rend3r.svo.interrupt import ctrl_c_ignored, off_main_thread

STARTUP = 20.0  # seconds allowed to reach the stage (imports on a loaded 2-core machine)
STOP = 2.0  # seconds allowed from Ctrl-C to exit
#: one state of a progress bar (click's), as a terminal receives it
BAR = re.compile(r"(\x1b\[\?25[lh])*(tracing|voxelising|building octree|simulating)  \[[#-]*\]\s+\d+%(\s+\d\d:\d\d:\d\d)?\s*"
                 r"(\x1b\[\?25[lh])*")


@pytest.fixture(scope="module")
def inputs(tmp_path_factory):
    d = tmp_path_factory.mktemp("inputs")
    run = CliRunner().invoke
    assert run(main, ["svo", "model", "folded", "-o", str(d / "f.ply"), "--detail", "64"]).exit_code == 0
    assert run(main, ["svo", "build", str(d / "f.ply"), "-o", str(d / "f.svo"), "--depth", "7"]).exit_code == 0
    return d


def interrupt(args: list[str], cwd, stage: str, wait: float = 0.5):
    """Run ``rend3r svo ARGS``, Ctrl-C ``wait`` s after stderr shows ``stage``: (status, stderr, s to stop)."""
    master, slave = pty.openpty()
    proc = subprocess.Popen([sys.executable, "-m", "rend3r", "svo", *args], cwd=cwd,
                            stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=slave,
                            start_new_session=True)
    os.close(slave)
    err = b""

    def read_until(deadline: float, marker: bytes | None) -> None:
        nonlocal err
        while time.monotonic() < deadline and (marker is None or marker not in err):
            if select.select([master], [], [], 0.05)[0]:
                try:
                    chunk = os.read(master, 4096)
                except OSError:  # the process closed the terminal
                    return
                if not chunk:
                    return
                err += chunk
            elif proc.poll() is not None and marker is not None:
                return

    try:
        read_until(time.monotonic() + STARTUP, stage.encode())
        assert stage.encode() in err, f"never reached {stage!r}: {err.decode(errors='replace')}"
        read_until(time.monotonic() + wait, None)
        assert proc.poll() is None, "finished before the Ctrl-C: make the work longer"
        sent = time.monotonic()
        os.killpg(proc.pid, signal.SIGINT)
        try:
            status = proc.wait(timeout=10)
        finally:
            stopped = time.monotonic() - sent
        read_until(time.monotonic() + 1, None)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
        os.close(master)
    return status, err.decode(errors="replace"), stopped


def assert_stopped(result, out_dir) -> None:
    status, err, stopped = result
    assert status == INTERRUPTED, err
    # nothing but the progress bar and one line: no traceback, no word from a worker
    said = [part for part in re.split(r"[\r\n]+", err) if part.strip() and not BAR.fullmatch(part)]
    assert said == ["rend3r: interrupted"], err
    assert stopped < STOP, f"took {stopped:.2f} s to stop"
    assert list(out_dir.iterdir()) == [], "the interrupted run left files"


def test_render_while_the_kernel_compiles(inputs, tmp_path):
    # REND3R_JIT_CACHE=0 (conftest): the first chunk compiles the numba kernel for seconds
    out = tmp_path / "out"
    assert_stopped(interrupt(["render", str(inputs / "f.svo"), "-o", str(out / "a.png"),
                              "--cost", str(out / "c.png")], tmp_path, "tracing"), tmp_path)


def test_render_while_tracing(inputs, tmp_path):
    assert_stopped(interrupt(["render", str(inputs / "f.svo"), "-o", str(tmp_path / "a.png"),
                              "--kernel", "numpy", "--size", "1024x768"], tmp_path, "tracing"), tmp_path)


def test_build_while_voxelising(inputs, tmp_path):
    assert_stopped(interrupt(["build", str(inputs / "f.ply"), "-o", str(tmp_path / "f.svo"), "--depth", "10",
                              "--binvox", str(tmp_path / "f.binvox")], tmp_path, "voxelising"), tmp_path)


def test_sweep_while_its_workers_simulate(inputs, tmp_path):
    assert_stopped(interrupt(["sweep", str(inputs / "f.svo"), "-o", str(tmp_path / "sw"), "--size", "64x48",
                              "--kernel", "numpy", "--jobs", "2"], tmp_path, "simulating"), tmp_path)


def test_a_ctrl_c_reaches_the_caller_while_the_helper_thread_works():
    threading.Timer(0.1, os.kill, (os.getpid(), signal.SIGINT)).start()
    start = time.monotonic()
    with pytest.raises(KeyboardInterrupt):
        off_main_thread(time.sleep, 2.0)
    assert time.monotonic() - start < 0.5


def test_the_helper_threads_result_and_errors_come_back():
    assert off_main_thread(lambda a, b: a + b, 2, 3) == 5
    with pytest.raises(ValueError, match="bad"):
        off_main_thread(lambda: (_ for _ in ()).throw(ValueError("bad")))


def test_ctrl_c_is_ignored_while_outputs_are_committed():
    with ctrl_c_ignored():
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(0.05)  # the signal arrives and is dropped
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    with pytest.raises(KeyboardInterrupt):
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(1)
