"""Hypothesis fuzzing of the device's frame parser and state machine, with a fixed budget.

Frames come as raw garbage, as field-level random frames with a correct CRC (any version,
type, load, seq, count, offset, payload length), as loads of random programs delivered out
of order, duplicated, dropped and interleaved, and as valid frames with flipped bits,
truncation, huge ``length`` fields and bad CRCs. After every frame the device must not have
raised, its reply must be a well-formed ACK/NACK echoing the request, and the active program
may only have changed through an acknowledged COMMIT whose length and CRC it carries (or a
RESET). Streams of the same material go through the serial link's COBS framing too.
"""

from __future__ import annotations

import threading
import time

import zlib

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rend3r.transport import cobs
from rend3r.transport.device import DeviceCore, RecordingExecutor
from rend3r.transport.links import SerialLink, open_serial
from rend3r.transport.protocol import (
    HEADER,
    HEADER_SIZE,
    MAX_FRAME,
    PROGRAM_INFO,
    Frame,
    FrameError,
    FrameType,
    bytes_to_words,
    decode,
    program_crc,
)
from rend3r.transport.session import load_frames

#: The fixed CI budget: about 25 s for the three suites on the 2-core machine.
BUDGET = settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
SMALL_BUDGET = settings(BUDGET, max_examples=60)
MAX_WORDS = 1024  # the device's limit here: BEGINs beyond it are refused, not allocated

