"""Clipping of camera-space triangles against the near plane and a guard band.

Sutherland-Hodgman, vectorised over polygons: each plane is a linear function of a
camera-space point, ``d(p) >= 0`` inside. A triangle crossing planes becomes a convex
polygon of up to 3 + (number of planes) vertices, returned as a fan of triangles.

Every new vertex is computed in the working precision from the edge's *inside* vertex
towards its *outside* vertex (``t = d_in / (d_in - d_out)``, ``v = v_in + t * (v_out -
v_in)``). The result therefore depends only on the (unordered) edge and the plane, so two
triangles sharing an edge get bit-identical clipped vertices on it: clipping opens no
cracks in a mesh.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .arith import Arith


@dataclass(frozen=True)
class ClipPlanes:
    """The view volume's clip planes in camera space (the camera looks towards -z).

    ``near``: inside where ``-z >= near``. ``gx``/``gy``: guard band, inside where
    ``|x| <= gx * (-z)`` and ``|y| <= gy * (-z)``; it keeps projected coordinates far
    from float16 overflow while lying well outside the screen.
    """

    near: np.ndarray
    gx: np.ndarray
    gy: np.ndarray

    def distances(self, ar: Arith, p: np.ndarray) -> np.ndarray:
        """Signed plane functions of points ``p`` (..., 3) -> (..., 5), working precision."""
        x, y, z = p[..., 0], p[..., 1], p[..., 2]
        w = ar.neg(z)
        gxw, gyw = ar.mul(self.gx, w), ar.mul(self.gy, w)
        return np.stack(
            [ar.sub(w, self.near), ar.sub(gxw, x), ar.add(gxw, x), ar.sub(gyw, y), ar.add(gyw, y)],
            axis=-1,
        )


@dataclass(frozen=True)
class Clipped:
    """Triangles after clipping: vertices (M, 3, 3) and each one's source triangle."""

    vertices: np.ndarray
    parent: np.ndarray
    clipped: int  # source triangles that crossed a plane
    rejected: int  # source triangles wholly outside a plane


def clip_triangles(ar: Arith, tris: np.ndarray, planes: ClipPlanes) -> Clipped:
    """Clip camera-space triangles ``tris`` (N, 3, 3) to the view volume."""
    d = planes.distances(ar, tris)  # (N, 3, 5)
    inside = d >= 0  # NaN counts as outside
    all_in = inside.all(axis=(1, 2))
    out_one = (~inside).all(axis=1).any(axis=1)  # every vertex outside one plane
    crossing = ~all_in & ~out_one
    idx = np.flatnonzero(crossing)
    poly_v = tris[idx]
    count = np.full(idx.size, 3, dtype=np.int64)
    for k in range(d.shape[-1]):
        poly_v, count = _clip_plane(ar, poly_v, count, planes, k)
    fan_v, fan_parent = _fan(poly_v, count, idx)
    keep = np.flatnonzero(all_in)
    return Clipped(
        vertices=np.concatenate([tris[keep], fan_v]),
        parent=np.concatenate([keep, fan_parent]).astype(np.int64),
        clipped=int(idx.size),
        rejected=int(out_one.sum()),
    )


def _clip_plane(
    ar: Arith, v: np.ndarray, count: np.ndarray, planes: ClipPlanes, k: int
) -> tuple[np.ndarray, np.ndarray]:
    """One Sutherland-Hodgman pass against plane ``k`` over polygons (M, S, 3)."""
    m, slots = v.shape[0], v.shape[1]
    if m == 0:
        return v, count
    d = planes.distances(ar, v)[..., k]  # (M, S)
    rows = np.arange(m)
    out = np.zeros((m, slots + 1, 3), dtype=v.dtype)
    n_out = np.zeros(m, dtype=np.int64)
    for i in range(slots):
        valid = i < count
        j = np.where(valid, (i + 1) % np.maximum(count, 1), 0)
        a, b = v[:, i], v[rows, j]
        da, db = d[:, i], d[rows, j]
        ina, inb = valid & (da >= 0), valid & (db >= 0)
        # The vertex itself when inside.
        out[rows[ina], n_out[ina]] = a[ina]
        n_out += ina
        # The crossing point, always computed from the inside end towards the outside end.
        cross = valid & (ina != inb)
        if cross.any():
            c = np.flatnonzero(cross)
            a_in = np.where(ina[c, None], a[c], b[c])
            a_out = np.where(ina[c, None], b[c], a[c])
            d_in = np.where(ina[c], da[c], db[c])
            d_out = np.where(ina[c], db[c], da[c])
            t = ar.div(d_in, ar.sub(d_in, d_out))[:, None]
            out[c, n_out[c]] = ar.add(a_in, ar.mul(t, ar.sub(a_out, a_in)))
            n_out[c] += 1
    alive = n_out >= 3
    return out[alive], n_out[alive]


def _fan(v: np.ndarray, count: np.ndarray, parent: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Triangulate convex polygons as fans around their first vertex."""
    n_tri = np.maximum(count - 2, 0)
    owner = np.repeat(np.arange(v.shape[0]), n_tri)
    k = np.arange(owner.size) - np.repeat(np.cumsum(n_tri) - n_tri, n_tri)
    tris = np.stack([v[owner, 0], v[owner, k + 1], v[owner, k + 2]], axis=1)
    return tris.reshape(-1, 3, 3), parent[owner]
