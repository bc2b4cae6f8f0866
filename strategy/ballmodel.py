"""How a kicked ball runs, and who gets to it first: the pass model's two halves.

The ball: the two-phase model the league uses (it slides at ``acc_slide`` after a kick until its
speed falls to ``slide_to_roll_fraction`` of the kick speed, then rolls at ``acc_roll``), one object
(:class:`BallModel`) built from the configured ball (field.yaml ``ball``) and read by every part of
strategy that predicts a ball's run: the kick speed of a pass, the arrival time at a receiving
point, the path a robot meets the ball on.

The robots: the earliest time a robot with its speed, acceleration and braking limits reaches a
point (:func:`reach_times`, arriving at any speed: an opponent only has to be in the ball's way),
and from that the earliest time it gets to a ball running along its predicted path
(:func:`interception_times`); the latency: a command acts that much later. Field frame, metres, seconds.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from cmdragons.control.acceleration import Limits
from cmdragons.geometry import RobotShape

__all__ = ["BallModel", "interception_times", "reach_times", "robot_limits"]

Array = NDArray[np.float64]


@dataclass(frozen=True)
class BallModel:
    """The two-phase ball (decelerations m/s², the share of the kick speed at which rolling starts)."""

    acc_slide_m_s2: float
    acc_roll_m_s2: float
    slide_to_roll_fraction: float

    def _switch(self, v0: float) -> tuple[float, float, float]:
        """(time, distance, speed) where a ball kicked at ``v0`` starts rolling."""
        v_roll = self.slide_to_roll_fraction * v0
        a = max(self.acc_slide_m_s2, 1e-9)
        return (v0 - v_roll) / a, (v0**2 - v_roll**2) / (2.0 * a), v_roll

    def speed_after(self, v0: float, distance: float) -> float:
        """Ball speed after running ``distance`` from a kick at ``v0`` (0 if it stops before)."""
        _, slide, v_roll = self._switch(v0)
        if distance <= slide:
            return math.sqrt(max(v0**2 - 2.0 * self.acc_slide_m_s2 * distance, 0.0))
        return math.sqrt(max(v_roll**2 - 2.0 * self.acc_roll_m_s2 * (distance - slide), 0.0))

    def stop_distance(self, v0: float) -> float:
        """How far a ball kicked at ``v0`` runs before it stops."""
        _, slide, v_roll = self._switch(v0)
        return slide + v_roll**2 / (2.0 * max(self.acc_roll_m_s2, 1e-9))

    def time_to(self, v0: float, distance: float) -> float:
        """When a ball kicked at ``v0`` has run ``distance`` (inf when it stops before)."""
        t_sw, slide, v_roll = self._switch(v0)
        if distance <= slide:
            a = self.acc_slide_m_s2
            disc = v0**2 - 2.0 * a * distance
            return (v0 - math.sqrt(max(disc, 0.0))) / a if a > 0 else distance / max(v0, 1e-9)
        rest = distance - slide
        a = self.acc_roll_m_s2
        disc = v_roll**2 - 2.0 * a * rest
        if disc < 0.0:
            return math.inf
        return t_sw + ((v_roll - math.sqrt(disc)) / a if a > 0 else rest / max(v_roll, 1e-9))

    def travel(self, v0: float, t: Array) -> tuple[Array, Array]:
        """Distance run and speed at times ``t`` (s, any shape) after a kick at ``v0``."""
        t = np.asarray(t, dtype=np.float64)
        t_sw, slide, v_roll = self._switch(v0)
        sliding = t <= t_sw
        ts = np.minimum(t, t_sw)
        d = v0 * ts - 0.5 * self.acc_slide_m_s2 * ts**2
        v = v0 - self.acc_slide_m_s2 * ts
        t_stop = v_roll / max(self.acc_roll_m_s2, 1e-9)
        tr = np.clip(t - t_sw, 0.0, t_stop)
        d_roll = slide + v_roll * tr - 0.5 * self.acc_roll_m_s2 * tr**2
        v_rolling = np.maximum(v_roll - self.acc_roll_m_s2 * tr, 0.0)
        return np.where(sliding, d, d_roll), np.where(sliding, v, v_rolling)

    def kick_speed(self, distance: float, arrival_m_s: float, lo_m_s: float, hi_m_s: float) -> float:
        """The kick speed (between ``lo_m_s`` and ``hi_m_s``) whose ball still runs ``arrival_m_s``
        after ``distance``: the speed after a distance grows with the kick speed, solved in closed form
        backwards through the two phases."""
        if arrival_m_s <= 0.0:
            v0 = math.sqrt(2.0 * self.acc_roll_m_s2 * distance) / max(self.slide_to_roll_fraction, 1e-9)
        else:
            v0 = self._kick_for(distance, arrival_m_s)
        return min(max(v0, lo_m_s), hi_m_s)

    def _kick_for(self, distance: float, arrival: float) -> float:
        # still sliding at the point: v0² = arrival² + 2 a_s d, when the switch lies beyond it
        v0 = math.sqrt(arrival**2 + 2.0 * self.acc_slide_m_s2 * distance)
        if arrival >= self.slide_to_roll_fraction * v0:
            return v0
        # rolling at the point: v_roll² = arrival² + 2 a_r (d - slide(v0)), with slide(v0) = v0² (1 - f²) / (2 a_s)
        f, a_s, a_r = self.slide_to_roll_fraction, max(self.acc_slide_m_s2, 1e-9), self.acc_roll_m_s2
        den = f**2 + a_r * (1.0 - f**2) / a_s
        return math.sqrt(max((arrival**2 + 2.0 * a_r * distance) / max(den, 1e-12), 0.0))


def robot_limits(robot: RobotShape) -> Limits:
    """The league robot's driving limits, as motion control names them."""
    return Limits(robot.max_speed_m_s, robot.max_accel_m_s2, robot.max_brake_m_s2, robot.max_omega_rad_s,
                  robot.max_alpha_rad_s2)


