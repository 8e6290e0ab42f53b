"""Each shape type and transform against an independent float64 reference (rotation
matrices instead of quaternion products), with fp64 emulation."""

import numpy as np
import pytest

from rend3r.emu.options import EmuOptions
from rend3r.emu.run import run_program

from .scenes import Prog

W, H, FOV = 80, 60, 0.4
FORMS = {1: (1.0, 1.0), 2: (0.0, 1.0), 3: (-1.0, 0.0)}


def _rotation(q) -> np.ndarray:
    w, x, y, z = np.asarray(q, float) / np.linalg.norm(q)
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ])


def _reference(kind, loc, scale, q, light_forward):
    """t per pixel (nan = miss) and the diffuse term, in float64, by matrices.

    Inputs are rounded to float16 first, as the program stores them.
    """
    h = lambda v: np.asarray(v, np.float16).astype(float)  # noqa: E731
    loc, scale, q, light_forward, fov = h(loc), h(scale), h(q), h(light_forward), float(h(FOV))
    xs = 10 * ((np.arange(W) + 0.5) / W - 0.5) * fov
    ys = 7.5 * (0.5 - (np.arange(H) + 0.5) / H) * fov
    d = np.stack(np.broadcast_arrays(xs[None, :], ys[:, None], -1.0), axis=-1)
    m = np.dot(q, q) * np.diag(scale) @ _rotation(q).T  # world -> normal space
    S = m @ (-np.asarray(loc, float))
    D = d @ m.T
    zs, one = FORMS[kind]
    w3 = np.array([1.0, 1.0, zs])
    a = (D * D * w3).sum(-1)
    b = 2 * (D * S * w3).sum(-1)
    c = (S * S * w3).sum() - one
    disc = b * b - 4 * a * c
    with np.errstate(invalid="ignore"):
        r = np.sqrt(disc)
        t1, t2 = (-b - r) / (2 * a), (-b + r) / (2 * a)
    t = np.where(t1 >= 1, t1, np.where(t2 >= 1, t2, np.nan))
    t[disc < 0] = np.nan
    P = S + t[..., None] * D
    n_obj = P * w3
    n = n_obj @ m  # (m^T n_obj) per pixel
    l = -np.asarray(light_forward, float)
    cos = (n @ l) / (np.linalg.norm(n, axis=-1) * np.linalg.norm(l))
    return t * np.linalg.norm(d, axis=-1), cos


CASES = {
    "sphere": (1, (0.3, -0.2, -4.0), (1.0, 1.0, 1.0), (1.0, 0.0, 0.0, 0.0)),
    "ellipsoid": (1, (0.0, 0.5, -5.0), (1.0, 2.0, 0.5), (0.9, 0.3, -0.2, 0.25)),
    "nonunit-quaternion": (1, (0.0, 0.0, -5.0), (0.25, 0.25, 0.25), (2.0, 0.0, 0.0, 0.0)),
    "cylinder-along-y": (2, (0.5, 0.0, -6.0), (2.0, 2.0, 1.0), (0.70703125, 0.70703125, 0.0, 0.0)),
    "cone-tilted": (3, (-0.5, 0.0, -6.0), (1.0, 1.0, 1.0), (0.9, 0.0, 0.4, 0.1)),
}


@pytest.mark.parametrize("name", list(CASES))
def test_shape_matches_independent_reference_in_fp64(name):
    kind, loc, scale, q = CASES[name]
    forward = (-1.0, -1.0, -1.0)
    prog = Prog().nr().cam(hfov=FOV, vfov=FOV).sphere(0, loc=loc, scale=scale, rot=q, col=0xFFFF, kind=kind)
    prog.dir_light(0, forward=forward).nf()
    res = run_program(prog.words, EmuOptions(width=W, height=H, precision="fp64"))
    frame = res.frames[0]
    dist, cos = _reference(kind, loc, scale, q, forward)
    hit_ref = np.isfinite(dist)
    hit = frame.provenance == 0
    assert hit.sum() > 50
    assert (hit != hit_ref).sum() <= 2  # only rays grazing the silhouette may differ
    both = hit & hit_ref
    assert np.allclose(frame.depth[both], dist[both], rtol=1e-5)
    lit = both & (cos > 0.01)
    red = (frame.rgb565 >> 11).astype(int)
    shadowless = np.floor(31 * np.clip(cos, 0, None) + 0.5)
    # a cylinder or cone can shadow itself (non-convex views): compare where the pixel is lit
    ok = (red[lit] == shadowless[lit]) | (red[lit] == 0)
    assert ok.all()
    assert (red[lit] == shadowless[lit]).mean() > 0.8


def test_fp16_pipeline_order_is_one_implementation():
    """fp16, fp32 and fp64 run the same code: fp16 results lie close to fp64 ones."""
    kind, loc, scale, q = CASES["ellipsoid"]
    prog = Prog().nr().cam(hfov=FOV, vfov=FOV).sphere(0, loc=loc, scale=scale, rot=q).nf()
    f16 = run_program(prog.words, EmuOptions(width=W, height=H)).frames[0]
    f64 = run_program(prog.words, EmuOptions(width=W, height=H, precision="fp64")).frames[0]
    both = (f16.provenance == 0) & (f64.provenance == 0)
    assert both.sum() > 50
    assert np.percentile(np.abs(f16.depth[both] - f64.depth[both]), 90) < 0.05
