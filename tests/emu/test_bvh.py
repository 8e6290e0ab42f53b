"""The shape hierarchy (rend3r/emu/bvh.py): every bounded shape in exactly one leaf, boxes
that hold their shapes' balls, floors that are the least below, depth within the
traversal stacks' room; the nearest hits it leads to are checked against the reference
renderer in test_engine_vs_reference.py."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from rend3r.emu import bounds, bvh, native

from .test_engine_vs_reference import _same_bits

STACK = 64  # csrc/bvh.h BVH_STACK


def table(centers: np.ndarray) -> np.ndarray:
    bnd = np.zeros((len(centers), native.B_COLUMNS))
    bnd[:, :3] = centers
    bnd[:, 3:] = 1.0
    return bnd


def walk(tree: bvh.Tree) -> list[tuple[int, int]]:
    """(node, depth) of every node reached from the root, checking the links."""
    seen, todo = [], [(0, 0)] if tree.nodes else []
    while todo:
        at, depth = todo.pop()
        seen.append((at, depth))
        first, count = (int(v) for v in tree.node[at])
        if count == 0:
            assert at + 1 < tree.nodes and at + 1 < first < tree.nodes
            todo += [(at + 1, depth + 1), (first, depth + 1)]
    return seen


@settings(max_examples=60, derandomize=True)
@given(st.integers(0, 3000), st.integers(0, 2**32 - 1), st.booleans())
def test_every_bounded_shape_is_in_exactly_one_leaf(n, seed, clustered):
    rng = np.random.default_rng(seed)
    centers = rng.normal(size=(n, 3)) * (rng.random((n, 1)) < 0.5 if clustered else 1.0)  # many equal centres
    bounded = rng.random(n) < 0.9
    if n:
        centers[rng.integers(0, n)] = np.inf  # a shape at infinity stays outside
    bnd = table(centers)
    tree = bvh.build(bnd, bounded)
    inside = bounded & np.isfinite(centers).all(axis=1)
    assert sorted(tree.items.tolist()) == np.flatnonzero(inside).tolist()
    assert tree.always.tolist() == np.flatnonzero(~inside).tolist()
    nodes = walk(tree)
    assert sorted(at for at, _ in nodes) == list(range(tree.nodes))
    leaves = [tree.node[at] for at, _ in nodes if tree.node[at][1] > 0]
    covered = sorted(i for first, count in leaves for i in range(first, first + count))
    assert covered == list(range(len(tree.items)))
    assert all(count <= 4 for _, count in leaves)
    assert max((d for _, d in nodes), default=0) + 2 < STACK


def shapes(n: int, seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """n balls at scales from 1e-3 to 1e3 (a few without a radius) and their floors."""
    rng = np.random.default_rng(seed)
    bnd = table(rng.normal(size=(n, 3)) * 10.0 ** rng.integers(-3, 4, size=(n, 1)))
    radius = rng.random(n) * 10.0 ** rng.integers(-3, 3, size=n)
    radius[rng.random(n) < 0.05] = np.inf
    return bnd, radius, rng.random(n)


def leaves(tree: bvh.Tree):
    """(node, shape slots below it) of every node."""
    for at, _ in walk(tree):
        first, count = (int(v) for v in tree.node[at])
        yield at, (tree.items[first:first + count] if count else leaves_below(tree, at))


def leaves_below(tree: bvh.Tree, at: int) -> np.ndarray:
    first, count = (int(v) for v in tree.node[at])
    if count:
        return tree.items[first:first + count]
    return np.concatenate([leaves_below(tree, at + 1), leaves_below(tree, first)])


@settings(max_examples=30, derandomize=True)
@given(st.integers(1, 300), st.integers(0, 2**32 - 1))
def test_cones_hold_every_line_through_the_apex_that_meets_a_ball(n, seed):
    bnd, radius, floor = shapes(n, seed)
    rng = np.random.default_rng(seed + 1)
    apex = rng.normal(size=3)
    tree = bvh.build(bnd, np.ones(n, bool))
    b = tree.refit(bnd, radius, floor, apex=apex).box
    for at, below in leaves(tree):
        assert b[at, native.BV_FLOOR] == floor[below].min()
        # lines from the apex to points on the balls' surfaces (the extreme ones among them)
        c, r = bnd[below, :3] - apex, radius[below]
        finite = np.isfinite(r) & (np.linalg.norm(c, axis=1) > r)
        if not finite.all():
            assert b[at, native.BV_SIN2] == np.inf
            continue
        offsets = rng.normal(size=(len(below), 3))
        w = c + r[:, None] * offsets / np.linalg.norm(offsets, axis=1)[:, None]
        cross = np.cross(w, b[at, :3])
        assert ((cross**2).sum(axis=1) <= (w**2).sum(axis=1) * b[at, native.BV_SIN2]).all()


@settings(max_examples=40, derandomize=True)
@given(st.integers(2, 200), st.integers(0, 2**32 - 1))
def test_cones_hold_nested_and_nearly_parallel_cones(n, seed):
    """Balls on a few lines through the apex, turned by 1e-15 to 1e-2 rad, from 1e-3 to 1e6
    away, of angular radii 1e-14 to 1: cones nested in each other, axes nearly parallel
    or opposite (lines), the cases where a cone's union cancels most."""
    rng = np.random.default_rng(seed)
    apex = rng.normal(size=3)
    lines = rng.normal(size=(3, 3))
    d = lines[rng.integers(0, 3, n)] + rng.normal(size=(n, 3)) * 10.0 ** rng.uniform(-15, -2, (n, 1))
    d /= np.linalg.norm(d, axis=1)[:, None]
    dist = 10.0 ** rng.uniform(-3, 6, n) * rng.choice([-1.0, 1.0], n)
    bnd = table(apex + d * dist[:, None])
    radius = np.abs(dist) * np.minimum(10.0 ** rng.uniform(-14, 0, n), 0.999)
    tree = bvh.build(bnd, np.ones(n, bool))
    b = tree.refit(bnd, radius, apex=apex).box
    for at, below in leaves(tree):
        c, r = bnd[below, :3] - apex, radius[below]
        for sign in (-1.0, 1.0):  # lines from the apex through the balls' extreme points
            offsets = np.cross(c, rng.normal(size=(len(below), 3)))
            w = c + sign * r[:, None] * offsets / np.linalg.norm(offsets, axis=1)[:, None]
            cross = np.cross(w, b[at, :3])
            assert ((cross**2).sum(axis=1) <= (w**2).sum(axis=1) * b[at, native.BV_SIN2]).all()


