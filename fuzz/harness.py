"""Run CLI cases in child processes and tally what the reliability report needs.

Each case is one ``python -m rend3r ...`` child, so a crash (a signal) is seen as a crash
and not as the end of the fuzzer, and each child's own time and peak RSS are measured.
The peak comes from a small starter process (:data:`_STARTER`, ``python -S``) that forks
the case and reports its ``wait4`` usage: Linux folds the memory of the process that
calls ``exec`` into the new program's ``ru_maxrss``, and a child forked (or
``posix_spawn``-ed, which shares its memory until ``exec``) straight from the fuzzer
reported the fuzzer's own peak, hundreds of MiB after a long run. The starter holds about
10 MiB, below any case. A case *passes* when the command exits
0, 1 or 2 and its stderr holds no Python traceback; exit 1 and 2 must come with an
``error:`` line, except the exits a command documents as verdicts (``verdicts``: e.g.
``trace-diff``'s 1, "traces differ", printed on standard output). Limits: ``timeout`` seconds (a hang is reported, not waited on) and
``max_rss`` bytes of address space (``RLIMIT_AS``), so a memory blow-up ends as a
failed case instead of taking the machine.

Used by the long fuzz runs under ``fuzz/``; the hypothesis suites in ``tests/`` run
in-process with a fixed budget.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

CHILD_MEMORY = 4 << 30
"""Default address-space limit of one case (4 GiB): beyond it the case fails as a blow-up."""


@dataclass(frozen=True)
class CaseResult:
    """What one child did."""

    args: tuple[str, ...]
    returncode: int
    seconds: float
    rss_bytes: int
    stderr: str
    timed_out: bool
    verdicts: tuple[int, ...] = ()

    @property
    def crashed(self) -> bool:
        """Killed by a signal (segfault, abort) other than our own timeout."""
        return self.returncode < 0 and not self.timed_out

    @property
    def traceback(self) -> bool:
        return "Traceback (most recent call last)" in self.stderr

    @property
    def unclear(self) -> bool:
        """Failed without saying why: exit 1 or 2 with no ``error:`` line."""
        return (self.returncode in (1, 2) and self.returncode not in self.verdicts
                and "error:" not in self.stderr.lower())

    @property
    def ok(self) -> bool:
        return (self.returncode in (0, 1, 2) and not self.traceback and not self.unclear
                and not self.timed_out)


def run_case(args: list[str], *, stdin: bytes | None = None, cwd: str | Path | None = None,
             timeout: float = 60.0, max_rss: int = CHILD_MEMORY, verdicts: tuple[int, ...] = ()) -> CaseResult:
    """Run ``python -m rend3r *args`` in a child and measure its time and its own peak RSS
    (``verdicts``: exit statuses that are documented answers, not errors)."""

    with tempfile.TemporaryFile() as err, tempfile.TemporaryFile() as given, \
            tempfile.TemporaryFile() as report:
        if stdin is not None:
            given.write(stdin)
            given.seek(0)
        start = time.perf_counter()
        starter = subprocess.Popen([sys.executable, "-S", "-c", _STARTER, str(max_rss),
                                    sys.executable, "-m", "rend3r", *args], cwd=cwd,
                                   stdin=given if stdin is not None else subprocess.DEVNULL,
                                   stdout=report, stderr=err, start_new_session=True)
        try:
            starter.wait(timeout)
            timed_out = False
        except subprocess.TimeoutExpired:
            timed_out = True
            os.killpg(starter.pid, signal.SIGKILL)  # the case is in the starter's session
            starter.wait()
        seconds = time.perf_counter() - start
        report.seek(0)
        measured = report.read().split()
        err.seek(0)
        text = err.read().decode("utf-8", "replace")
    if timed_out or len(measured) != 2:  # killed before the case ended: no usage to report
        return CaseResult(tuple(args), -signal.SIGKILL, seconds, 0, text, True, verdicts)
    status, rss_kib = (int(x) for x in measured)
    return CaseResult(tuple(args), os.waitstatus_to_exitcode(status), seconds, rss_kib * 1024, text,
                      False, verdicts)


_STARTER = """
import os, resource, sys
pid = os.fork()
if pid == 0:
    os.dup2(os.open(os.devnull, os.O_WRONLY), 1)
    limit = int(sys.argv[1])
    resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    os.execv(sys.argv[2], sys.argv[2:])
_, status, usage = os.wait4(pid, 0)
print(status, usage.ru_maxrss)
"""
"""Run by ``python -S -c``: fork the case (address space limited to ``argv[1]`` bytes,
standard output discarded), wait, and print its wait status and its own peak RSS in KiB."""


@dataclass
class Tally:
    """Counts over many cases of one parser, printed as one row of the report."""

    name: str
    cases: int = 0
    tracebacks: int = 0
    crashes: int = 0
    hangs: int = 0
    unclear: int = 0
    worst_seconds: float = 0.0
    worst_rss: int = 0
    worst_args: tuple[str, ...] = ()
    failures: list[CaseResult] = field(default_factory=list)

    def add(self, result: CaseResult) -> None:
        self.cases += 1
        self.tracebacks += result.traceback
        self.crashes += result.crashed
        self.hangs += result.timed_out
        self.unclear += result.unclear
        if result.seconds > self.worst_seconds:
            self.worst_seconds, self.worst_args = result.seconds, result.args
        self.worst_rss = max(self.worst_rss, result.rss_bytes)
        if not result.ok:
            self.failures.append(result)

    def report(self) -> str:
        """One Markdown table row: parser, cases, tracebacks, crashes, hangs, worst time, worst RSS."""
        return (f"| {self.name} | {self.cases} | {self.tracebacks} | {self.crashes} | {self.hangs} "
                f"| {self.unclear} | {self.worst_seconds:.2f} s | {self.worst_rss / 2**20:.0f} MiB |")

    def print_failures(self, limit: int = 5) -> None:
        """The first failures, and the slowest case, on standard error."""
        print(f"{self.name}: slowest case {self.worst_seconds:.2f} s: {' '.join(self.worst_args)[:200]}",
              file=sys.stderr)
        for result in self.failures[:limit]:
            print(f"FAILED ({result.returncode}, {result.seconds:.1f} s): {' '.join(result.args)[:200]}",
                  file=sys.stderr)
            print(result.stderr[-2000:], file=sys.stderr)


HEADER = ("| parser | cases | tracebacks | crashes | hangs | exits without `error:` | worst time "
          "| worst RSS |\n|---|---:|---:|---:|---:|---:|---:|---:|")
