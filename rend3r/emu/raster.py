"""The triangle rasterizer (``--mode raster``), vectorised over triangles and pixels.

Pipeline, per frame (see ``docs/raster.md``):

1. World -> camera space in the working precision, in the raytracer's order: translate by
   the negated camera location, rotate by the inverse camera quaternion.
2. Clip against the near plane and a guard band (:mod:`.raster_clip`).
3. Project each vertex in the device's float16 order: ``s = near*coord/(-z)``,
   ``ndc = s/canvas + 0.5``, ``px = ndc_x*W``, ``py = (1 - ndc_y)*H``; snap to a
   fixed-point grid (the device's ``round``; the spec keeps 8 sub-pixel bits).
4. Exact coverage with the top-left fill rule (:mod:`.raster_cover`).
5. Depth = distance from the eye along the pixel's ray to the triangle's plane, stored in
   the working format; z-buffer (nearest wins, ties to the earlier triangle) or painter
   (centroid distance descending, the paper's order; later draws win).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from functools import lru_cache
from time import perf_counter
from typing import Callable

import numpy as np

from ..isa import Table
from .arith import Arith
from .camera import VIEW_HEIGHT, VIEW_WIDTH, camera_quaternion, camera_value
from .frame import Frame
from .lighting import Recorder
from .lights import Light, lights_from_scene
from .options import EmuOptions
from .raster_clip import ClipPlanes, clip_triangles
from .raster_cover import Spans, fragments, spans
from .raster_shade import flat_colours
from .scene import ObjectTable, Scene, prop_index
from .stats import FrameStats
from .vec import Quat, rotate_inverse

DEPTH_MODES = ("zbuffer", "painter", "index")
#: Projected coordinates stay within this many screen sizes of the screen centre.
_GUARD_SCREENS = 8.0
#: Fragments handled per batch: bounds memory on scenes with many large triangles.
_BATCH_FRAGMENTS = 1 << 22


@dataclass(frozen=True)
class RasterView:
    """The camera as the rasterizer sees it, all values already in working precision.

    ``canvas`` is the viewport size (width, height) in world units at distance ``near``
    in front of the eye; ``far`` bounds the camera-space depth ``-z`` (inf: no bound), as
    the raytracer's ``tmax = far/near`` does.
    """

    location: np.ndarray  # (3,)
    rotation: Quat | None  # unit quaternion r, i, j, k; None: no rotation
    near: float
    far: float
    canvas: tuple[float, float]


@dataclass(frozen=True)
class RasterRules:
    """How coverage and placement work: the spec's rules or the original device's."""

    subpixel_bits: int = 8
    centre_samples: bool = True
    fill_rule: str = "top-left"
    column_offset: int = 0  # device defect: pixels land this many columns to the right


SPEC_RULES = RasterRules()
#: The original device (quirk ``raster-pixel-snap``): whole-pixel vertices, integer
#: sample positions, edges inside, zero-area triangles everywhere.
DEVICE_RULES = RasterRules(subpixel_bits=0, centre_samples=False, fill_rule="inclusive")


@dataclass
class RasterStats:
    """What one rasterized frame did."""

    triangles: int = 0
    clipped: int = 0
    rejected: int = 0
    nonfinite: int = 0  # (sub)triangles dropped because a projected vertex was not finite
    fragments: int = 0


@dataclass
class RasterResult:
    """A rasterized frame: RGB565, distance along each pixel's ray, triangle index."""

    rgb565: np.ndarray
    depth: np.ndarray
    provenance: np.ndarray
    stats: RasterStats = field(default_factory=RasterStats)


def to_camera(ar: Arith, p: np.ndarray, view: RasterView) -> np.ndarray:
    """World points (..., 3) -> camera space: ``conj(q) * (0, p - loc) * q``, as the shapes do."""
    rel = tuple(ar.sub(p[..., c], view.location[c]) for c in range(3))
    cam = rel if view.rotation is None else rotate_inverse(ar, view.rotation, rel)
    return np.stack(cam, axis=-1)