@settings(max_examples=30, derandomize=True)
@given(st.integers(1, 300), st.integers(0, 2**32 - 1))
def test_flat_boxes_hold_every_ball_projected_on_the_axes(n, seed):
    bnd, radius, _ = shapes(n, seed)
    axes = np.array([[0.6, 0.8, 0.0], [0.0, 0.0, 1.0]])
    tree = bvh.build(bnd, np.ones(n, bool))
    b = tree.refit(bnd, radius, axes=axes).box
    for at, below in leaves(tree):
        uv, r = bnd[below, :3] @ axes.T, radius[below]
        assert (b[at, 0] <= uv[:, 0] - r).all() and (b[at, 1] >= uv[:, 0] + r).all()
        assert (b[at, 2] <= uv[:, 1] - r).all() and (b[at, 3] >= uv[:, 1] + r).all()
        assert b[at, native.BV_FLOOR] == -np.inf  # no floors given


def test_a_nan_radius_bounds_nothing():
    bnd = table(np.zeros((2, 3)) + 5.0)
    tree = bvh.build(bnd, np.ones(2, bool))
    assert tree.refit(bnd, np.array([1.0, np.nan]), apex=np.zeros(3)).box[0, native.BV_SIN2] == np.inf
    flat = tree.refit(bnd, np.array([1.0, np.nan]), axes=np.eye(3)[:2]).box[0]
    assert (flat[[0, 2]] == -np.inf).all() and (flat[[1, 3]] == np.inf).all()


