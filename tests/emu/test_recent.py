"""What frames keep for the frames after: the bounded map, and frames that change only
their camera or only a light against the reference renderer (nothing stale kept)."""

from __future__ import annotations

import sys
import threading

import pytest

from rend3r.emu.options import EmuOptions
from rend3r.emu.processor import execute
from rend3r.emu.raytracer import render_frame
from rend3r.emu.reference import render_reference
from rend3r.recent import Recent

from .scenes import Prog
from .test_engine_vs_reference import assert_same


def test_keeps_the_most_recently_used_values():
    made: list[str] = []
    recent: Recent[str] = Recent(2)

    def make(key: str):
        return lambda: made.append(key) or key.upper()

    assert [recent.get(k, make(k)) for k in ("a", "b", "a", "c", "a", "b")] == ["A", "B", "A", "C", "A", "B"]
    assert made == ["a", "b", "c", "b"]  # b was the least recently used when c came


def test_refuses_an_empty_map():
    with pytest.raises(ValueError, match="at least one value"):
        Recent(0)


def test_threads_share_it():
    """Four threads on seven keys of a map of four: each gets its key's value, whether
    kept or made, and the map never holds more than four."""
    recent: Recent[tuple[int, int]] = Recent(4)
    wrong: list[tuple[int, tuple[int, int]]] = []
    sizes: list[int] = []

    def work(k: int) -> None:
        for i in range(3000):
            key = (k * 5 + i) % 7
            value = recent.get(key, lambda key=key: (key, key * key))
            if value != (key, key * key):
                wrong.append((key, value))
            sizes.append(len(recent))  # under the map's lock: a bare read can see an insert before its eviction

    threads = [threading.Thread(target=work, args=(k,)) for k in range(4)]
    interval = sys.getswitchinterval()
    sys.setswitchinterval(1e-6)  # threads switch often, so the lock's absence would show
    try:
        for t in threads:
            t.start()
        for t in threads:
            t.join()
    finally:
        sys.setswitchinterval(interval)
    assert not wrong and len(sizes) == 12000 and max(sizes) <= 4


@pytest.mark.parametrize("precision", ["fp16", "fp32"])
def test_frames_that_change_a_light_or_the_camera(precision):
    """Four frames of one run: a light's colour changes, then the field of view, then the
    light goes back (its kept tables come back): each frame as the reference renders it."""
    p = Prog().nr().cam(hfov=0.4, vfov=0.4).dir_light(0, forward=(0.3, -0.4, -1.0), col=0xF800)
    p.sphere(0, loc=(0.0, 0.0, -3.0)).sphere(1, loc=(0.4, 0.3, -4.0), col=0x07E0).nf()
    p.light(0, col=0xFFFF).nf()
    p.cam(hfov=0.25).nf()
    p.light(0, col=0xF800).nf().er()
    options = EmuOptions(precision=precision, width=32, height=24)
    frames: list = []
    execute(p.words, options, on_nf=lambda scene, n: frames.append((scene.copy(), render_frame(scene, options)[0])))
    assert len(frames) == 4
    for scene, frame in frames:
        assert_same(frame, render_reference(scene, options))
    assert len({f.rgb565.tobytes() for _, f in frames}) == 4
