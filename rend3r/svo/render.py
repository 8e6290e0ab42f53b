"""Render an SVO model: depth or shaded image, per-ray cost image, statistics."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .camera import Camera, PrimaryRays, model_matrix, primary_rays, t_to_distance, t_to_ndc_z
from .fileformat import SvoModel
from .traverse import Kernel, TraceResult, trace


@dataclass
class Render:
    """One rendered frame; images are (height, width[, 3])."""

    rgb: np.ndarray        #: uint8 (h, w, 3)
    ndc_z: np.ndarray      #: float32: projection z of the hit, inf on a miss
    distance: np.ndarray   #: float32: eye distance of the hit, inf on a miss
    cost: np.ndarray       #: int32: memory requests per ray
    result: TraceResult
    rays: PrimaryRays


def shade(result: TraceResult, direction: np.ndarray, dist: np.ndarray, mode: str, height: int,
          width: int, light=(0.4, 0.7, 0.6)) -> np.ndarray:
    """``depth``: grey by eye distance ``dist`` (near bright); ``shaded``: Lambert on the
    entered voxel faces (``direction``: the rays' octree-space directions)."""
    hit = result.hit
    img = np.zeros((len(hit), 3), dtype=np.float64)
    if mode == "depth":
        if hit.any():
            lo, hi = dist[hit].min(), dist[hit].max()
            img[hit] = (1.0 - 0.8 * (dist[hit] - lo) / max(hi - lo, 1e-12))[:, None]
    elif mode == "shaded":
        normal = np.zeros((len(hit), 3))
        rows = np.flatnonzero(hit)
        axis = result.axis[hit].astype(np.int64)
        normal[rows, axis] = -np.sign(direction[rows, axis])
        lvec = np.asarray(light, dtype=np.float64)
        lvec /= np.linalg.norm(lvec)
        lambert = np.clip(normal @ lvec, 0.0, 1.0)
        base = np.array([0.85, 0.75, 0.55])
        img[hit] = base * (0.25 + 0.75 * lambert[hit, None])
    else:
        raise ValueError(f"unknown shading mode {mode!r}")
    return (np.clip(img, 0, 1) * 255 + 0.5).astype(np.uint8).reshape(height, width, 3)


def render(model: SvoModel, cam: Camera, stack_depth: int = 8, fixed: bool = True,
           mode: str = "shaded", record: bool = False, kernel: Kernel = "auto",
           on_rays: Callable[[int], None] | None = None) -> Render:
    """Trace one frame; hits beyond the far plane (t > 1) count as misses.

    ``kernel``: traversal implementation (:func:`rend3r.svo.traverse.resolve_kernel`);
    ``on_rays(count)``: called as chunks of rays are traced (:func:`rend3r.svo.traverse.trace`).
    """
    rays = primary_rays(cam, model_matrix(model.bounds))
    res = trace(model.tree, rays.origin, rays.direction, stack_depth, fixed, record, kernel, on_rays)
    beyond = res.hit & (res.t > 1.0)
    res.hit[beyond] = False
    res.t[beyond] = np.inf
    res.axis[beyond] = -1
    res.voxel[beyond] = -1
    h, w = cam.height, cam.width
    dist = t_to_distance(rays, res.t)
    rgb = shade(res, rays.direction, dist, mode, h, w)
    ndc = t_to_ndc_z(rays, res.t, cam).astype(np.float32).reshape(h, w)
    return Render(rgb, ndc, dist.astype(np.float32).reshape(h, w), res.requests.reshape(h, w), res, rays)


def cost_image(cost: np.ndarray) -> np.ndarray:
    """Figure 7.5: grey level proportional to memory requests per ray (uint8)."""
    top = max(int(cost.max(initial=0)), 1)
    return (cost.astype(np.float64) / top * 255 + 0.5).astype(np.uint8)