def test_refit_checks_its_arrays():
    bnd = table(np.zeros((3, 3)))
    tree = bvh.build(bnd, np.ones(3, bool))
    with pytest.raises(TypeError):
        tree.refit(bnd, np.ones(2), apex=np.zeros(3))
    with pytest.raises(ValueError):
        tree.refit(bnd, np.ones(3))


@settings(max_examples=20, derandomize=True)
@given(st.integers(1, 400), st.integers(0, 2**32 - 1), st.integers(2, 5))
def test_refit_on_threads_gives_the_same_bits(n, seed, jobs):
    """Subtrees side by side, then the nodes above them: every node's bounds and keys
    exactly as one thread computes them, for cones and boxes (small chunks force splits)."""
    bnd, radius, floor = shapes(n, seed)
    keys = np.random.default_rng(seed).normal(size=(n, 3))
    tree = bvh.build(bnd, np.ones(n, bool))
    chunk, bounds.SHAPE_CHUNK = bounds.SHAPE_CHUNK, 8
    try:
        for kw, columns in (({"apex": np.array([0.5, -1.0, 2.0])}, slice(None)),
                            ({"axes": np.array([[0.6, 0.8, 0.0], [0.0, 0.0, 1.0]]), "keys": keys},
                             [0, 1, 2, 3, native.BV_FLOOR, *range(native.BV_FLOOR + 1, native.BV_COLUMNS)])):
            one, many = (tree.refit(bnd, radius, floor, jobs=j, **kw) for j in (1, jobs))
            assert one.box[:, columns].tobytes() == many.box[:, columns].tobytes()  # a box's columns
            assert (one.keys is None) == (many.keys is None)
            if one.keys is not None:
                assert one.keys.tobytes() == many.keys.tobytes()
    finally:
        bounds.SHAPE_CHUNK = chunk


def shadow_pass(bnd, ok, lo, hi, dmin, u, tiny, overflow, *, chord=np.nan, unit=None, length=0.0):
    """A light's shadow-ray pass over the shapes as csrc/band.c shadow_bounds fills it: for
    origins in the box lo..hi, a directional light along ``unit`` (its behind terms and
    stop keys) or a point light (``chord`` given: its behind-test terms as keys)."""
    n = len(bnd)
    p = bounds.shape_pass(bnd, ok, u, tiny, overflow, native.PASS_SHADOW)
    b = p.block
    b.mid[:] = (lo + hi) / 2
    b.half = float(np.sqrt(np.sum((hi - lo) ** 2))) / 2
    b.magnitude = float(np.abs(np.concatenate([lo, hi])).max())
    b.dmin, b.chord, b.l_len = dmin, chord, length
    if unit is not None:
        p.unit = np.ascontiguousarray(unit, np.float64)
        p.behind, p.keys = np.empty((n, 3)), np.empty((n, 3))
        b.unit, b.behind, b.keys = native.address(p.unit), native.address(p.behind), native.address(p.keys)
    elif not np.isnan(chord):
        p.keys = np.empty((n, native.SK_COLUMNS))
        b.point = native.address(p.keys)
    return p


