"""The engine's shape tables (csrc/datapath.inc shape_tables, a vector of rows converted at
a time) hold the values the reference reads (rend3r/emu/shapes.py shapes_from_scene), bit
for bit: every float16 pattern (infinities, subnormals flushed or kept; a NaN is a NaN,
its payload not modelled: converting to double quiets a signalling one), the all-zero
quaternion, shapes that are off, tables whose length is not a multiple of the lanes."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings, strategies as st

from rend3r.emu import native
from rend3r.emu.arith import make_arith
from rend3r.emu.options import EmuOptions
from rend3r.emu.raytracer import set_up
from rend3r.emu.scene import Scene, prop_index
from rend3r.emu.shapes import shapes_from_scene
from rend3r.isa import Table
from rend3r.isa.tables import PROP_LIMIT

PRECISIONS = [("fp16", "ftz"), ("fp16", "ieee"), ("fp32", "ftz"), ("fp64", "ftz"), ("e6m9", "ftz"), ("e6m9", "ieee"),
              ("e5m7", "ftz"), ("bf16", "ftz")]
#: Float16 patterns the conversion treats apart: zeros, subnormals, normals at both ends,
#: infinities, NaNs with payloads (quiet and signalling), either sign.
EDGES = [0x0000, 0x8000, 0x0001, 0x03FF, 0x8001, 0x83FF, 0x0400, 0x7BFF, 0xFBFF, 0x7C00, 0xFC00, 0x7E00, 0x7C01,
         0xFD55, 0x3C00, 0xBC00]
_NAMES = ("xloc", "yloc", "zloc", "rrot", "irot", "jrot", "krot", "xscl", "yscl", "zscl")


def bits(a: np.ndarray) -> np.ndarray:
    return a.view(np.uint32 if a.dtype == np.float32 else np.uint64)


@settings(max_examples=80, derandomize=True)
@given(st.sampled_from(PRECISIONS), st.integers(0, 41), st.integers(0, 2**32 - 1), st.sampled_from([0.5, 0.97, 1.0]))
def test_tables_hold_the_values_the_reference_reads(precision, rows, seed, on):
    """``on``: the share of rows that are shapes (whole vectors of them go straight into
    place; a vector with a row off is put together row by row)."""
    rng = np.random.default_rng(seed)
    scene = Scene()
    values = rng.integers(0, 1 << 16, size=(rows, PROP_LIMIT), dtype=np.uint16)
    edge = rng.random((rows, PROP_LIMIT)) < 0.3
    values[edge] = rng.choice(EDGES, size=int(edge.sum()))  # each its own edge pattern
    p = {n: prop_index(Table.SHAPE, n) for n in _NAMES + ("type",)}
    values[:, p["type"]] = np.where(rng.random(rows) < on, rng.choice([1, 2, 3], size=rows),
                                    rng.choice([0, 4, 7], size=rows))  # sphere, cylinder, cone; off
    zero_rot = rng.random(rows) < 0.2
    for n in ("rrot", "irot", "jrot", "krot"):
        values[zero_rot, p[n]] &= 0x8000  # signed zeros: the identity
    scene.objects.index = np.sort(rng.choice(1 << 19, size=rows, replace=False)).astype(np.int64)
    scene.objects.values = values
    options = EmuOptions(precision=precision[0], subnormals=precision[1])
    fr, ref = set_up(scene, options), shapes_from_scene(scene, make_arith(*precision))
    assert fr.index.tolist() == ref.index.tolist()
    columns = {native.SF_LOC: ref.loc, native.SF_ROT: ref.rot, native.SF_INV: ref.inv_scale,
               native.SF_ZSIGN: [ref.zsign], native.SF_ONE: [ref.one]}
    for first, vec in columns.items():
        for k, want in enumerate(vec):
            got, want = np.ascontiguousarray(fr.sf[:, first + k]), np.asarray(want, fr.dtype)
            assert ((bits(got) == bits(want)) | (np.isnan(got) & np.isnan(want))).all()
    assert fr.si[:, native.SI_COLOUR].tolist() == ref.color.astype(np.int64).tolist()
    # the bound table (bounds.py shape_bounds): |q|^2 times the least and largest |inverse
    # scale| in double (a NaN scale: both NaN); bounded: a sphere, a finite centre, moderate maps
    with np.errstate(invalid="ignore"):  # inf * 0 and NaN compare as the kernels' do
        rot, inv = (np.array(v, np.float64) for v in (ref.rot, ref.inv_scale))
        q2 = ((rot[0] * rot[0] + rot[1] * rot[1]) + rot[2] * rot[2]) + rot[3] * rot[3]
        nan = np.isnan(inv).any(axis=0)
        smin = np.where(nan, np.nan, q2 * np.min(np.abs(inv), axis=0))
        smax = np.where(nan, np.nan, q2 * np.max(np.abs(inv), axis=0))
        centre = np.array(ref.loc, np.float64).T
        for got, want in ((fr.bnd[:, native.B_CENTER:native.B_CENTER + 3], centre), (fr.bnd[:, native.B_SMIN], smin),
                          (fr.bnd[:, native.B_SMAX], smax)):
            assert ((bits(np.ascontiguousarray(got)) == bits(want)) | (np.isnan(got) & np.isnan(want))).all()
        want = (ref.zsign == 1) & np.isfinite(centre).all(axis=1) & (smin >= 0.015625) & (smax <= 64.0)
    assert fr.bounded.astype(bool).tolist() == want.tolist()
    ident = (rot[0] == 1) & ((rot[1:] == 0) & ~np.signbit(rot[1:])).all(axis=0)  # the quaternion (1, +0, +0, +0)
    assert fr.si[:, native.SI_IDENT].astype(bool).tolist() == ident.tolist()


@settings(max_examples=30, derandomize=True)
@given(st.integers(0, 300), st.integers(0, 2**32 - 1), st.integers(2, 4))
def test_tables_split_over_threads_are_the_same(rows, seed, jobs):
    """Ranges of rows on a team of threads, then moved up past the rows that are off, the
    tree and the primary bounds (csrc/setup.c frame_setup): the same tables, tree and
    bounds, bit for bit (small ranges force splits)."""
    from rend3r.emu import bounds

    rng = np.random.default_rng(seed)
    scene = Scene()
    values = rng.integers(0, 1 << 16, size=(rows, PROP_LIMIT), dtype=np.uint16)
    values[:, prop_index(Table.SHAPE, "type")] = rng.choice([0, 1, 2, 3], size=rows, p=[0.3, 0.3, 0.2, 0.2])
    scene.objects.index = np.sort(rng.choice(1 << 19, size=rows, replace=False)).astype(np.int64)
    scene.objects.values = values
    chunk, bounds.SHAPE_CHUNK = bounds.SHAPE_CHUNK, 8
    try:
        one, many = (set_up(scene, EmuOptions(precision="fp16", jobs=j)) for j in (1, jobs))
    finally:
        bounds.SHAPE_CHUNK = chunk
    for name in ("sf", "si", "bnd", "bounded", "index"):
        assert getattr(one, name).tobytes() == getattr(many, name).tobytes(), name
    for name in ("node", "items", "always"):  # the tree built in the same call, and the primary bounds
        assert getattr(one.tree, name).tobytes() == getattr(many.tree, name).tobytes(), name
    assert (one.primary is None) == (many.primary is None)
    if one.primary is not None:
        (box, *arrays), (box2, *arrays2) = one.primary, many.primary
        assert box.box.tobytes() == box2.box.tobytes()
        assert all(a.tobytes() == b.tobytes() for a, b in zip(arrays, arrays2))


def test_teams_led_side_by_side():
    """Two frames set up at once on two threads, each leading a team of two: the pool
    serves one team at a time and a team never waits for a member, so the other set-up
    runs on its own thread; both get the same bits as with one job."""
    import threading

    from rend3r.emu import bounds

    rng = np.random.default_rng(7)
    scene = Scene()
    rows = 200
    values = rng.integers(0, 1 << 16, size=(rows, PROP_LIMIT), dtype=np.uint16)
    values[:, prop_index(Table.SHAPE, "type")] = 1
    scene.objects.index = np.arange(rows, dtype=np.int64)
    scene.objects.values = values
    chunk, bounds.SHAPE_CHUNK = bounds.SHAPE_CHUNK, 8
    try:
        one = set_up(scene, EmuOptions(jobs=1))
        frames: list = []
        runs = [threading.Thread(target=lambda: frames.append(set_up(scene, EmuOptions(jobs=2)))) for _ in range(2)]
        for run in runs:
            run.start()
        for run in runs:
            run.join()
    finally:
        bounds.SHAPE_CHUNK = chunk
    assert len(frames) == 2
    for fr in frames:
        assert fr.sf.tobytes() == one.sf.tobytes() and fr.tree.node.tobytes() == one.tree.node.tobytes()
        assert fr.primary[0].box.tobytes() == one.primary[0].box.tobytes()
