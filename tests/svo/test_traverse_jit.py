"""The compiled (numba) traversal is bit-identical to the numpy traversal on every output."""

import importlib.util
import subprocess
import sys

import numpy as np
import pytest
from click.testing import CliRunner
from hypothesis import given, settings
from hypothesis import strategies as st
from PIL import Image

from rend3r.cli import main
from rend3r.svo.camera import orbit_camera
from rend3r.svo.fileformat import SvoModel, write_svo
from rend3r.svo.octree import build_octree, octree_to_voxels
from rend3r.svo.render import render
from rend3r.svo.traverse import resolve_kernel, trace

from .conftest import random_voxels

needs_numba = pytest.mark.skipif(
    importlib.util.find_spec("numba") is None,
    reason="numba is not installed (pip install 'rend3r[fast]'): the compiled kernel is not tested")

FIELDS = ("hit", "t", "axis", "voxel", "requests", "steps", "descents", "pops", "restarts",
          "max_level", "max_stack", "trace_ray", "trace_addr", "trace_level")


def assert_identical(tree, o, d, stack):
    """Both kernels on the same rays: every output equal, bit for bit and dtype for dtype."""
    a = trace(tree, o, d, stack, True, record=True, kernel="numpy")
    b = trace(tree, o, d, stack, True, record=True, kernel="numba")
    for name in FIELDS:
        x, y = getattr(a, name), getattr(b, name)
        assert x.dtype == y.dtype and x.shape == y.shape, name
        assert np.array_equal(x, y), name
    return a


def _rays(n, seed, spread=3.0):
    rng = np.random.default_rng(seed)
    return rng.uniform(-spread, spread, (n, 3)), rng.normal(size=(n, 3))


def _models():
    """(name, tree): dense and sparse random trees, a deep sparse tree, a full grid, a single
    voxel, and far-pointer trees (4-bit pointers)."""
    return {
        "random5": build_octree(random_voxels(5, 600, 7), 5),
        "dense3": build_octree(random_voxels(3, 300, 2), 3),
        "full2": build_octree(np.argwhere(np.ones((4, 4, 4))), 2),
        "single4": build_octree(np.array([[5, 9, 2]]), 4),
        "deep9": build_octree(random_voxels(9, 200, 5), 9),
        "far5": build_octree(random_voxels(5, 900, 21), 5, ptr_bits=4),
        "far7": build_octree(random_voxels(7, 3000, 9), 7, ptr_bits=4),
    }


@pytest.fixture(scope="module")
def models():
    trees = _models()
    assert trees["far5"].far_count() > 0 and trees["far7"].far_count() > 0
    return trees


@needs_numba
@pytest.mark.parametrize("stack", range(9))
def test_identical_on_random_rays_every_model(models, stack):
    o, d = _rays(400, 100 + stack)
    for name, tree in models.items():
        assert_identical(tree, o, d, stack)
        # and rays aimed at voxel centres, so sparse trees are hit too
        coords = octree_to_voxels(tree)[:150]
        centre = -1 + (coords + 0.5) * 2 / (1 << tree.depth)
        start = o[:len(centre)]
        res = assert_identical(tree, start, centre - start, stack)
        assert res.hit.all(), name
    # the cases are not trivial: far slots are read, and small stacks restart
    far = assert_identical(models["far7"], o, d, stack)
    near = trace(build_octree(random_voxels(7, 3000, 9), 7), o, d, stack, True, kernel="numpy")
    assert far.requests.sum() > near.requests.sum()
    if stack < 3:
        assert far.restarts.sum() > 0


@needs_numba
@pytest.mark.parametrize("stack", [0, 1, 2, 8])
def test_identical_through_edges_and_corners(stack):
    """Dyadic origins on grid lines, directions along edges, face diagonals and corners."""
    depth = 3
    tree = build_octree(random_voxels(depth, 120, 4), depth)
    grid = np.arange(-1, 1.001, 0.25)
    dirs = [(0, 0, -1), (1, 1, 1), (1, 1, 0.5), (-1, 0.5, 0.25), (1, -1, -1), (0, 1, -1),
            (-1, -1, -1), (0.5, 0, -1)]
    starts = [(a, b, 2.0) for a in grid for b in grid for _ in dirs]
    o = np.array(starts)
    d = np.array(dirs * (len(grid) ** 2), dtype=float)
    res = assert_identical(tree, o, d, stack)
    assert res.hit.sum() > 50
    # rays starting exactly on voxel corners inside the root, in every octant direction
    corners = np.array([(x, y, z) for x in grid for y in grid for z in grid])
    for dvec in [(1, 1, 1), (-1, 1, -1), (1, -1, 0), (0, 0, 1)]:
        assert_identical(tree, corners, np.broadcast_to(np.array(dvec, float), corners.shape), stack)


@needs_numba
@pytest.mark.parametrize("stack", [0, 4])
def test_identical_from_inside_the_root(models, stack):
    rng = np.random.default_rng(3)
    o = rng.uniform(-0.99, 0.99, (1000, 3))
    d = rng.normal(size=(1000, 3))
    for tree in models.values():
        assert_identical(tree, o, d, stack)


@needs_numba
def test_identical_on_parallel_rays(models):
    """Axis-parallel rays (components clamped to 2^-10), on and off voxel planes."""
    vals = np.linspace(-1, 1, 17)
    o, d = [], []
    for a in vals:
        for b in vals:
            for axis in range(3):
                for sign in (1.0, -1.0):
                    p = [a, b]
                    p.insert(axis, -2.0 * sign)
                    v = [0.0, 0.0]
                    v.insert(axis, sign)
                    o.append(p)
                    d.append(v)
    o, d = np.array(o), np.array(d)
    for stack in (0, 3, 8):
        for tree in models.values():
            assert_identical(tree, o, d, stack)


