"""SSL-Vision packets: :class:`DetectionFrame` and the field and camera geometry <->
``SSL_WrapperPacket`` bytes (millimetres on the wire, metres inside).

The detection inside the packet is the wire's own mapping (:func:`cmdragons.runtime.wire.to_proto`
of a DetectionFrame is the league's SSL_DetectionFrame already); this module adds the wrapper and
the geometry. Camera calibrations follow SSL-Vision's convention: the quaternion (q0, q1, q2 the
vector part, q3 the scalar) rotates field coordinates into the camera frame and (tx, ty, tz) is the
field origin in the camera frame, so a point's camera coordinates are R(q) p + t (mm). The
``distortion`` is SSL-Vision's: r_u = r_d (1 + distortion r_d^2) on normalised radii, positive for
barrel distortion (our lens model's k1 < 0), none at all for a value <= 0; our (k1, k2) go out as
the nearest such value over the image and come back as the (k1, k2) nearest to it
(:func:`cmdragons.camera.ssl_vision_distortion`). The league's layout has no second coefficient.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from cmdragons.camera import CameraModel, from_ssl_vision_distortion, ssl_vision_distortion
from cmdragons.geometry import BallShape, Field
from cmdragons.messages import DetectionFrame
from cmdragons.runtime import wire
from cmdragons.runtime.proto import ssl_geometry_pb2 as geo_pb
from cmdragons.runtime.proto import ssl_wrapper_pb2 as wrap_pb

__all__ = ["CameraCalibration", "FieldArc", "FieldLine", "VisionGeometry", "decode_wrapper", "detection_packet",
           "geometry_of", "geometry_packet"]  # fmt: skip

MM = wire.MM

# our field's straight markings (Field.line_segments' order) by the league's names
_LINE_NAMES = ("BottomTouchLine", "TopTouchLine", "LeftGoalLine", "RightGoalLine", "HalfwayLine", "CenterLine",
               "LeftFieldRightPenaltyStretch", "LeftFieldLeftPenaltyStretch", "LeftPenaltyStretch",
               "RightFieldRightPenaltyStretch", "RightFieldLeftPenaltyStretch", "RightPenaltyStretch")  # fmt: skip


@dataclass(frozen=True)
class FieldLine:
    name: str
    p1: tuple[float, float]  # m
    p2: tuple[float, float]  # m
    thickness_m: float


@dataclass(frozen=True)
class FieldArc:
    name: str
    center: tuple[float, float]  # m
    radius_m: float
    a1_rad: float
    a2_rad: float
    thickness_m: float


@dataclass(frozen=True)
class CameraCalibration:
    camera_id: int
    focal_px: float
    principal_point_px: tuple[float, float]
    distortion: float  # SSL-Vision's (see the module)
    quaternion: tuple[float, float, float, float]  # q0, q1, q2 (vector), q3 (scalar): field -> camera
    translation_m: tuple[float, float, float]  # the field origin in the camera frame
    position_m: tuple[float, float, float]  # the camera in the field frame
    resolution_px: tuple[int, int]  # (0, 0): not sent
    k1: float = 0.0  # our lens model's radial terms nearest to ``distortion`` over the image
    k2: float = 0.0


@dataclass(frozen=True)
class VisionGeometry:
    """What an SSL_GeometryData packet says, in metres."""

    field_length_m: float
    field_width_m: float
    goal_width_m: float
    goal_depth_m: float
    boundary_width_m: float
    penalty_area_depth_m: float
    penalty_area_width_m: float
    center_circle_radius_m: float
    line_thickness_m: float
    goal_height_m: float
    ball_radius_m: float
    max_robot_radius_m: float
    lines: tuple[FieldLine, ...]
    arcs: tuple[FieldArc, ...]
    cameras: tuple[CameraCalibration, ...]
    acc_slide_m_s2: float = math.nan
    acc_roll_m_s2: float = math.nan
    slide_to_roll_fraction: float = math.nan


def _v(p: tuple[float, float]) -> Any:
    return geo_pb.Vector2f(x=p[0] * MM, y=p[1] * MM)


def _calibration(cam: CameraModel) -> Any:
    r_field_to_cam = cam.R_cam_to_field.T
    q = Rotation.from_matrix(r_field_to_cam).as_quat()  # x, y, z, w
    t = -r_field_to_cam @ cam.center * MM
    c = cam.center * MM
    return geo_pb.SSL_GeometryCameraCalibration(
        camera_id=cam.id, focal_length=cam.f, principal_point_x=cam.cx, principal_point_y=cam.cy,
        distortion=ssl_vision_distortion(cam.params),
        q0=q[0], q1=q[1], q2=q[2], q3=q[3], tx=t[0], ty=t[1], tz=t[2], derived_camera_world_tx=c[0],
        derived_camera_world_ty=c[1], derived_camera_world_tz=c[2], pixel_image_width=cam.width,
        pixel_image_height=cam.height)  # fmt: skip


def geometry_packet(field: Field, cameras: list[CameraModel]) -> bytes:
    """An SSL_WrapperPacket with the field's size, lines and centre circle, the ball model and every
    camera's calibration."""
    d, league = field.dims, field.league
    g = wrap_pb.SSL_WrapperPacket()
    f = g.geometry.field
    f.field_length, f.field_width = round(d.length_m * MM), round(d.width_m * MM)
    f.goal_width, f.goal_depth, f.boundary_width = (round(v * MM) for v in (d.goal_width_m, d.goal_depth_m,
                                                                              d.boundary_width_m))  # fmt: skip
    f.penalty_area_depth, f.penalty_area_width = round(d.defense_depth_m * MM), round(d.defense_width_m * MM)
    f.center_circle_radius, f.line_thickness = round(d.center_circle_radius_m * MM), round(d.line_width_m * MM)
    f.goal_height = round(d.goal_height_m * MM)
    f.ball_radius, f.max_robot_radius = league.ball.radius_m * MM, league.robot.radius_m * MM
    for name, seg in zip(_LINE_NAMES, field.line_segments(), strict=True):
        f.field_lines.add(name=name, p1=_v(seg.a), p2=_v(seg.b), thickness=d.line_width_m * MM,
                          type=geo_pb.SSL_FieldShapeType.Value(name))  # fmt: skip
    f.field_arcs.add(name="CenterCircle", center=_v((0.0, 0.0)), radius=d.center_circle_radius_m * MM, a1=0.0,
                     a2=2.0 * math.pi, thickness=d.line_width_m * MM, type=geo_pb.CenterCircle)  # fmt: skip
    for cam in cameras:
        g.geometry.calib.append(_calibration(cam))
    ball: BallShape = league.ball
    m = g.geometry.models.straight_two_phase
    m.acc_slide, m.acc_roll, m.k_switch = -ball.acc_slide_m_s2, -ball.acc_roll_m_s2, ball.slide_to_roll_fraction
    return g.SerializeToString(deterministic=True)  # type: ignore[no-any-return]


