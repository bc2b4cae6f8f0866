"""Stage contracts: what a match's stages publish is what they declare; a table that does not fit is
refused naming both ends; a distributed node builds only its own stages."""

from __future__ import annotations

import gc
import importlib.util
from pathlib import Path
from typing import Any

import pytest

from cmdragons import messages as msg
from cmdragons.messages import DetectionFrame, Tick, WorldState
from cmdragons.runtime.bus import Bus
from cmdragons.runtime.distributed import MatchSpec
from cmdragons.runtime.match import CLOCK, Match, build, built_in_wiring
from cmdragons.runtime.settings import load_settings
from cmdragons.runtime.stages import SummaryCollector, Tap
from cmdragons.runtime.topics import Contract, Port, WiringError, check_wiring, topic_matches
from sim.simulator import Simulator

SETTINGS = load_settings()
ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize(("opponent", "perception"), [("simple", "truth"), ("defend", "truth"), ("self", "vision")])
def test_every_topic_published_is_declared_and_every_declared_one_is_published(opponent: str,
                                                                                perception: str) -> None:
    seen: dict[str, set[type]] = {}
    tap = Tap("every", ("*",), lambda topic, m: seen.setdefault(topic, set()).add(type(m)))
    match = Match(SETTINGS, opponent, perception, seed=1, extra=[tap])  # type: ignore[arg-type]
    match.run(5.0 if perception == "truth" else 1.0)  # (its summary: every stage's summary/<name> too)
    declared = [p for s in match.bus.stages for p in s.contract.writes] + list(CLOCK)
    for topic, types in seen.items():
        ports = [p for p in declared if topic_matches(p.topic, topic)]
        assert ports, f"{topic} published but declared by no stage"
        assert types == {ports[0].type}, f"{topic}: published {types}, declared {ports[0].type}"
    for p in declared:
        assert p.sometimes or any(topic_matches(p.topic, t) for t in seen), f"{p.topic} declared but never published"


def test_two_built_in_teams_play_each_other_on_their_declared_topics() -> None:
    seen: dict[str, set[type]] = {}
    tap = Tap("every", ("*",), lambda topic, m: seen.setdefault(topic, set()).add(type(m)))
    summaries = SummaryCollector()
    sim = Simulator(SETTINGS.field, SETTINGS.camera_models(), SETTINGS.sim, seed=1, render=False, referee=False)
    stages = build(built_in_wiring(SETTINGS, "simple", "defend", lambda: sim), [tap, summaries])
    bus = Bus()
    for stage in stages:
        bus.add(stage)
    bus.start()
    frames = 120
    for i in range(frames):
        bus.tick(i)
    bus.summarize()
    declared = [p for s in stages for p in s.contract.writes] + list(CLOCK)
    for topic, types in seen.items():
        ports = [p for p in declared if topic_matches(p.topic, topic)]
        assert ports and types == {ports[0].type}, topic
    assert {"commands/blue", "commands/yellow", "truth", "events", "referee"} <= set(seen)
    assert summaries.figures["sim"]["seconds"] == pytest.approx(frames / SETTINGS.sim.physics.frame_rate_hz)


def test_a_topic_read_that_nobody_writes_is_refused_naming_the_reader_and_the_topic() -> None:
    writer = Contract("tracker/blue", (), (Port("world/blue", WorldState),))
    reader = Contract("team/yellow", (Port("world/yellow", WorldState),))
    with pytest.raises(WiringError, match=r"'team/yellow' reads topic 'world/yellow'.*no stage writes"):
        check_wiring([writer, reader])
    check_wiring([writer, Contract("team/blue", (Port("world/blue", WorldState),))])  # what fits passes