u8, u16, u32 = st.integers(0, 0xFF), st.integers(0, 0xFFFF), st.integers(0, 0xFFFFFFFF)
small_words = st.binary(max_size=2400).map(lambda b: bytes_to_words(b[:len(b) // 4 * 4]))


def crc_fixed(body: bytes) -> bytes:
    return body + zlib.crc32(body).to_bytes(4, "big")


@st.composite
def field_frames(draw) -> bytes:
    """A frame with arbitrary header fields and payload, its CRC correct (the parser's checks
    beyond the CRC are what is fuzzed); the ``length`` field may disagree with the payload."""
    payload = draw(st.one_of(st.binary(max_size=40), st.binary(min_size=1000, max_size=1100)))
    ftype = draw(st.one_of(st.sampled_from(list(FrameType)), u8))
    if ftype in (FrameType.BEGIN, FrameType.COMMIT) and draw(st.booleans()):
        payload = PROGRAM_INFO.pack(draw(st.one_of(st.integers(0, MAX_WORDS + 1), u32)), draw(u32))
    length = len(payload) if draw(st.integers(0, 3)) else draw(u16)
    header = HEADER.pack(draw(st.sampled_from([1, 1, 1, 0, 2, 0xFF])), ftype, draw(u16), draw(u16),
                         draw(st.one_of(st.integers(0, 257), u16)), draw(st.one_of(st.integers(0, 2048), u32)),
                         length, draw(u8), draw(u8))
    body = header + payload
    if length <= len(payload):
        return crc_fixed(header + payload[:length]) + payload[length:]  # trailing bytes: padding
    return body + draw(st.binary(max_size=8))  # claims more than it has: truncated


@st.composite
def mangled(draw, frames: list[bytes]) -> bytes:
    """One of ``frames`` with a fault: bit flips, truncation, a huge length, a bad CRC."""
    data = bytearray(draw(st.sampled_from(frames)))
    fault = draw(st.sampled_from(["flip", "truncate", "length", "crc", "extend"]))
    if fault == "flip":
        for _ in range(draw(st.integers(1, 4))):
            data[draw(st.integers(0, len(data) - 1))] ^= 1 << draw(st.integers(0, 7))
    elif fault == "truncate":
        del data[draw(st.integers(0, len(data) - 1)):]
    elif fault == "length":
        data[12:14] = draw(st.sampled_from([0xFFFF, 0x0405, len(data) - 19, len(data)])).to_bytes(2, "big")
        if draw(st.booleans()):
            end = HEADER_SIZE + int.from_bytes(data[12:14], "big")
            if end <= len(data) - 4:
                data[end:end + 4] = zlib.crc32(data[:end]).to_bytes(4, "big")
    elif fault == "crc":
        data[-1] ^= 0xFF
    else:
        data += draw(st.binary(min_size=1, max_size=64))
    return bytes(data)


@st.composite
def sessions(draw) -> list[bytes]:
    """Loads of 1-3 random programs, out of order, duplicated, dropped, mangled, interleaved
    with field-level frames and garbage: what a hostile or broken peer might send."""
    pool: list[bytes] = []
    for _ in range(draw(st.integers(1, 3))):
        words = draw(small_words)
        pool += [f.encode() for f in load_frames(words, draw(st.integers(1, 3)), draw(u16),
                                                 draw(st.sampled_from([7, 64, 256])))]
    control = [Frame(t, 0, draw(u16)).encode() for t in (FrameType.RUN, FrameType.STOP, FrameType.RESET,
                                                        FrameType.STATUS)]
    pool += control
    items = st.one_of(st.sampled_from(pool), st.sampled_from(pool), mangled(pool), field_frames(),
                      st.binary(max_size=64))
    ordered = draw(st.booleans())
    return pool + draw(st.lists(items, max_size=30)) if ordered else draw(st.lists(items, max_size=60))


def well_formed(data: bytes) -> bool:
    """docs/protocol.md's rule, independently of the parser: 20 bytes at least, ``length``
    within the bytes received, CRC-32 of header and payload in the next four bytes."""
    if len(data) < 20:
        return False
    end = 16 + int.from_bytes(data[12:14], "big")
    return end + 4 <= len(data) and zlib.crc32(data[:end]) == int.from_bytes(data[end:end + 4], "big")


def feed(core: DeviceCore, data: bytes) -> None:
    """One frame into the device, checking the reply and the active program's invariant."""
    before, malformed = core.active, core.counters.malformed
    request = decode(data) if well_formed(data) else None
    reply = core.handle(data)
    if request is None:
        assert reply is None and core.counters.malformed == malformed + 1
        assert core.active == before
        return
    if request.type != FrameType.RESET:  # RESET zeroes the counters
        assert core.counters.malformed == malformed
    if reply is None:
        assert request.version == 1 and request.type in (FrameType.ACK, FrameType.NACK)
    else:
        r = decode(reply)
        assert r.type in (FrameType.ACK, FrameType.NACK) and r.version == 1
        assert (r.load, r.seq, r.offset, r.count, r.ref) == (
            request.load, request.seq, request.offset, request.count, request.type)
        assert len(reply) <= MAX_FRAME
    if core.active != before:
        assert reply is not None and decode(reply).type == FrameType.ACK
        if request.type == FrameType.COMMIT:
            assert PROGRAM_INFO.unpack(request.payload) == (len(core.active), program_crc(core.active))
        else:
            assert request.type == FrameType.RESET and core.active == ()
    assert core.active_crc == program_crc(core.active) and len(core.active) <= MAX_WORDS


@BUDGET
@given(sessions())
def test_sessions_never_crash_and_only_acknowledged_commits_change_the_program(frames):
    ex = RecordingExecutor()
    core = DeviceCore(ex, max_words=MAX_WORDS)
    active = {()}
    for data in frames:
        feed(core, data)
        active.add(core.active)
    assert set(ex.started) <= active  # the executor only ever ran a committed program


@settings(BUDGET, max_examples=100)
@given(st.lists(st.one_of(field_frames(), st.binary(max_size=1100)), max_size=20))
def test_field_level_frames_and_garbage(frames):
    core = DeviceCore(max_words=MAX_WORDS)
    for data in frames:
        feed(core, data)


@SMALL_BUDGET
@given(sessions(), st.lists(st.binary(max_size=300), max_size=4), st.randoms(use_true_random=False))
def test_the_serial_link_frames_any_byte_stream(frames, noise, rng):
    """Frames COBS-encoded (some corrupted after encoding) with noise between them, through
    loop://: the link yields frames or FrameError, never anything else, and resynchronises."""
    link = SerialLink(open_serial("loop://"))
    core = DeviceCore(max_words=MAX_WORDS)
    wire = bytearray(b"\0")
    for i, data in enumerate(frames):
        encoded = bytearray(cobs.encode(data))
        if rng.random() < 0.2:
            encoded[rng.randrange(len(encoded))] = rng.randrange(256)
        wire += encoded + b"\0"
        if noise and rng.random() < 0.3:
            wire += noise[i % len(noise)]
    marker = Frame(FrameType.STATUS, 0xBEEF, 0xBEEF).encode()
    wire += b"\0" + cobs.encode(marker) + b"\0"
    # loop:// holds 4,096 bytes: a longer stream written at once would block for ever, so a
    # thread writes while this one reads, as the two ends of a real link do
    writer = threading.Thread(target=link.write, args=(bytes(wire),), daemon=True)
    writer.start()
    last = None
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        try:
            data = link.recv(0.05)
        except FrameError:
            continue
        if data is None:
            if writer.is_alive():  # the writer is behind: wait for more bytes
                continue
            break
        feed(core, data)
        last = data
        if data == marker:
            break
    writer.join(timeout=10)
    assert not writer.is_alive()
    assert last == marker  # the link ends in sync
    assert len(link._buf) == 0
