"""Overhead camera model: pinhole with two-term radial distortion, field <-> pixel.

Shared by the simulator (which renders through it) and vision (which measures through it), so
there is one model and one set of parameters (``configs/cameras.yaml``).

Camera frame: x along the image u axis (columns), y along v (rows), z along the optical axis.
With ``yaw_rad = 0`` and no tilt, the camera looks straight down, u runs along the field's +x
and v along the field's -y. Pixel (u, v) is measured from the top-left corner of the top-left
pixel, so the centre of pixel (i, j) is (j + 0.5, i + 0.5).

Distortion, as OpenCV's first two radial terms: with normalised coordinates (x, y) and
``r^2 = x^2 + y^2``, the distorted coordinates are ``(x, y) * (1 + k1 r^2 + k2 r^4)``.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from cmdragons.config import Validated, setting
from cmdragons.geometry import Field, LeagueParams

__all__ = [
    "AutoLayout",
    "CameraModel",
    "CameraParams",
    "CamerasParams",
    "RealisticParams",
    "RecordingParams",
    "cameras_from_config",
    "from_ssl_vision_distortion",
    "opencv_extrinsics",
    "params_from_opencv",
    "scaled_to",
    "smallest_ball_px",
    "ssl_vision_distortion",
]


@dataclass(frozen=True)
class CameraParams(Validated):
    """One camera's intrinsic and extrinsic parameters."""

    id: int = setting(0, lo=0, hi=63)
    position_m: tuple[float, float, float] = (0.0, 0.0, 4.0)  # optical centre in the field frame
    yaw_rad: float = setting(0.0, lo=-2 * math.pi, hi=2 * math.pi)  # image u axis vs field +x
    tilt_x_rad: float = setting(0.0, lo=-0.5, hi=0.5)  # rotation about the camera x axis
    tilt_y_rad: float = setting(0.0, lo=-0.5, hi=0.5)  # rotation about the camera y axis
    focal_px: float = setting(600.0, lo=10.0, hi=100000.0)
    principal_point_px: tuple[float, float] = (512.0, 384.0)
    k1: float = setting(0.0, lo=-1.0, hi=1.0)
    k2: float = setting(0.0, lo=-1.0, hi=1.0)
    resolution_px: tuple[int, int] = (1024, 768)  # width, height

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.position_m[2] <= 0.3:
            raise ValueError("a camera must hang above the field: position_m[2] > 0.3")
        if min(self.resolution_px) < 16:
            raise ValueError("resolution_px must be at least 16 x 16")


@dataclass(frozen=True)
class AutoLayout(Validated):
    """Cameras derived from the field: a grid of downward cameras, each seeing its cell plus the
    overlap with its neighbours and a margin past the field lines, at robot-top height.

    ``grid: auto`` takes the fewest cameras for which the ball is at least ``min_ball_px`` across
    everywhere on the field; ``long_axis: auto`` lays each image's width along its cell's longer side.
    """

    grid: tuple[int, int] | Literal["auto"] = "auto"  # cameras along x, along y
    min_ball_px: float = setting(6.0, lo=1.0, hi=100.0)  # ball diameter in pixels that grid auto ensures
    height_m: float = setting(4.0, lo=0.5, hi=20.0)
    overlap_m: float = setting(0.4, lo=0.0, hi=5.0)  # width of the strip two neighbours both see
    margin_x_m: float = setting(0.25, lo=0.0, hi=2.0)  # past the goal lines
    margin_y_m: float = setting(0.2, lo=0.0, hi=2.0)  # past the touch lines
    resolution_px: tuple[int, int] = (1024, 768)
    long_axis: Literal["x", "y", "auto"] = "auto"  # field axis along the image width
    k1: float = setting(-0.02, lo=-0.5, hi=0.5)
    k2: float = setting(0.0, lo=-0.5, hi=0.5)

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.grid != "auto" and not (1 <= self.grid[0] <= 16 and 1 <= self.grid[1] <= 16):
            raise ValueError("grid must be 'auto' or [nx, ny] with 1 to 16 cameras along each axis")


