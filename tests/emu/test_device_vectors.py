"""The worked float16 vectors of original-device.md, bit for bit (fp16, flush to zero)."""

import numpy as np
import pytest

from rend3r.emu.arith import make_arith
from rend3r.emu.camera import camera_rays
from rend3r.emu.options import EmuOptions
from rend3r.emu.processor import execute
from rend3r.emu.raytracer import render_frame
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


def test_worked_vector_pixel_256_192():
    got = _trace(256, 192)
    want = dict(a2=0x4000, b=0xC400, c2=0x4600, disc=0x4400, sqrt=0x4000, t1=0x3C00, t2=0x4200, t=0x3C00, sq_dist=0x3C00)
    assert {k: got[k] for k in want} == want
    assert got["I"] & 0x8000  # negative: the pixel is black


def test_worked_vector_pixel_252_188():
    got = _trace(252, 188)
    assert {k: got[k] for k in ("a2", "b", "c2", "t", "sq_dist", "I")} == dict(
        a2=0x4009, b=0xC400, c2=0x4600, t=0x3C05, sq_dist=0x3C13, I=0x2E22)


@pytest.mark.parametrize("cull", [True, False])
def test_rendered_pixels_of_the_worked_scene(cull):
    frame, stats = render_frame(_scene(), EmuOptions(camera="device", cull=cull))
    assert frame.rgb565[192, 256] == 0  # I negative
    # white shape, white light of intensity 1: channel * I, rounded: 31*0.0958 -> 3, 63*0.0958 -> 6
    assert frame.rgb565[188, 252] == (3 << 11) | (6 << 5) | 3
    assert frame.depth[188, 252] == pytest.approx(np.sqrt(float(np.float16(1.0185546875))), rel=1e-6)
    assert frame.provenance[188, 252] == 0 and frame.provenance[0, 0] == -1
    assert stats.nan_rays == 0


def test_shading_stages_are_recorded_with_the_device_intensity():
    from rend3r.emu.cull import shape_bounds
    from rend3r.emu.lights import lights_from_scene
    from rend3r.emu.raytracer import shade_hits
    from rend3r.emu.stats import FrameStats

    ar = make_arith("fp16", "ftz")
    scene = _scene()
    rays = camera_rays(scene, DEVICE, ar)
    shapes = shapes_from_scene(scene, ar)
    p = 188 * DEVICE.width + 252
    D = tuple(d[p : p + 1] for d in rays.direction)
    S, Dh = to_object(ar, shapes, rays.origin, D)
    sol = solve(ar, shapes, S, Dh, origin_term(ar, shapes, S), rays.tmin, rays.tmax)
    point, normal = surface(ar, shapes, S, Dh, sol.t, rays.origin, D)
    seen = {}
    rgb, bad = shade_hits(ar, DEVICE, shapes, shape_bounds(shapes), lights_from_scene(scene, ar), np.array([p]),
                          np.array([0]), point, normal, FrameStats(), np.zeros(DEVICE.pixels, bool),
                          record=lambda stage, v: seen.setdefault(stage, np.asarray(v).copy()))
    assert list(seen) == [f"L0.{s}" for s in ("l.x", "l.y", "l.z", "n_dot_l", "n_len", "l_len", "denom", "cos", "f",
                                              "shadow")]
    assert _bits(seen["L0.cos"]) == 0x2E22 and seen["L0.shadow"].tolist() == [0]
    assert not bad[0] and rgb[0] == (3 << 11) | (6 << 5) | 3
