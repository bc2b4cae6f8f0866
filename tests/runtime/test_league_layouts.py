"""Our packets against the league's published layouts: each schema below is the league's field list
(names, numbers, types: facts of the wire format), written here as the independent reference, and
Debian's protoc (the league's own C++ parser) decodes our bytes with it or encodes bytes from it
for our readers."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from cmdragons.bench.league import PEERS, peer_script
from cmdragons.camera import CameraModel
from cmdragons.messages import Tick
from cmdragons.runtime.proto import ssl_tracked_pb2 as trk_pb
from cmdragons.runtime.proto import ssl_tracker_wrapper_pb2 as tw_pb
from cmdragons.runtime.proto import ssl_wrapper_pb2 as wrap_pb
from cmdragons.runtime.settings import load_settings
from cmdragons.runtime.ssl.clock import UnixEpoch
from cmdragons.runtime.ssl.commands import (
    UNSUPPORTED,
    Feedback,
    SimError,
    read_robot_control_response,
    read_simulator_response,
    robot_control_response,
    simulator_response,
)
from cmdragons.runtime.ssl.stages import VisionInStage
from cmdragons.runtime.ssl.tracker import read_tracker
from cmdragons.runtime.ssl.udp import DatagramQueue
from cmdragons.runtime.ssl.vision import PIXEL_ORIGIN, decode_wrapper, geometry_packet, read_wrapper

EPOCH = UnixEpoch(1_764_000_000)  # a Unix time of 2025, whole seconds
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
        "latin-1"), capture_output=True, check=True, text=True, encoding="latin-1")


def _encode(schema: Path, message: str, text: str) -> bytes:
    out = subprocess.run(["protoc", f"-I{schema.parent}", f"--encode={message}", schema.name], input=text.encode(),
                         capture_output=True, check=True)
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
                  'feedback { id: 7 dribbler_ball_contact: false } feedback { id: 2 }')
    answer = read_robot_control_response(now)
    assert answer.feedback == (Feedback(7, False), Feedback(2, None))
    assert answer.errors == (SimError("VELOCITY_TYPE", "global velocity"),) and not answer.earlier_layout
    earlier = _encode(_schema(tmp_path, "earlier.proto", SIMULATION_EARLIER), "RobotControlResponse",
                      'errors { code: "unsupported" message: "wheels" '
                      'unsupported_capability: SIMULATOR_CAPABILITY_MOVE_WHEEL_VELOCITY } '
                      'feedback { id { id: 5 team: BLUE } dribbler_ball_contact: true }')
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


def _ssl_vision_pixels(cal: Any, field_mm: np.ndarray, distortion: float | None = None) -> np.ndarray:
    """SSL-Vision's published camera model (field2image of its camera_calibration.cpp, the classic
    model) on an SSL_GeometryCameraCalibration as it is on the wire, field points in mm -> its
    pixels (counted from the centre of the top-left pixel): camera coordinates R(q) p + t, the
    normalised point, its radius distorted by solving r_u = r_d (1 + d r_d^2) in closed form (none
    for d <= 0), then f * p_d + the principal point."""
    pc = Rotation.from_quat([cal.q0, cal.q1, cal.q2, cal.q3]).apply(field_mm) + np.array([cal.tx, cal.ty, cal.tz])
    pu = pc[:, :2] / pc[:, 2:3]
    ru = np.hypot(pu[:, 0], pu[:, 1])
    a = cal.distortion if distortion is None else distortion
    if a <= np.finfo(float).tiny:
        rd = ru
    else:
        b = -9.0 * a * a * ru + a * np.sqrt(a * (12.0 + 81.0 * a * ru * ru))
        b = np.cbrt(b)
        rd = (2.0 / 3.0) ** (1.0 / 3.0) / b - b / (18.0 ** (1.0 / 3.0) * a)
    pd = pu * (rd / ru)[:, None]
    return cal.focal_length * pd + np.array([cal.principal_point_x, cal.principal_point_y])


def _image_points(cam: CameraModel) -> tuple[np.ndarray, np.ndarray]:
    """Field points (mm, on the ground) that fill ``cam``'s image, and our pixels of them."""
    u, v = np.meshgrid(np.linspace(1.0, cam.width - 1.0, 41), np.linspace(1.0, cam.height - 1.0, 31))
    xy = cam.unproject(np.stack([u.ravel(), v.ravel()], axis=-1), 0.0)
    pts = np.concatenate([xy, np.zeros((len(xy), 1))], axis=-1)
    return pts * 1000.0, cam.project(pts)


