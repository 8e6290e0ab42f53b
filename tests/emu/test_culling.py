"""Culling never changes a pixel: images, depth and provenance are bit-identical with and
without it, on random scenes including far shapes where float16 error is large."""

import numpy as np
from hypothesis import given, settings, strategies as st

from rend3r.emu.options import EmuOptions
from rend3r.emu.run import run_program

from .scenes import Prog

coord = st.floats(-6, 6, allow_nan=False, width=16)
depth = st.floats(-60, -1.5, allow_nan=False, width=16)
inv_scale = st.floats(0.25, 6, allow_nan=False, width=16)
quat = st.tuples(*[st.floats(-1.5, 1.5, allow_nan=False, width=16)] * 4)
sphere = st.tuples(coord, coord, depth, inv_scale, inv_scale, inv_scale, quat, st.integers(0, 0xFFFF))
light = st.one_of(
    st.none(),
    st.tuples(st.just(1), coord, coord, coord),
    st.tuples(st.just(2), coord, coord, st.floats(-20, 2, allow_nan=False, width=16)),
)


def _build(spheres, lt, fov, cam_loc) -> Prog:
    p = Prog().nr().cam(hfov=fov, vfov=fov, xloc=cam_loc[0], yloc=cam_loc[1])
    for i, (x, y, z, sx, sy, sz, q, col) in enumerate(spheres):
        p.sphere(3 * i + 1, loc=(x, y, z), scale=(sx, sy, sz), rot=q, col=col)
    if lt is not None:
        kind, a, b, c = lt
        if kind == 1:
            p.light(0, src=1, xfor=a, yfor=b, zfor=c)
        else:
            p.light(0, src=2, xloc=a, yloc=b, zloc=c)
    return p.nf()


def _same(prog: Prog, **opts) -> None:
    frames = []
    for cull in (True, False):
        res = run_program(prog.words, EmuOptions(width=48, height=36, cull=cull, **opts))
        frames.append(res.frames[0])
    a, b = frames
    assert (a.rgb565 == b.rgb565).all()
    assert (a.provenance == b.provenance).all()
    assert (a.depth.view(np.uint32) == b.depth.view(np.uint32)).all()


@settings(max_examples=30)
@given(st.lists(sphere, min_size=1, max_size=10), light, st.sampled_from([0.05, 0.2, 1.0]),
       st.tuples(coord, coord))
def test_culling_is_bit_identical_fp16(spheres, lt, fov, cam_loc):
    _same(_build(spheres, lt, fov, cam_loc))


@settings(max_examples=10)
@given(st.lists(sphere, min_size=1, max_size=6), light, st.sampled_from(["fp32", "fp64"]))
def test_culling_is_bit_identical_wider(spheres, lt, precision):
    _same(_build(spheres, lt, 0.2, (0.0, 0.0)), precision=precision)


def test_culling_at_silhouettes_of_distant_spheres():
    """A row of far, small spheres seen through a narrow view: the float16 halo is wide."""
    p = Prog().nr().cam(hfov=0.02, vfov=0.02)
    for i in range(12):
        p.sphere(i, loc=(-1.1 + 0.2 * i, 0.05 * i, -40.0 - i), scale=(5.0, 5.0, 5.0), col=0x1111 * (i + 1))
    p.dir_light(0, forward=(0.3, -0.2, -1.0)).nf()
    _same(p)
    _same(p, subnormals="ieee")


def test_culling_skips_work():
    p = Prog().nr().cam(hfov=0.5, vfov=0.5)
    for i in range(16):
        p.sphere(i, loc=(-3.0 + 0.4 * i, 0.0, -5.0), scale=(4.0, 4.0, 4.0))
    res = run_program(p.nf().words, EmuOptions(width=64, height=48))
    st_ = res.stats.frames[0]
    assert st_.skipped > 5 * st_.tests
