"""Loss, corruption, duplication and reordering: every commit is exact, nothing partial runs."""

from __future__ import annotations

import random
import threading

import pytest

from rend3r.transport.cli import serve
from rend3r.transport.device import DeviceCore, RecordingExecutor
from rend3r.transport.links import DirectLink, FaultLink, SerialLink, open_serial
from rend3r.transport.protocol import Frame, FrameType
from rend3r.transport.session import Sender, SendError


def random_program(rng: random.Random, longest: int) -> tuple[int, ...]:
    return tuple(rng.getrandbits(32) for _ in range(rng.randrange(0, longest)))


def check_loads(sender: Sender, core: DeviceCore, ex: RecordingExecutor, programs) -> int:
    """Load each program; return how many loads failed. Asserts the atomicity invariants."""
    failures = 0
    for words in programs:
        before = core.active
        try:
            sender.load(words)
        except SendError:
            failures += 1
            assert core.active == before  # a failed load leaves the old program in place
            continue
        assert core.active == words  # bit-identical
        assert ex.running == words
    sent = set(programs)
    assert all(p in sent for p in ex.started)  # nothing partial or corrupted ever ran
    return failures


@pytest.mark.timeout(120)
def test_thousand_programs_through_loss_and_corruption():
    rng = random.Random(20261121)
    ex = RecordingExecutor()
    core = DeviceCore(ex)
    link = FaultLink(DirectLink(core.handle), loss=0.10, corrupt=0.05, duplicate=0.02,
                     reorder=0.02, seed=1)
    sender = Sender(link, timeout=0.05, retries=12, rng=rng)
    programs = [random_program(rng, 1200) for _ in range(1000)]
    failures = check_loads(sender, core, ex, programs)
    assert failures == 0
    assert core.counters.loads == 1000
    # the fault model really was exercised, in both directions
    assert link.injected["loss"] > 500 and link.injected["corrupt"] > 250
    assert link.injected["duplicate"] > 50 and link.injected["reorder"] > 50
    assert core.counters.malformed > 100 and sender.stats.ignored > 50
    assert sender.stats.resends > 500


def test_a_dead_link_fails_cleanly_and_keeps_the_old_program():
    ex = RecordingExecutor()
    core = DeviceCore(ex)
    good = DirectLink(core.handle)
    Sender(good).load((1, 2, 3))
    dead = FaultLink(DirectLink(core.handle), loss=1.0, seed=0)
    with pytest.raises(SendError, match="no acknowledgement for BEGIN after 4 tries"):
        Sender(dead, timeout=0.01, retries=3).load((4, 5, 6))
    assert core.active == (1, 2, 3) and ex.started == [(1, 2, 3)]


def test_reply_loss_only_still_commits_once():
    ex = RecordingExecutor()
    core = DeviceCore(ex)

    class LoseReplies(FaultLink):
        def send(self, frame: bytes) -> None:  # forward direction is clean
            self.inner.send(frame)

    link = LoseReplies(DirectLink(core.handle), loss=0.5, seed=3)
    rng = random.Random(5)
    programs = [random_program(rng, 800) for _ in range(50)]
    assert check_loads(Sender(link, timeout=0.01, retries=30, rng=rng), core, ex, programs) == 0
    assert core.counters.loads == 50


def test_load_restarts_when_the_device_forgets_it():
    """A device reset between data and commit: the sender starts the load again."""
    ex = RecordingExecutor()
    core = DeviceCore(ex)
    state = {"commits": 0}

    def handle(frame: bytes) -> bytes | None:
        if frame[1] == FrameType.COMMIT and state["commits"] == 0:  # another host resets it
            state["commits"] += 1
            core.handle(Frame(FrameType.RESET, seq=1).encode())
        return core.handle(frame)

    sender = Sender(DirectLink(handle), rng=random.Random(1))
    sender.load((9, 8, 7))
    assert core.active == (9, 8, 7) and sender.stats.restarts == 1


@pytest.mark.timeout(120)
def test_faults_over_a_real_pty(pty_bridge):
    ex = RecordingExecutor()
    core = DeviceCore(ex)
    device_link = SerialLink(open_serial(pty_bridge.paths[1]))
    stop = threading.Event()
    thread = threading.Thread(target=serve, args=(device_link, core, stop, 0.02), daemon=True)
    thread.start()
    rng = random.Random(77)
    link = FaultLink(SerialLink(open_serial(pty_bridge.paths[0])), loss=0.10, corrupt=0.05,
                     duplicate=0.02, reorder=0.02, seed=4)
    try:
        programs = [random_program(rng, 600) for _ in range(25)]
        assert check_loads(Sender(link, timeout=0.1, retries=12, rng=rng), core, ex, programs) == 0
    finally:
        stop.set()
        thread.join()
        link.close()
        device_link.close()
    assert core.counters.loads == 25
