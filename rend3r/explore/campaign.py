"""The tasks of an exploration campaign, each a pure function of plain values.

A task renders one program in one format (:func:`render_design`, the fp64 references), or
renders it in a batch of designs and scores each against the reference
(:func:`score_designs`; :func:`batches` cuts the work into such tasks); :func:`design_cost`
costs a format. Inputs are program words and options, outputs plain dataclasses of
numbers, so a distributed runner can ship them to workers as they are.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..precision.datapath import Resources

#: The reference every design is scored against.
REFERENCE = "fp64"

#: Designs of one program rendered by one task, at most: a render takes milliseconds at
#: small sizes, where Dask's one to two milliseconds a task (and the GIL its bookkeeping
#: takes from the tasks on a local cluster) would cost several percent, and Dask's guidance
#: is tasks well above that. A task holds fewer designs of a larger program (words x frames
#: x pixels, the best guess of a render's work before rendering, over BATCH_WORK), and one
#: alone when a render may take seconds, so that Ctrl-C, which waits for the tasks
#: running, waits for one render at most.
BATCH, BATCH_WORK = 4, 1 << 26


@dataclass(frozen=True)
class ProgramSpec:
    """A loaded program: its words, the mode it renders in and the frames to render."""

    name: str
    words: tuple[int, ...]
    mode: str
    frames: int


@dataclass(frozen=True)
class Rendering:
    """One program rendered in one format: every frame's RGB565 and provenance, stacked."""

    rgb565: np.ndarray  # (frames * H, W) uint16
    provenance: np.ndarray  # (frames * H, W) int32, -1 = miss


@dataclass(frozen=True)
class Score:
    """How far a design's rendering is from the fp64 one."""

    psnr: float  # dB over every channel of every frame; inf when identical
    max_channel: int  # largest channel difference, 0..255 (RGB888)
    differing: float  # share of pixels with any channel different
    provenance: float  # share of pixels whose nearest shape differs (or hit against miss)
    interior_provenance: float  # the same share among pixels off every silhouette of fp64


def render_design(program: ProgramSpec, precision: str, subnormals: str, width: int, height: int,
                  jobs: int = 0) -> Rendering:
    """Render ``program`` in the design ``precision``: a working format for every operation,
    or a base format with formats per stage (:func:`.search.split_design`)."""
    from ..emu import EmuOptions, run_program
    from ..errors import Rend3rError
    from .search import split_design

    base, stages = split_design(precision)
    options = EmuOptions(precision=base, stage_precision=stages, subnormals=subnormals, mode=program.mode,  # type: ignore[arg-type]
                         width=width, height=height, jobs=jobs)
    frames = run_program(list(program.words), options=options, frames=program.frames).frames
    if not frames:
        raise Rend3rError(f"{program.name}: rendered no frame (no nf before the program ends)")
    return Rendering(np.concatenate([f.rgb565 for f in frames]), np.concatenate([f.provenance for f in frames]))


def score_design(reference: Rendering, design: Rendering) -> Score:
    """Colour and nearest-shape differences of ``design`` against ``reference``."""
    from ..golden.metrics import image_metrics, interior_mask

    colour = image_metrics(reference.rgb565, design.rgb565)
    differs = reference.provenance != design.provenance
    interior = interior_mask(reference.provenance)
    inside = int(interior.sum())
    return Score(
        psnr=colour.psnr, max_channel=colour.max_channel, differing=colour.share_differing,
        provenance=float(differs.mean()),
        interior_provenance=float(differs[interior].sum() / inside) if inside else 0.0,
    )


def render_and_score(program: ProgramSpec, precision: str, reference: Rendering, subnormals: str, width: int,
                     height: int, jobs: int = 0) -> Score:
    """Render ``program`` in ``precision`` and score it against ``reference`` (its fp64
    rendering), so only the score travels back from a worker."""
    return score_design(reference, render_design(program, precision, subnormals, width, height, jobs))


def score_designs(program: ProgramSpec, designs: tuple[str, ...], reference: Rendering, subnormals: str,
                  width: int, height: int, jobs: int = 0) -> list[Score]:
    """One campaign task: :func:`render_and_score` for each of ``designs``, in order."""
    return [render_and_score(program, d, reference, subnormals, width, height, jobs) for d in designs]


def batches(pairs: list[tuple[ProgramSpec, str]], pixels: int) -> list[tuple[ProgramSpec, tuple[str, ...]]]:
    """The (program, design) pairs as tasks of designs of one program (:data:`BATCH`), the
    largest programs first, so that their long renders start early rather than finish last."""
    per_program: dict[str, tuple[ProgramSpec, list[str]]] = {}
    for spec, design in pairs:
        per_program.setdefault(spec.name, (spec, []))[1].append(design)
    work = {name: len(spec.words) * spec.frames * pixels for name, (spec, _) in per_program.items()}
    tasks = []
    for name, (spec, designs) in per_program.items():
        size = max(1, min(BATCH, BATCH_WORK // max(1, work[name])))
        tasks += [(spec, tuple(designs[k:k + size])) for k in range(0, len(designs), size)]
    return sorted(tasks, key=lambda task: -work[task[0].name])  # stable: ties keep their order


def design_cost(precision: str) -> Resources:
    """Modelled cost of a device whose raytrace and raster datapaths both work in the design
    ``precision``'s base format, each raytrace stage of its map in that stage's format
    (:mod:`rend3r.precision.datapath` counts per stage, :mod:`rend3r.precision.cost` per unit)."""
    from ..precision.datapath import raster_counts, raytrace_counts
    from ..precision.formats import parse
    from .search import split_design

    base, stages = split_design(precision)
    fmt = parse(base)
    return raytrace_counts().cost(fmt, {s: parse(p) for s, p in stages}) + raster_counts().cost(fmt)


def cheapest(scores: dict[str, Score], costs: dict[str, Resources], min_psnr: float) -> str | None:
    """The cheapest format whose PSNR is at least ``min_psnr``; None when none is."""
    meeting = [f for f, s in scores.items() if s.psnr >= min_psnr]
    return min(meeting, key=lambda f: costs[f].key) if meeting else None


def worst_psnr(scores: list[Score]) -> float:
    """The lowest PSNR of a format over the programs (inf when every one is identical)."""
    return min((s.psnr for s in scores), default=math.inf)
