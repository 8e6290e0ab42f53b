"""Issue 13 regressions through the real command: corrupt octrees, hostile meshes, extreme
camera values, memory budgets and all-or-nothing outputs.

Cases that could crash the interpreter (a kernel reading a corrupt tree) or whose
warnings must be seen as a terminal would see them run ``python -m rend3r`` in a child.
"""

from __future__ import annotations

import os
import struct
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from rend3r.cli import main
from rend3r.svo.fileformat import SvoModel, decode_svo, encode_svo
from rend3r.svo.octree import build_octree

from .conftest import random_voxels

HEADER = 72


def _run(*args):
    r = CliRunner().invoke(main, ["svo", *map(str, args)])
    assert r.exception is None or isinstance(r.exception, SystemExit), r.exc_info
    return r


def _child(*args, cwd=None):
    env = dict(os.environ, REND3R_JIT_CACHE="0")
    return subprocess.run([sys.executable, "-m", "rend3r", "svo", *map(str, args)], capture_output=True,
                          text=True, timeout=300, env=env, cwd=cwd)


@pytest.fixture(scope="module")
def sphere(tmp_path_factory):
    """The issue's reproduction: a sphere mesh with detail 6 and its depth-5 octree."""
    d = tmp_path_factory.mktemp("hostile")
    assert _run("model", "sphere", "--detail", "6", "-o", d / "s.obj").exit_code == 0
    assert _run("build", d / "s.obj", "-o", d / "s.svo", "--depth", "5").exit_code == 0
    return d


def _corrupt(src: Path, dst: Path, word: int, patch: bytes, at: int = 2) -> int:
    """Copy ``src`` with ``patch`` written into node word ``word`` at byte ``at``; the byte offset."""
    data = bytearray(src.read_bytes())
    offset = HEADER + 4 * word + at
    data[offset:offset + len(patch)] = patch
    dst.write_bytes(bytes(data))
    return HEADER + 4 * word


@pytest.mark.parametrize("kernel", [["--kernel", "numba"], ["--kernel", "numpy"], ["--float"]])
def test_corrupt_node_pointer_is_an_error_not_a_crash(sphere, tmp_path, kernel):
    offset = _corrupt(sphere / "s.svo", tmp_path / "bad.svo", 5, b"\xff\x7f")
    r = _child("render", tmp_path / "bad.svo", "-o", tmp_path / "x.png", "--stack", "0", "--size", "16x12", *kernel)
    assert r.returncode == 1, r.stderr
    assert f"bad.svo: byte {offset}: corrupt octree" in r.stderr and "Traceback" not in r.stderr
    assert not (tmp_path / "x.png").exists()


def test_every_pointer_of_a_file_is_checked(sphere, tmp_path):
    """Each node word's pointer field replaced in turn: refused (or, if harmless, an identical tree)."""
    good = (sphere / "s.svo").read_bytes()
    words = np.frombuffer(good, "<u4", offset=HEADER)
    inner = np.flatnonzero((words >> 16) != 0)
    assert len(inner) > 10
    for w in inner:
        for patch in (b"\xff\x7f", b"\x01\x00", b"\x00\x00"):
            data = bytearray(good)
            data[HEADER + 4 * w + 2:HEADER + 4 * w + 4] = patch
            if bytes(data) == good:
                continue
            with pytest.raises(Exception, match=rf"byte {HEADER}|byte \d+: corrupt octree") as info:
                decode_svo(bytes(data), "f.svo")
            assert type(info.value).__name__ == "Rend3rError"


def test_header_claiming_zero_words(sphere, tmp_path):
    data = bytearray((sphere / "s.svo").read_bytes()[:HEADER])
    struct.pack_into("<I", data, 12, 0)
    (tmp_path / "z.svo").write_bytes(bytes(data))
    r = _run("render", tmp_path / "z.svo", "-o", tmp_path / "x.png", "--size", "8x8")
    assert r.exit_code == 1 and "z.svo: byte 12: header claims 0 words" in r.output


