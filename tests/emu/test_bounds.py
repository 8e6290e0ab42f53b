"""The bounds behind the raytracer's hierarchy are sound, and culling changes no pixel.

Rays are aimed at and around random ellipsoids in many formats and computed with the
reference raycaster: every computed hit lies within the cull radius of its line and no
nearer than the depth floor. Deep scenes (front spheres hiding columns behind them) render
as the reference renders them, while testing a small share of the pairs.
"""

import numpy as np
import pytest
from hypothesis import event, given, settings, strategies as st

from rend3r.emu import bounds, bvh, native
from rend3r.emu.arith import make_arith
from rend3r.emu.options import EmuOptions
from rend3r.emu.processor import execute
from rend3r.emu.raytracer import render_frame, set_up
from rend3r.emu.reference import render_reference
from rend3r.emu.shapes import origin_term, shapes_from_scene, solve, squared_distance, to_object

from .scenes import Prog

ARITHS = [("fp16", "ftz"), ("fp16", "ieee"), ("fp32", "ftz"), ("fp64", "ftz"), ("e6m9", "ftz"), ("e6m9", "ieee")]
#: Formats of fewer exponent bits than fp32, or coarser fractions: their products overflow
#: (a miss) and the bounds take their own u, smallest normal and overflow threshold.
OTHER = [("e5m7", "ftz"), ("e7m4", "ieee"), ("bf16", "ftz"), ("e4m10", "ieee"), ("e6m20", "ftz")]
coord = st.floats(-3, 3, allow_nan=False, width=16)


def _scene(prog: Prog):
    scenes = []
    execute(prog.nf().words, EmuOptions(), on_nf=lambda s, n: scenes.append(s))
    return scenes[0]


def _rays(ar, center, origin, radius, rng, count=4000):
    """Directions (working precision) aimed at and around a centre from an origin, of
    lengths from a hundredth to four times the distance (short ones are where underflow
    enters the bounds)."""
    aim = (center - origin) + rng.normal(size=(count, 3)) * radius * rng.uniform(0.2, 1.5)
    aim *= 10.0 ** rng.uniform(-2.0, 0.6, size=(count, 1))
    return tuple(ar.round(aim[:, k].astype(ar.dtype)) for k in range(3))


@settings(max_examples=120)
@given(st.sampled_from(ARITHS + OTHER), st.tuples(coord, coord, st.floats(-12, -2, allow_nan=False, width=16)),
       st.floats(0.25, 4.0, width=16), st.floats(0.75, 1.25, width=16),
       st.tuples(*[st.floats(-1, 1, allow_nan=False, width=16)] * 4), st.tuples(coord, coord), st.integers(0, 2**31))
def test_every_computed_hit_is_within_the_cull_radius_and_beyond_the_depth_floor(arith, loc, inv, stretch, q, cam,
                                                                                  seed):
    ar = make_arith(*arith)
    rot = q if any(abs(c) > 0.05 for c in q) else (1.0, 0.0, 0.0, 0.0)
    scene = _scene(Prog().nr().cam(xloc=cam[0], yloc=cam[1]).sphere(0, loc=loc, scale=(inv, inv * stretch, inv), rot=rot))
    shapes = shapes_from_scene(scene, ar)
    origin = tuple(ar.from_bits(scene.camera_bits(n)) for n in ("xloc", "yloc", "zloc"))
    o64 = np.array([float(c) for c in origin])
    fr = set_up(scene, EmuOptions(precision=arith[0], subnormals=arith[1]))  # the engine's bound table
    table, ok = fr.bnd, fr.bounded
    center = table[0, :3]
    d = _rays(ar, center, o64, 1.0 / (inv * min(1.0, stretch)), np.random.default_rng(seed))
    d64 = np.stack([np.asarray(c, np.float64) for c in d], axis=1)
    length = np.linalg.norm(d64, axis=1)
    p = bounds.primary(table, ok, o64, length.min(), length.max(), ar.unit_roundoff, ar.tiny, ar.overflow)
    fr.tree.fit(p, apex=o64)
    radius, floor = p.radius[0], p.floor[0]
    s = shapes.take(0)
    S, D = to_object(ar, s, origin, d)
    sol = solve(ar, s, S, D, origin_term(ar, s, S), ar.const(0.0), ar.const(np.inf))
    sqd = squared_distance(ar, ar.add(ar.add(ar.mul(d[0], d[0]), ar.mul(d[1], d[1])), ar.mul(d[2], d[2])), sol.t)
    hit = sol.hit & np.isfinite(sqd)
    v = center - o64
    gap = np.sqrt(np.maximum(0.0, v @ v - (d64 @ v) ** 2 / length**2))
    assert (gap[sol.disc >= 0] <= radius).all()  # a real root only near the line
    assert (np.asarray(sqd[hit], np.float64) >= floor).all()


