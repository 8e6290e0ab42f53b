"""Programs whose DATA frames put a zero after runs of non-zero bytes at COBS block boundaries.

A COBS block holds at most 254 data bytes; the cases that break a wrong encoder or decoder
are runs of 253, 254, 255 and 256 non-zero bytes, a run of exactly 254 followed by a zero,
and zeros back to back. A request's header ends with a zero byte (``code`` = 0), so a run
counted from the start of the payload is the run a COBS encoder sees. Used by the Python
tests (tests/transport/test_cobs.py) and the co-simulation (test_loader.py). No cocotb here.
"""

from __future__ import annotations

from rend3r.transport.protocol import MAX_DATA_WORDS, bytes_to_words

FILL = 0x5A
#: Per DATA frame: lengths of the runs of non-zero bytes, each followed by one zero.
BOUNDARY_RUNS = (
    (254, 254, 254),  # 254 then a zero, three times in one frame
    (253, 255, 256),
    (0, 254, 0, 254),  # zeros back to back around a 254-byte run
    (255, 254, 254),
    (),  # no zero in 1,024 bytes: four full blocks and a tail
)


def boundary_words(runs_per_frame=BOUNDARY_RUNS, frame_words: int = MAX_DATA_WORDS) -> list[int]:
    """A program that ``load_frames(words, ..., chunk=frame_words)`` splits into DATA frames
    whose payloads hold the runs of ``runs_per_frame``, one tuple per frame."""
    out = bytearray()
    for runs in runs_per_frame:
        payload = bytearray([FILL]) * (4 * frame_words)
        pos = -1  # the header's last byte is zero
        for run in runs:
            pos += run + 1
            payload[pos] = 0
        out += payload
    return bytes_to_words(bytes(out))
