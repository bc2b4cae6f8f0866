"""Shared fixtures of the runtime tests."""

from __future__ import annotations

import socket

import pytest


@pytest.fixture
def udp_port() -> int:
    """A UDP port free on loopback now: each test's multicast stream on its own port, so tests that
    run at once (pytest -n, other checkouts on this machine) never hear each other's packets."""
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def free_udp_ports(n: int) -> list[int]:
    """``n`` UDP ports free on loopback now (held open together so they differ)."""
    socks = [socket.socket(socket.AF_INET, socket.SOCK_DGRAM) for _ in range(n)]
    try:
        for s in socks:
            s.bind(("127.0.0.1", 0))
        return [int(s.getsockname()[1]) for s in socks]
    finally:
        for s in socks:
            s.close()
