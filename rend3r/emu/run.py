"""Running a program: the processor drives the renderer at every ``nf``."""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Callable, Sequence

import numpy as np

from .frame import Frame
from .options import EmuOptions
from .processor import execute
from .scene import Scene
from .stats import RunStats

FrameHook = Callable[[Frame], None]
#: Called at each ``nf`` with the scene about to be rendered and the frame number.
SceneHook = Callable[[Scene, int], None]
#: Called during rendering with (frame number, fraction of that frame done).
ProgressHook = Callable[[int, float], None]


@dataclass
class RunResult:
    frames: list[Frame] = field(default_factory=list)
    stats: RunStats = field(default_factory=RunStats)


def rgb444_display(rgb565: np.ndarray) -> np.ndarray:
    """What the device's monitor shows: the low 12 bits as RGB444, back in RGB565 form
    (each 4-bit channel widened by bit replication)."""
    c = rgb565.astype(np.uint16)
    r, g, b = (c >> 8) & 0xF, (c >> 4) & 0xF, c & 0xF
    return ((((r << 1) | (r >> 3)) << 11) | (((g << 2) | (g >> 2)) << 5) | ((b << 1) | (b >> 3))).astype(np.uint16)


def _renderer(options: EmuOptions):
    if options.mode == "hybrid":
        from .hybrid import render_frame as hybrid_frame

        return hybrid_frame
    if options.mode == "raster":
        from .raster import render_frame

        return render_frame
    from .raytracer import render_frame

    return render_frame


def run_program(
    words: Sequence[int],
    options: EmuOptions | None = None,
    frames: int | None = None,
    on_frame: FrameHook | None = None,
    progress: ProgressHook | None = None,
    keep_frames: bool = True,
    on_scene: SceneHook | None = None,
) -> RunResult:
    """Execute ``words``, rendering a frame at each ``nf`` (up to ``frames`` frames).

    The processor validates the control flow before the first frame, so decoding errors
    and unbounded loops are reported before any time is spent on frames.
    ``keep_frames=False`` leaves ``result.frames`` empty (use ``on_frame`` to consume
    frames as they come).
    ``on_scene`` sees each frame's scene (pixel traces use it).
    """
    options = options or EmuOptions()
    render = _renderer(options)
    result = RunResult()

    previous: list[Frame] = []

    def on_nf(scene: Scene, number: int) -> None:
        hook = (lambda f: progress(number, f)) if progress is not None else None
        if on_scene is not None:
            on_scene(scene, number)
        frame, st = render(scene, options, number, hook)
        if options.mode == "raster" and not options.clear_frames and previous:
            kept = np.where(frame.provenance >= 0, frame.rgb565, previous[0].rgb565)
            frame = replace(frame, rgb565=kept.astype(np.uint16))
        previous[:] = [frame]
        if options.display == "rgb444":
            frame = replace(frame, rgb565=rgb444_display(frame.rgb565))
        result.stats.frames.append(st)
        if keep_frames:
            result.frames.append(frame)
        if on_frame is not None:
            on_frame(frame)

    ex = execute(words, options, frames, on_nf)
    result.stats.instructions, result.stats.halt = ex.instructions, ex.halt
    return result
