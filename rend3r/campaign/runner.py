"""One runner for every campaign: map a pure task function over task inputs and get the
results back in input order, whatever runs them.

``--scheduler`` chooses where: ``local`` (the default) starts an in-process Dask
distributed cluster sized to the machine for the run, ``tcp://HOST:PORT`` uses an existing
one (``dask scheduler`` and ``dask worker`` started as Dask documents), ``none`` runs the
tasks one after another in this process, as does ``local`` when Dask is not installed
(with a one-line note). Dask is imported only here and only when a cluster is used.

A task that raises is reported by name (:class:`TaskFailed`, ``rend3r: error: TASK: ...``)
and the other tasks are cancelled; the caller writes its outputs only after every map
returned, so a failed run writes nothing. Ctrl-C cancels the tasks in flight and goes on as
a KeyboardInterrupt (exit 130). A worker that dies has its tasks rerun by the scheduler on
the others; the results do not depend on where a task ran.
"""

from __future__ import annotations

import logging
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


def dask_installed() -> bool:
    """Whether ``dask.distributed`` can be imported (without importing it)."""
    from importlib.util import find_spec

    return find_spec("dask") is not None and find_spec("distributed") is not None


class Campaign:
    """Where one run's tasks execute; a context manager that starts and stops the cluster.

    The local cluster runs in this process: one worker with a thread per core (the
    renderers' kernels release the GIL, and nothing is started or shipped between
    processes). ``note`` receives the line printed when Dask is missing and the run falls
    back to serial.
    """

    def __init__(self, scheduler: str = LOCAL, *,
                 note: Callable[[str], None] = lambda line: click.echo(line, err=True)) -> None:
        self.scheduler = parse_scheduler(scheduler)
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

        try:
            if self.scheduler == LOCAL:
                self._cluster = LocalCluster(n_workers=1, threads_per_worker=available_cores(), processes=False,
                                             dashboard_address=None, silence_logs=logging.CRITICAL)
                self._client = Client(self._cluster)
            else:
                self._client = Client(self.scheduler, timeout=CONNECT_TIMEOUT)
        except OSError as exc:
            self._close()
            raise Rend3rError(f"cannot reach the Dask scheduler at {self.scheduler}: {exc}") from None
        return self

    def __exit__(self, kind: type[BaseException] | None, value: BaseException | None,
                 tb: TracebackType | None) -> None:
        self._close()

    def _close(self) -> None:
        if self._client is not None:
            self._client.close()
            self._client = None
        if self._cluster is not None:
            self._cluster.close()
            self._cluster = None

    def map(self, function: Callable[..., R], inputs: Sequence[tuple], names: Sequence[str],
            progress: Progress) -> list[R]:
        """``[function(*args) for args in inputs]``, advancing ``progress`` one unit per task.

        ``names[i]`` names task ``i`` in a failure. ``function`` must be importable by the
        workers (a module-level function or a partial of one) and return picklable values.
        """
        if len(names) != len(inputs):
            raise ValueError("one name per task input")
        if self._client is None:
            return [self._serial(function, args, name, progress) for args, name in zip(inputs, names)]
        return self._distributed(function, inputs, names, progress)

    @staticmethod
    def _serial(function: Callable[..., R], args: tuple, name: str, progress: Progress) -> R:
        try:
            result = function(*args)
        except Exception as exc:
            raise TaskFailed(name, exc) from exc
        progress.advance(1)
        return result

    def _distributed(self, function: Callable[..., R], inputs: Sequence[tuple], names: Sequence[str],
                     progress: Progress) -> list[R]:
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
            return self._client.gather(futures)
        except BaseException:
            self._client.cancel(futures)
            raise