def fitted(bnd: np.ndarray, ok: np.ndarray, tree: bvh.Tree, jobs: int) -> list:
    """A bundle's shape pass, own bounds and refit in one call (csrc/setup.c
    bundle_bounds), for the primary rays and a directional and a point light's shadow
    rays: every per-shape array and node bound they fill (None where a pass has none)."""
    apex, axes, unit = np.array([0.5, -1.0, 2.0]), np.array([[0.6, 0.8, 0.0], [0.0, 0.0, 1.0]]), np.array([0, 0, 1.0])
    lo, hi, limits = bnd[:, :3].min(axis=0), bnd[:, :3].max(axis=0), (2.0**-24, 2.0**-126, 3.4e38)
    passes = ((lambda: bounds.primary(bnd, ok, apex, 0.5, 2.0, *limits), {"apex": apex}),
              (lambda: shadow_pass(bnd, ok, lo, hi, 2.0, *limits, unit=unit, length=2.0), {"axes": axes}),
              (lambda: shadow_pass(bnd, ok, lo, hi, 0.5, *limits, chord=1e-3), {"apex": apex}))
    out = []
    for make, kw in passes:
        p = make()
        b = tree.fit(p, jobs=jobs, **kw)
        box = b.box if "apex" in kw else np.delete(b.box, [4, 5], axis=1)  # a box's columns
        out += [p.radius, p.floor, p.pc, p.pc32, p.behind, p.keys, box, b.keys, b.item_box]
    return out


@settings(max_examples=20, derandomize=True)
@given(st.integers(1, 400), st.integers(0, 2**32 - 1), st.integers(2, 5))
def test_shape_passes_on_threads_give_the_same_bits(n, seed, jobs):
    """The bundles' passes on a team of threads: every per-shape array and node bound
    exactly as one thread computes them."""
    bnd, _, _ = shapes(n, seed)
    ok = np.random.default_rng(seed).random(n) < 0.9
    tree = bvh.build(bnd, ok)
    chunk, bounds.SHAPE_CHUNK = bounds.SHAPE_CHUNK, 8
    try:
        for one, many in zip(fitted(bnd, ok, tree, 1), fitted(bnd, ok, tree, jobs), strict=True):
            assert (one is None) == (many is None)
            assert one is None or one.tobytes() == many.tobytes()
    finally:
        bounds.SHAPE_CHUNK = chunk


@settings(max_examples=40, derandomize=True)
@given(st.integers(1, 400), st.integers(0, 2**32 - 1))
def test_shape_passes_of_every_build_give_the_same_bits(n, seed):
    """The shape passes' copies (csrc/shape_bounds.inc: four lanes portable and AVX2,
    eight AVX-512), each under the kernels' build that picks it: every per-shape array and
    node bound of the three bundles the same bit for bit (a NaN matching any NaN), for
    counts of shapes that leave any tail of a vector and shapes whose smallest and largest
    singular values differ."""
    sets = [s for s in native.INSTRUCTION_SETS if native.runs(s)]
    if len(sets) < 2:
        pytest.skip("this processor runs one build of the kernels")
    bnd, _, _ = shapes(n, seed)
    rng = np.random.default_rng(seed)
    bnd[:, 3] = rng.uniform(0.25, 2.0, n)
    bnd[:, 4] = bnd[:, 3] * rng.uniform(1.0, 4.0, n)
    ok = rng.random(n) < 0.9
    tree = bvh.build(bnd, ok)
    runs = []
    try:
        for name in sets:
            native.choose(name)
            assert native.shape_isa() == native.INSTRUCTION_SETS.index(name)
            runs.append(fitted(bnd, ok, tree, 1))
    finally:
        native.choose(None)
    for other in runs[1:]:
        for a, b in zip(runs[0], other, strict=True):
            assert (a is None) == (b is None)
            assert a is None or _same_bits(a, b)