@needs_numba
@settings(max_examples=40)
@given(seed=st.integers(0, 2**32 - 1), stack=st.integers(0, 8), depth=st.integers(1, 6),
       ptr_bits=st.sampled_from([4, 15]), dyadic=st.booleans())
def test_identical_property(seed, stack, depth, ptr_bits, dyadic):
    rng = np.random.default_rng(seed)
    n = 1 << depth
    coords = np.unique(rng.integers(0, n, (int(rng.integers(1, 4 * n * n)), 3)), axis=0)
    tree = build_octree(coords, depth, ptr_bits)
    o = rng.uniform(-2.5, 2.5, (200, 3))
    d = rng.normal(size=(200, 3))
    if dyadic:  # grid-aligned starts and directions: ties at voxel edges and corners
        o = np.round(o * n / 2) * 2 / n
        d = np.round(d * 2) / 2
        d[np.all(d == 0, axis=1)] = (1.0, 0.0, 0.0)
    assert_identical(tree, o, d, stack)


@needs_numba
def test_render_and_cli_identical(tmp_path):
    tree = build_octree(random_voxels(5, 600, 7), 5)
    model = SvoModel(tree, (-1.0, -1.0, -1.0, 1.0, 1.0, 1.0), 600)
    cam = orbit_camera(model.bounds, 20, 30, 1.6, 40, 30)
    a = render(model, cam, 2, True, "shaded", kernel="numpy")
    b = render(model, cam, 2, True, "shaded", kernel="numba")
    assert np.array_equal(a.rgb, b.rgb) and np.array_equal(a.cost, b.cost)
    assert a.result.hit.any()
    path = str(tmp_path / "m.svo")
    write_svo(path, model)
    images = []
    for kernel in ("numpy", "numba", "auto"):
        out = str(tmp_path / f"{kernel}.png")
        r = CliRunner().invoke(main, ["svo", "render", path, "-o", out, "--size", "40x30",
                                      "--kernel", kernel], catch_exceptions=False)
        assert r.exit_code == 0, r.output
        images.append(np.asarray(Image.open(out)))
    assert np.array_equal(images[0], images[1]) and np.array_equal(images[0], images[2])
    r = CliRunner().invoke(main, ["svo", "render", path, "-o", str(tmp_path / "f.png"), "--float",
                                  "--kernel", "numba"])
    assert r.exit_code == 1 and "float64 reference runs on numpy" in r.output


def test_auto_falls_back_to_numpy_without_numba(monkeypatch, tmp_path):
    """With numba unimportable, auto runs numpy with one note; numba is refused clearly."""
    monkeypatch.setitem(sys.modules, "numba", None)
    monkeypatch.delitem(sys.modules, "rend3r.svo.traverse_jit", raising=False)
    kernel, note = resolve_kernel("auto")
    assert kernel == "numpy" and "pip install 'rend3r[fast]'" in note
    with pytest.raises(ValueError, match="numba kernel unavailable"):
        resolve_kernel("numba")
    tree = build_octree(random_voxels(4, 100, 1), 4)
    o, d = _rays(200, 4)
    assert np.array_equal(trace(tree, o, d, kernel="auto").voxel, trace(tree, o, d, kernel="numpy").voxel)
    path = str(tmp_path / "m.svo")
    write_svo(path, SvoModel(tree, (-1.0, -1.0, -1.0, 1.0, 1.0, 1.0), 100))
    runner = CliRunner()
    r = runner.invoke(main, ["svo", "render", path, "-o", str(tmp_path / "a.png"), "--size", "16x12"])
    assert r.exit_code == 0 and r.output.count("note: numba is not available") == 1
    r = runner.invoke(main, ["svo", "render", path, "-o", str(tmp_path / "b.png"), "--kernel", "numba"])
    assert r.exit_code == 1 and "rend3r: error: numba kernel unavailable" in r.output


def test_unknown_kernel_refused():
    with pytest.raises(ValueError, match="unknown traversal kernel"):
        resolve_kernel("cuda")


def test_help_does_not_import_numba():
    code = ("import sys\nfrom click.testing import CliRunner\nfrom rend3r.cli import main\n"
            "for args in (['--help'], ['svo', '--help'], ['svo', 'render', '--help']):\n"
            "    assert CliRunner().invoke(main, args).exit_code == 0\n"
            "print('numba' in sys.modules)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


@needs_numba
def test_shared_origin_and_refused_rays_like_numpy(models):
    """One origin broadcast over many directions; unusable rays are refused by both kernels."""
    tree = models["random5"]
    _, d = _rays(300, 9)
    o = np.array([[0.1, 2.5, -2.0]])
    for kernel in ("numpy", "numba"):
        assert trace(tree, o, d, 8, kernel=kernel).hit.any()
    a = trace(tree, o, d, 8, kernel="numpy")
    b = trace(tree, o, d, 8, kernel="numba")
    assert np.array_equal(a.t, b.t) and np.array_equal(a.voxel, b.voxel)
    for o_bad, d_bad, err in (([[0.0, 0, 0]], [[0.0, 0, 0]], ValueError),
                              ([[0.0, np.inf, 0]], [[1.0, 0, 0]], ValueError),
                              ([[0.0, 0, 0]], [[np.nan, 1, 0]], ValueError)):
        for kernel in ("numpy", "numba"):
            with pytest.raises(err):
                trace(tree, np.array(o_bad), np.array(d_bad), kernel=kernel)