@dataclass(frozen=True)
class RecordingParams(Validated):
    """How ``cmdragons sim --record`` stores the cameras' frames (a recording's own cameras.yaml
    says what it holds): H.264 video in 4:2:0 at x264 quality ``crf`` (0 best .. 51; 18 visually
    lossless, 23 x264's default), lossless FFV1 video in .mkv, or lossless PNG frames."""

    codec: Literal["h264", "ffv1", "png"] = "h264"
    crf: int = setting(18, lo=0, hi=51)  # h264 only


@dataclass(frozen=True)
class RealisticParams(Validated):
    """configs/cameras.yaml ``realistic``: what a lab's camera adds to the simulator's clean render
    when ``preset: realistic`` (:mod:`sim.render`, ``CameraLook``). Colours BGR grey levels, SI units.

    The lab's own facts -- its ball's size, its tape's width -- are field.yaml's (``ball.radius_m``,
    ``dims.line_width_m``): the preset draws what field.yaml says, as vision reads it."""

    k1: float = setting(-0.2, lo=-0.5, hi=0.5)  # strong barrel distortion, in place of auto.k1 and k2
    k2: float = setting(0.04, lo=-0.5, hi=0.5)
    resolution_px: tuple[int, int] = (1920, 1200)  # in place of auto.resolution_px
    view_margin_m: float = setting(0.6, lo=0.0, hi=5.0)  # seen past the field lines, in place of auto's margins
    vignetting_fraction: float = setting(0.35, lo=0.0, hi=0.9)  # light lost at the image corners (cos^4 falloff)
    lamps: tuple[int, int] = (3, 2)  # ceiling lamps in a grid over the field, along x and y
    lamp_height_m: float = setting(3.0, lo=0.5, hi=20.0)  # above the carpet; lower: rounder pools of light
    lamp_level: float = setting(1.0, lo=0.0, hi=3.0)  # the lamps' light against the plain render's
    lamp_bgr: tuple[float, float, float] = setting((0.85, 1.0, 1.12), lo=0.0, hi=2.0)  # warm-white tint per channel
    lamp_drift_fraction: float = setting(0.15, lo=0.0, hi=0.9)  # each lamp's brightness wanders this much ...
    lamp_drift_period_s: float = setting(40.0, lo=1.0, hi=10000.0)  # ... over about this long (each its own phase)
    daylight_level: float = setting(0.3, lo=0.0, hi=3.0)  # window light from +y, strongest at that touch line
    daylight_bgr: tuple[float, float, float] = setting((1.15, 1.0, 0.88), lo=0.0, hi=2.0)  # bluish
    daylight_drift_fraction: float = setting(0.3, lo=0.0, hi=0.9)  # clouds: daylight wanders this much
    daylight_drift_period_s: float = setting(25.0, lo=1.0, hi=10000.0)
    exposure_target_grey: float = setting(90.0, lo=10.0, hi=240.0)  # auto exposure: mean luma it steers to
    exposure_rate: float = setting(0.15, lo=0.0, hi=1.0)  # share of the error corrected per frame (0: fixed)
    saturation: float = setting(0.75, lo=0.0, hi=1.0)  # colours pulled toward grey (1: as rendered)
    bayer: bool = True  # an RGGB sensor: one channel per pixel, the others interpolated (OpenCV demosaicing)
    specular_grey: float = setting(90.0, lo=0.0, hi=255.0)  # glare on a robot's cover at its peak, under full light
    specular_radius_m: float = setting(0.015, lo=0.001, hi=0.1)  # its Gaussian's sigma on the cover
    specular_reach_m: float = setting(0.15, lo=0.01, hi=2.0)  # how far off a lamp's mirror point a cover still glares
    codec: Literal["none", "jpeg", "h264"] = "jpeg"  # what the camera delivers: raw, JPEG (MJPEG) or H.264
    jpeg_quality: int = setting(85, lo=1, hi=100)
    h264_crf: int = setting(23, lo=0, hi=51)
    floor_bgr: tuple[int, int, int] = setting((70, 110, 150), lo=0, hi=255)  # wooden floor past the boundary
    clutter: int = setting(6, lo=0, hi=100)  # orange-ish things lying on the floor (boxes, a cone, a tan ball)
    hidden_dot: tuple[int, int, int] = (0, 2, 2)  # (team 0 blue / 1 yellow, id, dot 0..3) taped over; id < 0: none


