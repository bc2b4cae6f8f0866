"""numba kernels of the overhead camera renderer (:mod:`sim.render`), with plain-numpy references.

Frames and units. Field frame in metres (origin at the centre spot, z up); robot frame x forward
(toward the flat front), y to the left. Pixels (u, v) from the image's top-left corner, pixel
(i, j) = (row, column) has its centre at (j + 0.5, i + 0.5). A pixel's ray is stored as (dx, dy)
per metre of descent: the field point it sees at height z is ``C_xy + (C_z - z) * (dx, dy)``
with C the optical centre. ``foot`` is a pixel's footprint in metres per metre of descent, so a
pixel covers ``(C_z - z) * foot`` metres on the plane at height z.

Anti-aliasing: a shape's coverage of a pixel is ``clip(0.5 - d / footprint, 0, 1)`` with d the
signed distance (metres, negative inside) of the pixel's field point to the shape: a box filter
one pixel wide, so edges and dot centroids are sub-pixel accurate without supersampling.

Packed inputs (to keep the per-frame call short): ``cam`` (``CAM_*`` layout), ``shape``
(``SHAPE_*``), ``palette`` rows (``PAL_*``, BGR float32, before lighting).

Each kernel has a typed wrapper (the public names) and a numpy reference (``*_reference``) that
the tests compare it with.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numpy.typing import NDArray

from cmdragons.camera import CameraModel

__all__ = [
    "CAM_SIZE",
    "PAL_SIZE",
    "SHAPE_SIZE",
    "ObjectPlan",
    "add_noise_reference",
    "noise_pool",
    "camera_vector",
    "plan_objects",
    "plan_objects_reference",
    "project_points",
    "render_frame",
    "render_frame_reference",
    "sensor_noise_reference",
]

# --- packed layouts -----------------------------------------------------------------------------
CAM_CENTER = 0  # 3: optical centre, field frame, m
CAM_ROT = 3  # 9: R_cam_to_field, row-major (columns are the camera axes in the field frame)
CAM_FOCAL = 12  # px
CAM_PP = 13  # 2: principal point, px
CAM_K1 = 15
CAM_K2 = 16
CAM_WIDTH = 17  # px
CAM_HEIGHT = 18  # px
CAM_SIZE = 19

SHAPE_ROBOT_RADIUS = 0  # m
SHAPE_ROBOT_HEIGHT = 1  # m
SHAPE_ROBOT_FRONT = 2  # m, centre to the flat front
SHAPE_BALL_RADIUS = 3  # m
SHAPE_CENTER_DOT_RADIUS = 4  # m
SHAPE_ID_DOT_RADIUS = 5  # m
SHAPE_BALL_AMBIENT = 6  # fraction of the ball colour on a surface facing sideways
SHAPE_SIZE = 7

PAL_COVER = 0
PAL_SIDE = 1
PAL_BALL = 2
PAL_BLUE = 3  # team 0; team 1 (yellow) is the next row
PAL_YELLOW = 4
PAL_PINK = 5
PAL_GREEN = 6
PAL_SIZE = 7

N_OUTLINE = 16  # points on a robot top's rim checked for "the whole top is in the image"
BBOX_MARGIN_PX = 2  # slack around projected bounding boxes: coverage ramps, distortion bowing


def camera_vector(model: CameraModel) -> NDArray[np.float64]:
    """The camera's projection parameters packed in the ``CAM_*`` layout."""
    cam = np.zeros(CAM_SIZE)
    cam[CAM_CENTER : CAM_CENTER + 3] = model.center
    cam[CAM_ROT : CAM_ROT + 9] = model.R_cam_to_field.ravel()
    cam[CAM_FOCAL] = model.f
    cam[CAM_PP], cam[CAM_PP + 1] = model.cx, model.cy
    cam[CAM_K1], cam[CAM_K2] = model.k1, model.k2
    cam[CAM_WIDTH], cam[CAM_HEIGHT] = model.width, model.height
    return cam


# =================================================================================================
# numba kernels
# =================================================================================================


@njit(cache=True)
def _project(cam: NDArray[np.float64], x: float, y: float, z: float) -> tuple[float, float]:
    """Field point (m) -> pixel (u, v), the same model as ``CameraModel.project``; NaN behind."""
    c, r = CAM_CENTER, CAM_ROT  # r + 3 * row + column of R_cam_to_field
    px, py, pz = x - cam[c], y - cam[c + 1], z - cam[c + 2]
    xc = px * cam[r] + py * cam[r + 3] + pz * cam[r + 6]
    yc = px * cam[r + 1] + py * cam[r + 4] + pz * cam[r + 7]
    zc = px * cam[r + 2] + py * cam[r + 5] + pz * cam[r + 8]
    if zc <= 1e-9:
        return math.nan, math.nan
    xn, yn = xc / zc, yc / zc
    r2 = xn * xn + yn * yn
    k = 1.0 + cam[CAM_K1] * r2 + cam[CAM_K2] * r2 * r2
    return cam[CAM_FOCAL] * xn * k + cam[CAM_PP], cam[CAM_FOCAL] * yn * k + cam[CAM_PP + 1]


@njit(cache=True)
def _project_points_kernel(cam: NDArray[np.float64], pts: NDArray[np.float64], out: NDArray[np.float64]) -> None:
    for k in range(pts.shape[0]):
        out[k, 0], out[k, 1] = _project(cam, pts[k, 0], pts[k, 1], pts[k, 2])


def project_points(cam: NDArray[np.float64], pts: NDArray[np.float64]) -> NDArray[np.float64]:
    """Field points (n, 3) in metres -> pixels (n, 2); reference: ``CameraModel.project``."""
    pts = np.ascontiguousarray(pts, dtype=np.float64).reshape(-1, 3)
    out = np.empty((pts.shape[0], 2))
    _project_points_kernel(cam, pts, out)
    return out


