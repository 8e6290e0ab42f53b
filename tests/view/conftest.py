"""A real ``rend3r view`` process on a free loopback port, and plain-HTTP helpers."""

from __future__ import annotations

import http.client
import json
import os
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from urllib.parse import urlsplit

import pytest

pytest.importorskip("tornado", reason="rend3r view needs Tornado (pip install 'rend3r[view]')")

#: A lit sphere that fills the middle of a small view: the program the tests edit.
SPHERE = """\
nr
cam hfov, 0.3
cam vfov, 0.3
lt 0, src, 1
lt 0, zfor, -1
sp 0, type, col, 1, COLOUR
sp 0, zloc, rrot, -3, 1
sp 0, xscl, yscl, 1, 1
sp 0, zscl, zero, 1, 0
nf
er
er
"""


@dataclass
class Served:
    """A running view: its base URL (with token when it has one) and its process."""

    url: str
    proc: subprocess.Popen
    first_line: str
    stderr_text: str = ""  # what the server printed on stderr, once it has stopped

    @property
    def port(self) -> int:
        return urlsplit(self.url).port

    def request(self, path: str, host: str | None = None) -> tuple[int, str, bytes]:
        """(status, content type, body) of GET ``path`` sent exactly as given."""
        conn = http.client.HTTPConnection("127.0.0.1", self.port, timeout=60)
        try:
            conn.putrequest("GET", path, skip_host=True)
            conn.putheader("Host", host or f"127.0.0.1:{self.port}")
            conn.endheaders()
            r = conn.getresponse()
            return r.status, r.getheader("Content-Type", ""), r.read()
        finally:
            conn.close()

    def json(self, path: str) -> tuple[int, dict]:
        status, kind, body = self.request(path)
        assert kind.startswith("application/json"), (path, status, kind, body[:200])
        return status, json.loads(body)


@contextmanager
def serve(program: Path | str, *args: str) -> Iterator[Served]:
    """Start ``rend3r view PROGRAM --port 0 ARGS`` and stop it with Ctrl-C (SIGINT) after."""
    env = {**os.environ, "PYTHONUNBUFFERED": "1"}
    proc = subprocess.Popen([sys.executable, "-m", "rend3r", "view", str(program), "--port", "0", *args],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    served = None
    try:
        line = proc.stdout.readline()
        if "http://" not in line:
            proc.kill()
            raise AssertionError(f"rend3r view did not start: {line!r} {proc.stderr.read()}")
        served = Served(line.split(" at ", 1)[1].split()[0], proc, line)
        yield served
    finally:
        if proc.poll() is None:
            proc.send_signal(signal.SIGINT)
        try:
            _, err = proc.communicate(timeout=20)
        except subprocess.TimeoutExpired:
            proc.kill()
            _, err = proc.communicate()
        if served is not None:
            served.stderr_text = err


def wait_for(predicate, timeout: float = 20.0, step: float = 0.05):
    """Poll ``predicate`` until it returns a true value (its value), failing after ``timeout`` s."""
    end = time.monotonic() + timeout
    while True:
        value = predicate()
        if value:
            return value
        if time.monotonic() > end:
            raise AssertionError("condition not met in time")
        time.sleep(step)


@pytest.fixture
def sphere_program(tmp_path: Path) -> Path:
    """A temporary copy of :data:`SPHERE` (red) that a test may edit."""
    p = tmp_path / "scene.asm"
    p.write_text(SPHERE.replace("COLOUR", "0xF800"))
    return p
