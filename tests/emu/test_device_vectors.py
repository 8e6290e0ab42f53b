"""The worked float16 vectors of the original device's documentation, bit for bit (fp16,
flush to zero), from the reference raycaster and from the compiled kernels alike."""

import numpy as np
import pytest

from rend3r.emu.arith import make_arith
from rend3r.emu.camera import camera_rays
from rend3r.emu.options import EmuOptions
from rend3r.emu.processor import execute
from rend3r.emu.raytracer import render_frame, set_up, trace_pixel
from rend3r.emu.scene import Scene
from rend3r.emu.shapes import origin_term, shapes_from_scene, solve, squared_distance, surface, to_object
from rend3r.emu.vec import dot

from .scenes import Prog

DEVICE = EmuOptions(camera="device")
# sphere at (0, 0, -2), camera at the origin, light forward (1, 1, 0)
PROGRAM = Prog().nr().sphere(0, loc=(0.0, 0.0, -2.0), col=0xFFFF).light(0, src=1, xfor=1, yfor=1, zfor=0).nf().er()


def _bits(a) -> int:
    return int(np.asarray(a, dtype=np.float16).reshape(-1)[0].view(np.uint16))


def _scene() -> Scene:
    scene = Scene()
    execute(PROGRAM.words, DEVICE, scene=scene)
    return scene


_KERNEL_STAGES = dict(a2=6, b=7, c2=8, disc=9, sqrt=10, t1=11, t2=12, t=13, sq_dist=15)


def _kernel_trace(x: int, y: int) -> dict[str, int]:
    """The same values from the compiled kernels' own trace of the pixel."""
    t = trace_pixel(set_up(_scene(), DEVICE), DEVICE, x, y)
    values = {k: t.shapes[0, i] for k, i in _KERNEL_STAGES.items()}
    values["I"] = t.lights[0, 7]
    return {k: _bits(v) for k, v in values.items()}


def _trace(x: int, y: int) -> dict[str, int]:
    ar = make_arith("fp16", "ftz")
    scene = _scene()
    rays = camera_rays(scene, DEVICE, ar)
    shapes = shapes_from_scene(scene, ar)
    p = y * DEVICE.width + x
    D = tuple(d[p : p + 1] for d in rays.direction)
    S, Dh = to_object(ar, shapes, rays.origin, D)
    c2 = origin_term(ar, shapes, S)
    sol = solve(ar, shapes, S, Dh, c2, rays.tmin, rays.tmax)
    _, normal = surface(ar, shapes, S, Dh, sol.t, rays.origin, D)
    light = tuple(ar.const(v) for v in (-1.0, -1.0, 0.0))  # towards -forward
    cos = ar.div(dot(ar, normal, light), ar.mul(ar.sqrt(dot(ar, normal, normal)), ar.sqrt(dot(ar, light, light))))
    values = dict(a2=sol.a2, b=sol.b, c2=c2, disc=sol.disc, sqrt=sol.root, t1=sol.t1, t2=sol.t2, t=sol.t,
                  sq_dist=squared_distance(ar, dot(ar, D, D), sol.t), I=cos)
    assert sol.hit[0] and not sol.bad[0]
    return {k: _bits(v) for k, v in values.items()}


def test_device_ray_directions_are_float16_accumulations():
    ar = make_arith("fp16", "ftz")
    rays = camera_rays(_scene(), DEVICE, ar)
    dx, dy, dz = (np.asarray(d, np.float64).reshape(384, 512) for d in rays.direction)
    assert dx[0, 0] == -4.98828125 and dy[0, 0] == -3.740234375 and (dz == -1).all()
    assert dx[0, 1] == -4.98828125 + 0.01953125
    assert (np.diff(dx[0]) > 0).all() and (np.diff(dy[:, 0]) > 0).all()  # row 0 is world y = -3.74


@pytest.mark.parametrize("trace", [_trace, _kernel_trace], ids=["reference", "kernels"])
def test_worked_vector_pixel_256_192(trace):
    got = trace(256, 192)
    want = dict(a2=0x4000, b=0xC400, c2=0x4600, disc=0x4400, sqrt=0x4000, t1=0x3C00, t2=0x4200, t=0x3C00, sq_dist=0x3C00)
    assert {k: got[k] for k in want} == want
    assert got["I"] & 0x8000  # negative: the pixel is black


@pytest.mark.parametrize("trace", [_trace, _kernel_trace], ids=["reference", "kernels"])
def test_worked_vector_pixel_252_188(trace):
    got = trace(252, 188)
    assert {k: got[k] for k in ("a2", "b", "c2", "t", "sq_dist", "I")} == dict(
        a2=0x4009, b=0xC400, c2=0x4600, t=0x3C05, sq_dist=0x3C13, I=0x2E22)


def test_rendered_pixels_of_the_worked_scene():
    frame, stats = render_frame(_scene(), DEVICE)
    assert frame.rgb565[192, 256] == 0  # I negative
    # white shape, white light of intensity 1: channel * I, rounded: 31*0.0958 -> 3, 63*0.0958 -> 6
    assert frame.rgb565[188, 252] == (3 << 11) | (6 << 5) | 3
    assert frame.depth[188, 252] == pytest.approx(np.sqrt(float(np.float16(1.0185546875))), rel=1e-6)
    assert frame.provenance[188, 252] == 0 and frame.provenance[0, 0] == -1
    assert stats.nan_rays == 0


def test_shading_stages_of_the_worked_pixel():
    """The kernels' light stages at (252, 188): l = -forward, I, no shadow (one shape)."""
    t = trace_pixel(set_up(_scene(), DEVICE), DEVICE, 252, 188)
    l_x, l_y, l_z, *_, cos, f, fixed, lit, shadow = t.lights[0]
    assert (l_x, l_y, l_z) == (-1.0, -1.0, 0.0) and _bits(cos) == 0x2E22 and (lit, shadow) == (1, 0)
    assert t.colour == (3 << 11) | (6 << 5) | 3
