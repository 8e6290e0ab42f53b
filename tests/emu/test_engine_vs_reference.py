"""The compiled raytracer against the plain reference renderer (every pixel against every
shape, numpy): identical pixels, depth bits and provenance on random scenes.

Scenes mix every shape type (and types that are off), rotations, scales, both cameras,
directional and point lights, every precision (and other formats eEmM) with flushed and gradual underflow, the
original board's profile, exact ties (duplicated shapes), and float16 operands that are
infinite, NaN, subnormal, zero of either sign or the largest finite value. About 1,020
scenes run in CI, from a fixed seed; ``REND3R_FUZZ=10 python -m pytest
tests/emu/test_engine_vs_reference.py`` draws ten times as many from a random one
(hypothesis prints the seed and the failing scene, shrunk).
"""

from __future__ import annotations

import os
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import event, given, settings, strategies as st

from rend3r.emu.frame import Frame
from rend3r.emu.options import EmuOptions
from rend3r.emu.processor import execute
from rend3r.emu.quirks import apply_quirks, quirk_names
from rend3r.emu import bounds, raytracer, reference
from rend3r.emu.raytracer import render_frame
from rend3r.emu.reference import render_reference
from rend3r.emu.scene import Scene
from rend3r.emu.stats import FrameStats
from rend3r.isa import CameraSet, FrameOp, Func, LightSet, ShapeSet, Table, ValueType, encode, lookup
from rend3r.isa.float16 import float_to_bits

FUZZ = os.environ.get("REND3R_FUZZ", "")  # k: k times CI's scenes, from a random seed


def scenes(n: int) -> settings:
    """n scenes from a fixed seed, as CI draws them; with REND3R_FUZZ=k, k x n from a random one."""
    if not FUZZ:
        return settings(max_examples=n, derandomize=True)
    try:
        k = float(FUZZ)
    except ValueError:
        k = -1.0
    if not 0 < k <= 10_000:
        raise ValueError(f"REND3R_FUZZ={FUZZ!r}: a number of times CI's scenes, above 0 and at most 10,000")
    return settings(max_examples=max(1, round(n * k)), derandomize=False)


SPECIAL = [0x0000, 0x8000, 0x0001, 0x03FF, 0x8200, 0x0400, 0x7BFF, 0xFBFF, 0x7C00, 0xFC00, 0x7E00, 0x3C00, 0xBC00]


def f16(lo: float, hi: float, special: float = 0.03) -> st.SearchStrategy[int]:
    """float16 bits: a value in [lo, hi], or with probability ``special`` a special value."""
    lo, hi = float(np.float16(lo)), float(np.float16(hi))
    nice = st.floats(lo, hi, allow_nan=False, width=16).map(float_to_bits)
    return st.floats(0, 1).flatmap(lambda p: st.sampled_from(SPECIAL) if p < special else nice)


def quaternion(special: float = 0.03) -> st.SearchStrategy[tuple[int, ...]]:
    turned = st.tuples(*[f16(-1.5, 1.5, special)] * 4)
    return st.one_of(st.just((0x3C00, 0, 0, 0)), st.just((0, 0, 0, 0)), turned)


