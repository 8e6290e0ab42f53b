"""Shared builders for rasterizer tests."""

from __future__ import annotations

import numpy as np

from rend3r.emu.arith import Arith
from rend3r.emu.raster import RasterView

DEFAULT_CANVAS = (10.0, 7.5)


def view(ar: Arith, location=(0.0, 0.0, 0.0), rotation=None, near=1.0, far=np.inf, canvas=DEFAULT_CANVAS) -> RasterView:
    """A camera with values rounded to the working precision."""
    loc = ar.round(np.asarray(location, dtype=np.float64))
    rot = None if rotation is None else tuple(ar.const(c) for c in rotation)
    return RasterView(loc, rot, float(ar.const(near)), far, tuple(float(ar.const(c)) for c in canvas))


def unit_quaternion(axis, angle: float) -> tuple[float, float, float, float]:
    a = np.asarray(axis, dtype=np.float64)
    a = a / np.linalg.norm(a)
    s = np.sin(angle / 2)
    return (float(np.cos(angle / 2)), *(float(c) for c in a * s))


def ascii_image(prov: np.ndarray) -> str:
    return "\n".join("".join("." if v < 0 else chr(ord("a") + v % 26) for v in row) for row in prov)
