import numpy as np
import pytest

from rend3r.svo.camera import orbit_camera
from rend3r.svo.fileformat import SvoModel
from rend3r.svo.octree import build_octree
from rend3r.svo.render import render
from rend3r.svo.traverse import trace

from .conftest import brute_force, random_voxels


def _rays(n, seed, spread=3.0):
    rng = np.random.default_rng(seed)
    return rng.uniform(-spread, spread, (n, 3)), rng.normal(size=(n, 3))


@pytest.mark.parametrize("fixed", [True, False])
@pytest.mark.parametrize("stack", [0, 1, 3, 8])
def test_matches_brute_force(small_tree, fixed, stack):
    coords, tree = small_tree
    o, d = _rays(1500, 11)
    res = trace(tree, o, d, stack, fixed)
    t_ref, best = brute_force(coords, 5, o, d)
    assert np.array_equal(res.hit, np.isfinite(t_ref))
    assert np.allclose(res.t[res.hit], t_ref[res.hit], atol=1e-4)
    # the hit voxel agrees wherever the nearest two voxel boxes are not within fixed-point noise
    assert np.mean(np.all(res.voxel[res.hit] == coords[best[res.hit]], axis=1)) > 0.99


def test_fixed_and_float_agree_on_hit_voxel_away_from_edges(small_tree):
    coords, tree = small_tree
    o, d = _rays(4000, 12)
    fx = trace(tree, o, d, 8, True)
    fl = trace(tree, o, d, 8, False)
    n = 1 << 5
    # keep rays whose float hit point is at least 1/64 voxel from every voxel face (except
    # the entered one): there the 16.16 rounding cannot change the voxel
    p = o + fl.t[:, None] * d
    g = (p[fl.hit] + 1) * n / 2
    frac = np.abs(g - np.round(g))
    axis = fl.axis[fl.hit]
    frac[np.arange(len(axis)), axis] = 1.0
    clear = frac.min(1) > 1 / 64
    assert clear.sum() > 100
    assert np.array_equal(fx.hit, fl.hit)
    assert np.array_equal(fx.voxel[fl.hit][clear], fl.voxel[fl.hit][clear])
    assert np.array_equal(fx.axis[fl.hit][clear], fl.axis[fl.hit][clear])


def test_rays_through_edges_and_corners():
    """Rays along voxel edges and through voxel corners (dyadic origins on grid lines).

    A ray that only grazes a voxel along an edge or at a corner meets a zero-length
    child; the traversal visits it (the tie rule steps x before y before z), so such a
    graze counts as a hit. Neither arithmetic may skip a voxel the ray really crosses,
    every hit must lie on the closed box of the voxel it names, and the stack depth must
    not change the answer.
    """
    depth = 3
    coords = random_voxels(depth, 120, 4)
    tree = build_octree(coords, depth)
    grid = np.arange(-1, 1.001, 0.25)
    starts, dirs = [], []
    for a in grid:
        for b in grid:
            for d in [(0, 0, -1), (1, 1, 1), (1, 1, 0.5), (-1, 0.5, 0.25), (1, -1, -1), (0, 1, -1)]:
                starts.append((a, b, 2.0))
                dirs.append(d)
    o, d = np.array(starts), np.array(dirs, dtype=float)
    t_ref, _ = brute_force(coords, depth, o, d)
    size = 2 / (1 << depth)
    for fixed in (True, False):
        res = trace(tree, o, d, 8, fixed)
        assert res.hit.sum() > 50
        assert np.all(res.t <= t_ref + 1e-4)
        p = o + np.where(res.hit, res.t, 0)[:, None] * d
        lo = -1 + size * res.voxel
        on_box = np.all((p >= lo - 1e-4) & (p <= lo + size + 1e-4), axis=1)
        assert on_box[res.hit].all()
        for s in (0, 2):
            again = trace(tree, o, d, s, fixed)
            assert np.array_equal(again.voxel, res.voxel) and np.array_equal(again.t, res.t)