def test_a_topic_written_with_another_type_is_refused_naming_both_stages() -> None:
    writer = Contract("vision/0", (), (Port("detections/0", DetectionFrame),))
    reader = Contract("tracker/blue", (Port("detections/0", WorldState),))
    with pytest.raises(WiringError, match=r"'tracker/blue' reads topic 'detections/0' as WorldState, but stage "
                                          r"'vision/0' writes 'detections/0' as DetectionFrame"):
        check_wiring([writer, reader])
    with pytest.raises(WiringError, match=r"'detections/0'.*'vision/1'.*'vision/0'"):
        check_wiring([writer, Contract("vision/1", (), (Port("detections/0", Tick),))])


def test_the_match_table_is_checked_when_a_match_is_built() -> None:
    lost = Tap("viewer", ("world/blue",), lambda _t, _m: None)  # takes anything: fits
    Match(SETTINGS, "none", "truth", seed=1, extra=[lost])
    dangling = Tap("viewer", (), lambda _t, _m: None)
    dangling.contract = Contract("viewer", (Port("world/green", WorldState),))
    with pytest.raises(WiringError, match="'viewer' reads topic 'world/green'"):
        Match(SETTINGS, "none", "truth", seed=1, extra=[dangling])


def _simulators() -> int:
    # (by exact type: isinstance asks a dead weak proxy among the objects for its class, which raises)
    return sum(type(o) is Simulator for o in gc.get_objects())


@pytest.mark.parametrize("role", ["team", "opponent", "referee", "vision"])
def test_a_node_builds_only_its_own_stages_and_no_simulator_off_the_sim_node(role: str) -> None:
    spec = MatchSpec(SETTINGS, "simple", "truth", 1)
    nodes = spec.nodes()
    gc.collect()
    before = _simulators()
    stages = spec.stages(role)
    assert sorted(s.name for s in stages) == sorted(name for name, node in nodes.items() if node == role)
    assert _simulators() == before, f"the {role} node built a simulator"
    sim_node = spec.stages("sim")
    assert [s.name for s in sim_node] == ["sim"] and _simulators() == before + 1


