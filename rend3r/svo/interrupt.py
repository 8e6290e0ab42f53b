"""Ctrl-C in the svo commands: seen within a fraction of a second, never inside numba.

Python runs its SIGINT handler in the main thread between bytecodes. Two things follow:

* A compiled kernel never returns to Python while it runs, so Ctrl-C waits for it. The
  traversal is therefore cut into chunks of rays (:mod:`rend3r.svo.traverse`).
* When the handler runs inside numba's own Python code (loading the kernel from numba's
  cache, compiling it, or the dispatcher around a call), the KeyboardInterrupt is at times
  swallowed (the run goes on and writes its output), seen only after the call, reported as
  ``SystemError: CPUDispatcher(...) returned a result with an exception set``, or followed
  by a segfault (measured with numba 0.68: of 25 Ctrl-Cs sent while the first call loaded
  the kernel from numba's cache, 12 were seen only after it returned and 1 never; `svo
  render` segfaulted when interrupted there). :func:`off_main_thread` runs such work on a helper
  thread that never takes SIGINT, while the main thread waits in short steps and raises
  KeyboardInterrupt at once. The helper, a daemon, finishes its chunk (or compile) and ends
  with the process.

Outputs are committed only at the end (:mod:`rend3r.fileio`); :func:`ctrl_c_ignored`
covers that commit and the summary line, so a run either stops with nothing written or
completes and exits 0 with everything written, never both. ``svo sweep`` runs its tasks as
a campaign, whose local worker processes ignore Ctrl-C and are stopped by the command
(:mod:`rend3r.campaign.runner`).
"""

from __future__ import annotations

import signal
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import TypeVar

T = TypeVar("T")

#: how often the waiting main thread looks for a pending Ctrl-C (seconds)
POLL = 0.05


def off_main_thread(function: Callable[..., T], *args) -> T:
    """``function(*args)`` run on a helper thread with SIGINT blocked; its result or exception.

    A Ctrl-C meanwhile raises KeyboardInterrupt in the caller within :data:`POLL` seconds.
    """
    box: dict[str, object] = {}

    def run() -> None:
        signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
        try:
            box["value"] = function(*args)
        except BaseException as exc:  # handed to the caller, which raises it
            box["error"] = exc

    helper = threading.Thread(target=run, name="rend3r-svo-kernel", daemon=True)
    helper.start()
    while helper.is_alive():
        helper.join(POLL)
    if "error" in box:
        raise box["error"]
    return box["value"]


@contextmanager
def ctrl_c_ignored() -> Iterator[None]:
    """SIGINT ignored inside the block (main thread only; elsewhere a plain block)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