#: A shape aimed into the view: frame position (a, b) in [0, 1], distance t along that
#: pixel's ray, radius as a fraction of the distance, per-axis stretch; then properties
#: written as they are (type, colour, rotation) and, sometimes, one special value.
shape = st.fixed_dictionaries({
    "type": st.sampled_from([1, 1, 1, 2, 3, 0, 5]),
    "col": st.integers(0, 0xFFFF),
    "aim": st.tuples(st.floats(0.1, 0.9), st.floats(0.1, 0.9), st.floats(1.5, 30), st.floats(0.08, 0.4)),
    "stretch": st.tuples(*[st.floats(0.7, 1.5)] * 3),
    "rot": quaternion(),
    "special": st.sampled_from([None] * 6 + [(n, v) for n in ("xloc", "yloc", "zloc", "xscl", "yscl", "zscl")
                                             for v in SPECIAL]),
})
light = st.one_of(
    st.fixed_dictionaries({"src": st.just(1), "xfor": f16(-2, 2), "yfor": f16(-2, 2), "zfor": f16(-2, 2),
                           "col": st.integers(0, 0xFFFF), "int": f16(0, 2)}),
    st.fixed_dictionaries({"src": st.just(2), "xloc": f16(-8, 8), "yloc": f16(-8, 8), "zloc": f16(-30, 5),
                           "int": f16(0, 2)}),
    st.fixed_dictionaries({"src": st.sampled_from([0, 3])}),
)
camera = st.fixed_dictionaries({
    "xloc": f16(-2, 2, 0.02), "yloc": f16(-2, 2, 0.02), "zloc": f16(-2, 2, 0.02),
    "rot": st.one_of(st.just((0, 0, 0, 0)), quaternion(0.02)),
    "hfov": st.one_of(st.just(0), f16(0.05, 0.6, 0.02)), "vfov": st.one_of(st.just(0), f16(0.05, 0.6, 0.02)),
    "nclip": st.one_of(st.just(0), f16(0.05, 4, 0.02)), "fclip": st.one_of(st.just(0), f16(1, 60, 0.02)),
})
precision = st.sampled_from([("fp16", "ftz"), ("fp16", "ieee"), ("fp32", "ftz"), ("fp64", "ftz")])
#: Other formats: in float lanes (the narrow kernels: M <= 10 and E <= 7, or E = 8 with ftz)
#: and in double lanes (the format kernels), narrow and wide exponents, fractions that
#: round in double innocuously (M <= 25) or through round to odd (M > 25, every e11 format).
other_format = st.tuples(st.sampled_from(["bf16", "tf32", "e6m9", "e7m10", "e2m3", "fp24", "e4m3", "e5m2", "e3m6",
                                          "e6m12", "e8m30", "e9m40", "e11m20", "e11m51"]), st.sampled_from(["ftz", "ieee"]))


def _prop(table: Table, name: str) -> int:
    return lookup(table, name).index


def _value(bits: int, default: float) -> float:
    v = float(np.uint16(bits).view(np.float16))
    return default if v == 0 else v


def _aim(cam: dict, options: EmuOptions, a: float, b: float) -> tuple[np.ndarray, np.ndarray, float]:
    """The camera's origin, the direction through frame position (a, b) and the frame's
    width at t = 1, in float64 and unrounded: where to put a shape so that it shows."""
    origin = np.array([_value(cam[n], 0.0) for n in ("xloc", "yloc", "zloc")])
    if options.camera == "device":
        x0, y0, step = -4.98828125, -3.740234375, 0.01953125
        d = np.array([x0 + a * options.width * step, y0 + b * options.height * step, -1.0])
        return origin, d, options.width * step
    near = _value(cam["nclip"], 1.0)
    d = np.array([10 * (a - 0.5) * _value(cam["hfov"], 1.0) * near, 7.5 * (0.5 - b) * _value(cam["vfov"], 1.0) * near,
                  -near])
    q = np.array([float(np.uint16(c).view(np.float16)) for c in cam["rot"]])
    with np.errstate(all="ignore"):
        if q[1:].any():
            r, i, j, k = q / np.linalg.norm(q)
            rot = np.array([[1 - 2 * (j * j + k * k), 2 * (i * j - k * r), 2 * (i * k + j * r)],
                            [2 * (i * j + k * r), 1 - 2 * (i * i + k * k), 2 * (j * k - i * r)],
                            [2 * (i * k - j * r), 2 * (j * k + i * r), 1 - 2 * (i * i + j * j)]])
            d = rot @ d
    return origin, d, abs(10 * _value(cam["hfov"], 1.0) * near)