def _docs_topics() -> Any:
    spec = importlib.util.spec_from_file_location("docs_topics", ROOT / "docs" / "topics.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_topic_reference_in_the_docs_is_the_one_the_contracts_give() -> None:
    docs = _docs_topics()
    assert docs.written() == docs.section(), "docs/architecture.md's topics are stale: python docs/topics.py --write"


def test_every_declared_topic_crosses_the_wire_by_its_declared_type() -> None:
    """A topic's bytes go with their protobuf type (:func:`~cmdragons.runtime.wire.schema`), read
    back as the type the contract declares: the wire keeps no topic list of its own."""
    from cmdragons.runtime import wire

    for c in _docs_topics().contracts():
        for p in c.writes:
            assert p.type in wire.CODECS, f"{c.name} writes {p.topic} as {p.type.__name__}, which has no wire form"
    # and each protobuf type reads back as one message type
    names = {cls: codec.proto.DESCRIPTOR.full_name for cls, codec in wire.CODECS.items()}
    assert len(set(names.values())) == len(names)


def test_the_sim_command_is_a_table_of_declared_stages_on_the_bus() -> None:
    from cmdragons.messages import GameState, GroundTruth, SimEvents, TeamCommands
    from cmdragons.runtime.bus import Bus, run_frames
    from cmdragons.runtime.match import build, scripted_wiring
    from cmdragons.runtime.stages import RecorderStage
    from sim.script import ScriptedPlay

    sim = Simulator(SETTINGS.field, SETTINGS.camera_models(), SETTINGS.sim, seed=3)
    script = ScriptedPlay(SETTINGS.field_geometry(), SETTINGS.field.robot.radius_m, SETTINGS.sim.script, sim.rng)
    seen: list[tuple[str, Any]] = []
    bus = Bus()
    stages = build(scripted_wiring(sim, script, None), [Tap("every", ("*",), lambda t, m: seen.append((t, m)))])
    for s in stages:
        bus.add(s)
    bus.start()
    assert run_frames(bus.tick, 20, should_stop=lambda: sim.world.frame_number >= 12) == 12  # stopped before frame 12
    declared = [p for s in stages for p in s.contract.writes] + list(CLOCK)
    for topic, m in seen:
        ports = [p for p in declared if topic_matches(p.topic, topic)]
        assert ports and type(m) is ports[0].type, topic
    # each frame in the order the log keeps: truth, the referee's word, each camera, both teams' commands
    # for that frame, the events of the step they were sent with
    frames = [t for t, _ in seen if t != "clock"]
    per_frame = ["truth", "referee", "camera/0/frame", "camera/1/frame", "commands/blue", "commands/yellow", "events"]
    assert frames == per_frame * 12
    truths = [m for t, m in seen if t == "truth"]
    assert all(isinstance(m, GroundTruth) for m in truths) and [m.frame_number for m in truths] == list(range(12))
    assert [m.frame_number for t, m in seen if isinstance(m, TeamCommands)] == [i for i in range(12) for _ in "by"]
    assert [m.frame_number for t, m in seen if isinstance(m, SimEvents)] == list(range(12))
    assert all(isinstance(m, GameState) for t, m in seen if t == "referee")
    recorder = next(s for s in stages if isinstance(s, RecorderStage))
    assert sorted(recorder.images) == [0, 1]  # the last frame's images, for the snapshot
    # the simulator judges its own game: a table that adds a second referee is refused
    with pytest.raises(WiringError, match="'referee'"):
        check_wiring([*(s.contract for s in stages), Contract("judge", (), (Port("referee", Tick),))])


@pytest.mark.slow
def test_the_team_node_starts_without_loading_the_simulator() -> None:
    """A fresh process that builds the team node's stages and rehearses them (what ``cmdragons node
    team`` does before it is ready) never loads the simulator's module."""
    import subprocess
    import sys

    code = ("import sys, dataclasses\n"
            "from cmdragons.runtime.distributed import MatchSpec, rehearse\n"
            "from cmdragons.runtime.settings import load_settings\n"
            f"s = load_settings({str(ROOT / 'configs')!r})\n"
            "s = dataclasses.replace(s, runtime=dataclasses.replace(s.runtime, rehearsal_frames=3))\n"
            "spec = MatchSpec(s, 'self', 'truth', 1)\n"
            "for role in ('team', 'opponent'):\n"
            "    spec.stages(role); rehearse(spec, role)\n"
            "print('sim.simulator' in sys.modules)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=ROOT)
    assert out.stdout.strip() == "False"


def test_the_vision_command_is_a_table_of_declared_stages_fed_by_its_sources(tmp_path: Path) -> None:
    """``cmdragons vision``'s stages come from a table: a vision stage per camera (drawing overlays
    on its own detections where asked), the detections written by one stage; the camera frames are
    the set-up's outside (the sources): without them the table is refused naming the reader."""
    import io

    import cv2
    import numpy as np

    from cmdragons.runtime.match import build
    from cmdragons.runtime.vision_command import OverlaidVisionStage, vision_wiring
    from vision.sources import open_sources

    models = SETTINGS.camera_models()
    for cam, m in enumerate(models):
        cv2.imwrite(str(tmp_path / f"cam{cam}.png"), np.zeros((m.height, m.width, 3), np.uint8))
    sources, _ = open_sources([str(tmp_path / f"cam{cam}.png") for cam in range(len(models))])
    table = vision_wiring(list(zip(sources, models, strict=True)), SETTINGS.vision, SETTINGS.field, tmp_path,
                          io.StringIO(), {}, video=False, overlay=True, fps=60.0)
    assert [e.contract.name for e in table] == [f"vision/{m.id}" for m in models] + ["vision_out"]
    with pytest.raises(WiringError, match=r"'vision/0' reads topic 'camera/0/frame'"):
        build(table)
    frames = [Port(f"camera/{m.id}/frame", msg.CameraFrame) for m in models]
    stages = build(table, outside=frames)
    assert all(isinstance(s, OverlaidVisionStage) for s in stages[:-1])  # still images: PNG overlays
