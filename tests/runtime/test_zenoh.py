"""The zenoh transport on loopback: the default config stays on this machine; messages arrive as
the wire carries them; garbage is counted and dropped."""

from __future__ import annotations

import dataclasses
import io
import socket
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from cmdragons import messages as msg
from cmdragons.runtime import wire
from cmdragons.runtime.params import RuntimeParams, ZenohParams
from cmdragons.runtime.settings import load_settings

SETTINGS = load_settings(Path(__file__).resolve().parents[2] / "configs")


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def loopback_params(field_name: str = "test") -> RuntimeParams:
    """The default runtime config on a free loopback port (tests run side by side)."""
    z = dataclasses.replace(SETTINGS.runtime.zenoh, router=f"tcp/127.0.0.1:{free_port()}")
    return dataclasses.replace(SETTINGS.runtime, zenoh=z, field_name=field_name)


@pytest.fixture
def router() -> Iterator[RuntimeParams]:
    import zenoh

    params = loopback_params()
    session = zenoh.open(params.zenoh.config("router"))
    try:
        yield params
    finally:
        session.close()


@pytest.mark.parametrize("role", ["router", "client"])
def test_the_default_config_stays_on_loopback_without_multicast(role: str) -> None:
    cfg = SETTINGS.runtime.zenoh.session(role)
    assert cfg["scouting"]["multicast"]["enabled"] is False and cfg["scouting"]["gossip"]["enabled"] is False
    endpoints = cfg["listen"]["endpoints"] + cfg["connect"]["endpoints"]
    assert endpoints and all(e.startswith("tcp/127.0.0.1:") for e in endpoints)
    with pytest.raises(ValueError, match="network: true"):
        ZenohParams(router="tcp/10.0.0.1:7447")


def _transports(params: RuntimeParams, n: int, err: Any = None) -> list[Any]:
    from cmdragons.runtime.zenoh_transport import ZenohTransport

    return [ZenohTransport(params, f"node{k}", err=err) for k in range(n)]


def test_messages_arrive_as_the_wire_carries_them_locally_and_remotely(router: RuntimeParams) -> None:
    a, b = _transports(router, 2)
    try:
        got: dict[str, list[Any]] = {"a": [], "b": []}
        a.subscribe("detections/*", lambda t, m: got["a"].append((t, m)))
        b.subscribe("detections/*", lambda t, m: got["b"].append((t, m)))
        b.subscribe("camera/*", lambda t, m: got["b"].append((t, m)))
        assert a.wait_for(lambda: a.has_subscribers("camera/0/frame"), 10.0)
        det = msg.DetectionFrame(0, 1, 0.1, 0.1, (msg.BallDetection(0.123456789, 1.0, 0.9, (1.0, 2.0)),))
        image = np.random.default_rng(0).integers(0, 255, (160, 240, 3), dtype=np.uint8)  # 115 KB: shared memory
        a.publish("detections/0", det)
        a.publish("camera/0/frame", msg.CameraFrame(0, 1, 0.1, image))
        a.spin()
        assert b.wait_for(lambda: len(got["b"]) == 2, 10.0)
        assert got["a"] == [("detections/0", wire.canonical(det))]
        assert got["b"][0] == ("detections/0", wire.canonical(det)) and got["b"][0][1] != det  # 32-bit mm
        assert got["b"][1][0] == "camera/0/frame" and np.array_equal(got["b"][1][1].image, image)
    finally:
        for t in (a, b):
            t.close()


@pytest.mark.parametrize("latest_only", [True, False])
def test_a_receiver_behind_skips_to_the_newest_sensor_message_when_asked(router: RuntimeParams,
                                                                        latest_only: bool) -> None:
    import time

    from cmdragons.runtime.zenoh_transport import LATEST_ONLY

    a, b = _transports(router, 2)
    b.latest_only = LATEST_ONLY if latest_only else ()
    got: list[int] = []

    def slow(_t: str, d: Any) -> None:  # a stage busy with the first frame while four more come
        if not got:
            time.sleep(0.5)
        got.append(d.frame_number)

    try:
        b.subscribe("detections/*", slow)
        b.subscribe("referee", lambda _t, _m: got.append(-1))
        assert a.wait_for(lambda: a.has_subscribers("detections/0"), 10.0)
        for i in range(5):
            a.publish("detections/0", msg.DetectionFrame(0, i, i / 60, i / 60))
        a.publish("referee", msg.GameState(1.0, "stop"))  # not a sensor stream: always delivered
        assert b.wait_for(lambda: -1 in got and 4 in got, 10.0)
    finally:
        for t in (a, b):
            t.close()
    frames = [f for f in got if f >= 0]
    assert frames == sorted(set(frames)) and frames[-1] == 4 and got.count(-1) == 1
    if latest_only:  # of what waited while a frame was handled only the newest: each one delivered or skipped,
        # some skipped (how many arrive within the 0.5 s varies with the machine's load: a clean-clone CI run
        # saw 0-2 come together, then 3 and 4 one by one)
        assert len(frames) + b.superseded == 5 and b.superseded >= 1
    else:
        assert frames == [0, 1, 2, 3, 4] and b.superseded == 0


