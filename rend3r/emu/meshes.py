"""Closed triangle meshes for rasterizer tests and benchmarks (outward, counter-clockwise)."""

from __future__ import annotations

import numpy as np


def cube(centre: tuple[float, float, float] = (0.0, 0.0, -4.0), half: float = 1.0) -> np.ndarray:
    """An axis-aligned cube as 12 triangles (12, 3, 3), faces wound counter-clockwise seen from outside."""
    c = np.asarray(centre, dtype=np.float64)
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=np.float64)
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    tris = []
    for a, b, cc, d in quads:
        tris += [(a, b, cc), (a, cc, d)]
    return c + half * corners[np.array(tris)]


def uv_sphere(
    stacks: int, slices: int, centre: tuple[float, float, float] = (0.0, 0.0, -4.0), radius: float = 1.0
) -> np.ndarray:
    """A closed UV sphere of ``2 * slices * (stacks - 1)`` triangles, counter-clockwise outside."""
    theta = np.linspace(0.0, np.pi, stacks + 1)
    phi = np.linspace(0.0, 2.0 * np.pi, slices + 1)[:-1]
    ring = np.stack(
        [np.sin(theta)[:, None] * np.cos(phi), np.sin(theta)[:, None] * np.sin(phi), np.cos(theta)[:, None] + 0 * phi],
        axis=-1,
    )
    # The poles are single points, so every triangle touching them shares exact vertices.
    ring[0, :] = (0.0, 0.0, 1.0)
    ring[-1, :] = (0.0, 0.0, -1.0)
    pts = np.asarray(centre) + radius * ring
    tris = []
    for i in range(stacks):
        for j in range(slices):
            j2 = (j + 1) % slices
            a, b, c, d = pts[i, j], pts[i, j2], pts[i + 1, j], pts[i + 1, j2]
            if i > 0:
                tris.append((a, c, b))
            if i < stacks - 1:
                tris.append((b, c, d))
    return np.asarray(tris, dtype=np.float64)


def triangle_soup(count: int, seed: int = 0, depth: tuple[float, float] = (-12.0, -3.0), size: float = 0.4) -> np.ndarray:
    """``count`` random small triangles in front of the default camera (benchmark load)."""
    rng = np.random.default_rng(seed)
    z = rng.uniform(depth[0], depth[1], count)
    centre = np.stack([rng.uniform(-0.45, 0.45, count) * 10 * -z, rng.uniform(-0.45, 0.45, count) * 7.5 * -z, z], axis=1)
    offsets = rng.uniform(-size, size, (count, 3, 3))
    return centre[:, None, :] + offsets
