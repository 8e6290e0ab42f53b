"""Triangles near float16 limits, of zero area or edge-on: the rasterizer never fails,
leaves no pixel undefined, is deterministic, and a triangle with a repeated vertex covers
nothing."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from rend3r.emu import EmuOptions, run_program

from .scenes import SceneSpec
from .test_extremes import BACKGROUND, EDGE_VALUES, H, RAW, W

coord = st.one_of(st.sampled_from(EDGE_VALUES), st.floats(-20, 20, width=16), st.sampled_from(RAW))
vertex = st.tuples(coord, coord, coord)
MODES = [("fp16", "ftz"), ("fp16", "ieee"), ("fp64", "ftz")]


def _triangle(v1, v2, v3, col: int) -> dict:
    names = ("x1", "y1", "z1", "x2", "y2", "z2", "x3", "y3", "z3")
    return {**dict(zip(names, (*v1, *v2, *v3), strict=True)), "col": col}


@st.composite
def degenerate_triangle(draw: st.DrawFn) -> dict:
    """Zero-area (collinear or repeated vertices), edge-on (in the plane y = 0, which holds
    the camera) or arbitrary triangles with extreme coordinates."""
    kind = draw(st.sampled_from(["collinear", "repeated", "edge-on", "any"]))
    if kind == "collinear":
        finite = st.tuples(*[st.floats(-20, 20, width=16)] * 3)
        v1, v2, k = draw(finite), draw(finite), draw(st.floats(-4, 4))
        v3 = tuple(a + k * (b - a) for a, b in zip(v1, v2, strict=True))
    elif kind == "repeated":
        v1, v2 = draw(vertex), draw(vertex)
        v3 = v1
    elif kind == "edge-on":
        v1, v2, v3 = ((x, 0.0, z) for x, _, z in (draw(vertex), draw(vertex), draw(vertex)))
    else:
        v1, v2, v3 = draw(vertex), draw(vertex), draw(vertex)
    return _triangle(v1, v2, v3, draw(st.integers(0, 0xFFFF)))


def _render(spec: SceneSpec, mode: tuple[str, str]):
    options = EmuOptions(mode="raster", precision=mode[0], subnormals=mode[1], width=W, height=H, background=BACKGROUND)
    return run_program(spec.words(), options=options, frames=1).frames[0]


@settings(max_examples=40)
@given(st.lists(degenerate_triangle(), min_size=1, max_size=4), st.sampled_from(MODES))
def test_degenerate_triangles_render_cleanly(triangles: list[dict], mode: tuple[str, str]) -> None:
    spec = SceneSpec({"rrot": 1}, [{"src": 1, "xfor": -1, "yfor": -1, "zfor": -1}], triangles=triangles)
    a, b = _render(spec, mode), _render(spec, mode)
    assert np.array_equal(a.rgb565, b.rgb565) and np.array_equal(a.provenance, b.provenance)
    assert a.rgb565.shape == (H, W) and not np.isnan(a.depth).any()
    assert ((a.provenance >= -1) & (a.provenance < len(triangles))).all()
    assert (a.rgb565[a.provenance < 0] == BACKGROUND).all()


@settings(max_examples=20)
@given(vertex, vertex, st.sampled_from(MODES))
def test_triangle_with_a_repeated_vertex_covers_nothing(v1, v2, mode: tuple[str, str]) -> None:
    spec = SceneSpec({"rrot": 1}, triangles=[_triangle(v1, v2, v1, 0xFFFF)])
    frame = _render(spec, mode)
    assert (frame.provenance == -1).all()
