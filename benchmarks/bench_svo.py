"""SVO benchmarks: traversal rays/s on one core, build voxels/s and peak memory.

Usage: python benchmarks/bench_svo.py [--depth 10] [--size 640x480] [--runs 3]

Prints the median of ``--runs`` runs of each measurement. The model is the procedural
"folded" blob voxelised at ``--depth``; the camera frames it as ``rend3r svo render``
does. The issue's target is 1 M rays/s per core for the fixed-point traversal (the
thesis FPGA's four-core figure). Traversals: the lockstep numpy kernel (fixed point and
the float64 reference) and, when numba is installed, the compiled per-ray kernel
(``pip install 'rend3r[fast]'``); its one-off JIT compile is timed separately and the
numba/numpy ratio is taken against the numpy figure measured in the same run.
"""

from __future__ import annotations

import argparse
import os
import statistics
import time
import tracemalloc

from rend3r.svo.camera import model_matrix, orbit_camera, primary_rays
from rend3r.svo.fileformat import SvoModel
from rend3r.svo.models import folded
from rend3r.svo.octree import build_octree
from rend3r.svo.traverse import resolve_kernel, trace
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
    # time a real compile, not a load from numba's disk cache (read when the kernel loads)
    os.environ.setdefault("REND3R_JIT_CACHE", "0")
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
    times = {}
    for label, fixed, stack, kernel in (("fixed 16.16, stack 8, numpy", True, 8, "numpy"),
                                        ("fixed 16.16, stack 0, numpy", True, 0, "numpy"),
                                        ("float64 reference, stack 8, numpy", False, 8, "numpy")):
        times[label] = _report(label, tree, rays, stack, fixed, kernel, args.runs)
    t_numpy = times["fixed 16.16, stack 8, numpy"]
    print(f"fixed/float speed ratio (numpy): {times['float64 reference, stack 8, numpy'] / t_numpy:.2f}")

    kernel, note = resolve_kernel("auto")
    if kernel != "numba":
        print(f"numba kernel: not measured ({note})")
        t_best = t_numpy
    else:
        start = time.perf_counter()
        trace(tree, rays.origin[:1], rays.direction[:1], 8, True, True, "numba")
        print(f"numba JIT compile (one-off, first call on one ray, no disk cache): "
              f"{time.perf_counter() - start:.2f} s")
        for label, stack, record in (("fixed 16.16, stack 8, numba", 8, False),
                                     ("fixed 16.16, stack 0, numba", 0, False),
                                     ("fixed 16.16, stack 8, numba, request trace recorded", 8, True)):
            times[label] = _report(label, tree, rays, stack, True, "numba", args.runs, record)
        t_best = times["fixed 16.16, stack 8, numba"]
        print(f"numba/numpy speed ratio, fixed 16.16: stack 8 {t_numpy / t_best:.1f}x, stack 0 "
              f"{times['fixed 16.16, stack 0, numpy'] / times['fixed 16.16, stack 0, numba']:.1f}x")
    print(f"target 1 M rays/s per core: reached {n / t_best / 1e6:.3f} M rays/s "
          f"({'met' if n / t_best >= 1e6 else 'NOT met'})")


def _report(label: str, tree, rays, stack: int, fixed: bool, kernel: str, runs: int,
            record: bool = False) -> float:
    """Trace the frame ``runs`` times, print rays/s of the median run, return its seconds."""
    n = len(rays.origin)
    result = trace(tree, rays.origin, rays.direction, stack, fixed, record, kernel)
    t = _median_time(lambda: trace(tree, rays.origin, rays.direction, stack, fixed, record, kernel), runs)
    s = result.stats()
    print(f"trace {label}: {t:.3f} s = {n / t / 1e3:.1f} k rays/s on one core "
          f"({s['hits']} hits, {s['steps'] / n:.1f} steps/ray, {s['requests_per_ray']:.1f} requests/ray)")
    return t

if __name__ == "__main__":
    main()
