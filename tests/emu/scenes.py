"""Programs for the emulator tests, built from ISA instructions (names via the tables)."""

from __future__ import annotations

import numpy as np

from rend3r.isa import CameraSet, FrameOp, Func, LightSet, ShapeSet, Table, ValueType, encode, lookup


#: A lit sphere in front of a narrow camera: the smallest program with a shadowless hit.
ONE_SPHERE = """\
nr
cam hfov, 0.3
cam vfov, 0.3
lt 0, src, 1
lt 0, zfor, -1
sp 0, type, col, 1, 0xF800
sp 0, zloc, rrot, -3, 1
sp 0, xscl, yscl, 1, 1
sp 0, zscl, zero, 1, 0
nf
er
"""


def f16(value: float) -> int:
    return int(np.array(value, dtype=np.float16).view(np.uint16))


def _data(table: Table, name: str, value: float | int) -> tuple[int, int]:
    prop = lookup(table, name)
    assert prop is not None, name
    return prop.index, f16(value) if prop.vtype is ValueType.FLOAT16 else int(value)


class Prog:
    """A tiny program builder: ``Prog().nr().sphere(0, loc=(0, 0, -3)).nf().er().words``."""

    def __init__(self) -> None:
        self.words: list[int] = []

    def op(self, func: Func) -> "Prog":
        self.words += encode(FrameOp(func))
        return self

    def nr(self) -> "Prog":
        return self.op(Func.NR)

    def nf(self) -> "Prog":
        return self.op(Func.NF)

    def er(self) -> "Prog":
        return self.op(Func.ER)

    def lr(self) -> "Prog":
        return self.op(Func.LR)

    def cam(self, **props: float) -> "Prog":
        for name, value in props.items():
            self.words += encode(CameraSet(*_data(Table.CAMERA, name, value)))
        return self

    def light(self, index: int, **props: float) -> "Prog":
        for name, value in props.items():
            self.words += encode(LightSet(index, *_data(Table.LIGHT, name, value)))
        return self

    def shape(self, index: int, **props: float) -> "Prog":
        items = list(props.items())
        for (n1, v1), (n2, v2) in zip(items[::2], items[1::2] + [("zero", 0)] * (len(items) % 2)):
            p1, d1 = _data(Table.SHAPE, n1, v1)
            p2, d2 = _data(Table.SHAPE, n2, v2)
            self.words += encode(ShapeSet(index, p1, p2, d1, d2))
        return self

    def sphere(self, index: int, loc=(0.0, 0.0, -3.0), scale=(1.0, 1.0, 1.0), rot=(1.0, 0.0, 0.0, 0.0),
               col: int = 0xF800, kind: int = 1) -> "Prog":
        return self.shape(
            index, type=kind, col=col, xloc=loc[0], yloc=loc[1], zloc=loc[2],
            rrot=rot[0], irot=rot[1], jrot=rot[2], krot=rot[3], xscl=scale[0], yscl=scale[1], zscl=scale[2],
        )

    def dir_light(self, index: int, forward=(0.0, 0.0, -1.0), col: int = 0xFFFF, intensity: float = 1.0) -> "Prog":
        return self.light(index, src=1, xfor=forward[0], yfor=forward[1], zfor=forward[2], col=col, int=intensity)