def project(
    ar: Arith, v: np.ndarray, view: RasterView, width: int, height: int, record: Recorder | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Camera-space vertices (..., 3) -> screen coordinates (px, py), device order.

    ``record`` receives ``s.x s.y ndc.x ndc.y px.x px.y`` (pixel traces).
    """
    near = ar.const(view.near)
    w = ar.neg(v[..., 2])
    sx = ar.div(ar.mul(near, v[..., 0]), w)
    sy = ar.div(ar.mul(near, v[..., 1]), w)
    half, one = ar.const(0.5), ar.const(1.0)
    ndc_x = ar.add(ar.div(sx, ar.const(view.canvas[0])), half)
    ndc_y = ar.add(ar.div(sy, ar.const(view.canvas[1])), half)
    px, py = ar.mul(ndc_x, ar.const(width)), ar.mul(ar.sub(one, ndc_y), ar.const(height))
    if record is not None:
        for name, value in (("s.x", sx), ("s.y", sy), ("ndc.x", ndc_x), ("ndc.y", ndc_y), ("px.x", px), ("px.y", py)):
            record(name, value)
    return px, py


@dataclass(frozen=True)
class ScreenTriangles:
    """Clipped triangles: camera-space vertices, fixed-point screen vertices, source index."""

    camera: np.ndarray  # (M, 3, 3) working precision
    x: np.ndarray  # (M, 3) int64, 1/2**subpixel_bits pixel units
    y: np.ndarray
    parent: np.ndarray  # (M,) index of the source triangle
    clipped: int
    rejected: int
    nonfinite: int


def screen_triangles(
    ar: Arith, cam: np.ndarray, view: RasterView, size: tuple[int, int], rules: RasterRules = SPEC_RULES
) -> ScreenTriangles:
    """Clip camera-space triangles (N, 3, 3), project them and snap to the sub-pixel grid."""
    width, height = size
    clipped = clip_triangles(ar, cam, clip_planes_for(ar, view, width, height))
    one = float(1 << rules.subpixel_bits)
    if clipped.vertices.shape[0]:
        px, py = project(ar, clipped.vertices, view, width, height)
    else:
        px = py = np.zeros((0, 3), dtype=ar.dtype)
    with np.errstate(invalid="ignore", over="ignore"):
        fx, fy = px.astype(np.float64) * one, py.astype(np.float64) * one
    finite = np.isfinite(fx).all(axis=1) & np.isfinite(fy).all(axis=1)
    return ScreenTriangles(
        camera=clipped.vertices[finite],
        x=np.rint(fx[finite]).astype(np.int64),
        y=np.rint(fy[finite]).astype(np.int64),
        parent=clipped.parent[finite],
        clipped=clipped.clipped,
        rejected=clipped.rejected,
        nonfinite=int((~finite).sum()),
    )


def centroid_sq_distance(ar: Arith, cam_tris: np.ndarray) -> np.ndarray:
    """Squared eye distance of each camera-space triangle's centroid (painter's key)."""
    c = ar.div(ar.add(ar.add(cam_tris[:, 0], cam_tris[:, 1]), cam_tris[:, 2]), ar.const(3.0))
    sq = ar.mul(c, c)
    return ar.add(ar.add(sq[:, 0], sq[:, 1]), sq[:, 2])


def rasterize(
    tris: np.ndarray,
    colours: np.ndarray,
    view: RasterView,
    ar: Arith,
    size: tuple[int, int],
    depth_mode: str = "zbuffer",
    background: int = 0,
    rules: RasterRules = SPEC_RULES,
) -> RasterResult:
    """Rasterize world-space triangles ``tris`` (N, 3, 3) with flat RGB565 ``colours`` (N,).

    ``size`` is (width, height). Provenance holds the index into ``tris`` (-1: none).
    """
    if depth_mode not in DEPTH_MODES:
        raise ValueError(f"unknown depth mode {depth_mode!r}; expected one of {', '.join(DEPTH_MODES)}")
    width, height = size
    stats = RasterStats(triangles=int(tris.shape[0]))
    rgb = np.full((height, width), background, dtype=np.uint16)
    depth = np.full((height, width), np.inf, dtype=ar.dtype)
    prov = np.full((height, width), -1, dtype=np.int32)
    if tris.shape[0] == 0:
        return RasterResult(rgb, depth.astype(np.float32), prov, stats)

    cam = to_camera(ar, np.asarray(tris, dtype=ar.dtype), view)
    scr = screen_triangles(ar, cam, view, size, rules)
    stats.clipped, stats.rejected, stats.nonfinite = scr.clipped, scr.rejected, scr.nonfinite
    sub, parent, fx, fy = scr.camera, scr.parent, scr.x, scr.y

    # Draw order: table order for the z-buffer and index order, centroid distance
    # descending for painter; painter and index order resolve alike (later draws win).
    if depth_mode == "painter":
        key = centroid_sq_distance(ar, cam)
        order = np.argsort(-key.astype(np.float64), kind="stable")
        rank_of = np.empty_like(order)
        rank_of[order] = np.arange(order.size)
    else:
        rank_of = np.arange(tris.shape[0])
    rank = rank_of[parent]

    planes = _depth_planes(cam, parent, sub)
    ray = _pixel_rays(view, width, height)
    cov = spans(fx, fy, width, height, rules.subpixel_bits, rules.centre_samples, rules.fill_rule)
    best_rank = np.full(height * width, -1, dtype=np.int64)
    best_depth = depth.reshape(-1)
    for part in _batches(cov):
        span, col, row = fragments(part)
        t = part.tri[span]
        w, dist = _fragment_depth(planes, part, span, col, row * width + col, ray)
        d = ar.round(dist)
        if np.isfinite(view.far):
            inside = w <= view.far
            d, t, col, row = d[inside], t[inside], col[inside], row[inside]
        col = col + rules.column_offset
        on = col < width
        d, t, col, row = d[on], t[on], col[on], row[on]
        stats.fragments += int(t.size)
        _resolve(depth_mode, row * width + col, d, rank[t], best_depth, best_rank)

    hit = best_rank >= 0
    tri_of_rank = np.empty(tris.shape[0], dtype=np.int64)
    tri_of_rank[rank_of] = np.arange(tris.shape[0])
    winner = tri_of_rank[best_rank[hit]]
    rgb.reshape(-1)[hit] = np.asarray(colours, dtype=np.uint16)[winner]
    prov.reshape(-1)[hit] = winner
    return RasterResult(rgb, best_depth.reshape(height, width).astype(np.float32), prov, stats)


def render_triangles(
    tris: np.ndarray,
    colours: np.ndarray,
    lights: list[Light],
    view: RasterView,
    ar: Arith,
    size: tuple[int, int],
    depth_mode: str = "zbuffer",
    background: int = 0,
    rules: RasterRules = SPEC_RULES,
    shading: bool = True,
    intensity_fixed: bool = False,
) -> RasterResult:
    """Flat-shade triangles (N, 3, 3) with ``lights`` and rasterize them.

    Triangles whose shading meets NaN or infinity are not drawn (counted as non-finite).
    """
    tris = np.asarray(tris, dtype=ar.dtype)
    colours = np.asarray(colours, dtype=np.uint16)
    bad = np.zeros(tris.shape[0], dtype=bool)
    if shading and tris.shape[0]:
        colours, bad = flat_colours(ar, tris, colours, lights, intensity_fixed)
    keep = np.flatnonzero(~bad)
    res = rasterize(tris[keep], colours[keep], view, ar, size, depth_mode, background, rules)
    res.provenance[res.provenance >= 0] = keep[res.provenance[res.provenance >= 0]]
    res.stats.triangles = int(tris.shape[0])
    res.stats.nonfinite += int(bad.sum())
    return res


_VERTEX_PROPS = ("x1", "y1", "z1", "x2", "y2", "z2", "x3", "y3", "z3")


def triangles_from_scene(
    scene: Scene, ar: Arith, next_triangle: bool = False, store: ObjectTable | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every triangle the program wrote, in index order: (indices, vertices (N,3,3), colours).

    ``store`` is where SE/SD wrote them: ``scene.objects`` (raster mode, the default) or
    ``scene.triangles`` (hybrid mode). ``next_triangle`` (device defect): slot A holds
    the data of triangle A+1.
    """
    p = [prop_index(Table.TRIANGLE, n) for n in _VERTEX_PROPS]
    col = prop_index(Table.TRIANGLE, "col")
    store = scene.objects if store is None else store
    index, values = store.index.copy(), store.values
    if next_triangle:
        at = np.minimum(np.searchsorted(index, index + 1), max(len(index) - 1, 0))
        written = index[at] == index + 1
        values = np.where(written[:, None], values[at], np.uint16(0))
    return index, ar.from_bits(values[:, p].reshape(-1, 3, 3)), values[:, col].copy()


