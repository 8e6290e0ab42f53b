"""``rend3r send`` to files, argument checking, progress; the execute step on its own."""

from __future__ import annotations

import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from rend3r.asm.assembler import assemble_or_raise
from rend3r.asm.formats import read_file, render
from rend3r.transport.cli import serve
from rend3r.transport.device import DeviceCore, RecordingExecutor
from rend3r.transport.execute import RenderExecutor
from rend3r.transport.links import SerialLink, open_serial

RENDER = [sys.executable, "-m", "rend3r"]
PROGRAMS = Path(__file__).resolve().parents[2] / "programs"


def send(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run(RENDER + ["send", *map(str, args)], capture_output=True, text=True, timeout=60)


@pytest.mark.parametrize("fmt", ["mem", "coe"])
@pytest.mark.parametrize("option", ["-o", "--output", "alias"])
def test_file_targets_match_the_formats_module(tmp_path, fmt, option):
    out = tmp_path / f"main.{fmt}"
    r = send(PROGRAMS / "sphere.asm", f"--{fmt}" if option == "alias" else option, out)
    assert r.returncode == 0, r.stderr
    assert r.stderr.startswith("wrote 23 words (CRC-32 ")
    program = assemble_or_raise(PROGRAMS / "sphere.asm").program
    assert out.read_bytes() == render(fmt, program)
    assert read_file(out) == program.words
    assert [p.name for p in tmp_path.iterdir()] == [out.name]  # no temporary left behind


def test_memory_image_input_is_passed_through(tmp_path):
    src, out = tmp_path / "in.mem", tmp_path / "out.mem"
    src.write_text("00000200\n3c000009\n00000400\n00000000\n00000000\n")
    assert send(src, "-o", out).returncode == 0
    assert out.read_text() == src.read_text()


def test_output_folders_are_made_and_an_unknown_suffix_is_refused(tmp_path):
    out = tmp_path / "a" / "b" / "load.pcap"
    r = send(PROGRAMS / "sphere.asm", "-o", out)
    assert r.returncode == 0 and out.stat().st_size > 0, r.stderr
    r = send(PROGRAMS / "sphere.asm", "-o", tmp_path / "main.txt")
    assert r.returncode == 1 and "-o writes a .mem ($readmemh), .coe (Xilinx) or .pcap" in r.stderr
    (tmp_path / "plain").write_text("x")
    r = send(PROGRAMS / "sphere.asm", "-o", tmp_path / "plain" / "main.mem")
    assert (r.returncode, r.stderr) == (1, f"rend3r: error: cannot write {tmp_path / 'plain' / 'main.mem'}: "
                                           f"{tmp_path / 'plain'} is not a folder\n")


@pytest.mark.parametrize("name", ["scene.rdr", "scene.s", "scene.asm"])
def test_source_is_recognised_by_every_source_suffix(tmp_path, name):
    src, out = tmp_path / name, tmp_path / "out.mem"
    src.write_text((PROGRAMS / "sphere.asm").read_text())
    r = send(src, "-o", out)
    assert r.returncode == 0, r.stderr
    assert read_file(out) == assemble_or_raise(PROGRAMS / "sphere.asm").program.words


@pytest.mark.parametrize("args, message", [
    ([], "choose exactly one of -o FILE, --eth IFACE, --serial PORT"),
    (["-o", "a.mem", "--serial", "loop://"], "(got -o, --serial)"),
    (["-o", "a.mem", "--run"], "--run needs a device (--eth, --serial) or a .pcap file, not a .mem file"),
    (["--serial", "loop://", "--timeout", "0"], "--timeout must be positive"),
    (["-o", "o.pcap", "--ethertype", "0x10"], "not an Ethernet II type"),
    (["--pcap", "o.pcap", "--ethertype", "zz"], "malformed EtherType"),
])
def test_bad_arguments(tmp_path, args, message):
    r = subprocess.run(RENDER + ["send", str(PROGRAMS / "sphere.asm"), *args], cwd=tmp_path,
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 1 and message in r.stderr, r.stderr
    assert list(tmp_path.iterdir()) == []


def test_source_errors_are_reported_without_output(tmp_path):
    bad = tmp_path / "bad.asm"
    bad.write_text("frobnicate 1, 2\n")
    r = send(bad, "-o", tmp_path / "o.mem")
    assert r.returncode == 1 and "bad.asm:1" in r.stderr and "Traceback" not in r.stderr
    assert not (tmp_path / "o.mem").exists()
    r = send(tmp_path / "missing.mem", "-o", tmp_path / "o.mem")
    assert r.returncode == 1 and "missing.mem" in r.stderr


@pytest.mark.timeout(60)
def test_long_sends_report_progress(pty_bridge, tmp_path):
    core = DeviceCore(RecordingExecutor())
    link = SerialLink(open_serial(pty_bridge.paths[1]))
    stop = threading.Event()
    thread = threading.Thread(target=serve, args=(link, core, stop, 0.02), daemon=True)
    thread.start()
    src = tmp_path / "big.mem"
    src.write_text("".join(f"{i:08x}\n" for i in range(5000)))
    try:
        r = send(src, "--serial", pty_bridge.paths[0])
    finally:
        stop.set()
        thread.join()
        link.close()
    assert r.returncode == 0, r.stderr
    assert "5000/5000 words (100%)" in r.stderr
    assert core.active == tuple(range(5000))


def wait_for(predicate, timeout: float = 60.0) -> bool:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if predicate():
            return True
        time.sleep(0.02)
    return False


@pytest.mark.timeout(120)
def test_executor_renders_bounded_frames_and_is_superseded(tmp_path):
    looping = tuple(assemble_or_raise(PROGRAMS / "animation.asm").program.words)
    ex = RenderExecutor(tmp_path, width=16, height=12, max_frames=3, max_frame_rate=1000)
    ex.start(looping)
    assert wait_for(lambda: ex.frames == 3)
    ex.close()
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        f"run0001_frame{i:04d}.png" for i in range(3)]
    slow = RenderExecutor(tmp_path / "slow", width=16, height=12, max_frames=50, max_frame_rate=2)
    (tmp_path / "slow").mkdir()
    slow.start(looping)
    assert wait_for(lambda: slow.frames >= 1)
    slow.start(())  # the empty program supersedes the slow run at its next frame
    slow.close()
    rendered = slow.frames
    time.sleep(1.2)  # an uncancelled run would add two frames at 2 frames/s
    assert slow.frames == rendered < 50
    assert all(p.name.startswith("run0001") for p in (tmp_path / "slow").iterdir())
