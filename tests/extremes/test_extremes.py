"""Scenes near the limits of float16: the emulator never fails, never leaves an undefined
pixel, is deterministic, and for well-conditioned scenes fp16 agrees with fp64 on hit/miss
away from silhouettes (defined in ``test_fp16_agrees_with_fp64_away_from_silhouettes``)."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from rend3r.emu import EmuOptions, run_program
from rend3r.golden.metrics import interior_mask

from .scenes import SceneSpec, axis_angle

W, H = 32, 24
BACKGROUND = 0b00001_000010_00001  # distinct from black, so unlit hits and misses differ

#: float16 values at the edges: largest, around the smallest normal, subnormals, zeros.
EDGE_VALUES = [
    65504.0, -65504.0, 65000.0, 32768.0, 256.0, 255.9, 181.0, 6.103515625e-05, 6.0e-05,
    3.0e-05, 5.960464477539063e-08, 1e-7, 0.0, -0.0, 1.0, -1.0, 0.5, 1e-3, 1e-4,
]
#: Raw bit patterns a program can write: inf, -inf, NaN, the largest subnormal.
RAW = [("raw", 0x7C00), ("raw", 0xFC00), ("raw", 0x7E00), ("raw", 0x03FF)]

edge = st.one_of(st.sampled_from(EDGE_VALUES), st.floats(-65504, 65504, width=16, allow_subnormal=True))
edge_or_raw = st.one_of(edge, st.sampled_from(RAW))


def _check_frames(words: list[int], options: EmuOptions, shapes: int) -> list:
    """Run twice: no exception, identical results, every pixel defined and consistent."""
    first = run_program(words, options=options, frames=1).frames
    second = run_program(words, options=options, frames=1).frames
    assert len(first) == 1
    for a, b in zip(first, second, strict=True):
        assert a.rgb565.shape == (H, W) and a.rgb565.dtype == np.uint16
        assert np.array_equal(a.rgb565, b.rgb565)
        assert np.array_equal(a.provenance, b.provenance)
        assert np.array_equal(a.depth, b.depth, equal_nan=False)
        assert not np.isnan(a.depth).any(), "depth must never be NaN"
        assert ((a.provenance >= -1) & (a.provenance < max(shapes, 1))).all()
        miss = a.provenance < 0
        assert np.isinf(a.depth[miss]).all() and np.isfinite(a.depth[~miss]).all()
        assert (a.rgb565[miss] == BACKGROUND).all()
    return first


@st.composite
def extreme_scene(draw: st.DrawFn) -> tuple[list[int], int]:
    """A camera, up to two lights and up to three shapes with edge values anywhere."""
    spec = SceneSpec()
    for name in draw(st.lists(st.sampled_from(["xloc", "yloc", "zloc", "rrot", "irot", "jrot", "krot", "nclip", "fclip", "hfov", "vfov"]), max_size=5, unique=True)):
        spec.camera[name] = draw(edge_or_raw)
    for _ in range(draw(st.integers(0, 2))):
        light = {"src": draw(st.integers(0, 3)), "col": draw(st.integers(0, 0xFFFF)), "int": draw(edge)}
        for name in ("xloc", "yloc", "zloc", "xfor", "yfor", "zfor"):
            light[name] = draw(edge_or_raw)
        spec.lights.append(light)
    n = draw(st.integers(1, 3))
    for _ in range(n):
        shape = {"type": draw(st.integers(0, 15)), "col": draw(st.integers(0, 0xFFFF)), "mat": draw(st.integers(0, 3))}
        for name in ("xloc", "yloc", "zloc", "rrot", "irot", "jrot", "krot", "xscl", "yscl", "zscl"):
            shape[name] = draw(st.one_of(edge_or_raw, st.floats(-8, 8, width=16)))
        spec.shapes.append(shape)
    return spec.words(), n


@settings(max_examples=40)
@given(extreme_scene(), st.sampled_from([("fp16", "ftz"), ("fp16", "ieee"), ("fp32", "ftz"), ("fp64", "ftz")]))
def test_extreme_scenes_are_defined_and_deterministic(scene: tuple[list[int], int], mode: tuple[str, str]) -> None:
    words, n = scene
    options = EmuOptions(precision=mode[0], subnormals=mode[1], width=W, height=H, background=BACKGROUND)
    _check_frames(words, options, n)


def _named_scenes() -> dict[str, SceneSpec]:
    """The hand-made extremes the issue names, each a scene that must render cleanly."""
    light = {"src": 1, "xfor": -1, "yfor": -1, "zfor": -1, "col": 0xFFFF, "int": 1}
    unit = {"rrot": 1, "xscl": 1, "yscl": 1, "zscl": 1, "col": 0xFFFF}
    return {
        "camera inside a sphere": SceneSpec({"rrot": 1}, [light], [{**unit, "type": 1, "xscl": 0.25, "yscl": 0.25, "zscl": 0.25}]),
        "grazing sphere": SceneSpec({"rrot": 1}, [light], [{**unit, "type": 1, "xloc": 5.0, "zloc": -1.0}]),
        "ray along cylinder axis": SceneSpec({"rrot": 1}, [light], [{**unit, "type": 2}]),
        "cone apex on the view axis": SceneSpec({"rrot": 1}, [light], [{**unit, "type": 3, "zloc": -4}]),
        "light parallel to a cylinder": SceneSpec({"rrot": 1}, [{**light, "xfor": 0, "yfor": 0, "zfor": -1}], [{**unit, "type": 2, "zloc": -3}]),
        "coordinates near 65504": SceneSpec({"rrot": 1, "zloc": 65504}, [light], [{**unit, "type": 1, "zloc": 65000, "xscl": 1e-3}]),
        "overflowing inverse scale": SceneSpec({"rrot": 1}, [light], [{**unit, "type": 1, "zloc": -3, "xscl": 65504, "yscl": 65504, "zscl": 65504}]),
        "subnormal inverse scales": SceneSpec({"rrot": 1}, [light], [{**unit, "type": 1, "zloc": -3, "xscl": 3e-5, "yscl": 6e-8, "zscl": 1}]),
        "zero quaternion": SceneSpec({}, [light], [{"type": 1, "zloc": -3, "xscl": 1, "yscl": 1, "zscl": 1}]),
        "non-unit quaternion": SceneSpec({"rrot": 300}, [light], [{**unit, "type": 1, "zloc": -3, "rrot": 250, "irot": 0.001}]),
    }


def test_named_extremes_render_cleanly() -> None:
    for name, spec in _named_scenes().items():
        for precision, sub in (("fp16", "ftz"), ("fp16", "ieee"), ("fp64", "ftz")):
            options = EmuOptions(precision=precision, subnormals=sub, width=W, height=H, background=BACKGROUND)
            try:
                _check_frames(spec.words(), options, len(spec.shapes))
            except AssertionError as exc:
                raise AssertionError(f"{name} ({precision}-{sub}): {exc}") from exc


@st.composite
def well_conditioned_scene(draw: st.DrawFn) -> SceneSpec:
    """Shapes whose ray equations stay well-conditioned in float16 over the whole view.

    Ellipsoids (any rotation, semi-axes 1 to 2, 3 to 5 units ahead: object-space
    distances |S^| below 6, so the discriminant keeps a relative error of a few per cent)
    and cylinders whose axis lies in a plane parallel to the screen (turned 90 degrees
    about x, then rolled about z), so no ray runs along an axis. Cones are left out: rays
    through or beside the apex are ill-conditioned by nature (a double root); they are
    covered by the no-failure properties above.
    """
    spec = SceneSpec({"rrot": 1}, [{"src": 1, "xfor": -1, "yfor": -1, "zfor": -1, "col": 0xFFFF, "int": 1}])
    for _ in range(draw(st.integers(1, 3))):
        kind = draw(st.sampled_from([1, 2]))
        if kind == 1:
            axis = (draw(st.floats(-1, 1)), draw(st.floats(-1, 1)), draw(st.floats(0.1, 1)))
            rotation = axis_angle(axis, draw(st.floats(-180, 180)))
        else:
            roll = math.radians(draw(st.floats(-90, 90)))
            # rot(z, roll) * rot(x, 90): the cylinder's z axis turned into the screen plane
            c, s_ = math.cos(roll / 2) * math.sqrt(0.5), math.sin(roll / 2) * math.sqrt(0.5)
            rotation = {"rrot": c, "irot": c, "jrot": s_, "krot": s_}
        spec.shapes.append(
            {
                "type": kind,
                "col": draw(st.integers(1, 0xFFFF)),
                "xloc": draw(st.floats(-2, 2)),
                "yloc": draw(st.floats(-1.5, 1.5)),
                "zloc": draw(st.floats(-5, -3)),
                **rotation,
                "xscl": draw(st.floats(0.5, 1)),
                "yscl": draw(st.floats(0.5, 1)),
                "zscl": draw(st.floats(0.5, 1)),
            }
        )
    return spec


def _scaled(spec: SceneSpec, factor: float) -> SceneSpec:
    """The scene with every shape's size multiplied by ``factor`` (inverse scales divided)."""
    shapes = [{**sh, **{k: sh[k] / factor for k in ("xscl", "yscl", "zscl")}} for sh in spec.shapes]
    return SceneSpec(spec.camera, spec.lights, shapes)


