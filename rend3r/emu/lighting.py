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
#: Trace hook: (stage name, values per point) for every intermediate, in order.
Recorder = Callable[[str, np.ndarray], None]
_CHANNELS = ((11, 31), (5, 63), (0, 31))  # RGB565: (shift, largest value) per channel
#: The device's intensity converter: I * 2**14 into a 13-bit signed integer.
FIXED_SCALE, FIXED_BITS = 16384, 13


def fixed_intensity(f: np.ndarray) -> np.ndarray:
    """round(f * 16384) (nearest even) wrapped to a 13-bit two's-complement integer."""
    k = np.rint(np.asarray(f, np.float64) * FIXED_SCALE).astype(np.int64)
    half = 1 << (FIXED_BITS - 1)
    return ((k + half) & ((1 << FIXED_BITS) - 1)) - half


def light_factor(ar: Arith, cos: np.ndarray, intensity: np.ndarray) -> np.ndarray:
    """f = cos * intensity: the factor the colour is scaled by (the colour stage)."""
    return ar.mul(cos, intensity)


def diffuse(
    ar: Arith,
    base: np.ndarray,
    normal: Vec,
    point: Vec,
    lights: list[Light],
    occluded: Occluder | None = None,
    intensity_fixed: bool = False,
    record: Recorder | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """RGB565 per point and a mask of points whose lighting met NaN or infinity.

    ``occluded(light, lit, l_vec_of_lit)`` may veto lit points (shadow rays).
    ``intensity_fixed``: the device's 13-bit conversion of ``f`` (quirk intensity-13bit).
    ``record`` receives every intermediate (``docs/trace.md`` stage names).
    """
    rec = record if record is not None else (lambda name, value: None)
    bad = ~(np.isfinite(point[0]) & np.isfinite(point[1]) & np.isfinite(point[2]))
    if not lights:
        return base, bad
    channels = [(base >> shift) & top for shift, top in _CHANNELS]
    acc: list[np.ndarray | None] = [None] * len(_CHANNELS)
    nn = ar.sqrt(dot(ar, normal, normal))
    for light in lights:
        tag = f"L{light.index}."
        if light.kind == POINT:
            l_vec = sub3(ar, light.location, point)
        else:
            l_vec = tuple(ar.neg(c) for c in light.forward)
        for axis, c in zip("xyz", l_vec):
            rec(f"{tag}l.{axis}", c)
        n_dot_l = dot(ar, normal, l_vec)
        l_len = ar.sqrt(dot(ar, l_vec, l_vec))
        denom = ar.mul(nn, l_len)
        cos = ar.div(n_dot_l, denom)
        f = light_factor(ar, cos, light.intensity)
        for name, value in (("n_dot_l", n_dot_l), ("n_len", nn), ("l_len", l_len), ("denom", denom),
                            ("cos", cos), ("f", f)):
            rec(tag + name, value)
        finite = np.isfinite(cos) & np.isfinite(f)
        bad |= ~finite
        factor = f
        if intensity_fixed:
            k = fixed_intensity(np.where(finite, f, 0.0))
            rec(tag + "fixed", k)
            factor = k / FIXED_SCALE
        on = finite & ~bad & (cos > 0)
        if intensity_fixed:
            on &= factor > 0  # a wrapped, negative converter output is black
        if occluded is not None:
            lit = np.flatnonzero(on)
            shadow = occluded(light, lit, tuple(np.take(c, lit) if np.ndim(c) else c for c in l_vec))
            rec(tag + "shadow", shadow)
            on[lit[shadow]] = False
        # unlit points weigh 0: adding 0 * channel * scale (= +0) leaves their sums as they are
        weight = np.zeros(len(base))
        np.copyto(weight, factor, where=on)
        for c, (ch, (shift, top)) in enumerate(zip(channels, _CHANNELS)):
            term = np.multiply(weight, ch)  # float64, the channel cast exactly: factor * channel, then * scale
            term *= ((light.color >> shift) & top) / top
            acc[c] = term if acc[c] is None else np.add(acc[c], term, out=acc[c])
    out = np.zeros(len(base), np.uint16)
    for a, (shift, top) in zip(acc, _CHANNELS):
        a += 0.5
        np.floor(a, out=a)
        np.clip(a, 0, top, out=a)
        out |= a.astype(np.uint16) << shift
    return out, bad
