"""The raytracer's shortcuts change no pixel: the depth floor bounds every computed hit
distance, deep scenes render bit-identically with and without culling, grid cameras give
the same direction tables as per-pixel rays, cones hold their rays, and the batch and
merge fast paths agree with the general ones."""

from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from rend3r.emu import raytracer as rt
from rend3r.emu.arith import make_arith
from rend3r.emu.camera import camera_rays
from rend3r.emu.cull import (FINE, Rounding, depth_floor, grid_cones, pairs, screen_children, screen_tiles,
                             shape_bounds, tile_cones)
from rend3r.emu.options import EmuOptions
from rend3r.emu.processor import execute
from rend3r.emu.run import run_program
from rend3r.emu.scene import Scene
from rend3r.emu.shapes import shapes_from_scene, solve, squared_distance, to_object, origin_term

from .scenes import Prog

ARITHS = [("fp16", "ftz"), ("fp16", "ieee"), ("fp32", "ftz"), ("fp64", "ftz")]


def _scene(prog: Prog) -> Scene:
    scene = Scene()
    execute(prog.nf().words, EmuOptions(), on_nf=lambda s, n: None, scene=scene)
    return scene


coord = st.floats(-3, 3, allow_nan=False, width=16)


@settings(max_examples=40, deadline=None)
@given(st.sampled_from(ARITHS), st.tuples(coord, coord, st.floats(-12, -2, allow_nan=False, width=16)),
       st.floats(0.25, 4.0, width=16), st.floats(0.75, 1.25, width=16),
       st.tuples(*[st.floats(-1, 1, allow_nan=False, width=16)] * 4), st.tuples(coord, coord), st.integers(0, 2**31))
def test_depth_floor_bounds_every_computed_hit(arith, loc, inv, stretch, q, cam, seed):
    """Rays aimed at and around a sphere: each computed hit has sq_dist >= the floor."""
    ar = make_arith(*arith)
    rot = q if any(abs(c) > 0.05 for c in q) else (1.0, 0.0, 0.0, 0.0)
    scene = _scene(Prog().nr().cam(xloc=cam[0], yloc=cam[1])
                   .sphere(0, loc=loc, scale=(inv, inv * stretch, inv), rot=rot))
    shapes = shapes_from_scene(scene, ar)
    origin = tuple(ar.from_bits(scene.camera_bits(n)) for n in ("xloc", "yloc", "zloc"))
    o64, c64 = np.array([float(c) for c in origin]), shape_bounds(shapes).center[0]
    rng = np.random.default_rng(seed)
    radius = 1.0 / (float(shapes_from_scene(scene, make_arith("fp64")).inv_scale[0][0]) * min(1.0, stretch))
    aim = (c64 - o64) + rng.normal(size=(4000, 3)) * radius * rng.uniform(0.2, 1.5)
    aim *= rng.uniform(0.5, 4.0, size=(4000, 1))
    d = tuple(ar.round(aim[:, k].astype(np.float32 if ar.dtype == np.float32 else np.float64)) for k in range(3))
    length = np.sqrt(sum(np.asarray(c, np.float64) ** 2 for c in d))
    floor = depth_floor(shape_bounds(shapes), o64, length.min() * (1 - 1e-6), length.max() * (1 + 1e-6),
                        Rounding.of(ar))[0]
    s = shapes.take(0)
    S, D = to_object(ar, s, origin, d)
    sol = solve(ar, s, S, D, origin_term(ar, s, S), ar.const(0.0), ar.const(np.inf))
    dd = ar.add(ar.add(ar.mul(d[0], d[0]), ar.mul(d[1], d[1])), ar.mul(d[2], d[2]))
    sqd = squared_distance(ar, dd, sol.t)
    hit = sol.hit & np.isfinite(sqd)
    assert (np.asarray(sqd[hit], np.float64) >= floor).all()


def _deep(n: int = 4, k: int = 4, depth_step: float = 0.6, inv: float = 2.4, **cam) -> Prog:
    """An n x n wall of columns k deep (inverse scale inv / spacing): front spheres hide
    most of the ones behind."""
    p = Prog().nr().cam(hfov=0.25, vfov=0.25, **cam)
    spacing = 4.0 / n
    for i in range(n):
        for j in range(n):
            for d in range(k):
                x, y = (i - (n - 1) / 2) * spacing, (j - (n - 1) / 2) * spacing
                p.sphere(((i * n) + j) * k + d, loc=(x, y, -3.0 - d * depth_step), scale=(inv / spacing,) * 3,
                         col=(i * 4 + j * 2 + d) & 0xFFFF or 1)
    return p


