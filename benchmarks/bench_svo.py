"""SVO benchmarks: traversal rays/s on one core, build voxels/s and peak memory.

Usage: python benchmarks/bench_svo.py [--depth 10] [--size 640x480] [--runs 3]

Prints the median of ``--runs`` runs of each measurement. The model is the procedural
"folded" blob voxelised at ``--depth``; the camera frames it as ``rend3r svo render``
does. The issue's target is 1 M rays/s per core for the fixed-point traversal (the
thesis FPGA's four-core figure); the float64 reference traversal is measured in the same
run as the baseline the ratio is taken against.
"""

from __future__ import annotations

import argparse
import statistics
import time
import tracemalloc

from rend3r.svo.camera import model_matrix, orbit_camera, primary_rays
from rend3r.svo.fileformat import SvoModel
from rend3r.svo.models import folded
from rend3r.svo.octree import build_octree
from rend3r.svo.traverse import trace
from rend3r.svo.voxelize import voxelize


def _median_time(fn, runs: int) -> float:
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--depth", type=int, default=10)
    ap.add_argument("--size", default="640x480")
    ap.add_argument("--runs", type=int, default=3)
    args = ap.parse_args()
    width, height = (int(x) for x in args.size.split("x"))
    verts, faces = folded()

    tracemalloc.start()
    start = time.perf_counter()
    coords, lo, h = voxelize(verts, faces, args.depth)
    t_vox = time.perf_counter() - start
    _, peak_vox = tracemalloc.get_traced_memory()
    tracemalloc.reset_peak()
    start = time.perf_counter()
    tree = build_octree(coords, args.depth)
    t_build = time.perf_counter() - start
    _, peak_build = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    dense_bytes = (1 << args.depth) ** 3 // 8
    print(f"model: folded, depth {args.depth}, {len(coords)} voxels, {len(tree.words)} words "
          f"({4 * len(tree.words) / 2**20:.1f} MiB), {tree.far_count()} far pointers")
    print(f"voxelise: {t_vox:.2f} s = {len(coords) / t_vox / 1e6:.2f} M voxels/s, "
          f"peak {peak_vox / 2**20:.0f} MiB")
    print(f"octree build: {t_build:.2f} s = {len(coords) / t_build / 1e6:.2f} M voxels/s, "
          f"peak {peak_build / 2**20:.0f} MiB (a dense bit grid alone would be {dense_bytes / 2**20:.0f} MiB)")

    model = SvoModel(tree, tuple(lo) + tuple(lo + h * (1 << args.depth)), len(coords))
    cam = orbit_camera(model.bounds, width=width, height=height)
    rays = primary_rays(cam, model_matrix(model.bounds))
    n = width * height
    for label, fixed, stack in (("fixed 16.16, stack 8", True, 8), ("fixed 16.16, stack 0", True, 0),
                                ("float64 reference, stack 8", False, 8)):
        result = trace(tree, rays.origin, rays.direction, stack, fixed)
        t = _median_time(lambda: trace(tree, rays.origin, rays.direction, stack, fixed), args.runs)
        s = result.stats()
        print(f"trace {label}: {t:.2f} s = {n / t / 1e3:.1f} k rays/s on one core "
              f"({s['hits']} hits, {s['steps'] / n:.1f} steps/ray, {s['requests_per_ray']:.1f} requests/ray)")
        if label.startswith("fixed 16.16, stack 8"):
            t_fixed = t
        if label.startswith("float"):
            print(f"fixed/float speed ratio: {t / t_fixed:.2f}")
    print(f"target 1 M rays/s per core: reached {n / t_fixed / 1e6:.3f} M rays/s "
          f"({'met' if n / t_fixed >= 1e6 else 'NOT met'})")


if __name__ == "__main__":
    main()