@njit(cache=True)
def _bbox(cam: NDArray[np.float64], x: float, y: float, ext: float, z0: float, z1: float,
          out: NDArray[np.int32]) -> None:
    """Pixel rows/columns [i0, i1) x [j0, j1) holding the projection of the axis-aligned box
    ``[x-ext, x+ext] x [y-ext, y+ext] x [z0, z1]``, clipped to the image; (0, 0, 0, 0) if empty."""
    umin, umax, vmin, vmax = math.inf, -math.inf, math.inf, -math.inf
    for cx in (x - ext, x + ext):
        for cy in (y - ext, y + ext):
            for cz in (z0, z1):
                u, v = _project(cam, cx, cy, cz)
                if math.isnan(u):
                    out[:] = 0
                    return
                umin, umax = min(umin, u), max(umax, u)
                vmin, vmax = min(vmin, v), max(vmax, v)
    w, h = cam[CAM_WIDTH], cam[CAM_HEIGHT]
    i0 = max(0.0, math.floor(vmin) - BBOX_MARGIN_PX)
    i1 = min(h, math.ceil(vmax) + BBOX_MARGIN_PX)
    j0 = max(0.0, math.floor(umin) - BBOX_MARGIN_PX)
    j1 = min(w, math.ceil(umax) + BBOX_MARGIN_PX)
    if i0 >= i1 or j0 >= j1:
        out[:] = 0
    else:
        out[0], out[1], out[2], out[3] = int(i0), int(i1), int(j0), int(j1)


@njit(cache=True)
def _sample_count(motion_px: float, blur_step_px: float, max_samples: int) -> int:
    """Time samples across the exposure: sharp below one step, else at most a step apart."""
    if motion_px <= blur_step_px:
        return 1
    return min(max_samples, int(math.ceil(motion_px / blur_step_px)) + 1)


@njit(cache=True)
def _plan_objects_kernel(
    robots: NDArray[np.float64], ball: NDArray[np.float64], cam: NDArray[np.float64],
    shape: NDArray[np.float64], pink: NDArray[np.bool_], dots: NDArray[np.float64],
    palette: NDArray[np.float32], exposure_s: float, max_samples: int, blur_step_px: float,
    rob_samples: NDArray[np.float64], rob_k: NDArray[np.int64], rob_bbox: NDArray[np.int32],
    rob_colors: NDArray[np.float32], rob_truth: NDArray[np.float64], ball_samples: NDArray[np.float64],
    ball_bbox: NDArray[np.int32], ball_truth: NDArray[np.float64],
) -> int:
    r, h = shape[SHAPE_ROBOT_RADIUS], shape[SHAPE_ROBOT_HEIGHT]
    f, cz = cam[CAM_FOCAL], cam[CAM_CENTER + 2]
    w_img, h_img = cam[CAM_WIDTH], cam[CAM_HEIGHT]
    n_ids = pink.shape[0]
    for k in range(robots.shape[0]):
        team, rid = int(robots[k, 0]), int(robots[k, 1])
        x, y, th = robots[k, 2], robots[k, 3], robots[k, 4]
        vx, vy, om = robots[k, 5], robots[k, 6], robots[k, 7]
        speed = math.sqrt(vx * vx + vy * vy)
        # the image scale at the top; a rotating top's rim moves |omega| r
        motion_px = (speed + abs(om) * r) * exposure_s * f / (cz - h)
        n = _sample_count(motion_px, blur_step_px, max_samples)
        rob_k[k] = n
        for m in range(n):
            # exposure centred on the snapshot's instant, so the blurred centroid is the truth
            tm = ((m + 0.5) / n - 0.5) * exposure_s
            a = th + om * tm
            rob_samples[k, m, 0] = x + vx * tm
            rob_samples[k, m, 1] = y + vy * tm
            rob_samples[k, m, 2] = math.cos(a)
            rob_samples[k, m, 3] = math.sin(a)
        _bbox(cam, x, y, r + 0.5 * speed * exposure_s, 0.0, h, rob_bbox[k])
        for c in range(3):
            rob_colors[k, 0, c] = palette[PAL_BLUE + min(max(team, 0), 1), c]
            for d in range(dots.shape[0]):
                rob_colors[k, 1 + d, c] = palette[PAL_PINK if pink[rid % n_ids, d] else PAL_GREEN, c]
        u, v = _project(cam, x, y, h)
        rob_truth[k, 0], rob_truth[k, 1] = u, v
        inside = not math.isnan(u)
        for q in range(N_OUTLINE):
            a = 2.0 * math.pi * q / N_OUTLINE
            pu, pv = _project(cam, x + r * math.cos(a), y + r * math.sin(a), h)
            if not (0.0 <= pu <= w_img and 0.0 <= pv <= h_img):  # NaN fails too
                inside = False
        rob_truth[k, 2] = 1.0 if inside else 0.0

    rb = shape[SHAPE_BALL_RADIUS]
    bx, by, bz, bvx, bvy, bvz = ball[0], ball[1], ball[2], ball[3], ball[4], ball[5]
    speed = math.sqrt(bvx * bvx + bvy * bvy + bvz * bvz)
    n = _sample_count(speed * exposure_s * f / (cz - bz), blur_step_px, max_samples)
    for m in range(n):
        tm = ((m + 0.5) / n - 0.5) * exposure_s
        ball_samples[m, 0] = bx + bvx * tm
        ball_samples[m, 1] = by + bvy * tm
        ball_samples[m, 2] = bz + bvz * tm
    ext = rb + 0.5 * speed * exposure_s
    _bbox(cam, bx, by, ext, bz - ext, bz + ext, ball_bbox)
    u, v = _project(cam, bx, by, bz)
    ball_truth[0], ball_truth[1] = u, v
    ball_truth[2] = 1.0 if (0.0 <= u < w_img and 0.0 <= v < h_img) else 0.0
    return n


class ObjectPlan:
    """One frame's drawing plan (blur samples, boxes, colours) and projected truth per object.

    Robot arrays have ``capacity`` rows, reused across frames; the first ``n`` are in use.
    """

    def __init__(self, capacity: int, max_samples: int, n_dots: int = 4) -> None:
        self.max_samples = max_samples
        self.rob_samples = np.zeros((capacity, max_samples, 4))  # x m, y m, cos, sin per sample
        self.rob_k = np.zeros(capacity, dtype=np.int64)  # samples in use
        self.rob_bbox = np.zeros((capacity, 4), dtype=np.int32)  # i0, i1, j0, j1 (px, half-open)
        self.rob_colors = np.zeros((capacity, 1 + n_dots, 3), dtype=np.float32)  # centre, id dots; BGR
        self.rob_truth = np.zeros((capacity, 3))  # u, v px of the top centre; 1 if the top is inside
        self.ball_samples = np.zeros((max_samples, 3))  # x, y, z m
        self.ball_k = 1
        self.ball_bbox = np.zeros(4, dtype=np.int32)
        self.ball_truth = np.zeros(3)  # u, v px of the centre; 1 if inside the image
        self.n = 0

    @property
    def capacity(self) -> int:
        return int(self.rob_k.shape[0])