@settings(max_examples=30, derandomize=True)
@given(st.integers(1, 400), st.integers(0, 2**32 - 1), st.integers(1, 4))
def test_light_rows_are_in_leaf_order(n, seed, jobs):
    """A light's per-shape bounds come in rows in the tree's order (csrc/kernels.h
    PASS_SHADOW: the items' in leaf order, then the shapes outside the tree; ``where``
    maps a slot to its row), made in the subtree tasks: put back in slot order, each
    light's radii and keys refit into the same node bounds, bit for bit; and a shape's rows
    (radius, behind terms, keys) are its own whatever its slot and row, as the same shapes
    in another order give them."""
    bnd, _, _ = shapes(n, seed)
    rng = np.random.default_rng(seed)
    ok = rng.random(n) < 0.9
    order = rng.permutation(n)  # the same shapes in another order: shape s is at slot inverse[s] there
    inverse = np.argsort(order)
    tree, other = bvh.build(bnd, ok), bvh.build(bnd[order], ok[order])
    rows = np.concatenate([tree.items, tree.always])
    assert sorted(rows) == list(range(n)) and (tree.where[rows] == np.arange(n)).all()
    lo, hi, limits = bnd[:, :3].min(axis=0), bnd[:, :3].max(axis=0), (2.0**-24, 2.0**-126, 3.4e38)
    axes, apex = np.array([[0.6, 0.8, 0.0], [0.0, 0.0, 1.0]]), np.array([0.5, -1.0, 2.0])
    lights = (lambda b, o: shadow_pass(b, o, lo, hi, 2.0, *limits, unit=np.array([0, 0, 1.0]), length=2.0),
              {"axes": axes}), (lambda b, o: shadow_pass(b, o, lo, hi, 0.5, *limits, chord=1e-3), {"apex": apex})
    chunk, bounds.SHAPE_CHUNK = bounds.SHAPE_CHUNK, 8
    try:
        for make, kw in lights:
            p, q = make(bnd, ok), make(bnd[order], ok[order])
            fit = tree.fit(p, jobs=jobs, **kw)
            other.fit(q, jobs=jobs, **kw)
            again = tree.refit(bnd, p.radius[tree.where], keys=p.keys[tree.where], jobs=jobs, **kw)
            unused = [4, 5] if "axes" in kw else []  # a box's columns
            assert np.delete(fit.box, unused, axis=1).tobytes() == np.delete(again.box, unused, axis=1).tobytes()
            assert fit.keys.tobytes() == again.keys.tobytes()
            for mine, theirs in ((p.radius, q.radius), (p.behind, q.behind), (p.keys, q.keys)):
                if mine is not None:  # by slot: the row of slot s is where[s]
                    assert _same_bits(mine[tree.where], theirs[other.where][inverse])
    finally:
        bounds.SHAPE_CHUNK = chunk


@settings(max_examples=30, derandomize=True)
@given(st.integers(1, 300), st.integers(0, 2**32 - 1))
def test_point_light_terms_hold_every_shape_below(n, seed):
    """Per node, a point light's behind-test terms (csrc/kernels.c refit_cones): the box
    holds every centre below, the least mean2 and the largest K and radius bound every
    shape's; a NaN K becomes inf, which claims nothing."""
    bnd, radius, _ = shapes(n, seed)
    rng = np.random.default_rng(seed)
    terms = np.empty((n, native.SK_COLUMNS))
    terms[:, :3] = bnd[:, :3]
    terms[:, 3], terms[:, 4], terms[:, 5] = rng.random(n) + 0.1, rng.random(n), radius
    terms[rng.random(n) < 0.05, 4] = np.nan  # K
    tree = bvh.build(bnd, np.ones(n, bool))
    keys = tree.refit(bnd, radius, apex=np.array([0.5, -1.0, 2.0]), keys=terms).keys
    assert keys.shape == (tree.nodes, native.PK_COLUMNS)
    for at, below in leaves(tree):
        k, t = keys[at], terms[below]
        assert (k[0:3] <= t[:, :3]).all() and (k[3:6] >= t[:, :3]).all()
        assert k[6] == t[:, 3].min()
        assert k[7] == (np.inf if np.isnan(t[:, 4]).any() else t[:, 4].max())
        assert k[8] == t[:, 5].max()


def _same_tree(a: bvh.Tree, b: bvh.Tree) -> bool:
    return all(np.array_equal(x, y) for x, y in ((a.node, b.node), (a.items, b.items), (a.always, b.always),
                                                 (a.where, b.where)))


