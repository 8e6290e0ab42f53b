"""Scenes as instruction words, built from property values (float16 bits or ints)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from rend3r.isa import CameraSet, FrameOp, Func, LightSet, ShapeSet, Table, ValueType, encode, lookup
from rend3r.isa.float16 import float_to_bits


def bits(table: Table, name: str, value: float | int) -> tuple[int, int]:
    """(property index, 16-bit data): floats rounded to float16, ints as given, or raw ``('raw', b)``."""
    prop = lookup(table, name)
    assert prop is not None, name
    if isinstance(value, tuple):  # ("raw", bits)
        return prop.index, value[1]
    if prop.vtype is ValueType.FLOAT16:
        return prop.index, float_to_bits(float(value))
    return prop.index, int(value)


@dataclass
class SceneSpec:
    """Camera, lights and shapes (or triangles) as ``{name: value}`` dicts."""

    camera: dict[str, float] = field(default_factory=dict)
    lights: list[dict[str, float]] = field(default_factory=list)
    shapes: list[dict[str, float]] = field(default_factory=list)
    triangles: list[dict[str, float]] = field(default_factory=list)

    def words(self) -> list[int]:
        out: list[int] = list(encode(FrameOp(Func.NR)))
        for name, v in self.camera.items():
            out += encode(CameraSet(*bits(Table.CAMERA, name, v)))
        for i, light in enumerate(self.lights):
            for name, v in light.items():
                out += encode(LightSet(i, *bits(Table.LIGHT, name, v)))
        for table, objects in ((Table.SHAPE, self.shapes), (Table.TRIANGLE, self.triangles)):
            for i, obj in enumerate(objects):
                for name, v in obj.items():
                    p, d = bits(table, name, v)
                    out += encode(ShapeSet(i, p, p, d, d))
        out += encode(FrameOp(Func.NF)) + encode(FrameOp(Func.ER)) + encode(FrameOp(Func.ER))
        return out


def axis_angle(ax: tuple[float, float, float], degrees: float) -> dict[str, float]:
    """Unit rotation quaternion as shape/camera properties."""
    n = math.sqrt(sum(c * c for c in ax)) or 1.0
    s = math.sin(math.radians(degrees) / 2) / n
    return {"rrot": math.cos(math.radians(degrees) / 2), "irot": ax[0] * s, "jrot": ax[1] * s, "krot": ax[2] * s}
