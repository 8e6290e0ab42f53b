"""Raw Ethernet over a veth pair inside a user+network namespace the test creates; pcap output.

Nothing here sends on an interface outside that namespace: every raw socket is opened by a
process started under ``unshare -rn``.
"""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from rend3r.transport.links import DEFAULT_ETHERTYPE
from rend3r.transport.protocol import FrameType, decode, program_crc, words_to_bytes



def netns_available() -> str | None:
    """None if ``unshare -rn`` can create a veth pair here, else the reason it cannot."""
    if shutil.which("unshare") is None or shutil.which("ip") is None:
        return "needs unshare(1) and ip(8)"
    probe = subprocess.run(["unshare", "-rn", "sh", "-c", "ip link add v0 type veth peer name v1"],
                           capture_output=True, text=True, timeout=30)
    if probe.returncode != 0:
        return f"cannot create a veth pair in a user+network namespace: {probe.stderr.strip()}"
    return None


HERE = Path(__file__).parent
PROGRAM = [0x200, 0x3C000009, 0x400, 0, 0]
RENDER = [sys.executable, "-m", "rend3r"]
NETNS = netns_available()
needs_netns = pytest.mark.skipif(NETNS is not None, reason=f"no private network namespace: {NETNS}")


def in_netns(script: str, timeout: float = 120) -> subprocess.CompletedProcess:
    return subprocess.run(["unshare", "-rn", "sh", "-c", script], capture_output=True, text=True,
                          timeout=timeout)


@needs_netns
@pytest.mark.timeout(180)
def test_loads_over_veth_with_filtering():
    r = subprocess.run(["unshare", "-rn", sys.executable, str(HERE / "netns_scenario.py")],
                       capture_output=True, text=True, timeout=150)
    assert r.returncode == 0, r.stderr
    out = json.loads(r.stdout)
    assert out["loads"] == [[True, True, True]] * 5
    assert out["started"] == [True] * 5
    assert out["broadcast_stop"] is True
    assert "no acknowledgement for STATUS after 2 tries" in out["other_mac"]
    assert "no acknowledgement for STATUS after 2 tries" in out["other_ethertype"]
    assert out["foreign"] >= 2  # the frames to 02:00:00:00:00:99 reached the socket and were dropped


@needs_netns
def test_unknown_interface_and_no_raw_socket_permission(tmp_path):
    prog = tmp_path / "p.mem"
    prog.write_text("00000000\n")
    r = in_netns(f"ip link add v0 type veth peer name v1; "
                 f"{' '.join(RENDER)} send {prog} --eth nosuch0")
    assert r.returncode == 1 and "rend3r: error: no such network interface: nosuch0" in r.stderr
    r = in_netns(f"ip link add v0 type veth peer name v1; {' '.join(RENDER)} send {prog} --eth v0")
    assert r.returncode == 1 and "the link failed: Network is down" in r.stderr, r.stderr
    if shutil.which("setpriv") is None:
        pytest.skip("needs setpriv(1) to drop CAP_NET_RAW")
    r = in_netns(f"ip link add v0 type veth peer name v1; ip link set v0 up; "
                 f"setpriv --bounding-set -net_raw {' '.join(RENDER)} send {prog} --eth v0")
    assert r.returncode == 1, r.stderr
    assert "no permission to open a raw socket on v0" in r.stderr and "CAP_NET_RAW" in r.stderr
    assert "-o FILE.pcap" in r.stderr and "--pcap" not in r.stderr
    assert "Traceback" not in r.stderr


@pytest.mark.parametrize("mac", ["69:69:5a:06:54", "69:69:5a:06:54:9g", "6969.5a06.5491", ""])
def test_malformed_mac_is_refused(tmp_path, mac):
    prog = tmp_path / "p.mem"
    prog.write_text("00000000\n")
    r = subprocess.run(RENDER + ["send", str(prog), "--pcap", str(tmp_path / "o.pcap"), "--mac", mac],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 1 and "malformed MAC address" in r.stderr
    assert not (tmp_path / "o.pcap").exists()


def test_pcap_holds_the_exact_frames(tmp_path):
    from scapy.layers.l2 import Ether
    from scapy.utils import rdpcap

    prog = tmp_path / "p.mem"
    words = list(range(1, 301))
    prog.write_text("".join(f"{w:08x}\n" for w in words))
    out = tmp_path / "o.pcap"
    r = subprocess.run(RENDER + ["send", str(prog), "--pcap", str(out), "--run"],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    packets = rdpcap(str(out))
    assert all(p.haslayer(Ether) and p[Ether].dst == "69:69:5a:06:54:91"
               and p[Ether].type == DEFAULT_ETHERTYPE and len(p) >= 60 for p in packets)
    frames = [decode(bytes(p[Ether].payload)) for p in packets]  # padding ignored via length
    assert [f.type for f in frames] == [FrameType.BEGIN, FrameType.DATA, FrameType.DATA,
                                        FrameType.COMMIT, FrameType.RUN]
    assert b"".join(f.payload for f in frames[1:3]) == words_to_bytes(words)
    assert frames[0].payload[4:] == program_crc(words).to_bytes(4, "big")


def test_raw_pcap_is_bare_words(tmp_path):
    from scapy.layers.l2 import Ether
    from scapy.utils import rdpcap

    prog = tmp_path / "p.mem"
    words = list(range(400))
    prog.write_text("".join(f"{w:08x}\n" for w in words))
    out = tmp_path / "raw.pcap"
    r = subprocess.run(RENDER + ["send", str(prog), "--pcap", str(out), "--framing", "raw",
                                 "--ethertype", "0x88b6"], capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    packets = rdpcap(str(out))
    assert [p[Ether].type for p in packets] == [0x88B6, 0x88B6]
    assert b"".join(bytes(p[Ether].payload) for p in packets) == words_to_bytes(words)


@needs_netns
@pytest.mark.timeout(180)
def test_send_and_device_commands_over_veth(tmp_path):
    """Both commands, each in its own process, inside one private namespace."""
    prog = Path(__file__).resolve().parents[2] / "programs" / "sphere.asm"
    out, log = tmp_path / "frames", tmp_path / "device.log"
    rend3r = " ".join(RENDER)
    script = f"""
        set -e
        ip link add v0 type veth peer name v1; ip link set v0 up; ip link set v1 up
        {rend3r} device --eth v1 -o {out} --size 32x24 --frames 1 2>{log} & pid=$!
        until grep -q listening {log}; do sleep 0.05; done
        {rend3r} send {prog} --eth v0 --run
        {rend3r} send {prog} --eth v0 --mac 02:00:00:00:00:42 --timeout 0.05 --retries 1 || echo refused
        for i in $(seq 600); do ls {out}/*.png >/dev/null 2>&1 && break; sleep 0.1; done
        kill -TERM $pid; wait $pid
    """
    r = in_netns(script, timeout=170)
    device_log = log.read_text()
    assert r.returncode == 0, r.stderr + device_log
    assert "loaded" in r.stderr and "refused" in r.stdout
    assert "no acknowledgement for BEGIN after 2 tries" in r.stderr
    assert "stopped after 1 load (2 runs)" in device_log  # the commit starts it, --run restarts it and "frames for other addresses" in device_log
    assert list(out.glob("*.png"))