@settings(max_examples=40, derandomize=True)
@given(st.integers(1, 3000), st.integers(0, 2**32 - 1), st.sampled_from([1.0, 1e-3, 1e3, 0.0]))
def test_every_build_makes_the_same_tree(n, seed, spread):
    """The Morton codes' copies (csrc/kernels.c morton_keys: portable, AVX2, AVX-512) give
    the same tree, for any count and for centres spread over any range (0: all at one
    point) or ending exactly at a cell's edge; and each orders the shapes along the Morton
    curve computed here afresh (leaves in order of code; shapes of one code in any)."""
    rng = np.random.default_rng(seed)
    centers = rng.normal(size=(n, 3)) * spread
    grid = rng.random(n) < 0.5
    centers[grid] = np.round(centers[grid] * 4) / 4  # on a coarse grid: ties, and centres on the box's faces
    bnd, ok = table(centers), rng.random(n) < 0.95
    code = _morton(centers, ok)
    trees = []
    try:
        for name in (s for s in native.INSTRUCTION_SETS if native.runs(s)):
            native.choose(name)
            trees.append(bvh.build(bnd, ok))
            assert (np.diff(code[trees[-1].items]) >= 0).all(), name
    finally:
        native.choose(None)
    assert all(_same_tree(trees[0], other) for other in trees[1:])


def _morton(centers: np.ndarray, ok: np.ndarray) -> np.ndarray:
    """Each shape's Morton code as bvh_build makes it: centres as floats, 10 bits an axis
    on the cube from the bounded ones' least corner, x the highest of each three bits."""
    c = centers.astype(np.float32)
    lo, hi = c[ok].min(axis=0), c[ok].max(axis=0)
    side = max(float(hi[k]) - float(lo[k]) for k in range(3)) if ok.any() else 0.0
    scale = 1024 / side if 0 < side < np.inf else 0.0
    q = (c.astype(np.float64) - lo.astype(np.float64)) * scale
    step = np.where(q < 1023, q, 1023).astype(np.int64)
    code = np.zeros(len(c), np.int64)
    for bit in range(10):
        for k in range(3):
            code |= (step[:, k] >> bit & 1) << (3 * bit + 2 - k)
    return code


def _kept() -> int:
    return bvh.tree_room(0)[0].kept


@settings(max_examples=60, derandomize=True)
@given(st.integers(0, 2000), st.integers(0, 2**32 - 1), st.sampled_from(["moved", "float ulp", "unbounded",
                                                                          "swapped", "fewer", "more"]),
       st.sampled_from([0.9, 1.0]))
def test_a_kept_tree_is_found_only_for_the_same_shapes(n, seed, change, share):
    """bvh_build in this thread's tree room builds nothing when the centres (as floats),
    slots and unbounded shapes are the last build's, and builds every other: each tree is
    the one built afresh. A share of the shapes bounded (all of them: every block of eight
    takes the AVX-512 first pass's vector path, which compares as it goes)."""
    rng = np.random.default_rng(seed)
    centers = rng.normal(size=(n, 3)) * (rng.random((n, 1)) < 0.5)  # ties among the centres
    bounded = rng.random(n) < share
    bvh.forget()
    first = bvh.build(table(centers), bounded, kept=True)
    assert _same_tree(first, bvh.build(table(centers), bounded))
    kept = _kept()
    again = bvh.build(table(centers), bounded, kept=True)
    assert _same_tree(again, first) and _kept() == kept + (len(first.items) > 0)  # no tree: none kept
    other, ok = centers.copy(), bounded.copy()
    i = int(rng.integers(0, n)) if n else 0
    if change == "fewer":
        other, ok = other[:-1], ok[:-1]
    elif change == "more":
        other, ok = np.vstack([other, [[0.5, 0.25, 2.0]]]), np.append(ok, True)
    elif n == 0:
        return
    elif change == "moved":
        other[i, int(rng.integers(0, 3))] += 1.0
    elif change == "float ulp":  # the build reads centres as floats: one float step apart
        c = np.float32(other[i, 0])
        other[i, 0] = np.nextafter(c, np.float32(np.inf), dtype=np.float32)
    elif change == "unbounded":
        ok[i] = not ok[i]
    elif change == "swapped":  # the same centres in other slots
        j = (i + 1) % n
        other[[i, j]] = other[[j, i]]
        ok[[i, j]] = ok[[j, i]]
    same = len(ok) == n and np.array_equal(ok, bounded) and \
        other[ok].astype(np.float32).tobytes() == centers[ok].astype(np.float32).tobytes()  # -0 is not 0 here
    kept = _kept()
    built = bvh.build(table(other), ok, kept=True)
    assert _same_tree(built, bvh.build(table(other), ok))
    assert _kept() == kept + (same and len(first.items) > 0)


