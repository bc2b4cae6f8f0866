"""Dynamics Safety Search (DSS, Bruce 2006 ch. 5): cooperative safety for a team of robots.

Field frame, metres, seconds. Each robot's command is modelled as one control period of constant
acceleration followed by braking at the maximum deceleration until it rests (§5.1, §5.3); a command
is safe when that braking trajectory keeps clear of every other own robot's current trajectory, of
every opponent (whose future motion is bounded by a disc that grows as it could accelerate, at its
current velocity) and of the static obstacles. All robots start on their stop trajectories, which
the previous frame made safe (§5.4); in turn, each keeps its command when it is safe, or searches
random and heuristic samples of its acceleration set A(v) for the safe one closest to it, with the
stop as the fallback that is always accepted. Margins come from configs/safety.yaml.

Two allowances for what the model does not know: the distance kept between two own robots grows
over their braking trajectories by their velocity error (a robot whose speed is misjudged by dv
brakes dv t away from its model), and it widens to ``pushed_margin_m`` while an opponent is near
enough to push one of them into the other.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from cmdragons.config import Validated, setting
from cmdragons.control.motion import MotionParams
from cmdragons.planning.world import CollisionWorld
from cmdragons.safety import _kernels as K
from cmdragons.safety.base import ArraySafety, SafetyResult, StaticObstacles

__all__ = ["DSSParams", "DynamicsSafetySearch", "braking_path", "heuristic_table"]

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class DSSParams(Validated):
    """configs/safety.yaml ``dss``: margins and the search (Bruce 2006 §5.3, §5.5)."""

    own_margin_m: float = setting(0.03, lo=0.0, hi=1.0)  # kept between two own robots' bodies
    # how far an own robot's velocity estimate may be off (m/s): the distance kept between two own
    # robots grows by twice this per second of their braking trajectories
    velocity_error_m_s: float = setting(0.1, lo=0.0, hi=5.0)
    # kept between two own robots instead of own_margin_m while an opponent is within push_range_m
    # of either: a push at walking pace moves a robot several centimetres before it can brake
    pushed_margin_m: float = setting(0.1, lo=0.0, hi=1.0)
    push_range_m: float = setting(0.3, lo=0.0, hi=5.0)  # opponent body to own robot body
    opponent_margin_m: float = setting(0.0, lo=0.0, hi=1.0)  # kept from an opponent's reachable disc
    # bound on how opponents may accelerate; 0: they keep their velocity (a disc growing at every
    # opponent near the ball holds our robot off every contested ball)
    opponent_accel_m_s2: float = setting(0.0, lo=0.0, hi=50.0)
    static_margin_m: float = setting(0.01, lo=0.0, hi=1.0)  # kept from walls and static obstacles
    static_step_m: float = setting(0.02, lo=0.001, hi=0.5)  # sample spacing of the static check
    random_samples: int = setting(40, lo=0, hi=1000)  # random points of A(v) per searching robot
    scales: tuple[float, ...] = setting((0.75, 0.5, 0.25), lo=0.0, hi=1.0)  # shorter versions of the command
    rotations_deg: tuple[float, ...] = setting((20.0, 45.0, 90.0, 135.0), lo=0.0, hi=180.0)  # turned both ways


def heuristic_table(params: DSSParams) -> FloatArray:
    """Rows (scale, rotation rad, from the A(v) boundary) of the heuristic samples: the command
    shortened, and turned both ways at full strength (§5.5)."""
    rows = [(s, 0.0, 0.0) for s in params.scales]
    for deg in params.rotations_deg:
        rows += [(1.0, math.radians(deg), 1.0), (1.0, -math.radians(deg), 1.0)]
    return np.array(rows, dtype=np.float64).reshape(-1, 3)


class DynamicsSafetySearch(ArraySafety):
    """DSS for one team (Bruce 2006 §5.3). Holds the random generator that draws the samples."""

    def __init__(
        self,
        params: DSSParams,
        motion: MotionParams,
        robot_radius_m: float,
        static: CollisionWorld | None,
        rng: np.random.Generator,
    ) -> None:
        self.params = params
        self.motion = motion
        self.rng = rng
        self.static = StaticObstacles.from_world(static, robot_radius_m)
        self.limits = np.array([motion.max_speed_m_s, motion.max_accel_m_s2, motion.max_brake_m_s2])
        self.cfg = np.array([
            motion.period_s, motion.max_accel_m_s2, motion.max_brake_m_s2, 2.0 * robot_radius_m + params.own_margin_m,
            2.0 * robot_radius_m + params.opponent_margin_m, params.opponent_accel_m_s2,
            params.static_margin_m, params.static_step_m, 2.0 * params.velocity_error_m_s,
            2.0 * robot_radius_m + max(params.own_margin_m, params.pushed_margin_m),
            2.0 * robot_radius_m + params.push_range_m,
        ])  # fmt: skip
        self.heuristics = heuristic_table(params)

    def unit_samples(self, n: int) -> FloatArray:
        """(n, random_samples, 2) points uniform in the unit disc, one set per robot."""
        k = self.params.random_samples
        r = np.sqrt(self.rng.random((n, k)))
        phi = self.rng.uniform(-math.pi, math.pi, (n, k))
        return np.stack([r * np.cos(phi), r * np.sin(phi)], axis=2)

    def search(
        self, states: ArrayLike, velocities: ArrayLike, opponents: ArrayLike
    ) -> tuple[FloatArray, NDArray[np.int64]]:
        """The accelerations (n, 2) DSS picks and each robot's status; inputs as :meth:`filter`."""
        s = np.ascontiguousarray(states, dtype=np.float64).reshape(-1, 4)
        v = np.ascontiguousarray(velocities, dtype=np.float64).reshape(-1, 2)
        opp = np.ascontiguousarray(opponents, dtype=np.float64).reshape(-1, 4)
        dt = self.motion.period_s
        desired = (v - s[:, 2:4]) / dt
        stop_asked = np.all(v == 0.0, axis=1)
        st = self.static
        acc, status = K.dss(s, desired, stop_asked, opp, st.inner, st.boxes, st.circles, self.limits, self.cfg,
                            self.unit_samples(len(s)), self.heuristics)  # fmt: skip
        return np.asarray(acc), np.asarray(status)

    def filter(self, states: ArrayLike, velocities: ArrayLike, opponents: ArrayLike) -> SafetyResult:
        """Safe velocities: the command where it is safe, the stop (zero) where nothing else is,
        else the velocity one period of the chosen acceleration reaches."""
        s = np.asarray(states, dtype=np.float64).reshape(-1, 4)
        v = np.asarray(velocities, dtype=np.float64).reshape(-1, 2)
        acc, status = self.search(s, v, opponents)
        out = s[:, 2:4] + acc * self.motion.period_s
        out[status == K.KEPT] = v[status == K.KEPT]
        out[(status == K.STOPPED) | (status == K.STOP_ASKED)] = 0.0
        return SafetyResult(out, status)

    def clear(self, states: ArrayLike, accelerations: ArrayLike, opponents: ArrayLike) -> NDArray[np.bool_]:
        """Per robot: is the trajectory of ``accelerations`` clear of all others, opponents and
        static obstacles (the property every search result has)?"""
        s = np.ascontiguousarray(states, dtype=np.float64).reshape(-1, 4)
        a = np.ascontiguousarray(accelerations, dtype=np.float64).reshape(-1, 2)
        opp = np.ascontiguousarray(opponents, dtype=np.float64).reshape(-1, 4)
        st = self.static
        return np.asarray(K.trajectories_clear(s, a, opp, st.inner, st.boxes, st.circles, self.cfg))