@dataclass(frozen=True)
class CamerasParams(Validated):
    """configs/cameras.yaml."""

    layout: Literal["auto", "list"] = "auto"
    auto: AutoLayout = AutoLayout()
    cameras: tuple[CameraParams, ...] = ()
    recording: RecordingParams = RecordingParams()
    preset: Literal["plain", "realistic"] = "plain"  # the simulated camera: the clean render, or a lab's
    realistic: RealisticParams = RealisticParams()

    def look(self) -> RealisticParams | None:
        """The realistic camera's parameters when that preset is chosen, else None (the clean render)."""
        return self.realistic if self.preset == "realistic" else None

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.layout == "list" and not self.cameras:
            raise ValueError("layout 'list' needs at least one entry under cameras")
        ids = [c.id for c in self.cameras]
        if len(set(ids)) != len(ids):
            raise ValueError("camera ids must be distinct")


class CameraModel:
    """Projection between the field frame (metres) and one camera's pixels."""

    def __init__(self, params: CameraParams) -> None:
        self.params = params
        self.id = params.id
        self.width, self.height = params.resolution_px
        self.f = params.focal_px
        self.cx, self.cy = params.principal_point_px
        self.k1, self.k2 = params.k1, params.k2
        self.center = np.asarray(params.position_m, dtype=np.float64)
        c, s = math.cos(params.yaw_rad), math.sin(params.yaw_rad)
        # camera axes in the field frame, before tilt: x = u, y = v, z = optical axis (down)
        base = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, -1.0]])  # columns: x_c, y_c, z_c
        base[:, 1] = np.cross(base[:, 2], base[:, 0])
        tx, ty = params.tilt_x_rad, params.tilt_y_rad
        rx = np.array([[1, 0, 0], [0, math.cos(tx), -math.sin(tx)], [0, math.sin(tx), math.cos(tx)]])
        ry = np.array([[math.cos(ty), 0, math.sin(ty)], [0, 1, 0], [-math.sin(ty), 0, math.cos(ty)]])
        self.R_cam_to_field: NDArray[np.float64] = base @ rx @ ry

    # --- distortion on normalised coordinates ------------------------------------------------
    def distort(self, xy: NDArray[np.float64]) -> NDArray[np.float64]:
        r2 = np.sum(xy * xy, axis=-1, keepdims=True)
        out: NDArray[np.float64] = xy * (1.0 + self.k1 * r2 + self.k2 * r2 * r2)
        return out

    def undistort(self, xy_d: NDArray[np.float64], iterations: int = 20) -> NDArray[np.float64]:
        """Inverse of :meth:`distort` by Newton's method on the radius (exact to ~1e-12)."""
        rd = np.sqrt(np.sum(xy_d * xy_d, axis=-1))
        r = rd.copy()
        if self.k1 != 0.0 or self.k2 != 0.0:
            for _ in range(iterations):
                r2 = r * r
                g = r * (1.0 + self.k1 * r2 + self.k2 * r2 * r2) - rd
                dg = 1.0 + 3.0 * self.k1 * r2 + 5.0 * self.k2 * r2 * r2
                step = g / np.where(np.abs(dg) < 1e-9, 1e-9, dg)
                r = r - step
                if float(np.max(np.abs(step), initial=0.0)) < 1e-14:
                    break
        scale = np.where(rd > 1e-15, r / np.where(rd > 1e-15, rd, 1.0), 1.0)
        return xy_d * scale[..., None]

    # --- projection ----------------------------------------------------------------------------
    def project(self, points: NDArray[np.float64]) -> NDArray[np.float64]:
        """Field points (..., 3) in metres -> pixels (..., 2). Points behind the camera give NaN."""
        p = np.asarray(points, dtype=np.float64)
        pc = (p - self.center) @ self.R_cam_to_field
        z = pc[..., 2:3]
        with np.errstate(divide="ignore", invalid="ignore"):
            xy = np.where(z > 1e-9, pc[..., :2] / z, np.nan)
        xy = self.distort(xy)
        return np.stack([self.f * xy[..., 0] + self.cx, self.f * xy[..., 1] + self.cy], axis=-1)

    def project_xy(self, xy: NDArray[np.float64], z: float) -> NDArray[np.float64]:
        """Field points (..., 2) on the plane at height ``z`` -> pixels (..., 2)."""
        xy = np.asarray(xy, dtype=np.float64)
        pts = np.concatenate([xy, np.full(xy.shape[:-1] + (1,), z)], axis=-1)
        return self.project(pts)

    def rays(self, pixels: NDArray[np.float64]) -> NDArray[np.float64]:
        """Pixels (..., 2) -> ray directions (..., 3) in the field frame, scaled to dz = -1."""
        px = np.asarray(pixels, dtype=np.float64)
        xy_d = np.stack([(px[..., 0] - self.cx) / self.f, (px[..., 1] - self.cy) / self.f], axis=-1)
        xy = self.undistort(xy_d)
        d_cam = np.concatenate([xy, np.ones(xy.shape[:-1] + (1,))], axis=-1)
        d: NDArray[np.float64] = d_cam @ self.R_cam_to_field.T
        return d / (-d[..., 2:3])

    def unproject(self, pixels: NDArray[np.float64], z: float) -> NDArray[np.float64]:
        """Pixels (..., 2) -> field points (..., 2) on the plane at height ``z`` metres."""
        d = self.rays(pixels)
        t = self.center[2] - z
        out: NDArray[np.float64] = self.center[:2] + d[..., :2] * t
        return out

    def pixel_rays_grid(self) -> NDArray[np.float32]:
        """Ray (dx, dy) per pixel centre, shape (height, width, 2): the field point seen at
        height z is ``center_xy + (center_z - z) * (dx, dy)``."""
        u = np.arange(self.width, dtype=np.float64) + 0.5
        v = np.arange(self.height, dtype=np.float64) + 0.5
        grid = np.stack(np.meshgrid(u, v), axis=-1)
        return self.rays(grid)[..., :2].astype(np.float32)

    def in_image(self, pixels: NDArray[np.float64], margin: float = 0.0) -> NDArray[np.bool_]:
        px = np.asarray(pixels)
        with np.errstate(invalid="ignore"):
            return (
                (px[..., 0] >= margin)
                & (px[..., 0] <= self.width - margin)
                & (px[..., 1] >= margin)
                & (px[..., 1] <= self.height - margin)
            )

    def pixels_per_metre(self, xy: tuple[float, float], z: float) -> float:
        """Local image scale (pixels per metre) at a field point on the plane at height ``z``."""
        h = 1e-3
        pts = np.array([[xy[0] - h, xy[1]], [xy[0] + h, xy[1]], [xy[0], xy[1] - h], [xy[0], xy[1] + h]])
        px = self.project_xy(pts, z)
        sx = np.linalg.norm(px[1] - px[0]) / (2 * h)
        sy = np.linalg.norm(px[3] - px[2]) / (2 * h)
        return float(min(sx, sy))


