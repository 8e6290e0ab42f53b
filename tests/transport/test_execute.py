"""The virtual device's render step: its size option and how it writes frames."""

import logging
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from rend3r.asm.assembler import assemble_or_raise
from rend3r.transport.execute import RenderExecutor

PROGRAMS = Path(__file__).resolve().parents[2] / "programs"


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



def coloured_spheres(n: int) -> list[tuple[int, ...]]:
    """``n`` variants of sphere.asm, each with its own sphere colour (distinct programs)."""
    from rend3r.asm.assembler import assemble_source

    source = (PROGRAMS / "sphere.asm").read_text()
    out = []
    for i in range(n):
        colour = 0x0800 * (i % 31 + 1) | 0x20 * (i // 31 % 63)
        text = source.replace("0b11111_000000_00000   ; sphere, red", f"{colour} ; sphere")
        result = assemble_source(text, "<input>")
        assert result.ok, result.format_diagnostics()
        out.append(tuple(result.program.words))
    assert len(set(out)) == n
    return out


def rendered_png(words: tuple[int, ...], width: int, height: int) -> np.ndarray:
    """What the device must write for ``words``' first frame: the emulator's pixels as RGB888."""
    from rend3r.emu import EmuOptions, run_program
    from rend3r.emu.image import rgb565_to_rgb888

    frame = run_program(list(words), EmuOptions(width=width, height=height), frames=1).frames[0]
    return rgb565_to_rgb888(frame.rgb565)


def read_png(path: Path) -> np.ndarray:
    from PIL import Image

    with Image.open(path) as im:
        return np.asarray(im.convert("RGB"))


@pytest.mark.timeout(300)
def test_a_commit_storm_keeps_one_render_in_flight_and_renders_the_last_program(tmp_path):
    """Issue 13: each replaced render used to run to its end in its own thread (62 threads,
    > 10 GB at 4096x4096). Now a newer program cancels the render at its next band."""
    width, height = 4096, 512  # two bands of 256 rows: a render can be cut mid-frame
    programs = coloured_spheres(150)
    ex = RenderExecutor(tmp_path, width=width, height=height, max_frames=1, max_frame_rate=1000)
    most = 0
    try:
        for words in programs:
            ex.start(words)
            most = max(most, sum(t.name.startswith("render") and t.is_alive() for t in threading.enumerate()))
            time.sleep(0.01)
        assert _wait(lambda: (tmp_path / f"run{len(programs):04d}_frame0000.png").exists())
        assert _wait(lambda: ex.rendered[-1] == len(programs) and ex.frames >= 1)
    finally:
        ex.close(wait=60)
    assert most == 1 and not ex._thread.is_alive()
    written = sorted(tmp_path.iterdir())
    assert all(p.suffix == ".png" for p in written)  # no temporary left by a cancelled write
    assert len(written) < len(programs) // 2, "superseded programs were rendered to the end"
    last = read_png(tmp_path / f"run{len(programs):04d}_frame0000.png")
    assert np.array_equal(last, rendered_png(programs[-1], width, height))
    assert not np.array_equal(last, rendered_png(programs[-2], width, height))


@pytest.mark.timeout(300)
def test_a_newer_program_cancels_the_render_in_flight(tmp_path):
    words = coloured_spheres(2)
    ex = RenderExecutor(tmp_path, width=4096, height=2048, max_frames=1, max_frame_rate=1000)
    try:
        ex.start(words[0])  # 8 bands, about 2 s of work
        assert _wait(lambda: ex.rendered == [1])
        ex.start(words[1])
        assert _wait(lambda: (tmp_path / "run0002_frame0000.png").exists(), 120)
    finally:
        ex.close(wait=60)
    assert [p.name for p in tmp_path.iterdir()] == ["run0002_frame0000.png"]
    assert ex.rendered == [1, 2] and ex.frames == 1


def test_stop_and_close_end_the_worker(tmp_path):
    ex = RenderExecutor(tmp_path, width=4096, height=1024, max_frames=8, max_frame_rate=1000)
    ex.start(coloured_spheres(1)[0])
    assert _wait(lambda: ex.rendered == [1])
    ex.stop()
    ex.close(wait=60)
    assert not ex._thread.is_alive()
    ex.start(coloured_spheres(1)[0])  # after close: ignored, no new thread
    assert ex.runs == 1 and not ex._thread.is_alive()
