"""The virtual device's execute step: run the committed program in the emulator, save PNGs.

Rendering runs in one worker thread so the device keeps answering frames while it renders;
starting a new program (or stopping) cancels the running render at its next band.
"""

from __future__ import annotations

import logging
import threading
import time
from pathlib import Path
from typing import TYPE_CHECKING, Callable

from ..errors import Rend3rError

if TYPE_CHECKING:
    from ..emu.frame import Frame

log = logging.getLogger("rend3r.device")


#: The virtual device renders frames of at most this many pixels per side: a frame is rendered
#: for each program a sender pushes, so the cap bounds the work one received program causes.
MAX_DEVICE_SIDE = 4096


#: A program starts rendering once no newer one has arrived for this long (seconds).
SETTLE = 0.05


class _Superseded(Exception):
    """Raised inside the emulator's callbacks to abandon a run that was replaced or stopped."""


def run_and_save(words: tuple[int, ...], size: tuple[int, int], max_frames: int,
                 save: Callable[[Frame], None], check: Callable[[], None] = lambda: None) -> None:
    """Execute ``words`` in the emulator, handing each rendered frame to ``save``.

    ``check`` is called after every band of every frame; it raises to abandon the run.
    """
    from ..emu import EmuOptions, run_program

    width, height = size
    run_program(list(words), EmuOptions(width=width, height=height), frames=max_frames,
                on_frame=save, progress=lambda _number, _fraction: check(), keep_frames=False)


class RenderExecutor:
    """Runs the latest program it is given in the emulator and writes its frames to ``out``.

    One worker thread renders at a time. :meth:`start` leaves the program in a one-slot
    mailbox (a newer one replaces a program not yet begun) and cancels the running render,
    which stops at its next band, frame-rate wait or PNG band; a program starts once no
    newer one has come for :data:`SETTLE` seconds. So however fast commits
    arrive, one render is in flight, its memory is one frame's, and the program rendered
    last is the one committed last. Frames go to ``run{N:04d}_frame{F:04d}.png`` where N
    counts :meth:`start` calls: runs superseded before they began leave no files.
    """

    def __init__(self, out: Path, *, width: int, height: int, max_frames: int,
                 max_frame_rate: float) -> None:
        self.out = out
        self.size = (width, height)
        self.max_frames = max_frames
        self.interval = 1.0 / max_frame_rate
        self.frames = 0  # frames written since the last reset
        self.runs = 0  # programs started (the N of the file names)
        self.rendered: list[int] = []  # runs whose rendering began, in order (the last few)
        self._cond = threading.Condition()
        self._pending: tuple[tuple[int, ...], int] | None = None
        self._cancel = threading.Event()  # set: the render in flight must stop
        self._closed = False
        self._thread: threading.Thread | None = None
        self._next_frame_at = 0.0

    def start(self, words: tuple[int, ...]) -> None:
        with self._cond:
            if self._closed:
                return
            self.runs += 1
            self._pending = (words, self.runs)
            self._cancel.set()
            if self._thread is None:
                self._thread = threading.Thread(target=self._work, daemon=True, name="render")
                self._thread.start()
            self._cond.notify()

    def stop(self) -> None:
        with self._cond:
            self._pending = None
            self._cancel.set()

    def reset(self) -> None:
        self.stop()
        self.frames = 0

    def close(self, wait: float = 5.0) -> None:
        """Stop and wait (bounded) for the worker to leave the band it is on."""
        with self._cond:
            self._closed = True
            self._pending = None
            self._cancel.set()
            self._cond.notify()
        if self._thread is not None:
            self._thread.join(wait)

    def _work(self) -> None:
        while True:
            with self._cond:
                if not self._settled():
                    continue
                if self._closed:
                    return
                (words, run), self._pending = self._pending, None
                self._cancel.clear()
                self.rendered[:] = [*self.rendered[-15:], run]
            self._run(words, run)

    def _settled(self) -> bool:
        """Wait (holding the lock) for a program that no newer one replaced within SETTLE
        seconds; False if the mailbox was emptied meanwhile (stop). Under a commit storm the
        worker then stays idle, leaving the processor to the link, and renders the last one."""
        while self._pending is None and not self._closed:
            self._cond.wait()
        while not self._closed:
            run = self._pending[1]
            self._cond.wait(SETTLE)
            if self._pending is None:
                return False
            if self._pending[1] == run:
                return True
        return True

    def _check(self) -> None:
        if self._cancel.is_set():
            raise _Superseded

    def _run(self, words: tuple[int, ...], run: int) -> None:
        def save(frame: Frame) -> None:
            if self._cancel.wait(max(0.0, self._next_frame_at - time.monotonic())):
                raise _Superseded
            _write_png(frame, self.out / f"run{run:04d}_frame{frame.number:04d}.png", self._check)
            self._next_frame_at = time.monotonic() + self.interval
            self.frames += 1

        if not words:
            return  # the all-zero memory: nothing to execute
        try:
            run_and_save(words, self.size, self.max_frames, save, self._check)
        except _Superseded:
            pass
        except Rend3rError as exc:
            log.warning("program of run %d stopped: %s", run, exc)
        except Exception:  # an emulator bug must not take the device down
            log.exception("program of run %d crashed the emulator", run)


def _write_png(frame: Frame, path: Path, check: Callable[[], None]) -> None:
    """Encode the frame (abandoned between bands when ``check`` raises) and write it
    atomically, into the folder the device was started with: a folder removed while it
    runs is reported, not made again."""
    from ..fileio import write_atomic
    from .png import encode_rgb565

    if not path.parent.is_dir():
        raise Rend3rError(f"{path}: folder {path.parent} does not exist")
    write_atomic(path, encode_rgb565(frame.rgb565, check))
