"""Lights that are on, read from the scene through the light property table."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..isa import Table, lookup
from ..isa.tables import LIGHT_SOURCE_CODES
from .arith import Arith
from .scene import Scene, prop_index
from .vec import Vec

DIRECTIONAL, POINT = LIGHT_SOURCE_CODES["directional"], LIGHT_SOURCE_CODES["point"]
_SRC_MASK = lookup(Table.LIGHT, "src").value_mask
WHITE = 0xFFFF
_PROPS = {n: prop_index(Table.LIGHT, n) for n in ("src", "xloc", "yloc", "zloc", "xfor", "yfor", "zfor", "col", "int")}
_VALUES = ("xloc", "yloc", "zloc", "xfor", "yfor", "zfor", "int")  # the float16 ones
#: Unset (never written since the last nr) colour and intensity: white at full strength.
DEFAULT_INTENSITY = 1.0


@dataclass(frozen=True)
class Light:
    index: int
    kind: int  # DIRECTIONAL or POINT
    location: Vec
    forward: Vec
    color: int  # RGB565
    intensity: np.ndarray


def lights_key(scene: Scene, arith: Arith, model: str = "spec") -> tuple:
    """What :func:`lights_from_scene` depends on: equal keys give equal lights (the lights'
    property words in index and property order, whatever order they were written in)."""
    return tuple((i, tuple(sorted(p.items()))) for i, p in sorted(scene.lights.items())), arith, model


def lights_from_scene(scene: Scene, arith: Arith, model: str = "spec") -> list[Light]:
    """Lights whose ``src`` low two bits say directional (1) or point (2), in index order.

    ``model="device"``: only light 0, always directional (whatever its ``src``), white at
    intensity 1 (the device ignores colour and intensity).
    """
    p = _PROPS
    out = []
    for index in sorted(scene.lights) if model == "spec" else [0]:
        props = scene.lights.get(index, {})
        kind = props.get(p["src"], 0) & _SRC_MASK if model == "spec" else DIRECTIONAL
        if kind not in (DIRECTIONAL, POINT):
            continue
        if model != "spec":
            props = {k: v for k, v in props.items() if k not in (p["col"], p["int"])}
        v = arith.from_bits([props.get(p[n], 0) for n in _VALUES])  # one conversion: 0-d views of it
        out.append(Light(
            index, kind, (v[0, ...], v[1, ...], v[2, ...]), (v[3, ...], v[4, ...], v[5, ...]),
            props.get(p["col"], WHITE),
            v[6, ...] if p["int"] in props else arith.const(DEFAULT_INTENSITY),
        ))
    return out
