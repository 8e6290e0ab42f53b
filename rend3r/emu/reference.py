"""The reference raytracer: every pixel against every shape, no culling, in numpy.

Small and plain on purpose: it is the oracle the compiled engine (:mod:`.raytracer`) is
tested against, pixel, depth and provenance alike (``tests/emu/test_engine_vs_reference.py``).
It shares only the definitions of the arithmetic (:mod:`.arith`, :mod:`.vec`), the
raycaster written over numpy arrays (:mod:`.shapes`) and the lighting (:mod:`.lighting`);
its cost is pixels x shapes, so it is for small frames.
"""

from __future__ import annotations

import numpy as np

from .arith import Arith
from .camera import camera_rays
from .frame import Frame
from .lighting import diffuse
from .lights import POINT, Light, lights_from_scene
from .options import EmuOptions
from .scene import Scene
from .shapes import Shapes, origin_term, shapes_from_scene, solve, squared_distance, surface, to_object
from .vec import Vec, dot


def render_reference(scene: Scene, options: EmuOptions) -> Frame:
    """The raytraced frame of ``scene`` (``options.mode`` is taken to be raytrace)."""
    ar = options.arith
    rays = camera_rays(scene, options, ar)
    shapes = shapes_from_scene(scene, ar)
    lights = lights_from_scene(scene, ar, options.light_model)
    n_pix, n = options.pixels, len(shapes)
    rgb = np.full(n_pix, options.background, np.uint16)
    depth = np.full(n_pix, np.inf, np.float32)
    prov = np.full(n_pix, -1, np.int32)
    if n:
        pix, slot = np.repeat(np.arange(n_pix), n), np.tile(np.arange(n), n_pix)  # every (pixel, shape) pair
        d = tuple(c[pix] for c in rays.direction)
        s = shapes.take(slot)
        S, D = to_object(ar, s, rays.origin, d)
        sol = solve(ar, s, S, D, origin_term(ar, s, S), rays.tmin, rays.tmax)
        sqd = squared_distance(ar, dot(ar, d, d), sol.t)
        hit = sol.hit & np.isfinite(sqd)
        # nearest: smallest sq_dist, then the lower shape index (shapes are in index order)
        order = np.lexsort((slot, sqd, ~hit, pix))
        first = order[np.r_[True, pix[order][1:] != pix[order][:-1]]]
        win = first[hit[first]]
        w = shapes.take(slot[win])
        point, normal = surface(ar, w, tuple(c[win] for c in S), tuple(c[win] for c in D), sol.t[win], rays.origin,
                                tuple(c[win] for c in d))
        if lights:
            occluded = lambda light, lit, l_vec: _blocked(ar, shapes, light, slot[win][lit],  # noqa: E731
                                                          tuple(c[lit] for c in point), l_vec)
            colour, bad = diffuse(ar, w.color, normal, point, lights, occluded, options.intensity_fixed)
        else:
            colour, bad = w.color, ~(np.isfinite(point[0]) & np.isfinite(point[1]) & np.isfinite(point[2]))
        shown, px = win[~bad], pix[win][~bad]
        rgb[px] = colour[~bad]
        prov[px] = shapes.index[slot[shown]]
        depth[px] = np.sqrt(sqd[shown].astype(np.float64))
    h, w_ = options.height, options.width
    return Frame(0, rgb.reshape(h, w_), depth.reshape(h, w_), prov.reshape(h, w_))


def _blocked(ar: Arith, shapes: Shapes, light: Light, own: np.ndarray, origin: Vec, l_vec: Vec) -> np.ndarray:
    """Whether any other shape lies on each shadow ray origin + t*l, t > 0 (t <= 1 for a
    point light)."""
    k, n = len(own), len(shapes)
    ray, slot = np.repeat(np.arange(k), n), np.tile(np.arange(n), k)
    s = shapes.take(slot)
    S, D = to_object(ar, s, tuple(np.broadcast_to(c, (k,))[ray] for c in origin),
                     tuple(np.broadcast_to(c, (k,))[ray] for c in l_vec))
    tmax = ar.const(1.0 if light.kind == POINT else np.inf)
    sol = solve(ar, s, S, D, origin_term(ar, s, S), ar.const(0.0), tmax)
    blocked = np.zeros(k, bool)
    blocked[ray[sol.hit & (slot != own[ray])]] = True
    return blocked