def _deep(n=4, k=4, depth_step=0.6, inv=2.4, **cam) -> Prog:
    """An n x n wall of columns k deep: front spheres hide most of the ones behind."""
    p = Prog().nr().cam(hfov=0.25, vfov=0.25, **cam)
    spacing = 4.0 / n
    for i in range(n):
        for j in range(n):
            for d in range(k):
                x, y = (i - (n - 1) / 2) * spacing, (j - (n - 1) / 2) * spacing
                p.sphere(((i * n) + j) * k + d, loc=(x, y, -3.0 - d * depth_step), scale=(inv / spacing,) * 3,
                         col=(i * 4 + j * 2 + d) & 0xFFFF or 1)
    return p


def _same(prog: Prog, options: EmuOptions):
    scene = _scene(prog)
    engine, stats = render_frame(scene, options)
    ref = render_reference(scene, options)
    assert (engine.rgb565 == ref.rgb565).all()
    assert (engine.provenance == ref.provenance).all()
    assert (engine.depth.view(np.uint32) == ref.depth.view(np.uint32)).all()
    return stats


@pytest.mark.parametrize("precision,subnormals", ARITHS)
@pytest.mark.parametrize("cam", [{}, {"rrot": 0.96, "jrot": 0.1, "irot": -0.05}], ids=["grid", "rotated"])
def test_deep_scenes_render_as_the_reference_with_few_tests(precision, subnormals, cam):
    prog = _deep(n=8, k=5, **cam).dir_light(0, forward=(0.3, -0.2, -1.0)).light(1, src=2, xloc=0.5, yloc=2.0, zloc=1.0)
    stats = _same(prog, EmuOptions(width=80, height=60, precision=precision, subnormals=subnormals))
    assert stats.tests < stats.skipped / 10


@pytest.mark.parametrize("precision,per_pixel", [("fp16", 3), ("fp32", 1.2), ("fp64", 1.2)])
def test_shapes_behind_the_nearest_hit_are_not_tested(precision, per_pixel):
    """A column of 40 spheres straight ahead: a pixel stops after the first ones (the
    float16 depth floor is looser)."""
    p = Prog().nr().cam(hfov=0.08, vfov=0.08)
    for d in range(40):
        p.sphere(d, loc=(0.0, 0.0, -3.0 - 0.5 * d), col=0x0841 * (d % 31 + 1))
    stats = _same(p, EmuOptions(width=40, height=30, precision=precision))
    assert stats.hits > 800
    assert stats.tests < per_pixel * stats.hits


def test_equal_spheres_at_equal_depth_keep_the_lower_index():
    p = Prog().nr().cam(hfov=0.3, vfov=0.3)
    for i in range(6):
        p.sphere(10 - i, loc=(0.0, 0.0, -4.0), col=0x1000 + i)
    p.sphere(20, loc=(0.0, 0.0, -9.0), col=0xFFFF)
    _same(p, EmuOptions(width=40, height=30))
    frame, _ = render_frame(_scene(p), EmuOptions(width=40, height=30))
    assert set(np.unique(frame.provenance)) <= {-1, 5}


@pytest.mark.parametrize("dmin", [1e160, np.inf])
def test_a_squared_direction_length_that_overflows_bounds_nothing(dmin):
    """fp64's overflow threshold is infinite, so the cull radius's cap on |S| is
    sqrt(1 + inf / |D|^2): NaN once |D|^2 overflows, and the shape is then left unbounded
    (a shortcut that skipped the cap gave such shapes a finite radius)."""
    bnd = np.zeros((8, native.B_COLUMNS))
    bnd[:, 2] = -10.0 - np.arange(8)
    bnd[:, native.B_SMIN] = bnd[:, native.B_SMAX] = 1.0
    ar = make_arith("fp64", "ftz")
    assert ar.overflow == np.inf
    ok = np.ones(8, bool)
    p = bounds.primary(bnd, ok, np.zeros(3), dmin, dmin, ar.unit_roundoff, ar.tiny, ar.overflow)
    bvh.build(bnd, ok).fit(p, apex=np.zeros(3))
    assert (p.radius == np.inf).all()


