"""Raytracer behaviour: camera conventions, shape types against an independent reference,
nearest hit, lights and shadows, clipping, precision modes, NaN accounting."""

import numpy as np
import pytest

from rend3r.emu.options import EmuOptions
from rend3r.emu.run import run_program

from .scenes import Prog

W, H = 64, 48
SMALL = EmuOptions(width=W, height=H)


def render(prog: Prog, **opts):
    options = EmuOptions(**{"width": W, "height": H, **opts})
    result = run_program(prog.words, options)
    return result.frames[0], result.stats.frames[0]


def one(**kw) -> Prog:
    return Prog().nr().sphere(0, **kw)


def test_spec_screen_y_is_up_and_device_y_is_down():
    prog = one(loc=(0.0, 1.5, -5.0)).nf()
    spec, _ = render(prog)
    dev, _ = render(prog, camera="device", width=512, height=384)  # the device's rays are fixed
    rows = lambda f: np.nonzero((f.provenance >= 0).any(axis=1))[0]  # noqa: E731
    assert rows(spec).max() < H // 2
    assert rows(dev).min() > 384 // 2


def test_no_light_shows_the_flat_shape_colour_and_misses_take_the_background():
    frame, st = render(one(col=0x1234).nf(), background=0x001F)
    hit = frame.provenance == 0
    assert hit.any() and (~hit).any()
    assert (frame.rgb565[hit] == 0x1234).all() and (frame.rgb565[~hit] == 0x001F).all()
    assert np.isinf(frame.depth[~hit]).all() and np.isfinite(frame.depth[hit]).all()
    assert st.hits == hit.sum() and st.nan_rays == 0