ASPECT_TOLERANCE = 0.005  # relative difference of width/height ratios still taken as the same aspect


def scaled_to(params: CameraParams, width: int, height: int) -> CameraParams | None:
    """``params`` for frames of ``width`` x ``height`` px of the same camera (a calibration made at
    one size, frames delivered at another): focal length and principal point scaled with the image
    (pixels measured from the top-left corner, so the corner stays the origin); the distortion acts
    on normalised coordinates and is unchanged. None when the aspect ratio differs by more than
    ``ASPECT_TOLERANCE`` (a cropped or stretched image: the model cannot follow it)."""
    w0, h0 = params.resolution_px
    if (width, height) == (w0, h0):
        return params
    sx, sy = width / w0, height / h0
    if abs(sx - sy) > ASPECT_TOLERANCE * max(sx, sy):
        return None
    cx, cy = params.principal_point_px
    return dataclasses.replace(params, resolution_px=(width, height), focal_px=params.focal_px * math.sqrt(sx * sy),
                               principal_point_px=(cx * sx, cy * sy))


def opencv_extrinsics(model: CameraModel) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """OpenCV's (rvec, tvec) of a camera: ``x_cam = R(rvec) p + tvec`` for field points p (m).
    The camera axes are the same (x along u, y along v, z along the optical axis); OpenCV's
    intrinsics differ only in measuring pixels from the centre of the top-left pixel (cx - 0.5)."""
    import cv2

    r_world_to_cam = model.R_cam_to_field.T
    rvec, _ = cv2.Rodrigues(r_world_to_cam)
    tvec: NDArray[np.float64] = -r_world_to_cam @ model.center
    return np.asarray(rvec, dtype=np.float64).ravel(), tvec