# our lens (k1, k2) -> the largest and the RMS distance (px) over the image between a point through
# SSL-Vision's model with the distortion we send and through ours: its one coefficient follows our
# default lens to a third of a pixel, a strong two-term lens only to about a pixel in the corners
LENSES = [((-0.02, 0.0), 0.4, 0.1), ((-0.08, 0.01), 1.1, 0.3), ((0.0, 0.0), 1e-3, 1e-3)]


@pytest.mark.parametrize("lens, max_px, rms_px", LENSES)
def test_our_calibrations_project_through_ssl_visions_model_as_through_ours(lens: tuple[float, float], max_px: float,
                                                                           rms_px: float) -> None:
    k1, k2 = lens
    settings = load_settings(None, [f"cameras.auto.k1={k1}", f"cameras.auto.k2={k2}"])
    cams = settings.camera_models()
    sent = wrap_pb.SSL_WrapperPacket.FromString(geometry_packet(settings.field_geometry(), cams)).geometry.calib
    for cal, cam in zip(sent, cams, strict=True):
        field_mm, ours = _image_points(cam)
        off = np.hypot(*(_ssl_vision_pixels(cal, field_mm) + PIXEL_ORIGIN - ours).T)
        assert off.max() < max_px and np.sqrt(np.mean(off**2)) < rms_px, (lens, off.max())
        if k1 < 0.0:  # our k1 as it went before (SSL-Vision reads a negative value as no distortion)
            before = _ssl_vision_pixels(cal, field_mm, distortion=k1) + PIXEL_ORIGIN
            assert np.hypot(*(before - ours).T).max() > 5.0


@pytest.mark.parametrize("distortion, max_px", [(0.0, 1e-3), (0.03, 0.1), (0.1, 0.7), (-0.05, 1e-3)])
def test_an_ssl_vision_calibration_reads_as_our_lens_model(distortion: float, max_px: float) -> None:
    """A calibration as SSL-Vision sends it (its own distortion and pixels) projects through our
    camera model of what we read from it where SSL-Vision's model puts the points (to ``max_px``
    over the image: two terms follow its model closely, not exactly, for a strong lens)."""
    base = load_settings().camera_models()[0]
    q = Rotation.from_matrix(base.R_cam_to_field.T).as_quat()
    t = -base.R_cam_to_field.T @ base.center * 1000.0
    wrapper = wrap_pb.SSL_WrapperPacket()
    wrapper.geometry.field.CopyFrom(wrap_pb.SSL_WrapperPacket.FromString(
        geometry_packet(load_settings().field_geometry(), [base])).geometry.field)
    cal = wrapper.geometry.calib.add(camera_id=3, focal_length=base.f, principal_point_x=511.5, principal_point_y=383.5,
                                     distortion=distortion, q0=q[0], q1=q[1], q2=q[2], q3=q[3], tx=t[0], ty=t[1],
                                     tz=t[2], pixel_image_width=base.width, pixel_image_height=base.height)
    _, geo = decode_wrapper(wrapper.SerializeToString())
    assert geo is not None
    read = geo.cameras[0]
    ours = CameraModel(read.camera_params())
    assert (ours.cx, ours.cy) == (512.0, 384.0)  # the image's centre in either way of counting
    field_mm, _ = _image_points(ours)
    off = np.hypot(*(_ssl_vision_pixels(cal, field_mm) + PIXEL_ORIGIN - ours.project(field_mm / 1000.0)).T)
    assert off.max() < max_px, (distortion, read.k1, read.k2, off.max())
    if distortion <= 0.0:
        assert (read.k1, read.k2) == (0.0, 0.0)


