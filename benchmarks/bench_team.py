"""What a team of threads costs to open, by the pause since the last one closed.

Run: ``python benchmarks/bench_team.py [--teams N] [--pauses-ms P ...]``. Each team is
opened for ``--jobs 2`` (one member of the kernels' pool), runs one phase of four short
tasks (csrc/team.c team_check_runs) and is closed, each a pause after the last (busy
waiting, as Python between two runs does). A pool thread that leaves a team waits
spinning for the next one for POOL_LINGER_NS (csrc/team.c) before it sleeps: a team
opened within that finds it awake, a later one must wake it. Printed per pause: the
medians over N teams of opening the team and of the whole team (open, phase, close), and
their ratios to the longest pause's (the pool's thread asleep).
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from rend3r.emu import native, threads
from two_cpus import _at_least

#: The longest pause a case may ask for (each of its teams waits it out).
LONGEST_PAUSE_MS = 100.0


def _pause(text: str) -> float:
    """An argparse type: a pause in ms, 0 to LONGEST_PAUSE_MS."""
    value = float(text)
    if not 0.0 <= value <= LONGEST_PAUSE_MS:
        raise argparse.ArgumentTypeError(f"{text} ms is outside 0..{LONGEST_PAUSE_MS:g}")
    return value


def _teams(count: int, pause: float) -> tuple[float, float]:
    """Median seconds of team_open and of a whole team over ``count`` teams, each opened
    ``pause`` seconds (busy-waited) after the last one closed."""
    lib = native.library()
    tasks = np.array([4], np.int64)
    runs = np.zeros(4, np.int32)
    opens, wholes = [], []
    for _ in range(count):
        until = time.perf_counter() + pause
        while time.perf_counter() < until:
            pass
        start = time.perf_counter()
        team = lib.team_open(1)
        opened = time.perf_counter()
        lib.team_check_runs(team, native.address(tasks), 1, native.address(runs))
        lib.team_close(team)
        opens.append(opened - start)
        wholes.append(time.perf_counter() - start)
    return statistics.median(opens), statistics.median(wholes)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--teams", type=_at_least(1), default=2000, help="teams per case; medians are reported")
    ap.add_argument("--pauses-ms", type=_pause, nargs="+", default=[0.0, 0.05, 0.1, 0.5, 2.0],
                    help="pauses before each team, one case each (the longest is the baseline)")
    args = ap.parse_args()
    if threads.available_cores() < 2:
        raise SystemExit("bench_team: needs two CPUs (a member and its leader)")
    _teams(50, 0.0)  # the pool's thread started
    pauses = sorted(args.pauses_ms)
    cases = {p: _teams(args.teams, p / 1e3) for p in pauses}
    base = cases[pauses[-1]]
    print(f"median of {args.teams} teams per pause, one member; ratios: the {pauses[-1]:g} ms pause's over this one's")
    for p, (opened, whole) in cases.items():
        print(f"pause {p:5.2f} ms  team_open {opened * 1e6:6.2f} us ({base[0] / opened:5.1f}x)  "
              f"whole team {whole * 1e6:6.2f} us ({base[1] / whole:5.1f}x)")


if __name__ == "__main__":
    main()