def params_from_opencv(rvec: NDArray[np.float64], tvec: NDArray[np.float64], base: CameraParams) -> CameraParams:
    """``base`` with the pose of OpenCV's (rvec, tvec): the inverse of :func:`opencv_extrinsics`.

    With R = base(yaw) @ Rx(tilt_x) @ Ry(tilt_y) (the model's convention), base(yaw) is symmetric,
    so base(yaw) @ R has a zero in row 0, column 1: that fixes yaw up to a half turn, and the
    small tilts (cos(tilt_y) > 0) fix the half turn.
    """
    import cv2

    rot, _ = cv2.Rodrigues(np.asarray(rvec, dtype=np.float64))
    r = rot.T  # camera -> field
    center = -r @ np.asarray(tvec, dtype=np.float64)
    yaw = math.atan2(-r[0, 1], r[1, 1])
    c, s = math.cos(yaw), math.sin(yaw)
    if c * r[0, 0] + s * r[1, 0] < 0.0:
        yaw += math.pi
        c, s = -c, -s
    base_yaw = np.array([[c, s, 0.0], [s, -c, 0.0], [0.0, 0.0, -1.0]])
    m = base_yaw @ r
    return dataclasses.replace(
        base, position_m=(float(center[0]), float(center[1]), float(center[2])),
        yaw_rad=math.remainder(yaw, 2.0 * math.pi), tilt_x_rad=math.atan2(m[2, 1], m[1, 1]),
        tilt_y_rad=math.atan2(m[0, 2], m[0, 0]),
    )


def _image_radii(focal_px: float, principal_point_px: tuple[float, float],
                 resolution_px: tuple[int, int]) -> NDArray[np.float64]:
    """Distorted normalised radii of a grid of points over the whole image (the weights a lens
    model is fitted with: every part of the image as much as it covers)."""
    u = np.linspace(0.0, resolution_px[0], 33) - principal_point_px[0]
    v = np.linspace(0.0, resolution_px[1], 25) - principal_point_px[1]
    uu, vv = np.meshgrid(u, v)
    r: NDArray[np.float64] = np.hypot(uu, vv).ravel() / focal_px
    return r[r > 0.0]


def ssl_vision_distortion(params: CameraParams) -> float:
    """The ``distortion`` of SSL-Vision's camera model nearest to our lens (k1, k2) over the image.

    SSL-Vision relates the undistorted normalised radius r_u and the distorted one r_d by
    r_u = r_d (1 + d r_d^2): a positive d is barrel distortion (our k1 < 0), and a d <= 0 means no
    distortion at all there (a pincushion lens has no value: 0 is sent). d is the least-squares fit
    over the image (to first order d = -k1)."""
    rd = _image_radii(params.focal_px, params.principal_point_px, params.resolution_px)
    ru = np.hypot(*CameraModel(params).undistort(np.stack([rd, np.zeros_like(rd)], axis=-1)).T)
    d = float(np.sum(rd**3 * (ru - rd)) / np.sum(rd**6))
    return max(d, 0.0)


def from_ssl_vision_distortion(distortion: float, focal_px: float, principal_point_px: tuple[float, float],
                               resolution_px: tuple[int, int]) -> tuple[float, float]:
    """Our (k1, k2) nearest, over the image, to SSL-Vision's ``distortion`` (see
    :func:`ssl_vision_distortion`): the least-squares fit of r_d = r_u (1 + k1 r_u^2 + k2 r_u^4) to
    SSL-Vision's r_u = r_d (1 + d r_d^2); (0, 0) for d <= 0, SSL-Vision's "no distortion"."""
    if not distortion > 0.0:
        return 0.0, 0.0
    rd = _image_radii(focal_px, principal_point_px, resolution_px)
    ru = rd * (1.0 + distortion * rd * rd)
    (k1, k2), *_ = np.linalg.lstsq(np.stack([ru**3, ru**5], axis=-1), rd - ru, rcond=None)
    return float(k1), float(k2)


