"""``rend3r device`` end to end: source file -> send -> virtual device -> rendered PNG."""

from __future__ import annotations

import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

RENDER = [sys.executable, "-m", "rend3r"]
PROGRAMS = Path(__file__).resolve().parents[2] / "programs"


def start_device(args: list[str]) -> subprocess.Popen:
    """Start ``rend3r device`` and wait until it says it is listening."""
    proc = subprocess.Popen(RENDER + ["device", *args], stderr=subprocess.PIPE, text=True)
    line = proc.stderr.readline()
    assert "listening on" in line, line + proc.stderr.read()
    return proc


def stop_device(proc: subprocess.Popen) -> str:
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=30)
    assert proc.returncode == 0, err
    return err


def wait_for(predicate, timeout: float = 60.0) -> bool:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if predicate():
            return True
        time.sleep(0.05)
    return False


@pytest.mark.timeout(120)
def test_source_to_png_over_a_pty(pty_bridge, tmp_path):
    from PIL import Image

    out = tmp_path / "frames"
    device = start_device(["--serial", pty_bridge.paths[1], "-o", str(out), "--size", "32x24",
                           "--frames", "2"])
    try:
        # a corrupted-in-flight frame never reaches the emulator: garbage is counted (sent
        # first, so the device has read it once the good load's frame is out)
        with open(pty_bridge.paths[0], "wb", buffering=0) as raw:
            raw.write(b"\x00\x05garbage\x00")
        r = subprocess.run(RENDER + ["send", str(PROGRAMS / "sphere.asm"), "--serial",
                                     pty_bridge.paths[0]], capture_output=True, text=True, timeout=60)
        assert r.returncode == 0, r.stderr
        assert "loaded 23 words" in r.stderr and "; the device is running it" in r.stderr, r.stderr
        assert wait_for(lambda: any(out.glob("*.png")))
    finally:
        err = stop_device(device)
    assert sorted(p.name for p in out.glob("*.png")) == ["run0001_frame0000.png"]  # sphere.asm ends after one
    with Image.open(out / "run0001_frame0000.png") as im:
        assert im.size == (32, 24)
    assert "stopped after 1 load (1 run), 1 frame rendered, 1 malformed protocol frame;" in err, err


def test_device_refuses_bad_arguments(tmp_path):
    for args, message in [
        ([], "choose exactly one of --eth and --serial"),
        (["--serial", str(tmp_path / "none")], "cannot open serial port"),
        (["--eth", "nosuch0"], "no such network interface: nosuch0"),
        (["--serial", "loop://", "--mac", "01:02"], "malformed MAC address"),
    ]:
        r = subprocess.run(RENDER + ["device", "-o", str(tmp_path / "o"), *args],
                           capture_output=True, text=True, timeout=60)
        assert r.returncode == 1 and message in r.stderr, (args, r.stderr)
        assert "Traceback" not in r.stderr
    for size in ("0x5", "4097x1", "128"):
        r = subprocess.run(RENDER + ["device", "--serial", "loop://", "-o", str(tmp_path / "o"), "--size", size],
                           capture_output=True, text=True, timeout=60)
        assert r.returncode == 2 and "Invalid value for '--size'" in r.stderr, (size, r.stderr)
    (tmp_path / "plain").write_text("x")
    r = subprocess.run(RENDER + ["device", "--serial", "loop://", "-o", str(tmp_path / "plain" / "frames")],
                       capture_output=True, text=True, timeout=60)
    assert (r.returncode, r.stderr) == (1, f"rend3r: error: cannot write {tmp_path / 'plain' / 'frames'}: "
                                           f"{tmp_path / 'plain'} is not a folder\n")


def test_device_renders_at_the_boards_size_by_default():
    from click.testing import CliRunner

    from rend3r.cli import main

    r = CliRunner().invoke(main, ["device", "--help"])
    assert "--size WxH" in r.output and "[default: 512x384]" in r.output


@pytest.mark.timeout(60)
def test_device_stops_on_sigint_with_the_interrupted_status(tmp_path):
    device = start_device(["--serial", "loop://", "-o", str(tmp_path / "a" / "o")])
    device.send_signal(signal.SIGINT)
    _, err = device.communicate(timeout=30)
    assert device.returncode == 130 and "stopped after 0 loads (0 runs), 0 frames rendered" in err, err


@pytest.mark.timeout(120)
def test_device_size_limit_is_reported_to_the_sender(pty_bridge, tmp_path):
    device = start_device(["--serial", pty_bridge.paths[1], "-o", str(tmp_path / "o"),
                           "--max-words", "4"])
    try:
        r = subprocess.run(RENDER + ["send", str(PROGRAMS / "sphere.asm"), "--serial",
                                     pty_bridge.paths[0]], capture_output=True, text=True, timeout=60)
    finally:
        err = stop_device(device)
    assert r.returncode == 1
    assert "the device refuses a program of" in r.stderr and "its limit is 4" in r.stderr
    assert "NACKs: TOO_LARGE 1" in err