def _same(prog: Prog, **opts) -> tuple:
    frames = [run_program(prog.words, EmuOptions(width=80, height=60, cull=c, **opts)) for c in (True, False)]
    a, b = (r.frames[0] for r in frames)
    assert (a.rgb565 == b.rgb565).all()
    assert (a.provenance == b.provenance).all()
    assert (a.depth.view(np.uint32) == b.depth.view(np.uint32)).all()
    return frames[0].stats.frames[0], frames[1].stats.frames[0]


@pytest.mark.parametrize("precision,subnormals", ARITHS)
@pytest.mark.parametrize("cam", [{}, {"rrot": 0.96, "jrot": 0.1, "irot": -0.05}], ids=["grid", "rotated"])
def test_deep_scenes_are_bit_identical_with_and_without_culling(precision, subnormals, cam):
    prog = _deep(n=8, k=5, **cam).dir_light(0, forward=(0.3, -0.2, -1.0)).light(1, src=2, xloc=0.5, yloc=2.0, zloc=1.0)
    culled, full = _same(prog.nf(), precision=precision, subnormals=subnormals)
    assert culled.tests < full.tests / 4


@pytest.mark.parametrize("precision,share", [("fp16", 0.9), ("fp32", 0.5)])
def test_depth_culling_acts_on_deep_scenes(precision, share, monkeypatch):
    """768 spheres in 12 layers (three blocks): the front blocks hide most of the rest
    (float16's looser floor skips less)."""
    prog = _deep(n=8, k=12, depth_step=0.3, inv=1.2).nf()  # float16-sized: no overflow
    run = lambda: run_program(prog.words, EmuOptions(width=80, height=60, precision=precision)).stats.frames[0]  # noqa: E731
    with_floor = run().tests
    monkeypatch.setattr(rt, "depth_floor", lambda b, *rest: np.zeros(len(b.smin)))
    assert with_floor < share * run().tests


def test_equal_spheres_at_equal_depth_keep_the_lower_index():
    """Ties in distance go to the lower shape index, also when depth culling is on."""
    p = Prog().nr().cam(hfov=0.3, vfov=0.3)
    for i in range(6):
        p.sphere(10 - i, loc=(0.0, 0.0, -4.0), col=0x1000 + i)
    p.sphere(20, loc=(0.0, 0.0, -9.0), col=0xFFFF).nf()
    _same(p)
    frame = run_program(p.words, EmuOptions(width=40, height=30)).frames[0]
    assert set(np.unique(frame.provenance)) <= {-1, 5}


def test_grid_cameras_give_the_per_pixel_tables():
    ar = make_arith("fp16")
    options = EmuOptions(width=96, height=64)
    scene = _scene(_deep(n=2, k=2).sphere(99, loc=(0.5, 0.2, -6.0), scale=(1.5, 2.0, 1.0), rot=(0.9, 0.3, 0.1, 0.2)))
    rays = camera_rays(scene, options, ar)
    assert rays.grid is not None
    flat = replace(rays, grid=None)
    shapes = shapes_from_scene(scene, ar)
    a, b = rt._direction_tables(ar, shapes, rays), rt._direction_tables(ar, shapes, flat)
    for x, y in zip(a.columns, b.columns):
        assert (x.view(np.uint32) == y.view(np.uint32)).all()
    assert (rt._squared_lengths(ar, rays).view(np.uint32) == rt._squared_lengths(ar, flat).view(np.uint32)).all()


@pytest.mark.parametrize("size", [(512, 384), (100, 75)])
@pytest.mark.parametrize("camera", ["spec", "device"])
def test_cones_hold_their_rays(size, camera):
    w, h = size
    options = EmuOptions(width=w, height=h, camera=camera)
    ar = options.arith
    rays = camera_rays(_scene(Prog().nr().cam(hfov=0.7, vfov=0.4, nclip=0.5)), options, ar)
    d = np.stack([np.asarray(c, np.float64) for c in rays.direction], axis=1)
    for tile in (None, FINE):
        tiles = screen_tiles(w * h, w) if tile is None else screen_tiles(w * h, w, tile)
        dirs = d[tiles.order]
        for cones in (grid_cones(*rays.grid, tiles, w), tile_cones(tiles, dirs)):
            axis = cones.axis[tiles.of_pixel]
            length = np.linalg.norm(dirs, axis=1)
            angle = np.arccos(np.clip(np.einsum("ij,ij->i", dirs / length[:, None], axis), -1, 1))
            assert (angle <= cones.half[tiles.of_pixel] + 1e-12).all()
            assert (length >= cones.dmin[tiles.of_pixel, 0] * (1 - 1e-12)).all()


