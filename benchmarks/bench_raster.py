"""Rasterizer speed: 12, 1,000 and 100,000 triangles at 512x384 against the device.

Run: ``python benchmarks/bench_raster.py [--runs R] [--precision fp16]``. For each scene
and visibility mode it prints the median wall time per frame over R runs (one directional
light, flat shading, fp16 ftz by default) beside the original device's figure of about
1.96 ms per triangle (a whole-screen scan per triangle, paper section V-C1), and the
ratio device / emulator (above 1: the emulator is faster), and the same frame in fp32
measured in the same run as a baseline for the cost of float16 rounding.

Scenes, with their coverage of the 512x384 frame in fp16 (pixels any triangle covers):
a cube of 12 triangles covering 23.1% (23.3% in fp32); a UV sphere of 1,000 triangles
covering 2.3%; 100,000 small random triangles scattered over the whole view at depths
3-12, covering 90.8% (1.15 million fragments, depth complexity ~6). The cube and sphere
draw their back faces too, so each has twice as many fragments as covered pixels. The
emulator's time follows fragments more than triangles: the sphere's 1,000 triangles take
less time than the cube's 12 because they cover a tenth of the pixels. The device's
time follows triangles only.
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from rend3r.emu.arith import make_arith
from rend3r.emu.lights import DIRECTIONAL, Light
from rend3r.emu.meshes import cube, triangle_soup, uv_sphere
from rend3r.emu.raster import RasterView, render_triangles

DEVICE_S_PER_TRIANGLE = 196_675 * 10e-9  # paper: 63 + 4 + 512*384 cycles at 100 MHz
WIDTH, HEIGHT = 512, 384


def scenes() -> list[tuple[str, np.ndarray]]:
    return [
        ("cube", cube(centre=(0.0, 0.0, -3.7), half=2.5)),
        ("sphere", uv_sphere(11, 50, centre=(0.0, 0.0, -5.0), radius=3.0)),
        ("soup", triangle_soup(100_000)),
    ]


def _median_ms(tris, colours, light, view, ar, mode: str, runs: int):
    times = []
    for _ in range(runs):
        t0 = time.perf_counter()
        res = render_triangles(tris, colours, [light], view, ar, (WIDTH, HEIGHT), mode)
        times.append(time.perf_counter() - t0)
    return statistics.median(times) * 1e3, res


def _setup(ar):
    view = RasterView(ar.round(np.zeros(3)), None, 1.0, np.inf, (10.0, 7.5))
    one = ar.const(1.0)
    light = Light(0, DIRECTIONAL, (ar.const(0.0),) * 3, (ar.const(-0.5), ar.const(-1.0), ar.neg(one)), 0xFFFF, one)
    return view, light


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--precision", default="fp16", choices=["fp16", "fp32", "fp64"])
    args = ap.parse_args()
    ar, base = make_arith(args.precision), make_arith("fp32")
    view, light = _setup(ar)
    bview, blight = _setup(base)
    print(f"rasterizer, {WIDTH}x{HEIGHT}, {ar.label}, median of {args.runs} runs per frame; "
          f"baseline: the same frame in fp32 (no per-operation rounding), measured in this run")
    print(f"{'scene':8} {'triangles':>9} {'depth':8} {'emulator ms':>12} {'fp32 ms':>8} {'device ms':>10} "
          f"{'device/emu':>10} {'fragments':>10}")
    for name, tris in scenes():
        colours = (np.arange(len(tris)) * 2654435761 % 65536).astype(np.uint16)
        device_ms = DEVICE_S_PER_TRIANGLE * len(tris) * 1e3
        for mode in ("zbuffer", "painter"):
            ms, res = _median_ms(tris, colours, light, view, ar, mode, args.runs)
            base_ms, _ = _median_ms(tris, colours, blight, bview, base, mode, args.runs)
            print(f"{name:8} {len(tris):9d} {mode:8} {ms:12.2f} {base_ms:8.2f} {device_ms:10.1f} "
                  f"{device_ms / ms:10.1f} {res.stats.fragments:10d}")


if __name__ == "__main__":
    main()
