"""Transport goodput and wire efficiency: veth (raw Ethernet) and pty (serial, COBS).

    python benchmarks/bench_transport.py [--runs 5]

Goodput is program words per second from the first BEGIN to the COMMIT's ACK (median of
``--runs``). Efficiency is program payload bytes / bytes on the wire, counting both
directions (frames, COBS or Ethernet headers and padding, ACKs); the forward-only figure
is printed too.

* veth: sender and device in one process inside a private user+network namespace (the
  script re-runs itself under ``unshare -rn``), a veth pair between them. Baseline: the
  same load stop-and-wait (window 1).
* pty: a null-modem pair of ptys. A pty has no line rate, so the 115200 and 3,000,000 baud
  figures pace every write at 10 bits per byte (8N1) on both ends: they are wire-time
  limited figures. The "unpaced" row is raw pty goodput. Baseline: the line rate itself
  (payload bytes could at best move at baud/10 bytes per second).
"""

from __future__ import annotations

import argparse
import os
import random
import select
import statistics
import subprocess
import sys
import threading
import time
import tty

from rend3r.transport.cli import serve
from rend3r.transport.device import DeviceCore, RecordingExecutor
from rend3r.transport.links import DEFAULT_MAC, EthernetLink, Link, SerialLink, open_serial, parse_mac
from rend3r.transport.session import Sender


def program(n: int) -> list[int]:
    rng = random.Random(n)
    return [rng.getrandbits(32) for _ in range(n)]


def measure(sender: Sender, link: Link, words: list[int], runs: int) -> tuple[float, float, float]:
    """(median seconds per load, efficiency both ways, efficiency forward) over ``runs`` loads."""
    times = []
    tx0, rx0 = link.tx_bytes, link.rx_bytes
    for _ in range(runs):
        start = time.perf_counter()
        sender.load(words)
        times.append(time.perf_counter() - start)
    payload = 4 * len(words) * runs
    tx, rx = link.tx_bytes - tx0, link.rx_bytes - rx0
    return statistics.median(times), payload / (tx + rx), payload / tx


class PtyCable:
    """Two ptys whose masters are copied into each other."""

    def __init__(self) -> None:
        self.fds, self.masters, self.paths = [], [], []
        for _ in range(2):
            master, slave = os.openpty()
            tty.setraw(slave)
            self.fds += [master, slave]
            self.masters.append(master)
            self.paths.append(os.ttyname(slave))
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self._copy, daemon=True)
        self.thread.start()

    def _copy(self) -> None:
        a, b = self.masters
        other = {a: b, b: a}
        while not self.stop.is_set():
            for fd in select.select([a, b], [], [], 0.05)[0]:
                data = memoryview(os.read(fd, 65536))
                while data:
                    data = data[os.write(other[fd], data):]

    def close(self) -> None:
        self.stop.set()
        self.thread.join()
        for fd in self.fds:
            os.close(fd)


def bench_pty(runs: int) -> None:
    print("serial over a pty pair (COBS framing)")
    print(f"  {'line':>18} {'words':>6} {'median ms':>10} {'words/s':>10} {'eff both':>9} "
          f"{'eff fwd':>8} {'vs line':>8}")
    cases = [(None, n) for n in (1000, 1024, 4096, 16384)] + [(115200, 1024), (115200, 2048),
                                                                (3_000_000, 4096), (3_000_000, 16384)]
    for baud, n in cases:
        cable = PtyCable()
        core = DeviceCore(RecordingExecutor())
        dlink = SerialLink(open_serial(cable.paths[1]), line_rate=baud)
        stop = threading.Event()
        t = threading.Thread(target=serve, args=(dlink, core, stop, 0.01), daemon=True)
        t.start()
        link = SerialLink(open_serial(cable.paths[0]), line_rate=baud)
        words = program(n)
        secs, eff, fwd = measure(Sender(link, timeout=2.0), link, words, 1 if baud == 115200 else runs)
        assert core.active == tuple(words)
        stop.set()
        t.join()
        link.close()
        dlink.close()
        cable.close()
        line = "unpaced" if baud is None else f"paced {baud}"
        vs = "" if baud is None else f"{(n * 4 / secs) / (baud / 10):8.1%}"
        print(f"  {line:>18} {n:>6} {secs * 1e3:10.1f} {n / secs:10.0f} {eff:9.2%} {fwd:8.2%} {vs:>8}")


def bench_veth(runs: int) -> None:
    subprocess.run("ip link add v0 type veth peer name v1 && ip link set v0 up && ip link set v1 up",
                   shell=True, check=True)
    mac = parse_mac(DEFAULT_MAC)
    core = DeviceCore(RecordingExecutor(), max_words=1 << 20)
    dlink = EthernetLink("v1", device_mac=mac)
    stop = threading.Event()
    t = threading.Thread(target=serve, args=(dlink, core, stop, 0.01), daemon=True)
    t.start()
    print("raw Ethernet over veth (in a private network namespace)")
    print(f"  {'window':>8} {'words':>6} {'median ms':>10} {'words/s':>11} {'eff both':>9} {'eff fwd':>8}")
    with EthernetLink("v0", peer=mac) as link:
        for n in (1024, 16384, 65536):
            words = program(n)
            results = {}
            for window in (1, 8):
                secs, eff, fwd = measure(Sender(link, timeout=0.5, window=window), link, words, runs)
                assert core.active == tuple(words)
                results[window] = secs
                print(f"  {window:>8} {n:>6} {secs * 1e3:10.2f} {n / secs:11.0f} {eff:9.2%} {fwd:8.2%}")
            print(f"  {'':>8} {n:>6} windowed is {results[1] / results[8]:.2f}x stop-and-wait")
    stop.set()
    t.join()
    dlink.close()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--in-netns", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.in_netns:
        bench_veth(args.runs)
        return
    r = subprocess.run(["unshare", "-rn", sys.executable, __file__, "--in-netns", "--runs", str(args.runs)])
    if r.returncode:
        print("veth benchmark skipped: cannot create a private network namespace here")
    bench_pty(args.runs)


if __name__ == "__main__":
    main()
