"""The virtual device's render step: its size option and how it writes frames."""

import logging
import time
from pathlib import Path

import pytest

from rend3r.asm.assembler import assemble_or_raise
from rend3r.errors import Rend3rError
from rend3r.transport.execute import MAX_DEVICE_SIDE, RenderExecutor, parse_size

PROGRAMS = Path(__file__).resolve().parents[2] / "programs"


def test_size_uses_the_shared_parser_with_the_device_cap():
    assert parse_size("128x96") == (128, 96)
    assert parse_size(f"{MAX_DEVICE_SIDE}x1") == (MAX_DEVICE_SIDE, 1)
    for text, why in (("0x5", "1..4096"), ("4097x1", "1..4096"), ("١٢x3", "WIDTHxHEIGHT"), ("big", "WIDTHxHEIGHT")):
        with pytest.raises(Rend3rError, match=f"malformed size: .*{why}"):
            parse_size(text)


def _wait(cond, seconds=60.0):
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        if cond():
            return True
        time.sleep(0.02)
    return False


@pytest.mark.timeout(120)
def test_frames_are_written_whole_and_a_missing_folder_is_logged_not_created(tmp_path, caplog):
    words = tuple(assemble_or_raise(PROGRAMS / "sphere.asm").program.words)
    ex = RenderExecutor(tmp_path, width=8, height=6, max_frames=1, max_frame_rate=1000)
    ex.start(words)
    assert _wait(lambda: ex.frames == 1)
    ex.close()
    assert [p.name for p in tmp_path.iterdir()] == ["run0001_frame0000.png"]  # no temporary left
    gone = tmp_path / "gone"
    lost = RenderExecutor(gone, width=8, height=6, max_frames=1, max_frame_rate=1000)
    with caplog.at_level(logging.WARNING, logger="rend3r.device"):
        lost.start(words)
        assert _wait(lambda: "does not exist" in caplog.text)
        lost.close()
    assert lost.frames == 0 and not gone.exists()