def plan_objects(
    plan: ObjectPlan, robots: NDArray[np.float64], ball: NDArray[np.float64], cam: NDArray[np.float64],
    shape: NDArray[np.float64], pink: NDArray[np.bool_], dots: NDArray[np.float64],
    palette: NDArray[np.float32], exposure_s: float, blur_step_px: float,
) -> None:
    """Fill ``plan`` for the snapshot's robots (n, 8: team, id, x, y, theta, vx, vy, omega) and
    ball (6: x, y, z, vx, vy, vz), field frame, SI units. The plan must hold n robots.

    Motion blur: an object whose image moves more than ``blur_step_px`` during the exposure
    (``exposure_s``, centred on the snapshot's instant) gets samples at most that far apart.
    """
    n = robots.shape[0]
    if n > plan.capacity or plan.rob_colors.shape[1] != 1 + dots.shape[0]:
        raise ValueError(f"the plan holds {plan.capacity} robots of {plan.rob_colors.shape[1] - 1} id dots")
    plan.n = n
    plan.ball_k = _plan_objects_kernel(
        robots, ball, cam, shape, pink, dots, palette, exposure_s, plan.max_samples, blur_step_px,
        plan.rob_samples[:n], plan.rob_k[:n], plan.rob_bbox[:n], plan.rob_colors[:n], plan.rob_truth[:n],
        plan.ball_samples, plan.ball_bbox, plan.ball_truth,
    )


# --- per-pixel shading ---------------------------------------------------------------------------


@njit(cache=True, fastmath=True, inline="always")
def _shape_sd(x: float, y: float, r: float, front: float) -> float:
    """Signed distance (m) of robot-frame point (x, y) to the top outline: a disc cut flat at the
    front (max of the two distances: exact inside and along the edges, low only near the corners)."""
    return max(math.sqrt(x * x + y * y) - r, x - front)


@njit(cache=True, fastmath=True, inline="always")
def _segment_sd(ax: float, ay: float, bx: float, by: float, r: float, front: float) -> tuple[float, float]:
    """Smallest :func:`_shape_sd` along the robot-frame segment A -> B and the parameter t in [0, 1]
    where it occurs. The function is convex along the segment, so its minimum is at an end, at the
    point nearest the centre (disc part) or where the disc and the flat front distances cross."""
    best, bt = _shape_sd(ax, ay, r, front), 0.0
    v = _shape_sd(bx, by, r, front)
    if v < best:
        best, bt = v, 1.0
    dx, dy = bx - ax, by - ay
    dd = dx * dx + dy * dy
    if dd < 1e-18:
        return best, bt
    ad = ax * dx + ay * dy
    t = min(max(-ad / dd, 0.0), 1.0)
    v = _shape_sd(ax + t * dx, ay + t * dy, r, front)
    if v < best:
        best, bt = v, t
    # |A + tD| - r = A_x + t D_x - front  =>  |A + tD|^2 = (c0 + c1 t)^2; spurious roots are harmless
    c0, c1 = r - front + ax, dx
    qa, qb, qc = dd - c1 * c1, 2.0 * (ad - c0 * c1), ax * ax + ay * ay - c0 * c0
    if abs(qa) > 1e-15:
        disc = qb * qb - 4.0 * qa * qc
        if disc >= 0.0:
            sq = math.sqrt(disc)
            for t in ((-qb - sq) / (2.0 * qa), (-qb + sq) / (2.0 * qa)):
                if 0.0 < t < 1.0:
                    v = _shape_sd(ax + t * dx, ay + t * dy, r, front)
                    if v < best:
                        best, bt = v, t
    elif abs(qb) > 1e-15:
        t = -qc / qb
        if 0.0 < t < 1.0:
            v = _shape_sd(ax + t * dx, ay + t * dy, r, front)
            if v < best:
                best, bt = v, t
    return best, bt


@njit(cache=True, fastmath=True, inline="always")
def _coverage(sd: float, pix: float) -> float:
    return min(max(0.5 - sd / pix, 0.0), 1.0)


@njit(cache=True, fastmath=True, inline="always")
def _body_coverage(samples: NDArray[np.float64], k: int, n: int, shape: NDArray[np.float64],
                   ax_w: float, ay_w: float, bx_w: float, by_w: float, z_a: float, z_b: float,
                   cam_z: float, foot: float) -> float:
    """Coverage of robot k's body (averaged over its n blur samples) along the part of a pixel's
    ray between heights z_a > z_b, whose field points are A_w and B_w: the ray passes through the
    body's vertical prism there when the segment A -> B meets the top outline."""
    r, front = shape[SHAPE_ROBOT_RADIUS], shape[SHAPE_ROBOT_FRONT]
    half_a = 0.5 * (cam_z - z_a) * foot
    # the outline lies inside the disc: a segment farther than half the largest footprint along
    # the ray from the disc cannot touch it (the common case in a bounding box: no square root)
    reach = r + 0.5 * cam_z * foot
    inner = r - half_a
    acc = 0.0
    for m in range(n):
        px, py, co, si = samples[k, m, 0], samples[k, m, 1], samples[k, m, 2], samples[k, m, 3]
        ex, ey = ax_w - px, ay_w - py
        ax, ay = co * ex + si * ey, co * ey - si * ex
        ex, ey = bx_w - px, by_w - py
        bx, by = co * ex + si * ey, co * ey - si * ex
        dx, dy = bx - ax, by - ay
        dd = dx * dx + dy * dy
        t = min(max(-(ax * dx + ay * dy) / dd, 0.0), 1.0) if dd > 1e-18 else 0.0
        qx, qy = ax + t * dx, ay + t * dy
        if qx * qx + qy * qy >= reach * reach:
            continue
        if inner > 0.0 and ax * ax + ay * ay <= inner * inner and ax - front <= -half_a:
            acc += 1.0  # enters through the top, away from its rim: inside
            continue
        sd, t = _segment_sd(ax, ay, bx, by, r, front)
        acc += _coverage(sd, (cam_z - (z_a + t * (z_b - z_a))) * foot)
    return acc / n


