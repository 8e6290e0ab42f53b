"""A commit storm against ``rend3r device``: its threads and memory while programs pour in.

    python benchmarks/bench_device_storm.py [--commits 1000] [--seconds 10] [--size 4096x4096]

The device runs as the real command, its serial link a ``socket://`` URL to a TCP server on
loopback that this script owns. The script streams BEGIN, DATA, COMMIT of ``--commits``
distinct programs (sphere.asm in as many colours) at an even pace over ``--seconds``
without waiting for the ACKs (a thread drains them), sampling the device's thread count and
RSS from /proc every 20 ms. Then it waits for the last program's first frame and asks
STATUS. Issue 13 measured the old executor at 62 threads and > 10 GB after 60 commits in
3 s at 4096x4096; a flat device stays at its idle thread count plus one render worker and
the emulator's pool.
"""

from __future__ import annotations

import argparse
import os
import select
import socket
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

from rend3r.transport import cobs
from rend3r.transport.protocol import Frame, FrameType, Status, decode
from rend3r.transport.session import load_frames

REPO = Path(__file__).resolve().parents[1]


def sphere_programs(n: int) -> list[list[int]]:
    """``n`` distinct programs: sphere.asm with the sphere in colour 1..n (RGB565, wrapping)."""
    from rend3r.asm.assembler import assemble_source

    source = (REPO / "programs" / "sphere.asm").read_text()
    out = []
    for i in range(n):
        colour = 0x0800 * (i % 31 + 1) | 0x20 * (i // 31 % 63)
        result = assemble_source(source.replace("0b11111_000000_00000   ; sphere, red", f"{colour} ; sphere"))
        out.append(list(result.program.words))
    return out


def proc_status(pid: int) -> dict[str, int]:
    """Threads, VmRSS and VmHWM (bytes) of a live process."""
    fields = {}
    with open(f"/proc/{pid}/status") as fh:
        for line in fh:
            key, _, value = line.partition(":")
            if key in ("Threads", "VmRSS", "VmHWM"):
                number = int(value.split()[0])
                fields[key] = number * 1024 if key.startswith("Vm") else number
    return fields


def _read(fh) -> bytes:
    fh.seek(0)
    return fh.read()


def storm(commits: int, seconds: float, size: str, out: Path, frames: int = 8) -> dict[str, float]:
    """Run the storm; return the figures (threads, RSS, commits acknowledged, files, latency)."""
    programs = sphere_programs(commits)
    final_load = (commits - 1) % 65535 + 1
    server = socket.create_server(("127.0.0.1", 0))
    port = server.getsockname()[1]
    log = tempfile.TemporaryFile()  # the device logs every commit: a pipe nobody reads would stall it
    device = subprocess.Popen([sys.executable, "-m", "rend3r", "device", "--serial", f"socket://127.0.0.1:{port}",
                               "-o", str(out), "--size", size, "--frames", str(frames)], stderr=log)
    conn, _ = server.accept()
    server.close()
    while b"listening on" not in _read(log):  # pyserial drains the socket while it opens the port
        if device.poll() is not None:
            raise RuntimeError(f"rend3r device exited: {_read(log).decode()}")
        time.sleep(0.02)
    acks: list[Frame] = []
    last_commit_acked = [0.0]
    done = threading.Event()

    def drain() -> None:
        buf = bytearray()
        while not done.is_set():
            if select.select([conn], [], [], 0.05)[0]:
                data = conn.recv(65536)
                if not data:
                    return
                buf += data
                *whole, rest = bytes(buf).split(b"\0")
                buf = bytearray(rest)
                acks.extend(decode(cobs.decode(w)) for w in whole if w)
                if any(a.ref == FrameType.COMMIT and a.load == final_load for a in acks[-len(whole):]):
                    last_commit_acked[0] = time.monotonic()

    reader = threading.Thread(target=drain, daemon=True)
    reader.start()
    samples: list[dict[str, int]] = []
    try:
        conn.sendall(b"\0")
        idle = proc_status(device.pid)
        start = time.monotonic()
        for i, words in enumerate(programs):
            wire = b"".join(cobs.encode(f.encode()) + b"\0" for f in load_frames(words, i % 65535 + 1, 3 * i))
            conn.sendall(wire)
            samples.append(proc_status(device.pid))
            time.sleep(max(0.0, start + (i + 1) * seconds / commits - time.monotonic()))
        sent = time.monotonic()
        last = out / f"run{commits:04d}_frame0000.png"
        while not last.exists() and time.monotonic() - sent < 120:
            samples.append(proc_status(device.pid))
            time.sleep(0.02)
        latency = time.monotonic() - sent
        conn.sendall(cobs.encode(Frame(FrameType.STATUS, 0, 0xFFFF).encode()) + b"\0")
        deadline = time.monotonic() + 10
        while not any(a.ref == FrameType.STATUS for a in acks) and time.monotonic() < deadline:
            time.sleep(0.02)
        status = Status.unpack(next(a for a in acks if a.ref == FrameType.STATUS).payload)
        final = proc_status(device.pid)
    finally:
        done.set()
        device.terminate()
        device.wait(timeout=60)
        conn.close()
        log.close()
    committed = sum(a.type == FrameType.ACK and a.ref == FrameType.COMMIT for a in acks)
    return {
        "commits": commits, "seconds": sent - start, "acked": committed, "loads": status.loads,
        "idle_threads": idle["Threads"], "max_threads": max(s["Threads"] for s in samples),
        "idle_rss": idle["VmRSS"], "max_rss": max(s["VmRSS"] for s in samples), "peak_rss": final["VmHWM"],
        "final_rss": final["VmRSS"], "files": len(list(out.glob("*.png"))),
        "last_frame_after": latency, "last_ack_after": last_commit_acked[0] - sent, "last_exists": float(last.exists()),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--commits", type=int, default=1000)
    parser.add_argument("--seconds", type=float, default=10.0)
    parser.add_argument("--size", default="4096x4096")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        r = storm(args.commits, args.seconds, args.size, Path(tmp))
    mib = 1 / 2**20
    print(f"rend3r device at {args.size}, {r['commits']} commits in {r['seconds']:.1f} s "
          f"({r['acked']} COMMITs acknowledged, STATUS loads {r['loads']}), {os.cpu_count()} cores")
    print("| figure | value |\n|---|---:|")
    print(f"| threads idle / most during the storm | {r['idle_threads']} / {r['max_threads']} |")
    print(f"| RSS idle / most sampled / peak (VmHWM) / after | {r['idle_rss'] * mib:.0f} / {r['max_rss'] * mib:.0f} "
          f"/ {r['peak_rss'] * mib:.0f} / {r['final_rss'] * mib:.0f} MiB |")
    print(f"| PNG files written (runs that finished a frame before being replaced) | {r['files']} |")
    print(f"| last COMMIT acknowledged, after it was sent | {r['last_ack_after']:.2f} s |")
    print(f"| last program's first frame written, after the last commit was sent | {r['last_frame_after']:.2f} s |")


if __name__ == "__main__":
    main()
