"""The wire format: every message round-trips through protobuf; the league-shaped ones decode as the
league's messages with an independent decoder; the generated modules are current; garbage is an error."""

from __future__ import annotations

import filecmp
import json
import math
import shutil
import subprocess
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from cmdragons import messages as msg
from cmdragons.runtime import wire
from cmdragons.runtime.proto.generate import PROTO_DIR, ROOT, generate, schemas

DET = msg.DetectionFrame(
    1, 42, 0.7, 0.702,
    (msg.BallDetection(0.5, -0.25, 0.9, (100.5, 200.25)), msg.BallDetection(-1.0, 2.0, 0.4, (5.0, 6.0), 0.004)),
    (msg.RobotDetection("blue", 3, 1.0, 2.0, 0.5, 0.99, (10.0, 20.0)),
     msg.RobotDetection("yellow", 15, -1.0, -2.0, -3.0, 0.5, (30.0, 40.0))),
)
WORLD = msg.WorldState(1.5, msg.BallState(0.1, 0.2, 1.0, -1.0, True),
                       (msg.RobotState("blue", 0, 1.0, 1.0, 0.1, 0.5, 0.25, 1.0, True),
                        msg.RobotState("yellow", 7, -1.0, 0.0, 3.0, visible=False)), 17)
COMMANDS = msg.TeamCommands("yellow", 17, 1.5, (msg.RobotCommand("yellow", 4, 1.0, -0.5, 2.0, 3.5, True, 0.5),
                                                msg.RobotCommand("yellow", 0)))
# messages whose wire form is exact (64-bit floats): they come back equal
EXACT: list[Any] = [
    msg.GroundTruth(9, 0.15, msg.BallTruth(0.0, 0.1, 0.0215, 1.0, 0.0, 0.0, {0: (10.0, 20.0, 0.75)}),
                    (msg.RobotTruth("blue", 1, 1.0, 2.0, 0.3, 0.1, 0.2, 0.3, {0: (5.0, 6.0), 1: (7.0, 8.0)}),)),
    msg.GameState(3.0, "free_kick", "yellow", 2, 1, False, (1.0, -2.8)),
    msg.GameState(0.0),
    # every field of the league's Referee message that the rules use
    msg.GameState(41.5, "ball_placement", "blue", 1, 0, True, (-2.0, 1.5), ready=False, stage="second_half",
                  stage_time_left_s=187.25, command_counter=17, command_t=40.0, action_time_left_s=28.5,
                  next_command="free_kick", next_for_team="blue",
                  blue_team=msg.TeamInfo(fouls=2, goalkeeper=1, placement_failures=1, max_robots=6),
                  yellow_team=msg.TeamInfo(red_cards=1, yellow_cards=2, yellow_card_times_s=(75.5, 3.25), fouls=6,
                                           timeouts=3, timeout_time_s=120.0, can_place_ball=False, max_robots=3)),
    msg.GameEvents(12.0, (msg.GameEvent(11.98, "crash", "yellow", 4, 1.61, 1.5, "m/s", "free_kick", "blue"),
                          msg.GameEvent(12.0, "placement_succeeded", "blue", None, 7.5, 30.0, "s"))),
    msg.SimEvents(5, 0.1, (0.25, -0.5), (msg.Goal(0.1, "blue", 4.5, 0.1), msg.BallOut(0.1, 1.0, 3.0, None),
                                         msg.BallOut(0.1, 1.0, 3.0, "yellow"), msg.Kick(0.1, "blue", 2, 4.5, True),
                                         msg.Contact(0.05, 0.1, ("blue", 1), ("yellow", 3), 0.004, 0.7),
                                         msg.Contact(0.05, 0.1, ("blue", 1), ("blue", 2), 0.001, 0.4, ("yellow", 5)))),
    msg.Teleport(1.0, (("blue", 0, -4.0, 0.0, 0.0), ("yellow", 2, 1.0, 1.0, 3.1)), (0.0, 0.0)),
    msg.Teleport(1.0),
    msg.Tick(12),
    msg.Timing("team/blue", 3, {"plan": 1.5, "safety": 0.25}),
    msg.StageSummary("referee", {"score": {"blue": 1, "yellow": 0}, "kicks": 3, "ratio": 0.5}),
    msg.NodeControl("team", "ready"),
    msg.PhysicsFacts(12.5, (msg.FactEstimate(msg.Fact.BALL_ROLL, 0.7, 0.26, 45, 0.02, True, True),
                            msg.FactEstimate(msg.Fact.BALL_SLIDE, math.nan, 3.0, 0, math.nan, False, False))),
    msg.CameraFrame(0, 3, 0.05, np.arange(4 * 5 * 3, dtype=np.uint8).reshape(4, 5, 3)),
]  # fmt: skip
REPORT = msg.TeamReport(
    "blue", 4, 0.07,
    (msg.RobotReport(0, "solved", (1.0, 2.0, 0.5), np.array([[0.0, 0.0], [1.0, 2.0]]),
                     msg.RobotCommand("blue", 0, 0.5, 0.25, 1.0), np.array([[0.0, 0.0], [0.1, 0.05]])),
     msg.RobotReport(1, "halt", (0.0, 0.0, 0.0))),
    {0: msg.KickPurpose.PASS, 1: msg.KickPurpose.WAIT}, np.array([[1.0, 1.0], [2.0, -1.0]]), np.array([0.25, 0.75]),
    msg.PassReport(0, 1, (2.0, -1.0), (4.5, 0.25), kicked=True),
)
REPORT_TRAP = msg.TeamReport("blue", 5, 0.08, passing=msg.PassReport(1, 0, (1.0, 1.0)))  # no one-touch aim


