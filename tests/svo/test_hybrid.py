import numpy as np
import pytest

from rend3r.emu.image import rgb565_to_rgb888
from rend3r.svo.camera import Camera, orbit_camera
from rend3r.svo.fileformat import SvoModel
from rend3r.svo.hybrid import distance_to_ndc_z, merge, ndc_z_to_distance, program_hybrid, rgb888_to_565
from rend3r.svo.octree import build_octree
from rend3r.svo.render import render

from .conftest import random_voxels


def test_merge_occlusion_both_ways():
    svo_c = np.full((2, 3), 0xF800, np.uint16)
    frm_c = np.full((2, 3), 0x001F, np.uint16)
    svo_d = np.array([[1.0, 5.0, np.inf], [2.0, 2.0, np.inf]], np.float32)
    frm_d = np.array([[3.0, 4.0, 7.0], [np.inf, 2.0, np.inf]], np.float32)
    c, d = merge(svo_c, svo_d, frm_c, frm_d)
    assert c.tolist() == [[0xF800, 0x001F, 0x001F], [0xF800, 0x001F, 0x001F]]
    assert d.tolist() == [[1.0, 4.0, 7.0], [2.0, 2.0, np.inf]]
    with pytest.raises(ValueError):
        merge(svo_c, np.full((2, 3), np.nan, np.float32), frm_c, frm_d)


def test_depth_conversions_round_trip_and_match_the_tracer():
    coords = random_voxels(4, 300, 1)
    model = SvoModel(build_octree(coords, 4), (-1.0, -1.0, -1.0, 1.0, 1.0, 1.0), len(coords))
    cam = orbit_camera(model.bounds, width=40, height=30)
    r = render(model, cam, 4)
    hit = np.isfinite(r.distance)
    assert hit.sum() > 50
    d = ndc_z_to_distance(r.ndc_z.astype(np.float64), cam)
    assert np.allclose(d[hit], r.distance[hit], rtol=1e-5)
    z = distance_to_ndc_z(r.distance.astype(np.float64), cam)
    assert np.allclose(z[hit], r.ndc_z[hit], atol=1e-5)
    assert np.isinf(d[~hit]).all() and np.isinf(z[~hit]).all()


def test_depth_conversion_is_monotonic():
    cam = Camera((0, 0, 0), (0, 0, -1), near=0.5, far=50, width=8, height=6)
    dist = np.broadcast_to(np.linspace(1, 40, 6)[:, None], (6, 8)).copy()
    z = distance_to_ndc_z(dist, cam)
    assert np.all(np.diff(z, axis=0) > 0) and z.min() > -1 and z.max() < 1


def test_rgb565_conversions():
    c = np.arange(0, 65536, 97, dtype=np.uint16).reshape(1, -1)
    assert np.array_equal(rgb888_to_565(rgb565_to_rgb888(c)), c)


def test_program_hybrid_occludes_both_ways():
    """An SVO cube straddling the unit sphere of programs/sphere.asm (centre z = -3)."""
    coords = np.stack(np.meshgrid(*[np.arange(4)] * 3, indexing="ij"), -1).reshape(-1, 3)
    model = SvoModel(build_octree(coords, 2), (-1.0, -1.0, -1.0, 1.0, 1.0, 1.0), len(coords))
    place = np.diag([0.6, 0.6, 0.6, 1.0])
    place[:3, 3] = (0.7, 0.0, -3.0)  # overlaps the sphere's right half
    (rgb, dist), = program_hybrid(model, "programs/sphere.asm", place, 64, 48)
    from rend3r.emu import EmuOptions, run_program
    from rend3r.emu.loader import load_program
    frame = run_program(load_program("programs/sphere.asm").words, EmuOptions(width=64, height=48)).frames[0]
    sphere_px = np.isfinite(frame.depth)
    cube_px = np.isfinite(dist) & (dist < frame.depth)
    both = sphere_px & np.isfinite(dist)
    # where both cover a pixel, each wins somewhere: the cube in front near its face at
    # z = -2.4 (sphere surface further away off-centre), the sphere in front at its centre
    assert cube_px.any() and (both & ~cube_px).any()
    assert np.array_equal(dist, np.minimum(dist, frame.depth))
    assert np.all(rgb[~np.isfinite(dist)] == frame.rgb565[~np.isfinite(dist)])
