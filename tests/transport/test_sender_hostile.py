"""``rend3r send`` against a hostile device: fixed scenarios of ``fuzz/sender.py``.

Each runs the real command over ``socket://`` to a device on loopback whose replies are
hostile, and checks the verdict the long fuzz run checks: exit 0 when the exchange still
completes, exit 1 with an ``error:`` naming the problem otherwise, never a traceback, a
signal or a hang, and a peak RSS within the fuzz run's bound.
"""

from __future__ import annotations

import importlib.util
import os
import resource
import sys
import threading
import tty
from pathlib import Path

import pytest
from serial import SerialException

from rend3r.transport import cobs
from rend3r.transport.device import DeviceCore
from rend3r.transport.links import DirectLink, SerialLink, open_serial
from rend3r.transport.protocol import FrameType, Nack, decode
from rend3r.transport.session import Sender, SendError

_spec = importlib.util.spec_from_file_location(
    "fuzz_sender", Path(__file__).resolve().parents[2] / "fuzz" / "sender.py")
hostile = sys.modules[_spec.name] = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(hostile)

SCENARIOS = [
    # behaviour, words, --timeout, --retries, what stderr must say
    ("honest", 700, 0.5, 2, "loaded 700 words"),
    ("phantom-acks", 700, 0.5, 2, "loaded 700 words"),
    ("dup-reorder", 700, 0.5, 2, "loaded 700 words"),
    ("trickle", 300, 3.0, 1, "loaded 300 words"),
    ("silence", 700, 0.1, 2, "error: no acknowledgement for BEGIN after 3 tries"),
    ("stall", 700, 0.1, 1, "error: no acknowledgement for "),
    ("close", 700, 0.1, 2, "the link failed"),
    ("status-lies", 700, 0.5, 2, "error: the device"),
    ("too-large", 700, 0.5, 2, "error: the device refused DATA: TOO_LARGE"),
    ("fields", 700, 0.05, 1, ""),
    ("garbage", 700, 0.05, 1, ""),
    ("nack-storm", 700, 0.05, 1, ""),
    ("mixed", 3000, 0.05, 3, ""),
]


@pytest.mark.timeout(120)
@pytest.mark.parametrize("behaviour, words, timeout, retries, says", SCENARIOS)
def test_send_against_a_hostile_device(tmp_path, behaviour, words, timeout, retries, says):
    case = hostile.Case(behaviour, seed=5, words=words, timeout=timeout, retries=retries, run=True)
    result = hostile.run_sender(case, tmp_path)
    assert result.ok and not result.timed_out, result.stderr
    assert result.returncode in hostile.BEHAVIOURS[behaviour], result.stderr
    assert result.returncode == 0 or "rend3r: error: " in result.stderr, result.stderr
    assert says in result.stderr
    assert result.seconds < case.bound
    # Linux keeps a forked child's RSS high-water mark across exec, so the child's figure
    # starts at this (pytest) process's RSS.
    assert result.rss_bytes <= hostile.MAX_RSS + resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


@pytest.mark.parametrize("request_type", [FrameType.DATA, FrameType.COMMIT, FrameType.STATUS])
def test_too_large_for_a_frame_that_is_not_begin_is_refused_by_name(request_type):
    """TOO_LARGE answers BEGIN; for any other request it is a protocol mismatch, not a crash."""
    core = DeviceCore()

    def handle(data: bytes) -> bytes | None:
        request = decode(data)
        if request.type == request_type:
            return request.reply(False, Nack.TOO_LARGE).encode()
        return core.handle(data)

    sender = Sender(DirectLink(handle), timeout=0.1, retries=1)
    with pytest.raises(SendError, match=f"refused {request_type.name}: TOO_LARGE"):
        sender.load(list(range(300)))
        sender.status()


def test_too_large_for_begin_names_the_limit():
    sender = Sender(DirectLink(lambda data: decode(data).reply(False, Nack.TOO_LARGE, b"\0\0\1\0").encode()),
                    timeout=0.1, retries=1)
    with pytest.raises(SendError, match="refuses a program of 300 words: its limit is 256"):
        sender.load(list(range(300)))


@pytest.mark.timeout(60)
def test_a_device_that_stops_reading_a_pty_ends_the_send():
    """A device that acknowledges BEGIN and then stops reading fills the pty's few KiB:
    the sender's writes must give up like its reads do, not block for ever."""
    master, slave = os.openpty()
    tty.setraw(slave)
    core = DeviceCore()

    def answer_begin_then_stall() -> None:
        data = b""
        while b"\0" not in data.lstrip(b"\0"):
            data += os.read(master, 4096)
        frame = data.lstrip(b"\0").split(b"\0")[0]
        os.write(master, cobs.encode(core.handle(cobs.decode(frame))) + b"\0")

    threading.Thread(target=answer_begin_then_stall, daemon=True).start()
    outcome: list[BaseException | None] = []

    def send() -> None:
        try:
            with SerialLink(open_serial(os.ttyname(slave))) as link:
                Sender(link, timeout=0.05, retries=1).load(list(range(20000)))
            outcome.append(None)
        except BaseException as exc:  # noqa: BLE001 - what the test checks
            outcome.append(exc)

    sender = threading.Thread(target=send, daemon=True)
    sender.start()
    sender.join(20)
    try:
        assert not sender.is_alive(), "the sender blocked in a write"
        assert isinstance(outcome[0], SerialException) and "timeout" in str(outcome[0]).lower()
    finally:
        os.close(master)
        os.close(slave)
