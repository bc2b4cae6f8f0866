"""Our packets against the league's published layouts: each schema below is the league's field list
(names, numbers, types: facts of the wire format), written here as the independent reference, and
Debian's protoc (the league's own C++ parser) decodes our bytes with it or encodes bytes from it
for our readers."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest

from cmdragons.runtime.ssl.commands import (
    UNSUPPORTED,
    Feedback,
    SimError,
    read_robot_control_response,
    read_simulator_response,
    robot_control_response,
    simulator_response,
)

NO_PROTOC = "Debian's protoc (apt-get install protobuf-compiler) is the independent parser"
needs_protoc = pytest.mark.skipif(shutil.which("protoc") is None, reason=NO_PROTOC)

# The simulation protocol's answers as the league defines them now (ssl_simulation_error.proto,
# ssl_simulation_robot_feedback.proto; the feedback's Any in field 3 left out: parsers skip it).
SIMULATION_NOW = """syntax = "proto2";
message SimulatorError { optional string code = 1; optional string message = 2; }
message RobotFeedback { required uint32 id = 1; optional bool dribbler_ball_contact = 2; }
message RobotControlResponse { repeated SimulatorError errors = 1; repeated RobotFeedback feedback = 2; }
message SimulatorResponse { repeated SimulatorError errors = 1; }
"""

# ... and as it was before 2021-01-27 (a RobotId for the feedback, a capability in the error).
SIMULATION_EARLIER = """syntax = "proto2";
enum Team { UNKNOWN = 0; YELLOW = 1; BLUE = 2; }
message RobotId { optional uint32 id = 1; optional Team team = 2; }
enum SimulatorCapability { SIMULATOR_CAPABILITY_UNKNOWN = 1; SIMULATOR_CAPABILITY_MOVE_WHEEL_VELOCITY = 2;
  SIMULATOR_CAPABILITY_MOVE_LOCAL_VELOCITY = 3; SIMULATOR_CAPABILITY_MOVE_GLOBAL_VELOCITY = 4; }
message SimulatorError { optional string code = 1; optional SimulatorCapability unsupported_capability = 2;
  optional string message = 3; }
message RobotFeedback { required RobotId id = 1; optional bool dribbler_ball_contact = 2; }
message RobotControlResponse { repeated SimulatorError errors = 1; repeated RobotFeedback feedback = 2; }
"""


def _schema(tmp: Path, name: str, text: str) -> Path:
    path = tmp / name
    path.write_text(text)
    return path


def _decode(schema: Path, message: str, data: bytes) -> subprocess.CompletedProcess[str]:
    return subprocess.run(["protoc", f"-I{schema.parent}", f"--decode={message}", schema.name], input=data.decode(
        "latin-1"), capture_output=True, check=True, text=True, encoding="latin-1")  # fmt: skip


def _encode(schema: Path, message: str, text: str) -> bytes:
    out = subprocess.run(["protoc", f"-I{schema.parent}", f"--encode={message}", schema.name], input=text.encode(),
                         capture_output=True, check=True)  # fmt: skip
    return out.stdout


@needs_protoc
def test_our_robot_control_response_is_the_leagues_current_layout(tmp_path: Path) -> None:
    schema = _schema(tmp_path, "now.proto", SIMULATION_NOW)
    data = robot_control_response([Feedback(3, True), Feedback(11)], [SimError(UNSUPPORTED, "robot 4: wheels")])
    out = _decode(schema, "RobotControlResponse", data)
    assert "missing required fields" not in out.stderr, out.stderr  # what the C++ parser refused before
    assert out.stdout.split() == ("errors { code: \"UNSUPPORTED\" message: \"robot 4: wheels\" } "
                                  "feedback { id: 3 dribbler_ball_contact: true } feedback { id: 11 }").split()
    out = _decode(schema, "SimulatorResponse", simulator_response([SimError(UNSUPPORTED, "config: no")]))
    assert out.stdout.split() == "errors { code: \"UNSUPPORTED\" message: \"config: no\" }".split()


@needs_protoc
def test_answers_in_the_current_and_the_earlier_layout_are_both_read(tmp_path: Path) -> None:
    now = _encode(_schema(tmp_path, "now.proto", SIMULATION_NOW), "RobotControlResponse",
                  'errors { code: "VELOCITY_TYPE" message: "global velocity" } '
                  'feedback { id: 7 dribbler_ball_contact: false } feedback { id: 2 }')  # fmt: skip
    answer = read_robot_control_response(now)
    assert answer.feedback == (Feedback(7, False), Feedback(2, None))
    assert answer.errors == (SimError("VELOCITY_TYPE", "global velocity"),) and not answer.earlier_layout
    earlier = _encode(_schema(tmp_path, "earlier.proto", SIMULATION_EARLIER), "RobotControlResponse",
                      'errors { code: "unsupported" message: "wheels" '
                      'unsupported_capability: SIMULATOR_CAPABILITY_MOVE_WHEEL_VELOCITY } '
                      'feedback { id { id: 5 team: BLUE } dribbler_ball_contact: true }')  # fmt: skip
    answer = read_robot_control_response(earlier)
    assert answer.feedback == (Feedback(5, True),) and answer.earlier_layout and answer.unnamed == 0
    assert answer.errors == (SimError("unsupported", "wheels (SIMULATOR_CAPABILITY_MOVE_WHEEL_VELOCITY)"),)
    assert read_simulator_response(now) == (SimError("VELOCITY_TYPE", "global velocity"),)


def test_our_answer_reads_back_and_a_feedback_naming_no_robot_is_counted() -> None:
    data = robot_control_response([Feedback(0), Feedback(15, False)], [SimError("C", "text")])
    assert read_robot_control_response(data).feedback == (Feedback(0), Feedback(15, False))
    nameless = data + bytes([0x12, 0x02, 0x10, 0x01])  # one more feedback: only dribbler_ball_contact = true
    answer = read_robot_control_response(nameless)
    assert answer.unnamed == 1 and len(answer.feedback) == 2 and answer.errors == (SimError("C", "text"),)