@njit(cache=True, fastmath=True, inline="always")
def _top_colour(samples: NDArray[np.float64], k: int, n: int, shape: NDArray[np.float64], dots: NDArray[np.float64],
                colors: NDArray[np.float32], cover: NDArray[np.float32], qx_w: float, qy_w: float,
                pix: float, acc: NDArray[np.float64]) -> float:
    """Premultiplied colour of robot k's top (cover with its pattern) at the field point Q_w on
    the plane of the top, averaged over the blur samples, into ``acc``; returns the coverage.
    Squared distances reject what a shape's coverage ramp cannot reach before any square root."""
    r, front = shape[SHAPE_ROBOT_RADIUS], shape[SHAPE_ROBOT_FRONT]
    rc, ri = shape[SHAPE_CENTER_DOT_RADIUS], shape[SHAPE_ID_DOT_RADIUS]
    half = 0.5 * pix
    reach2, reach_c2, reach_i2 = (r + half) ** 2, (rc + half) ** 2, (ri + half) ** 2
    acc[0] = acc[1] = acc[2] = 0.0
    a_sum = 0.0
    for m in range(n):
        ex, ey = qx_w - samples[k, m, 0], qy_w - samples[k, m, 1]
        co, si = samples[k, m, 2], samples[k, m, 3]
        qx, qy = co * ex + si * ey, co * ey - si * ex
        r2 = qx * qx + qy * qy
        if r2 >= reach2 or qx - front >= half:
            continue
        rq = math.sqrt(r2)
        a = _coverage(max(rq - r, qx - front), pix)
        c0, c1, c2 = cover[0], cover[1], cover[2]
        if r2 < reach_c2:
            ad = _coverage(rq - rc, pix)
            c0 += ad * (colors[k, 0, 0] - c0)
            c1 += ad * (colors[k, 0, 1] - c1)
            c2 += ad * (colors[k, 0, 2] - c2)
        for d in range(dots.shape[0]):
            ux, uy = qx - dots[d, 0], qy - dots[d, 1]
            u2 = ux * ux + uy * uy
            if u2 < reach_i2:
                ad = _coverage(math.sqrt(u2) - ri, pix)
                c0 += ad * (colors[k, 1 + d, 0] - c0)
                c1 += ad * (colors[k, 1 + d, 1] - c1)
                c2 += ad * (colors[k, 1 + d, 2] - c2)
        acc[0] += a * c0
        acc[1] += a * c1
        acc[2] += a * c2
        a_sum += a
    acc[0] /= n
    acc[1] /= n
    acc[2] /= n
    return a_sum / n


@njit(cache=True, fastmath=True, inline="always")
def _ball_sample(cam: NDArray[np.float64], rdx: float, rdy: float, foot: float, bx: float, by: float,
                 bz: float, rb: float, ambient: float) -> tuple[float, float, float]:
    """Ray (dx, dy, -1) from the optical centre against the ball sphere at B: (coverage, shade,
    height of the visible surface point). Off the silhouette the nearest point of the ray stands
    in for the hit, so the anti-aliased rim still gets a height and a shade."""
    wx, wy, wz = bx - cam[CAM_CENTER], by - cam[CAM_CENTER + 1], bz - cam[CAM_CENTER + 2]
    dd = rdx * rdx + rdy * rdy + 1.0
    tc = (wx * rdx + wy * rdy - wz) / dd  # ray parameter = descent (m) at the nearest point
    dist2 = max(wx * wx + wy * wy + wz * wz - tc * tc * dd, 0.0)
    dist = math.sqrt(dist2)
    # footprint across the ray: the plane footprint over |d|^(1/2) (|d|: slant per metre of descent)
    pix = foot * tc / math.sqrt(math.sqrt(dd))
    a = _coverage(dist - rb, pix)
    if a <= 0.0:
        return 0.0, 0.0, 0.0
    t = tc
    if dist2 < rb * rb:
        t = tc - math.sqrt((rb * rb - dist2) / dd)
    nx, ny, nz = rdx * t - wx, rdy * t - wy, -t - wz
    nlen = math.sqrt(nx * nx + ny * ny + nz * nz)
    up = nz / nlen if nlen > 1e-12 else 1.0
    # light from straight above: the rim, facing sideways, darkens to the ambient fraction
    shade = ambient + (1.0 - ambient) * max(up, 0.0)
    return a, shade, cam[CAM_CENTER + 2] - t


# --- sensor noise: fresh every frame ------------------------------------------------------------
# A pool of Gaussian noise values (one frame's worth plus a row, drawn once per camera) is read
# each frame at a fresh offset per row, and every value's sign is flipped by a fresh bit: row i of
# the frame with key K starts at r % (len(pool) - W3) with r = splitmix64(K + (i + 1) * GOLDEN), and
# value q's sign is bit q % 64 of splitmix64(r + (q // 64 + 1) * GOLDEN). A pixel's noise in one
# frame is thus independent of its noise in the next (and of its neighbours'), as a real sensor's,
# at the cost of a copy: no per-value generator, which would double the time of a frame. No
# state is carried between rows or frames: rows run on any thread in any order, same bytes.
_GOLDEN = np.uint64(0x9E3779B97F4A7C15)
_MIX1 = np.uint64(0xBF58476D1CE4E5B9)
_MIX2 = np.uint64(0x94D049BB133111EB)


def noise_pool(rng: np.random.Generator, frame_size: int, row_size: int, sigma_grey: float) -> NDArray[np.int8]:
    """``frame_size + row_size`` values of N(0, sigma) sensor noise rounded to grey levels and
    saturated to -127..127 (int8); a single zero when ``sigma_grey`` is 0 (no noise)."""
    if sigma_grey <= 0.0:
        return np.zeros(1, dtype=np.int8)
    pool = np.empty(frame_size + row_size, dtype=np.int8)
    chunk = 1 << 20  # bounded temporary memory
    for k in range(0, pool.shape[0], chunk):
        n = min(chunk, pool.shape[0] - k)
        noise = rng.standard_normal(n, dtype=np.float32) * np.float32(sigma_grey)
        pool[k : k + n] = np.clip(np.rint(noise), -127, 127).astype(np.int8)
    return pool


@njit(cache=True, inline="always")
def _splitmix64(z: np.uint64) -> np.uint64:
    z = (z ^ (z >> np.uint64(30))) * _MIX1
    z = (z ^ (z >> np.uint64(27))) * _MIX2
    return z ^ (z >> np.uint64(31))


