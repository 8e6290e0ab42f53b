"""Diffuse lighting and its colour arithmetic, shared by the raytracer and the rasterizer.

Per light that is on: ``l`` = ``-forward`` (directional) or ``location - point`` (point);
``cos = (n.l) / (sqrt(n.n) * sqrt(l.l))`` and ``f = cos * intensity``, each step in the
working precision; lights with ``cos <= 0`` (or occluded, per the caller) add nothing.
The RGB565 channels are then accumulated in float64, ``channel * f * light_channel /
channel_max``, rounded half up and clamped to the channel range (``docs/emulator.md``).
With no light on, the base colour shows unlit.
"""

from __future__ import annotations

from typing import Callable

import numpy as np

from .arith import Arith
from .lights import POINT, Light
from .vec import Vec, dot, sub3

#: Occlusion test: (light, positions of the lit points) -> mask of those in shadow.
Occluder = Callable[[Light, np.ndarray, Vec], np.ndarray]
_MAX = np.array([31, 63, 31])


def diffuse(
    ar: Arith, base: np.ndarray, normal: Vec, point: Vec, lights: list[Light], occluded: Occluder | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """RGB565 per point and a mask of points whose lighting met NaN or infinity.

    ``occluded(light, lit, l_vec_of_lit)`` may veto lit points (shadow rays).
    """
    bad = ~(np.isfinite(point[0]) & np.isfinite(point[1]) & np.isfinite(point[2]))
    if not lights:
        return base, bad
    channels = np.stack([base >> 11, (base >> 5) & 0x3F, base & 0x1F], axis=1).astype(np.float64)
    acc = np.zeros_like(channels)
    nn = ar.sqrt(dot(ar, normal, normal))
    for light in lights:
        if light.kind == POINT:
            l_vec = sub3(ar, light.location, point)
        else:
            l_vec = tuple(ar.neg(c) for c in light.forward)
        cos = ar.div(dot(ar, normal, l_vec), ar.mul(nn, ar.sqrt(dot(ar, l_vec, l_vec))))
        f = ar.mul(cos, light.intensity)
        finite = np.isfinite(cos) & np.isfinite(f)
        bad |= ~finite
        lit = np.nonzero(finite & ~bad & (cos > 0))[0]
        if occluded is not None:
            lit = lit[~occluded(light, lit, tuple(c[lit] if np.ndim(c) else c for c in l_vec))]
        lc = light.color
        scale = np.array([(lc >> 11) / 31.0, ((lc >> 5) & 0x3F) / 63.0, (lc & 0x1F) / 31.0])
        acc[lit] += np.asarray(f, np.float64)[lit, None] * channels[lit] * scale
    ch = np.clip(np.floor(acc + 0.5), 0, _MAX).astype(np.uint16)
    return (ch[:, 0] << 11) | (ch[:, 1] << 5) | ch[:, 2], bad