def braking_path(position: ArrayLike, velocity: ArrayLike, command: ArrayLike, motion: MotionParams,
                 samples_per_phase: int = 6) -> NDArray[np.float64]:  # fmt: skip
    """The trajectory DSS checks for one robot (§5.1): from ``position`` (m) at ``velocity`` (m/s),
    the commanded velocity ``command`` (m/s) pursued for one control period, then braking at
    ``motion.max_brake_m_s2`` to rest; as points (k, 2), field frame, m, from the start."""
    px, py = (float(v) for v in np.asarray(position, dtype=np.float64).reshape(2))
    vx, vy = (float(v) for v in np.asarray(velocity, dtype=np.float64).reshape(2))
    cx, cy = (float(v) for v in np.asarray(command, dtype=np.float64).reshape(2))
    dt = motion.period_s
    tr = K.trajectory(px, py, vx, vy, (cx - vx) / dt, (cy - vy) / dt, dt, motion.max_accel_m_s2,
                      motion.max_brake_m_s2)  # fmt: skip
    pts = [(px, py)]
    for t0, t1, x, y, u, w, ax, ay in tr:
        if math.isfinite(t1) and t1 > t0:
            for h in np.linspace(0.0, t1 - t0, max(2, samples_per_phase))[1:]:
                pts.append((x + u * h + 0.5 * ax * h * h, y + w * h + 0.5 * ay * h * h))
    return np.array(pts)
