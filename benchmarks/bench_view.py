"""``rend3r view`` speed, over HTTP against a real server (``docs/view.md``).

Run: ``python benchmarks/bench_view.py [--runs R] [--only history|reload]``. Prints the
median of R runs of

- a pixel's history (``GET /api/pixel``: the working-precision trace, the fp64 trace and
  their comparison, as JSON) on a front sphere of a 4,096-sphere wall (``walls.wall(4096)``,
  written as a ``.bin`` image), with the shapes hit and with every shape (target < 200 ms);
- a re-render on save of each example program in ``programs/``: from the write of a
  changed copy (one ``.word 0`` after its end, then without it again) to the page's four
  requests answered (``/api/frame`` and its three PNGs), through the websocket's reload
  message (target < 1 s).

Figures depend on the machine's load; there is no pass or fail here.
"""

from __future__ import annotations

import argparse
import asyncio
import json
import signal
import statistics
import subprocess
import sys
import tempfile
import time
import urllib.request
from pathlib import Path

import numpy as np

from walls import wall

ROOT = Path(__file__).resolve().parents[1]
#: Where the histories are taken (x grows by one each run): on a front sphere of the wall.
PIXEL = (128, 100)


class Server:
    """``rend3r view PROGRAM --port 0`` in a child process, stopped with Ctrl-C."""

    def __init__(self, program: Path) -> None:
        self.proc = subprocess.Popen([sys.executable, "-m", "rend3r", "view", str(program), "--port", "0"],
                                     stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
        line = self.proc.stdout.readline()
        self.url = line.split(" at ", 1)[1].split()[0]

    def get(self, path: str) -> bytes:
        with urllib.request.urlopen(self.url.rstrip("/") + path, timeout=600) as r:
            return r.read()

    def close(self) -> None:
        self.proc.send_signal(signal.SIGINT)
        self.proc.wait(60)


def _median_ms(fn, runs: int) -> float:
    times = []
    for _ in range(runs):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times) * 1e3


def bench_history(runs: int, tmp: Path) -> None:
    program = tmp / "wall4096.bin"
    program.write_bytes(np.asarray(wall(4096).words, dtype=">u4").tobytes())
    s = Server(program)
    try:
        s.get("/api/pixel?x=0&y=0")  # imports and compiled kernels warm
        for shapes in ("hit", "all"):
            body, x = [b""], [PIXEL[0]]

            def one() -> None:  # a new pixel each run: the server keeps the last few traces
                x[0] += 1
                body[0] = s.get(f"/api/pixel?x={x[0]}&y={PIXEL[1]}&shapes={shapes}")

            ms = _median_ms(one, runs)
            h = json.loads(body[0])
            nearest = next(r["dec"] for r in h["records"] if r["stage"] == "nearest")
            print(f"pixel history, 4,096 spheres, shapes {shapes}: {ms:,.0f} ms (sphere {nearest}, "
                  f"{len(h['records']):,} records, {len(body[0]) / 1e6:.1f} MB; target < 200 ms)")
    finally:
        s.close()


async def _save_and_reload(s: Server, path: Path, text: str) -> None:
    from tornado.websocket import websocket_connect

    ws = await websocket_connect(s.url.replace("http://", "ws://").rstrip("/") + "/api/live")
    await ws.read_message()  # hello
    path.write_text(text)
    while json.loads(await ws.read_message())["type"] != "reload":
        pass
    ws.close()
    loop = asyncio.get_running_loop()
    info = json.loads(await loop.run_in_executor(None, s.get, "/api/frame"))
    for image in ("frame", "fp64", "diff"):
        await loop.run_in_executor(None, s.get, f"/api/image/{image}.png?v={info['version']}")


def bench_reload(runs: int, tmp: Path) -> None:
    worst = 0.0
    for source in sorted((ROOT / "programs").glob("*.asm")):
        path = tmp / source.name
        text = source.read_text()
        path.write_text(text)
        s = Server(path)
        try:
            s.get("/api/frame")
            s.get("/api/image/frame.png")
            flip = [False]

            def one() -> None:
                flip[0] = not flip[0]
                asyncio.run(_save_and_reload(s, path, text + "\n.word 0\n" if flip[0] else text))

            ms = _median_ms(one, runs)
        finally:
            s.close()
        worst = max(worst, ms)
        print(f"re-render on save, {source.name}: {ms:,.0f} ms")
    print(f"re-render on save, slowest program: {worst:,.0f} ms (target < 1,000 ms)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--only", choices=("history", "reload"), help="one of the two rows")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        if args.only != "reload":
            bench_history(args.runs, Path(tmp))
        if args.only != "history":
            bench_reload(args.runs, Path(tmp))


if __name__ == "__main__":
    main()
