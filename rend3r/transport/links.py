"""Links carry protocol frames: serial (COBS), raw Ethernet, in-memory, and a fault injector.

A link moves whole protocol frames (see :mod:`.protocol`) and adds its own delimiting.
``recv`` returns one frame's bytes, None when ``timeout`` passed without one, and raises
:class:`~.protocol.FrameError` for bytes that arrived but cannot be a frame. ``tx_bytes``
and ``rx_bytes`` count bytes on the wire, framing included.
"""

from __future__ import annotations

import errno
import random
import re
import socket
import struct
import time
from collections import deque
from typing import Callable

from . import cobs
from .protocol import MAX_FRAME, FrameError
from ..errors import Rend3rError

DEFAULT_MAC = "69:69:5a:06:54:91"  # the original design's device address
DEFAULT_ETHERTYPE = 0x88B5  # IEEE 802 local experimental EtherType 1
BROADCAST = b"\xff" * 6
ETH_HEADER = 14
ETH_MIN_FRAME = 60  # without FCS; shorter frames are padded with zeros
ETH_MAX_PAYLOAD = 1500
_MAC_RE = re.compile(r"^[0-9a-fA-F]{2}([:-][0-9a-fA-F]{2}){5}$")


class Link:
    """Base class: counters and context management; subclasses implement send/recv."""

    tx_bytes = 0
    rx_bytes = 0

    def send(self, frame: bytes) -> None:
        raise NotImplementedError

    def recv(self, timeout: float) -> bytes | None:
        raise NotImplementedError

    def limit_writes(self, seconds: float) -> None:
        """Make a write that cannot proceed for ``seconds`` fail instead of blocking (links
        that can block: a serial port whose other end stopped reading)."""

    def close(self) -> None:
        """Release the link's resources."""

    def __enter__(self) -> Link:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


# -- serial ----------------------------------------------------------------------------


def open_serial(port: str, baud: int = 115200):
    """Open a serial device path or pyserial URL exclusively; Rend3rError if impossible."""
    import serial

    try:
        return serial.serial_for_url(port, baudrate=baud, timeout=0, write_timeout=None,
                                     exclusive=True)
    except (serial.SerialException, OSError, ValueError) as exc:
        msg = str(exc)
        if "lock" in msg.lower() or getattr(exc, "errno", None) in (errno.EBUSY, errno.EAGAIN):
            raise Rend3rError(f"serial port {port} is busy (another program has it open)") from exc
        raise Rend3rError(f"cannot open serial port {port}: {msg}") from exc


class SerialLink(Link):
    """Frames over a byte stream: COBS-encoded and each followed by a 0x00 delimiter.

    ``line_rate`` (baud, 8N1: 10 bits per byte) makes ``send`` take as long as the bytes
    would on a real line, for modelling a port that has no rate of its own (a pty).
    """

    POLL = 0.02  # longest single blocking read, seconds

    def __init__(self, port, line_rate: int | None = None) -> None:
        self.port = port
        self.line_rate = line_rate
        self._buf = bytearray()
        self._line_free = 0.0
        self._sent = False
        self.tx_bytes = self.rx_bytes = 0

    def send(self, frame: bytes) -> None:
        data = cobs.encode(frame) + b"\0"
        if not self._sent:  # a leading delimiter ends whatever noise the line held before
            data = b"\0" + data
            self._sent = True
        self.write(data)

    def limit_writes(self, seconds: float) -> None:
        self.port.write_timeout = seconds  # pyserial raises SerialTimeoutException

    def write(self, data: bytes) -> None:
        """Write raw bytes (paced when ``line_rate`` is set)."""
        self.port.write(data)
        self.port.flush()
        self.tx_bytes += len(data)
        if self.line_rate:
            now = time.monotonic()
            self._line_free = max(now, self._line_free) + len(data) * 10 / self.line_rate
            time.sleep(max(0.0, self._line_free - now))

    def recv(self, timeout: float) -> bytes | None:
        deadline = time.monotonic() + timeout
        while True:
            end = self._buf.find(0)
            if end >= 0:
                raw = bytes(self._buf[:end])
                del self._buf[:end + 1]
                if not raw:
                    continue  # an empty frame: delimiters back to back
                try:
                    return cobs.decode(raw)
                except cobs.CobsError as exc:
                    raise FrameError(str(exc)) from exc
            if len(self._buf) > 2 * MAX_FRAME:
                self._buf.clear()  # no delimiter for too long: line noise; resynchronise
                raise FrameError("more than a frame's worth of bytes without a delimiter")
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                return None
            wait = min(remaining, self.POLL)
            if self.port.timeout != wait:  # reconfiguring a port costs system calls
                self.port.timeout = wait
            chunk = self.port.read(max(1, self.port.in_waiting))
            self.rx_bytes += len(chunk)
            self._buf += chunk

    def close(self) -> None:
        self.port.close()


