"""A bounded map of the last few values computed, by key (least recently used out).

The raytracer keeps what a frame derives from a few dozen scene words (the camera's
kernel block, the lights' rows) for the frames and runs after that have the same words
(building them again took about a fifth of a small frame's Python); ``rend3r view`` keeps
its last pixel traces.
"""

from __future__ import annotations

from collections import OrderedDict
from collections.abc import Callable, Hashable
from threading import Lock
from typing import Generic, TypeVar

T = TypeVar("T")


class Recent(Generic[T]):
    """Up to ``size`` values by key; safe to share between threads (frames render side by
    side). Two threads that miss the same key at once each make a value (equal ones, as
    ``make`` must give for a key) and the later is kept."""

    def __init__(self, size: int) -> None:
        if size < 1:
            raise ValueError(f"a Recent map holds at least one value, not {size}")
        self._size, self._values, self._lock = size, OrderedDict[Hashable, T](), Lock()

    def __len__(self) -> int:
        with self._lock:
            return len(self._values)

    def get(self, key: Hashable, make: Callable[[], T]) -> T:
        """The value kept for ``key``, else ``make()`` kept for it (made outside the lock)."""
        with self._lock:
            value = self._values.get(key)
            if value is not None:
                self._values.move_to_end(key)
                return value
        value = make()
        with self._lock:
            self._values[key] = value
            self._values.move_to_end(key)
            if len(self._values) > self._size:
                self._values.popitem(last=False)
        return value
