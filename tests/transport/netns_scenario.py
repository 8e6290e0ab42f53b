"""Run inside a fresh user+network namespace (``unshare -rn``): veth pair v0 <-> v1.

Invoked by test_ethernet.py as ``unshare -rn python netns_scenario.py``; prints one JSON
object with what it observed. It only ever touches the namespace's own v0, v1 and lo.
"""

from __future__ import annotations

import json
import random
import subprocess
import threading

from rend3r.transport.cli import serve
from rend3r.transport.device import DeviceCore, RecordingExecutor
from rend3r.transport.links import BROADCAST, DEFAULT_MAC, EthernetLink, parse_mac
from rend3r.transport.protocol import FrameType, program_crc
from rend3r.transport.session import Sender, SendError


def main() -> None:
    subprocess.run("ip link add v0 type veth peer name v1 && ip link set v0 up && ip link set v1 up",
                   shell=True, check=True)
    mac = parse_mac(DEFAULT_MAC)
    ex = RecordingExecutor()
    core = DeviceCore(ex, max_words=20000)
    device_link = EthernetLink("v1", device_mac=mac)
    stop = threading.Event()
    thread = threading.Thread(target=serve, args=(device_link, core, stop, 0.02), daemon=True)
    thread.start()
    out: dict[str, object] = {}
    rng = random.Random(3)
    try:
        with EthernetLink("v0", peer=mac) as link:
            sender = Sender(link, timeout=0.2)
            programs = [[rng.getrandbits(32) for _ in range(n)] for n in (0, 1, 255, 257, 16384)]
            out["loads"] = []
            for words in programs:
                sender.load(words)
                status = sender.status()
                out["loads"].append([status.words == len(words), status.crc == program_crc(words),
                                     core.active == tuple(words)])
            out["started"] = [list(p) == w for p, w in zip(ex.started, programs)]
            out["resends"] = sender.stats.resends
        with EthernetLink("v0", peer=BROADCAST) as link:
            Sender(link, timeout=0.2).control(FrameType.STOP)
            out["broadcast_stop"] = not core.running
        with EthernetLink("v0", peer=parse_mac("02:00:00:00:00:99")) as link:
            out["other_mac"] = _fails(Sender(link, timeout=0.05, retries=1))
        with EthernetLink("v0", peer=mac, ethertype=0x88B6) as link:
            out["other_ethertype"] = _fails(Sender(link, timeout=0.05, retries=1))
        out["foreign"] = device_link.foreign
    finally:
        stop.set()
        thread.join()
        device_link.close()
    print(json.dumps(out))


def _fails(sender: Sender) -> str:
    try:
        sender.control(FrameType.STATUS)
    except SendError as exc:
        return str(exc)
    return "answered"


if __name__ == "__main__":
    main()