def reach_times(xy: Array, vel: Array, points: Array, reach_m: float, limits: Limits, latency_s: float) -> Array:
    """Earliest time (s) each robot (rows of ``xy`` and ``vel``, (M, 2)) comes within ``reach_m`` of
    each point (``points`` (K, 2)): straight at it, first braking what of its velocity runs away from
    it, then speeding up to its limit, arriving at any speed; the velocity across the way is left
    as it is (an opponent's best case). Shape (M, K)."""
    rel = points[None, :, :] - xy[:, None, :]
    dist = np.hypot(rel[..., 0], rel[..., 1])
    u = rel / np.maximum(dist, 1e-9)[..., None]
    v0 = np.einsum("mkj,mj->mk", u, vel)
    d = np.maximum(dist - reach_m, 0.0)
    a, b, vmax = limits.accel, limits.brake, limits.vmax
    # running away: brake to rest first (it drifts on meanwhile)
    away = v0 < 0.0
    t_brake = np.where(away, -v0 / b, 0.0)
    d = d + np.where(away, v0**2 / (2.0 * b), 0.0)
    v = np.clip(np.where(away, 0.0, v0), 0.0, vmax)
    d_acc = (vmax**2 - v**2) / (2.0 * a)
    t_short = (-v + np.sqrt(v**2 + 2.0 * a * d)) / a
    t_long = (vmax - v) / a + (d - d_acc) / vmax
    out: Array = latency_s + t_brake + np.where(d <= d_acc, t_short, t_long)
    return out


def interception_times(xy: Array, vel: Array, ball: tuple[float, float], ball_vel: tuple[float, float],
                       model: BallModel, limits: Limits, latency_s: float, reach_m: float, horizon_s: float,
                       step_s: float) -> tuple[Array, Array]:
    """The earliest time (s) each robot ((M, 2) rows) can be at the ball running from ``ball`` with
    ``ball_vel`` (the model's run, sampled every ``step_s`` up to ``horizon_s``; a ball that stops
    before is met where it lies, its stop time or the robot's arrival there, whichever is later), and
    the point (M, 2) where. inf (and the ball's last point) for a robot that cannot."""
    speed = math.hypot(*ball_vel)
    n = max(int(horizon_s / step_s), 1)
    ts: Array = np.arange(n + 1, dtype=np.float64) * step_s
    if speed > 1e-6:
        ux, uy = ball_vel[0] / speed, ball_vel[1] / speed
        dist, _ = model.travel(speed, ts)
    else:
        ux = uy = 0.0
        dist = np.zeros_like(ts)
    pts = np.stack([ball[0] + ux * dist, ball[1] + uy * dist], axis=1)
    if len(xy) == 0:
        return np.zeros(0), np.zeros((0, 2))
    reach = reach_times(np.asarray(xy, dtype=np.float64), np.asarray(vel, dtype=np.float64), pts, reach_m, limits,
                        latency_s)
    ok = reach <= ts[None, :]
    first = np.argmax(ok, axis=1)
    found = ok[np.arange(len(xy)), first]
    t_out = np.where(found, ts[first], np.maximum(reach[:, -1], ts[-1]))
    stopped = speed <= 1e-6 or dist[-1] - dist[-2] < 1e-9
    t_out = np.where(found | stopped, t_out, np.inf)
    where = np.where(found[:, None], pts[first], pts[-1][None, :])
    return t_out, where