def view_from_scene(scene: Scene, ar: Arith) -> RasterView:
    """The spec camera of ``docs/emulator.md`` as the rasterizer needs it.

    The viewport at the near plane is ``(10 * hfov * near, 7.5 * vfov * near)``, the same
    pixel rays the raytracer casts; zero (unset) near/fov mean the defaults, far 0 no bound.
    """
    loc = np.array([ar.from_bits(scene.camera_bits(n)) for n in ("xloc", "yloc", "zloc")], dtype=ar.dtype)
    near = camera_value(scene, "nclip", ar, 1.0)
    hfov, vfov = camera_value(scene, "hfov", ar, 1.0), camera_value(scene, "vfov", ar, 1.0)
    far = float(ar.from_bits(scene.camera_bits("fclip")))
    canvas = (ar.mul(ar.mul(ar.const(VIEW_WIDTH), hfov), near), ar.mul(ar.mul(ar.const(VIEW_HEIGHT), vfov), near))
    return RasterView(
        location=loc,
        rotation=camera_quaternion(scene, ar),
        near=float(near),
        far=np.inf if far == 0.0 else far,
        canvas=(float(canvas[0]), float(canvas[1])),
    )


def render_frame(
    scene: Scene,
    options: EmuOptions,
    number: int = 0,
    progress: Callable[[float], None] | None = None,
    store: dict[int, dict[int, int]] | None = None,
) -> tuple[Frame, FrameStats]:
    """Render the scene's triangles (the processor's ``nf`` hook in raster mode).

    ``store``: the triangle table to draw (default ``scene.objects``; see
    :func:`triangles_from_scene`).
    """
    start = perf_counter()
    ar = options.arith
    index, tris, colours = triangles_from_scene(scene, ar, options.raster_next_triangle, store)
    lights = lights_from_scene(scene, ar, options.light_model)
    view = frame_view(scene, options)
    rules = DEVICE_RULES if options.raster_rules == "device" else SPEC_RULES
    rules = replace(rules, column_offset=options.raster_column_offset)
    res = render_triangles(
        tris, colours, lights, view, ar, (options.width, options.height), options.depth, options.background,
        rules, options.raster_shading, options.intensity_fixed,
    )
    lookup = np.append(index, -1)  # provenance -1 (no triangle) reads the appended -1
    prov = lookup[res.provenance].astype(np.int32)
    st = FrameStats(
        number=number, pixels=options.pixels, shapes=len(index), lights=len(lights),
        nan_tests=res.stats.nonfinite, hits=int((prov >= 0).sum()), seconds=perf_counter() - start,
        mode="raster",
    )
    if progress is not None:
        progress(1.0)
    return Frame(number, res.rgb565, res.depth, prov), st


