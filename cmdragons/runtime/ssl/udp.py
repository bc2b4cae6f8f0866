"""UDP sockets for the league's protocols: multicast pinned to one interface, unicast to a peer.

Multicast is sent with ``IP_MULTICAST_IF`` set to the configured interface's address and the
configured TTL (defaults: 127.0.0.1 and 0, so nothing leaves this machine), and received by joining
the group on that same interface: a socket that joins on INADDR_ANY hears nothing over loopback, and
a sender without a pinned interface follows the default route. Receivers bind to the group's
address (they hear only that group) with ``SO_REUSEADDR``, so several programs on one host can
listen to the same stream, as league software does.

:class:`DropLog` counts the packets a receiver drops by reason and says so on stderr, one line at
most every ``interval_s``.
"""

from __future__ import annotations

import select
import socket
import sys
import time
from typing import TextIO

__all__ = ["DatagramQueue", "DropLog", "MulticastReceiver", "MulticastSender", "UdpEndpoint", "free_udp_ports"]


def _sockopt_reuse(sock: socket.socket) -> None:
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    if hasattr(socket, "SO_REUSEPORT"):
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEPORT, 1)


class MulticastSender:
    """Sends datagrams to ``group:port`` out of the interface with address ``interface``, ``ttl`` hops."""

    def __init__(self, group: str, port: int, interface: str, ttl: int) -> None:
        self.address = (group, port)
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
        self.sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_IF, socket.inet_aton(interface))
        self.sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, ttl)
        self.sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_LOOP, 1)  # receivers on this host hear it
        self.sent = 0
        self.bytes = 0

    def send(self, data: bytes) -> None:
        self.sock.sendto(data, self.address)
        self.sent += 1
        self.bytes += len(data)

    def close(self) -> None:
        self.sock.close()


class MulticastReceiver:
    """Joins ``group`` on the interface with address ``interface`` and reads ``port``'s datagrams."""

    def __init__(self, group: str, port: int, interface: str, buffer_bytes: int, max_bytes: int = 65507) -> None:
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
        _sockopt_reuse(self.sock)
        self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, buffer_bytes)
        self.sock.bind((group, port))
        membership = socket.inet_aton(group) + socket.inet_aton(interface)
        self.sock.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP, membership)
        self.sock.setblocking(False)
        self.max_bytes = max_bytes

    def receive(self, timeout_s: float = 0.0) -> bytes | None:
        """The next datagram, waiting up to ``timeout_s``; None when none came."""
        try:
            return self.sock.recv(self.max_bytes)
        except BlockingIOError:
            pass
        if timeout_s <= 0.0:
            return None
        ready, _, _ = select.select([self.sock], [], [], timeout_s)
        if not ready:
            return None
        try:
            return self.sock.recv(self.max_bytes)
        except BlockingIOError:
            return None

    def drain(self) -> list[bytes]:
        """Every datagram waiting now."""
        out: list[bytes] = []
        data = self.receive()
        while data is not None:
            out.append(data)
            data = self.receive()
        return out

    def close(self) -> None:
        self.sock.close()


class DatagramQueue:
    """Datagrams handed in by the program (a log file's records) instead of a socket, with a
    receiver's :meth:`receive` and :meth:`drain`: what a receiving stage reads in a replay."""

    def __init__(self) -> None:
        self._items: list[bytes] = []

    def push(self, data: bytes) -> None:
        self._items.append(data)

    def receive(self, timeout_s: float = 0.0) -> bytes | None:
        return self._items.pop(0) if self._items else None

    def drain(self) -> list[bytes]:
        out, self._items = self._items, []
        return out

    def close(self) -> None:
        self._items = []


def free_udp_ports(n: int) -> list[int]:
    """``n`` UDP ports free on loopback now (held open together so they differ): a stream of its own
    for a test or a bench's match, never heard by another running beside it."""
    socks = [socket.socket(socket.AF_INET, socket.SOCK_DGRAM) for _ in range(n)]
    try:
        for s in socks:
            s.bind(("127.0.0.1", 0))
        return [int(s.getsockname()[1]) for s in socks]
    finally:
        for s in socks:
            s.close()


class UdpEndpoint:
    """A unicast socket bound to ``address:port`` (port 0: any free one): what grSim and the
    simulation protocol speak. :meth:`send_to` a peer, :meth:`receive` with the sender's address."""

    def __init__(self, address: str, port: int = 0, max_bytes: int = 65507) -> None:
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
        try:
            self.sock.bind((address, port))
        except OSError:  # (a port another program holds) the socket is not left open
            self.sock.close()
            raise
        self.sock.setblocking(False)
        self.max_bytes = max_bytes
        self.port = self.sock.getsockname()[1]

    def send_to(self, data: bytes, address: tuple[str, int]) -> None:
        self.sock.sendto(data, address)

    def receive(self, timeout_s: float = 0.0) -> tuple[bytes, tuple[str, int]] | None:
        if timeout_s > 0.0:
            select.select([self.sock], [], [], timeout_s)
        try:
            data, peer = self.sock.recvfrom(self.max_bytes)
        except BlockingIOError:
            return None
        return data, (str(peer[0]), int(peer[1]))

    def close(self) -> None:
        self.sock.close()


class DropLog:
    """Counts dropped packets by reason; one stderr line at most every ``interval_s`` (the first at
    once) naming the stream, the reason of the last drop and the counts so far."""

    def __init__(self, stream: str, interval_s: float, err: TextIO | None = None) -> None:
        self.stream = stream
        self.interval_s = interval_s
        self.counts: dict[str, int] = {}
        self._err = err if err is not None else sys.stderr
        self._last = -float("inf")

    def drop(self, reason: str, detail: str) -> None:
        self.counts[reason] = self.counts.get(reason, 0) + 1
        now = time.monotonic()
        if now - self._last >= self.interval_s:
            self._last = now
            counts = ", ".join(f"{k} {v}" for k, v in sorted(self.counts.items()))
            print(f"{self.stream}: dropped a packet ({reason}: {detail}); dropped so far: {counts}", file=self._err)

    @property
    def total(self) -> int:
        return sum(self.counts.values())
