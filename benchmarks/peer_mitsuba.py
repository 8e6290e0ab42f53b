"""Peer renderer for the sphere benchmarks: Mitsuba 3 renders the same scenes, timed on pinned cores.

Set-up: ``python -m pip install mitsuba`` (3.9.1 with Dr.Jit 1.5.0 was measured). The
``llvm_ad_rgb`` variant needs an LLVM >= 16 shared library (LLVM 15 crashes in code
generation): ``apt-get install libllvm19`` on Debian bookworm. Its path is passed to Dr.Jit
as ``DRJIT_LIBLLVM_PATH`` unless that is already set (see :func:`find_libllvm`).

Scene: REND3R's spec camera (eye at the origin looking along -z, +y up, a 10*hfov x 7.5*vfov
viewport at distance 1, hits from camera depth 1 on, one sample at each pixel centre), one
``diffuse`` sphere per input sphere, one ``directional`` light of irradiance 1, and the
``direct`` integrator with one emitter sample and no BSDF sample: one camera ray per pixel
and one shadow ray per hit pixel (a BSDF-sampled ray can never reach a delta light).

Each measurement runs in a fresh interpreter pinned with ``os.sched_setaffinity`` before
numpy, Dr.Jit or Mitsuba start a thread, with Dr.Jit's pool (which Mitsuba's scalar
renderer and scene loader use too) set to ``threads``. Build time (Mitsuba objects from the
arrays, the scene, its BVH) is taken apart from render time: ``mi.render(scene, spp=1)`` plus
the copy to numpy, which forces the lazy LLVM variant's kernels; one untimed warm-up
render (the LLVM variant compiles its kernel there) precedes ``runs`` timed renders. The
worker prints ``ready`` and waits for a line on its stdin before each timed render, so a
benchmark can time its own renderer in between (``render_spheres``'s ``between``; each
timed render then follows an untimed one, which doubles Mitsuba's part of the run).

    python benchmarks/peer_mitsuba.py [--variants scalar_rgb llvm_ad_rgb] [--sizes 1 16 256 4096 65536]
                                      [--runs 3] [--threads 1] [--check]
"""

from __future__ import annotations

import argparse
import contextlib
import glob
import importlib.util
import math
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

VARIANTS = ("scalar_rgb", "llvm_ad_rgb")
#: A 'k x k x depth' sphere grid for each benchmark size.
LAYOUT = {1: (1, 1), 16: (4, 1), 256: (16, 1), 4096: (64, 1), 65536: (64, 16)}
BENCH_FOV = 0.2  # hfov = vfov of the benchmark table: a 90-degree horizontal view
BENCH_LIGHT = (-0.3, -0.4, -1.0)  # bench_raytrace.py's light direction


@dataclass
class PeerResult:
    """Timings (seconds) and image of one Mitsuba measurement."""

    variant: str
    n: int  #: number of spheres
    threads: int  #: CPUs the process was pinned to, and Dr.Jit's thread count
    build_seconds: float  #: arrays -> Mitsuba objects -> scene (incl. the BVH)
    warmup_seconds: float  #: the untimed first render (incl. the LLVM variant's compile)
    render_seconds: list[float]  #: each timed render, forced to a numpy array
    #: LLVM variant: Dr.Jit's kernel execution time in one more render, with its kernel history
    #: on (which costs ~4%, so not in the timed ones); the rest of a render is tracing the
    #: renderer, which grows with the number of shapes and distinct BSDFs. Scalar: None.
    kernel_seconds: float | None
    image: np.ndarray = field(repr=False)  #: (H, W, 3) float32 linear RGB, row 0 at the top
    hit: np.ndarray = field(repr=False)  #: (H, W) bool: the camera ray hits a sphere (untimed depth render)

    @property
    def median(self) -> float:
        """Median of the timed renders."""
        return statistics.median(self.render_seconds)


def find_libllvm() -> str | None:
    """Path of the newest system libLLVM with major version >= 16, or None."""
    best: tuple[int, str] | None = None
    for path in glob.glob("/usr/lib/*/libLLVM*.so*") + glob.glob("/usr/lib/llvm-*/lib/libLLVM*.so*"):
        m = re.search(r"libLLVM(?:-|\.so\.)(\d+)", os.path.basename(path))
        if m and int(m.group(1)) >= 16 and (best is None or int(m.group(1)) > best[0]):
            best = (int(m.group(1)), path)
    return best[1] if best else None