# -- Ethernet --------------------------------------------------------------------------


def parse_mac(text: str) -> bytes:
    """``aa:bb:cc:dd:ee:ff`` (or with dashes) to 6 bytes; Rend3rError if malformed."""
    if not _MAC_RE.match(text.strip()):
        raise Rend3rError(f"malformed MAC address {text!r}: expected six hex pairs like {DEFAULT_MAC}")
    return bytes(int(p, 16) for p in re.split(r"[:-]", text.strip()))


def format_mac(mac: bytes) -> str:
    return ":".join(f"{b:02x}" for b in mac)


def ethernet_frame(dst: bytes, src: bytes, ethertype: int, payload: bytes) -> bytes:
    """An Ethernet II frame without FCS, zero-padded to the 60-byte minimum."""
    frame = dst + src + struct.pack(">H", ethertype) + payload
    return frame + bytes(max(0, ETH_MIN_FRAME - len(frame)))


def interface_index(iface: str) -> int:
    """The interface's index; Rend3rError naming the interface if there is none."""
    try:
        return socket.if_nametoindex(iface)
    except OSError as exc:
        raise Rend3rError(f"no such network interface: {iface}") from exc


_SOL_PACKET = 263
_PACKET_ADD_MEMBERSHIP = 1
_PACKET_MR_MULTICAST = 0
_PACKET_MR_PROMISC = 1
_PACKET_OUTGOING = 4


class EthernetLink(Link):
    """Protocol frames in Ethernet II frames on an AF_PACKET socket bound to one interface.

    As a sender it addresses ``peer`` and accepts frames for its own MAC. As a device
    (``device=True``) it accepts frames for ``own`` (multicast allowed) or broadcast and
    answers whoever sent the last one, from the interface's own address.
    """

    def __init__(self, iface: str, peer: bytes | None = None, ethertype: int = DEFAULT_ETHERTYPE,
                 device_mac: bytes | None = None) -> None:
        index = interface_index(iface)
        try:
            self.sock = socket.socket(socket.AF_PACKET, socket.SOCK_RAW, socket.htons(ethertype))
        except PermissionError as exc:
            raise Rend3rError(
                f"no permission to open a raw socket on {iface}: run as root or give the "
                "Python interpreter CAP_NET_RAW (setcap cap_net_raw+ep ...), or write the frames to a file "
                "with -o FILE.pcap"
            ) from exc
        try:
            self.sock.bind((iface, ethertype))
        except OSError as exc:
            self.sock.close()
            raise Rend3rError(f"cannot bind a raw socket to {iface}: {exc.strerror or exc}") from exc
        self.iface = iface
        self.ethertype = ethertype
        self.mac = self.sock.getsockname()[4][:6]
        self.peer = peer
        self.accept = {device_mac, BROADCAST} if device_mac is not None else {self.mac}
        self.device = device_mac is not None
        self.foreign = 0  # frames of our EtherType addressed to someone else
        self.tx_bytes = self.rx_bytes = 0
        if device_mac is not None and device_mac != self.mac:
            mr_type = _PACKET_MR_MULTICAST if device_mac[0] & 1 else _PACKET_MR_PROMISC
            mreq = struct.pack("iHH8s", index, mr_type, 6, device_mac)
            self.sock.setsockopt(_SOL_PACKET, _PACKET_ADD_MEMBERSHIP, mreq)

    def send(self, frame: bytes) -> None:
        if self.peer is None:
            raise Rend3rError("no peer to send to yet")
        self.send_payload(frame)

    def send_payload(self, payload: bytes) -> None:
        """Send ``payload`` (at most 1500 bytes) in one Ethernet frame to the peer."""
        data = ethernet_frame(self.peer, self.mac, self.ethertype, payload)
        self.sock.send(data)
        self.tx_bytes += len(data)

    def recv(self, timeout: float) -> bytes | None:
        deadline = time.monotonic() + timeout
        while True:
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                return None
            self.sock.settimeout(remaining)
            try:
                data, addr = self.sock.recvfrom(65536)
            except (socket.timeout, BlockingIOError):
                return None
            if addr[2] == _PACKET_OUTGOING:
                continue
            self.rx_bytes += len(data)
            if len(data) < ETH_HEADER or data[:6] not in self.accept:
                self.foreign += 1
                continue
            if self.device:
                self.peer = data[6:12]
            return data[ETH_HEADER:]

    def close(self) -> None:
        self.sock.close()


