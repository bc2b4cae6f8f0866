"""The bus: lock-step delivery order, stages that only talk through topics, and the match on it."""

from __future__ import annotations

import hashlib
import pickle
from pathlib import Path
from typing import Any

import pytest
from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory

from cmdragons import messages as msg
from cmdragons.runtime import wire
from cmdragons.runtime.bus import BaseStage, Bus, InProcessTransport, Publish, run_frames
from cmdragons.runtime.log import RunLog, read_log
from cmdragons.runtime.match import Match
from cmdragons.runtime.settings import load_settings
from cmdragons.runtime.stages import LoggerStage, Tap, TrackerStage
from cmdragons.runtime.topics import ANY, Contract, Port, topic_matches
from cmdragons.tracking import Tracker

CONFIGS = Path(__file__).resolve().parents[2] / "configs"
SETTINGS = load_settings(CONFIGS)


@pytest.mark.parametrize(
    ("pattern", "topic", "match"),
    [("world/blue", "world/blue", True), ("world/blue", "world/yellow", False), ("detections/*", "detections/1", True),
     ("detections/*", "detections", False), ("camera/*", "camera/0/frame", True), ("*", "anything/at/all", True)],
)
def test_topic_patterns(pattern: str, topic: str, match: bool) -> None:
    assert topic_matches(pattern, topic) is match


class Relay(BaseStage):
    """Publishes ``out`` + the message for each input: the order of deliveries becomes visible."""

    def __init__(self, name: str, inputs: tuple[str, ...], out: str, seen: list[str]) -> None:
        self.contract = Contract(name, tuple(Port(t, ANY) for t in inputs), (Port(out, ANY),) if out else ())
        self.out, self.seen = out, seen

    def on_message(self, topic: str, message: Any, publish: Publish) -> None:
        self.seen.append(f"{self.name}<{topic}:{message}")
        if self.out:
            publish(self.out, f"{message}>{self.name}")


def test_in_process_delivery_is_first_published_first_delivered_in_subscription_order() -> None:
    seen: list[str] = []
    bus = Bus(InProcessTransport())
    bus.add(Relay("a", ("in",), "mid", seen))
    bus.add(Relay("b", ("in", "mid"), "", seen))
    bus.add(Relay("c", ("mid",), "", seen))
    bus.publish("in", 1)
    bus.publish("in", 2)
    assert bus.spin() == 8
    # both inputs are delivered (to a, then b) before what a published in answer to them
    assert seen == ["a<in:1", "b<in:1", "a<in:2", "b<in:2", "b<mid:1>a", "c<mid:1>a", "b<mid:2>a", "c<mid:2>a"]
    assert set(bus.take_times()) >= {"a", "b", "c", "a:in", "b:mid"}


def test_two_stages_of_one_name_are_refused() -> None:
    bus = Bus()
    bus.add(Relay("a", ("x",), "", []))
    with pytest.raises(ValueError, match="two stages named 'a'"):
        bus.add(Relay("a", ("y",), "", []))


def test_settings_and_every_message_pickle() -> None:
    assert pickle.loads(pickle.dumps(SETTINGS)) == SETTINGS
    m = Match(SETTINGS, "simple", "truth", seed=5, render=True)
    seen: list[Any] = []
    m.bus.add(Tap("everything", ("*",), lambda _t, message: seen.append(message)))
    for _ in range(3):
        m.step()
    m.summary()
    kinds = {type(x) for x in seen}
    assert {msg.CameraFrame, msg.GroundTruth, msg.DetectionFrame, msg.WorldState, msg.TeamCommands, msg.TeamReport,
            msg.SimEvents, msg.GameState, msg.StageSummary, msg.Tick} <= kinds
    for x in seen:
        data = pickle.dumps(x)
        back = pickle.loads(data)
        assert type(back) is type(x) and pickle.dumps(back) == data  # (== fails on NaN fields)


# small images keep a log that holds them small (160x120, two cameras)
SMALL = load_settings(CONFIGS, ["cameras.auto.resolution_px=[160,120]", "cameras.auto.grid=[2,1]"])


def _play(tmp: Path, seconds: float, seed: int, images: bool = False) -> Path:
    path = tmp / f"run-{seed}-{images}.mcap"
    log = RunLog(path)
    m = Match(SMALL if images else SETTINGS, "simple", "vision", seed=seed, extra=[LoggerStage(log, images=images)])
    m.run(seconds)
    log.close()
    return path