def render_spheres(variant: str, centers: np.ndarray, radii: np.ndarray, colors: np.ndarray,
                   light_dir: tuple[float, float, float], width: int = 512, height: int = 384,
                   hfov: float = 1.0, vfov: float = 1.0, runs: int = 3, threads: int = 1,
                   between: Callable[[], None] | None = None) -> PeerResult:
    """Build and render the spheres with Mitsuba ``variant`` in a subprocess pinned to ``threads`` CPUs.

    ``between`` (if given) runs in this process before each timed render, while the
    subprocess waits: a benchmark times its own renderer there, so that the two alternate
    render by render and a drift of the machine's speed falls on both. Each timed render
    then follows an untimed one, so that it finds the core's caches warm with its own data
    as ``between`` should find them with the benchmark's.

    ``centers`` (N, 3) and ``radii`` (N,) in world units, ``colors`` (N, 3) linear diffuse
    reflectance in [0, 1]; ``light_dir`` is the direction the light travels. Mitsuba's
    pixels are square (its sensor rejects a scaled ``to_world``), so the viewport must
    be too: ``10*hfov/width == 7.5*vfov/height`` (hfov == vfov at 4:3), else ValueError.
    Raises RuntimeError naming what to install when Mitsuba or the variant is missing.
    """
    centers, radii, colors = (np.asarray(a, np.float64) for a in (centers, radii, colors))
    n = len(centers)
    if centers.shape != (n, 3) or radii.shape != (n,) or colors.shape != (n, 3):
        raise ValueError(f"want centers (N, 3), radii (N,), colors (N, 3); got {centers.shape}, "
                         f"{radii.shape}, {colors.shape}")
    if not math.isclose(10 * hfov * height, 7.5 * vfov * width, rel_tol=1e-6):
        raise ValueError(f"non-square pixels ({10 * hfov / width:.6g} x {7.5 * vfov / height:.6g}): Mitsuba's "
                         f"perspective sensor cannot render them; need 10*hfov/width == 7.5*vfov/height")
    cpus = sorted(os.sched_getaffinity(0))
    if not 1 <= threads <= len(cpus):
        raise ValueError(f"threads={threads}, but this process may use {len(cpus)} CPUs")
    if runs < 1:
        raise ValueError(f"runs={runs}: need at least one timed render")
    if variant not in VARIANTS:
        raise ValueError(f"variant {variant!r}: choose from {', '.join(VARIANTS)}")
    if importlib.util.find_spec("mitsuba") is None:
        raise RuntimeError("Mitsuba 3 is not installed: python -m pip install mitsuba")
    env = dict(os.environ)
    if variant.startswith("llvm") and "DRJIT_LIBLLVM_PATH" not in env and (lib := find_libllvm()):
        env["DRJIT_LIBLLVM_PATH"] = lib
    with tempfile.TemporaryDirectory(prefix="peer_mitsuba_") as tmp:
        scene, out = Path(tmp, "scene.npz"), Path(tmp, "result.npz")
        np.savez(scene, centers=centers, radii=radii, colors=colors, light_dir=np.asarray(light_dir, np.float64),
                 size=np.array([width, height]), fov=np.array([hfov, vfov]), runs=runs, threads=threads,
                 variant=variant, warm=int(between is not None))
        # Pin first: threads inherit the affinity of the thread that creates them.
        code = ("import os, sys; os.sched_setaffinity(0, {int(c) for c in sys.argv[1].split(',')})\n"
                "sys.path.insert(0, sys.argv[2]); from peer_mitsuba import _worker; _worker(sys.argv[3], sys.argv[4])")
        with open(Path(tmp, "stderr.txt"), "w+") as err:
            proc = subprocess.Popen([sys.executable, "-c", code, ",".join(map(str, cpus[:threads])),
                                     os.path.dirname(os.path.abspath(__file__)), str(scene), str(out)],
                                    env=env, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=err, text=True)
            with proc:
                try:
                    for _ in range(runs):  # the worker waits for a line before each timed render
                        if not _said(proc, "ready"):
                            break
                        if between is not None:
                            between()
                        proc.stdin.write("go\n")
                        proc.stdin.flush()
                except BrokenPipeError:  # the worker died: its exit status and stderr say why
                    pass
                with contextlib.suppress(BrokenPipeError):  # closed even when the flush fails
                    proc.stdin.close()
                proc.stdout.read()
            err.seek(0)
            if proc.returncode != 0:
                raise RuntimeError(f"Mitsuba peer ({variant}) failed: {err.read().strip()[-2000:]}")
        with np.load(out) as r:
            kernel = float(r["kernel"]) if r["kernel"] >= 0 else None
            return PeerResult(variant, n, threads, float(r["build"]), float(r["warmup"]), r["render"].tolist(),
                              kernel, r["image"], r["hit"])