# Answers recorded on this machine to a RobotControl for blue robot 0 (local velocity; then a global
# velocity, which the ER-Force simulator does not take), in the league's current layout.
GRSIM_ANSWER = bytes.fromhex("120408001000")  # grSim fe2bd29: feedback { id: 0 dribbler_ball_contact: false }
ERFORCE_REFUSAL = bytes.fromhex(
    "0a620a0d56454c4f434954595f545950451251546865207265636569766564206d6573736167652068616420612076656c6f6369"
    "7479207479706520756e737570706f7274656420627920746869732073696d756c61746f722028526f626f74203a3029")


def test_answers_of_grsim_and_the_erforce_simulator_read_with_the_robots_id() -> None:
    answer = read_robot_control_response(GRSIM_ANSWER)
    assert answer.feedback == (Feedback(0, False),) and not answer.errors and not answer.earlier_layout
    refusal = read_robot_control_response(ERFORCE_REFUSAL)
    assert not refusal.feedback and [e.code for e in refusal.errors] == ["VELOCITY_TYPE"]
    assert "velocity type unsupported" in refusal.errors[0].message


# what a global velocity gets from each: refused by its error code, or taken
GLOBAL_ANSWER = {"erforce": [[], ["VELOCITY_TYPE"], False], "grsim": [[3], [], False]}
PROBE = """
import json, sys
from cmdragons.runtime.proto import ssl_simulation_control_pb2 as ctl_pb
from cmdragons.runtime.ssl.commands import read_robot_control_response
from cmdragons.runtime.ssl.udp import UdpEndpoint
ep, out = UdpEndpoint("127.0.0.1"), []
for kind in ("local_velocity", "global_velocity", "local_velocity"):
    m = ctl_pb.RobotControl()
    move = getattr(m.robot_commands.add(id=3).move_command, kind)
    for name in ("forward", "left", "angular") if kind == "local_velocity" else ("vel_x", "vel_y", "vel_angular"):
        setattr(move, name, 0.0)
    ids, codes, earlier = set(), set(), False
    for _ in range(3):  # every answer to three such packets (an error may come apart from the feedback)
        ep.send_to(m.SerializeToString(), ("127.0.0.1", 10301))
        got = ep.receive(2.0)
        while got is not None:
            a = read_robot_control_response(got[0])
            ids |= {f.id for f in a.feedback}
            codes |= {e.code for e in a.errors}
            earlier = earlier or a.earlier_layout
            got = ep.receive(0.2)
    out.append([sorted(ids), sorted(codes), earlier])
print(json.dumps(out))
"""


@pytest.mark.parametrize("name", sorted(GLOBAL_ANSWER))
def test_a_league_simulator_answers_our_commands_with_the_robots_id(name: str) -> None:
    """grSim and the league's reference simulator, run in a private network namespace when found:
    their answers read with the robot's id, a refused global velocity as the error's code."""
    script, why = peer_script(next(p for p in PEERS if p.name == name))
    if script is None:
        pytest.skip(why)
    global_answer = GLOBAL_ANSWER[name]
    out = subprocess.run([script, sys.executable, "-c", PROBE], capture_output=True, text=True,
                         timeout=180, check=True).stdout
    local, global_velocity, again = json.loads(out.strip().splitlines()[-1])
    assert local == [[3], [], False] and again == [[3], [], False]
    assert global_velocity[1:] == global_answer[1:]


def test_a_live_receiver_takes_a_senders_clock_from_its_first_packet() -> None:
    """grSim stamps its frames with its simulation time, SSL-Vision with Unix time: the receiver
    from outside takes the first packet's epoch, so both read as match time near 0 (grSim's clock
    counts from its own start, long before a match may begin)."""
    for first_t, want in ((47.6, 0.6), (EPOCH.to_unix(0.25), 0.25)):
        queue = DatagramQueue()
        stage = VisionInStage(load_settings().protocols, [0], lockstep=False, receiver=queue)
        w = wrap_pb.SSL_WrapperPacket()
        w.detection.frame_number, w.detection.t_capture, w.detection.t_sent, w.detection.camera_id = 1, first_t, \
            first_t, 0
        queue.push(w.SerializeToString())
        got: list[Any] = []
        stage.on_message("clock", Tick(0), lambda _t, d, got=got: got.append(d))
        assert got[0].t_capture == pytest.approx(want, abs=1e-6)


