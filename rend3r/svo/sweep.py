"""Design-space sweeps like the thesis's Tables 7.1 (cache miss rates) and 8.2 (frame
times), run as a campaign (:mod:`rend3r.campaign.runner`, ``docs/campaigns.md``).

Each stack depth is traced once in every view with its memory requests recorded (a task
per stack, :func:`trace_stack`, whose traces stay on the worker); every (stack, cache) pair
is then simulated (a task per pair, :func:`evaluate`, given its stack's traces), and the
frame-time model is evaluated for each core count and scheduling policy of that pair.
"""

from __future__ import annotations

import csv
import io
from dataclasses import asdict, dataclass

import numpy as np

from ..campaign.runner import Campaign
from ..progress import ProgressFactory, hidden
from .cache import CacheConfig, simulate
from .camera import orbit_camera
from .cores import Platform, compute_cycles, frame_time
from .fileformat import SvoModel
from .render import render
from .traverse import Kernel


@dataclass(frozen=True)
class DesignPoint:
    stack: int
    cache: int
    block: int
    ways: int
    max_level: int | None
    cores: int
    policy: str = "round-robin"


def thesis_points() -> list[DesignPoint]:
    """The design points of Tables 7.1 and 8.2 A-E, plus a scheduling-policy comparison."""
    pts: set[DesignPoint] = set()
    for size in (32, 128, 512):  # Table 7.1
        for block in (1, 2, 4, 8):
            for ways in (1, 2, 4):
                pts.add(DesignPoint(8, size, block, ways, None, 1))
    for size in (8, 32, 128, 512):
        for lvl in (2, 4, 6, 8):
            pts.add(DesignPoint(8, size, 1, 2, lvl, 1))
    for size in (128, 512, 1024):  # 8.2 A
        for block in (1, 4, 8, 16):
            pts.add(DesignPoint(8, size, block, 1, None, 2))
    for stack in (0, 2, 4, 8, 16):  # 8.2 B, C
        for size in (0, 128, 512, 1024):
            pts.add(DesignPoint(stack, size, 1, 1, None, 2))
        for cores in (1, 2, 3, 4):
            pts.add(DesignPoint(stack, 128, 1, 1, None, cores))
    for cores in (1, 2, 3, 4):  # 8.2 D, E, and the policies
        for size in (0, 128, 512, 1024):
            pts.add(DesignPoint(8, size, 1, 1, None, cores))
        for size in (128, 512, 1024):
            pts.add(DesignPoint(8, size, 1, 2, None, cores))
        for policy in ("round-robin", "first-available"):
            pts.add(DesignPoint(8, 128, 1, 1, None, cores, policy))
    return sorted(pts, key=lambda p: (p.stack, p.cache, p.block, p.ways, p.max_level or 0,
                                      p.cores, p.policy))


Trace = dict[str, np.ndarray]
"""One view's per-ray compute cycles and requests, and its memory requests in ray order."""

Job = tuple[int, int, int, int, "int | None", tuple[tuple[int, str], ...]]
"""(stack, cache size, block, ways, max level, ((cores, policy), ...)): one simulation task."""


def trace_stack(model: SvoModel, stack: int, views: int, width: int, height: int, kernel: Kernel) -> list[Trace]:
    """Task: ``model`` traced with a ``stack``-deep short stack from each of ``views`` azimuths."""
    out = []
    for v in range(views):
        cam = orbit_camera(model.bounds, azimuth=35.0 + 360.0 * v / views, width=width, height=height)
        res = render(model, cam, stack, True, "depth", record=True, kernel=kernel).result
        out.append({
            "compute": compute_cycles(res.steps, res.descents, res.pops, res.restarts, res.requests),
            "requests": res.requests, "ray": res.trace_ray, "addr": res.trace_addr,
            "level": res.trace_level,
        })
    return out


def evaluate(job: Job, traces: list[Trace]) -> list[dict]:
    """Task: one (stack, cache) pair over all its (cores, policy) combinations, on its
    stack's ``traces``."""
    stack, size, block, ways, max_level, runs = job
    cfg = CacheConfig(size, block, ways, max_level)
    per_view = []
    for tr in traces:
        hits = simulate(tr["addr"], tr["level"], cfg)
        misses = np.bincount(tr["ray"][~hits], minlength=len(tr["compute"])).astype(np.float64)
        per_view.append((tr, hits, misses))
    rows = []
    for cores, policy in runs:
        frames = [frame_time(tr["compute"], misses, block, cores, policy, Platform())
                  for tr, _, misses in per_view]
        n_acc = sum(len(h) for _, h, _ in per_view)
        rows.append({
            **asdict(DesignPoint(stack, size, block, ways, max_level, cores, policy)),
            "miss_rate": round(1 - sum(int(h.sum()) for _, h, _ in per_view) / max(n_acc, 1), 4),
            "requests_per_ray": round(float(np.mean([tr["requests"].mean() for tr, _, _ in per_view])), 3),
            "frame_ms": round(1e3 * float(np.mean([f["frame_s"] for f in frames])), 1),
            "rays_per_s": round(float(np.mean([f["rays_per_s"] for f in frames]))),
            "bus_utilisation": round(float(np.mean([f["bus_utilisation"] for f in frames])), 3),
        })
    return rows