@settings(max_examples=40, derandomize=True)
@given(st.sampled_from(ARITHS + OTHER), st.integers(40, 400), st.floats(0.3, 3.0), st.booleans(),
       st.tuples(coord, coord, coord), st.integers(0, 2**31))
def test_a_waiting_subtree_bounds_every_shape_below_it(arith, n, spread, turned, cam, seed):
    """A subtree left to be made when first entered (csrc/setup.c bundle_lazy) gets bounds
    from its shapes' extremes (shape_bounds.inc subtree_bound): its depth floor is at most
    each of its shapes' own, and its cone holds every line through the camera that meets
    one of their balls (centre, cull radius), as the bundle made whole computes them."""
    rng = np.random.default_rng(seed)
    p = Prog().nr().cam(xloc=cam[0], yloc=cam[1], zloc=cam[2], hfov=0.3, vfov=0.3)
    for i in range(n):
        loc = rng.normal(size=3) * spread + (0.0, 0.0, -8.0)
        inv = 2.0 ** rng.uniform(-1.5, 1.5, size=3)
        rot = tuple(rng.normal(size=4)) if turned else (1.0, 0.0, 0.0, 0.0)
        p.sphere(i, loc=tuple(loc), scale=tuple(inv), rot=rot)
    scene = _scene(p)
    options = EmuOptions(precision=arith[0], subnormals=arith[1], width=32, height=24)
    kept = bounds.LAZY_ITEMS
    try:
        bounds.LAZY_ITEMS = 0
        whole = set_up(scene, options)
        bounds.LAZY_ITEMS = 12
        part = set_up(scene, options)
    finally:
        bounds.LAZY_ITEMS = kept
    tree, box = part.tree, part.primary[0].box
    floor, radius, bnd = whole.primary[1], whole.waiting.made.radius, whole.bnd
    apex = np.array([float(c) for c in whole.cam[native.CAM_ORIGIN:native.CAM_ORIGIN + 3]], np.longdouble)
    waiting = np.flatnonzero(np.asarray(part.waiting.state[:tree.nodes]) == native.LAZY_WAITING)
    assert len(waiting) > 0 and len(tree.items) > 12
    for at in waiting:
        right = at
        while tree.node[right, 1] == 0:
            right = tree.node[right, 0]
        left = at
        while tree.node[left, 1] == 0:
            left += 1
        slots = tree.items[tree.node[left, 0]:tree.node[right, 0] + tree.node[right, 1]]
        b = box[at]
        assert b[native.BV_FLOOR] <= floor[slots].min()
        event(f"a floor: {'yes' if b[native.BV_FLOOR] > 0 else 'no'}; a cone: {'yes' if b[native.BV_SINE] < np.inf else 'no'}")
        if not b[native.BV_SINE] < np.inf:
            continue
        axis = b[:3].astype(np.longdouble)  # BV_AXIS
        half = np.arcsin(np.longdouble(b[native.BV_SINE]))
        for s in slots:
            v = bnd[s, :3].astype(np.longdouble) - apex
            dist = np.sqrt(v @ v)
            assert radius[s] < dist  # else the subtree could hold no cone
            turn = np.arccos(np.clip(abs(v @ axis) / dist / np.sqrt(axis @ axis), -1, 1))
            assert turn + np.arcsin(np.longdouble(radius[s]) / dist) <= half


@pytest.mark.parametrize("kinds", [(2, 3), (1, 2, 3)], ids=["none bounded", "few bounded"])
def test_a_frame_made_in_part_with_few_or_no_bounded_shapes(kinds):
    """More shapes than a waiting subtree holds, few or none of them spheres the tree
    bounds (cylinders and cones stay outside it): the frame renders as the reference."""
    p = Prog().nr().cam(hfov=0.3, vfov=0.3).dir_light(0, forward=(0.3, -0.2, -1.0))
    for i in range(30):
        p.sphere(i, loc=((i % 6) * 0.4 - 1.0, (i // 6) * 0.4 - 1.0, -4.0 - 0.1 * i), scale=(4.0, 4.0, 4.0),
                 kind=kinds[i % len(kinds)], col=0x0841 * (i + 1) & 0xFFFF or 1)
    kept = bounds.LAZY_ITEMS
    try:
        bounds.LAZY_ITEMS = 8
        for precision in ("fp16", "fp32"):
            _same(p, EmuOptions(width=40, height=30, precision=precision, jobs=2))
    finally:
        bounds.LAZY_ITEMS = kept
