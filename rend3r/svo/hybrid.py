"""Hybrid frames (thesis Chapter 7.4): an SVO's colour and depth merged with a REND3R
frame through one depth buffer.

Depth conventions: REND3R frames hold the Euclidean distance from the camera to the
hit (``inf`` where nothing was hit); the thesis's ray tracer produces the projection's
z (Equations 5.4-5.5). :func:`ndc_z_to_distance` and :func:`distance_to_ndc_z` convert
one into the other for a :class:`~rend3r.svo.camera.Camera`; :func:`merge` compares
distances. On equal distances the REND3R frame's pixel is kept.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..errors import Rend3rError
from .camera import Camera


def rgb888_to_565(rgb: np.ndarray) -> np.ndarray:
    """(h, w, 3) uint8 -> (h, w) uint16 RGB565 (truncating, as the frame buffer does)."""
    rgb = np.asarray(rgb, dtype=np.uint16)
    return ((rgb[..., 0] >> 3) << 11) | ((rgb[..., 1] >> 2) << 5) | (rgb[..., 2] >> 3)


def _pixel_dirs(cam: Camera) -> np.ndarray:
    """Camera-space direction of each pixel centre with z = -1, shape (h, w, 3)."""
    proj = cam.projection()
    xs = (2 * (np.arange(cam.width) + 0.5) / cam.width - 1) / proj[0, 0]
    ys = (1 - 2 * (np.arange(cam.height) + 0.5) / cam.height) / proj[1, 1]
    x, y = np.meshgrid(xs, ys)
    return np.stack([x, y, -np.ones_like(x)], -1)


def ndc_z_to_distance(ndc_z: np.ndarray, cam: Camera) -> np.ndarray:
    """Projection z (h, w) -> eye distance (h, w); inf stays inf."""
    proj = cam.projection()
    a, b = proj[2, 2], proj[2, 3]
    finite = np.isfinite(ndc_z)
    z = np.where(finite, ndc_z, 0.0)
    depth = b / (z + a)  # -z_eye: ndc = (a*z_eye + b) / -z_eye
    length = np.linalg.norm(_pixel_dirs(cam), axis=-1)
    return np.where(finite, depth * length, np.inf)


def distance_to_ndc_z(dist: np.ndarray, cam: Camera) -> np.ndarray:
    """Eye distance (h, w) -> projection z (h, w); inf stays inf."""
    proj = cam.projection()
    a, b = proj[2, 2], proj[2, 3]
    finite = np.isfinite(dist)
    depth = np.where(finite, dist, 1.0) / np.linalg.norm(_pixel_dirs(cam), axis=-1)
    return np.where(finite, b / depth - a, np.inf)


def merge(svo_rgb565: np.ndarray, svo_dist: np.ndarray, frame_rgb565: np.ndarray,
          frame_dist: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per pixel, the nearer of the two (colour, distance) pairs; ties keep the frame."""
    if not (svo_rgb565.shape == svo_dist.shape == frame_rgb565.shape == frame_dist.shape):
        raise ValueError("colour and depth buffers must all have the same shape")
    if np.isnan(svo_dist).any() or np.isnan(frame_dist).any():
        raise ValueError("depth buffers must not hold NaN")
    nearer = svo_dist < frame_dist
    return (np.where(nearer, svo_rgb565, frame_rgb565).astype(np.uint16),
            np.where(nearer, svo_dist, frame_dist).astype(np.float32))


def program_hybrid(model, program: str, model_matrix: np.ndarray, width: int, height: int,
                   stack_depth: int = 8, frames: int = 1, kernel: str = "auto",
                   on_rays: Callable[[int], None] | None = None
                   ) -> list[tuple[np.ndarray, np.ndarray]]:
    """Run a REND3R program in the emulator and merge the SVO into each of its frames.

    The SVO is traced with the emulator's own primary rays for the frame (same camera),
    taken into octree space by the inverse of ``model_matrix``; a hit's distance is
    ``t * |d|`` in world space, the emulator's depth convention. ``on_rays(count)`` is
    called as the SVO's rays are traced. Returns (rgb565, distance) per frame.
    """
    from ..emu import EmuOptions, run_program
    from ..emu.camera import camera_rays
    from ..emu.loader import load_program
    from ..emu.processor import execute
    from .render import shade
    from .traverse import trace

    loaded = load_program(program)
    options = EmuOptions(mode=loaded.mode_hint or "raytrace", width=width, height=height)
    rays: list[tuple[np.ndarray, np.ndarray]] = []

    def on_nf(scene, number: int) -> None:
        r = camera_rays(scene, options, options.arith)
        o = np.array([float(c) for c in r.origin])
        d = np.stack([np.asarray(c, dtype=np.float64) for c in r.direction], 1)
        rays.append((o, d))

    execute(loaded.words, options, frames, on_nf)
    result = run_program(loaded.words, options, frames)
    inv = np.linalg.inv(model_matrix)
    out = []
    for frame, (o, d) in zip(result.frames, rays):
        if not (np.all(np.isfinite(o)) and np.all(np.isfinite(d)) and np.all(np.abs(d).sum(1) > 0)):
            raise Rend3rError(f"{program}: frame {frame.number}: the camera produces non-finite or zero rays")
        o_oct = inv[:3, :3] @ o + inv[:3, 3]
        d_oct = d @ inv[:3, :3].T
        res = trace(model.tree, np.broadcast_to(o_oct, d.shape), d_oct, stack_depth, kernel=kernel,
                    on_rays=on_rays)
        dist = np.where(res.hit, res.t * np.linalg.norm(d, axis=1), np.inf)
        rgb = shade(res, d_oct, dist, "shaded", height, width)
        out.append(merge(rgb888_to_565(rgb), dist.reshape(height, width).astype(np.float32),
                         frame.rgb565, frame.depth))
    return out
