"""Scene state as the instruction processor leaves it: float16 bits as stored.

Shapes and triangles are columnar (:class:`ObjectTable`): the sorted indices a program
touched and one row of 32 property words per index, so renderers read tens of thousands
of shapes with array operations. The camera and lights (at most 32 and 64 x 32 words) are
dicts. Values are the raw 16-bit words of the instructions; the renderers interpret them
with the property tables (never hard-coded numbers).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..isa import Table, lookup
from ..isa.tables import LIGHT_INDEX_LIMIT, PROP_LIMIT
from . import native


def prop_index(table: Table, name: str) -> int:
    """Index of a property by name (KeyError if the table has no such property)."""
    prop = lookup(table, name)
    if prop is None:
        raise KeyError(f"{table.value} table has no property {name!r}")
    return prop.index


def _last(cell: np.ndarray, cells: int) -> np.ndarray:
    """For writes to ``cell`` (each in ``range(cells)``) in program order: True for the
    last write to each cell."""
    position = np.arange(len(cell), dtype=np.int32 if len(cell) < 2**31 else np.int64)
    last = np.full(cells, -1, dtype=position.dtype)
    np.maximum.at(last, cell, position)
    return last[cell] == position


class ObjectTable:
    """Shapes or triangles: ``index`` (sorted unique int64: every index written since the
    last clear) and ``values`` ((n, 32) uint16: property words, 0 where never written)."""

    def __init__(self) -> None:
        self.clear()

    def clear(self) -> None:
        self.index = np.empty(0, dtype=np.int64)
        self.values = np.zeros((0, PROP_LIMIT), dtype=np.uint16)

    def __len__(self) -> int:
        return len(self.index)

    def update(self, index: np.ndarray, prop: np.ndarray, value: np.ndarray) -> None:
        """Write ``value`` to ``(index, prop)`` in array order (the last write wins, in the
        compiled loop of csrc/kernels.c table_write); every index given is touched, so it
        gets a row."""
        if not len(index):
            return
        rows = self._rows(index)
        prop = np.ascontiguousarray(prop, np.int64)
        value = np.ascontiguousarray(value, np.uint16)
        if not len(rows) == len(prop) == len(value):
            raise ValueError("update: index, prop and value differ in length")
        done = native.library().table_write(native.ptr(self.values, np.uint16, (None, PROP_LIMIT)), len(self.values),
                                            rows.ctypes.data, prop.ctypes.data, value.ctypes.data, len(rows))
        if done != len(rows):
            raise ValueError(f"update: property {int(prop[done])} of write {done} is outside 0..{PROP_LIMIT - 1}")

    def _rows(self, index: np.ndarray) -> np.ndarray:
        """The row of each element of ``index``, adding zero rows for new indices.

        A dense map over the index range (no sort): SE indices have 19 bits.
        """
        slot = np.zeros(max(int(index.max()), int(self.index.max(initial=-1))) + 1, dtype=np.int64)
        slot[self.index] = 1
        slot[index] = 1
        merged = np.flatnonzero(slot)
        slot[merged] = np.arange(len(merged))
        if len(merged) > len(self.index):
            values = np.zeros((len(merged), PROP_LIMIT), dtype=np.uint16)
            values[slot[self.index]] = self.values
            self.index, self.values = merged, values
        return slot[index]

    def row(self, index: int) -> dict[int, int]:
        """The non-zero property words of ``index`` (KeyError if it was never written)."""
        at = int(np.searchsorted(self.index, index))
        if at == len(self.index) or self.index[at] != index:
            raise KeyError(index)
        return {prop: int(v) for prop, v in enumerate(self.values[at]) if v}


@dataclass
class Scene:
    """Camera ``{prop: bits}``, lights ``{index: {prop: bits}}`` (a key means written),
    and the object tables.

    ``objects`` holds what SE/SD pairs write in raytrace and raster mode; in hybrid mode
    (``docs/isa-extensions.md``) pairs aimed at the triangle table go to ``triangles``.
    """

    camera: dict[int, int] = field(default_factory=dict)
    lights: dict[int, dict[int, int]] = field(default_factory=dict)
    objects: ObjectTable = field(default_factory=ObjectTable)
    triangles: ObjectTable = field(default_factory=ObjectTable)

    def clear(self) -> None:
        self.camera.clear()
        self.lights.clear()
        self.objects.clear()
        self.triangles.clear()

    def write_camera(self, prop: np.ndarray, data: np.ndarray) -> None:
        """C writes in program order, null properties dropped (the last write wins)."""
        last = _last(prop, PROP_LIMIT)
        self.camera.update(zip(prop[last].tolist(), data[last].tolist()))

    def write_lights(self, index: np.ndarray, prop: np.ndarray, data: np.ndarray) -> None:
        """L writes in program order, null properties dropped (the last write wins); the
        loop runs once per distinct (light, property), not per word."""
        last = _last(index.astype(np.int64) * PROP_LIMIT + prop, LIGHT_INDEX_LIMIT * PROP_LIMIT)
        for light, p, bits in zip(index[last].tolist(), prop[last].tolist(), data[last].tolist()):
            self.lights.setdefault(light, {})[p] = bits

    def camera_bits(self, name: str, default: int = 0) -> int:
        return self.camera.get(prop_index(Table.CAMERA, name), default)