def test_a_tracker_packet_with_a_robot_of_no_team_keeps_the_rest() -> None:
    """The league's RobotId may say team UNKNOWN (0): that robot is left out and counted, the
    packet's other robots and ball read as sent (it was refused whole)."""
    m = tw_pb.TrackerWrapperPacket(uuid="u", source_name="autoref")
    f = m.tracked_frame
    f.frame_number, f.timestamp = 9, EPOCH.to_unix(2.5)
    for rid, team in ((1, trk_pb.BLUE), (4, trk_pb.UNKNOWN), (2, trk_pb.YELLOW)):
        f.robots.add(robot_id=trk_pb.RobotId(id=rid, team=team), pos=trk_pb.Vector2(x=rid, y=0.5), orientation=0.25)
    f.balls.add(pos=trk_pb.Vector3(x=1.0, y=-1.0, z=0.0))
    got = read_tracker(m.SerializeToString(), EPOCH)
    assert got.unknown_team == 1 and got.world is not None and got.world.t == 2.5
    assert [(r.team, r.id, r.x) for r in got.world.robots] == [("blue", 1, 1.0), ("yellow", 2, 2.0)]
    assert got.world.ball is not None and (got.world.ball.x, got.world.ball.y) == (1.0, -1.0)


def test_detections_without_id_or_orientation_are_left_out_and_counted(udp_port: int) -> None:
    """SSL-Vision's robot_id and orientation are optional: a robot without either is not read as id
    0 or heading 0; it is left out, counted by reason in the receiving stage's summary."""
    w = wrap_pb.SSL_WrapperPacket()
    d = w.detection
    d.frame_number, d.t_capture, d.t_sent, d.camera_id = 5, EPOCH.to_unix(1.0), EPOCH.to_unix(1.004), 6
    d.robots_blue.add(confidence=0.9, robot_id=3, x=100.0, y=200.0, orientation=1.5, pixel_x=1.0, pixel_y=2.0)
    d.robots_blue.add(confidence=0.9, x=300.0, y=200.0, orientation=0.5, pixel_x=1.0, pixel_y=2.0)  # no id
    d.robots_yellow.add(confidence=0.9, robot_id=0, x=-100.0, y=0.0, pixel_x=1.0, pixel_y=2.0)  # no orientation
    d.robots_yellow.add(confidence=0.8, robot_id=7, x=-500.0, y=0.0, orientation=-1.0, pixel_x=1.0, pixel_y=2.0)
    got = read_wrapper(w.SerializeToString(), EPOCH)
    assert got.robots_left_out == {"no id": 1, "no orientation": 1} and got.detection is not None
    assert [(r.team, r.id, r.theta) for r in got.detection.robots] == [("blue", 3, 1.5), ("yellow", 7, -1.0)]
    queue = DatagramQueue()
    stage = VisionInStage(load_settings().protocols, [], lockstep=False, receiver=queue, epoch=EPOCH)
    queue.push(w.SerializeToString())
    published: list[tuple[str, Any]] = []
    stage.on_message("clock", Tick(0), lambda topic, m: published.append((topic, m)))
    figures: list[Any] = []
    stage.summarize(lambda _t, s: figures.append(s.figures))
    assert [t for t, _ in published] == ["ssl/vision/6"]  # camera 6: not in any config of ours, taken
    assert figures[0]["robots_left_out"] == {"no id": 1, "no orientation": 1}


def test_a_calibration_read_back_is_our_camera_model() -> None:
    """A geometry packet's calibration as our camera model (the pose from SSL-Vision's quaternion
    and translation): the same pixels as the camera it was sent for, to 0.5 px over the image."""
    settings = load_settings()
    cams = settings.camera_models()
    _, geo = decode_wrapper(geometry_packet(settings.field_geometry(), cams))
    assert geo is not None
    for cal, cam in zip(geo.cameras, cams, strict=True):
        back = CameraModel(cal.camera_params())
        field_mm, ours = _image_points(cam)
        assert np.hypot(*(back.project(field_mm / 1000.0) - ours).T).max() < 0.5
        assert back.center == pytest.approx(cam.center, abs=1e-3)