def _said(proc: subprocess.Popen, word: str) -> bool:
    """Reads the worker's output up to a line ``word`` (Mitsuba may print other lines);
    False when it ended first."""
    for line in proc.stdout:
        if line.strip() == word:
            return True
    return False


def _build_scene(mi: Any, s: dict[str, np.ndarray]) -> Any:
    """The Mitsuba scene for a scene read from the npz written by :func:`render_spheres`.

    Each sphere is made by its own ``mi.load_dict`` and the scene from those objects, with one
    BSDF per distinct colour: 1.5x faster than one ``mi.load_dict`` of the whole scene in
    scalar_rgb (65,536 spheres: 3.9 s against 5.7 s) and 10% in llvm_ad_rgb, same image.
    """
    width, height = (int(v) for v in s["size"])
    hfov = float(s["fov"][0])
    scene: dict[str, Any] = {
        "type": "scene",
        "integrator": {"type": "direct", "emitter_samples": 1, "bsdf_samples": 0},
        "sensor": {
            "type": "perspective",
            "fov_axis": "x",
            "fov": math.degrees(2 * math.atan(5 * hfov)),  # vertical extent follows from square pixels
            "near_clip": 1.0,  # the spec camera accepts hits from camera depth 1 on
            "to_world": mi.ScalarTransform4f().look_at(origin=[0, 0, 0], target=[0, 0, -1], up=[0, 1, 0]),
            # one sample at each pixel centre, as the spec camera; times as 'independent' (measured)
            "sampler": {"type": "stratified", "sample_count": 1, "jitter": False},
            "film": {"type": "hdrfilm", "width": width, "height": height, "pixel_format": "rgb",
                     "rfilter": {"type": "box"}},
        },
        "light": {"type": "directional", "direction": s["light_dir"].tolist(),
                  "irradiance": {"type": "rgb", "value": 1.0}},
    }
    colors, which = np.unique(s["colors"], axis=0, return_inverse=True)
    bsdfs = [mi.load_dict({"type": "diffuse", "reflectance": {"type": "rgb", "value": rgb}})
             for rgb in colors.tolist()]
    for i, (c, r, k) in enumerate(zip(s["centers"].tolist(), s["radii"].tolist(), which.ravel().tolist(),
                                      strict=True)):
        scene[f"sphere{i}"] = mi.load_dict({"type": "sphere", "center": c, "radius": r, "bsdf": bsdfs[k]})
    return mi.load_dict(scene)


def _worker(scene_path: str, out_path: str) -> None:
    """Subprocess side of :func:`render_spheres`: build, warm up, time, write the result npz."""
    with np.load(scene_path) as f:
        s = {k: f[k] for k in f.files}
    variant, threads, runs, warm = str(s["variant"]), int(s["threads"]), int(s["runs"]), int(s["warm"])
    import drjit as dr
    import mitsuba as mi

    dr.set_thread_count(threads)  # before any parallel work; the calling thread counts as one
    if variant not in mi.variants():
        sys.exit(f"variant {variant} is not in this Mitsuba build (it has {', '.join(mi.variants())})")
    hint = ("The LLVM variants need LLVM >= 16: apt-get install libllvm19, and DRJIT_LIBLLVM_PATH=<path of "
            "libLLVM.so.19.1> if Dr.Jit does not find it")
    try:
        mi.set_variant(variant)
    except ImportError as e:
        sys.exit(f"cannot start {variant}: {e}\n{hint}")
    if variant.startswith("llvm") and dr.detail.llvm_version() < (16,):
        sys.exit(f"{variant}: Dr.Jit loaded LLVM {dr.detail.llvm_version()}, whose code generation crashes. {hint}")
    start = time.perf_counter()
    scene = _build_scene(mi, s)
    build = time.perf_counter() - start
    start = time.perf_counter()
    np.array(mi.render(scene, spp=1))
    warmup = time.perf_counter() - start
    renders = []
    for _ in range(runs):
        print("ready", flush=True)
        if not sys.stdin.readline():  # render_spheres runs its `between` meanwhile
            sys.exit("the benchmark stopped before the timed renders")
        for _ in range(warm):
            np.array(mi.render(scene, spp=1))
        start = time.perf_counter()
        image = np.array(mi.render(scene, spp=1), dtype=np.float32)
        renders.append(time.perf_counter() - start)
    kernel = -1.0
    if variant.startswith("llvm"):
        dr.set_flag(dr.JitFlag.KernelHistory, True)
        np.array(mi.render(scene, spp=1))
        kernel = sum(k.get("execution_time", 0.0) for k in dr.kernel_history()) / 1000  # from ms
    # the 'depth' integrator; the 'aov' one's depth costs O(spheres) per pixel in scalar_rgb (150 s at 4096)
    depth = np.array(mi.render(scene, integrator=mi.load_dict({"type": "depth"}), spp=1))
    np.savez(out_path, build=build, warmup=warmup, render=np.array(renders), kernel=kernel, image=image,
             hit=depth[..., 0] > 0)