def frame_view(scene: Scene, options: EmuOptions) -> RasterView:
    """The camera the rasterizer uses for this frame: the scene's, or the device's fixed one."""
    return DEVICE_VIEW if options.raster_camera == "device" else view_from_scene(scene, options.arith)


#: The device rasterizer's fixed projection (quirk ``raster-fixed-camera``).
DEVICE_VIEW = RasterView(np.zeros(3, dtype=np.float32), None, 1.0, np.inf, (VIEW_WIDTH, VIEW_HEIGHT))


def clip_planes_for(ar: Arith, view: RasterView, width: int, height: int) -> ClipPlanes:
    # |px - W/2| <= G*W  <=>  |x| / (-z) <= G * canvas_w / near (likewise y).
    g = _GUARD_SCREENS
    return ClipPlanes(
        near=ar.const(view.near),
        gx=ar.const(g * view.canvas[0] / view.near),
        gy=ar.const(g * view.canvas[1] / view.near),
    )


@dataclass(frozen=True)
class _Planes:
    """Per (sub)triangle: camera-space plane ``n.p = num`` and its vertices' ``-z`` range."""

    n: np.ndarray
    num: np.ndarray
    wmin: np.ndarray
    wmax: np.ndarray


def _depth_planes(cam: np.ndarray, parent: np.ndarray, sub: np.ndarray) -> _Planes:
    v = cam.astype(np.float64)
    n = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])
    num = np.einsum("ij,ij->i", n, v[:, 0])
    w = -sub[..., 2].astype(np.float64)
    return _Planes(n[parent], num[parent], w.min(axis=1), w.max(axis=1))


