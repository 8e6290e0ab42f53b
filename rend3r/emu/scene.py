"""Scene state as the instruction processor leaves it: float16 bits as stored.

Shapes and triangles are columnar (:class:`ObjectTable`): the sorted indices a program
touched and one row of 32 property words per index, so renderers read tens of thousands
of shapes with array operations. The camera and lights (at most 32 and 64 x 32 words) are
dicts. Values are the raw 16-bit words of the instructions; the renderers interpret them
with the property tables (never hard-coded numbers).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np

from ..isa import Table, lookup
from ..isa.tables import PROP_LIMIT


@lru_cache(maxsize=256)
def prop_index(table: Table, name: str) -> int:
    """Index of a property by name (KeyError if the table has no such property)."""
    prop = lookup(table, name)
    if prop is None:
        raise KeyError(f"{table.value} table has no property {name!r}")
    return prop.index


#: An empty table's arrays, shared (read-only: writes replace them, never write into them).
_NO_INDEX, _NO_VALUES = np.empty(0, dtype=np.int64), np.zeros((0, PROP_LIMIT), dtype=np.uint16)
_NO_INDEX.flags.writeable = _NO_VALUES.flags.writeable = False


class ObjectTable:
    """Shapes or triangles: ``index`` (sorted unique int64: every index written since the
    last clear) and ``values`` ((n, 32) uint16: property words, 0 where never written)."""

    def __init__(self) -> None:
        self.clear()

    def clear(self) -> None:
        self.index, self.values = _NO_INDEX, _NO_VALUES

    def __len__(self) -> int:
        return len(self.index)

    def copy(self) -> ObjectTable:
        """A copy that later writes to this table leave as it is."""
        other = ObjectTable()
        other.index, other.values = self.index.copy(), self.values.copy()
        return other

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

    def copy(self) -> Scene:
        """A copy that later writes to this scene leave as it is."""
        return Scene(dict(self.camera), {k: dict(v) for k, v in self.lights.items()}, self.objects.copy(),
                     self.triangles.copy())

    def clear(self) -> None:
        self.camera.clear()
        self.lights.clear()
        self.objects.clear()
        self.triangles.clear()

    def write_camera(self, prop: np.ndarray, data: np.ndarray) -> None:
        """C writes in program order, null properties dropped (the last write wins: a
        dict's update keeps the last value of a key)."""
        self.camera.update(zip(prop.tolist(), data.tolist()))

    def write_lights(self, index: np.ndarray, prop: np.ndarray, data: np.ndarray) -> None:
        """L writes in program order, null properties dropped (the last write wins); a dict
        keeps each (light, property)'s last value, so the loop runs once per distinct
        one, not per word."""
        last = dict(zip((index.astype(np.int64) * PROP_LIMIT + prop).tolist(), data.tolist()))
        for cell, bits in last.items():
            self.lights.setdefault(cell // PROP_LIMIT, {})[cell % PROP_LIMIT] = bits

    def camera_bits(self, name: str, default: int = 0) -> int:
        return self.camera.get(prop_index(Table.CAMERA, name), default)
