"""Rasterizer behaviour: camera, clipping, visibility, depth, shading, device-order projection."""

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from rend3r.emu.arith import make_arith
from rend3r.emu.camera import camera_rays
from rend3r.emu.lights import DIRECTIONAL, Light
from rend3r.emu.options import EmuOptions
from rend3r.emu.raster import project, rasterize, render_triangles, to_camera, view_from_scene
from rend3r.emu.scene import Scene, prop_index
from rend3r.isa import Table
from rend3r.isa.float16 import float_to_bits

from .helpers import view

W, H = 40, 30
RED, GREEN = 0xF800, 0x07E0


def _tri(*pts):
    return np.array([pts], dtype=np.float64)


def test_projection_follows_the_device_float16_order():
    ar = make_arith("fp16")
    v = np.array([[1.0, 0.5, -3.0]])
    px, py = project(ar, ar.round(v), view(ar), 512, 384)
    h = np.float16
    s_x = h(h(h(1.0) * h(1.0)) / h(3.0))
    s_y = h(h(h(1.0) * h(0.5)) / h(3.0))
    want_x = h(h(h(s_x / h(10.0)) + h(0.5)) * h(512))
    want_y = h(h(h(1.0) - h(h(s_y / h(7.5)) + h(0.5))) * h(384))
    assert float(px[0]) == float(want_x) and float(py[0]) == float(want_y)


def test_triangle_behind_the_camera_draws_nothing():
    ar = make_arith("fp16")
    r = rasterize(_tri((-1, -1, 3), (1, -1, 3), (0, 1, 3)), np.array([RED]), view(ar), ar, (W, H))
    assert (r.provenance == -1).all()
    assert r.stats.rejected == 1


