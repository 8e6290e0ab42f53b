"""``svo build --solid``: the fill is made slab by slab into the codes buffer, so its
memory is the codes' 8 bytes a voxel plus one slab, and the estimate bounds the peak."""

import subprocess
import sys

import numpy as np
import pytest
from click.testing import CliRunner

from rend3r.cli import main
from rend3r.errors import Rend3rError
from rend3r.svo import voxelize as vox
from rend3r.svo.budget import BASE, FILL_BYTES, SURFACE_BYTES, estimate_voxels
from rend3r.svo.models import make_model
from rend3r.svo.voxelize import fit_bounds, voxelize_codes

from .test_budget import _PEAK


@pytest.mark.parametrize("name, depth, chunk", [("torus", 6, 1000), ("folded", 5, 1 << 19), ("sphere", 5, 1 << 19)])
def test_slabs_and_batches_make_the_same_fill(name, depth, chunk, monkeypatch):
    """One column of x a slab (and batches of ``chunk`` voxels) against one slab."""
    verts, faces = make_model(name)
    monkeypatch.setattr(vox, "_SLAB", 1 << 40)
    whole, _, _ = voxelize_codes(verts, faces, depth, True)
    monkeypatch.setattr(vox, "_SLAB", 1)
    monkeypatch.setattr(vox, "_CHUNK", chunk)
    assert np.array_equal(voxelize_codes(verts, faces, depth, True)[0], whole)


def _cube(lo: float, inward: bool) -> tuple[np.ndarray, np.ndarray]:
    v = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], float) + lo
    f = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                  [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
    return v, f[:, ::-1] if inward else f


def test_a_fill_the_estimate_misses_is_refused_within_the_budget():
    """Two cubes facing opposite ways: their signed volumes cancel (an estimate of no fill),
    yet each fills; the fill stops when its codes pass what the budget holds."""
    (va, fa), (vb, fb) = _cube(0, False), _cube(2, True)
    verts, faces = np.concatenate([va, vb]), np.concatenate([fa, fb + 8])
    depth = 7
    lo, h = fit_bounds(verts, depth)
    surface, fill = estimate_voxels((verts[faces] - lo) / h, 1 << depth, True)
    codes, _, _ = voxelize_codes(verts, faces, depth, True)
    assert fill < 0.01 * len(codes)  # the estimate sees (almost) no fill
    budget = BASE + SURFACE_BYTES * surface + FILL_BYTES * len(codes) // 2
    with pytest.raises(Rend3rError, match="the solid fill holds more than"):
        voxelize_codes(verts, faces, depth, True, budget)
    assert np.array_equal(voxelize_codes(verts, faces, depth, True, budget + FILL_BYTES * len(codes))[0], codes)


def test_depth_12_solid_is_refused_up_front_with_its_estimate(tmp_path):
    mesh = tmp_path / "t.obj"
    CliRunner().invoke(main, ["svo", "model", "torus", "-o", str(mesh), "-q"])
    r = CliRunner().invoke(main, ["svo", "build", str(mesh), "-o", str(tmp_path / "t.svo"), "--depth", "12",
                                  "--solid", "--max-memory", "2G"])
    assert r.exit_code == 1 and "depth 12 solid: about 8,3" in r.output and "GiB at peak, over the memory " \
        "budget of 2.0 GiB" in r.output, r.output
    assert not (tmp_path / "t.svo").exists()


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads the peak from /proc")
def test_depth_8_solid_peak_within_the_estimate(tmp_path):
    """The fill's coordinates were made at once (229 MiB measured here before); the peak
    is now 127 MiB against an estimate of 153 MiB."""
    mesh = tmp_path / "t.obj"
    subprocess.run([sys.executable, "-m", "rend3r", "svo", "model", "torus", "-o", str(mesh), "-q"], check=True)
    out = subprocess.run([sys.executable, "-c", _PEAK, "svo", "build", str(mesh), "-o", str(tmp_path / "t.svo"),
                          "--depth", "8", "--solid", "-q"], check=True, capture_output=True, text=True).stdout
    peak = int(out.split()[-1]) << 10
    verts, faces = make_model("torus")
    lo, h = fit_bounds(verts, 8)
    surface, fill = estimate_voxels((verts[faces] - lo) / h, 256, True)
    assert peak <= BASE + SURFACE_BYTES * surface + FILL_BYTES * fill, peak >> 20