def program(cam: dict, lights: list[dict], shapes: list[dict], ties: list[int], options: EmuOptions) -> list[int]:
    """nr, the camera, lights and shapes (``ties``: shapes repeated at higher indices), nf."""
    words = list(encode(FrameOp(Func.NR)))
    for name, value in cam.items():
        names = ("rrot", "irot", "jrot", "krot") if name == "rot" else (name,)
        for n, v in zip(names, value if name == "rot" else (value,)):
            words += encode(CameraSet(_prop(Table.CAMERA, n), v))
    for i, lt in enumerate(lights):
        for name, v in lt.items():
            words += encode(LightSet(i, _prop(Table.LIGHT, name), v))
    for i, sh in enumerate(shapes + [shapes[k % len(shapes)] for k in ties]):
        a, b, t, size = sh["aim"]
        origin, d, width = _aim(cam, options, a, b)
        with np.errstate(all="ignore"):
            loc = origin + t * d
            inv = 1 / (size * t * width * np.array(sh["stretch"]))
        props = {"type": sh["type"], "col": sh["col"], **dict(zip(("rrot", "irot", "jrot", "krot"), sh["rot"])),
                 **{n: float_to_bits(float(v)) for n, v in zip(("xloc", "yloc", "zloc"), loc)},
                 **{n: float_to_bits(float(v)) for n, v in zip(("xscl", "yscl", "zscl"), inv)}}
        if sh["special"] is not None:
            props[sh["special"][0]] = sh["special"][1]
        items = list(props.items())
        for (n1, v1), (n2, v2) in zip(items[::2], items[1::2] + [("zero", 0)] * (len(items) % 2)):
            words += encode(ShapeSet(3 * i + 1, _prop(Table.SHAPE, n1), _prop(Table.SHAPE, n2), v1, v2))
    return words + list(encode(FrameOp(Func.NF)))


def scene_of(words: list[int], options: EmuOptions) -> Scene:
    scenes: list[Scene] = []
    execute(words, options, on_nf=lambda scene, n: scenes.append(scene))
    return scenes[0]


def assert_same(a: Frame, b: Frame) -> None:
    assert (a.provenance == b.provenance).all(), np.argwhere(a.provenance != b.provenance)[:5]
    assert (a.rgb565 == b.rgb565).all(), np.argwhere(a.rgb565 != b.rgb565)[:5]
    assert (a.depth.view(np.uint32) == b.depth.view(np.uint32)).all()


def check(words: list[int], options: EmuOptions) -> None:
    hits = compare(scene_of(words, options), options).hits
    event(f"pixels hit: {'none' if not hits else 'some' if hits < options.pixels // 4 else 'many'}")


def compare(scene: Scene, options: EmuOptions) -> FrameStats:
    """The engine's frame against the oracle's, then split over threads and bands with the
    primary hierarchy's subtrees of a few items made when first entered; returns the
    engine's stats."""
    engine, stats = render_frame(scene, options)
    assert_same(engine, render_reference(scene, options))
    chunks = raytracer.MIN_CHUNK, bounds.SHAPE_CHUNK, raytracer.BAND_PIXELS, bounds.LAZY_ITEMS
    # tiny chunks: every pass split over the team; bands of 5 rows (the last one shorter)
    raytracer.MIN_CHUNK, bounds.SHAPE_CHUNK, raytracer.BAND_PIXELS = 16, 2, 5 * options.width
    try:
        for jobs, lazy in ((1, 8), (3, 16)):  # one thread; a team of three, racing to make subtrees
            bounds.LAZY_ITEMS = lazy
            split, counts = render_frame(scene, replace(options, jobs=jobs))
            assert_same(engine, split)
            # (tests and those meeting NaN depend on what each band's bounds skip)
            assert (counts.hits, counts.shadow_rays) == (stats.hits, stats.shadow_rays)
    finally:
        raytracer.MIN_CHUNK, bounds.SHAPE_CHUNK, raytracer.BAND_PIXELS, bounds.LAZY_ITEMS = chunks
    return stats


scene_args = (camera, st.lists(light, max_size=3), st.lists(shape, min_size=1, max_size=7),
              st.lists(st.integers(0, 6), max_size=2), precision)


@scenes(400)
@given(*scene_args)
def test_random_scenes(cam, lights, shapes, ties, prec):
    options = EmuOptions(precision=prec[0], subnormals=prec[1], width=24, height=18)
    check(program(cam, lights, shapes, ties, options), options)


