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


def _band_after_nearest(fr, options: EmuOptions) -> tuple[native.Band, list]:
    """The frame's one band with its nearest hits (the nearest-hit kernel over every row),
    and the arrays it points into."""
    n_pix, dtype = options.pixels, fr.dtype
    bands, keep = raytracer._bands(fr, options, options.height)
    band = bands.band.contents
    arrays = {"slot": np.empty(n_pix, np.int32), "sqd": np.empty(n_pix, dtype), "pt": np.empty((3, n_pix), dtype),
              "nm": np.empty((3, n_pix), dtype), "bad": np.empty(n_pix, np.uint8), "nan_px": np.empty(n_pix, np.uint8),
              "acc": np.empty((3, 0)), "rgb": np.empty(n_pix, np.uint16), "depth": np.empty(n_pix, np.float32),
              "prov": np.empty(n_pix, np.int32)}
    for name, a in arrays.items():
        setattr(band, name, a.ctypes.data)
    band.npix = n_pix
    fr.kernel("nearest")(ctypes.byref(band), 0, options.height, np.array(_REPORT).ctypes.data)
    return band, [bands, keep, arrays]


#: The nearest-hit kernel's report row as it starts (csrc/band.c REPORT).
_REPORT = [0.0] * 4 + [np.inf] * 3 + [-np.inf] * 3 + [0.0, 0.0]


@pytest.mark.parametrize("precision", ["fp16", "fp32", "fp64"])
@pytest.mark.parametrize("light_at", [(2.0, 3.0, 4.0), (0.3, -0.2, -3.5), (40.0, -7.0, -2.0)])
def test_shadow_origins_match_a_plain_computation(precision, light_at):
    """Spheres of several sizes, some pixels missing every shape (a box over 37 x 23
    pixels: packets cut short at each row's end), a light near the eye, inside a sphere,
    far away; the kernel over the whole band and over two chunks (whose figures join)."""
    prog = Prog().nr().cam(hfov=0.6, vfov=0.6)
    for i, (loc, s) in enumerate((((0.0, 0.0, -3.5), 1.0), ((1.2, 0.6, -5.0), 2.5), ((-1.5, -0.8, -6.0), 0.7))):
        prog.sphere(i, loc=loc, scale=(s, s * 1.3, s))
    prog.light(0, src=2, xloc=light_at[0], yloc=light_at[1], zloc=light_at[2], col=0xFFFF, int=1.0)
    options = EmuOptions(precision=precision, width=37, height=23, jobs=1)
    scenes = []
    run_program(prog.nf().words, options, on_scene=lambda scene, _: scenes.append(scene))
    fr = raytracer.set_up(scenes[0], options)
    band, _keep = _band_after_nearest(fr, options)
    lp = native.LightPass(ctypes.pointer(fr.shapes), ctypes.pointer(band), fr.light_rows[0].ctypes.data)
    origins = fr.kernel("shadow_origins")
    start = [np.inf] * 3 + [-np.inf] * 3 + [0.0, 0.0, 0.0, np.inf]
    whole, halves = np.array(start), np.array([start, start])
    origins(ctypes.byref(lp), 0, band.npix, whole.ctypes.data)
    for k, (p0, p1) in enumerate(((0, 301), (301, band.npix))):  # a packet cut short at 301
        origins(ctypes.byref(lp), p0, p1, halves[k].ctypes.data)
    want = expected(lp, make_arith(precision), fr.dtype)
    assert want[8] > 0  # points with a usable l
    assert want.tolist() == whole.tolist()
    joined = [*halves[:, :3].min(axis=0), *halves[:, 3:8].max(axis=0), halves[:, 8].sum(), halves[:, 9].min()]
    assert joined == whole.tolist()