def test_a_tree_room_in_use_is_not_reused():
    """While an array made from the thread's tree room lives, the next build gets new
    arrays (and builds): a frame's tree never changes under whoever still holds it."""
    centers = np.random.default_rng(1).normal(size=(100, 3))
    bvh.build(table(centers), np.ones(100, bool), kept=True)
    held = bvh.tree_room(100)[2][:10]
    kept = _kept()
    assert not np.shares_memory(held, bvh.tree_room(100)[2])
    bvh.build(table(centers), np.ones(100, bool), kept=True)
    assert _kept() == 0  # a new memo: nothing found in it
    del held
    bvh.build(table(centers), np.ones(100, bool), kept=True)
    assert _kept() == 1


@pytest.mark.parametrize("jobs", [1, 2])
def test_frames_of_moving_shapes_match_frames_built_afresh(jobs):
    """Frames alternating between scenes, their shapes moved or not, render as each scene's
    first frame does, test counts included (those depend on the tree's grouping: the kept
    tree is copied only for the same shapes)."""
    from rend3r.asm.assembler import assemble_source
    from rend3r.emu.options import EmuOptions
    from rend3r.emu.run import run_program

    grid = [(x - 1.5, y - 1.5) for y in range(4) for x in range(4)]

    def scene(order: list[int]) -> list[int]:
        lines = ["nr", "cam rrot, 1", "cam hfov, 0.25", "cam vfov, 0.25", "lt 0, src, 1", "lt 0, xfor, -1",
                 "lt 0, yfor, -1", "lt 0, zfor, -1", "lt 0, col, 0xFFFF", "lt 0, int, 1"]
        for k, at in enumerate(order):
            x, y = grid[at]
            lines += [f"sp {k}, type, col, 1, {0x0841 * (k + 1)}", f"sp {k}, xloc, yloc, {x}, {y}",
                      f"sp {k}, zloc, rrot, -8, 1", f"sp {k}, xscl, yscl, 2.5, 2.5", f"sp {k}, zscl, mat, 2.5, 0"]
        made = assemble_source("\n".join([*lines, "nf", "er"]))
        assert made.ok, made.format_diagnostics()
        return made.program.words

    same, swapped = list(range(16)), list(range(16))
    swapped[3], swapped[12] = 12, 3  # two shapes change places: the same centres, other slots
    options = EmuOptions(precision="fp32", width=64, height=48, jobs=jobs)
    scenes = [scene(order) for order in (same, same, swapped, same, swapped, swapped, same[::-1])]
    bvh.forget()
    kept = _kept()
    runs = [run_program(words, options) for words in scenes]
    assert _kept() == kept + 2
    for words, run in zip(scenes, runs):
        bvh.forget()
        fresh = run_program(words, options)
        mine, theirs = run.frames[0], fresh.frames[0]
        assert np.array_equal(mine.provenance, theirs.provenance) and np.array_equal(mine.rgb565, theirs.rgb565)
        assert mine.depth.tobytes() == theirs.depth.tobytes()
        counts = [(st.tests, st.skipped, st.hits) for st in (run.stats.frames[0], fresh.stats.frames[0])]
        assert counts[0] == counts[1]