@scenes(200)
@given(*scene_args[:-1], other_format)
def test_random_scenes_in_other_formats(cam, lights, shapes, ties, fmt):
    """Any format eEmM: the narrow or format kernels against the reference's exactly
    rounded numpy."""
    options = EmuOptions(precision=fmt[0], subnormals=fmt[1], width=24, height=18)
    check(program(cam, lights, shapes, ties, options), options)


@scenes(40)
@given(*scene_args[:-1])
def test_random_scenes_judging_tininess_before_rounding(cam, lights, shapes, ties):
    """fp16 with the tiny-before-rounding quirk runs on the narrow kernels."""
    options = EmuOptions(precision="fp16", subnormals="ftz", tininess="before", width=24, height=18)
    check(program(cam, lights, shapes, ties, options), options)


@scenes(100)
@given(camera, st.lists(light, min_size=1, max_size=3).filter(lambda ls: ls[0]["src"] == 1),
       *scene_args[2:], st.booleans())
def test_random_scenes_on_the_original_board(cam, lights, shapes, ties, prec, ieee):
    """The board lights every point with light 0 as a directional light."""
    options = apply_quirks(EmuOptions(precision=prec[0], width=24, height=18), quirk_names("rend3r-2022", []))
    options = replace(options, subnormals="ieee" if ieee else options.subnormals)
    check(program(cam, lights, shapes, ties, options), options)