def test_floor_through_the_near_plane_is_clipped_not_wrapped():
    # A floor at y = -5 from behind the camera (z = 8) to far ahead (z = -40); the near
    # plane (z = -1) cuts it below the screen's bottom edge (y = -3.75 there).
    ar = make_arith("fp16")
    a, b, c, d = (-30, -5, 8), (30, -5, 8), (30, -5, -40), (-30, -5, -40)
    tris = np.array([[a, b, c], [a, c, d]], dtype=np.float64)
    r = rasterize(tris, np.array([RED, RED]), view(ar), ar, (W, H))
    covered = r.provenance >= 0
    assert r.stats.clipped == 2
    assert not covered[: H // 2].any()  # nothing above the horizon (no wrap-around)
    assert covered[-1].all()  # the near floor fills the bottom row
    # Rows fill monotonically downwards: the horizon is the only boundary.
    rows = covered.any(axis=1)
    first = int(np.argmax(rows))
    assert rows[first:].all()


def test_zbuffer_resolves_intersecting_triangles_per_pixel_painter_per_triangle():
    ar = make_arith("fp32")
    # Two triangles crossing each other in depth along x.
    t0 = ((-2, -1, -3), (2, -1, -5), (0, 1.5, -4))
    t1 = ((-2, -1, -5), (2, -1, -3), (0, 1.5, -4.2))
    tris = np.array([t0, t1], dtype=np.float64)
    v = view(ar, canvas=(2.0, 1.5))
    z = rasterize(tris, np.array([RED, GREEN]), v, ar, (W, H), "zbuffer")
    p = rasterize(tris, np.array([RED, GREEN]), v, ar, (W, H), "painter")
    both = (z.provenance >= 0)
    left = z.provenance[:, : W // 2 - 2][both[:, : W // 2 - 2]]
    right = z.provenance[:, W // 2 + 2:][both[:, W // 2 + 2:]]
    assert (left == 0).all() and (right == 1).all()
    # Painter: t1's centroid is farther (z -4.07 vs -4.0), so t0 is drawn last and wins
    # wherever it covers.
    only0 = rasterize(tris[:1], np.array([RED]), v, ar, (W, H)).provenance >= 0
    assert (p.provenance[only0] == 0).all()
    assert (p.provenance[both & ~only0] == 1).all()


def test_zbuffer_ties_go_to_the_earlier_triangle():
    ar = make_arith("fp16")
    t = ((-3, -3, -2), (3, -3, -2), (0, 3, -2))
    r = rasterize(np.array([t, t], dtype=np.float64), np.array([RED, GREEN]), view(ar), ar, (W, H))
    assert set(np.unique(r.provenance)) == {-1, 0}


def test_depth_is_the_distance_along_the_pixel_ray():
    ar = make_arith("fp64")
    v = view(ar)
    r = rasterize(_tri((-20, -20, -3), (20, -20, -3), (0, 20, -3)), np.array([RED]), v, ar, (W, H))
    j, i = 20, 30
    u = ((i + 0.5) / W - 0.5) * 10.0
    w = (0.5 - (j + 0.5) / H) * 7.5
    assert r.depth[j, i] == pytest.approx(3.0 * np.sqrt(u * u + w * w + 1.0), rel=1e-6)


def test_far_clip_drops_fragments_beyond_it():
    ar = make_arith("fp16")
    tris = np.array([((-20, -20, -3), (20, -20, -3), (0, 20, -3)), ((-20, -20, -6), (20, -20, -6), (0, 20, -6))])
    near_only = rasterize(tris, np.array([RED, GREEN]), view(ar, far=4.0), ar, (W, H))
    assert set(np.unique(near_only.provenance)) <= {-1, 0}
    far_only = rasterize(tris[1:], np.array([GREEN]), view(ar, far=4.0), ar, (W, H))
    assert (far_only.provenance == -1).all()


@settings(max_examples=15)
@given(
    st.floats(-0.8, 0.8), st.floats(-0.8, 0.8), st.floats(-0.8, 0.8),
    st.floats(0.6, 1.6), st.floats(0.6, 1.6), st.floats(0.5, 2.0), st.booleans(),
)
def test_coverage_matches_the_raytracers_camera_rays(qi, qj, px, hfov, vfov, near, crossing):
    """Pixels whose spec-camera ray hits the triangle well inside (and well beyond the near
    plane) are covered; well outside, or well before the near plane, not."""
    ar = make_arith("fp32")
    scene = Scene()
    for name, value in (("rrot", 1.0), ("irot", qi * 0.3), ("jrot", qj * 0.3), ("xloc", px),
                        ("hfov", hfov), ("vfov", vfov), ("nclip", near)):
        scene.camera[prop_index(Table.CAMERA, name)] = float_to_bits(value)
    opts = EmuOptions(precision="fp32", width=W, height=H)
    rays = camera_rays(scene, opts, ar)
    tri = np.array([[-3.0, -2.0, -6.0], [4.0, -1.0, -7.0], [0.5, 3.0, -5.0]])
    if crossing:  # one vertex close to the eye: the near plane cuts the triangle
        tri[2] = (0.3, 0.4, -0.2)
    r = rasterize(tri[None], np.array([RED]), view_from_scene(scene, ar), ar, (W, H))
    o = np.array([float(c) for c in rays.origin])
    d = np.stack([np.broadcast_to(c, (W * H,)) for c in rays.direction], axis=1).astype(np.float64)
    # Barycentric coordinates of each ray's hit on the triangle's plane.
    e1, e2 = tri[1] - tri[0], tri[2] - tri[0]
    n = np.cross(e1, e2)
    t = ((tri[0] - o) @ n) / (d @ n)
    p = o + t[:, None] * d - tri[0]
    m = np.linalg.inv(np.stack([e1, e2, n], axis=1))
    b = p @ m.T
    bary = np.stack([1 - b[:, 0] - b[:, 1], b[:, 0], b[:, 1]], axis=1).min(axis=1)
    # the near plane cuts the triangle when its vertices' camera depths lie on both sides
    # (the camera's turn and offset can take the close vertex back beyond the near plane)
    depths = -to_camera(ar, tri, view_from_scene(scene, ar))[:, 2]
    near_plane = float(view_from_scene(scene, ar).near)
    assert r.stats.clipped == int(bool((depths < near_plane).any() and (depths > near_plane).any()))
    covered = (r.provenance >= 0).reshape(-1)
    # Camera depth -z of each ray's hit: t along the spec ray, whose t = 1 is the near plane.
    depth = t * float(view_from_scene(scene, ar).near)
    assert covered[(bary > 0.04) & (depth > 1.15 * near)].all()
    assert not covered[(bary < -0.04) | (depth < 0.85 * near)].any()


def _light(ar, forward):
    one = ar.const(1.0)
    return Light(0, DIRECTIONAL, (ar.const(0.0),) * 3, tuple(ar.const(c) for c in forward), 0xFFFF, one)


def test_flat_shading_uses_the_winding_normal_and_the_light():
    ar = make_arith("fp16")
    ccw = ((-3, -3, -2), (3, -3, -2), (0, 3, -2))  # normal +z, towards the camera
    base = np.array([0x7BEF])
    v = view(ar)
    facing = render_triangles(np.array([ccw]), base, [_light(ar, (0, 0, -1))], v, ar, (W, H))
    assert set(np.unique(facing.rgb565[facing.provenance >= 0])) == {0x7BEF}
    away = render_triangles(np.array([ccw[::-1]]), base, [_light(ar, (0, 0, -1))], v, ar, (W, H))
    assert set(np.unique(away.rgb565[away.provenance >= 0])) == {0}
    # 60 degrees: cos 0.5 halves each channel (15 -> 7.5 -> 8, 31 -> 15.5 -> 16).
    slanted = render_triangles(np.array([ccw]), base, [_light(ar, (0, -np.sqrt(3), -1))], v, ar, (W, H))
    got = int(np.unique(slanted.rgb565[slanted.provenance >= 0])[0])
    assert (got >> 11, (got >> 5) & 63, got & 31) == (8, 16, 8)
    unlit = render_triangles(np.array([ccw]), base, [], v, ar, (W, H))
    assert set(np.unique(unlit.rgb565[unlit.provenance >= 0])) == {0x7BEF}


def test_overflowing_normal_is_not_drawn_and_counted():
    ar = make_arith("fp16")
    huge = ((-60000, -60000, -2), (60000, -60000, -2), (0, 60000, -2))
    r = render_triangles(np.array([huge]), np.array([RED]), [_light(ar, (0, 0, -1))], view(ar), ar, (W, H))
    assert (r.provenance == -1).all() and r.stats.nonfinite == 1


@pytest.mark.parametrize("precision", ["fp16", "fp32", "fp64"])
def test_every_precision_renders_the_same_silhouette_away_from_edges(precision):
    ar = make_arith(precision)
    ref = make_arith("fp64")
    tri = _tri((-2.5, -1.7, -3.1), (2.2, -1.1, -3.6), (0.3, 2.4, -2.7))
    a = rasterize(tri, np.array([RED]), view(ar, canvas=(2.0, 1.5)), ar, (W, H)).provenance >= 0
    b = rasterize(tri, np.array([RED]), view(ref, canvas=(2.0, 1.5)), ref, (W, H)).provenance >= 0
    assert (a != b).sum() <= 0.1 * b.sum()


def _program(tris, colours):
    from rend3r.isa import CameraSet, FrameOp, Func, ShapeSet, encode
    from rend3r.isa.tables import lookup

    idx = lambda n: lookup(Table.TRIANGLE, n).index  # noqa: E731
    words = [*encode(FrameOp(Func.NR))]
    names = ("x1", "y1", "z1", "x2", "y2", "z2", "x3", "y3", "z3")
    for k, (tri, col) in enumerate(zip(tris, colours)):
        vals = [float_to_bits(c) for c in np.asarray(tri, dtype=np.float64).ravel()]
        for a in range(0, 8, 2):
            words += encode(ShapeSet(k, idx(names[a]), idx(names[a + 1]), vals[a], vals[a + 1]))
        words += encode(ShapeSet(k, idx("z3"), idx("col"), vals[8], col))
    words += [*encode(CameraSet(prop_index(Table.CAMERA, "nclip"), float_to_bits(1.0)))]
    words += [*encode(FrameOp(Func.NF)), *encode(FrameOp(Func.ER)), *encode(FrameOp(Func.ER))]
    return words


def test_run_program_renders_triangles_in_raster_mode():
    from rend3r.emu.run import run_program

    tris = [((-20, -20, -3), (20, -20, -3), (0, 20, -3)), ((-1, -1, -2), (1, -1, -2), (0, 1, -2))]
    res = run_program(_program(tris, [RED, GREEN]), EmuOptions(mode="raster", width=W, height=H))
    (frame,) = res.frames
    assert frame.provenance[H // 2, W // 2] == 1 and frame.rgb565[H // 2, W // 2] == GREEN
    assert frame.provenance[2, W // 2] == 0 and frame.rgb565[2, W // 2] == RED
    assert frame.depth[H // 2, W // 2] == pytest.approx(2.0 * np.sqrt(1 + 2 * 0.125**2), rel=1e-3)
    assert res.stats.frames[0].hits == (frame.provenance >= 0).sum()


@settings(max_examples=40)
@given(st.lists(st.integers(0, 0xFFFF), min_size=9, max_size=27), st.sampled_from(["zbuffer", "painter"]))
def test_any_float16_vertices_give_a_defined_frame(bits, depth_mode):
    """Infinities, NaNs, subnormals, huge and degenerate triangles: no exception, no NaN pixel."""
    ar = make_arith("fp16")
    n = len(bits) // 9
    tris = ar.from_bits(np.array(bits[: n * 9], dtype=np.uint16)).reshape(n, 3, 3)
    light = _light(ar, (0.3, -0.5, -1.0))
    r = render_triangles(tris, np.arange(n) * 0x1111, [light], view(ar), ar, (16, 12), depth_mode)
    hit = r.provenance >= 0
    assert np.isfinite(r.depth[hit]).all() and (r.depth[hit] > 0).all()
    assert np.isinf(r.depth[~hit]).all() and (r.rgb565[~hit] == 0).all()
