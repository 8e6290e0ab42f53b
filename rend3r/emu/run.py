"""Running a program: the processor drives the renderer at every ``nf``."""

from __future__ import annotations

from collections import deque
from contextlib import nullcontext
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass, field, replace
from functools import lru_cache
from time import perf_counter
from typing import Callable, Sequence

import numpy as np

from . import threads
from .frame import Frame
from .options import EmuOptions
from .processor import plan
from .scene import Scene
from .stats import FrameStats, RunStats

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


@lru_cache(maxsize=None)
def _renderer(mode: str):
    """The render_frame of ``mode``, imported when first asked for."""
    if mode == "hybrid":
        from .hybrid import render_frame as hybrid_frame

        return hybrid_frame
    if mode == "raster":
        from .raster import render_frame

        return render_frame
    from .raytracer import render_frame

    return render_frame


#: Working memory of a frame in flight, per pixel and per shape or triangle, at most (every
#: mode: the raytracer's band arrays take about 85 bytes a pixel; the scene's copy, shape
#: tables, tree and bounds about 480 bytes a shape), and what frames in flight may hold
#: together by default.
FRAME_BYTES_PER_PIXEL = 128
FRAME_BYTES_PER_SHAPE = 512
FLIGHT_BYTES = 512 << 20


def frame_bytes(options: EmuOptions, scene: Scene) -> int:
    """The most a frame of ``scene`` holds while it renders (FRAME_BYTES_PER_*)."""
    return FRAME_BYTES_PER_PIXEL * options.pixels + FRAME_BYTES_PER_SHAPE * (len(scene.objects) + len(scene.triangles))


def frames_at_once(options: EmuOptions, count: int, memory: int = FLIGHT_BYTES) -> int:
    """How many of a run's ``count`` frames render side by side, each on one thread: one per
    thread when the run has a frame for every thread and ``memory`` holds that many frames'
    working arrays; else 1 (each frame then splits over the threads)."""
    jobs = options.jobs or threads.available_cores()
    at_once = min(jobs, memory // (FRAME_BYTES_PER_PIXEL * options.pixels))
    return at_once if 1 < jobs <= count and at_once > 1 else 1


def run_program(
    words: Sequence[int],
    options: EmuOptions | None = None,
    frames: int | None = None,
    on_frame: FrameHook | None = None,
    progress: ProgressHook | None = None,
    keep_frames: bool = True,
    on_scene: SceneHook | None = None,
    memory: int = FLIGHT_BYTES,
) -> RunResult:
    """Execute ``words``, rendering a frame at each ``nf`` (up to ``frames`` frames).

    The processor validates the control flow before the first frame, so decoding errors
    and unbounded loops are reported before any time is spent on frames.
    ``keep_frames=False`` leaves ``result.frames`` empty (use ``on_frame`` to consume
    frames as they come, in order). ``on_scene`` sees each frame's scene (pixel traces use
    it). A run with a frame for every thread renders frames side by side (a copy of each
    scene per thread, their working arrays within ``memory`` bytes); the frames are the same.
    """
    start = perf_counter()
    options = options or EmuOptions()
    render = _renderer(options.mode)
    result = RunResult()
    planned = plan(words, options, frames)
    at_once = frames_at_once(options, planned.execution.frames, memory)
    one = replace(options, jobs=1) if at_once > 1 else options  # a thread per frame
    previous: list[Frame] = []
    pending: deque[tuple[int, int, Future]] = deque()  # frame number, bytes, its render

    def deliver(frame: Frame, st: FrameStats) -> None:
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

    def oldest() -> None:
        number, _, future = pending.popleft()
        deliver(*future.result())
        if progress is not None:
            progress(number, 1.0)

    def on_nf(scene: Scene, number: int) -> None:
        if on_scene is not None:
            on_scene(scene, number)
        if at_once == 1:
            hook = (lambda f: progress(number, f)) if progress is not None else None
            deliver(*render(scene, options, number, hook))
            return
        need = frame_bytes(options, scene)  # frames in flight (and this one) within memory
        while pending and (len(pending) == at_once or sum(b for _, b, _ in pending) + need > memory):
            oldest()
        pending.append((number, need, pool.submit(render, scene.copy(), one, number)))

    if at_once == 1:  # the processor's and the frames' passes on one team (the rasterizer uses none)
        with threads.team(options.jobs or threads.available_cores()) if options.mode != "raster" else nullcontext():
            planned.replay(on_nf)
    else:
        with ThreadPoolExecutor(max_workers=at_once, thread_name_prefix="rend3r-frame") as pool:
            try:
                planned.replay(on_nf)
                while pending:
                    oldest()
            finally:  # after an error or an interrupt, frames not started are dropped
                for _, _, future in pending:
                    future.cancel()
    result.stats.instructions, result.stats.halt = planned.execution.instructions, planned.execution.halt
    result.stats.at_once, result.stats.seconds = at_once, perf_counter() - start
    return result
