"""A Dask cluster on 127.0.0.1 started from the command line as Dask documents (``dask
scheduler``, ``dask worker``): what the campaign tests and ``bench_explore.py`` run
``--scheduler tcp://`` against."""

from __future__ import annotations

import os
import socket
import subprocess
from collections.abc import Iterator
from contextlib import contextmanager


def free_port() -> int:
    """A TCP port of 127.0.0.1 that nothing listens on now."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@contextmanager
def localhost_cluster(path: str, workers: int = 2, nanny: bool = True) -> Iterator[tuple[str, list[subprocess.Popen]]]:
    """``(address, [scheduler, worker...])``: a scheduler and ``workers`` one-thread workers
    importing from ``path`` first, all stopped on leaving. Without ``nanny`` a killed worker
    stays dead."""
    from distributed import Client

    address = f"tcp://127.0.0.1:{free_port()}"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([path, os.environ.get("PYTHONPATH", "")])}
    quiet = {"stdout": subprocess.DEVNULL, "stderr": subprocess.DEVNULL, "env": env}
    processes = [subprocess.Popen(["dask", "scheduler", "--host", "127.0.0.1", "--port", address.rsplit(":", 1)[1],
                                   "--no-dashboard"], **quiet)]
    try:
        with Client(address, timeout="60s") as client:
            for n in range(workers):
                processes.append(subprocess.Popen(["dask", "worker", address, "--name", f"w{n}", "--nthreads", "1",
                                                   "--no-dashboard", "--host", "127.0.0.1",
                                                   *([] if nanny else ["--no-nanny"])], **quiet))
            client.wait_for_workers(workers, timeout=120)
        yield address, processes
    finally:
        for p in reversed(processes):
            p.terminate()
        for p in reversed(processes):
            try:
                p.wait(timeout=10)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()
