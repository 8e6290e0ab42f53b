"""COBS at every block boundary: exact bytes against a byte-at-a-time reference, round trips,
and loads over a real pty whose frames hold runs of 253-256 non-zero bytes and zeros at each
position (issue 13: an encoder splitting at 255 instead of 254 passed the old suite)."""

from __future__ import annotations

import sys
import threading
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rend3r.transport import cobs
from rend3r.transport.cli import serve
from rend3r.transport.device import DeviceCore
from rend3r.transport.links import SerialLink, open_serial
from rend3r.transport.protocol import program_crc
from rend3r.transport.session import Sender, load_frames

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "firmware" / "tests"))
from cobs_patterns import BOUNDARY_RUNS, boundary_words

X = b"\x5a"


def reference_encode(data: bytes) -> bytes:
    """Cheshire and Baker's encoder, one byte at a time: the oracle for ``cobs.encode``."""
    out = bytearray([0])
    code_at, code = 0, 1
    for byte in data:
        if byte:
            out.append(byte)
            code += 1
        if not byte or code == 0xFF:
            out[code_at] = code
            code_at, code = len(out), 1
            out.append(0)
    out[code_at] = code
    return bytes(out)


def check(data: bytes) -> None:
    encoded = cobs.encode(data)
    assert encoded == reference_encode(data)
    assert 0 not in encoded and len(encoded) <= len(data) + len(data) // 254 + 1
    assert cobs.decode(encoded) == data


def test_a_254_byte_run_then_a_zero_is_a_full_block_then_an_empty_one():
    assert cobs.encode(X * 254 + b"\0") == b"\xff" + X * 254 + b"\x01\x01"
    assert cobs.encode(X * 254) == b"\xff" + X * 254 + b"\x01"
    assert cobs.encode(X * 253 + b"\0") == b"\xfe" + X * 253 + b"\x01"
    assert cobs.encode(X * 255 + b"\0") == b"\xff" + X * 254 + b"\x02" + X + b"\x01"


@pytest.mark.parametrize("run", [0, 1, 2, 252, 253, 254, 255, 256, 507, 508, 509, 510, 762])
@pytest.mark.parametrize("before, after", [(b"", b""), (b"", b"\0"), (b"\0", b"\0\x11"), (b"\x22\0", b"\0\0")])
def test_runs_at_block_boundaries(run, before, after):
    check(before + X * run + after)


def test_a_zero_at_each_position_of_a_long_frame():
    for n in (253, 254, 255, 256, 600):
        for i in range(n):
            data = bytearray(X * n)
            data[i] = 0
            check(bytes(data))
            data[(i + 254) % n] = 0  # and a second zero one block further
            check(bytes(data))


@pytest.mark.parametrize("k", [1, 2, 3, 4])
def test_repeated_254_byte_runs_each_followed_by_a_zero(k):
    check((X * 254 + b"\0") * k)
    check(b"\0" + (X * 254 + b"\0") * k + X * 254)


@settings(max_examples=150, deadline=None)
@given(st.lists(st.tuples(st.integers(250, 258), st.integers(0, 2)), max_size=6))
def test_random_runs_near_the_boundary(parts):
    check(b"".join(X * run + b"\0" * zeros for run, zeros in parts))


def test_boundary_programs_make_frames_with_those_runs():
    words = boundary_words()
    frames = load_frames(words, 0x1111, 1)[1:-1]
    assert len(frames) == len(BOUNDARY_RUNS)
    for frame, runs in zip(frames, BOUNDARY_RUNS):
        data = frame.encode()
        assert data[15] == 0 and len(data) > 254
        assert [len(r) for r in data[16:].split(b"\0")[:len(runs)]] == list(runs)
        check(data)


@pytest.mark.parametrize("bad", [b"\x05\x11", b"\x02\x00", b"\x00", b"\xff" + X * 253, b"\x03\x11\x00"])
def test_invalid_encodings_are_rejected(bad):
    with pytest.raises(cobs.CobsError):
        cobs.decode(bad)


@pytest.mark.timeout(120)
def test_boundary_frames_load_over_a_real_pty(pty_bridge):
    """Every DATA frame crosses block boundaries on a pty; no frame may need a resend."""
    core = DeviceCore()
    stop = threading.Event()
    device_link = SerialLink(open_serial(pty_bridge.paths[1]))
    thread = threading.Thread(target=serve, args=(device_link, core, stop, 0.02), daemon=True)
    thread.start()
    words = boundary_words()
    try:
        with SerialLink(open_serial(pty_bridge.paths[0])) as link:
            sender = Sender(link, timeout=2.0, retries=2)
            sender.load(words)
            status = sender.status()
    finally:
        stop.set()
        thread.join()
        device_link.close()
    assert (status.words, status.crc) == (len(words), program_crc(words))
    assert core.active == tuple(words)
    assert core.counters.malformed == 0 and sender.stats.resends == 0