def test_fine_tiles_partition_their_coarse_tiles():
    w, h = 100, 75
    coarse, fine, children = screen_tiles(w * h, w), screen_tiles(w * h, w, FINE), screen_children(w * h, w)
    covered = np.sort(children[children >= 0])
    assert (covered == np.arange(len(fine))).all()
    for c in range(len(coarse)):
        mine = set(coarse.order[coarse.start[c]:coarse.start[c] + coarse.count[c]].tolist())
        kids = [k for k in children[c] if k >= 0]
        theirs = set(np.concatenate([fine.order[fine.start[k]:fine.start[k] + fine.count[k]] for k in kids]).tolist())
        assert mine == theirs


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**31))
def test_pairs_cover_every_kept_cell_once_in_distinct_batches(seed):
    rng = np.random.default_rng(seed)
    tiles = screen_tiles(64 * 40, 64)
    sel = np.sort(rng.choice(500, size=int(rng.integers(1, 40)), replace=False))
    keep = rng.random((len(tiles), len(sel))) < rng.uniform(0.05, 0.9)
    want = sorted((int(p), int(s)) for t, j in zip(*np.nonzero(keep))
                  for p in tiles.order[tiles.start[t]:tiles.start[t] + tiles.count[t]] for s in [sel[j]])
    for distinct in (True, False):
        got = []
        for pix, slot in pairs(tiles, keep, sel, distinct=distinct):
            if distinct:
                assert len(np.unique(pix)) == len(pix)
            got += zip(pix.tolist(), slot.tolist())
        assert sorted(got) == want


@settings(max_examples=50, deadline=None)
@given(st.integers(0, 2**31))
def test_distinct_merges_equal_the_general_merge(seed):
    rng = np.random.default_rng(seed)
    n = 50
    general, fast = rt._Nearest(n, np.float32), rt._Nearest(n, np.float32)
    for _ in range(int(rng.integers(1, 6))):
        m = int(rng.integers(1, n))
        pix = rng.choice(n, size=m, replace=False)
        slot = rng.integers(0, 8, size=m)
        # as in rendering, a pixel and shape always give the same values; few values: many ties
        sqd = ((pix * 7 + slot * 3) % 4 + 1).astype(np.float32)
        t = ((pix * 31 + slot * 17) % 97 / 97).astype(np.float32)
        hit = rng.random(m) < 0.7
        general.update(pix, slot, sqd, t, hit=hit)
        fast.update(pix, slot, sqd, t, distinct=True, hit=hit)
    assert (general.sqd == fast.sqd).all() and (general.slot == fast.slot).all()
    assert (general.t.view(np.uint32) == fast.t.view(np.uint32)).all()


component = st.one_of(st.floats(-1000, 1000, width=16), st.floats(allow_nan=True, allow_infinity=True, width=32),
                      st.sampled_from([0.0, -0.0, 1e-40, -1e-40, 2.0**-14, -(2.0**-15), 65504.0, 1e30]))


@settings(max_examples=200, deadline=None)
@given(st.sampled_from(ARITHS), st.lists(st.tuples(component, component, component), min_size=1, max_size=8))
def test_identity_rotations_skip_no_bit(arith, rows):
    """Rotating by exactly (1, +0, +0, +0) may return v itself: only when that is what the
    full device-order computation gives, bit for bit."""
    from rend3r.emu.vec import conj, hamilton, hamilton_pure, rotate, rotate_inverse
    ar = make_arith(*arith)
    v = tuple(ar.round(np.array([r[k] for r in rows], dtype=np.float64).astype(ar.dtype)) for k in range(3))
    q = tuple(ar.const(c) for c in (1.0, 0.0, 0.0, 0.0))
    full_inv = hamilton(ar, hamilton_pure(ar, conj(ar, q), v), q, real=False)[1:]
    full_fwd = hamilton(ar, hamilton_pure(ar, q, v), conj(ar, q), real=False)[1:]
    bits = np.uint32 if ar.dtype == np.float32 else np.uint64
    for got, want in ((rotate_inverse(ar, q, v), full_inv), (rotate(ar, q, v), full_fwd)):
        for g, w in zip(got, want):
            assert (np.asarray(g).view(bits) == np.asarray(w).view(bits)).all()


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**31), st.sampled_from([(64, 48), (100, 75)]))
def test_subset_tiles_equal_sorting_the_subset(seed, size):
    from rend3r.emu.cull import make_tiles, subset_tiles
    w, h = size
    rng = np.random.default_rng(seed)
    pixels = np.flatnonzero(rng.random(w * h) < rng.uniform(0.01, 1.0))
    a, b = subset_tiles(screen_tiles(w * h, w), pixels), make_tiles(pixels, w)
    for name in ("order", "start", "count", "of_pixel"):
        assert (getattr(a, name) == getattr(b, name)).all()
