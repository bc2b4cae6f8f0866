"""Pass and shot evaluation (Bruce 2006, appendix B.5), vectorised over many candidate points.

For a candidate receiving point p the pass evaluation looks at two arcs: arc a from the ball to p
and arc b from p to the opponent goal. Each arc has a radius (its length) and an open angle (the
free angular width around its centre line, between the nearest obstacles on either side); the
third input is the angle between the two centre lines, the deflection a one-touch shot at p must
make (a kicker can turn the ball by well under a right angle, so a bigger turn means trapping the
ball first). Each input goes through a simple saturating function, and the factors are combined as a
weighted product (weights as exponents), so any hopeless factor makes the whole pass hopeless.

Shot evaluation: the widest free part of the goal mouth seen from a point, with the obstacles'
angular shadows taken out. Between two shadows the shot aims at the gap's centre, so a blocker must
cover half the gap; a gap that ends at a post is aimed at that end (a post does not move), so the
blocker must cover all of it: such a gap counts double.

Field frame, metres, radians. "Obstacles" are circles (robots) of one radius; the ball's radius
should be added to it by the caller when the question is whether the ball passes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, cast

import numpy as np
from numpy.typing import NDArray

from cmdragons.config import Validated, setting
from cmdragons.geometry import Field, wrap_angle
from strategy._kernels import free_runs, goal_samples_free

__all__ = [
    "PassEvaluation",
    "PassParams",
    "best_shot",
    "clearest_direction",
    "lane_open_angle",
    "one_touch_turn",
    "open_goal_angle",
    "pass_values",
]

Array = NDArray[np.float64]


@dataclass(frozen=True)
class PassParams(Validated):
    grid_step_m: float = setting(0.25, lo=0.02, hi=2.0)  # candidate receiving points are sampled this far apart
    field_margin_m: float = setting(0.3, lo=0.0, hi=2.0)  # candidates stay this far inside the lines
    defense_margin_m: float = setting(0.2, lo=0.0, hi=2.0)  # ... and this far off the defense areas
    min_pass_m: float = setting(0.6, lo=0.0, hi=10.0)  # shorter passes are not worth the risk
    max_pass_m: float = setting(6.0, lo=0.1, hi=20.0)  # longer ones are too slow or inaccurate ...
    pass_length_fade: float = setting(0.2, lo=0.01, hi=5.0)  # ... their value fades to 0 over this share of max_pass_m
    lane_open_angle_rad: float = setting(0.35, lo=0.01, hi=3.0)  # a pass lane this wide is fully open
    shot_open_angle_rad: float = setting(0.2, lo=0.01, hi=3.0)  # a goal gap this wide is fully open
    shot_distance_scale_m: float = setting(3.0, lo=0.1, hi=20.0)  # shots decay as exp(-distance / scale)
    # one-touch: the ball turns from "back toward the passer" to "toward the goal"; a kicker can do
    # that only while the turn is well under a right angle (the ball must meet the front face)
    max_turn_rad: float = setting(1.3, lo=0.1, hi=3.14)
    trap_factor: float = setting(0.5, lo=0.0, hi=1.0)  # value kept when the receiver must trap, not one-touch
    goal_samples: int = setting(24, lo=3, hi=256)  # angular samples across the goal mouth
    post_margin_m: float = setting(0.1, lo=0.0, hi=1.0)  # shots aim at most this near a post (ball centre)
    weight_length: float = setting(1.0, lo=0.0, hi=10.0)  # exponents of the factors
    weight_lane: float = setting(2.0, lo=0.0, hi=10.0)
    weight_shot_open: float = setting(1.0, lo=0.0, hi=10.0)
    weight_shot_distance: float = setting(1.0, lo=0.0, hi=10.0)
    weight_redirect: float = setting(0.5, lo=0.0, hi=10.0)


def _wrap(a: Array) -> Array:
    """:func:`cmdragons.geometry.wrap_angle` elementwise (its arithmetic holds for arrays as it is)."""
    return cast(Array, wrap_angle(cast(Any, a)))


def lane_open_angle(origin: Array, targets: Array, obstacles: Array, radius: float, cap: float) -> Array:
    """Free angular width around each line origin -> target (shape (N,)), counting obstacles
    nearer to the origin than the target; each side is capped at ``cap`` (0 where blocked)."""
    targets = np.atleast_2d(targets)
    n = len(targets)
    if len(obstacles) == 0:
        return np.full(n, 2.0 * cap)
    to_t = targets - origin
    length = np.hypot(to_t[:, 0], to_t[:, 1])
    heading = np.arctan2(to_t[:, 1], to_t[:, 0])
    rel = obstacles - origin
    d = np.hypot(rel[:, 0], rel[:, 1])  # (M,)
    phi = _wrap(np.arctan2(rel[:, 1], rel[:, 0])[None, :] - heading[:, None])  # (N, M)
    alpha = np.arcsin(np.clip(radius / np.maximum(d, 1e-9), 0.0, 1.0))[None, :]
    relevant = (d[None, :] < length[:, None] + radius) & (np.abs(phi) < np.pi / 2 + alpha)
    inside = d[None, :] <= radius  # an obstacle on the origin blocks nothing (it is the passer)
    relevant &= ~inside
    blocked = relevant & (np.abs(phi) <= alpha)
    left = np.where(relevant & (phi - alpha > 0), phi - alpha, cap).min(axis=1)
    right = np.where(relevant & (phi + alpha < 0), -(phi + alpha), cap).min(axis=1)
    out: Array = np.minimum(left, cap) + np.minimum(right, cap)
    out[blocked.any(axis=1)] = 0.0
    return out


def goal_samples_free_reference(points: Array, ys: Array, gx: float, obstacles: Array,
                                radius: float) -> NDArray[np.bool_]:
    """The plain-numpy reference of :func:`strategy._kernels.goal_samples_free`."""
    dx = gx - points[:, 0:1]
    dy = ys[None, :] - points[:, 1:2]
    theta, dist = np.arctan2(dy, dx), np.hypot(dx, dy)
    rel = obstacles[None, :, :] - points[:, None, :]  # (N, M, 2)
    d = np.hypot(rel[..., 0], rel[..., 1])  # (N, M)
    phi = np.arctan2(rel[..., 1], rel[..., 0])
    alpha = np.arcsin(np.clip(radius / np.maximum(d, 1e-9), 0.0, 1.0))
    # an obstacle shadows a goal sample when it is nearer than the sample and within its angle
    near = (d[:, None, :] < dist[:, :, None]) & (d[:, None, :] > radius)
    hit = np.abs(_wrap(theta[:, :, None] - phi[:, None, :])) <= alpha[:, None, :]
    return np.asarray(~(near & hit).any(axis=2))


def open_goal_angle(points: Array, field: Field, goal_sign: float, obstacles: Array, radius: float, samples: int,
                    post_margin_m: float) -> tuple[Array, Array]:
    """Open angle of the goal at x = goal_sign * half_length from each point (N,), and the y on the
    goal line to aim at (aim points reach up to ``post_margin_m`` from the posts). A free run of the
    mouth between two shadows (or the whole mouth) is aimed at its centre and counts its width; a
    run from a post to a shadow is aimed at the post end and counts twice its width (the angle from
    the aim to the nearest shadow, doubled, in both cases). The best of the widest run and the two
    post runs is taken. Obstacles behind the goal line do not block."""
    points = np.atleast_2d(points)
    gx = goal_sign * field.half_length
    gw = max(field.goal_half_width - post_margin_m, 0.0)
    ys = np.linspace(-gw, gw, samples)  # (K,)
    dx = gx - points[:, 0:1]  # (N, 1)
    dy = ys[None, :] - points[:, 1:2]  # (N, K)
    theta = np.arctan2(dy, dx)  # (N, K)
    free: NDArray[np.bool_] = np.ones(theta.shape, dtype=bool)
    if len(obstacles):
        free = goal_samples_free(np.ascontiguousarray(points, dtype=np.float64), ys, float(gx),
                                 np.ascontiguousarray(obstacles, dtype=np.float64), float(radius))
    # the longest run of free samples per point, and the free runs from each post
    n, k = free.shape
    best_len, best_end, lead, trail = free_runs(free)
    start = best_end - best_len + 1
    rows = np.arange(n)
    width = np.where(best_len > 1, np.abs(theta[rows, best_end] - theta[rows, np.maximum(start, 0)]), 0.0)
    aim = np.where(best_len > 0, 0.5 * (ys[np.maximum(start, 0)] + ys[best_end]), 0.0)
    # a lone free sample is a gap of at most one sample spacing: count it as half a spacing
    spacing = np.abs(np.diff(theta, axis=1)).mean(axis=1) if k > 1 else np.zeros(n)
    width = np.where(best_len == 1, 0.5 * spacing, width)
    # a gap with one end at a post, aimed at that end: the blocker has all of it to cover
    for run_len, end, post_y in ((lead, 0, ys[0]), (trail, k - 1, ys[-1])):
        inner = np.clip(end + (run_len - 1) * (1 if end == 0 else -1), 0, k - 1)
        post_width = np.where(run_len > 1, 2.0 * np.abs(theta[rows, inner] - theta[:, end]), spacing)
        better = (run_len > 0) & (run_len < k) & (post_width > width)
        width = np.where(better, post_width, width)
        aim = np.where(better, post_y, aim)
    return width, aim


def best_shot(ball: Array, field: Field, goal_sign: float, obstacles: Array, radius: float,
              params: PassParams) -> tuple[float, tuple[float, float], float]:
    """(open angle rad, aim point on the goal line, value 0..1) of a shot from ``ball``."""
    width, aim = open_goal_angle(ball[None, :], field, goal_sign, obstacles, radius, params.goal_samples,
                                 params.post_margin_m)
    target = (goal_sign * field.half_length, float(aim[0]))
    d = math.hypot(target[0] - ball[0], target[1] - ball[1])
    value = min(1.0, float(width[0]) / params.shot_open_angle_rad) * math.exp(-d / params.shot_distance_scale_m)
    return float(width[0]), target, value


@dataclass(frozen=True)
class PassEvaluation:
    points: Array  # (N, 2) candidate receiving points
    values: Array  # (N,) 0..1
    aims: Array  # (N, 2) where a shot from each point would aim

    def best(self) -> tuple[Array, float]:
        i = int(np.argmax(self.values))
        return self.points[i], float(self.values[i])


def one_touch_turn(ball: Array, points: Array, aims: Array) -> Array:
    """At each receiving point, the angle between the way back to the passer and the way to the aim:
    0 sends the ball straight back, pi lets it run on (no kicker can do that)."""
    back = ball - points
    out = np.atleast_2d(aims) - points
    turn: Array = np.abs(_wrap(np.arctan2(out[:, 1], out[:, 0]) - np.arctan2(back[:, 1], back[:, 0])))
    return turn


def candidate_grid(field: Field, params: PassParams) -> Array:
    """Receiving points on a regular grid inside the field, off both defense areas."""
    m = params.field_margin_m
    xs = np.arange(-field.half_length + m, field.half_length - m + 1e-9, params.grid_step_m)
    ys = np.arange(-field.half_width + m, field.half_width - m + 1e-9, params.grid_step_m)
    pts = np.stack(np.meshgrid(xs, ys), axis=-1).reshape(-1, 2)
    keep = [field.in_defense_area(x, y, params.defense_margin_m) == 0 for x, y in pts]
    out: Array = pts[np.array(keep, dtype=bool)]
    return out


def pass_values(ball: Array, points: Array, field: Field, goal_sign: float, obstacles: Array, radius: float,
                params: PassParams) -> PassEvaluation:
    """The pass evaluation function at each candidate point (B.5): arcs a (ball -> p) and
    b (p -> goal), their lengths and open angles, and the deflection between them."""
    points = np.atleast_2d(points)
    to_p = points - ball
    len_a = np.hypot(to_p[:, 0], to_p[:, 1])
    open_a = lane_open_angle(ball, points, obstacles, radius, params.lane_open_angle_rad)
    open_b, aim_y = open_goal_angle(points, field, goal_sign, obstacles, radius, params.goal_samples,
                                    params.post_margin_m)
    aims = np.stack([np.full(len(points), goal_sign * field.half_length), aim_y], axis=1)
    to_goal = aims - points
    len_b = np.hypot(to_goal[:, 0], to_goal[:, 1])
    turn = one_touch_turn(ball, points, aims)

    lo, hi = params.min_pass_m, params.max_pass_m
    fade = params.pass_length_fade
    f_len = np.clip(len_a / max(lo, 1e-9), 0.0, 1.0) * np.clip(((1.0 + fade) * hi - len_a) / (fade * hi), 0.0, 1.0)
    f_lane = np.clip(open_a / (2.0 * params.lane_open_angle_rad), 0.0, 1.0)
    f_open = np.clip(open_b / params.shot_open_angle_rad, 0.0, 1.0)
    f_dist = np.exp(-len_b / params.shot_distance_scale_m)
    f_redirect = np.where(turn <= params.max_turn_rad, 1.0, params.trap_factor)
    values = (f_len**params.weight_length * f_lane**params.weight_lane * f_open**params.weight_shot_open
              * f_dist**params.weight_shot_distance * f_redirect**params.weight_redirect)
    return PassEvaluation(points, values, aims)


def clearest_direction(ball: Array, toward: float, obstacles: Array, radius: float, reach_m: float, spread_rad: float,
                       samples: int, cap_rad: float, turn_cost: float) -> tuple[float, float]:
    """Among ``samples`` directions within ``spread_rad`` of ``toward``, the one whose lane of length
    ``reach_m`` from the ball is most open (each side capped at ``cap_rad``), less ``turn_cost``
    per radian off ``toward``. Returns (angle, open angle)."""
    angles = toward + np.linspace(-spread_rad, spread_rad, samples)
    targets = ball + reach_m * np.stack([np.cos(angles), np.sin(angles)], axis=1)
    open_ = lane_open_angle(ball, targets, obstacles, radius, cap_rad)
    score = open_ - turn_cost * np.abs(angles - toward)
    k = int(np.argmax(score))
    return float(angles[k]), float(open_[k])