def test_rays_from_inside_the_root(small_tree):
    coords, tree = small_tree
    rng = np.random.default_rng(3)
    o = rng.uniform(-0.9, 0.9, (1000, 3))
    d = rng.normal(size=(1000, 3))
    res = trace(tree, o, d, 4, True)
    t_ref, _ = brute_force(coords, 5, o, d)
    assert np.array_equal(res.hit, np.isfinite(t_ref))
    assert np.allclose(res.t[res.hit], t_ref[res.hit], atol=1e-4)
    # a ray starting inside a solid voxel hits it at t = 0
    inside = (coords[0] + 0.5) * 2 / 32 - 1
    one = trace(tree, inside[None], np.array([[0.3, -0.2, 1.0]]), 8, True)
    assert one.hit[0] and one.t[0] == 0 and one.voxel[0].tolist() == coords[0].tolist()


def test_parallel_rays():
    """Direction components of 0 are clamped to 2^-10 and the traversal still terminates."""
    depth = 4
    coords = np.array([[x, 5, 9] for x in range(16)] + [[3, y, 2] for y in range(16)])
    tree = build_octree(coords, depth)
    o = np.array([[-2.0, -1 + 2 * 5.5 / 16, -1 + 2 * 9.5 / 16],   # along +x through row y=5, z=9
                  [-1 + 2 * 3.5 / 16, 2.0, -1 + 2 * 2.5 / 16],    # along -y through column x=3
                  [0.0, 0.0, -2.0]])                               # along +z through an empty line
    d = np.array([[1.0, 0, 0], [0, -1.0, 0], [0, 0, 1.0]])
    for fixed in (True, False):
        res = trace(tree, o, d, 0, fixed)
        assert res.hit.tolist() == [True, True, False]
        assert res.voxel[0].tolist() == [0, 5, 9] and res.voxel[1].tolist() == [3, 15, 2]
        assert res.t[0] == pytest.approx(1.0, abs=1e-4) and res.t[1] == pytest.approx(1.0, abs=1e-4)


def test_stack_depths_give_identical_images(small_tree):
    coords, tree = small_tree
    model = SvoModel(tree, (-1.0, -1.0, -1.0, 1.0, 1.0, 1.0), len(coords))
    cam = orbit_camera(model.bounds, 20, 30, 1.6, 48, 36)
    images = [render(model, cam, s, True, "shaded") for s in range(0, 7)]
    base = images[0]
    for im in images[1:]:
        assert np.array_equal(im.rgb, base.rgb)
        assert np.array_equal(im.result.t, base.result.t)
    # the stack only changes the cost: restarts vanish once the stack covers the depth
    assert base.result.restarts.sum() > 0 and images[-1].result.restarts.sum() == 0
    assert images[-1].cost.sum() < base.cost.sum()


def test_recorded_requests_match_counts(small_tree):
    coords, tree = small_tree
    o, d = _rays(300, 5)
    res = trace(tree, o, d, 2, True, record=True)
    assert np.array_equal(np.bincount(res.trace_ray, minlength=300), res.requests)
    assert np.all(np.diff(res.trace_ray) >= 0)
    first = np.r_[True, res.trace_ray[1:] != res.trace_ray[:-1]]
    assert np.all(res.trace_addr[first] == 0) and np.all(res.trace_level[first] == 0)
    assert res.trace_addr.max() < len(tree.words)


def test_far_pointers_trace_like_near_pointers():
    coords = random_voxels(5, 900, 21)
    near = build_octree(coords, 5)
    far = build_octree(coords, 5, ptr_bits=4)
    assert far.far_count() > 0
    o, d = _rays(800, 8)
    a = trace(near, o, d, 2, True, record=True)
    b = trace(far, o, d, 2, True, record=True)
    assert np.array_equal(a.voxel, b.voxel) and np.array_equal(a.t, b.t)
    assert np.array_equal(a.steps, b.steps)
    # each descent into a far node costs one extra request (the far slot)
    assert b.requests.sum() > a.requests.sum()
    assert np.all(b.requests - a.requests >= 0)


def test_bad_rays_are_refused(small_tree):
    _, tree = small_tree
    with pytest.raises(ValueError):
        trace(tree, np.array([[0.0, 0, 0]]), np.array([[0.0, 0, 0]]))
    with pytest.raises(ValueError):
        trace(tree, np.array([[np.nan, 0, 0]]), np.array([[1.0, 0, 0]]))