def check_projection(variant: str = "scalar_rgb", fov: float = 1.0) -> float:
    """Pixel distance between a small off-centre sphere's centroid in the Mitsuba image and its analytic projection.

    The centroid of the sphere's hit pixels (centre (2, 1, -5), radius 0.3) is compared with the spec
    camera's projection of its centre, ((x/-z) / (10*fov) + 0.5) * W, (0.5 - (y/-z) / (7.5*fov)) * H.
    Perspective draws an off-axis sphere as an ellipse whose centre lies slightly further out
    than the projected centre: by 0.08 px at fov 1 and 0.41 px at fov 0.2.
    """
    centre = np.array([2.0, 1.0, -5.0])
    res = render_spheres(variant, centre[None], np.array([0.3]), np.ones((1, 3)), (0.0, 0.0, -1.0),
                         hfov=fov, vfov=fov, runs=1)
    height, width = res.hit.shape
    ys, xs = np.nonzero(res.hit)
    if len(xs) == 0:
        raise RuntimeError("the sphere is not in the Mitsuba image")
    want_x = (centre[0] / -centre[2] / (10 * fov) + 0.5) * width
    want_y = (0.5 - centre[1] / -centre[2] / (7.5 * fov)) * height
    return math.hypot(xs.mean() + 0.5 - want_x, ys.mean() + 0.5 - want_y)


def grid_scene(n: int, fov: float = BENCH_FOV) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The benchmark's ``n`` spheres: a k x k x depth grid (LAYOUT) filling the view, front layer at z = -10.

    The grid spans x, y in [-8, 8] * fov / 0.2 (the view is 20 x 15 at that distance); each
    sphere's radius is 0.45 of the spacing, and its colour follows its grid position.
    """
    k, depth = LAYOUT[n]
    spacing = 16.0 * fov / 0.2 / k
    i, j, d = (a.ravel() for a in np.meshgrid(np.arange(k), np.arange(k), np.arange(depth), indexing="ij"))
    centers = np.stack([(i - (k - 1) / 2) * spacing, (j - (k - 1) / 2) * spacing, -10.0 - d * spacing], axis=1)
    colors = np.stack([(i + 1) / k, (j + 1) / k, 1.0 - d / depth], axis=1)
    return centers, np.full(n, 0.45 * spacing), colors


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--variants", nargs="+", default=list(VARIANTS), choices=VARIANTS)
    ap.add_argument("--sizes", type=int, nargs="+", default=sorted(LAYOUT), choices=sorted(LAYOUT))
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--threads", type=int, nargs="+", default=[1])
    ap.add_argument("--check", action="store_true", help="first print check_projection() for each variant")
    args = ap.parse_args()
    if args.check:
        for variant in args.variants:
            print(f"projection error, {variant}: {check_projection(variant):.3f} px (hfov 1), "
                  f"{check_projection(variant, BENCH_FOV):.3f} px (hfov {BENCH_FOV})", flush=True)
    print(f"{'variant':>12} {'spheres':>7} {'threads':>7} {'build s':>8} {'warm-up s':>9} {'render s':>9} "
          f"{'kernel s':>9} {'coverage':>8}")
    for variant in args.variants:
        for n in args.sizes:
            centers, radii, colors = grid_scene(n)
            for threads in args.threads:
                r = render_spheres(variant, centers, radii, colors, BENCH_LIGHT, hfov=BENCH_FOV, vfov=BENCH_FOV,
                                   runs=args.runs, threads=threads)
                kernel = f"{r.kernel_seconds:9.4f}" if r.kernel_seconds is not None else f"{'-':>9}"
                coverage = float(r.hit.mean())
                print(f"{variant:>12} {n:>7} {threads:>7} {r.build_seconds:8.3f} {r.warmup_seconds:9.3f} "
                      f"{r.median:9.4f} {kernel} {coverage:8.3f}", flush=True)


if __name__ == "__main__":
    main()
