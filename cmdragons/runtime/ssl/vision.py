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
Pixels (principal points, detections' pixel_x and pixel_y) are SSL-Vision's on the wire
(:data:`PIXEL_ORIGIN`).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from cmdragons.camera import (
    CameraModel,
    CameraParams,
    from_ssl_vision_distortion,
    params_from_opencv,
    ssl_vision_distortion,
)
from cmdragons.geometry import BallShape, Field, FieldDims
from cmdragons.messages import DetectionFrame, MessageError
from cmdragons.runtime import wire
from cmdragons.runtime.proto import ssl_geometry_pb2 as geo_pb
from cmdragons.runtime.proto import ssl_wrapper_pb2 as wrap_pb
from cmdragons.runtime.settings import Settings
from cmdragons.runtime.ssl.clock import UnixEpoch, run_epoch

__all__ = ["CameraCalibration", "FieldArc", "FieldLine", "VisionGeometry", "decode_wrapper", "detection_packet",
           "WrapperContents", "field_dims_of", "geometry_of", "geometry_packet", "read_wrapper",
           "settings_on_geometry"]

MM = wire.MM
# SSL-Vision's pixel coordinates count from the centre of the top-left pixel (its regions' centroids
# are means of column and row indices), ours from that pixel's corner: ours = SSL-Vision's + 0.5
PIXEL_ORIGIN = 0.5

# our field's straight markings (Field.line_segments' order) by the league's names
_LINE_NAMES = ("BottomTouchLine", "TopTouchLine", "LeftGoalLine", "RightGoalLine", "HalfwayLine", "CenterLine",
               "LeftFieldRightPenaltyStretch", "LeftFieldLeftPenaltyStretch", "LeftPenaltyStretch",
               "RightFieldRightPenaltyStretch", "RightFieldLeftPenaltyStretch", "RightPenaltyStretch")


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

    def camera_params(self) -> CameraParams:
        """Our camera model's parameters of this calibration (its pose from the quaternion and
        translation, our k1 and k2; an image size not sent taken as twice the principal point's);
        :class:`MessageError` for a calibration our model cannot hold (a camera tilted more than
        0.5 rad, below 0.3 m)."""
        pp = self.principal_point_px
        size = self.resolution_px if min(self.resolution_px) > 0 else (round(2.0 * pp[0]), round(2.0 * pp[1]))
        try:
            base = CameraParams(id=self.camera_id, focal_px=self.focal_px, principal_point_px=pp, k1=self.k1,
                                k2=self.k2, resolution_px=size)
            rvec = Rotation.from_quat(self.quaternion).as_rotvec()
            return params_from_opencv(rvec, np.asarray(self.translation_m, dtype=np.float64), base)
        except ValueError as exc:
            raise MessageError(f"camera {self.camera_id}'s calibration does not fit our camera model: {exc}") from None


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
        camera_id=cam.id, focal_length=cam.f, principal_point_x=cam.cx - PIXEL_ORIGIN,
        principal_point_y=cam.cy - PIXEL_ORIGIN,
        distortion=ssl_vision_distortion(cam.params),
        q0=q[0], q1=q[1], q2=q[2], q3=q[3], tx=t[0], ty=t[1], tz=t[2], derived_camera_world_tx=c[0],
        derived_camera_world_ty=c[1], derived_camera_world_tz=c[2], pixel_image_width=cam.width,
        pixel_image_height=cam.height)


def geometry_packet(field: Field, cameras: list[CameraModel]) -> bytes:
    """An SSL_WrapperPacket with the field's size, lines and centre circle, the ball model and every
    camera's calibration."""
    d, league = field.dims, field.league
    g = wrap_pb.SSL_WrapperPacket()
    f = g.geometry.field
    f.field_length, f.field_width = round(d.length_m * MM), round(d.width_m * MM)
    f.goal_width, f.goal_depth, f.boundary_width = (round(v * MM) for v in (d.goal_width_m, d.goal_depth_m,
                                                                              d.boundary_width_m))
    f.penalty_area_depth, f.penalty_area_width = round(d.defense_depth_m * MM), round(d.defense_width_m * MM)
    f.center_circle_radius, f.line_thickness = round(d.center_circle_radius_m * MM), round(d.line_width_m * MM)
    f.goal_height = round(d.goal_height_m * MM)
    f.ball_radius, f.max_robot_radius = league.ball.radius_m * MM, league.robot.radius_m * MM
    for name, seg in zip(_LINE_NAMES, field.line_segments(), strict=True):
        f.field_lines.add(name=name, p1=_v(seg.a), p2=_v(seg.b), thickness=d.line_width_m * MM,
                          type=geo_pb.SSL_FieldShapeType.Value(name))
    f.field_arcs.add(name="CenterCircle", center=_v((0.0, 0.0)), radius=d.center_circle_radius_m * MM, a1=0.0,
                     a2=2.0 * math.pi, thickness=d.line_width_m * MM, type=geo_pb.CenterCircle)
    for cam in cameras:
        g.geometry.calib.append(_calibration(cam))
    ball: BallShape = league.ball
    m = g.geometry.models.straight_two_phase
    m.acc_slide, m.acc_roll, m.k_switch = -ball.acc_slide_m_s2, -ball.acc_roll_m_s2, ball.slide_to_roll_fraction
    return g.SerializeToString(deterministic=True)  # type: ignore[no-any-return]