@dataclass(frozen=True)
class _Rays:
    """Camera-space pixel ray directions (u, v, -1) through the sample points."""

    u: np.ndarray  # (W,)
    v: np.ndarray  # (H,)
    length: np.ndarray  # (H, W)


@lru_cache(maxsize=8)
def _pixel_rays_cached(cw: float, ch: float, near: float, width: int, height: int) -> _Rays:
    u = ((np.arange(width) + 0.5) / width - 0.5) * cw / near
    v = (0.5 - (np.arange(height) + 0.5) / height) * ch / near
    return _Rays(u, v, np.sqrt(u[None, :] ** 2 + v[:, None] ** 2 + 1.0))


def _pixel_rays(view: RasterView, width: int, height: int) -> _Rays:
    # Inverse of the projection: x/(-z) = (px/W - 0.5) * canvas_w / near.
    return _pixel_rays_cached(view.canvas[0], view.canvas[1], view.near, width, height)


def _fragment_depth(
    p: _Planes, part: Spans, span: np.ndarray, col: np.ndarray, pix: np.ndarray, ray: _Rays
) -> tuple[np.ndarray, np.ndarray]:
    """Camera depth ``-z`` and eye distance of each fragment's point on its triangle's plane.

    The ray through the sample is ``s * (u, v, -1)``; it meets the plane at
    ``s = num / (n . (u, v, -1))``, clamped to the triangle's depth range (which also
    settles edge-on planes, where the quotient is not finite). Coefficients are formed
    once per span and expanded to its pixels.
    """
    t = part.tri
    a = p.n[t, 0]
    b = p.n[t, 1] * ray.v[part.row] - p.n[t, 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        w = p.num[t][span] / (a[span] * ray.u[col] + b[span])
    lo, hi = p.wmin[t][span], p.wmax[t][span]
    w = np.clip(np.where(np.isfinite(w), w, hi), lo, hi)
    return w, w * ray.length.reshape(-1)[pix]


def _batches(cov):
    """Split spans so that each batch expands to at most ``_BATCH_FRAGMENTS`` pixels."""
    n = cov.hi - cov.lo + 1
    ends = np.cumsum(n)
    start = 0
    while start < n.size:
        base = ends[start - 1] if start else 0
        stop = max(int(np.searchsorted(ends, base + _BATCH_FRAGMENTS, side="right")), start + 1)
        yield type(cov)(cov.tri[start:stop], cov.row[start:stop], cov.lo[start:stop], cov.hi[start:stop])
        start = stop


def _resolve(mode: str, pix: np.ndarray, d: np.ndarray, rank: np.ndarray, best_depth: np.ndarray, best_rank: np.ndarray) -> None:
    """Merge one batch of fragments into the frame's depth and rank buffers."""
    if mode != "zbuffer":
        # Later in draw order wins: the highest rank.
        cand = np.full(best_rank.shape, -1, dtype=np.int64)
        np.maximum.at(cand, pix, rank)
        won = cand > best_rank
        sel = (cand[pix] == rank) & won[pix]
        best_rank[won] = cand[won]
        best_depth[pix[sel]] = d[sel]
        return
    # z-buffer: nearest wins; equal depths go to the earlier triangle (lower rank).
    cand_d = np.full(best_depth.shape, np.inf, dtype=best_depth.dtype)
    np.minimum.at(cand_d, pix, d)
    at_min = d == cand_d[pix]
    cand_r = np.full(best_rank.shape, np.iinfo(np.int64).max, dtype=np.int64)
    np.minimum.at(cand_r, pix[at_min], rank[at_min])
    won = (cand_r != np.iinfo(np.int64).max) & (
        (cand_d < best_depth) | ((cand_d == best_depth) & ((best_rank < 0) | (cand_r < best_rank)))
    )
    best_depth[won] = cand_d[won]
    best_rank[won] = cand_r[won]
