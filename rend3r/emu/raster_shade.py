"""Flat shading of triangles: one colour per triangle from its normal and the lights.

The paper (section IV-A2): the surface normal is the cross product of two edges, so the
winding decides which side faces out; its dot product with the direction to each light
says how much the face looks at the light; that masks the triangle's colour. The lighting
formula and colour arithmetic are the raytracer's (:func:`.lighting.diffuse`); the
normal is, in the working precision, ``n = (v2 - v1) x (v3 - v1)`` with each component
``a*b - c*d`` (two products, one subtraction), and point lights are aimed at the
centroid ``((v1 + v2) + v3) / 3``. Triangles cast no shadows in raster mode.
"""

from __future__ import annotations

import numpy as np

from .arith import Arith
from .lighting import Recorder, diffuse
from .lights import Light
from .vec import Vec


def face_normals(ar: Arith, tris: np.ndarray) -> Vec:
    """Unnormalised normals ``(v2 - v1) x (v3 - v1)`` of triangles (N, 3, 3)."""
    e1 = [ar.sub(tris[:, 1, c], tris[:, 0, c]) for c in range(3)]
    e2 = [ar.sub(tris[:, 2, c], tris[:, 0, c]) for c in range(3)]
    return (
        ar.sub(ar.mul(e1[1], e2[2]), ar.mul(e1[2], e2[1])),
        ar.sub(ar.mul(e1[2], e2[0]), ar.mul(e1[0], e2[2])),
        ar.sub(ar.mul(e1[0], e2[1]), ar.mul(e1[1], e2[0])),
    )


def centroids(ar: Arith, tris: np.ndarray) -> Vec:
    third = ar.const(3.0)
    return tuple(ar.div(ar.add(ar.add(tris[:, 0, c], tris[:, 1, c]), tris[:, 2, c]), third) for c in range(3))


def flat_colours(
    ar: Arith,
    tris: np.ndarray,
    base: np.ndarray,
    lights: list[Light],
    intensity_fixed: bool = False,
    record: Recorder | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """RGB565 per triangle, and a mask of triangles whose shading met NaN or infinity.

    ``record`` receives the normal (``n.x n.y n.z``) and the lighting stages.
    """
    normal = face_normals(ar, tris)
    if record is not None:
        for axis, value in zip("xyz", normal):
            record(f"n.{axis}", value)
    return diffuse(
        ar, np.asarray(base, dtype=np.uint16), normal, centroids(ar, tris), lights,
        intensity_fixed=intensity_fixed, record=record,
    )