def detection_packet(det: DetectionFrame) -> bytes:
    """An SSL_WrapperPacket with one camera frame's detections (mm)."""
    g = wrap_pb.SSL_WrapperPacket()
    g.detection.CopyFrom(wire.to_proto(det))
    return g.SerializeToString(deterministic=True)  # type: ignore[no-any-return]


def geometry_of(m: Any) -> VisionGeometry:
    """Our reading of an SSL_GeometryData (metres)."""
    f = m.field
    lines = tuple(FieldLine(s.name, (s.p1.x / MM, s.p1.y / MM), (s.p2.x / MM, s.p2.y / MM), s.thickness / MM)
                  for s in f.field_lines)  # fmt: skip
    arcs = tuple(FieldArc(a.name, (a.center.x / MM, a.center.y / MM), a.radius / MM, a.a1, a.a2, a.thickness / MM)
                 for a in f.field_arcs)  # fmt: skip
    cams = tuple(_calibration_of(c) for c in m.calib)
    s = m.models.straight_two_phase if m.models.HasField("straight_two_phase") else None
    return VisionGeometry(
        f.field_length / MM, f.field_width / MM, f.goal_width / MM, f.goal_depth / MM, f.boundary_width / MM,
        f.penalty_area_depth / MM, f.penalty_area_width / MM, f.center_circle_radius / MM, f.line_thickness / MM,
        f.goal_height / MM, f.ball_radius / MM, f.max_robot_radius / MM, lines, arcs, cams,
        -s.acc_slide if s else math.nan, -s.acc_roll if s else math.nan, s.k_switch if s else math.nan)  # fmt: skip


def _calibration_of(c: Any) -> CameraCalibration:
    """One SSL_GeometryCameraCalibration (metres); the image's size, when not sent, taken as twice
    the principal point's for fitting our lens terms."""
    pp = (c.principal_point_x, c.principal_point_y)
    size = (c.pixel_image_width, c.pixel_image_height)
    fit_size = size if min(size) > 0 else (round(2.0 * pp[0]), round(2.0 * pp[1]))
    k1, k2 = from_ssl_vision_distortion(c.distortion, c.focal_length, pp, fit_size) if c.focal_length > 0 and \
        min(fit_size) > 0 else (0.0, 0.0)  # fmt: skip
    return CameraCalibration(c.camera_id, c.focal_length, pp, c.distortion, (c.q0, c.q1, c.q2, c.q3),
                             (c.tx / MM, c.ty / MM, c.tz / MM), _camera_position(c), size, k1, k2)  # fmt: skip


def _camera_position(c: Any) -> tuple[float, float, float]:
    """The camera in the field frame (m): the derived fields when sent, else -R(q)^T t."""
    if c.HasField("derived_camera_world_tx"):
        return (c.derived_camera_world_tx / MM, c.derived_camera_world_ty / MM, c.derived_camera_world_tz / MM)
    r = Rotation.from_quat([c.q0, c.q1, c.q2, c.q3]).as_matrix()
    p = -r.T @ np.array([c.tx, c.ty, c.tz]) / MM
    return (float(p[0]), float(p[1]), float(p[2]))


def decode_wrapper(data: bytes) -> tuple[DetectionFrame | None, VisionGeometry | None]:
    """The detections and the geometry of an SSL_WrapperPacket's bytes (either may be absent);
    :class:`MessageError` for bytes that are not one (garbage, cut short, a required field missing)."""
    g = wire.parse(wrap_pb.SSL_WrapperPacket, data)
    det = wire.from_proto(g.detection) if g.HasField("detection") else None
    geo = geometry_of(g.geometry) if g.HasField("geometry") else None
    return det, geo