def _wall(g, k, size, distance, lights, rot, prec):
    """g x g spheres k deep in view, rendered by the engine and the reference."""
    cam = {"xloc": 0, "yloc": 0, "zloc": 0, "rot": (0, 0, 0, 0), "hfov": float_to_bits(0.4),
           "vfov": float_to_bits(0.4), "nclip": 0, "fclip": 0}
    shapes = [{"type": 1, "col": 0x1234 * (i + 1) & 0xFFFF, "rot": rot, "stretch": (1.0, 1.0, 1.0), "special": None,
               "aim": (0.5 + ((i % g) - (g - 1) / 2) / (g + 1), 0.5 + ((i // g % g) - (g - 1) / 2) / (g + 1),
                       distance * (1 + 0.15 * (i // (g * g))), size)} for i in range(g * g * k)]
    options = EmuOptions(precision=prec[0], subnormals=prec[1], width=24, height=18)
    check(program(cam, lights, shapes, [], options), options)


wall_args = (st.integers(1, 6), st.integers(1, 4), st.floats(0.02, 0.12), st.floats(2, 12),
             st.lists(light, min_size=1, max_size=2), quaternion(0))


@scenes(100)
@given(*wall_args, precision)
def test_random_walls(g, k, size, distance, lights, rot, prec):
    """Many spheres in view, in front of each other: deep hierarchies, depth order,
    shadows cast by neighbours."""
    _wall(g, k, size, distance, lights, rot, prec)


@scenes(60)
@given(*wall_args, other_format)
def test_random_walls_in_other_formats(g, k, size, distance, lights, rot, prec):
    """Walls in any format: culled with each format's own bounds (overflowing tests miss)."""
    _wall(g, k, size, distance, lights, rot, prec)


#: A directional light grazing a wall: travelling mostly along x or y, so that spheres
#: shadow their neighbours.
grazing = st.tuples(st.sampled_from([0, 1]), st.sampled_from([-1.0, 1.0]), st.floats(-0.4, 0.4),
                    st.floats(-0.6, 0.2)).map(
    lambda a: {"src": 1, **{n: float_to_bits(v) for n, v in zip(("xfor", "yfor", "zfor"),
                                                                 (a[1], a[2], a[3]) if a[0] else (a[2], a[1], a[3]))},
               "col": 0xFFFF, "int": float_to_bits(1.0)})


@scenes(60)
@given(st.integers(2, 5), st.integers(1, 3), st.floats(0.3, 0.6), st.floats(2, 12), grazing,
       st.tuples(*[st.floats(0.6, 1.6)] * 3), quaternion(0), precision)
def test_neighbours_shadowing_each_other(g, k, fill, distance, lit, stretch, rot, prec):
    """A directional light's packets of one receiver test only that receiver's casters
    (csrc/casters.h): close walls of stretched, turned spheres under a grazing light, where
    neighbours block shadow rays (counted in the reference), render as the reference does."""
    cam, shapes = _columns(g, k, fill, distance, stretch, rot, 0.1)
    options = EmuOptions(precision=prec[0], subnormals=prec[1], width=32, height=24)
    _check_counting_blocked(program(cam, [lit], shapes, [], options), options)


def _columns(g: int, k: int, fill: float, distance: float, stretch: tuple, rot: tuple,
             step: float) -> tuple[dict, list[dict]]:
    """The eye at the origin looking along -z, and g x g columns k deep of stretched,
    turned spheres filling ``fill`` of their spacing, ``distance`` away, each layer
    ``step`` of it behind the one before."""
    cam = {"xloc": 0, "yloc": 0, "zloc": 0, "rot": (0, 0, 0, 0), "hfov": float_to_bits(0.4),
           "vfov": float_to_bits(0.4), "nclip": 0, "fclip": 0}
    shapes = [{"type": 1, "col": 0x0841 * (i + 1) & 0xFFFF, "rot": rot, "stretch": stretch, "special": None,
               "aim": (0.5 + ((i % g) - (g - 1) / 2) / (g + 1), 0.5 + ((i // g % g) - (g - 1) / 2) / (g + 1),
                       distance * (1 + step * (i // (g * g))), fill / (g + 1))} for i in range(g * g * k)]
    return cam, shapes


def _check_counting_blocked(words: list[int], options: EmuOptions) -> None:
    """check(), reporting whether the reference found shadow rays blocked."""
    blocked, plain = [], reference._blocked

    def counted(*args):
        out = plain(*args)
        blocked.append(int(out.sum()))
        return out

    reference._blocked = counted
    try:
        check(words, options)
    finally:
        reference._blocked = plain
    event(f"shadowed points: {'none' if not sum(blocked) else 'some'}")


@scenes(60)
@given(camera, st.lists(light, max_size=3), st.lists(shape, min_size=12, max_size=60),
       st.lists(st.integers(0, 11), max_size=3), precision)
def test_random_crowds(cam, lights, shapes, ties, prec):
    """Enough shapes of every kind for a hierarchy several levels deep: inner nodes, leaves
    and the list of shapes outside the tree, for primary and shadow rays."""
    options = EmuOptions(precision=prec[0], subnormals=prec[1], width=24, height=18)
    check(program(cam, lights, shapes, ties, options), options)


@scenes(120)
@given(*scene_args[:-1], st.one_of(precision, other_format), st.booleans())
def test_every_instruction_set_renders_alike(cam, lights, shapes, ties, prec, wall):
    """The kernels' builds this processor runs (portable, AVX2, AVX-512; the other tests
    run the one in use): the same shape tables and primary bounds, bit for bit, and the
    same pixels, depth bits, provenance and counts, on random scenes or walls of spheres
    several deep."""
    from rend3r.emu import native

    sets = [s for s in native.INSTRUCTION_SETS if native.runs(s)]
    if len(sets) < 2:
        pytest.skip("this processor runs one build of the kernels")
    options = EmuOptions(precision=prec[0], subnormals=prec[1], width=24, height=18)
    if wall:
        cam, shapes = _columns(3, 3, 0.5, 6, (1.0, 1.0, 1.0), shapes[0]["rot"], 0.15)
    scene = scene_of(program(cam, lights, shapes, ties, options), options)
    try:
        renders, tables = [], []
        for name in sets:
            native.choose(name)
            assert native.kernel("nearest", options.arith).__name__.endswith(f"_{name}")  # the build in use
            renders.append(render_frame(scene, options))
            fr = raytracer.set_up(scene, options)
            primary = () if fr.primary is None else (*_node_columns(fr.primary[0].box), *fr.primary[1:])
            tables.append([np.array(a) for a in (fr.sf, fr.si, fr.bnd, *primary)])
    finally:
        native.choose(None)
    (first, counts), rest = renders[0], renders[1:]
    for frame, other in rest:
        assert_same(first, frame)
        assert replace(other, seconds=0) == replace(counts, seconds=0)
    for other in tables[1:]:
        assert all(_same_bits(a, b) for a, b in zip(tables[0], other, strict=True))


def _node_columns(box: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A node table's double columns, and its float columns as floats (two to a double: a
    float NaN there need not make a NaN double)."""
    from rend3r.emu import native

    return box[:, :native.BV_F32], np.ascontiguousarray(box[:, native.BV_F32:]).view(np.float32)


def _same_bits(a: np.ndarray, b: np.ndarray) -> bool:
    """The same values bit for bit, except that a NaN matches any NaN (IEEE leaves a NaN's
    sign and payload to the instructions; the frames, compared above, do not depend on them)."""
    if a.dtype.kind != "f":
        return np.array_equal(a, b)
    bits = a.view(f"u{a.itemsize}") == b.view(f"u{b.itemsize}")
    return bool((bits | (np.isnan(a) & np.isnan(b))).all())


def test_value_types_are_what_the_tables_say():
    """The strategies write float16 bits to float properties and ints to int properties."""
    assert lookup(Table.SHAPE, "type").vtype is ValueType.INT
    assert lookup(Table.SHAPE, "xloc").vtype is ValueType.FLOAT16
    assert lookup(Table.LIGHT, "src").vtype is ValueType.INT


#: A point light beside columns of shapes, between the eye and beyond them: shadow rays
#: towards it pass shapes lying behind their origins, beside them and in front of them.
near_light = st.tuples(st.floats(-1.5, 1.5), st.floats(-1.5, 1.5), st.floats(0.3, 1.3))


@scenes(80)
@given(st.integers(1, 4), st.integers(4, 10), st.floats(0.3, 0.7), st.floats(2, 8), near_light,
       st.tuples(*[st.floats(0.6, 1.6)] * 3), quaternion(0), precision)
def test_point_light_among_columns(g, k, fill, distance, at, stretch, rot, prec):
    """A point light's packets skip the nodes whose every shape lies behind a lane's
    origin (csrc/cull.h point_behind4): g x g columns of stretched, turned spheres k deep,
    the light beside them (x and y a fraction of the distance, z a fraction of the
    columns' depth), render as the reference does (blocked rays counted in the reference)."""
    depth = distance * (1 + 0.12 * (k - 1))
    light = {"src": 2, "col": 0xFFFF, "int": float_to_bits(1.0),
             **{n: float_to_bits(v) for n, v in zip(("xloc", "yloc", "zloc"),
                                                     (at[0] * distance, at[1] * distance, -at[2] * depth))}}
    cam, shapes = _columns(g, k, fill, distance, stretch, rot, 0.12)
    options = EmuOptions(precision=prec[0], subnormals=prec[1], width=32, height=24)
    _check_counting_blocked(program(cam, [light], shapes, [], options), options)


def test_lights_whose_shadow_rays_nothing_bounds():
    """A point light at infinity or NaN (no l is usable, so csrc/band.c shadow_bounds gives
    its rays infinite radii) and a directional light of no direction (likewise): the band
    goes through with hit points whose lighting is NaN and no shadow ray (their cosines
    are not finite), and the frames equal the oracle's."""
    from .scenes import Prog

    inf, nan = float("inf"), float("nan")
    for light in ({"src": 2, "xloc": inf, "yloc": 1.0, "zloc": 0.0}, {"src": 2, "xloc": nan},
                  {"src": 2, "zloc": -inf}, {"src": 1, "xfor": 0.0, "yfor": 0.0, "zfor": 0.0}):
        prog = Prog().nr().cam(hfov=0.6, vfov=0.6).light(0, col=0xFFFF, int=1.0, **light)
        for i, (x, z) in enumerate(((0.0, -3.5), (0.8, -5.0), (-0.9, -4.2))):
            prog.sphere(i, loc=(x, 0.1 * i, z), scale=(0.4, 0.4, 0.4))
        words = prog.nf().words
        for precision in ("fp16", "fp32"):
            options = EmuOptions(precision=precision, width=48, height=36)
            stats = compare(scene_of(words, options), options)
            assert stats.hits + stats.nan_rays > 0 and stats.shadow_rays == 0