def _auto_camera(cam_id: int, center: tuple[float, float], half: tuple[float, float], lay: AutoLayout,
                 robot_height: float) -> CameraParams:
    w, h = lay.resolution_px
    long_axis = lay.long_axis if lay.long_axis != "auto" else ("x" if half[0] >= half[1] else "y")
    yaw = 0.0 if long_axis == "x" else -math.pi / 2.0
    # the covered rectangle at robot-top height, in camera-frame half extents (u, v)
    hu, hv = (half[0], half[1]) if long_axis == "x" else (half[1], half[0])
    dist = lay.height_m - robot_height
    corner = np.array([hu / dist, hv / dist])

    def fits(f: float) -> bool:
        r2 = float(corner @ corner)
        d = corner * (1.0 + lay.k1 * r2 + lay.k2 * r2 * r2) * f
        return bool(d[0] <= w / 2.0 and d[1] <= h / 2.0)

    lo, hi = 1.0, 100000.0  # the largest focal length whose image still holds the rectangle
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if fits(mid) else (lo, mid)
    return CameraParams(
        id=cam_id, position_m=(center[0], center[1], lay.height_m), yaw_rad=yaw, focal_px=lo,
        principal_point_px=(w / 2.0, h / 2.0), k1=lay.k1, k2=lay.k2, resolution_px=(w, h),
    )


def _grid_cameras(grid: tuple[int, int], lay: AutoLayout, league: LeagueParams) -> list[CameraModel]:
    f = Field(league)
    x0, x1 = -f.half_length - lay.margin_x_m, f.half_length + lay.margin_x_m
    y0, y1 = -f.half_width - lay.margin_y_m, f.half_width + lay.margin_y_m
    nx, ny = grid
    cx_w, cy_w = (x1 - x0) / nx, (y1 - y0) / ny
    models = []
    for j in range(ny):
        for i in range(nx):
            # each camera sees its cell, plus half the overlap toward every neighbour
            lo_x = x0 + i * cx_w - (lay.overlap_m / 2.0 if i > 0 else 0.0)
            hi_x = x0 + (i + 1) * cx_w + (lay.overlap_m / 2.0 if i < nx - 1 else 0.0)
            lo_y = y0 + j * cy_w - (lay.overlap_m / 2.0 if j > 0 else 0.0)
            hi_y = y0 + (j + 1) * cy_w + (lay.overlap_m / 2.0 if j < ny - 1 else 0.0)
            centre = ((lo_x + hi_x) / 2.0, (lo_y + hi_y) / 2.0)
            half = ((hi_x - lo_x) / 2.0, (hi_y - lo_y) / 2.0)
            models.append(CameraModel(_auto_camera(j * nx + i, centre, half, lay, league.robot.height_m)))
    return models


def smallest_ball_px(models: list[CameraModel], league: LeagueParams, samples: int = 15) -> float:
    """The ball's smallest diameter in pixels over the playing area, each point taken in the camera
    that sees it largest; 0 where no camera sees a point."""
    f = Field(league)
    z = league.ball.radius_m
    worst = math.inf
    for x in np.linspace(-f.half_length, f.half_length, samples):
        for y in np.linspace(-f.half_width, f.half_width, samples):
            p = np.array([x, y])
            best = max(
                (m.pixels_per_metre((float(x), float(y)), z) for m in models if m.in_image(m.project_xy(p, z))),
                default=0.0,
            )
            worst = min(worst, best * 2.0 * z)
    return worst


_GRIDS = ((1, 1), (2, 1), (1, 2), (2, 2), (3, 2), (2, 3), (3, 3), (4, 2), (4, 3), (3, 4), (4, 4), (6, 4), (8, 4))


def cameras_from_config(params: CamerasParams, league: LeagueParams) -> list[CameraModel]:
    """The camera models in force: the explicit list, or the auto layout over the field."""
    if params.layout == "list":
        return [CameraModel(p) for p in params.cameras]
    lay = params.auto
    if params.preset == "realistic":
        r = params.realistic
        lay = dataclasses.replace(lay, k1=r.k1, k2=r.k2, resolution_px=r.resolution_px, margin_x_m=r.view_margin_m,
                                  margin_y_m=r.view_margin_m)
    if lay.grid != "auto":
        return _grid_cameras(lay.grid, lay, league)
    for grid in _GRIDS:
        models = _grid_cameras(grid, lay, league)
        if smallest_ball_px(models, league) >= lay.min_ball_px:
            return models
    return models
