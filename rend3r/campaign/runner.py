"""One runner for every campaign: map a pure task function over task inputs and get the
results back in input order, whatever runs them.

``--scheduler`` chooses where: ``local`` (the default) starts an in-process Dask
distributed cluster sized to the machine for the run, ``tcp://HOST:PORT`` uses an existing
one (``dask scheduler`` and ``dask worker`` started as Dask documents), ``none`` runs the
tasks one after another in this process, as does ``local`` when Dask is not installed
(with a one-line note). Dask is imported only here and only when a cluster is used.
The local cluster runs tasks on threads of this process by default, or in worker
processes for tasks that hold the GIL (``processes=True``).

A task that raises is reported by name (:class:`TaskFailed`, ``rend3r: error: TASK: ...``)
and the other tasks are cancelled; the caller writes its outputs only after every map
returned, so a failed run writes nothing. Ctrl-C cancels the tasks in flight and goes on as
a KeyboardInterrupt (exit 130); local worker processes ignore Ctrl-C and are stopped at once
by this process (a Ctrl-C while they start, a few seconds, is ignored too). A worker that
dies has its tasks rerun by the scheduler on the others (and the results of earlier maps it
held, :meth:`Campaign.map` ``keep=True``, recomputed); the results do not depend on where a
task ran.
"""

from __future__ import annotations

import logging
import os
import signal
from collections.abc import Callable, Sequence
from types import TracebackType
from typing import Any, TypeVar

import click

from ..errors import Rend3rError
from ..progress import Progress

R = TypeVar("R")

#: ``--scheduler`` values besides ``tcp://HOST:PORT``.
LOCAL, SERIAL = "local", "none"

#: How long to wait for an existing scheduler to answer.
CONNECT_TIMEOUT = "10s"

#: What to install for the cluster paths.
EXTRA = "pip install 'rend3r[campaign]'"


class TaskFailed(Rend3rError):
    """A task raised: its name and its error, as the user reads them."""

    def __init__(self, name: str, error: BaseException) -> None:
        reason = str(error) if isinstance(error, Rend3rError) else f"{type(error).__name__}: {error}"
        super().__init__(f"{name}: {reason}")


def parse_scheduler(text: str) -> str:
    """``local``, ``none`` or ``tcp://HOST:PORT``; ValueError with the reason otherwise."""
    value = text.strip()
    if value.lower() in (LOCAL, SERIAL):
        return value.lower()
    host, _, port = value.removeprefix("tcp://").rpartition(":")
    if not value.startswith("tcp://") or not host or not port.isdigit() or not 0 < int(port) < 65536:
        raise ValueError(f"expected local, none or tcp://HOST:PORT, not {text!r}")
    return value


#: The module every local worker process preloads (its dask_setup tunes the allocator).
_PRELOAD = "rend3r.memory"


def _configured_preloads() -> list[str]:
    """The worker preloads of the user's Dask configuration (a name or a list of them)."""
    import dask

    value = dask.config.get("distributed.worker.preload", default=[])
    return [value] if isinstance(value, str) else list(value or [])


def dask_installed() -> bool:
    """Whether ``dask.distributed`` can be imported (without importing it)."""
    from importlib.util import find_spec

    return find_spec("dask") is not None and find_spec("distributed") is not None