@njit(cache=True, inline="always")
def _noise_row(nz: NDArray[np.int8], pool: NDArray[np.int8], key: np.uint64, row: int) -> None:
    """Row ``row``'s sensor noise of the frame with ``key`` into ``nz`` (length 3 * image width)."""
    w3 = nz.shape[0]
    r = _splitmix64(key + np.uint64(row + 1) * _GOLDEN)
    off = np.int64(r % np.uint64(pool.shape[0] - w3))
    src = pool[off : off + w3]
    for blk in range((w3 + 63) // 64):
        z = _splitmix64(r + np.uint64(blk + 1) * _GOLDEN)
        base = 64 * blk
        for t in range(min(64, w3 - base)):
            # branch-free, in int32: the loop vectorises (8x faster than a conditional negation)
            flip = np.int32(z >> np.uint64(t)) & np.int32(1)
            v = np.int32(src[base + t])
            nz[base + t] = v - 2 * flip * v


@njit(cache=True, fastmath=True, inline="always")
def _write_span(o: NDArray[np.uint8], scratch: NDArray[np.float32], nz: NDArray[np.int8], noise_on: bool,
                q0: int, q1: int) -> None:
    for q in range(q0, q1):
        v = int(scratch[q] + 0.5)  # colours are never negative: truncation rounds
        if noise_on:
            v += nz[q]
        o[q] = min(max(v, 0), 255)


@njit(cache=True, fastmath=True)
def _render_frame_kernel(
    out2: NDArray[np.uint8], bg2: NDArray[np.uint8], pool: NDArray[np.int8], noise_key: np.uint64, noise_on: bool,
    rays: NDArray[np.float32], foot: NDArray[np.float32], gain: NDArray[np.float32], cam: NDArray[np.float64],
    shape: NDArray[np.float64], dots: NDArray[np.float64], palette: NDArray[np.float32],
    rob_samples: NDArray[np.float64], rob_k: NDArray[np.int64], rob_bbox: NDArray[np.int32],
    rob_colors: NDArray[np.float32], ball_samples: NDArray[np.float64], ball_k: int,
    ball_bbox: NDArray[np.int32], row_ball: NDArray[np.float64], n_chunks: int,
) -> None:
    h_img, w3 = out2.shape
    n_rob = rob_k.shape[0]
    cx, cy, cz = cam[CAM_CENTER], cam[CAM_CENTER + 1], cam[CAM_CENTER + 2]
    h, rb, ambient = shape[SHAPE_ROBOT_HEIGHT], shape[SHAPE_BALL_RADIUS], shape[SHAPE_BALL_AMBIENT]
    side, cover, ball_col = palette[PAL_SIDE], palette[PAL_COVER], palette[PAL_BALL]
    # rows are dealt out round-robin in chunks. The kernel is serial: the parallel version cost the
    # first run ~12 s of compiling, and with the 2 cores shared it was the slower one (1.8 against
    # 1.2 ms median a camera frame, 2026-12-01, load 3.4); every row is written by one chunk only,
    # so the image is the same either way.
    for chunk in range(n_chunks):
        scratch = np.empty(w3, dtype=np.float32)  # the row's clean (noise-free) colours
        nz = np.empty(w3, dtype=np.int8)  # the row's sensor noise
        active = np.empty(n_rob, dtype=np.int64)
        acc = np.empty(3)
        for i in range(chunk, h_img, n_chunks):
            o, b = out2[i], bg2[i]
            if noise_on:
                _noise_row(nz, pool, noise_key, i)
                for q in range(w3):
                    o[q] = min(max(np.int32(b[q]) + np.int32(nz[q]), 0), 255)
            else:
                for q in range(w3):  # not o[:] = b: numba's slice assignment compiles for seconds
                    o[q] = b[q]
            row_ball[i, 0] = row_ball[i, 1] = 0.0
            n_act = 0
            for k in range(n_rob):
                if rob_bbox[k, 0] <= i < rob_bbox[k, 1]:
                    active[n_act] = k
                    n_act += 1
            ball_on = ball_bbox[0] <= i < ball_bbox[1]
            if n_act == 0 and not ball_on:
                continue
            for a in range(n_act):
                k = active[a]
                for q in range(3 * rob_bbox[k, 2], 3 * rob_bbox[k, 3]):
                    scratch[q] = b[q]
            if ball_on:
                for q in range(3 * ball_bbox[2], 3 * ball_bbox[3]):
                    scratch[q] = b[q]

            # every robot's sides before any robot's top: a top is never hidden by a side
            for a in range(n_act):
                k = active[a]
                for j in range(rob_bbox[k, 2], rob_bbox[k, 3]):
                    rdx, rdy, fp = rays[i, j, 0], rays[i, j, 1], foot[i, j]
                    al = _body_coverage(rob_samples, k, rob_k[k], shape, cx + (cz - h) * rdx, cy + (cz - h) * rdy,
                                        cx + cz * rdx, cy + cz * rdy, h, 0.0, cz, fp)
                    if al > 0.0:
                        g = gain[i, j]
                        for c in range(3):
                            s = scratch[3 * j + c]
                            scratch[3 * j + c] = s + al * (side[c] * g - s)
            for a in range(n_act):
                k = active[a]
                for j in range(rob_bbox[k, 2], rob_bbox[k, 3]):
                    rdx, rdy = rays[i, j, 0], rays[i, j, 1]
                    al = _top_colour(rob_samples, k, rob_k[k], shape, dots, rob_colors, cover,
                                     cx + (cz - h) * rdx, cy + (cz - h) * rdy, (cz - h) * foot[i, j], acc)
                    if al > 0.0:
                        g = gain[i, j]
                        for c in range(3):
                            s = scratch[3 * j + c]
                            scratch[3 * j + c] = s * (1.0 - al) + acc[c] * g

            if ball_on:
                vis_sum, sil_sum = 0.0, 0.0
                for j in range(ball_bbox[2], ball_bbox[3]):
                    rdx, rdy, fp = rays[i, j, 0], rays[i, j, 1], foot[i, j]
                    a_sum, c_sum, sil = 0.0, 0.0, 0.0
                    for m in range(ball_k):
                        al, shade, z_hit = _ball_sample(cam, rdx, rdy, fp, ball_samples[m, 0], ball_samples[m, 1],
                                                        ball_samples[m, 2], rb, ambient)
                        if al <= 0.0:
                            continue
                        sil += al
                        vis = 1.0
                        if z_hit < h:
                            # hidden where the ray passes through a robot above the ball's surface
                            zb = max(z_hit, 0.0)
                            for a in range(n_act):
                                k = active[a]
                                if rob_bbox[k, 2] <= j < rob_bbox[k, 3]:
                                    occ = _body_coverage(rob_samples, k, rob_k[k], shape, cx + (cz - h) * rdx,
                                                         cy + (cz - h) * rdy, cx + (cz - zb) * rdx,
                                                         cy + (cz - zb) * rdy, h, zb, cz, fp)
                                    vis *= 1.0 - occ
                        a_sum += al * vis
                        c_sum += al * vis * shade
                    if sil <= 0.0:
                        continue
                    a_sum /= ball_k
                    c_sum /= ball_k
                    vis_sum += a_sum
                    sil_sum += sil / ball_k
                    g = gain[i, j]
                    for c in range(3):
                        s = scratch[3 * j + c]
                        scratch[3 * j + c] = s * (1.0 - a_sum) + c_sum * ball_col[c] * g
                row_ball[i, 0], row_ball[i, 1] = vis_sum, sil_sum

            for a in range(n_act):
                k = active[a]
                _write_span(o, scratch, nz, noise_on, 3 * rob_bbox[k, 2], 3 * rob_bbox[k, 3])
            if ball_on:
                _write_span(o, scratch, nz, noise_on, 3 * ball_bbox[2], 3 * ball_bbox[3])


def render_frame(
    out: NDArray[np.uint8], background: NDArray[np.uint8], pool: NDArray[np.int8], noise_key: int | None,
    rays: NDArray[np.float32], foot: NDArray[np.float32], gain: NDArray[np.float32], cam: NDArray[np.float64],
    shape: NDArray[np.float64], dots: NDArray[np.float64], palette: NDArray[np.float32], plan: ObjectPlan,
    row_ball: NDArray[np.float64], n_chunks: int = 2,
) -> tuple[float, float]:
    """Compose one frame into ``out`` (H, W, 3 BGR uint8): the static ``background``, the planned
    robots (sides, then tops) and ball, lighting ``gain`` on object colours, then sensor noise
    drawn from ``pool`` (:func:`noise_pool`) by the frame's ``noise_key`` (0 .. 2**64 - 1) and
    added with saturation (``noise_key`` None: no noise).

    ``row_ball`` (H, 2) is scratch. Returns the ball's (visible, silhouette) coverage in pixels.
    """
    h_img, w_img = out.shape[:2]
    noise_on = noise_key is not None
    if noise_on and pool.shape[0] <= w_img * 3:
        raise ValueError(f"the noise pool ({pool.shape[0]} values) must be longer than a row ({w_img * 3})")
    n = plan.n
    _render_frame_kernel(
        out.reshape(h_img, w_img * 3), background.reshape(h_img, w_img * 3), pool,
        np.uint64(noise_key if noise_key is not None else 0), noise_on,
        rays, foot, gain, cam, shape, dots, palette, plan.rob_samples[:n], plan.rob_k[:n], plan.rob_bbox[:n],
        plan.rob_colors[:n], plan.ball_samples, plan.ball_k, plan.ball_bbox, row_ball, n_chunks,
    )
    return _ball_rows_sum(row_ball, int(plan.ball_bbox[0]), int(plan.ball_bbox[1]))


@njit(cache=True)
def _ball_rows_sum(row_ball: NDArray[np.float64], i0: int, i1: int) -> tuple[float, float]:
    # in a fixed order, so the visible fraction does not depend on the thread count
    vis, sil = 0.0, 0.0
    for i in range(i0, i1):
        vis += row_ball[i, 0]
        sil += row_ball[i, 1]
    return vis, sil


# =================================================================================================
# plain-numpy references (for the tests; same inputs, same maths, vectorised, unhurried)
# =================================================================================================


def sensor_noise_reference(pool: NDArray[np.int8], key: int, shape: tuple[int, ...]) -> NDArray[np.int8]:
    """The sensor noise of the frame with ``key`` for an image of ``shape`` (H, W, 3), all rows at once."""
    h, w3 = shape[0], int(np.prod(shape[1:]))
    q = np.arange(w3)

    def mix(z: NDArray[np.uint64]) -> NDArray[np.uint64]:
        z = (z ^ (z >> np.uint64(30))) * _MIX1
        z = (z ^ (z >> np.uint64(27))) * _MIX2
        out: NDArray[np.uint64] = z ^ (z >> np.uint64(31))
        return out

    with np.errstate(over="ignore"):  # uint64 arithmetic wraps, as in the kernel
        r = mix(np.uint64(key) + (np.arange(h, dtype=np.uint64) + np.uint64(1)) * _GOLDEN)
        off = (r % np.uint64(pool.shape[0] - w3)).astype(np.int64)
        words = mix(r[:, None] + (q // 64 + 1).astype(np.uint64)[None, :] * _GOLDEN)
    flip = ((words >> (q % 64).astype(np.uint64)[None, :]) & np.uint64(1)).astype(bool)
    values = pool[off[:, None] + q[None, :]]
    noise: NDArray[np.int8] = np.where(flip, -values, values).astype(np.int8)
    return noise.reshape(shape)


def add_noise_reference(background: NDArray[np.uint8], pool: NDArray[np.int8], key: int) -> NDArray[np.uint8]:
    """The background plus the sensor noise of the frame with ``key``, saturated to 0..255."""
    noise = sensor_noise_reference(pool, key, background.shape)
    out: NDArray[np.uint8] = np.clip(background.astype(np.int16) + noise, 0, 255).astype(np.uint8)
    return out


def plan_objects_reference(
    model: CameraModel, robots: NDArray[np.float64], ball: NDArray[np.float64], shape: NDArray[np.float64],
    pink: NDArray[np.bool_], palette: NDArray[np.float32], exposure_s: float, max_samples: int,
    blur_step_px: float,
) -> ObjectPlan:
    """:func:`plan_objects` computed with ``CameraModel.project``, robot by robot."""
    r, h, rb = shape[SHAPE_ROBOT_RADIUS], shape[SHAPE_ROBOT_HEIGHT], shape[SHAPE_BALL_RADIUS]

    def count(motion_px: float) -> int:
        if motion_px <= blur_step_px:
            return 1
        return int(min(max_samples, math.ceil(motion_px / blur_step_px) + 1))

    def bbox(x: float, y: float, ext: float, z0: float, z1: float) -> NDArray[np.int32]:
        c = np.array([[x + sx * ext, y + sy * ext, z] for sx in (-1, 1) for sy in (-1, 1) for z in (z0, z1)])
        px = model.project(c)
        if np.isnan(px).any():
            return np.zeros(4, dtype=np.int32)
        i0 = max(0, math.floor(px[:, 1].min()) - BBOX_MARGIN_PX)
        i1 = min(model.height, math.ceil(px[:, 1].max()) + BBOX_MARGIN_PX)
        j0 = max(0, math.floor(px[:, 0].min()) - BBOX_MARGIN_PX)
        j1 = min(model.width, math.ceil(px[:, 0].max()) + BBOX_MARGIN_PX)
        if i0 >= i1 or j0 >= j1:
            return np.zeros(4, dtype=np.int32)
        return np.array([i0, i1, j0, j1], dtype=np.int32)

    plan = ObjectPlan(robots.shape[0], max_samples, pink.shape[1])
    for k, row in enumerate(robots):
        team, rid, x, y, th, vx, vy, om = row
        speed = math.hypot(vx, vy)
        n = count((speed + abs(om) * r) * exposure_s * model.f / (model.center[2] - h))
        tm = ((np.arange(n) + 0.5) / n - 0.5) * exposure_s
        plan.rob_k[k] = n
        plan.rob_samples[k, :n] = np.stack([x + vx * tm, y + vy * tm, np.cos(th + om * tm), np.sin(th + om * tm)], 1)
        plan.rob_bbox[k] = bbox(x, y, r + 0.5 * speed * exposure_s, 0.0, h)
        ids = [PAL_PINK if p else PAL_GREEN for p in pink[int(rid) % pink.shape[0]]]
        plan.rob_colors[k] = palette[[PAL_BLUE + int(team), *ids]]
        ang = 2.0 * np.pi * np.arange(N_OUTLINE) / N_OUTLINE
        rim = model.project_xy(np.stack([x + r * np.cos(ang), y + r * np.sin(ang)], 1), h)
        uv = model.project_xy(np.array([x, y]), h)
        plan.rob_truth[k] = (uv[0], uv[1], float(model.in_image(rim).all()))
    bx, by, bz, bvx, bvy, bvz = ball
    speed = math.sqrt(bvx * bvx + bvy * bvy + bvz * bvz)
    n = count(speed * exposure_s * model.f / (model.center[2] - bz))
    tm = ((np.arange(n) + 0.5) / n - 0.5) * exposure_s
    ext = rb + 0.5 * speed * exposure_s
    uv = model.project(np.array([bx, by, bz]))
    inside = 0.0 <= uv[0] < model.width and 0.0 <= uv[1] < model.height
    plan.ball_k = n
    plan.ball_samples[:n] = np.stack([bx + bvx * tm, by + bvy * tm, bz + bvz * tm], 1)
    plan.ball_bbox[:] = bbox(bx, by, ext, bz - ext, bz + ext)
    plan.ball_truth[:] = (uv[0], uv[1], float(inside))
    plan.n = robots.shape[0]
    return plan


def _shape_sd_np(x: NDArray[np.float64], y: NDArray[np.float64], r: float, front: float) -> NDArray[np.float64]:
    return np.maximum(np.hypot(x, y) - r, x - front)


def _segment_sd_np(ax: NDArray[np.float64], ay: NDArray[np.float64], bx: NDArray[np.float64],
                   by: NDArray[np.float64], r: float, front: float,
                   ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Vectorised :func:`_segment_sd` (the same candidate points of t)."""
    dx, dy = bx - ax, by - ay
    dd = dx * dx + dy * dy
    safe = np.where(dd < 1e-18, 1.0, dd)
    cands = [np.zeros_like(ax), np.ones_like(ax), np.clip(-(ax * dx + ay * dy) / safe, 0.0, 1.0)]
    c0, c1 = r - front + ax, dx
    qa, qb, qc = dd - c1 * c1, 2.0 * (ax * dx + ay * dy - c0 * c1), ax * ax + ay * ay - c0 * c0
    disc = qb * qb - 4.0 * qa * qc
    ok = (np.abs(qa) > 1e-15) & (disc >= 0.0) & (dd >= 1e-18)
    qa_s = np.where(ok, qa, 1.0)
    sq = np.sqrt(np.where(ok, disc, 0.0))
    for root in ((-qb - sq) / (2.0 * qa_s), (-qb + sq) / (2.0 * qa_s)):
        cands.append(np.where(ok & (root > 0.0) & (root < 1.0), root, 0.0))
    ts = np.stack(cands)
    sds = _shape_sd_np(ax + ts * dx, ay + ts * dy, r, front)
    best = np.argmin(sds, axis=0)
    return np.take_along_axis(sds, best[None], 0)[0], np.take_along_axis(ts, best[None], 0)[0]


def _body_coverage_np(samples: NDArray[np.float64], shape: NDArray[np.float64], a_w: NDArray[np.float64],
                      b_w: NDArray[np.float64], z_a: float, z_b: NDArray[np.float64] | float, cam_z: float,
                      foot: NDArray[np.float64]) -> NDArray[np.float64]:
    r, front = shape[SHAPE_ROBOT_RADIUS], shape[SHAPE_ROBOT_FRONT]
    acc = np.zeros(foot.shape)
    for px, py, co, si in samples:
        ex, ey = a_w[..., 0] - px, a_w[..., 1] - py
        ax, ay = co * ex + si * ey, co * ey - si * ex
        ex, ey = b_w[..., 0] - px, b_w[..., 1] - py
        bx, by = co * ex + si * ey, co * ey - si * ex
        sd, t = _segment_sd_np(ax, ay, bx, by, r, front)
        cov = np.clip(0.5 - sd / ((cam_z - (z_a + t * (z_b - z_a))) * foot), 0.0, 1.0)
        # a ray that enters through the top, away from its rim, is inside
        acc += np.where(_shape_sd_np(ax, ay, r, front) <= -0.5 * (cam_z - z_a) * foot, 1.0, cov)
    return acc / len(samples)


def render_frame_reference(
    background: NDArray[np.uint8], pool: NDArray[np.int8], noise_key: int | None, rays: NDArray[np.float32],
    foot: NDArray[np.float32], gain: NDArray[np.float32], cam: NDArray[np.float64], shape: NDArray[np.float64],
    dots: NDArray[np.float64], palette: NDArray[np.float32], plan: ObjectPlan,
) -> tuple[NDArray[np.uint8], float, float]:
    """:func:`render_frame` object by object over whole boxes: (image, ball visible, silhouette)."""
    cx, cy, cz = cam[:3]
    r, h, front = shape[SHAPE_ROBOT_RADIUS], shape[SHAPE_ROBOT_HEIGHT], shape[SHAPE_ROBOT_FRONT]
    rc, ri, rb = shape[SHAPE_CENTER_DOT_RADIUS], shape[SHAPE_ID_DOT_RADIUS], shape[SHAPE_BALL_RADIUS]
    clean = background.astype(np.float32)
    rob_bbox = plan.rob_bbox[: plan.n]
    boxes = [tuple(b) for b in rob_bbox] + [tuple(plan.ball_bbox)]

    def region(box: tuple[int, ...]) -> tuple[slice, slice]:
        return slice(box[0], box[1]), slice(box[2], box[3])

    def plane_points(sl: tuple[slice, slice], z: float | NDArray[np.float64]) -> NDArray[np.float64]:
        d = rays[sl].astype(np.float64)
        depth = cz - np.asarray(z)
        return np.stack([cx + depth * d[..., 0], cy + depth * d[..., 1]], -1)

    for k, box in enumerate(rob_bbox):
        sl = region(tuple(box))
        samples = plan.rob_samples[k, : plan.rob_k[k]]
        al = _body_coverage_np(samples, shape, plane_points(sl, h), plane_points(sl, 0.0), h, 0.0, cz,
                               foot[sl].astype(np.float64))[..., None]
        clean[sl] = clean[sl] + al * (palette[PAL_SIDE] * gain[sl][..., None] - clean[sl])
    for k, box in enumerate(rob_bbox):
        sl = region(tuple(box))
        q_w = plane_points(sl, h)
        pix = (cz - h) * foot[sl].astype(np.float64)
        samples = plan.rob_samples[k, : plan.rob_k[k]]
        acc, a_sum = np.zeros(pix.shape + (3,)), np.zeros(pix.shape)
        for px, py, co, si in samples:
            ex, ey = q_w[..., 0] - px, q_w[..., 1] - py
            qx, qy = co * ex + si * ey, co * ey - si * ex
            a = np.clip(0.5 - _shape_sd_np(qx, qy, r, front) / pix, 0.0, 1.0)
            col = np.broadcast_to(palette[PAL_COVER].astype(np.float64), pix.shape + (3,)).copy()
            centres = [(0.0, 0.0, rc)] + [(dx, dy, ri) for dx, dy in dots]
            for e, (ux, uy, rad) in enumerate(centres):
                ad = np.clip(0.5 - (np.hypot(qx - ux, qy - uy) - rad) / pix, 0.0, 1.0)[..., None]
                col += ad * (plan.rob_colors[k, e] - col)
            acc += a[..., None] * col
            a_sum += a
        n = len(samples)
        clean[sl] = clean[sl] * (1.0 - a_sum[..., None] / n) + acc / n * gain[sl][..., None]

    sl = region(tuple(plan.ball_bbox))
    d = rays[sl].astype(np.float64)
    fp = foot[sl].astype(np.float64)
    dd = d[..., 0] ** 2 + d[..., 1] ** 2 + 1.0
    a_tot, c_tot, sil_tot = np.zeros(fp.shape), np.zeros(fp.shape), np.zeros(fp.shape)
    for bx, by, bz in plan.ball_samples[: plan.ball_k]:
        wv = np.array([bx - cx, by - cy, bz - cz])
        tc = (wv[0] * d[..., 0] + wv[1] * d[..., 1] - wv[2]) / dd
        dist2 = np.maximum(wv @ wv - tc * tc * dd, 0.0)
        a = np.clip(0.5 - (np.sqrt(dist2) - rb) / (fp * tc / dd**0.25), 0.0, 1.0)
        t = np.where(dist2 < rb * rb, tc - np.sqrt(np.maximum(rb * rb - dist2, 0.0) / dd), tc)
        nrm = np.stack([d[..., 0] * t - wv[0], d[..., 1] * t - wv[1], -t - wv[2]], -1)
        up = nrm[..., 2] / np.maximum(np.linalg.norm(nrm, axis=-1), 1e-12)
        amb = shape[SHAPE_BALL_AMBIENT]
        shade = amb + (1.0 - amb) * np.maximum(up, 0.0)
        z_hit = cz - t
        zb = np.maximum(z_hit, 0.0)
        vis = np.ones(fp.shape)
        for k, box in enumerate(rob_bbox):
            i0, i1, j0, j1 = box
            b_i0, b_i1, b_j0, b_j1 = plan.ball_bbox
            inside = np.zeros(fp.shape, dtype=bool)
            inside[max(i0 - b_i0, 0) : max(i1 - b_i0, 0), max(j0 - b_j0, 0) : max(j1 - b_j0, 0)] = True
            samples = plan.rob_samples[k, : plan.rob_k[k]]
            occ = _body_coverage_np(samples, shape, plane_points(sl, h), plane_points(sl, zb), h, zb, cz, fp)
            vis *= np.where(inside & (z_hit < h), 1.0 - occ, 1.0)
        a_tot += a * vis
        c_tot += a * vis * shade
        sil_tot += a
    n_b = plan.ball_k
    a_tot, c_tot, sil_tot = a_tot / n_b, c_tot / n_b, sil_tot / n_b
    clean[sl] = clean[sl] * (1.0 - a_tot[..., None]) + (c_tot * gain[sl])[..., None] * palette[PAL_BALL]

    out = background.copy() if noise_key is None else add_noise_reference(background, pool, noise_key)
    noisy = np.floor(clean + 0.5).astype(np.int32)
    if noise_key is not None:
        noisy += sensor_noise_reference(pool, noise_key, background.shape)
    for b_box in boxes:
        sl = region(b_box)
        out[sl] = np.clip(noisy[sl], 0, 255)
    return out, float(a_tot.sum()), float(sil_tot.sum())
