"""What a point light's shadow rays need of a band's hit points (csrc/datapath.inc
shadow_origins, a packet of pixels at a time): the box of the points, their largest
coordinate, the largest chord between a computed l = fl(location - point) and the exact
line to the light, how many points have a usable l and the shortest |l|, exactly as a
plain computation over the band's arrays finds them."""

from __future__ import annotations

import ctypes

import numpy as np
import pytest

from rend3r.emu import native, raytracer
from rend3r.emu.arith import make_arith
from rend3r.emu.options import EmuOptions
from rend3r.emu.run import run_program

from .scenes import Prog


def _array(address: int, dtype: np.dtype, count: int) -> np.ndarray:
    return np.frombuffer((ctypes.c_char * (count * np.dtype(dtype).itemsize)).from_address(address), dtype).copy()


def expected(lp: native.LightPass, ar, dtype: np.dtype) -> np.ndarray:
    """shadow_origins' ten figures, from the band's arrays, one pixel at a time in numpy."""
    band = lp.band.contents
    n = band.npix
    slot, bad = _array(band.slot, np.int32, n), _array(band.bad, np.uint8, n)
    pt = _array(band.pt, dtype, 3 * n).reshape(3, n)[:, (slot >= 0) & (bad == 0)]
    light = _array(lp.light, dtype, native.LT_COLUMNS)
    at = light[native.LT_LOC:native.LT_LOC + 3]
    l = np.stack([ar.sub(np.full(pt.shape[1], at[c], dtype), pt[c]) for c in range(3)]).astype(np.float64)
    p, a = pt.astype(np.float64), at.astype(np.float64)
    e = a[:, None] - p
    ln, en = np.sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]), np.sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2])
    with np.errstate(all="ignore"):
        c = l / ln - e / en
        chord = np.sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2])
    usable = (ln > 0) & (ln < np.inf)
    return np.array([*p.min(axis=1), *p.max(axis=1), np.abs(p).max(), chord[(ln > 0) & (en > 0)].max(initial=0.0),
                     usable.sum(), ln[usable].min(initial=np.inf)])


@pytest.mark.parametrize("precision", ["fp16", "fp32", "fp64"])
@pytest.mark.parametrize("light_at", [(2.0, 3.0, 4.0), (0.3, -0.2, -3.5), (40.0, -7.0, -2.0)])
def test_shadow_origins_match_a_plain_computation(precision, light_at, monkeypatch):
    """Spheres of several sizes, some pixels missing every shape (a box over 37 x 23
    pixels: packets cut short at each row's end), a light near the eye, inside a sphere,
    far away."""
    prog = Prog().nr().cam(hfov=0.6, vfov=0.6)
    for i, (loc, s) in enumerate((((0.0, 0.0, -3.5), 1.0), ((1.2, 0.6, -5.0), 2.5), ((-1.5, -0.8, -6.0), 0.7))):
        prog.sphere(i, loc=loc, scale=(s, s * 1.3, s))
    prog.light(0, src=2, xloc=light_at[0], yloc=light_at[1], zloc=light_at[2], col=0xFFFF, int=1.0)
    options = EmuOptions(precision=precision, width=37, height=23, jobs=1)
    ar, seen, real = make_arith(precision), [], raytracer._report_origins

    def report(outs):
        merged = real(outs)
        seen.append(merged)
        return merged

    monkeypatch.setattr(raytracer, "_report_origins", report)
    real_run = raytracer._run

    def run(jobs, n, fn, block, last, smallest=None):
        if isinstance(block, native.LightPass) and getattr(fn, "__name__", "").startswith("shadow_origins"):
            seen.append(expected(block, ar, native.dtype(ar)))
        return real_run(jobs, n, fn, block, last, smallest)

    monkeypatch.setattr(raytracer, "_run", run)
    run_program(prog.nf().words, options)
    want, got = seen[0], seen[1]
    assert want[8] > 0  # points with a usable l
    assert want.tolist() == got.tolist()
