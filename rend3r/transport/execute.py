"""The virtual device's execute step: run the committed program in the emulator, save PNGs.

Rendering runs in a worker thread so the device keeps answering frames while it renders;
starting a new program (or stopping) supersedes the running one at its next frame.
"""

from __future__ import annotations

import logging
import threading
import time
from pathlib import Path
from typing import TYPE_CHECKING, Callable

from .. import cliutil
from ..errors import Rend3rError

if TYPE_CHECKING:
    from ..emu.frame import Frame

log = logging.getLogger("rend3r.device")


#: The virtual device renders frames of at most this many pixels per side: a frame is rendered
#: for each program a sender pushes, so the cap bounds the work one received program causes.
MAX_DEVICE_SIDE = 4096


def parse_size(text: str) -> tuple[int, int]:
    """``WxH`` to (width, height), each 1..MAX_DEVICE_SIDE; Rend3rError if malformed."""
    try:
        return cliutil.parse_size(text, max_side=MAX_DEVICE_SIDE)
    except ValueError as exc:
        raise Rend3rError(f"malformed size: {exc}") from None


class _Superseded(Exception):
    """Raised inside the emulator's frame callback to abandon a run that was replaced."""


def run_and_save(words: tuple[int, ...], size: tuple[int, int], max_frames: int,
                 save: Callable[[Frame], None]) -> None:
    """Execute ``words`` in the emulator, handing each rendered frame to ``save``."""
    from ..emu import EmuOptions, run_program

    width, height = size
    run_program(list(words), EmuOptions(width=width, height=height), frames=max_frames,
                on_frame=save, keep_frames=False)


class RenderExecutor:
    """Runs each program it is given in the emulator and writes its frames to ``out``."""

    def __init__(self, out: Path, *, width: int, height: int, max_frames: int,
                 max_frame_rate: float) -> None:
        self.out = out
        self.size = (width, height)
        self.max_frames = max_frames
        self.interval = 1.0 / max_frame_rate
        self.frames = 0
        self.runs = 0
        self._lock = threading.Lock()
        self._cancel = threading.Event()
        self._thread: threading.Thread | None = None
        self._next_frame_at = 0.0

    def start(self, words: tuple[int, ...]) -> None:
        with self._lock:
            self._cancel.set()
            self._cancel = threading.Event()
            self.runs += 1
            self._thread = threading.Thread(
                target=self._run, args=(words, self.runs, self._cancel), daemon=True,
                name=f"render-{self.runs}",
            )
            self._thread.start()

    def stop(self) -> None:
        with self._lock:
            self._cancel.set()

    def reset(self) -> None:
        self.stop()
        self.frames = 0

    def close(self, wait: float = 5.0) -> None:
        """Stop and wait (bounded) for the worker to finish the frame it is on."""
        self.stop()
        if self._thread is not None:
            self._thread.join(wait)

    def _run(self, words: tuple[int, ...], run: int, cancel: threading.Event) -> None:
        from ..emu.image import save_png

        def save(frame: Frame) -> None:
            delay = self._next_frame_at - time.monotonic()
            if cancel.wait(max(0.0, delay)):
                raise _Superseded
            save_png(frame.rgb565, self.out / f"run{run:04d}_frame{frame.number:04d}.png")  # atomic
            self._next_frame_at = time.monotonic() + self.interval
            self.frames += 1

        if not words:
            return  # the all-zero memory: nothing to execute
        try:
            run_and_save(words, self.size, self.max_frames, save)
        except _Superseded:
            pass
        except Rend3rError as exc:
            log.warning("program of run %d stopped: %s", run, exc)
        except Exception:  # an emulator bug must not take the device down
            log.exception("program of run %d crashed the emulator", run)
