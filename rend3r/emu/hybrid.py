"""Hybrid frames: analytic shapes (raytraced) and triangles (rasterized) merged by depth.

Both renderers see the same camera; a pixel shows whichever surface is nearer along its
ray (the depth of both is the eye distance along the pixel's ray), shapes on ties.
Triangles cast no shadows and receive none (the rasterizer's flat shading). Provenance
keeps shape indices as they are and reports triangle ``i`` as ``TRIANGLE_BASE + i``.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Callable

import numpy as np

from ..isa.tables import SHAPE_INDEX_LIMIT
from .frame import Frame
from .options import EmuOptions
from .raster import render_frame as raster_frame
from .raytracer import render_frame as raytrace_frame
from .scene import Scene
from .stats import FrameStats

#: Triangle provenance offset: above every shape index (SE indices have 19 bits).
TRIANGLE_BASE = SHAPE_INDEX_LIMIT


def render_frame(
    scene: Scene, options: EmuOptions, number: int = 0, progress: Callable[[float], None] | None = None
) -> tuple[Frame, FrameStats]:
    """Raytrace ``scene.objects``, rasterize ``scene.triangles``, keep the nearer per pixel."""
    shapes, st = raytrace_frame(scene, options, number, progress)
    tris, tst = raster_frame(scene, options, number, None, scene.triangles)
    nearer = tris.depth < shapes.depth
    merged = Frame(
        number,
        np.where(nearer, tris.rgb565, shapes.rgb565).astype(np.uint16),
        np.where(nearer, tris.depth, shapes.depth).astype(np.float32),
        np.where(nearer, tris.provenance + TRIANGLE_BASE, shapes.provenance).astype(np.int32),
    )
    stats = replace(st, hits=int((merged.provenance >= 0).sum()), seconds=st.seconds + tst.seconds,
                    nan_tests=st.nan_tests + tst.nan_tests)
    return merged, stats
