"""A point light's shadows against a directional light's, 1-65,536 spheres.

The scenes are the benchmark walls (walls.py) lit by one light with shadows: the
directional light of bench_peer.py, or a point light up, right and behind the eye
(walls.POINT_LIGHT), lighting the same faces. Its shadow rays head back past the eye,
and the walls' hidden spheres lie behind every origin along the rays' lines: the scenes
where a point light's packets must skip subtrees lying behind them (csrc/cull.h
point_behind4). One core, 512x384, whole ``run_program``, median of ``--runs`` timed runs
after a warm-up; the ratio is point / directional, measured in the same run. Both lights'
frames must show the same shapes (exit 1 if not: the light changes colours only).

    python benchmarks/bench_lights.py [--sizes 1 16 256 4096 65536] [--runs 5] [--precision fp32]
"""

from __future__ import annotations

import argparse
import sys

import walls
from bench_raytrace import measure

from rend3r.emu.options import EmuOptions
from rend3r.memory import reuse_freed_memory

WIDTH, HEIGHT = 512, 384


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=sorted(walls.LAYOUT), choices=sorted(walls.LAYOUT))
    ap.add_argument("--runs", type=int, default=5, help="timed runs per measurement; medians are reported")
    ap.add_argument("--precision", default="fp32")
    args = ap.parse_args()
    reuse_freed_memory()
    options = EmuOptions(precision=args.precision, width=WIDTH, height=HEIGHT, jobs=1)
    print(f"{args.precision}, {WIDTH}x{HEIGHT}, one core, median of {args.runs} runs; point light at "
          f"{walls.POINT_LIGHT}, directional along {walls.LIGHT}")
    print(f"{'spheres':>8} {'directional':>12} {'point':>10} {'point / dir':>12} {'shadow rays (point)':>20}")
    same = True
    for n in args.sizes:
        directional, d = measure(walls.wall(n, 1).words, options, args.runs)
        point, p = measure(walls.wall(n, 1, point=True).words, options, args.runs)
        same &= bool((d.frames[0].provenance == p.frames[0].provenance).all())
        print(f"{n:>8,} {directional * 1e3:>10.2f}ms {point * 1e3:>8.2f}ms {point / directional:>11.2f}x "
              f"{p.stats.frames[0].shadow_rays:>20,}", flush=True)
    if not same:
        print("the two lights' frames show different shapes", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
