"""Scene state as the instruction processor leaves it: sparse, float16 bits as stored.

Only what a program touched is held: a shape index near 2**19 costs one dict entry.
Values are the raw 16-bit words of the instructions; the renderer interprets them with
the property tables (never hard-coded numbers).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from ..isa import CameraSet, LightSet, ShapeSet, Table, ValueType, by_index, lookup


def prop_index(table: Table, name: str) -> int:
    """Index of a property by name (KeyError if the table has no such property)."""
    prop = lookup(table, name)
    if prop is None:
        raise KeyError(f"{table.value} table has no property {name!r}")
    return prop.index


#: Per table, the null properties (``zero``): writing them stores nothing.
_NULL_PROPS = {t: frozenset(i for i, p in by_index(t).items() if p.vtype is ValueType.ZERO) for t in Table}


def _writes(table: Table, prop: int) -> bool:
    return prop not in _NULL_PROPS[table]


@dataclass
class Scene:
    """Camera, lights and shapes (or triangles): ``{index: {prop: bits}}``.

    ``objects`` holds what SE/SD pairs write in raytrace and raster mode; in hybrid mode
    (``docs/isa-extensions.md``) pairs aimed at the triangle table go to ``triangles``.
    """

    camera: dict[int, int] = field(default_factory=dict)
    lights: dict[int, dict[int, int]] = field(default_factory=dict)
    objects: dict[int, dict[int, int]] = field(default_factory=dict)
    triangles: dict[int, dict[int, int]] = field(default_factory=dict)

    def clear(self) -> None:
        self.camera.clear()
        self.lights.clear()
        self.objects.clear()
        self.triangles.clear()

    def set_camera(self, ins: CameraSet) -> None:
        if _writes(Table.CAMERA, ins.prop):
            self.camera[ins.prop] = ins.data

    def set_light(self, ins: LightSet) -> None:
        if _writes(Table.LIGHT, ins.prop):
            self.lights.setdefault(ins.index, {})[ins.prop] = ins.data

    def set_object(self, ins: ShapeSet, table: Table, store: dict[int, dict[int, int]] | None = None) -> None:
        """SE/SD: prop then prop2 (so prop2 wins when both name the same property).

        ``store`` is ``objects`` unless given (hybrid mode's ``triangles``).
        """
        target = self.objects if store is None else store
        null = _NULL_PROPS[table]
        for prop, data in ((ins.prop, ins.data), (ins.prop2, ins.data2)):
            if prop not in null:
                target.setdefault(ins.index, {})[prop] = data

    def camera_bits(self, name: str, default: int = 0) -> int:
        return self.camera.get(prop_index(Table.CAMERA, name), default)