# -- in memory and fault injection -----------------------------------------------------


class DirectLink(Link):
    """A sender's link straight into a device's ``handle`` function, in the same thread.

    Nothing arrives later than the device answers, so ``recv`` never needs to wait: a
    missing reply is reported at once as a timeout (time is virtual).
    """

    def __init__(self, handle: Callable[[bytes], bytes | None]) -> None:
        self.handle = handle
        self.inbox: deque[bytes] = deque()
        self.tx_bytes = self.rx_bytes = 0

    def send(self, frame: bytes) -> None:
        self.tx_bytes += len(frame)
        reply = self.handle(frame)
        if reply is not None:
            self.inbox.append(reply)

    def recv(self, timeout: float) -> bytes | None:
        if not self.inbox:
            return None
        reply = self.inbox.popleft()
        self.rx_bytes += len(reply)
        return reply


class FaultLink(Link):
    """Wraps a link and, in both directions, loses, corrupts, duplicates and reorders frames.

    Each rate is a probability per frame; ``seed`` makes a run reproducible. A reordered
    frame is held back and delivered after the next one (or at the next idle moment).
    """

    def __init__(self, inner: Link, *, loss: float = 0.0, corrupt: float = 0.0,
                 duplicate: float = 0.0, reorder: float = 0.0, seed: int | None = None) -> None:
        self.inner = inner
        self.rates = (loss, corrupt, duplicate, reorder)
        self.rng = random.Random(seed)
        self._held_out: bytes | None = None
        self._inbox: deque[bytes] = deque()
        self._held_in: bytes | None = None
        self.injected = {"loss": 0, "corrupt": 0, "duplicate": 0, "reorder": 0}

    @property
    def tx_bytes(self) -> int:  # type: ignore[override]
        return self.inner.tx_bytes

    @property
    def rx_bytes(self) -> int:  # type: ignore[override]
        return self.inner.rx_bytes

    def _mangle(self, frame: bytes) -> list[bytes]:
        """What the fault model delivers for ``frame``: nothing, it, or it twice."""
        loss, corrupt, duplicate, _ = self.rates
        rng = self.rng
        if rng.random() < loss:
            self.injected["loss"] += 1
            return []
        if rng.random() < corrupt:
            self.injected["corrupt"] += 1
            frame = self._corrupt(frame)
        if rng.random() < duplicate:
            self.injected["duplicate"] += 1
            return [frame, frame]
        return [frame]

    def _corrupt(self, frame: bytes) -> bytes:
        rng = self.rng
        data = bytearray(frame)
        if data and rng.random() < 0.8:
            for _ in range(rng.randint(1, 4)):
                data[rng.randrange(len(data))] ^= 1 << rng.randrange(8)
            return bytes(data)
        return bytes(data[:rng.randrange(len(data) + 1)])  # truncated

    def _reorders(self) -> bool:
        if self.rng.random() < self.rates[3]:
            self.injected["reorder"] += 1
            return True
        return False

    def send(self, frame: bytes) -> None:
        for f in self._mangle(frame):
            if self._held_out is None and self._reorders():
                self._held_out = f
                continue
            self.inner.send(f)
            if self._held_out is not None:
                held, self._held_out = self._held_out, None
                self.inner.send(held)

    def recv(self, timeout: float) -> bytes | None:
        if self._held_out is not None:  # the sender went idle: the held frame arrives now
            held, self._held_out = self._held_out, None
            self.inner.send(held)
        deadline = time.monotonic() + timeout
        while not self._inbox:
            frame = self.inner.recv(max(0.0, deadline - time.monotonic()))
            if frame is None:
                if self._held_in is not None:
                    held, self._held_in = self._held_in, None
                    return held
                return None
            for f in self._mangle(frame):
                if self._held_in is None and self._reorders():
                    self._held_in = f
                else:
                    self._inbox.append(f)
                    if self._held_in is not None:
                        self._inbox.append(self._held_in)
                        self._held_in = None
        return self._inbox.popleft()

    def limit_writes(self, seconds: float) -> None:
        self.inner.limit_writes(seconds)

    def close(self) -> None:
        self.inner.close()
