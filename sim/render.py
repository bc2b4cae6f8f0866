"""Overhead camera renderer: what one ceiling camera would see of the field, robots and ball.

Geometry through :class:`cmdragons.camera.CameraModel` (pinhole + radial distortion), so a pixel
sees exactly what vision's inverse of the same model expects. Objects are drawn at their real
heights: robot tops (with the league's standard pattern) at ``robot.height_m``, their sides where
the ray passes through the body below the top, the ball as a sphere; this gives the parallax and
occlusions of a real overhead camera (SSL-Vision's setting, Bruce's thesis §2).

Cost model: the static scene (carpet, lines, goals in 3D, lighting) is drawn once per camera;
a frame is a noisy copy of it plus the dynamic objects inside their projected bounding boxes,
all in one numba pass (:mod:`sim._kernels`).
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass
from typing import Any

import cv2
import numba
import numpy as np
from numpy.typing import NDArray

from cmdragons.camera import CameraModel, RealisticParams
from cmdragons.config import Validated, setting
from cmdragons.geometry import Field, LeagueParams
from cmdragons.videoio import H264RoundTrip
from sim import _kernels as kern
from sim.snapshot import Snapshot

__all__ = ["CameraLook", "CameraRenderer", "CameraTruth", "Lighting", "RenderParams"]

BGR = tuple[int, int, int]


@dataclass(frozen=True)
class RenderParams(Validated):
    """configs/sim.yaml ``render``: the camera's sensor and the colours of the scene.

    Colours are BGR grey levels (0..255) under full light, chosen far apart in YUV so a colour
    segmenter can separate them; the id-dot green is brighter and more saturated than the carpet.
    """

    noise_sigma_grey: float = setting(2.5, lo=0.0, hi=40.0)  # per channel, grey levels; 0: off
    vignetting_fraction: float = setting(0.12, lo=0.0, hi=0.9)  # light lost at the image corners
    gradient_fraction: float = setting(0.08, lo=0.0, hi=0.9)  # light change from -x to +x goal line
    exposure_s: float = setting(0.002, lo=0.0, hi=0.05)  # motion blur; 0: off
    max_blur_samples: int = setting(8, lo=1, hi=64)  # time samples per moving object, at most
    blur_step_px: float = setting(0.5, lo=0.05, hi=10.0)  # samples at most this far apart (px)
    static_supersampling: int = setting(4, lo=1, hi=8)  # per axis, for the goals' edges (once)
    ball_ambient_fraction: float = setting(0.6, lo=0.0, hi=1.0)  # ball rim brightness vs its top

    carpet_bgr: BGR = setting((40, 110, 40), lo=0, hi=255)
    line_bgr: BGR = setting((235, 235, 235), lo=0, hi=255)
    goal_bgr: BGR = setting((150, 150, 155), lo=0, hi=255)  # goal wall tops; their sides are darker
    boundary_bgr: BGR = setting((60, 75, 65), lo=0, hi=255)  # outside the boundary
    ball_bgr: BGR = setting((20, 115, 250), lo=0, hi=255)  # orange
    blue_bgr: BGR = setting((230, 120, 20), lo=0, hi=255)
    yellow_bgr: BGR = setting((20, 220, 240), lo=0, hi=255)
    pink_bgr: BGR = setting((200, 80, 255), lo=0, hi=255)
    green_bgr: BGR = setting((60, 235, 60), lo=0, hi=255)  # id dots
    cover_bgr: BGR = setting((28, 28, 28), lo=0, hi=255)  # matte-black robot top
    side_bgr: BGR = setting((85, 85, 90), lo=0, hi=255)  # robot body seen from the side


@dataclass(frozen=True)
class CameraTruth:
    """What the image shows, projected exactly: for scoring vision against ground truth.

    ``ball``: (u, v) px of the ball centre and the visible fraction of its silhouette (0..1),
    None when the centre is outside the image. ``robots``: (team 0 blue / 1 yellow, id) ->
    (u, v) px of the centre of the robot's top, for robots whose whole top is in the image.
    """

    camera_id: int
    frame_number: int
    t_capture: float
    ball: tuple[float, float, float] | None
    robots: dict[tuple[int, int], tuple[float, float]]


class CameraRenderer:
    """Renders one camera's BGR image of a :class:`~sim.snapshot.Snapshot`.

    Sensor noise is fresh every frame, as a real sensor's: each frame draws a 64-bit key from a
    generator seeded by ``seed`` and the camera id, and the key picks every row's values from a
    pool of Gaussian noise and flips their signs (:mod:`sim._kernels`, sensor noise). The same
    seed and snapshots give identical bytes.

    ``lighting`` (a lab's light, one for all cameras of a match): the frames are a lab camera's
    (:class:`CameraLook`, cameras.yaml ``preset: realistic``), not the clean render's.
    """

    def __init__(self, model: CameraModel, league: LeagueParams, params: RenderParams, seed: int,
                 lighting: Lighting | None = None) -> None:
        self.model, self.league, self.params = model, league, params
        self.field = Field(league)
        self.rng = np.random.default_rng([seed, model.id])
        h, w = model.height, model.width
        self.shape_hw = (h, w)

        self.rays = np.ascontiguousarray(model.pixel_rays_grid())  # (h, w, 2) per metre of descent
        self.foot = _footprints(self.rays)
        ground = model.center[:2] + model.center[2] * self.rays.astype(np.float64)
        self.gain = _lighting_gain(model, ground, self.field.dims.length_m, params)
        self.background = _static_background(model, self.field, params, self.rays, self.foot, self.gain)
        self.look: CameraLook | None = None
        if lighting is not None:
            self.look = CameraLook(model, league, lighting.params, lighting, self.rays, seed)
            self.background = self.look.floor(self.background, self.rays, self.gain, self.field)

        robot, pattern = league.robot, league.pattern
        self.cam = kern.camera_vector(model)
        self.shape = np.zeros(kern.SHAPE_SIZE)
        self.shape[kern.SHAPE_ROBOT_RADIUS] = robot.radius_m
        self.shape[kern.SHAPE_ROBOT_HEIGHT] = robot.height_m
        self.shape[kern.SHAPE_ROBOT_FRONT] = robot.front_distance_m
        self.shape[kern.SHAPE_BALL_RADIUS] = league.ball.radius_m
        self.shape[kern.SHAPE_CENTER_DOT_RADIUS] = pattern.center_dot_diameter_m / 2.0
        self.shape[kern.SHAPE_ID_DOT_RADIUS] = pattern.id_dot_diameter_m / 2.0
        self.shape[kern.SHAPE_BALL_AMBIENT] = params.ball_ambient_fraction
        self.dots = np.array(pattern.dot_positions_m, dtype=np.float64).reshape(-1, 2)
        self.pink = np.array([pattern.dot_is_pink(i) for i in range(len(pattern.ids))], dtype=np.bool_)
        palette = np.zeros((kern.PAL_SIZE, 3), dtype=np.float32)
        palette[kern.PAL_COVER] = params.cover_bgr
        palette[kern.PAL_SIDE] = params.side_bgr
        palette[kern.PAL_BALL] = params.ball_bgr
        palette[kern.PAL_BLUE] = params.blue_bgr
        palette[kern.PAL_YELLOW] = params.yellow_bgr
        palette[kern.PAL_PINK] = params.pink_bgr
        palette[kern.PAL_GREEN] = params.green_bgr
        self.palette = palette

        self.noise = kern.noise_pool(self.rng, h * w * 3, w * 3, params.noise_sigma_grey)
        self._plan = kern.ObjectPlan(32, params.max_blur_samples, len(self.dots))
        self._row_ball = np.zeros((h, 2))
        self._n_chunks = max(1, numba.get_num_threads())
        self._last_image: NDArray[np.uint8] | None = None

    # --- per frame ---------------------------------------------------------------------------
    def render(self, snapshot: Snapshot) -> tuple[NDArray[np.uint8], CameraTruth]:
        """The camera image (height, width, 3) BGR uint8 of ``snapshot`` (field frame, SI units)
        and its truth. The image is the caller's: it is never written again by this renderer."""
        out = self._last_image
        # reuse the previous image when nothing outside holds it (nor a view of it): a fresh
        # 2.4 MB array costs about 0.25 ms of page faults, a fifth of the frame budget.
        # References here: the attribute, ``out`` and getrefcount's argument.
        if out is None or sys.getrefcount(out) > 3:
            out = np.empty((self.model.height, self.model.width, 3), dtype=np.uint8)
        truth = self.render_into(snapshot, out)
        self._last_image = out
        if self.look is not None:
            return self.look.apply(out, snapshot, self.gain, self.params.cover_bgr), truth
        return out, truth

    def render_into(self, snapshot: Snapshot, out: NDArray[np.uint8]) -> CameraTruth:
        """Render ``snapshot`` into ``out`` (height, width, 3) BGR uint8, C-contiguous."""
        if out.shape != (*self.shape_hw, 3) or out.dtype != np.uint8 or not out.flags.c_contiguous:
            raise ValueError(f"out must be a C-contiguous uint8 array of shape {(*self.shape_hw, 3)}")
        robots = np.ascontiguousarray(snapshot.robots, dtype=np.float64).reshape(-1, 8)
        ball = np.ascontiguousarray(snapshot.ball, dtype=np.float64)
        plan = self._plan
        if robots.shape[0] > plan.capacity:
            plan = self._plan = kern.ObjectPlan(robots.shape[0], self.params.max_blur_samples, len(self.dots))
        kern.plan_objects(plan, robots, ball, self.cam, self.shape, self.pink, self.dots, self.palette,
                          self.params.exposure_s, self.params.blur_step_px)
        noise_key = None
        if self.params.noise_sigma_grey > 0.0:
            noise_key = int(self.rng.integers(2**64, dtype=np.uint64))
        vis, sil = kern.render_frame(out, self.background, self.noise, noise_key, self.rays, self.foot, self.gain,
                                     self.cam, self.shape, self.dots, self.palette, plan, self._row_ball,
                                     self._n_chunks)
        return self._truth(snapshot, robots, plan, vis, sil)

    def _truth(self, snapshot: Snapshot, robots: NDArray[np.float64], plan: kern.ObjectPlan, vis: float,
               sil: float) -> CameraTruth:
        bt = plan.ball_truth
        ball = None
        if bt[2] > 0.0:
            ball = (float(bt[0]), float(bt[1]), min(1.0, vis / sil) if sil > 0.0 else 0.0)
        seen: dict[tuple[int, int], tuple[float, float]] = {}
        for k in np.flatnonzero(plan.rob_truth[: plan.n, 2] > 0.0):
            seen[(int(robots[k, 0]), int(robots[k, 1]))] = (float(plan.rob_truth[k, 0]), float(plan.rob_truth[k, 1]))
        return CameraTruth(self.model.id, snapshot.frame_number, snapshot.t, ball, seen)


# --- the static scene, once per camera ---------------------------------------------------------------


def _footprints(rays: NDArray[np.float32]) -> NDArray[np.float32]:
    """Per pixel, the side (m) of the square of equal area that the pixel covers on a horizontal
    plane one metre below the camera: the finite-difference Jacobian of the rays."""
    r = rays.astype(np.float64)
    du = np.gradient(r, axis=1)
    dv = np.gradient(r, axis=0)
    area = np.abs(du[..., 0] * dv[..., 1] - du[..., 1] * dv[..., 0])
    foot: NDArray[np.float32] = np.sqrt(area).astype(np.float32)
    return foot


def _lighting_gain(model: CameraModel, ground: NDArray[np.float64], field_length_m: float,
                   params: RenderParams) -> NDArray[np.float32]:
    """Per-pixel light gain: vignetting (quadratic in the distance from the principal point,
    ``1 - vignetting`` at the farthest corner) times a linear gradient along the field's x
    (``1 +- gradient/2`` at the goal lines)."""
    v, u = np.mgrid[0 : model.height, 0 : model.width].astype(np.float64) + 0.5
    r2 = (u - model.cx) ** 2 + (v - model.cy) ** 2
    corners = [(0.0, 0.0), (model.width, 0.0), (0.0, model.height), (model.width, model.height)]
    r2_max = max((cu - model.cx) ** 2 + (cv - model.cy) ** 2 for cu, cv in corners)
    gain = (1.0 - params.vignetting_fraction * r2 / r2_max) * (
        1.0 + params.gradient_fraction * ground[..., 0] / field_length_m
    )
    out: NDArray[np.float32] = np.clip(gain, 0.0, None).astype(np.float32)
    return out


def _coverage(sd: NDArray[np.float64], pix: NDArray[np.float64]) -> NDArray[np.float64]:
    return np.clip(0.5 - sd / pix, 0.0, 1.0)


def _segment_distance(px: NDArray[np.float64], py: NDArray[np.float64], a: tuple[float, float],
                      b: tuple[float, float]) -> NDArray[np.float64]:
    ax, ay = a
    dx, dy = b[0] - ax, b[1] - ay
    t = np.clip(((px - ax) * dx + (py - ay) * dy) / max(dx * dx + dy * dy, 1e-18), 0.0, 1.0)
    return np.hypot(px - ax - t * dx, py - ay - t * dy)


def _goal_hits(center: NDArray[np.float64], d: NDArray[np.float64], boxes: list[tuple[float, float, float, float]],
               height_m: float) -> tuple[NDArray[np.bool_], NDArray[np.int64]]:
    """Rays ``center + t (dx, dy, -1)`` against vertical boxes (x0, y0, x1, y1) of ``height_m``:
    hit mask and the face the nearest hit enters (0 top, 1 an x face, 2 a y face)."""
    best_t = np.full(d.shape[:-1], np.inf)
    face = np.zeros(d.shape[:-1], dtype=np.int64)
    cx, cy, cz = center
    for x0, y0, x1, y1 in boxes:
        enter = [np.full(best_t.shape, cz - height_m)]
        leave = [np.full(best_t.shape, cz)]
        for lo, hi, c, dc in ((x0, x1, cx, d[..., 0]), (y0, y1, cy, d[..., 1])):
            # rays parallel to a slab never cross it: a tiny slope stands in, giving +-huge t
            safe = np.where(np.abs(dc) < 1e-12, 1e-12, dc)
            ta, tb = (lo - c) / safe, (hi - c) / safe
            enter.append(np.minimum(ta, tb))
            leave.append(np.maximum(ta, tb))
        t_in = np.max(enter, axis=0)
        t_out = np.min(leave, axis=0)
        hit = (t_in <= t_out) & (t_in < best_t)
        best_t = np.where(hit, t_in, best_t)
        face = np.where(hit, np.argmax(enter, axis=0), face)
    return np.isfinite(best_t), face


def _static_background(model: CameraModel, field: Field, params: RenderParams, rays: NDArray[np.float32],
                       foot: NDArray[np.float32], gain: NDArray[np.float32]) -> NDArray[np.uint8]:
    """The field without robots and ball, lit: carpet, painted lines (anti-aliased by coverage),
    the boundary, and the goals as 3D walls seen with parallax (supersampled at their edges)."""
    d = rays.astype(np.float64)
    cz = model.center[2]
    gx = model.center[0] + cz * d[..., 0]
    gy = model.center[1] + cz * d[..., 1]
    pix = cz * foot.astype(np.float64)
    carpet = np.array(params.carpet_bgr, dtype=np.float64)

    out_sd = np.maximum(np.abs(gx) - field.boundary_half_length, np.abs(gy) - field.boundary_half_width)
    a_out = _coverage(-out_sd, pix)[..., None]
    img = carpet + a_out * (np.array(params.boundary_bgr, dtype=np.float64) - carpet)

    half_w = field.dims.line_width_m / 2.0
    radius = field.dims.center_circle_radius_m
    a_line = np.zeros(gx.shape)
    ring = np.linspace(0.0, 2.0 * np.pi, 65)
    win = _window(model, np.stack([radius * np.cos(ring), radius * np.sin(ring), 0.0 * ring], 1))
    if win is not None and field.dims.center_circle:
        a_line[win] = _coverage(np.abs(np.hypot(gx[win], gy[win]) - radius) - half_w, pix[win])
    for seg in field.painted_segments():
        along = np.linspace(0.0, 1.0, 33)[:, None]
        pts = np.array(seg.a) + along * (np.array(seg.b) - np.array(seg.a))
        win = _window(model, np.concatenate([pts, np.zeros((33, 1))], 1))
        if win is not None:
            a = _coverage(_segment_distance(gx[win], gy[win], seg.a, seg.b) - half_w, pix[win])
            a_line[win] = np.maximum(a_line[win], a)
    img += a_line[..., None] * (np.array(params.line_bgr, dtype=np.float64) - img)

    gh = field.dims.goal_height_m
    face_gain = np.array([1.0, 0.8, 0.68])  # top, x-facing, y-facing: light from above, off-axis
    goal = np.array(params.goal_bgr, dtype=np.float64)
    for side in (1.0, -1.0):
        boxes = field.goal_walls(side)
        corners = np.array([(x, y, z) for x0, y0, x1, y1 in boxes for x in (x0, x1) for y in (y0, y1)
                            for z in (0.0, gh)])
        win = _window(model, corners)
        if win is not None:
            img[win] = _draw_goal(model, boxes, gh, d[win], img[win], win, params.static_supersampling,
                                  face_gain, goal)

    img *= gain[..., None]
    return np.clip(np.floor(img + 0.5), 0, 255).astype(np.uint8)


def _window(model: CameraModel, points: NDArray[np.float64], margin_px: int = 3) -> tuple[slice, slice] | None:
    """Image rows and columns holding the projection of ``points`` (n, 3), field frame, m,
    widened by ``margin_px``; None when it misses the image. The points sample a shape densely
    enough that distortion cannot bow its image out of the window."""
    px = model.project(points)
    px = px[np.isfinite(px).all(axis=1)]
    if px.size == 0:
        return None
    j0 = max(0, int(np.floor(px[:, 0].min())) - margin_px)
    j1 = min(model.width, int(np.ceil(px[:, 0].max())) + margin_px)
    i0 = max(0, int(np.floor(px[:, 1].min())) - margin_px)
    i1 = min(model.height, int(np.ceil(px[:, 1].max())) + margin_px)
    if i0 >= i1 or j0 >= j1:
        return None
    return slice(i0, i1), slice(j0, j1)


def _draw_goal(model: CameraModel, boxes: list[tuple[float, float, float, float]], height_m: float,
               d: NDArray[np.float64], img: NDArray[np.float64], win: tuple[slice, slice], s: int,
               face_gain: NDArray[np.float64], goal: NDArray[np.float64]) -> NDArray[np.float64]:
    """One goal's walls over the window ``img`` (rays ``d``): pixels near a wall are
    supersampled s x s, since the walls are only a few pixels thick in the image."""
    img = img.copy()
    hit, _ = _goal_hits(model.center, d, boxes, height_m)
    near = hit.copy()  # dilated by one pixel: edge pixels whose centre misses the wall
    near[1:] |= hit[:-1]
    near[:-1] |= hit[1:]
    near[:, 1:] |= near[:, :-1].copy()
    near[:, :-1] |= near[:, 1:].copy()
    ii, jj = np.nonzero(near)
    if ii.size == 0:
        return img
    offs = (np.arange(s) + 0.5) / s
    sub_u = (win[1].start + jj[:, None, None] + offs[None, None, :]).repeat(s, axis=1)
    sub_v = (win[0].start + ii[:, None, None] + offs[None, :, None]).repeat(s, axis=2)
    sub_d = model.rays(np.stack([sub_u, sub_v], axis=-1))[..., :2]  # (n, s, s, 2)
    sub_hit, sub_face = _goal_hits(model.center, sub_d, boxes, height_m)
    wall = np.where(sub_hit[..., None], face_gain[sub_face][..., None] * goal, img[ii, jj][:, None, None, :])
    img[ii, jj] = wall.mean(axis=(1, 2))
    return img


# --- a lab's camera: cameras.yaml ``preset: realistic`` ------------------------------------------------

_LIGHT_STEP_PX = 8  # the light is smooth: computed on every 8th pixel and interpolated
_CLUTTER_BGR = ((30, 105, 235), (55, 125, 205), (35, 80, 215), (20, 95, 250), (80, 140, 200))  # orange-ish, tan


class Lighting:
    """The lab's light over the field, one for all cameras of a match: ``lamps`` in a grid under the
    ceiling, each a pool of light (a point source's irradiance on the carpet, brightest straight
    below it) whose brightness wanders slowly with its own period and phase, and daylight through a
    window along the +y touch line, wandering with the clouds. Phases from ``seed``."""

    def __init__(self, league: LeagueParams, params: RealisticParams, seed: int) -> None:
        self.params, self.seed = params, seed
        f = Field(league)
        rng = np.random.default_rng([seed, 0x11647])
        nx, ny = params.lamps
        xs = (np.arange(nx) + 0.5) / nx * 2.0 * f.half_length - f.half_length
        ys = (np.arange(ny) + 0.5) / ny * 2.0 * f.half_width - f.half_width
        self.lamps_xy = np.array([(x, y) for x in xs for y in ys], dtype=np.float64).reshape(-1, 2)
        k = len(self.lamps_xy)
        self.periods_s = params.lamp_drift_period_s * rng.uniform(0.7, 1.3, k)
        self.phases = rng.uniform(0.0, 2.0 * np.pi, k)
        self.day_phase = float(rng.uniform(0.0, 2.0 * np.pi))
        self.half_width = f.boundary_half_width
        # the lamps' pools, scaled so that their sum's mean over the field is 1
        g = np.stack(np.meshgrid(np.linspace(-f.half_length, f.half_length, 25),
                                 np.linspace(-f.half_width, f.half_width, 17)), -1).reshape(-1, 2)
        self.scale = 1.0 / max(float(np.mean(self.pools(g).sum(axis=1))), 1e-9)

    def pools(self, ground: NDArray[np.float64]) -> NDArray[np.float64]:
        """Each lamp's irradiance at ground points (..., 2), 1 straight below it: (..., lamps)."""
        h = self.params.lamp_height_m
        d2 = ((ground[..., None, :] - self.lamps_xy) ** 2).sum(axis=-1)
        out: NDArray[np.float64] = h**3 / (d2 + h * h) ** 1.5
        return out

    def weights(self, t: float) -> tuple[NDArray[np.float64], float]:
        """Each lamp's brightness and the daylight's at time ``t`` (s), against their nominal levels."""
        p = self.params
        lamps = p.lamp_level * (1.0 + p.lamp_drift_fraction * np.sin(2.0 * np.pi * t / self.periods_s + self.phases))
        day = p.daylight_level * (1.0 + p.daylight_drift_fraction
                                  * math.sin(2.0 * math.pi * t / p.daylight_drift_period_s + self.day_phase))
        return lamps * self.scale, day

    def daylight(self, ground: NDArray[np.float64]) -> NDArray[np.float64]:
        """The window light's share at ground points (..., 2): 1 at the +y boundary, 0.25 at the -y."""
        out: NDArray[np.float64] = 0.25 + 0.75 * np.clip((ground[..., 1] / self.half_width + 1.0) / 2.0, 0.0, 1.0)
        return out


class CameraLook:
    """What a lab's camera makes of the clean render (``RealisticParams``), deterministic per seed:
    the floor past the field with orange-ish clutter (into the static scene), a cover with one dot
    taped over, the lamps' and daylight's light with cos^4 vignetting, glare on the covers under
    the lamps, auto exposure, desaturation, an RGGB sensor demosaiced, and the camera's
    compression (JPEG or H.264). Geometry (the strong barrel distortion) is the camera model's."""

    def __init__(self, model: CameraModel, league: LeagueParams, params: RealisticParams, lighting: Lighting,
                 rays: NDArray[np.float32], seed: int) -> None:
        self.model, self.league, self.params, self.lighting = model, league, params, lighting
        self.seed = seed
        h, w = model.height, model.width
        s = _LIGHT_STEP_PX
        self.small_ground = model.center[:2] + model.center[2] * rays[::s, ::s].astype(np.float64)
        self.small_pools = lighting.pools(self.small_ground)  # (hs, ws, lamps)
        self.small_day = lighting.daylight(self.small_ground)
        # cos^4 vignetting, as strong at the farthest corner as asked
        r2 = (rays[::s, ::s].astype(np.float64) ** 2).sum(axis=-1)  # tan^2 of the angle off the vertical
        c4 = 1.0 / (1.0 + r2) ** 2
        c4_min = float(c4.min())
        power = math.log(1.0 - params.vignetting_fraction) / math.log(c4_min) if c4_min < 1.0 else 0.0
        self.small_vignette = c4**power
        self.size = (w, h)
        self.exposure: float | None = None
        y = np.array([0.114, 0.587, 0.299], dtype=np.float32)
        sat = np.float32(params.saturation)
        self.desaturate = (sat * np.eye(3, dtype=np.float32) + (1 - sat) * np.outer(np.ones(3, np.float32), y))
        self._h264: H264RoundTrip | None = None
        if params.codec == "h264":
            self._h264 = H264RoundTrip(w, h, params.h264_crf)
        pat, robot = league.pattern, league.robot
        self.top_m = robot.height_m
        # mirror points of the lamps on the robots' tops, seen from this camera
        hc, hl = model.center[2] - self.top_m, params.lamp_height_m - self.top_m
        self.mirror_xy = model.center[:2] + (lighting.lamps_xy - model.center[:2]) * hc / max(hc + hl, 1e-6)
        self.dot_radius_m = pat.id_dot_diameter_m / 2.0
        self.dots = np.array(pat.dot_positions_m, dtype=np.float64).reshape(-1, 2)
        self.robot_radius_m = robot.radius_m

    # the static scene --------------------------------------------------------------------------
    def floor(self, background: NDArray[np.uint8], rays: NDArray[np.float32], gain: NDArray[np.float32],
              field: Field) -> NDArray[np.uint8]:
        """``background`` with the floor past the boundary: wooden planks along x, and ``clutter``
        orange-ish things (boxes and discs, placed by the seed) lying on it."""
        p = self.params
        ground = self.model.center[:2] + self.model.center[2] * rays.astype(np.float64)
        gx, gy = ground[..., 0], ground[..., 1]
        hx, hy = field.boundary_half_length, field.boundary_half_width
        outside = (np.abs(gx) > hx) | (np.abs(gy) > hy)
        if not outside.any():
            return background
        plank = 0.92 + 0.08 * np.sin(gy / 0.15 * np.pi) ** 2 + 0.03 * np.sin(gx * 7.0 + 3.0 * np.sin(gy * 5.0))
        img = np.array(p.floor_bgr, dtype=np.float64) * plank[..., None]
        rng = np.random.default_rng([self.lighting.seed, 0xF1002])  # one floor for all cameras
        reach = p.view_margin_m + 0.5
        placed = 0
        while placed < p.clutter:
            x, y = rng.uniform(-hx - reach, hx + reach), rng.uniform(-hy - reach, hy + reach)
            size = rng.uniform(0.04, 0.25)
            colour = np.array(_CLUTTER_BGR[int(rng.integers(len(_CLUTTER_BGR)))], dtype=np.float64)
            if abs(x) <= hx + size and abs(y) <= hy + size:
                continue  # on the floor, not on the carpet
            placed += 1
            if rng.uniform() < 0.5:  # a disc (a tan ball, a cone seen from above)
                shape = np.hypot(gx - x, gy - y) <= size / 2.0
            else:  # a box, turned
                a = rng.uniform(0.0, np.pi)
                u = (gx - x) * math.cos(a) + (gy - y) * math.sin(a)
                v = -(gx - x) * math.sin(a) + (gy - y) * math.cos(a)
                shape = (np.abs(u) <= size / 2.0) & (np.abs(v) <= size / 3.0)
            img[shape] = colour
        img *= gain[..., None]
        out = background.copy()
        out[outside] = np.clip(np.floor(img[outside] + 0.5), 0, 255).astype(np.uint8)
        return out

    # per frame --------------------------------------------------------------------------------
    def apply(self, image: NDArray[np.uint8], snapshot: Snapshot, gain: NDArray[np.float32],
              cover_bgr: BGR) -> NDArray[np.uint8]:
        """The camera's frame of the clean render ``image`` (not written) at ``snapshot``."""
        p = self.params
        img = image.copy()
        robots = np.asarray(snapshot.robots, dtype=np.float64).reshape(-1, 8)
        self._hide_dot(img, robots, gain, cover_bgr)
        lamps, day = self.lighting.weights(snapshot.t)
        small = self.small_pools @ lamps
        light = (small[..., None] * np.array(p.lamp_bgr) + (day * self.small_day)[..., None] * np.array(p.daylight_bgr))
        light *= self.small_vignette[..., None]
        w, h = self.size
        full = cv2.resize(light.astype(np.float32), (w, h), interpolation=cv2.INTER_LINEAR)
        f = img.astype(np.float32)
        f *= full
        self._glare(f, robots, lamps)
        if self.exposure is None:  # the camera starts settled on its first scene
            self.exposure = p.exposure_target_grey / max(self._luma(f), 1.0)
        f *= np.float32(self.exposure)
        f = np.asarray(cv2.transform(f, self.desaturate), dtype=np.float32)
        out = np.clip(f + 0.5, 0, 255).astype(np.uint8)
        if p.exposure_rate > 0.0:
            self.exposure *= (p.exposure_target_grey / max(self._luma(out), 1.0)) ** p.exposure_rate
        if p.bayer:
            out = _demosaic(out)
        if p.codec == "jpeg":
            ok, buf = cv2.imencode(".jpg", out, [cv2.IMWRITE_JPEG_QUALITY, p.jpeg_quality])
            out = np.asarray(cv2.imdecode(buf, cv2.IMREAD_COLOR), dtype=np.uint8)
        elif self._h264 is not None:
            out = self._h264(out)
        return np.asarray(out, dtype=np.uint8)

    @staticmethod
    def _luma(img: NDArray[Any]) -> float:
        sub = img[::4, ::4].astype(np.float64)
        return float(np.mean(0.114 * sub[..., 0] + 0.587 * sub[..., 1] + 0.299 * sub[..., 2]))

    def _hide_dot(self, img: NDArray[np.uint8], robots: NDArray[np.float64], gain: NDArray[np.float32],
                  cover_bgr: BGR) -> None:
        team, rid, dot = self.params.hidden_dot
        if rid < 0 or not 0 <= dot < len(self.dots):
            return
        for r in robots[(robots[:, 0] == team) & (robots[:, 1] == rid)]:
            c, s = math.cos(r[4]), math.sin(r[4])
            dx, dy = self.dots[dot]
            xy = np.array([r[2] + c * dx - s * dy, r[3] + s * dx + c * dy])
            px = self.model.project_xy(xy, self.top_m)
            if not np.all(np.isfinite(px)) or not self.model.in_image(px[None], margin=0.0)[0]:
                continue
            rad = 1.15 * self.dot_radius_m * self.model.pixels_per_metre((float(xy[0]), float(xy[1])), self.top_m)
            g = float(gain[min(int(px[1]), self.model.height - 1), min(int(px[0]), self.model.width - 1)])
            colour = tuple(int(round(v * g)) for v in cover_bgr)
            sh = 4  # sub-pixel centre: cv2 draws in 1/16 px
            cv2.circle(img, (int(round(px[0] * 2**sh - 0.5 * 2**sh)), int(round(px[1] * 2**sh - 0.5 * 2**sh))),
                       int(round(rad * 2**sh)), colour, -1, cv2.LINE_AA, sh)

    def _glare(self, f: NDArray[np.float32], robots: NDArray[np.float64], lamps: NDArray[np.float64]) -> None:
        """Glare on each cover near a lamp's mirror point: a Gaussian spot on the cover's side
        toward that point, as bright as the lamp and the cover's distance from the point allow."""
        p = self.params
        if p.specular_grey <= 0.0 or not len(robots):
            return
        level = lamps / max(float(lamps.mean()), 1e-9) if lamps.size else lamps
        rad = self.robot_radius_m
        for r in robots:
            for k, m in enumerate(self.mirror_xy):
                d = float(np.hypot(*(m - r[2:4])))
                amp = p.specular_grey * level[k] * math.exp(-0.5 * (max(0.0, d - rad) / p.specular_reach_m) ** 2)
                if amp < 4.0:
                    continue
                spot = r[2:4] + (m - r[2:4]) * min(1.0, 0.55 * rad / max(d, 1e-9))
                px = self.model.project_xy(spot, self.top_m)
                if not np.all(np.isfinite(px)):
                    continue
                sig = p.specular_radius_m * self.model.pixels_per_metre((float(spot[0]), float(spot[1])), self.top_m)
                half = int(3.0 * sig) + 1
                i0, i1 = max(0, int(px[1]) - half), min(f.shape[0], int(px[1]) + half + 1)
                j0, j1 = max(0, int(px[0]) - half), min(f.shape[1], int(px[0]) + half + 1)
                if i0 >= i1 or j0 >= j1:
                    continue
                vv, uu = np.mgrid[i0:i1, j0:j1] + 0.5
                spot_img = amp * np.exp(-0.5 * ((uu - px[0]) ** 2 + (vv - px[1]) ** 2) / (sig * sig))
                f[i0:i1, j0:j1] += spot_img[..., None].astype(np.float32)


def _demosaic(image: NDArray[np.uint8]) -> NDArray[np.uint8]:
    """``image`` as an RGGB sensor sees it (one channel per pixel: R G on even rows, G B on odd)
    and OpenCV's demosaicing makes of it."""
    h, w = image.shape[:2]
    raw = np.empty((h, w), np.uint8)
    raw[0::2, 0::2] = image[0::2, 0::2, 2]
    raw[0::2, 1::2] = image[0::2, 1::2, 1]
    raw[1::2, 0::2] = image[1::2, 0::2, 1]
    raw[1::2, 1::2] = image[1::2, 1::2, 0]
    # (OpenCV names the layout by its second row)
    out = np.asarray(cv2.cvtColor(raw, cv2.COLOR_BayerBG2BGR), dtype=np.uint8)
    return out
