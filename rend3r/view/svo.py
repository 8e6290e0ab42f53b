"""An ``.svo`` model in the view: its render, per-ray cost image, and one ray's traversal,
from :func:`rend3r.svo.render.render` and :func:`rend3r.svo.traverse.trace`."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .params import Args, RequestError, integer, number, one, size

#: Memory requests of one ray listed in full (a longer traversal is cut, and says so).
MAX_NODES = 4096


@dataclass(frozen=True)
class SvoView:
    """How to look at the model: the orbit camera and the traversal's settings."""

    width: int
    height: int
    azimuth: float
    elevation: float
    distance: float
    stack: int
    fixed: bool
    mode: str


def svo_view(args: Args) -> SvoView:
    """The view a request names (``rend3r svo render``'s options and ranges)."""
    w, h = size(args, "640x480")
    mode = one(args, "mode", "shaded")
    if mode not in ("shaded", "depth"):
        raise RequestError(f"mode: shaded or depth, not {mode!r}")
    fixed = one(args, "float", "0")
    if fixed not in ("0", "1"):
        raise RequestError("float: 0 (16.16 fixed point) or 1 (float64 reference)")
    return SvoView(w, h, number(args, "azimuth", -1e6, 1e6, 35.0), number(args, "elevation", -89.9, 89.9, 25.0),
                   number(args, "distance", 0.1, 1e6, 1.6), integer(args, "stack", 0, 64, 8), fixed == "0", mode)


def _camera(model, view: SvoView):
    from ..svo.camera import orbit_camera

    return orbit_camera(model.bounds, view.azimuth, view.elevation, view.distance, view.width, view.height)


def _kernel(fixed: bool) -> str:
    from ..svo.traverse import resolve_kernel

    return resolve_kernel("auto", fixed)[0]


def render(model, view: SvoView):
    """The model's :class:`rend3r.svo.render.Render` for ``view``."""
    from ..svo.render import render as render_svo

    with np.errstate(all="ignore"):
        return render_svo(model, _camera(model, view), view.stack, view.fixed, view.mode, kernel=_kernel(view.fixed))


def cost_rgb(r) -> np.ndarray:
    """The cost image (grey by memory requests per ray) as RGB."""
    from ..svo.render import cost_image

    return np.repeat(cost_image(r.cost)[..., None], 3, axis=2)


def ray(model, view: SvoView, r, x: int, y: int) -> dict:
    """The traversal of the ray through pixel (x, y): every memory request (node word or
    far slot, with its level), pushes, pops and restarts, and where it hit."""
    from ..svo.traverse import trace

    if not (0 <= x < view.width and 0 <= y < view.height):
        raise RequestError(f"pixel {x},{y} is outside the {view.width}x{view.height} image")
    i = y * view.width + x
    with np.errstate(all="ignore"):
        t = trace(model.tree, r.rays.origin[i : i + 1], r.rays.direction[i : i + 1], view.stack, view.fixed,
                  record=True, kernel=_kernel(view.fixed))
    hit = bool(r.result.hit[i])
    addr, level = t.trace_addr.tolist(), t.trace_level.tolist()
    return {"pixel": [x, y], "hit": hit, "t": float(r.result.t[i]) if hit else None,
            "distance": float(r.distance[y, x]) if hit else None,
            "voxel": r.result.voxel[i].tolist() if hit else None, "axis": int(r.result.axis[i]),
            "requests": int(t.requests[0]), "steps": int(t.steps[0]), "pushes": int(t.descents[0]),
            "pops": int(t.pops[0]), "restarts": int(t.restarts[0]), "max_level": int(t.max_level[0]),
            "max_stack": int(t.max_stack[0]), "cost": int(r.cost[y, x]),
            "nodes": [{"address": a, "level": lv} for a, lv in zip(addr[:MAX_NODES], level[:MAX_NODES])],
            "nodes_cut": max(len(addr) - MAX_NODES, 0)}