def detection_packet(det: DetectionFrame, epoch: UnixEpoch | None = None) -> bytes:
    """An SSL_WrapperPacket with one camera frame's detections (mm): ``t_capture`` and ``t_sent``
    in Unix time (``epoch``, by default the run's), ``t_capture_camera`` the match time (our
    cameras' own clock)."""
    e = run_epoch() if epoch is None else epoch
    g = wrap_pb.SSL_WrapperPacket()
    g.detection.CopyFrom(wire.to_proto(det))
    d = g.detection
    d.t_capture, d.t_sent, d.t_capture_camera = e.to_unix(det.t_capture), e.to_unix(det.t_sent), det.t_capture
    for row in (*d.balls, *d.robots_blue, *d.robots_yellow):
        row.pixel_x, row.pixel_y = row.pixel_x - PIXEL_ORIGIN, row.pixel_y - PIXEL_ORIGIN
    return g.SerializeToString(deterministic=True)  # type: ignore[no-any-return]


def geometry_of(m: Any) -> VisionGeometry:
    """Our reading of an SSL_GeometryData (metres)."""
    f = m.field
    lines = tuple(FieldLine(s.name, (s.p1.x / MM, s.p1.y / MM), (s.p2.x / MM, s.p2.y / MM), s.thickness / MM)
                  for s in f.field_lines)
    arcs = tuple(FieldArc(a.name, (a.center.x / MM, a.center.y / MM), a.radius / MM, a.a1, a.a2, a.thickness / MM)
                 for a in f.field_arcs)
    cams = tuple(_calibration_of(c) for c in m.calib)
    s = m.models.straight_two_phase if m.models.HasField("straight_two_phase") else None
    return VisionGeometry(
        f.field_length / MM, f.field_width / MM, f.goal_width / MM, f.goal_depth / MM, f.boundary_width / MM,
        f.penalty_area_depth / MM, f.penalty_area_width / MM, f.center_circle_radius / MM, f.line_thickness / MM,
        f.goal_height / MM, f.ball_radius / MM, f.max_robot_radius / MM, lines, arcs, cams,
        -s.acc_slide if s else math.nan, -s.acc_roll if s else math.nan, s.k_switch if s else math.nan)


def _calibration_of(c: Any) -> CameraCalibration:
    """One SSL_GeometryCameraCalibration (metres); the image's size, when not sent, taken as twice
    the principal point's for fitting our lens terms."""
    pp = (c.principal_point_x + PIXEL_ORIGIN, c.principal_point_y + PIXEL_ORIGIN)
    size = (c.pixel_image_width, c.pixel_image_height)
    fit_size = size if min(size) > 0 else (round(2.0 * pp[0]), round(2.0 * pp[1]))
    k1, k2 = from_ssl_vision_distortion(c.distortion, c.focal_length, pp, fit_size) if c.focal_length > 0 and \
        min(fit_size) > 0 else (0.0, 0.0)
    return CameraCalibration(c.camera_id, c.focal_length, pp, c.distortion, (c.q0, c.q1, c.q2, c.q3),
                             (c.tx / MM, c.ty / MM, c.tz / MM), _camera_position(c), size, k1, k2)


def _camera_position(c: Any) -> tuple[float, float, float]:
    """The camera in the field frame (m): the derived fields when sent, else -R(q)^T t."""
    if c.HasField("derived_camera_world_tx"):
        return (c.derived_camera_world_tx / MM, c.derived_camera_world_ty / MM, c.derived_camera_world_tz / MM)
    r = Rotation.from_quat([c.q0, c.q1, c.q2, c.q3]).as_matrix()
    p = -r.T @ np.array([c.tx, c.ty, c.tz]) / MM
    return (float(p[0]), float(p[1]), float(p[2]))


