"""image.OrderedWriter: items encoded on threads, their files written in the items' order."""

from __future__ import annotations

import threading
import time
from pathlib import Path

import pytest

from rend3r.emu.image import OrderedWriter


def _encode(item: int) -> list[tuple[Path, bytes]]:
    time.sleep(0.002 * (item % 3))  # later items often finish first
    return [(Path(f"{item}.png"), bytes([item])), (Path(f"{item}.npy"), bytes([item, item]))]


def test_files_arrive_in_the_items_order_from_the_calling_thread():
    written: list[tuple[str, bytes, str]] = []
    sink = lambda path, data: written.append((str(path), data, threading.current_thread().name))  # noqa: E731
    with OrderedWriter(_encode, sink, workers=3) as writer:
        for item in range(20):
            writer.add(item)
        writer.finish()
    assert [p for p, _, _ in written] == [f"{i}.{ext}" for i in range(20) for ext in ("png", "npy")]
    assert {t for _, _, t in written} == {threading.current_thread().name}


def test_an_encoding_error_reaches_the_caller_and_later_items_are_not_written():
    def encode(item: int) -> list[tuple[Path, bytes]]:
        if item == 2:
            raise ValueError("cannot encode item 2")
        return [(Path(f"{item}.png"), b"x")]

    written: list[str] = []
    with pytest.raises(ValueError, match="item 2"), OrderedWriter(encode, lambda p, d: written.append(str(p)), 2) as w:
        for item in range(6):
            w.add(item)
        w.finish()
    assert written == ["0.png", "1.png"]