def test_nearest_hit_wins_and_equal_distances_go_to_the_lower_index():
    prog = Prog().nr().cam(hfov=0.5, vfov=0.5).sphere(7, loc=(0.0, 0.0, -4.0)).sphere(3, loc=(0.0, 0.0, -4.0), col=0x07E0)
    prog.sphere(1000, loc=(6.0, 0.0, -8.0), scale=(0.5, 0.5, 0.5)).nf()
    frame, _ = render(prog)
    assert set(np.unique(frame.provenance)) == {-1, 3, 1000}
    assert (frame.provenance[H // 2 - 2 : H // 2 + 2, W // 2 - 2 : W // 2 + 2] == 3).all()


def test_headon_directional_light_gives_the_full_colour_at_the_centre():
    frame, _ = render(one(col=0xFFFF).dir_light(0, forward=(0.0, 0.0, -1.0)).nf(), width=65, height=49)
    assert frame.rgb565[24, 32] == 0xFFFF
    edge = frame.rgb565[24][frame.provenance[24] == 0]
    assert int(edge[0]) >> 11 < 31  # darker towards the silhouette


def test_light_colour_intensity_and_off():
    full, _ = render(Prog().nr().sphere(0, col=0xFFFF).dir_light(0, intensity=1.0).nf(), width=65, height=49)
    half, _ = render(Prog().nr().sphere(0, col=0xFFFF).dir_light(0, intensity=0.5).nf(), width=65, height=49)
    red, _ = render(Prog().nr().sphere(0, col=0xFFFF).dir_light(0, col=0xF800).nf(), width=65, height=49)
    off, _ = render(Prog().nr().sphere(0, col=0xFFFF).dir_light(0).light(0, src=0).nf(), width=65, height=49)
    c = (24, 32)
    assert full.rgb565[c] == 0xFFFF
    assert half.rgb565[c] == (16 << 11) | (32 << 5) | 16  # 31*0.5, 63*0.5, rounded half up
    assert red.rgb565[c] == 0xF800
    assert off.rgb565[c] == 0xFFFF  # no light on: flat colour


def test_two_lights_add_and_saturate():
    prog = Prog().nr().sphere(0, col=0x8410).dir_light(0).dir_light(5).nf()
    frame, st = render(prog, width=65, height=49)
    assert st.lights == 2
    assert frame.rgb565[24, 32] == (31 << 11) | (63 << 5) | 31  # 2 * 0x8410 channels, clamped


def test_point_light_lights_the_side_facing_it():
    prog = one(col=0xFFFF).light(0, src=2, xloc=5.0, yloc=0.0, zloc=-3.0).nf()
    frame, st = render(prog)
    row = frame.rgb565[H // 2][frame.provenance[H // 2] == 0]
    assert st.lights == 1
    assert row[-1] > 0 and row[0] == 0  # right side lit, left side dark


def test_shadow_of_one_sphere_on_another_and_no_self_shadow():
    # light along (-1, 0, -1): a small sphere up and to the right shadows the big one
    def scene(with_blocker: bool) -> Prog:
        p = Prog().nr().cam(hfov=0.1, vfov=0.1).sphere(0, loc=(0.0, 0.0, -6.0), col=0xFFFF)
        if with_blocker:
            p.sphere(1, loc=(1.5, 0.0, -4.5), scale=(4.0, 4.0, 4.0), col=0x07E0)
        return p.dir_light(0, forward=(-1.0, 0.0, -1.0)).nf()

    alone, _ = render(scene(False))
    shaded, st = render(scene(True))
    lit = (alone.provenance == 0) & (alone.rgb565 > 0)
    assert lit.sum() > 50
    cos_positive = alone.rgb565[alone.provenance == 0] > 0
    assert cos_positive.sum() == lit.sum()  # a lone convex shape never shadows itself
    dark = lit & (shaded.provenance == 0) & (shaded.rgb565 == 0)
    assert dark.sum() > 5
    assert st.shadow_rays > 0


def test_far_clip_bounds_hits_and_near_clip_cuts_the_front():
    assert (render(one(loc=(0.0, 0.0, -5.0)).cam(fclip=3.0).nf())[0].provenance < 0).all()
    assert (render(one(loc=(0.0, 0.0, -5.0)).cam(fclip=10.0).nf())[0].provenance >= 0).any()
    frame, _ = render(one(loc=(0.0, 0.0, -1.5)).nf(), width=65, height=49)
    # the front surface (t = 0.5) lies before the near plane (t = 1): the back surface shows
    assert frame.depth[24, 32] == pytest.approx(2.5, rel=1e-3)


def test_camera_rotation_turns_the_view():
    prog = Prog().nr().sphere(0, loc=(0.0, 0.0, 5.0)).cam(rrot=0.0, jrot=1.0).nf()
    frame, _ = render(prog)
    assert (frame.provenance == 0).any()
    front, _ = render(Prog().nr().sphere(0, loc=(0.0, 0.0, 5.0)).nf())
    assert (front.provenance < 0).all()


def test_camera_location_translates_rays():
    a, _ = render(Prog().nr().sphere(0, loc=(2.0, 0.0, -5.0)).cam(xloc=2.0).nf())
    b, _ = render(Prog().nr().sphere(0, loc=(0.0, 0.0, -5.0)).nf())
    assert ((a.provenance >= 0) == (b.provenance >= 0)).all()


@pytest.mark.parametrize("precision", ["fp32", "fp64"])
def test_wider_precisions_agree_with_fp16_on_a_plain_scene(precision):
    prog = one(col=0xFFFF).dir_light(0, forward=(-1.0, -1.0, -1.0)).nf()
    f16, _ = render(prog)
    wide, _ = render(prog, precision=precision)
    assert ((f16.provenance >= 0) != (wide.provenance >= 0)).sum() <= 4
    both = (f16.provenance >= 0) & (wide.provenance >= 0)
    assert np.abs(f16.depth[both] - wide.depth[both]).max() < 0.01
    diff = np.abs((f16.rgb565[both] >> 11).astype(int) - (wide.rgb565[both] >> 11))
    assert diff.max() <= 1


def test_ieee_and_ftz_agree_on_a_plain_scene():
    prog = one(col=0xFFFF).dir_light(0, forward=(-1.0, -1.0, -1.0)).nf()
    a, _ = render(prog)
    b, _ = render(prog, subnormals="ieee")
    assert (a.rgb565 == b.rgb565).all()


def test_degenerate_shape_counts_nan_and_leaves_defined_pixels():
    frame, st = render(one(scale=(0.0, 0.0, 0.0)).nf())
    assert st.nan_tests == W * H and st.nan_rays == W * H
    assert (frame.provenance == -1).all() and (frame.rgb565 == 0).all()


def test_light_without_direction_counts_nan_rays_as_misses():
    frame, st = render(one(col=0xFFFF).light(0, src=1).nf(), background=0x0001)
    assert st.nan_rays > 0
    assert (frame.rgb565 == 0x0001).all() and (frame.provenance == -1).all()


def test_overflow_in_float16_is_a_counted_miss_not_in_fp32():
    prog = one(loc=(0.0, 0.0, -300.0)).cam(hfov=0.01, vfov=0.01).nf()
    f16, s16 = render(prog)
    f32, s32 = render(prog, precision="fp32")
    assert s16.nan_tests > 0 and (f16.provenance == -1).all()
    assert s32.nan_tests == 0 and (f32.provenance == 0).any()


def test_zero_quaternion_reads_as_no_rotation():
    a, _ = render(one(rot=(0.0, 0.0, 0.0, 0.0), scale=(1.0, 2.0, 1.0)).nf())
    b, _ = render(one(rot=(1.0, 0.0, 0.0, 0.0), scale=(1.0, 2.0, 1.0)).nf())
    assert (a.provenance == b.provenance).all() and (a.depth == b.depth).all()


def test_shapes_that_are_off_cost_nothing():
    prog = Prog().nr().sphere(0).shape(500000, xloc=1.0).sphere(9, kind=0).nf()
    _, st = render(prog)
    assert st.shapes == 1 and st.tests + st.skipped == W * H


def test_device_light_model_uses_light_0_only_white_and_full_strength():
    prog = Prog().nr().sphere(0, col=0xFFFF).dir_light(0, col=0xF800, intensity=0.25).dir_light(1).nf()
    spec, s1 = render(prog, width=65, height=49)
    dev, s2 = render(prog, width=65, height=49, light_model="device")
    assert (s1.lights, s2.lights) == (2, 1)
    assert dev.rgb565[24, 32] == 0xFFFF  # light 0 as white at intensity 1, head-on


def test_device_intensity_converter_wraps_above_a_quarter():
    prog = Prog().nr().sphere(0, col=0xFFFF).dir_light(0).nf()
    frame, _ = render(prog, width=65, height=49, intensity_fixed=True)
    assert frame.rgb565[24, 32] == 0  # I = 1 -> 16384 wraps to 0 in 13 bits
    assert (frame.rgb565[frame.provenance == 0] > 0).any()  # grazing parts (I < 0.25) stay lit
