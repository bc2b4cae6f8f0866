"""Shared fixtures of the runtime tests."""

from __future__ import annotations

import socket

import pytest

from cmdragons.runtime.ssl.udp import free_udp_ports

__all__ = ["free_udp_ports"]


@pytest.fixture
def udp_port() -> int:
    """A UDP port free on loopback now: each test's multicast stream on its own port, so tests that
    run at once (pytest -n, other checkouts on this machine) never hear each other's packets."""
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])
