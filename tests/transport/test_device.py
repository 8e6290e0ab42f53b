"""The device state machine: atomic commit, idempotence, limits, control, malformed input."""

from __future__ import annotations

import pytest
from hypothesis import given, settings, strategies as st

from rend3r.transport.device import DeviceCore, RecordingExecutor
from rend3r.transport.protocol import (
    LIMIT, PROGRAM_INFO, Frame, FrameType, Nack, Status, decode, program_crc, words_to_bytes,
)
from rend3r.transport.session import load_frames

PROGRAM = [0x200, 0x3C000009, 0x400, 0, 0]


def ask(core: DeviceCore, frame: Frame) -> Frame:
    reply = core.handle(frame.encode())
    assert reply is not None
    return decode(reply)


def load(core: DeviceCore, words, load_id: int = 1) -> list[Frame]:
    return [ask(core, f) for f in load_frames(words, load_id)]


def test_load_commits_and_starts_the_program():
    ex = RecordingExecutor()
    core = DeviceCore(ex)
    replies = load(core, PROGRAM)
    assert all(r.type == FrameType.ACK for r in replies)
    assert [r.ref for r in replies] == [FrameType.BEGIN, FrameType.DATA, FrameType.COMMIT]
    assert core.active == tuple(PROGRAM) and ex.started == [tuple(PROGRAM)]
    st_ = Status.unpack(ask(core, Frame(FrameType.STATUS, seq=9)).payload)
    assert (st_.words, st_.crc, st_.loads, st_.running, st_.staging) == (5, program_crc(PROGRAM), 1, True, False)


def test_commit_without_all_data_is_refused_and_old_program_keeps_running():
    ex = RecordingExecutor()
    core = DeviceCore(ex)
    load(core, PROGRAM, 1)
    new = list(range(1, 600))
    begin, d0, d1, d2, commit = load_frames(new, 2)
    for f in (begin, d0, d2):  # d1 lost
        assert ask(core, f).type == FrameType.ACK
    r = ask(core, commit)
    assert (r.type, r.code) == (FrameType.NACK, Nack.MISMATCH)
    assert core.active == tuple(PROGRAM) and ex.started == [tuple(PROGRAM)]
    assert ask(core, d1).type == FrameType.ACK
    assert ask(core, commit).type == FrameType.ACK
    assert core.active == tuple(new) and ex.started[-1] == tuple(new)


def test_commit_with_wrong_crc_is_refused():
    core = DeviceCore()
    begin, data, _ = load_frames(PROGRAM, 3)
    ask(core, begin), ask(core, data)
    bad = Frame(FrameType.COMMIT, 3, 50, payload=PROGRAM_INFO.pack(5, program_crc(PROGRAM) ^ 1))
    assert ask(core, bad).code == Nack.MISMATCH
    assert core.active == ()


def test_duplicates_are_harmless():
    ex = RecordingExecutor()
    core = DeviceCore(ex)
    begin, data, commit = load_frames(PROGRAM, 4)
    for f in (begin, begin, data, begin, data, commit, commit, data, begin, commit):
        assert ask(core, f).type == FrameType.ACK
    assert core.active == tuple(PROGRAM) and ex.started == [tuple(PROGRAM)]
    assert core.counters.loads == 1


def test_stale_data_from_another_load_is_refused():
    core = DeviceCore()
    _, old_data, _ = load_frames([7, 7, 7], 5)
    begin, data, commit = load_frames(PROGRAM, 6)
    ask(core, begin)
    assert ask(core, old_data).code == Nack.NO_LOAD
    ask(core, data)
    assert ask(core, commit).type == FrameType.ACK and core.active == tuple(PROGRAM)


def test_out_of_range_data_and_size_limit():
    core = DeviceCore(max_words=4)
    r = ask(core, load_frames(PROGRAM, 1)[0])
    assert (r.type, r.code, LIMIT.unpack(r.payload)[0]) == (FrameType.NACK, Nack.TOO_LARGE, 4)
    begin, _, _ = load_frames([1, 2], 2)
    ask(core, begin)
    beyond = Frame(FrameType.DATA, 2, 3, offset=1, count=2, payload=words_to_bytes([1, 2]))
    assert ask(core, beyond).code == Nack.OUT_OF_RANGE


@pytest.mark.parametrize("frame, code", [
    (Frame(FrameType.DATA, 1, 1, count=2, payload=b"\0" * 4), Nack.BAD_FIELDS),
    (Frame(FrameType.DATA, 1, 1, count=0), Nack.BAD_FIELDS),
    (Frame(FrameType.DATA, 1, 1, count=257, payload=b"\0" * 1028), Nack.BAD_FIELDS),
    (Frame(FrameType.BEGIN, 1, 1, payload=b"\0" * 7), Nack.BAD_FIELDS),
    (Frame(FrameType.RUN, 1, 1, payload=b"x"), Nack.BAD_FIELDS),
    (Frame(0x42, 1, 1), Nack.BAD_TYPE),
    (Frame(FrameType.STATUS, 1, 1, version=2), Nack.BAD_VERSION),
    (Frame(FrameType.COMMIT, 1, 1, payload=PROGRAM_INFO.pack(0, 0)), Nack.NO_LOAD),
])
def test_bad_requests_are_nacked_with_a_reason(frame, code):
    core = DeviceCore()
    r = ask(core, frame)
    assert (r.type, r.code, r.seq, r.ref) == (FrameType.NACK, code, frame.seq, frame.type)
    assert core.counters.nacks[code] == 1


def test_replies_sent_to_the_device_are_ignored_and_counted():
    core = DeviceCore()
    assert core.handle(Frame(FrameType.ACK).encode()) is None
    assert core.counters.unexpected == 1


@settings(max_examples=300)
@given(st.binary(max_size=300))
def test_garbage_never_crashes_and_never_commits(data):
    ex = RecordingExecutor()
    core = DeviceCore(ex)
    reply = core.handle(data)
    assert reply is None or decode(reply).type in (FrameType.ACK, FrameType.NACK)
    assert core.active == () and ex.started == []


def test_run_stop_reset():
    ex = RecordingExecutor()
    core = DeviceCore(ex)
    load(core, PROGRAM)
    ask(core, Frame(FrameType.STOP, seq=1))
    assert ex.running is None and not core.running
    new = [0x400, 0, 0]
    load(core, new, 2)  # committed while stopped: swapped in, not started
    assert core.active == tuple(new) and ex.started == [tuple(PROGRAM)]
    ask(core, Frame(FrameType.RUN, seq=2))
    assert ex.running == tuple(new)
    core.handle(b"junk")
    ask(core, Frame(FrameType.RESET, seq=3))
    status = core.status()
    assert (status.words, status.loads, status.malformed, status.running) == (0, 0, 0, True)
    assert ex.running is None