def run_sweep(model: SvoModel, points: list[DesignPoint], campaign: Campaign, width: int = 320,
              height: int = 240, views: int = 1, progress: ProgressFactory = hidden,
              kernel: Kernel = "auto") -> list[dict]:
    """Evaluate ``points`` as tasks of ``campaign`` (entered); one row per point (see
    :data:`COLUMNS`), the same wherever the tasks ran.

    ``kernel`` traces the frames (:func:`rend3r.svo.traverse.resolve_kernel`; the rows do
    not depend on it). ``progress(total, label)`` makes the bars of the two stages, in
    tasks: tracing (a stack depth each) and simulating (a (stack, cache) pair each).
    """
    stacks = sorted({p.stack for p in points})
    with progress(len(stacks), "tracing") as bar:
        traced = campaign.map(trace_stack, [(model, s, views, width, height, kernel) for s in stacks],
                              [f"tracing stack {s}" for s in stacks], bar, keep=True)
    traces = dict(zip(stacks, traced))
    groups: dict[tuple, list[tuple[int, str]]] = {}
    for p in points:
        groups.setdefault((p.stack, p.cache, p.block, p.ways, p.max_level), []).append((p.cores, p.policy))
    jobs = [key + (tuple(runs),) for key, runs in groups.items()]
    names = [f"stack {j[0]}, cache {j[1]}x{j[2]} {j[3]}-way" + (f" to level {j[4]}" if j[4] is not None else "")
             for j in jobs]
    with progress(len(jobs), "simulating") as bar:
        results = campaign.map(evaluate, [(j, traces[j[0]]) for j in jobs], names, bar)
    return [row for rows in results for row in rows]


COLUMNS = ["stack", "cache", "block", "ways", "max_level", "cores", "policy", "miss_rate",
           "requests_per_ray", "frame_ms", "rays_per_s", "bus_utilisation"]


def to_csv(rows: list[dict]) -> str:
    buf = io.StringIO()
    writer = csv.DictWriter(buf, COLUMNS, lineterminator="\n")
    writer.writeheader()
    for row in rows:
        writer.writerow({k: ("" if row[k] is None else row[k]) for k in COLUMNS})
    return buf.getvalue()


def _pivot(rows: list[dict], title: str, fixed: dict, row_key: str, col_key: str,
           value: str, fmt: str) -> str | None:
    sel = [r for r in rows if all(r[k] == v for k, v in fixed.items())]
    if not sel:
        return None
    rvals = sorted({r[row_key] for r in sel}, key=lambda x: (x is not None, x or 0))
    cvals = sorted({r[col_key] for r in sel}, key=lambda x: (x is not None, x or 0))
    table = {(r[row_key], r[col_key]): r[value] for r in sel}
    head = ", ".join(f"{k} {v}" for k, v in fixed.items())
    lines = [f"### {title}", "", f"{value} ({head}); rows: {row_key}, columns: {col_key}", "",
             "| " + row_key + " | " + " | ".join(str(c) for c in cvals) + " |",
             "|---" * (len(cvals) + 1) + "|"]
    for rv in rvals:
        cells = [format(table[(rv, cv)], fmt) if (rv, cv) in table else "" for cv in cvals]
        lines.append(f"| {rv} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def to_markdown(rows: list[dict]) -> str:
    """Pivot tables in the shape of Tables 7.1 and 8.2 (those the rows cover)."""
    rr = "round-robin"
    specs = [
        ("7.1 direct mapped", dict(stack=8, ways=1, max_level=None, cores=1, policy=rr), "cache", "block", "miss_rate", ".2f"),
        ("7.1 two-way", dict(stack=8, ways=2, max_level=None, cores=1, policy=rr), "cache", "block", "miss_rate", ".2f"),
        ("7.1 four-way", dict(stack=8, ways=4, max_level=None, cores=1, policy=rr), "cache", "block", "miss_rate", ".2f"),
        ("7.1 level limit", dict(stack=8, ways=2, block=1, cores=1, policy=rr), "max_level", "cache", "miss_rate", ".2f"),
        ("8.2 A block vs cache size", dict(stack=8, ways=1, max_level=None, cores=2, policy=rr), "cache", "block", "frame_ms", ".0f"),
        ("8.2 B stack vs cache size", dict(block=1, ways=1, max_level=None, cores=2, policy=rr), "stack", "cache", "frame_ms", ".0f"),
        ("8.2 C stack vs cores", dict(cache=128, block=1, ways=1, max_level=None, policy=rr), "stack", "cores", "frame_ms", ".0f"),
        ("8.2 D cache vs cores (direct mapped)", dict(stack=8, block=1, ways=1, max_level=None, policy=rr), "cache", "cores", "frame_ms", ".0f"),
        ("8.2 E cache vs cores (two-way)", dict(stack=8, block=1, ways=2, max_level=None, policy=rr), "cache", "cores", "frame_ms", ".0f"),
        ("Scheduling policy", dict(stack=8, cache=128, block=1, ways=1, max_level=None), "policy", "cores", "frame_ms", ".0f"),
    ]
    parts = [_pivot(rows, *spec) for spec in specs]
    return "\n".join(p for p in parts if p)