#: Relative size change that defines "away from silhouettes" (see the test below).
MARGIN = 0.05


@settings(max_examples=25)
@given(well_conditioned_scene())
def test_fp16_agrees_with_fp64_away_from_silhouettes(spec: SceneSpec) -> None:
    """Away from silhouettes, fp16 and fp64 agree on hit/miss.

    A pixel is away from silhouettes when its fp64 hit/miss does not change if every shape
    grows or shrinks by 5% (a hit in the shrunk scene, or a miss in the grown one); the 3x3
    neighbourhood rule of ``interior_mask`` is also required. 5% covers the float16 error
    of the discriminant for these scenes with a margin of about two.
    """

    def provenance(s: SceneSpec, precision: str) -> np.ndarray:
        options = EmuOptions(precision=precision, width=W, height=H, background=BACKGROUND)
        return run_program(s.words(), options=options, frames=1).frames[0].provenance

    ref = provenance(spec, "fp64")
    sure_hit = provenance(_scaled(spec, 1 - MARGIN), "fp64") >= 0
    sure_miss = provenance(_scaled(spec, 1 + MARGIN), "fp64") < 0
    away = (sure_hit | sure_miss) & interior_mask(ref)
    hit16 = provenance(spec, "fp16") >= 0
    disagree = away & (hit16 != (ref >= 0))
    assert not disagree.any(), f"fp16 hit/miss differs from fp64 at pixels {np.argwhere(disagree)[:5].tolist()}"
