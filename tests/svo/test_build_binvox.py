"""``svo build`` from a binvox grid: hostile files name the byte at fault, decoding runs
in bounded batches, and the peak stays within the estimate."""

import subprocess
import sys

import numpy as np
import pytest
from click.testing import CliRunner
from hypothesis import given
from hypothesis import strategies as st

from rend3r.cli import main
from rend3r.errors import Rend3rError
from rend3r.svo import binvox
from rend3r.svo.binvox import decode_binvox, decode_binvox_codes, encode_binvox, encode_binvox_codes
from rend3r.svo.budget import BASE, SURFACE_BYTES, estimate_voxels
from rend3r.svo.mesh_io import encode_mesh, read_mesh
from rend3r.svo.models import make_model
from rend3r.svo.octree import morton_decode, morton_encode
from rend3r.svo.voxelize import fit_bounds, voxelize_codes

from .conftest import random_voxels
from .test_budget import _PEAK
from .test_fuzz import FUZZ


def _file(dim: str, body: bytes) -> bytes:
    return f"#binvox 1\ndim {dim}\ntranslate 0 0 0\nscale 1\ndata\n".encode() + body


def _full(dim: int, on: int) -> bytes:
    """A grid whose first ``on`` voxels (binvox order) are solid, in runs of 255."""
    body = bytearray()
    for value, count in ((1, on), (0, dim ** 3 - on)):
        q, r = divmod(count, 255)
        body += bytes([value, 255]) * q + (bytes([value, r]) if r else b"")
    return _file(f"{dim} {dim} {dim}", bytes(body))


HEADER = len(_file("4 4 4", b""))  # 49: the first run's byte


@pytest.mark.parametrize("data, message", [
    (_file("99999999 99999999 99999999", bytes([1, 255])), "byte 10: malformed binvox header line: needs a cubic "
                                                           "'dim' of 1..65536"),
    (_file("9" * 5000 + " 1 1", bytes([1, 1])), "byte 10: malformed binvox header line"),
    (_file("4 4", bytes([1, 16])), "byte 10: malformed binvox header line"),
    (_file("4 4 x", bytes([1, 64])), "byte 10: malformed binvox header line"),
    (_file("4 4 4", bytes([0, 60, 1, 10, 0, 255])), f"byte {HEADER + 2}: binvox runs overflow the 4^3 grid"),
    (_file("4 4 4", bytes([0, 60])), f"byte {HEADER + 2}: truncated binvox data (runs end at voxel 60 of 64)"),
    (_file("4 4 4", bytes([0, 60, 1])), f"byte {HEADER + 2}: truncated binvox data (a run value without"),
    (_file("4 4 4", b""), f"byte {HEADER}: truncated binvox data"),
    (_file("4 4 4", bytes([0, 64])), "the binvox grid holds no solid voxel"),
    (b"#binvox 1\ndim 4 4 4\nscale x\ndata\n\x01\x40", "byte 20: malformed binvox header line: could not convert"),
    (b"#binvox 1\ndim 4 4 4\nscale 1e999\ndata\n\x01\x40", "binvox translate and scale must be finite"),
])
def test_hostile_binvox_is_an_error_naming_the_file_and_byte(tmp_path, data, message):
    path = tmp_path / "h.binvox"
    path.write_bytes(data)
    r = CliRunner().invoke(main, ["svo", "build", str(path), "-o", str(tmp_path / "o.svo"), "-q"])
    assert r.exit_code == 1 and f"error: {path}: {message}" in r.output, r.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["h.binvox"]