def test_local_only_topics_reach_this_process_only(router: RuntimeParams) -> None:
    a, b = _transports(router, 2)
    a.local_only = ("camera/*",)
    got: dict[str, list[str]] = {"a": [], "b": []}
    try:
        for name, t in (("a", a), ("b", b)):
            t.subscribe("camera/*", lambda topic, _m, name=name: got[name].append(topic))
            t.subscribe("clock", lambda topic, _m, name=name: got[name].append(topic))
        assert a.wait_for(lambda: a.has_subscribers("clock"), 10.0)
        a.publish("camera/0/frame", msg.CameraFrame(0, 1, 0.1, np.zeros((4, 4, 3), np.uint8)))
        a.publish("clock", msg.Tick(1))
        a.spin()
        assert b.wait_for(lambda: "clock" in got["b"], 10.0)
    finally:
        for t in (a, b):
            t.close()
    assert got == {"a": ["camera/0/frame", "clock"], "b": ["clock"]}


def test_a_topic_no_other_node_hears_is_not_sent_until_one_subscribes(router: RuntimeParams) -> None:
    params = dataclasses.replace(router, settle_s=0.2)
    a, b = _transports(params, 2)
    got: list[int] = []
    world = msg.WorldState(0.0, msg.BallState(0.0, 0.0, 0.0, 0.0), ())

    def sends() -> bool:
        before = a.sent
        a.publish("world/blue", world)
        return a.sent > before

    try:
        a.publish("world/blue", world)  # a new publisher: sent while it learns who subscribes
        assert a.sent == 1
        # it learns that nobody subscribes (how soon depends on the machine's load: a bounded wait)
        assert a.wait_for(lambda: not sends(), 10.0, poll_s=0.01)
        quiet = a.sent
        for _ in range(3):
            a.publish("world/blue", world)
        assert a.sent == quiet  # nobody subscribes: neither encoded nor sent
        b.subscribe("world/blue", lambda _t, w: got.append(w.frame_number))
        # the publisher hears of the subscriber on zenoh's thread: from then on it sends
        assert a.wait_for(lambda: a.has_subscribers("world/blue") and sends(), 10.0)
        for k in range(1, 4):
            a.publish("world/blue", dataclasses.replace(world, frame_number=k))
        assert b.wait_for(lambda: got[-3:] == [1, 2, 3], 10.0)
        assert len(got) == a.sent - quiet  # every message sent since was heard, and only those
        b.close()  # the subscriber goes: its publisher hears so and sends no more
        assert a.wait_for(lambda: not sends(), 10.0, poll_s=0.01)
    finally:
        for t in (a, b):
            t.close()


def test_garbage_is_counted_dropped_and_reported_once(router: RuntimeParams) -> None:
    """A client outside cmdragons puts plain protobuf bytes (no zenoh encoding naming their type):
    they are read as the type this node's stages read on the topic; garbage is dropped."""
    import zenoh

    from cmdragons.runtime.topics import Contract, Port

    err = io.StringIO()
    (b,) = _transports(router, 1, err=err)
    raw = zenoh.open(router.zenoh.config("client"))
    try:
        got: list[Any] = []
        b.subscribe("referee", lambda _t, m: got.append(m))
        b.expect([Contract("watcher", (Port("referee", msg.GameState),))])
        pub = raw.declare_publisher(f"cmdragons/{router.field_name}/referee")
        assert b.wait_for(lambda: bool(pub.matching_status.matching), 10.0)
        for _ in range(5):
            pub.put(b"\xff\x00garbage")
        pub.put(wire.encode(msg.GameState(1.0, "stop")))
        assert b.wait_for(lambda: len(got) == 1, 10.0)
        assert got == [msg.GameState(1.0, "stop")] and b.dropped == 5
        assert err.getvalue().count("dropped") == 1  # reported once within the interval
    finally:
        raw.close()
        b.close()


def test_every_ping_of_the_floor_measure_comes_back(router: RuntimeParams) -> None:
    from cmdragons.runtime.zenoh_transport import round_trips

    assert len(round_trips(router, 20, 300)) == 20  # (what they take is bench runtime's, not a test's)


def test_every_ping_of_the_floor_measure_from_the_routers_session_comes_back() -> None:
    import zenoh

    from cmdragons.runtime.zenoh_transport import round_trips

    params = loopback_params()
    with zenoh.open(params.zenoh.config("router")) as session:
        assert len(round_trips(params, 20, 300, session=session)) == 20
