"""The exploration campaign on Dask: 20 programs x 12 uniform designs at 256x192.

Prints, with the targets of issue 15 (docs/campaigns.md):

* 1 local worker against 2 (the in-process cluster of ``rend3r explore``, a render per
  worker thread, each render on one thread, ``--jobs 1``): the campaign's wall time, the
  median of ``--repeat`` runs, and the speed-up (target >= 1.8x on 2 cores);
* the scheduling overhead: (wall x workers - sum of task times) / sum of task times, the
  task times measured inside the tasks (target <= 5%); the cluster's start is reported
  apart;
* the same campaign through a ``tcp://`` scheduler with two one-thread worker processes
  this script starts on 127.0.0.1 (``dask scheduler``, ``dask worker``): the
  ``results.csv`` that ``rend3r explore`` writes there must be identical to the one of the
  last local campaign;
* render time of a non-native format (e6m9) and of e5m10 with ftz against fp16 (targets
  <= 2x and <= 1x), each program rendered alone, the three in turn, the median of
  ``--repeat`` rounds; e5m10 meets its target when it runs fp16's own kernels and its time
  lies within fp16's own spread over the rounds (they are the same computation).
The campaign is cut into tasks as ``rend3r explore`` cuts it (``batches``).

Exits 1 when the two ``results.csv`` differ (or a step fails), else 0; a missed speed
target is printed as ``MISSED``.

    python benchmarks/bench_explore.py [--repeat 3] [--size 256x192]
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from functools import partial
from pathlib import Path

import rend3r
from rend3r.campaign.runner import Campaign
from rend3r.cliutil import parse_size
from rend3r.emu import native
from rend3r.emu.arith import make_arith
from rend3r.explore.campaign import (REFERENCE, ProgramSpec, Rendering, Score, batches, design_cost, render_design,
                                    score_designs)
from rend3r.explore.cli import load_spec
from rend3r.explore.report import Results, results_csv
from rend3r.progress import Progress

sys.path.insert(0, str(Path(__file__).resolve().parent))
from dask_cluster import localhost_cluster  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
#: where the rend3r in use is imported from: the workers and commands started here import it too
PACKAGE_PATH = str(Path(rend3r.__file__).resolve().parents[1])
#: the 12 designs: uniform working formats from 4 to 32 bits
FORMATS = ("e4m3", "e5m6", "fp16", "e6m9", "bf16", "e8m10", "e6m12", "fp24", "e8m15", "e8m19", "e11m22", "fp32")
SUBNORMALS, MIN_PSNR = "ftz", 40.0  # rend3r explore's defaults


def timed(task: Callable, *args):
    """``(seconds, task(*args))``: a campaign task that reports how long it ran."""
    start = time.perf_counter()
    result = task(*args)
    return time.perf_counter() - start, result


def timed_scores(program: ProgramSpec, designs: tuple[str, ...], reference: tuple[float, Rendering],
                 **options) -> tuple[float, list[Score]]:
    """``(seconds, scores)``: explore's scoring task, given the timed reference task's result."""
    return timed(partial(score_designs, **options), program, designs, reference[1])


def seconds(result: tuple[float, object]) -> float:
    """The time a timed task reported (a task of its own: the result may be kept on a worker)."""
    return result[0]


def campaign_run(campaign: Campaign, specs: list[ProgramSpec], size: tuple[int, int]) -> tuple[float, float, bytes]:
    """Run explore's two stages as ``rend3r explore`` does (fp64 references kept on the
    workers, then the designs in batches, :func:`batches`); (wall s, sum of task s, the
    results.csv ``rend3r explore`` writes for them with its defaults)."""
    options = {"subnormals": SUBNORMALS, "width": size[0], "height": size[1], "jobs": 1}
    tasks = batches([(s, f) for f in FORMATS for s in specs], size[0] * size[1])
    names = [s.name for s in specs]
    start = time.perf_counter()
    with Progress(len(specs) + len(tasks), f"{campaign.workers} worker(s)") as bar:
        refs = campaign.map(partial(timed, partial(render_design, precision=REFERENCE, **options)),
                            [(s,) for s in specs], names, bar, keep=True)
        reference = dict(zip(names, refs))
        scored = campaign.map(partial(timed_scores, **options), [(s, ds, reference[s.name]) for s, ds in tasks],
                              [f"{s.name} in {', '.join(ds)}" for s, ds in tasks], bar)
    wall = time.perf_counter() - start
    with Progress(len(specs), "reference times", quiet=True) as bar:
        ref_seconds = campaign.map(seconds, [(r,) for r in refs], names, bar)
    found = {(s.name, d): score for (s, ds), (_, batch) in zip(tasks, scored) for d, score in zip(ds, batch)}
    csv = results_csv(Results(specs, list(FORMATS), found, {f: design_cost(f) for f in FORMATS}, MIN_PSNR, SUBNORMALS,
                              size))
    return wall, sum(ref_seconds) + sum(t for t, _ in scored), csv


def local_workers(specs: list[ProgramSpec], size: tuple[int, int],
                  repeat: int) -> tuple[dict[int, dict[str, float]], bytes]:
    """Per worker count: median start, wall and overhead share over ``repeat`` campaigns;
    and the results.csv of the last."""
    found: dict[int, dict[str, list[float]]] = {}
    for _ in range(repeat):
        for workers in (1, 2):
            start = time.perf_counter()
            with Campaign("local", workers=workers) as campaign:
                up = time.perf_counter() - start
                wall, tasks, csv = campaign_run(campaign, specs, size)
            runs = found.setdefault(workers, {"start": [], "wall": [], "overhead": [], "tasks": []})
            runs["start"].append(up)
            runs["wall"].append(wall)
            runs["tasks"].append(tasks)
            runs["overhead"].append((wall * workers - tasks) / tasks)
            print(f"  {workers} worker(s): start {up:.1f} s, campaign {wall:.1f} s, tasks {tasks:.1f} s, "
                  f"overhead {100 * runs['overhead'][-1]:.1f}%", flush=True)
    return {w: {k: statistics.median(v) for k, v in runs.items()} for w, runs in found.items()}, csv


def format_times(specs: list[ProgramSpec], size: tuple[int, int], repeat: int) -> dict[str, list[float]]:
    """Per precision (fp16, e5m10, e6m9), the render time (s) over the programs of each of
    ``repeat`` rounds; a round renders each program in the three in turn, so that drifts of
    a shared machine fall on all three alike."""
    totals: dict[str, list[float]] = {p: [0.0] * repeat for p in ("fp16", "e5m10", "e6m9")}
    for spec in specs:
        render_design(spec, "fp16", SUBNORMALS, *size, jobs=1)  # warm: the first render of a program pays more
        for k in range(repeat):
            for precision, rounds in totals.items():
                rounds[k] += timed(render_design, spec, precision, SUBNORMALS, *size, 1)[0]
    return totals


def package_env() -> dict[str, str]:
    """This environment with :data:`PACKAGE_PATH` first on the module path."""
    return {**os.environ, "PYTHONPATH": os.pathsep.join([PACKAGE_PATH, os.environ.get("PYTHONPATH", "")])}


def explore_csv(programs: list[Path], size: tuple[int, int], scheduler: str, out: Path) -> tuple[bytes, float]:
    """``rend3r explore`` of the campaign on ``scheduler``: (results.csv, wall s of the command)."""
    command = [sys.executable, "-m", "rend3r", "explore", *map(str, programs), "-o", str(out), "--formats",
               ",".join(FORMATS), "--size", f"{size[0]}x{size[1]}", "--jobs", "1", "--scheduler", scheduler, "-q"]
    start = time.perf_counter()
    done = subprocess.run(command, env=package_env(), capture_output=True, text=True, check=False)
    if done.returncode:
        raise RuntimeError(f"rend3r explore --scheduler {scheduler} failed (exit {done.returncode}): "
                           f"{done.stderr.strip()}")
    return (out / "results.csv").read_bytes(), time.perf_counter() - start


def verdict(ok: bool) -> str:
    return "met" if ok else "MISSED"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3, help="runs of each measurement; medians are printed")
    ap.add_argument("--size", default="256x192", help="image size WxH (default 256x192)")
    args = ap.parse_args(argv)
    size = parse_size(args.size)
    programs = sorted((ROOT / "programs").glob("*.asm"))
    specs = [load_spec(p) for p in programs]
    print(f"{len(specs)} programs x {len(FORMATS)} designs at {size[0]}x{size[1]} ({len(specs)} fp64 references "
          f"+ {len(specs) * len(FORMATS)} scored renders), {os.cpu_count()} cores, load average "
          f"{os.getloadavg()[0]:.1f}", flush=True)

    local, here = local_workers(specs, size, args.repeat)
    speedup = local[1]["wall"] / local[2]["wall"]
    for workers, m in local.items():
        print(f"{workers} local worker(s): campaign {m['wall']:.1f} s (cluster start {m['start']:.1f} s apart), "
              f"task time {m['tasks']:.1f} s, scheduling overhead {100 * m['overhead']:.1f}% (median of {args.repeat})")
    print(f"speed-up of 2 local workers over 1: {speedup:.2f}x (target >= 1.8x: {verdict(speedup >= 1.8)})")
    worst = max(m["overhead"] for m in local.values())
    print(f"scheduling overhead: at most {100 * worst:.1f}% of task time (target <= 5%: {verdict(worst <= 0.05)})",
          flush=True)

    rounds = format_times(specs, size, args.repeat)
    totals = {p: statistics.median(r) for p, r in rounds.items()}
    spread = (max(rounds["fp16"]) - min(rounds["fp16"])) / totals["fp16"]
    e6m9, e5m10 = totals["e6m9"] / totals["fp16"], totals["e5m10"] / totals["fp16"]
    same = native.suffix(make_arith("e5m10", SUBNORMALS)) == native.suffix(make_arith("fp16", SUBNORMALS))
    print(f"render time over the {len(specs)} programs: fp16 {totals['fp16']:.2f} s, e5m10 {totals['e5m10']:.2f} s, "
          f"e6m9 {totals['e6m9']:.2f} s (median of {args.repeat} interleaved rounds, one thread; fp16's rounds "
          f"spread {100 * spread:.1f}%)")
    print(f"e6m9 / fp16: {e6m9:.2f}x (target <= 2x: {verdict(e6m9 <= 2)})")
    print(f"e5m10-ftz / fp16: {e5m10:.3f}x, {'the same' if same else 'OTHER'} kernels "
          f"(target <= 1x: {verdict(same and e5m10 <= 1 + spread)}, within fp16's own spread)", flush=True)

    with tempfile.TemporaryDirectory() as tmp:
        try:
            with localhost_cluster(PACKAGE_PATH) as (address, _):
                remote, remote_s = explore_csv(programs, size, address, Path(tmp) / "tcp")
        except (OSError, RuntimeError) as exc:  # TimeoutError (no scheduler or workers) is an OSError
            print(f"error: {exc}", file=sys.stderr)
            return 1
    same = remote == here
    print(f"rend3r explore through {address} (2 worker processes): {remote_s:.1f} s for the command; "
          f"results.csv {'identical to' if same else 'DIFFERENT from'} the local campaign's "
          f"({len(here.splitlines()) - 1} rows)")
    return 0 if same else 1


if __name__ == "__main__":
    raise SystemExit(main())
