"""Fixtures for transport tests: a null-modem pair of real ptys."""

from __future__ import annotations

import os
import select
import threading
import tty

import pytest


class PtyBridge:
    """Two pty pairs whose masters are copied into each other: a null-modem cable.

    ``paths`` are the two slave device paths; open one at each end (pyserial, the CLI).
    """

    def __init__(self) -> None:
        self._fds: list[int] = []
        masters, self.paths = [], []
        for _ in range(2):
            master, slave = os.openpty()
            tty.setraw(slave)
            masters.append(master)
            self.paths.append(os.ttyname(slave))
            self._fds += [master, slave]  # slaves stay open so masters never see a hangup
        self._masters = masters
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._copy, daemon=True)
        self._thread.start()

    def _copy(self) -> None:
        a, b = self._masters
        other = {a: b, b: a}
        while not self._stop.is_set():
            ready, _, _ = select.select([a, b], [], [], 0.05)
            for fd in ready:
                try:
                    data = os.read(fd, 65536)
                except OSError:
                    continue
                view = memoryview(data)
                while view:
                    view = view[os.write(other[fd], view):]

    def close(self) -> None:
        self._stop.set()
        self._thread.join()
        for fd in self._fds:
            os.close(fd)


@pytest.fixture
def pty_bridge():
    bridge = PtyBridge()
    yield bridge
    bridge.close()
