"""Frames side by side (run.py frames_at_once): the same frames, stats and hooks, in order."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from rend3r.asm.assembler import assemble_source
from rend3r.emu.loader import load_program
from rend3r.emu.options import EmuOptions
from rend3r.emu.run import FRAME_BYTES_PER_PIXEL, FRAME_BYTES_PER_SHAPE, frames_at_once, run_program
from rend3r.emu.scene import Scene

ANIMATION = load_program(Path(__file__).parents[2] / "programs" / "animation.asm").words
#: A red triangle that moves right frame by frame in front of a green one.
_SLIDE = assemble_source("\n".join([
    "nr", "cam rrot, 1", "cam hfov, 0.25", "cam vfov, 0.25",
    "tr 1, x1, y1, -1, -3", "tr 1, z1, x2, -6, 4", "tr 1, y2, z2, -2, -6", "tr 1, x3, y3, 1, 3",
    "tr 1, z3, col, -6, 0x07E0",
    "tr 0, y1, z1, -1, -4", "tr 0, y2, z2, -1, -4", "tr 0, y3, z3, 1.5, -4", "tr 0, col, col, 0xF800, 0xF800",
    *(f"tr 0, x1, x2, {-2 + k / 4}, {1 + k / 4}\ntr 0, x3, x3, {-0.5 + k / 4}, {-0.5 + k / 4}\nnf" for k in range(10)),
    "er"]))
assert _SLIDE.ok, _SLIDE.format_diagnostics()
SLIDE = _SLIDE.program.words


def _run(options: EmuOptions, frames: int = 10):
    seen, progress = [], []
    words = SLIDE if options.mode == "raster" else ANIMATION
    result = run_program(words, options, frames, on_frame=lambda f: seen.append(f.number),
                         progress=lambda n, f: progress.append((n, f)))
    return result, seen, progress


@pytest.mark.parametrize("options", [
    EmuOptions(precision="fp16", width=64, height=48),
    EmuOptions(precision="fp32", subnormals="ieee", width=33, height=17, display="rgb444"),
    EmuOptions(mode="raster", clear_frames=False, width=40, height=30),  # each frame keeps the last one's pixels
    EmuOptions(mode="hybrid", precision="fp32", width=24, height=18),
], ids=["fp16", "fp32-rgb444", "raster-keeps-pixels", "hybrid"])
def test_side_by_side_frames_equal_one_at_a_time(options):
    one, seen_one, _ = _run(replace(options, jobs=1))
    many, seen_many, progress = _run(replace(options, jobs=3))
    assert frames_at_once(replace(options, jobs=3), 10) == many.stats.at_once == 3
    assert "3 frames at a time" in many.stats.report()
    assert seen_one == seen_many == list(range(10))
    assert [n for n, f in progress if f == 1.0] == list(range(10))
    assert [s.number for s in many.stats.frames] == list(range(10))
    assert (many.stats.instructions, many.stats.halt) == (one.stats.instructions, one.stats.halt)
    for a, b in zip(one.frames, many.frames, strict=True):
        assert a.number == b.number
        assert np.array_equal(a.rgb565, b.rgb565) and np.array_equal(a.provenance, b.provenance)
        assert np.array_equal(a.depth.view(np.uint32), b.depth.view(np.uint32))
    assert len({f.rgb565.tobytes() for f in many.frames}) > 1  # the frames do differ


def test_frames_at_once_needs_a_frame_per_thread_and_the_memory():
    options = EmuOptions(width=512, height=384, jobs=4)
    frame = FRAME_BYTES_PER_PIXEL * options.pixels
    assert frames_at_once(options, 4, memory=4 * frame) == 4
    assert frames_at_once(options, 3, memory=4 * frame) == 1  # fewer frames than threads: bands
    assert frames_at_once(options, 100, memory=2 * frame) == 2
    assert frames_at_once(options, 100, memory=frame) == 1
    assert frames_at_once(replace(options, jobs=1), 100) == 1


def test_frames_wait_for_memory_the_shapes_take():
    """Memory for two frames' pixels but not their shapes as well: one frame at a time."""
    options = EmuOptions(precision="fp32", width=32, height=24, jobs=2)
    memory = 2 * FRAME_BYTES_PER_PIXEL * options.pixels + FRAME_BYTES_PER_SHAPE
    assert frames_at_once(options, 6, memory) == 2
    tight = run_program(ANIMATION, options, 6, memory=memory)
    free = run_program(ANIMATION, replace(options, jobs=1), 6)
    assert [f.number for f in tight.frames] == list(range(6))
    for a, b in zip(tight.frames, free.frames, strict=True):
        assert np.array_equal(a.rgb565, b.rgb565) and np.array_equal(a.provenance, b.provenance)


def test_a_scene_copy_keeps_its_values_when_the_scene_changes():
    options = EmuOptions(precision="fp32", width=8, height=6)
    scenes: list[Scene] = []
    run_program(ANIMATION, options, 2, on_scene=lambda s, n: scenes.append(s.copy()))
    first, second = (s.objects for s in scenes)
    assert first.index.tolist() == second.index.tolist() == [0, 1]
    assert not np.array_equal(first.values, second.values)  # the green sphere moved