def _close(a: Any, b: Any, rel: float) -> None:
    """Equal dict forms, floats to ``rel`` (32-bit floats on the wire: rel 1e-6)."""
    if isinstance(a, dict):
        assert isinstance(b, dict) and a.keys() == b.keys()
        for k in a:
            _close(a[k], b[k], rel)
    elif isinstance(a, list):
        assert isinstance(b, list) and len(a) == len(b)
        for x, y in zip(a, b, strict=True):
            _close(x, y, rel)
    elif isinstance(a, float) and not isinstance(b, bool):
        assert b == pytest.approx(a, rel=rel, abs=1e-9)
    else:
        assert a == b


def _back(m: Any) -> Any:
    return wire.decode(wire.schema(m), wire.encode(m))


@pytest.mark.parametrize("m", EXACT, ids=lambda m: type(m).__name__)
def test_exact_messages_round_trip_equal(m: Any) -> None:
    assert _back(m) == m


@pytest.mark.parametrize("m", [DET, WORLD, COMMANDS, REPORT, REPORT_TRAP], ids=lambda m: type(m).__name__)
def test_float32_messages_round_trip_to_a_millionth_and_are_stable(m: Any) -> None:
    back = _back(m)
    _close(m.to_dict(), back.to_dict(), rel=1e-6)
    # what came off the wire goes through it unchanged: in-process and remote stages see the same
    assert wire.encode(back) == wire.encode(m)
    assert _back(back).to_dict() == back.to_dict() == wire.canonical(m).to_dict()


def test_every_message_of_the_key_space_is_covered() -> None:
    tested = {type(m) for m in [*EXACT, DET, WORLD, COMMANDS, REPORT]}
    assert tested == set(wire.CODECS)
    assert len({wire.schema(m) for m in [*EXACT, DET, WORLD, COMMANDS, REPORT]}) == len(tested)  # one type each


def test_detection_frame_is_the_leagues_in_millimetres() -> None:
    p = wire.to_proto(DET)
    assert type(p).DESCRIPTOR.name == "SSL_DetectionFrame"
    assert [b.x for b in p.balls] == [500.0, -1000.0] and p.balls[1].position_sigma_mm == pytest.approx(4.0)
    assert [r.robot_id for r in p.robots_blue] == [3] and [r.robot_id for r in p.robots_yellow] == [15]
    assert not p.balls[0].HasField("position_sigma_mm") and math.isnan(_back(DET).balls[0].sigma_m)


def test_commands_are_robot_control_with_field_frame_velocities() -> None:
    p = wire.to_proto(COMMANDS)
    assert type(p).DESCRIPTOR.name == "RobotControl"
    c = p.robot_commands[0]
    assert c.move_command.WhichOneof("command") == "global_velocity"
    assert (c.move_command.global_velocity.vel_x, c.kick_speed, c.chip) == (1.0, 3.5, True)
    # a plain RobotControl (no cmdragons fields) from outside names no team: refused, not guessed
    with pytest.raises(msg.MessageError):
        wire.from_proto(type(p)(robot_commands=[c]))


