"""Serial links: COBS framing on loop:// and real ptys, the send CLI end to end, bad ports."""

from __future__ import annotations

import subprocess
import sys
import threading
import time

import pytest

from rend3r.transport.cli import serve
from rend3r.transport.device import DeviceCore, RecordingExecutor
from rend3r.transport.links import SerialLink, open_serial
from rend3r.transport.protocol import (
    Frame, FrameError, FrameType, decode, program_crc, words_to_bytes,
)
from rend3r.transport.session import Sender

PROGRAM = [0x200, 0x3C000009, 0x400, 0, 0]
RENDER = [sys.executable, "-m", "rend3r"]


def test_frames_round_trip_over_loop_url():
    link = SerialLink(open_serial("loop://"))
    frames = [Frame(FrameType.DATA, 1, i, 0, 1, words_to_bytes([i])).encode() for i in range(3)]
    for f in frames:
        link.send(f)
    assert [link.recv(1.0) for _ in frames] == frames
    assert link.recv(0.01) is None
    # one COBS byte and one delimiter per frame, plus the leading delimiter of the first
    assert link.tx_bytes == link.rx_bytes == sum(len(f) + 2 for f in frames) + 1


def recv_after_errors(link: SerialLink) -> tuple[int, bytes | None]:
    """(frames rejected by the link or the protocol, the first valid frame) from ``link``."""
    errors = 0
    while True:
        try:
            frame = link.recv(1.0)
            if frame is not None:
                decode(frame)
            return errors, frame
        except FrameError:
            errors += 1


def test_line_noise_is_reported_then_the_link_resynchronises():
    link = SerialLink(open_serial("loop://"))
    good = Frame(FrameType.STATUS, 0, 5).encode()
    link.write(b"\x07\x01\x02\x00")  # a COBS block longer than its frame
    link.send(good)
    assert recv_after_errors(link) == (1, good)
    link.write(b"\x01" * 2200)  # more than two frames' worth without a delimiter
    link.send(good)  # lost: it ends the noise's tail (as a corrupted frame would be)
    link.send(good)
    errors, frame = recv_after_errors(link)
    assert frame == good and errors >= 1


@pytest.fixture
def serial_device(pty_bridge):
    """A device (state machine, recording executor) serving the far end of a pty cable."""
    ex = RecordingExecutor()
    core = DeviceCore(ex)
    link = SerialLink(open_serial(pty_bridge.paths[1]))
    stop = threading.Event()
    thread = threading.Thread(target=serve, args=(link, core, stop, 0.02), daemon=True)
    thread.start()
    yield core, ex, pty_bridge.paths[0]
    stop.set()
    thread.join()
    link.close()


@pytest.mark.timeout(60)
def test_sender_loads_controls_and_queries_over_a_pty(serial_device):
    core, ex, path = serial_device
    words = list(range(3000))
    with SerialLink(open_serial(path)) as link:
        sender = Sender(link, timeout=0.5)
        sender.load(words)
        sender.control(FrameType.STOP)
        status = sender.status()
    assert (status.words, status.crc, status.running) == (3000, program_crc(words), False)
    assert core.active == tuple(words) and ex.started == [tuple(words)]


@pytest.mark.timeout(60)
def test_send_cli_over_a_pty(serial_device, tmp_path):
    core, ex, path = serial_device
    prog = tmp_path / "p.mem"
    prog.write_text("".join(f"{w:08x}\n" for w in PROGRAM))
    r = subprocess.run(RENDER + ["send", str(prog), "--serial", path, "--run"],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    assert f"loaded 5 words (CRC-32 {program_crc(PROGRAM):08x})" in r.stderr
    assert core.active == tuple(PROGRAM)
    assert ex.started == [tuple(PROGRAM), tuple(PROGRAM)]  # the commit, then RUN


@pytest.mark.timeout(60)
def test_raw_framing_writes_bare_big_endian_words(pty_bridge, tmp_path):
    prog = tmp_path / "p.mem"
    prog.write_text("".join(f"{w:08x}\n" for w in PROGRAM))
    far = SerialLink(open_serial(pty_bridge.paths[1]))
    r = subprocess.run(RENDER + ["send", str(prog), "--serial", pty_bridge.paths[0], "--framing", "raw"],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    got = b""
    deadline = time.monotonic() + 5
    while len(got) < 20 and time.monotonic() < deadline:
        far.port.timeout = 0.1
        got += far.port.read(20 - len(got))
    far.close()
    assert got == words_to_bytes(PROGRAM)


def test_no_device_on_the_link_fails_after_bounded_tries(tmp_path):
    prog = tmp_path / "p.mem"
    prog.write_text("00000000\n")
    r = subprocess.run(RENDER + ["send", str(prog), "--serial", "loop://", "--timeout", "0.02",
                                 "--retries", "2"], capture_output=True, text=True, timeout=60)
    assert r.returncode == 1
    assert "rend3r: error: no acknowledgement for BEGIN after 3 tries" in r.stderr
    assert "Traceback" not in r.stderr


def test_missing_and_busy_ports(pty_bridge, tmp_path):
    prog = tmp_path / "p.mem"
    prog.write_text("00000000\n")
    r = subprocess.run(RENDER + ["send", str(prog), "--serial", str(tmp_path / "ttyNONE")],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 1 and "cannot open serial port" in r.stderr and "No such file" in r.stderr
    held = open_serial(pty_bridge.paths[0])
    try:
        r = subprocess.run(RENDER + ["send", str(prog), "--serial", pty_bridge.paths[0]],
                           capture_output=True, text=True, timeout=60)
    finally:
        held.close()
    assert r.returncode == 1 and "is busy" in r.stderr, r.stderr


@pytest.mark.timeout(60)
def test_sender_over_a_socket_url(serial_device):
    """``socket://``: a TCP server relays to the pty the device listens on (like ser2net)."""
    import os
    import select
    import socket

    core, _, path = serial_device
    server = socket.create_server(("127.0.0.1", 0))
    port = server.getsockname()[1]
    fd = os.open(path, os.O_RDWR | os.O_NOCTTY)
    stop = threading.Event()

    def relay() -> None:
        conn, _ = server.accept()
        with conn:
            while not stop.is_set():
                for ready in select.select([conn, fd], [], [], 0.05)[0]:
                    if ready is conn:
                        data = conn.recv(65536)
                        if not data:
                            return
                        os.write(fd, data)
                    else:
                        conn.sendall(os.read(fd, 65536))

    thread = threading.Thread(target=relay, daemon=True)
    thread.start()
    words = list(range(700))
    try:
        with SerialLink(open_serial(f"socket://127.0.0.1:{port}")) as link:
            Sender(link, timeout=0.5).load(words)
    finally:
        stop.set()
        thread.join()
        server.close()
        os.close(fd)
    assert core.active == tuple(words)