def test_overflow_far_into_the_file_names_its_run(tmp_path):
    """The run at fault is found across blocks of runs (a grid of 32^3 in runs of one voxel)."""
    data = _file("32 32 32", bytes([1, 1, 0, 1]) * (32 ** 3 // 2) + bytes([1, 1]))
    first = len(_file("32 32 32", b""))
    with pytest.raises(Rend3rError, match=rf"^<binvox>: byte {first + 2 * 32 ** 3}: binvox runs overflow"):
        decode_binvox_codes(data)


def test_batches_and_blocks_decode_the_same_codes(monkeypatch):
    """Block and batch boundaries inside runs of every length change nothing."""
    coords = np.concatenate([random_voxels(5, 3000, 4), np.stack(np.mgrid[:32, :2, :32], -1).reshape(-1, 3)])
    data = encode_binvox(coords, 32, (1, 2, 3), 4)
    want = np.unique(morton_encode(coords, 5))
    codes, dim, translate, scale = decode_binvox_codes(data)
    assert np.array_equal(codes, want) and dim == 32 and translate.tolist() == [1, 2, 3] and scale == 4
    monkeypatch.setattr(binvox, "_RUN_BLOCK", 3)
    monkeypatch.setattr(binvox, "_VOXEL_BATCH", 7)
    assert np.array_equal(decode_binvox_codes(data)[0], want)


def test_budget_sees_the_exact_count_before_decoding():
    seen = []

    def refuse(voxels):
        seen.append(voxels)
        raise Rend3rError("refused")

    with pytest.raises(Rend3rError, match="refused"):
        decode_binvox_codes(_full(64, 1000), budget=refuse)
    assert seen == [1000]


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads the peak from /proc")
def test_peak_of_a_full_grid_stays_within_the_estimate(tmp_path):
    """2 M solid voxels in 256 bytes of runs: the decoder held 78 bytes a voxel (all runs
    expanded at once), about 195 MiB here; the estimate, 157 MiB, now bounds the peak."""
    dim = 128
    (tmp_path / "f.binvox").write_bytes(_full(dim, dim ** 3))
    out = subprocess.run([sys.executable, "-c", _PEAK, "svo", "build", str(tmp_path / "f.binvox"), "-o",
                          str(tmp_path / "f.svo"), "-q"], check=True, capture_output=True, text=True).stdout
    peak = int(out.split()[-1]) << 10
    assert peak <= BASE + SURFACE_BYTES * dim ** 3, peak >> 20


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads the peak from /proc")
def test_binvox_output_stays_within_the_estimate(tmp_path):
    """Writing ``--binvox`` decoded every code to coordinates at once (about 100 bytes a
    voxel, 776 MiB against 212 MiB without it for folded at depth 10); it now stays
    within the build's estimate, and the file is the one the coordinate encoder writes."""
    verts, faces = make_model("folded")
    mesh = tmp_path / "f.ply"
    mesh.write_bytes(encode_mesh(mesh, verts, faces))
    out = subprocess.run([sys.executable, "-c", _PEAK, "svo", "build", str(mesh), "-o", str(tmp_path / "f.svo"),
                          "--depth", "9", "--binvox", str(tmp_path / "f.binvox"), "-q"],
                         check=True, capture_output=True, text=True).stdout
    peak = int(out.split()[-1]) << 10
    lo, h = fit_bounds(verts, 9)
    surface, _ = estimate_voxels((verts[faces] - lo) / h, 512, False)
    assert peak <= BASE + SURFACE_BYTES * surface, peak >> 20
    codes, lo, h = voxelize_codes(*read_mesh(mesh), 9)
    assert (tmp_path / "f.binvox").read_bytes() == encode_binvox(morton_decode(codes, 9), 512, tuple(lo), h * 512)


def test_code_and_coordinate_encoders_agree_across_batches(monkeypatch):
    """Runs cut by batch boundaries, a full grid (one run) and an empty one."""
    full = np.stack(np.mgrid[:8, :8, :8], -1).reshape(-1, 3)
    for coords, depth in [(random_voxels(5, 3000, 9), 5), (full, 3), (full[:0], 3)]:
        want = encode_binvox(coords, 1 << depth, (1, 2, 3), 4)
        codes = np.sort(morton_encode(coords, depth))
        for batch in (1, 5, 1 << 19):
            monkeypatch.setattr(binvox, "_VOXEL_BATCH", batch)
            assert encode_binvox_codes(codes, depth, (1, 2, 3), 4) == want
            assert decode_binvox(want)[0].tolist() == morton_decode(codes, depth).tolist()


_SEED = encode_binvox(random_voxels(4, 500, 2), 16)


@FUZZ
@given(st.lists(st.tuples(st.integers(0, len(_SEED) - 1), st.integers(0, 255)), max_size=6),
       st.integers(0, len(_SEED)))
def test_mutated_binvox_decodes_or_is_refused(pokes, keep):
    """Poked and truncated files: valid codes of the grid, or a Rend3rError naming the file."""
    data = bytearray(_SEED)
    for pos, value in pokes:
        data[pos] = value
    try:
        codes, dim, _, _ = decode_binvox_codes(bytes(data[:keep]), "m.binvox")
    except Rend3rError as exc:
        assert str(exc).startswith("m.binvox: ")
        return
    depth = max((dim - 1).bit_length(), 1)
    assert np.all(codes[1:] > codes[:-1]) and (len(codes) == 0 or 0 <= codes[0] <= codes[-1] < 8 ** depth)
    assert np.all(morton_decode(codes, depth) < dim)
