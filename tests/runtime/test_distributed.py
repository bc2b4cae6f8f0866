"""The match as nodes on zenoh (loopback): lock-step equals the embedded match; a silent team is
stepped without and its robots brake; a node that comes back rejoins."""

from __future__ import annotations

import math
import threading
from collections.abc import Iterator
from typing import Any

import pytest

from cmdragons.runtime.distributed import MatchSpec, node_roles, run_clock, run_node
from cmdragons.runtime.match import Match
from cmdragons.runtime.stages import Tap
from tests.runtime.test_zenoh import SETTINGS, loopback_params

SECONDS = 1.0
SEED = 7


@pytest.fixture
def router() -> Iterator[Any]:
    import zenoh

    params = loopback_params("match")
    session = zenoh.open(params.zenoh.config("router"))
    try:
        yield params
    finally:
        session.close()


def _nodes(spec: MatchSpec, roles: list[str], stop: threading.Event) -> list[threading.Thread]:
    from cmdragons.runtime.zenoh_transport import ZenohTransport

    def node(role: str) -> None:
        t = ZenohTransport(spec.settings.runtime, role)
        try:
            run_node(role, spec, t, should_stop=stop.is_set)
        finally:
            t.close()

    threads = [threading.Thread(target=node, args=(r,), daemon=True) for r in roles]
    for th in threads:
        th.start()
    return threads


def test_lock_step_nodes_play_the_embedded_match(router: Any) -> None:
    import dataclasses

    from cmdragons.runtime.zenoh_transport import ZenohTransport

    settings = dataclasses.replace(SETTINGS, runtime=router)
    embedded: list[Any] = []
    m = Match(settings, "simple", "truth", seed=SEED,
              extra=[Tap("rec", ("commands/*", "referee"), lambda t, x: embedded.append((t, x)))])  # fmt: skip
    expected = m.run(SECONDS)
    spec = MatchSpec(settings, "simple", "truth", m.seed)
    roles = node_roles("simple", log=False)
    stop = threading.Event()
    threads = _nodes(spec, [r for r in roles if r != "sim"], stop)
    got: list[Any] = []
    clock = ZenohTransport(router, "sim")
    try:
        summary = run_clock(spec, clock, SECONDS, roles,
                            extra=[Tap("rec", ("commands/*", "referee"), lambda t, x: got.append((t, x)))])  # fmt: skip
    finally:
        stop.set()
        for th in threads:
            th.join(10)
        clock.close()
    for key in ("score", "shots", "passes", "collisions", "kicks", "balls_out", "command_faults", "tracker"):
        assert summary[key] == expected[key], key
    by_topic = {t: [x for tt, x in embedded if tt == t] for t in ("commands/blue", "commands/yellow", "referee")}
    for topic, xs in by_topic.items():
        assert [x for t, x in got if t == topic] == xs, topic
    assert summary["frames_stepped_without_a_team"] == 0 and summary["dropped_messages"] == 0


def test_a_silent_team_is_stepped_without_and_its_robots_brake(router: Any) -> None:
    import dataclasses

    from cmdragons.runtime.zenoh_transport import ZenohTransport

    settings = dataclasses.replace(SETTINGS, runtime=dataclasses.replace(router, lockstep_wait_s=0.05))
    spec = MatchSpec(settings, "simple", "truth", SEED)
    roles = [r for r in node_roles("simple", log=False) if r != "team"]  # our team's node never comes
    stop = threading.Event()
    threads = _nodes(spec, [r for r in roles if r != "sim"], stop)
    truth: list[Any] = []
    clock = ZenohTransport(settings.runtime, "sim")
    try:
        summary = run_clock(spec, clock, 0.75, roles, extra=[Tap("rec", ("truth",), lambda _t, x: truth.append(x))])
    finally:
        stop.set()
        for th in threads:
            th.join(10)
        clock.close()
    frames = summary["frames"]
    assert summary["frames_stepped_without_a_team"] == frames
    blue = [r for r in truth[-1].robots if r.team == "blue"]
    # never commanded: the watchdog holds them (braked, at rest) while the opponent plays
    assert blue and all(math.hypot(r.vx, r.vy) < 0.05 for r in blue)
    assert any(math.hypot(r.vx, r.vy) > 0.1 for tr in truth for r in tr.robots if r.team == "yellow")