def test_valid_trees_pass_and_far_pointers_are_checked():
    coords = random_voxels(5, 300, 3)
    tree = build_octree(coords, 5, ptr_bits=4)
    model = SvoModel(tree, (-1.0, -1.0, -1.0, 1.0, 1.0, 1.0), len(coords))
    data = encode_svo(model)
    assert np.array_equal(decode_svo(data).tree.words, tree.words)
    words = tree.words.astype(np.int64)
    far = np.flatnonzero((words >> 16) & 1)
    assert len(far)
    slot = far[0] + (words[far[0]] >> 17)
    bad = bytearray(data)
    struct.pack_into("<I", bad, HEADER + 4 * int(slot), 0xFFFFFF00)
    with pytest.raises(Exception, match=rf"byte {HEADER + 4 * far[0]}: corrupt octree.*child table lies outside"):
        decode_svo(bytes(bad), "f.svo")


@pytest.mark.parametrize(("name", "text"), [
    ("big.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 100000000000000000000\n"),
    ("zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n"),
    ("big.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                "0 0 0\n1 0 0\n0 1 0\n3 0 1 100000000000000000000\n"),
    ("count.ply", "ply\nformat ascii 1.0\nelement vertex 99999999999999999999\nproperty float x\nend_header\n"),
    ("nan.obj", "v 0 0 nan\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"),
    ("inf.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 inf\nvertex 1 0 0\nvertex 0 1 0\n"
                "endloop\nendfacet\nendsolid x\n"),
])
def test_hostile_meshes_are_clear_errors(tmp_path, name, text):
    (tmp_path / name).write_text(text)
    r = _run("build", tmp_path / name, "-o", tmp_path / "o.svo", "--depth", "3")
    assert r.exit_code == 1 and f"{name}:" in r.output, r.output
    assert not (tmp_path / "o.svo").exists()


def test_float_list_counts_in_binary_ply(tmp_path):
    header = ("ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
              "property float z\nelement face 1\nproperty list float float vertex_indices\nend_header\n")
    body = np.zeros(9, "<f4").tobytes() + np.array([np.inf, 0, 1, np.nan], "<f4").tobytes()
    (tmp_path / "f.ply").write_bytes(header.encode() + body)
    r = _child("build", tmp_path / "f.ply", "-o", tmp_path / "o.svo", "--depth", "3")
    assert r.returncode == 1 and "f.ply: list property 'vertex_indices' needs integer types" in r.stderr, r.stderr


def test_extreme_vertices_no_warning_and_a_clear_reason(tmp_path):
    (tmp_path / "h.obj").write_text("v 1e308 0 0\nv -1e308 0 0\nv 0 1e308 0\nf 1 2 3\n")
    r = _child("build", tmp_path / "h.obj", "-o", tmp_path / "o.svo", "--depth", "3")
    assert r.returncode == 1 and "Warning" not in r.stderr and "no area" not in r.stderr
    assert "h.obj: mesh coordinates must lie within" in r.stderr, r.stderr


@pytest.mark.parametrize(("option", "value"), [("--distance", "1e308"), ("--distance", "inf"),
                                               ("--azimuth", "inf"), ("--azimuth", "nan"),
                                               ("--elevation", "90")])
def test_extreme_camera_values_are_usage_errors(sphere, tmp_path, option, value):
    r = _child("render", sphere / "s.svo", "-o", tmp_path / "x.png", "--size", "8x8", option, value)
    assert r.returncode == 2 and "Warning" not in r.stderr and "is not in the range" in r.stderr, r.stderr


@pytest.mark.parametrize("place", ["0,0,-3,1e300", "0,0,nan,1", "1e9,0,0,1", "60000,0,0,1e-12"])
def test_extreme_placement_is_a_usage_error(sphere, tmp_path, place):
    r = _run("render", sphere / "s.svo", "-o", tmp_path / "x.png", "--size", "8x8",
             "--with-program", "programs/sphere.asm", "--place", place)
    assert r.exit_code == 2 and "--place" in r.output, r.output


def test_build_refuses_over_budget_up_front(sphere, tmp_path):
    r = _run("build", sphere / "s.obj", "-o", tmp_path / "o.svo", "--depth", "10", "--solid",
             "--max-memory", "300M")
    assert r.exit_code == 1 and "voxels need an estimated" in r.output and "--max-memory" in r.output, r.output
    assert not (tmp_path / "o.svo").exists()
    r = _run("build", sphere / "s.obj", "-o", tmp_path / "o.svo", "--depth", "3", "--max-memory", "lots")
    assert r.exit_code == 2 and "expected a size" in r.output


def test_default_budget_refuses_depth_16_solid(sphere, tmp_path):
    r = _run("build", sphere / "s.obj", "-o", tmp_path / "o.svo", "--depth", "16", "--solid")
    assert r.exit_code == 1 and "over the memory budget" in r.output, r.output


def test_build_binvox_to_a_directory_keeps_no_svo(sphere, tmp_path):
    (tmp_path / "dir.binvox").mkdir()
    r = _run("build", sphere / "s.obj", "-o", tmp_path / "o.svo", "--depth", "4", "--binvox", tmp_path / "dir.binvox")
    assert r.exit_code == 1 and f"cannot write {tmp_path / 'dir.binvox'}" in r.output, r.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["dir.binvox"]


def test_render_failing_cost_keeps_no_image_and_restores_the_old_one(sphere, tmp_path):
    (tmp_path / "c.png").mkdir()
    r = _run("render", sphere / "s.svo", "-o", tmp_path / "r.png", "--cost", tmp_path / "c.png", "--size", "8x8")
    assert r.exit_code == 1 and not (tmp_path / "r.png").exists()
    (tmp_path / "r.png").write_bytes(b"old")
    r = _run("render", sphere / "s.svo", "-o", tmp_path / "r.png", "--cost", tmp_path / "c.png", "--size", "8x8")
    assert r.exit_code == 1 and (tmp_path / "r.png").read_bytes() == b"old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["c.png", "r.png"]


@pytest.mark.skipif(os.geteuid() != 0, reason="mounting a small tmpfs needs root")
def test_render_cost_on_a_full_disk_keeps_nothing(sphere, tmp_path):
    disk = tmp_path / "disk"
    disk.mkdir()
    if subprocess.run(["mount", "-t", "tmpfs", "-o", "size=12k", "tmpfs", str(disk)],
                      capture_output=True).returncode != 0:
        pytest.skip("tmpfs cannot be mounted here")
    try:
        r = _run("render", sphere / "s.svo", "-o", disk / "r.png", "--cost", disk / "c.png", "--size", "320x240")
        assert r.exit_code == 1 and f"cannot write {disk / 'c.png'}" in r.output, r.output
        assert list(disk.iterdir()) == []
    finally:
        subprocess.run(["umount", str(disk)], check=True)


def test_binvox_run_bomb_is_refused_before_expanding(tmp_path):
    """8 MB of runs standing for 2**30 solid voxels."""
    dim = 1024
    pairs, rest = divmod(dim ** 3, 255)
    body = bytes([1, 255]) * pairs + bytes([1, rest])
    (tmp_path / "b.binvox").write_bytes(b"#binvox 1\ndim 1024 1024 1024\ntranslate 0 0 0\nscale 1\ndata\n" + body)
    r = _child("build", tmp_path / "b.binvox", "-o", tmp_path / "o.svo", "--max-memory", "1G")
    assert r.returncode == 1 and "b.binvox: about 1,073,741,824 voxels need an estimated" in r.stderr, r.stderr


def test_sliver_triangles_count_in_the_estimate(tmp_path):
    """Needles of no area crossing the grid: refused by the estimate, not after the work."""
    rng = np.random.default_rng(1)
    ends = rng.uniform(0, 1, (20000, 2, 3))
    text = "".join(f"v {a} {b} {c}\nv {d} {e} {f}\nv {d} {e} {f + 1e-9}\n" for (a, b, c), (d, e, f) in ends)
    text += "".join(f"f {3 * i + 1} {3 * i + 2} {3 * i + 3}\n" for i in range(len(ends)))
    (tmp_path / "n.obj").write_text(text)
    r = _run("build", tmp_path / "n.obj", "-o", tmp_path / "o.svo", "--depth", "12", "--max-memory", "1G")
    assert r.exit_code == 1 and "voxels need an estimated" in r.output, r.output
