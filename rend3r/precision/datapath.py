"""Operation counts of the emulator's datapaths, taken from the emulator's own code.

The count runs the datapath itself on a 1x1 frame with one shape (or one triangle) and
one point light, through an :class:`~rend3r.emu.arith.Arith` that counts its calls. Each
call on arrays is one hardware unit of a fully pipelined datapath (every operation of
``docs/emulator.md`` section 4 its own adder, multiplier, divider or square root), so the
counts are the units such a datapath instantiates: for the raytracer, one ray against one
shape, then per light the lighting and one shadow test; for the rasterizer, one
triangle's set-up and one pixel. Raytracer units are counted per stage of
:data:`rend3r.precision.stages.STAGES` (the table the staged arithmetic reads, so a
design with a format per stage is costed stage by stage; a shadow test's units are in
the transform to square-root stages, as in the kernels); the rasterizer's per function. A datapath that shares units between steps needs fewer. Rotations use a quaternion that is not the identity, so the
emulator's identity short cut (``vec.rotate_inverse``) does not skip their units;
negation (a sign flip) and comparisons are not counted.
"""

from __future__ import annotations

import sys
from collections import Counter
from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import cache
from types import FrameType
from typing import TYPE_CHECKING

import numpy as np

from .cost import operator_cost
from .formats import FloatFormat
from .stages import current_stage

if TYPE_CHECKING:
    from ..emu.options import Mode

#: The operators counted, as :func:`rend3r.precision.cost.operator_cost` names them
#: (subtraction is counted as an adder).
COUNTED = ("add", "mul", "div", "sqrt")


_RAY_SCENE = """
nr
cam rrot, 1
cam irot, 0.03125
lt 0, src, 2
lt 0, xloc, 2
lt 0, yloc, 2
lt 0, zloc, 1
lt 0, col, 0xFFFF
lt 0, int, 1
sp 0, type, col, 1, 0xFFFF
sp 0, xloc, yloc, 0, 0
sp 0, zloc, rrot, -4, 1
sp 0, irot, jrot, 0.25, 0.125
sp 0, xscl, yscl, 1, 1
sp 0, zscl, mat, 1, 0
nf
er
er
"""

_RASTER_SCENE = """
nr
cam rrot, 1
cam irot, 0.03125
lt 0, src, 2
lt 0, zloc, 1
lt 0, col, 0xFFFF
lt 0, int, 1
tr 0, x1, y1, -1, -1
tr 0, z1, x2, -4, 1
tr 0, y2, z2, -1, -4
tr 0, x3, y3, 0, 1
tr 0, z3, col, -4, 0xFFFF
nf
er
er
"""


@dataclass(frozen=True)
class Resources:
    """FPGA resources of a set of units: LUTs, flip-flops and DSP48E1 slices."""

    lut: int
    ff: int
    dsp: int

    def __add__(self, other: Resources) -> Resources:
        return Resources(self.lut + other.lut, self.ff + other.ff, self.dsp + other.dsp)

    @property
    def key(self) -> tuple[int, int, int]:
        """Ranking: fewer LUTs first, then DSP48E1 slices, then flip-flops."""
        return self.lut, self.dsp, self.ff


@dataclass(frozen=True)
class OperationCounts:
    """Units of each operator in one datapath, in total and per stage."""

    total: dict[str, int]
    stages: dict[str, dict[str, int]]

    def cost(self, fmt: FloatFormat, stages: Mapping[str, FloatFormat] | None = None) -> Resources:
        """The datapath's units in ``fmt``, those of a stage in ``stages`` in its format: each
        unit's modelled LUT, FF and DSP, summed."""
        formats = stages or {}
        parts = [(n, operator_cost(op, formats.get(stage, fmt)))
                 for stage, ops in self.stages.items() for op, n in ops.items()]
        return Resources(*(sum(n * getattr(c, f) for n, c in parts) for f in ("lut", "ff", "dsp")))


def _counting_arith():
    """An Arith (fp64) that counts its add/sub/mul/div/sqrt calls per operator and stage."""
    from ..emu.arith import Arith

    @dataclass(frozen=True)
    class CountingArith(Arith):
        counts: Counter = field(default_factory=Counter, compare=False)

        def _count(self, op: str) -> None:
            self.counts[(_stage(), op)] += 1

        def add(self, a, b):
            self._count("add")
            return super().add(a, b)

        def sub(self, a, b):
            self._count("add")
            return super().sub(a, b)

        def mul(self, a, b):
            self._count("mul")
            return super().mul(a, b)

        def div(self, a, b):
            self._count("div")
            return super().div(a, b)

        def sqrt(self, a):
            self._count("sqrt")
            return super().sqrt(a)

    return CountingArith("fp64", False)


def _stage() -> str:
    """The stage of the datapath the current Arith call is made in: its raytrace stage
    (:func:`~rend3r.precision.stages.current_stage`), else the innermost function of the
    rasterizer's modules."""
    stage = current_stage(3)  # from the counting method up
    if stage is not None:
        return stage
    frame: FrameType | None = sys._getframe(3)
    while frame is not None:
        name = frame.f_code.co_name
        if name == "diffuse":  # the lighting the raytracer shares
            return "lighting"
        if frame.f_globals.get("__name__", "").startswith("rend3r.emu.raster") and not name.startswith("<"):
            return name.lstrip("_")
        frame = frame.f_back
    return "scene"


def _scene(source: str):
    from ..asm.assembler import assemble_source
    from ..emu.options import EmuOptions
    from ..emu.run import run_program

    result = assemble_source(source, "<datapath>")
    errors = [d.message for d in result.diagnostics if d.severity == "error"]
    if errors:
        raise AssertionError(f"the counting scene does not assemble: {errors}")
    words = list(result.program.words)
    scenes = []
    run_program(words, EmuOptions(precision="fp64", width=1, height=1), on_scene=lambda s, n: scenes.append(s),
                keep_frames=False)
    return scenes[0]


def _count(render, source: str, mode: Mode) -> OperationCounts:
    from ..emu.options import EmuOptions

    ar = _counting_arith()

    @dataclass(frozen=True)
    class CountingOptions(EmuOptions):
        @property
        def arith(self):
            return ar

    frame = render(_scene(source), CountingOptions(precision="fp64", mode=mode, width=1, height=1))
    if isinstance(frame, tuple):
        frame = frame[0]
    if int(np.asarray(frame.provenance).ravel()[0]) < 0:
        raise AssertionError(f"the {mode} counting scene missed its shape")
    total: Counter = Counter()
    stages: dict[str, Counter] = {}
    for (stage, op), n in ar.counts.items():
        total[op] += n
        stages.setdefault(stage, Counter())[op] += n
    order = lambda c: {op: c[op] for op in COUNTED if c[op]}
    return OperationCounts(order(total), {s: order(c) for s, c in stages.items()})


@cache
def raytrace_counts() -> OperationCounts:
    """Units of the raytracer: one ray, one shape, one point light with its shadow test."""
    from ..emu.reference import render_reference

    return _count(render_reference, _RAY_SCENE, "raytrace")


@cache
def raster_counts() -> OperationCounts:
    """Units of the rasterizer: one triangle, one pixel, one point light."""
    from ..emu.raster import render_frame

    return _count(render_frame, _RASTER_SCENE, "raster")