class Campaign:
    """Where one run's tasks execute; a context manager that starts and stops the cluster.

    The local cluster runs ``workers`` tasks at once (default: one per core). By default
    they are threads of one worker in this process: the renderers' kernels release the
    GIL, and nothing is started or shipped between processes. With ``processes=True``,
    for tasks that hold the GIL (pure-Python loops), each is a worker process with one
    thread. ``note`` receives the line printed when Dask is missing and the run falls back
    to serial.
    """

    def __init__(self, scheduler: str = LOCAL, *, workers: int | None = None, processes: bool = False,
                 note: Callable[[str], None] = lambda line: click.echo(line, err=True)) -> None:
        if workers is not None and workers < 1:
            raise ValueError("a local cluster needs at least one worker")
        self.scheduler = parse_scheduler(scheduler)
        self.workers, self.processes = workers, processes
        self._note = note
        self._cluster: Any = None
        self._client: Any = None

    @property
    def distributed(self) -> bool:
        """Whether tasks run on a Dask cluster (False: serially in this process)."""
        return self._client is not None

    def __enter__(self) -> Campaign:
        if self.scheduler == SERIAL:
            return self
        if not dask_installed():
            if self.scheduler != LOCAL:
                raise Rend3rError(f"--scheduler {self.scheduler} needs Dask distributed: {EXTRA}")
            self._note(f"rend3r: note: Dask is not installed, running serially ({EXTRA} to use every core)")
            return self
        from distributed import Client, LocalCluster

        from ..emu.threads import available_cores
        from ..svo.interrupt import ctrl_c_ignored

        # Dask's own logs (a closed comm's traceback as a cluster stops, at INFO) are not ours
        # to show: LocalCluster's silence_logs covers only its start, so they are silenced for
        # the process; failures reach the user as rend3r's errors.
        logging.getLogger("distributed").setLevel(logging.CRITICAL)
        try:
            if self.scheduler == LOCAL:
                slots = self.workers or available_cores()
                # worker processes tune their allocator as the rend3r command does (rend3r/memory.py),
                # after the preloads of the user's Dask config (an explicit list replaces them)
                shape = {"n_workers": slots, "threads_per_worker": 1, "preload": [*_configured_preloads(), _PRELOAD]} \
                    if self.processes else {"n_workers": 1, "threads_per_worker": slots}
                with ctrl_c_ignored():  # worker processes inherit it: a Ctrl-C stops the run here, which stops them
                    # no dashboard; the scheduler's HTTP server on any free port of the loopback (its
                    # default, 8787, is taken by another campaign running here, with a warning)
                    self._cluster = LocalCluster(**shape, processes=self.processes, dashboard_address=None,
                                                 scheduler_kwargs={"dashboard_address": "127.0.0.1:0"},
                                                 silence_logs=logging.CRITICAL)
                self._client = Client(self._cluster)
            else:
                self._client = Client(self.scheduler, timeout=CONNECT_TIMEOUT)
        except OSError as exc:
            self._close()
            raise Rend3rError(f"cannot reach the Dask scheduler at {self.scheduler}: {exc}") from None
        return self

    def __exit__(self, kind: type[BaseException] | None, value: BaseException | None,
                 tb: TracebackType | None) -> None:
        if kind is not None and self._cluster is not None and self.processes:
            self._stop_worker_processes()
        self._close()

    def _stop_worker_processes(self) -> None:
        """Kill the local worker processes, still busy with cancelled tasks, rather than wait
        for them (a graceful close waits seconds for a task to end)."""
        for nanny in self._cluster.workers.values():
            nanny.close_gracefully()  # no restart when its worker dies
            if nanny.process is not None and nanny.process.pid is not None:
                os.kill(nanny.process.pid, signal.SIGKILL)

    def _close(self) -> None:
        if self._client is not None:
            self._client.close()
            self._client = None
        if self._cluster is not None:
            self._cluster.close()
            self._cluster = None

    def map(self, function: Callable[..., R], inputs: Sequence[tuple], names: Sequence[str],
            progress: Progress, *, keep: bool = False) -> list[R]:
        """``[function(*args) for args in inputs]``, advancing ``progress`` one unit per task.

        ``names[i]`` names task ``i`` in a failure. ``function`` must be importable by the
        workers (a module-level function or a partial of one) and return picklable values.
        With ``keep`` the results stay on the workers that computed them: what comes back
        are handles (the results themselves when serial) to pass as arguments of a later
        map's tasks, which receive the results; a handle lost with its worker is recomputed.
        """
        if len(names) != len(inputs):
            raise ValueError("one name per task input")
        if self._client is None:
            return [self._serial(function, args, name, progress) for args, name in zip(inputs, names)]
        return self._distributed(function, inputs, names, progress, keep)

    @staticmethod
    def _serial(function: Callable[..., R], args: tuple, name: str, progress: Progress) -> R:
        try:
            result = function(*args)
        except Exception as exc:
            raise TaskFailed(name, exc) from exc
        progress.advance(1)
        return result

    def _distributed(self, function: Callable[..., R], inputs: Sequence[tuple], names: Sequence[str],
                     progress: Progress, keep: bool) -> list[R]:
        from distributed import as_completed

        # pure=False: every task runs, even two with equal inputs; keys stay unique per run
        futures = [self._client.submit(function, *args, pure=False) for args in inputs]
        index = {f.key: i for i, f in enumerate(futures)}
        try:
            for future in as_completed(futures):
                if future.status == "error":
                    raise TaskFailed(names[index[future.key]], future.exception())
                if future.status == "cancelled":  # the scheduler went away, or gave up on the task
                    raise Rend3rError(f"{names[index[future.key]]}: cancelled: the Dask scheduler went away "
                                      "or gave up on it")
                progress.advance(1)
            return futures if keep else self._client.gather(futures)
        except BaseException:
            self._client.cancel(futures)
            raise