@pytest.mark.parametrize("m", [DET, WORLD, COMMANDS, *EXACT], ids=lambda m: type(m).__name__)
@pytest.mark.parametrize("garbage", [b"\xff\xff\xff", b"\x08", b"not a protobuf message at all"])
def test_garbage_raises_message_error(m: Any, garbage: bytes) -> None:
    try:
        back = wire.decode(wire.schema(m), garbage)
    except msg.MessageError:
        return
    # bytes a protobuf parser takes as a message with every field unset (b"\x08" is a field without its
    # value, which some types skip) may only give a message of the type asked for, never another
    assert type(back) is type(m)


def test_a_type_that_is_not_ours_is_an_error() -> None:
    with pytest.raises(msg.MessageError, match="not one of our messages"):
        wire.decode("SSL_WrapperPacket", b"")
    assert not wire.is_known("SSL_WrapperPacket") and wire.is_known(wire.schema(DET))


NO_PROTOC = "Debian's protoc (apt-get install protobuf-compiler) is the independent decoder"


def _protoc_decode(name: str, schema: str, data: bytes) -> str:
    """protoc's text form of ``data`` as message ``name`` of ``schema`` (a file of the proto folder)."""
    args = ["protoc", f"-I{ROOT}", f"--decode={name}", str((PROTO_DIR / schema).relative_to(ROOT))]
    return subprocess.run(args, input=data, capture_output=True, check=True, cwd=ROOT).stdout.decode()


@pytest.mark.skipif(shutil.which("protoc") is None, reason=NO_PROTOC)
def test_detection_bytes_decode_with_protoc_as_ssl_detection_frame() -> None:
    out = _protoc_decode("cmdragons.league.SSL_DetectionFrame", "ssl_detection.proto", wire.encode(DET))
    assert "frame_number: 42" in out and "camera_id: 1" in out and "t_capture: 0.7" in out
    assert "x: 500" in out and "x: -1000" in out and "robot_id: 15" in out
    assert out.index("robots_yellow") < out.index("robot_id: 15") and "robots_blue" in out


@pytest.mark.skipif(shutil.which("protoc") is None, reason=NO_PROTOC)
def test_command_bytes_decode_with_protoc_as_robot_control() -> None:
    out = _protoc_decode("cmdragons.league.RobotControl", "ssl_simulation_control.proto", wire.encode(COMMANDS))
    assert "global_velocity" in out and "kick_speed: 3.5" in out and "team: YELLOW" in out


def test_generated_modules_are_current(tmp_path: Path) -> None:
    pytest.importorskip("grpc_tools", reason="grpcio-tools (the test extra) bundles the protoc that generates them")
    generate(tmp_path)
    made = tmp_path / PROTO_DIR.relative_to(ROOT)
    names = sorted(p.name for p in made.iterdir())
    assert names == sorted(f"{p.stem}_pb2{ext}" for p in schemas() for ext in (".py", ".pyi"))
    stale = [n for n in names if not filecmp.cmp(made / n, PROTO_DIR / n, shallow=False)]
    assert not stale, f"regenerate with: python -m cmdragons.runtime.proto.generate ({stale})"


def test_summary_figures_survive_as_json() -> None:
    s = msg.StageSummary("stats/blue", {"passes": {"tried": 2, "completed": 1}, "none": None})
    assert json.loads(wire.to_proto(s).figures_json) == s.figures


@pytest.mark.parametrize("shape", [(768, 1024, 3), (120, 160, 3), (1, 1, 3)])
def test_a_camera_frame_in_pieces_joins_to_its_protobuf_bytes(shape: tuple[int, int, int]) -> None:
    image = np.random.default_rng(1).integers(0, 256, shape, dtype=np.uint8)
    frame = msg.CameraFrame(3, 70_000, 12.5, image[:, ::-1])  # a view that is not contiguous
    chunks = wire.encode_chunks(frame)
    assert len(chunks) == 2 and b"".join(chunks) == wire.encode(frame)
    back = wire.decode(wire.schema(frame), b"".join(chunks))
    assert np.array_equal(back.image, image[:, ::-1]) and back.frame_number == 70_000


def test_other_messages_are_one_piece() -> None:
    tick = msg.Tick(5)
    assert wire.encode_chunks(tick) == (wire.encode(tick),)


@pytest.mark.parametrize("m", [*EXACT, DET, WORLD, COMMANDS, REPORT], ids=lambda m: type(m).__name__)
def test_canonical_and_chunks_at_once_are_each_alone(m: Any) -> None:
    local, chunks = wire.canonical_and_chunks(m)
    assert chunks == wire.encode_chunks(m)
    assert type(local) is type(m) and wire.encode(local) == wire.encode(wire.canonical(m))
    assert (local is m) == (type(m) not in wire.LOSSY)
