"""Procedural, watertight triangle meshes (no downloads): sphere, torus and a folded blob."""

from __future__ import annotations

import numpy as np

from ..errors import Rend3rError


def _grid_faces(nu: int, nv: int, wrap_u: bool) -> np.ndarray:
    """Triangles of an nu x nv vertex grid, v always wrapping, u wrapping if ``wrap_u``."""
    rows = nu if wrap_u else nu - 1
    i, j = np.meshgrid(np.arange(rows), np.arange(nv), indexing="ij")
    a = i * nv + j
    b = ((i + 1) % nu) * nv + j
    c = ((i + 1) % nu) * nv + (j + 1) % nv
    d = i * nv + (j + 1) % nv
    return np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3),
                           np.stack([a, c, d], -1).reshape(-1, 3)])


def _closed_sphere_like(radius_fn, n: int) -> tuple[np.ndarray, np.ndarray]:
    """A latitude/longitude sphere with radius ``radius_fn(theta, phi)``, poles capped."""
    nu, nv = n, 2 * n
    theta = np.linspace(0, np.pi, nu + 1)[1:-1]
    phi = np.linspace(0, 2 * np.pi, nv, endpoint=False)
    th, ph = np.meshgrid(theta, phi, indexing="ij")
    r = radius_fn(th, ph)
    ring = np.stack([r * np.sin(th) * np.cos(ph), r * np.sin(th) * np.sin(ph), r * np.cos(th)], -1)
    verts = ring.reshape(-1, 3)
    faces = _grid_faces(nu - 1, nv, wrap_u=False)
    top = len(verts)
    bottom = top + 1
    r_top = float(radius_fn(np.array(0.0), np.array(0.0)))
    r_bot = float(radius_fn(np.array(np.pi), np.array(0.0)))
    verts = np.concatenate([verts, [[0, 0, r_top], [0, 0, -r_bot]]])
    j = np.arange(nv)
    last = (nu - 2) * nv
    caps = [np.stack([np.full(nv, top), j, (j + 1) % nv], -1),
            np.stack([np.full(nv, bottom), last + (j + 1) % nv, last + j], -1)]
    faces = np.concatenate([faces] + caps)
    return verts.astype(np.float64), faces.astype(np.int64)


def sphere(n: int = 32) -> tuple[np.ndarray, np.ndarray]:
    """A unit sphere with ``n`` latitude bands."""
    return _closed_sphere_like(lambda th, ph: np.ones_like(th, dtype=np.float64), n)


def torus(n: int = 48, major: float = 1.0, minor: float = 0.35) -> tuple[np.ndarray, np.ndarray]:
    """A torus around the z axis."""
    u = np.linspace(0, 2 * np.pi, n, endpoint=False)
    v = np.linspace(0, 2 * np.pi, n // 2, endpoint=False)
    uu, vv = np.meshgrid(u, v, indexing="ij")
    x = (major + minor * np.cos(vv)) * np.cos(uu)
    y = (major + minor * np.cos(vv)) * np.sin(uu)
    z = minor * np.sin(vv)
    verts = np.stack([x, y, z], -1).reshape(-1, 3)
    return verts, _grid_faces(n, n // 2, wrap_u=True)


def folded(n: int = 96) -> tuple[np.ndarray, np.ndarray]:
    """A blob with deep folds: many silhouette edges, like the thesis's dragon."""
    def radius(th, ph):
        return (1.0 + 0.22 * np.sin(7 * ph) * np.sin(th) ** 2
                + 0.12 * np.sin(11 * th + 3 * ph) + 0.06 * np.cos(17 * ph - 5 * th))
    return _closed_sphere_like(radius, n)


MODELS = {"sphere": sphere, "torus": torus, "folded": folded}


def make_model(name: str, detail: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """One of :data:`MODELS` by name, optionally with a tessellation ``detail``."""
    if name not in MODELS:
        raise Rend3rError(f"unknown model {name!r} (choose from {', '.join(sorted(MODELS))})")
    return MODELS[name]() if detail is None else MODELS[name](detail)