@pytest.mark.slow
def test_same_seed_gives_a_byte_identical_log(tmp_path: Path) -> None:
    a = tmp_path / "a"
    b = tmp_path / "b"
    a.mkdir(), b.mkdir()
    digest = [hashlib.sha256(_play(d, 1.0, seed=3).read_bytes()).hexdigest() for d in (a, b)]
    assert digest[0] == digest[1]


@pytest.mark.slow
def test_the_log_holds_every_topic_each_readable_as_its_message(tmp_path: Path) -> None:
    path = _play(tmp_path, 5.0, seed=2, images=True)
    types = {"truth": msg.GroundTruth, "referee": msg.GameState, "events": msg.SimEvents, "teleport": msg.Teleport,
             "world": msg.WorldState, "commands": msg.TeamCommands, "report": msg.TeamReport,
             "detections": msg.DetectionFrame, "camera": msg.CameraFrame, "summary": msg.StageSummary}
    counts: dict[str, int] = {}
    with path.open("rb") as f:  # every channel has its protobuf schema: decoded from the file alone
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        for schema, channel, _message, proto in reader.iter_decoded_messages():
            assert schema is not None and schema.encoding == "protobuf" and proto.DESCRIPTOR.full_name == schema.name
            counts[channel.topic] = counts.get(channel.topic, 0) + 1
    for topic, _t, message in read_log(path):  # and as our messages
        assert isinstance(message, types[topic.strip("/").split("/")[0]]), topic
    frames = 5 * 60
    cams = [m.id for m in SMALL.camera_models()]
    for topic in ["/truth", "/events", "/world/blue", "/commands/blue", "/commands/yellow", "/report/blue",
                  *(f"/detections/{c}" for c in cams), *(f"/camera/{c}/frame" for c in cams)]:
        assert counts.get(topic) == frames, topic
    assert counts["/referee"] == frames + 1  # the referee's first word comes before the first frame
    assert counts["/teleport"] >= 1  # the kickoff formation
    assert {"/summary/sim", "/summary/referee", "/summary/tracker/blue", "/summary/stats/blue"} <= set(counts)


@pytest.mark.slow
@pytest.mark.parametrize("synchronized", [False, True])
def test_the_tracker_stage_on_a_recorded_detection_topic_equals_the_direct_call(synchronized: bool) -> None:
    m = Match(SETTINGS, "simple", "vision", seed=4)
    recorded: list[tuple[str, Any]] = []
    m.bus.add(Tap("recorder", ("detections/*", "commands/blue", "world/blue"), lambda t, x: recorded.append((t, x))))
    for _ in range(90):
        m.step()
    cams = [f"detections/{c.id}" for c in m.cameras]
    # the stage, fed the recorded topics on a bus of its own
    bus = Bus()
    worlds: list[msg.WorldState] = []
    stage = TrackerStage("blue", Tracker(SETTINGS.tracker), cams, synchronized=synchronized)
    bus.add(stage)
    bus.add(Tap("out", ("world/blue",), lambda _t, w: worlds.append(w)))
    for topic, x in recorded:
        if topic != "world/blue":
            before = stage.tracker.stats.detections
            bus.publish(topic, x)
            bus.spin()
            if topic == cams[0] and x.robots:  # synchronized: the first camera is taken before the second comes
                assert (stage.tracker.stats.detections > before) == synchronized
    # the direct calls on the same detections and commands
    direct = Tracker(SETTINGS.tracker)
    expected: list[msg.WorldState] = []
    pending: list[msg.DetectionFrame] = []
    t_capture = 0.0
    for _topic, x in recorded:
        if isinstance(x, msg.DetectionFrame):
            pending.append(x)
            if len(pending) == len(cams):
                w = direct.step(pending)
                t_capture = pending[0].t_capture
                # the bus delivers a world state as it comes off the wire (32-bit floats)
                expected.append(wire.canonical(msg.WorldState(w.t, w.ball, w.robots, x.frame_number)))
                pending = []
        elif isinstance(x, msg.TeamCommands):
            direct.command_sent(x.commands, t_capture)
    live = [x for t, x in recorded if t == "world/blue"]
    assert len(worlds) == len(expected) == len(live) == 90
    assert worlds == expected == live


def test_the_frame_loop_stops_before_the_frame_after_its_stop_was_asked() -> None:
    stepped: list[int] = []
    shown: list[int] = []
    assert run_frames(stepped.append, 10, on_frame=shown.append) == 10
    assert stepped == shown == list(range(10))
    stepped.clear()
    # a condition a step sets (a game over) ends the loop before the next frame: that step is the last
    assert run_frames(stepped.append, 10, should_stop=lambda: 4 in stepped) == 5
    assert stepped == [0, 1, 2, 3, 4]
    assert run_frames(stepped.append, 10, should_stop=lambda: True) == 0
