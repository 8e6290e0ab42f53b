"""The raytrace datapath's stages (``docs/trace.md``) and a format per stage.

One table says which stage every operation of the datapath belongs to:
:data:`FUNCTION_STAGES`, keyed by the emulator function (``rend3r/emu``) the operation is
made in, the innermost such function on the call stack deciding. The Python reference's
staged arithmetic (:class:`rend3r.emu.arith.Arith` with stages) and the operation counts
(:mod:`.datapath`) both read it; the compiled format kernels mark the same functions with
``STAGE(STAGE_...)`` (``csrc/datapath.inc``, the enum in ``csrc/fformat.h`` is
:data:`STAGES` in order, checked by ``tests/precision/test_stages.py``), and the
differential test holds the two to the same bits. :data:`VALUE_STAGES` gives each traced
value's stage, for traces in each stage's format.

A value that crosses from one stage to the next enters the consuming stage through a
converter: every operation rounds its operands to its stage's format (correctly rounded,
with that format's subnormal mode) before it computes. Rounding a value already in the
format changes nothing, so a uniform map is the plain working precision.
"""

from __future__ import annotations

import sys
from types import FrameType

#: The stages, in datapath order (also the C enum's order).
STAGES: tuple[str, ...] = ("camera", "transform", "quadratic", "discriminant", "sqrt", "distance", "hit",
                           "lighting", "colour")

#: What each stage computes (for help texts and docs).
DESCRIPTIONS: dict[str, str] = {
    "camera": "camera rays: viewport axes, the camera quaternion's normalisation, rotated directions",
    "transform": "ray origin and direction into each shape's normal space",
    "quadratic": "the quadratic's terms a2, b, c2",
    "discriminant": "b*b - a2*c2",
    "sqrt": "the square root of the discriminant and the roots t1, t2",
    "distance": "|d|^2 and sq_dist = |d|^2 t^2",
    "hit": "world hit point and normal",
    "lighting": "light vector, n.l, lengths, cos",
    "colour": "the light factor f = cos * intensity",
}

#: Emulator function -> stage of the operations made in it (innermost listed function wins).
FUNCTION_STAGES: dict[str, str] = {
    "camera_rays": "camera", "direction": "camera",
    "to_object": "transform",
    "origin_term": "quadratic", "direction_term": "quadratic", "solve": "quadratic",
    "discriminant": "discriminant",
    "roots": "sqrt",
    "squared_distance": "distance", "render_reference": "distance",  # |d|^2 is computed by the caller
    "surface": "hit",
    "lights_from_scene": "lighting", "diffuse": "lighting",
    "light_factor": "colour",
}

#: Traced value name (``docs/trace.md``, the part after ``L<k>.``) -> its stage.
VALUE_STAGES: dict[str, str] = {
    **{f"{v}.{a}": "transform" for v in ("origin", "dir") for a in "xyz"},
    "a2": "quadratic", "b": "quadratic", "c2": "quadratic", "disc": "discriminant",
    "sqrt": "sqrt", "t1": "sqrt", "t2": "sqrt", "t": "sqrt", "sq_dist": "distance",
    **{f"{v}.{a}": "hit" for v in ("point", "normal") for a in "xyz"},
    **{f"l.{a}": "lighting" for a in "xyz"},
    "n_dot_l": "lighting", "n_len": "lighting", "l_len": "lighting", "denom": "lighting", "cos": "lighting",
    "f": "colour",
}

_MAX_TEXT = 400  # longest --stage-precision value read


def parse_stage_map(text: str) -> tuple[tuple[str, str], ...]:
    """``STAGE=FORMAT[,...]`` -> ((stage, canonical precision name), ...) in stage order.

    ValueError naming what is wrong (an unknown or repeated stage, a bad format, a format
    with a subnormal suffix: the mode is ``--subnormals``'s for every stage).
    """
    from ..emu.arith import precision_name

    if len(text) > _MAX_TEXT:
        raise ValueError(f"--stage-precision is {len(text)} characters long, at most {_MAX_TEXT} are read")
    out: dict[str, str] = {}
    for item in filter(None, (part.strip() for part in text.split(","))):
        stage, eq, fmt = (p.strip() for p in item.partition("="))
        shown = item if len(item) <= 40 else item[:37] + "..."
        if not eq or not stage or not fmt:
            raise ValueError(f"expected STAGE=FORMAT, not {shown!r}")
        if stage not in STAGES:
            raise ValueError(f"unknown stage {stage[:40]!r}: the stages are {', '.join(STAGES)}")
        if stage in out:
            raise ValueError(f"stage {stage} given twice")
        out[stage] = precision_name(fmt)
    if not out:
        raise ValueError("expected STAGE=FORMAT[,...], e.g. discriminant=e8m15,lighting=fp16")
    return tuple((s, out[s]) for s in STAGES if s in out)


def stage_text(stages: tuple[tuple[str, str], ...]) -> str:
    """The ``--stage-precision`` text of a stage map (``""`` for none)."""
    return ",".join(f"{s}={p}" for s, p in stages)


def current_stage(depth: int = 2) -> str | None:
    """The stage of the operation being made: the innermost function of
    :data:`FUNCTION_STAGES` on the call stack above ``depth`` frames; None outside them,
    and inside the rasterizer (its datapath stays in the base precision, even where it
    shares the lighting's functions)."""
    frame: FrameType | None = sys._getframe(depth)
    stage = None
    while frame is not None:
        module = frame.f_globals.get("__name__", "")
        if module.startswith("rend3r.emu.raster"):
            return None
        if stage is None and module.startswith("rend3r.emu."):
            stage = FUNCTION_STAGES.get(frame.f_code.co_name)
        frame = frame.f_back
    return stage
