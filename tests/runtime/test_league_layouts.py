"""Our packets against the league's published layouts: each schema below is the league's field list
(names, numbers, types: facts of the wire format), written here as the independent reference, and
Debian's protoc (the league's own C++ parser) decodes our bytes with it or encodes bytes from it
for our readers."""

from __future__ import annotations

import dataclasses
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from cmdragons.camera import CameraModel
from cmdragons.runtime.proto.ssl_wrapper_pb2 import SSL_WrapperPacket
from cmdragons.runtime.settings import load_settings

from cmdragons.runtime.ssl.commands import (
    UNSUPPORTED,
    Feedback,
    SimError,
    read_robot_control_response,
    read_simulator_response,
    robot_control_response,
    simulator_response,
)
from cmdragons.runtime.ssl.vision import CameraCalibration, decode_wrapper, geometry_packet

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


def _ssl_vision_pixels(cal: CameraCalibration, field_mm: np.ndarray) -> np.ndarray:
    """SSL-Vision's published camera model (field2image of its camera_calibration.cpp, the classic
    model), field points in mm -> pixels: camera coordinates R(q) p + t, the normalised point, its
    radius distorted by solving r_u = r_d (1 + d r_d^2) in closed form (none for d <= 0), then
    f * p_d + the principal point."""
    pc = Rotation.from_quat(cal.quaternion).apply(field_mm) + np.asarray(cal.translation_m) * 1000.0
    pu = pc[:, :2] / pc[:, 2:3]
    ru = np.hypot(pu[:, 0], pu[:, 1])
    a = cal.distortion
    if a <= np.finfo(float).tiny:
        rd = ru
    else:
        b = -9.0 * a * a * ru + a * np.sqrt(a * (12.0 + 81.0 * a * ru * ru))
        b = np.cbrt(b)
        rd = (2.0 / 3.0) ** (1.0 / 3.0) / b - b / (18.0 ** (1.0 / 3.0) * a)
    pd = pu * (rd / ru)[:, None]
    return cal.focal_px * pd + np.asarray(cal.principal_point_px)


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
                                                                           rms_px: float) -> None:  # fmt: skip
    k1, k2 = lens
    settings = load_settings(None, [f"cameras.auto.k1={k1}", f"cameras.auto.k2={k2}"])
    cams = settings.camera_models()
    _, geo = decode_wrapper(geometry_packet(settings.field_geometry(), cams))
    assert geo is not None
    for cal, cam in zip(geo.cameras, cams, strict=True):
        field_mm, ours = _image_points(cam)
        off = np.hypot(*(_ssl_vision_pixels(cal, field_mm) - ours).T)
        assert off.max() < max_px and np.sqrt(np.mean(off**2)) < rms_px, (lens, off.max())
        if k1 < 0.0:  # our k1 as it went before (SSL-Vision reads a negative value as no distortion)
            before = _ssl_vision_pixels(dataclasses.replace(cal, distortion=k1), field_mm)
            assert np.hypot(*(before - ours).T).max() > 5.0


@pytest.mark.parametrize("distortion, max_px", [(0.0, 1e-3), (0.03, 0.1), (0.1, 0.7), (-0.05, 1e-3)])
def test_an_ssl_vision_calibration_reads_as_our_lens_model(distortion: float, max_px: float) -> None:
    """A calibration as SSL-Vision sends it (its own distortion) projects through our camera model,
    with the (k1, k2) we read from it, where SSL-Vision's model puts the points (to ``max_px`` over
    the image: two terms follow its model closely, not exactly, for a strong lens)."""
    base = load_settings().camera_models()[0]
    wrapper = SSL_WrapperPacket()
    wrapper.geometry.field.CopyFrom(SSL_WrapperPacket.FromString(
        geometry_packet(load_settings().field_geometry(), [base])).geometry.field)  # fmt: skip
    q = Rotation.from_matrix(base.R_cam_to_field.T).as_quat()
    t = -base.R_cam_to_field.T @ base.center * 1000.0
    wrapper.geometry.calib.add(camera_id=3, focal_length=base.f, principal_point_x=base.cx, principal_point_y=base.cy,
                               distortion=distortion, q0=q[0], q1=q[1], q2=q[2], q3=q[3], tx=t[0], ty=t[1], tz=t[2],
                               pixel_image_width=base.width, pixel_image_height=base.height)  # fmt: skip
    _, geo = decode_wrapper(wrapper.SerializeToString())
    assert geo is not None
    cal = geo.cameras[0]
    ours = CameraModel(dataclasses.replace(base.params, id=3, k1=cal.k1, k2=cal.k2))
    field_mm, _ = _image_points(ours)
    off = np.hypot(*(_ssl_vision_pixels(cal, field_mm) - ours.project(field_mm / 1000.0)).T)
    assert off.max() < max_px, (distortion, cal.k1, cal.k2, off.max())
    if distortion <= 0.0:
        assert (cal.k1, cal.k2) == (0.0, 0.0)