@dataclass(frozen=True)
class WrapperContents:
    """An SSL_WrapperPacket read: its detections and geometry (either may be absent) and the robot
    detections left out by rule, by reason: ``no id`` (a robot SSL-Vision could not identify) and
    ``no orientation`` (our tracker follows a robot's heading: a detection without one is not
    guessed as 0)."""

    detection: DetectionFrame | None
    geometry: VisionGeometry | None
    robots_left_out: dict[str, int]


def _keep_whole_robots(m: Any) -> dict[str, int]:
    """Take the robot detections without an id or an orientation out of an SSL_DetectionFrame; how
    many of each."""
    out = {"no id": 0, "no orientation": 0}
    for rows in (m.robots_blue, m.robots_yellow):
        keep = []
        for r in rows:
            if not r.HasField("robot_id"):
                out["no id"] += 1
            elif not r.HasField("orientation"):
                out["no orientation"] += 1
            else:
                keep.append(r)
        if len(keep) < len(rows):
            del rows[:]
            rows.extend(keep)
    return {k: v for k, v in out.items() if v}


def read_wrapper(data: bytes, epoch: UnixEpoch | None = None, camera_clock: bool = False) -> WrapperContents:
    """An SSL_WrapperPacket's bytes read; :class:`MessageError` for bytes that are not one
    (garbage, cut short, a required field missing). Times in match time: the packet's Unix times
    less ``epoch`` (by default the run's), or with ``camera_clock`` (packets known to be our own)
    ``t_capture_camera`` as the capture time when sent. Robots without id or orientation are left
    out and counted (:class:`WrapperContents`)."""
    g = wire.parse(wrap_pb.SSL_WrapperPacket, data)
    det = None
    left_out: dict[str, int] = {}
    if g.HasField("detection"):
        e = run_epoch() if epoch is None else epoch
        m = g.detection
        left_out = _keep_whole_robots(m)
        for row in (*m.balls, *m.robots_blue, *m.robots_yellow):
            row.pixel_x, row.pixel_y = row.pixel_x + PIXEL_ORIGIN, row.pixel_y + PIXEL_ORIGIN
        t = m.t_capture_camera if camera_clock and m.HasField("t_capture_camera") else e.to_match(m.t_capture)
        det = dataclasses.replace(wire.from_proto(m), t_capture=t, t_sent=e.to_match(m.t_sent))
    geo = geometry_of(g.geometry) if g.HasField("geometry") else None
    return WrapperContents(det, geo, left_out)


def decode_wrapper(data: bytes, epoch: UnixEpoch | None = None,
                   camera_clock: bool = False) -> tuple[DetectionFrame | None, VisionGeometry | None]:
    """:func:`read_wrapper`'s detections and geometry."""
    got = read_wrapper(data, epoch, camera_clock)
    return got.detection, got.geometry


def field_dims_of(geo: VisionGeometry, base: FieldDims) -> FieldDims:
    """``base`` with the sizes of a geometry packet's field (metres): the required ones always, an
    optional one (defense area, centre circle, lines, goal height) where it was sent; what a
    packet does not say (the robots a team, the goal walls' thickness) stays ``base``'s.
    :class:`MessageError` for sizes that make no field."""
    sent: dict[str, Any] = {"defense_depth_m": geo.penalty_area_depth_m, "defense_width_m": geo.penalty_area_width_m,
            "center_circle_radius_m": geo.center_circle_radius_m, "line_width_m": geo.line_thickness_m,
            "goal_height_m": geo.goal_height_m}
    try:
        return dataclasses.replace(
            base, length_m=geo.field_length_m, width_m=geo.field_width_m, goal_width_m=geo.goal_width_m,
            goal_depth_m=geo.goal_depth_m, boundary_width_m=geo.boundary_width_m,
            **{k: v for k, v in sent.items() if v > 0.0})
    except ValueError as exc:
        raise MessageError(f"the geometry's field ({geo.field_length_m:g} x {geo.field_width_m:g} m) is not one we "
                           f"can play on: {exc}") from None


def settings_on_geometry(settings: Settings, geo: VisionGeometry) -> Settings:
    """``settings`` with the division in force sized as the geometry's field (:func:`field_dims_of`)."""
    league = settings.field
    dims = field_dims_of(geo, league.dims)
    return dataclasses.replace(settings, field=dataclasses.replace(league, divisions={**league.divisions,
                                                                                     league.division: dims}))
