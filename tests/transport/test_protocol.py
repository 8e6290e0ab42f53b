"""Frame layout, CRC and COBS: byte-exact vectors and round trips."""

from __future__ import annotations

import zlib

import pytest
from hypothesis import given, strategies as st

from rend3r.transport import cobs
from rend3r.transport.protocol import (
    HEADER_SIZE, MAX_PAYLOAD, Frame, FrameError, FrameType, Status, bytes_to_words, decode,
    program_crc, words_to_bytes,
)
from rend3r.transport.session import load_frames

u16 = st.integers(0, 0xFFFF)
frames = st.builds(
    Frame, type=st.integers(0, 255), load=u16, seq=u16, offset=st.integers(0, 0xFFFFFFFF),
    count=u16, payload=st.binary(max_size=MAX_PAYLOAD), ref=st.integers(0, 255),
    code=st.integers(0, 255), version=st.integers(0, 255),
)


def test_data_frame_is_byte_exact():
    frame = Frame(FrameType.DATA, load=0x1234, seq=0x0102, offset=0x100, count=2,
                  payload=words_to_bytes([0x3C000009, 0x00000400]))
    body = bytes.fromhex(
        "01" "02" "1234" "0102" "0002" "00000100" "0008" "00" "00"  # header
        "3c000009" "00000400"  # payload, big-endian words
    )
    assert frame.encode() == body + zlib.crc32(body).to_bytes(4, "big")


def test_begin_and_commit_carry_length_and_program_crc():
    words = [0x200, 0x3C000009, 0x400, 0, 0]
    begin, data, commit = load_frames(words, load=7, first_seq=0xFFFF)
    info = len(words).to_bytes(4, "big") + zlib.crc32(words_to_bytes(words)).to_bytes(4, "big")
    assert (begin.type, begin.seq, begin.payload) == (FrameType.BEGIN, 0xFFFF, info)
    assert (data.seq, data.offset, data.count) == (0, 0, 5)  # sequence numbers wrap
    assert (commit.type, commit.seq, commit.payload) == (FrameType.COMMIT, 1, info)
    assert program_crc(words) == zlib.crc32(bytes.fromhex("00000200 3c000009 00000400" + "00" * 8))


def test_the_worked_example_of_docs_protocol_md():
    begin, data, commit = load_frames([0x200, 0x3C000009, 0x400, 0, 0], load=0x1234, first_seq=0x10)
    hexes = [f.encode().hex(" ") for f in (begin, data, commit, data.reply(True))]
    assert hexes == [
        "01 01 12 34 00 10 00 00 00 00 00 00 00 08 00 00 00 00 00 05 d2 45 cc b7 59 c2 20 f6",
        "01 02 12 34 00 11 00 05 00 00 00 00 00 14 00 00 00 00 02 00 3c 00 00 09 00 00 04 00"
        " 00 00 00 00 00 00 00 00 b5 91 1b d4",
        "01 03 12 34 00 12 00 00 00 00 00 00 00 08 00 00 00 00 00 05 d2 45 cc b7 c0 e0 f5 ee",
        "01 80 12 34 00 11 00 05 00 00 00 00 00 00 02 00 5b 91 69 c1",
    ]
    assert (cobs.encode(begin.encode()) + b"\0").hex(" ") == (
        "05 01 01 12 34 02 10 01 01 01 01 01 01 02 08 01 01 01 01 0a 05 d2 45 cc b7 59 c2 20 f6 00")


def test_large_programs_split_into_256_word_frames():
    words = list(range(1000))
    frames_ = load_frames(words, load=1)
    data = frames_[1:-1]
    assert [(f.offset, f.count) for f in data] == [(0, 256), (256, 256), (512, 256), (768, 232)]
    assert [w for f in data for w in bytes_to_words(f.payload)] == words


@given(frames)
def test_encode_decode_round_trip(frame):
    assert decode(frame.encode()) == frame


@given(frames, st.binary(max_size=64))
def test_padding_after_the_crc_is_ignored(frame, padding):
    assert decode(frame.encode() + padding) == frame


@given(frames, st.data())
def test_any_bit_flip_is_detected(frame, data):
    raw = bytearray(frame.encode())
    bit = data.draw(st.integers(0, 8 * len(raw) - 1))
    raw[bit // 8] ^= 1 << (bit % 8)
    with pytest.raises(FrameError):
        decode(bytes(raw))


@given(frames, st.data())
def test_truncation_is_detected(frame, data):
    raw = frame.encode()
    cut = data.draw(st.integers(0, len(raw) - 1))
    with pytest.raises(FrameError):
        decode(raw[:cut])


def test_short_and_overlong_length_rejected():
    with pytest.raises(FrameError, match="shorter"):
        decode(bytes(HEADER_SIZE))
    raw = bytearray(Frame(FrameType.STATUS).encode())
    raw[12:14] = (100).to_bytes(2, "big")
    with pytest.raises(FrameError, match="length field"):
        decode(bytes(raw))


def test_status_round_trip_and_size_check():
    status = Status(words=5, crc=0xDEADBEEF, frames=3, running=True, staging=False, load=9,
                    malformed=2, loads=1)
    assert Status.unpack(status.pack()) == status
    assert len(status.pack()) == 24
    with pytest.raises(FrameError):
        Status.unpack(status.pack()[:-1])


@given(st.binary(max_size=2000))
def test_cobs_round_trip_without_zeros(data):
    encoded = cobs.encode(data)
    assert 0 not in encoded
    assert len(encoded) <= len(data) + len(data) // 254 + 1
    assert cobs.decode(encoded) == data


@given(st.integers(0, 3), st.sampled_from([0, 1, 253, 254, 255, 508, 509]))
def test_cobs_block_boundaries(fill, n):
    data = bytes([fill]) * n
    assert cobs.decode(cobs.encode(data)) == data


def test_cobs_vectors():
    # the examples of Cheshire and Baker's paper / Wikipedia
    assert cobs.encode(b"\x00") == b"\x01\x01"
    assert cobs.encode(b"\x00\x00") == b"\x01\x01\x01"
    assert cobs.encode(b"\x11\x22\x00\x33") == b"\x03\x11\x22\x02\x33"
    assert cobs.encode(b"\x11\x00\x00\x00") == b"\x02\x11\x01\x01\x01"


@pytest.mark.parametrize("bad", [b"\x05\x11", b"\x02\x00", b"\x00"])
def test_cobs_rejects_invalid(bad):
    with pytest.raises(cobs.CobsError):
        cobs.decode(bad)
