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
from cmdragons.planning.world import CollisionWorld, CompiledWorld
from cmdragons.safety import _kernels as K
from cmdragons.safety.base import ArraySafety, SafetyResult

__all__ = ["DSSParams", "DynamicsSafetySearch", "crash_hold", "heuristic_table"]

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
    # the rules' crash: toward an opponent, a robot's speed along the line between them is held to what
    # braking at crash_brake_share of max_brake_m_s2 over the gap (less crash_latency_s of closing) brings
    # down to this closing speed, less the opponent's own speed toward it, at contact (0: no hold)
    crash_closing_m_s: float = setting(1.0, lo=0.0, hi=10.0)
    crash_brake_share: float = setting(0.75, lo=0.01, hi=1.0)
    crash_latency_s: float = setting(0.1, lo=0.0, hi=1.0)


def heuristic_table(params: DSSParams) -> FloatArray:
    """Rows (scale, rotation rad, from the A(v) boundary) of the heuristic samples: the command
    shortened, and turned both ways at full strength (§5.5)."""
    rows = [(s, 0.0, 0.0) for s in params.scales]
    for deg in params.rotations_deg:
        rows += [(1.0, math.radians(deg), 1.0), (1.0, -math.radians(deg), 1.0)]
    return np.array(rows, dtype=np.float64).reshape(-1, 3)


def crash_hold(states: FloatArray, velocities: FloatArray, opponents: FloatArray, body_m: float, closing_m_s: float,
               brake_m_s2: float, latency_s: float) -> FloatArray:
    """The commands (n, 2) with each robot's speed toward each opponent held to ``sqrt(c**2 + 2 b g)``:
    ``c`` the closing speed allowed at contact less the opponent's speed toward the robot, ``g`` the
    gap between their bodies less ``latency_s`` of their closing speed now, ``b`` the braking. A
    robot braking no harder than ``b`` then meets the opponent no faster than ``closing_m_s``, the
    opponent's share included (the rules call a crash beyond 1.5 m/s, the faster robot at fault).
    ``states`` (n, 4) and ``opponents`` (m, 4): x, y, vx, vy."""
    out = np.array(velocities, dtype=np.float64, copy=True)
    rel = opponents[None, :, :2] - states[:, None, :2]  # (n, m, 2)
    dist = np.maximum(np.hypot(rel[..., 0], rel[..., 1]), 1e-9)
    unit = rel / dist[..., None]
    theirs = -np.einsum("mj,nmj->nm", opponents[:, 2:4], unit)  # each opponent's speed toward each robot
    now = np.einsum("nj,nmj->nm", states[:, 2:4], unit) + theirs  # closing speeds now
    gap = np.maximum(dist - body_m - latency_s * np.maximum(now, 0.0), 0.0)
    allowed = np.sqrt(np.maximum(closing_m_s - np.maximum(theirs, 0.0), 0.0) ** 2 + 2.0 * brake_m_s2 * gap)
    over = np.einsum("nj,nmj->nm", out, unit) > allowed
    for i in np.flatnonzero(over.any(axis=1)):
        for k in np.argsort(dist[i]):  # the nearest first: each hold only takes speed away
            toward = float(out[i] @ unit[i, k])
            if toward > allowed[i, k]:
                out[i] -= (toward - allowed[i, k]) * unit[i, k]
    return out


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
        # the walls and fixed obstacles as the collision world answers for a robot of this radius
        unbounded = CollisionWorld((-1e9, -1e9, 1e9, 1e9))
        self.static: CompiledWorld = (static or unbounded).compile(robot_radius_m)
        self.limits = motion.limits()
        d = 2.0 * robot_radius_m
        self.cfg = K.DSSConfig(
            dt=motion.period_s, own_radius=d + params.own_margin_m,
            pushed_radius=d + max(params.own_margin_m, params.pushed_margin_m), push_reach=d + params.push_range_m,
            own_growth=2.0 * params.velocity_error_m_s, opponent_radius=d + params.opponent_margin_m,
            opponent_accel=params.opponent_accel_m_s2, static_margin=params.static_margin_m,
            static_step=params.static_step_m,
        )
        self.heuristics = heuristic_table(params)
        self.body_m = d  # centre to centre at contact

    def unit_samples(self, n: int) -> FloatArray:
        """(n, random_samples, 2) points uniform in the unit disc, one set per robot."""
        k = self.params.random_samples
        r = np.sqrt(self.rng.random((n, k)))
        phi = self.rng.uniform(-math.pi, math.pi, (n, k))
        return np.stack([r * np.cos(phi), r * np.sin(phi)], axis=2)

    def search(
        self, states: ArrayLike, velocities: ArrayLike, opponents: ArrayLike
    ) -> tuple[FloatArray, NDArray[np.int64], FloatArray]:
        """The accelerations (n, 2) DSS picks, each robot's status and the braking trajectories it
        checked (n, N_SEG, 8); inputs as :meth:`filter`."""
        s = np.ascontiguousarray(states, dtype=np.float64).reshape(-1, 4)
        v = np.ascontiguousarray(velocities, dtype=np.float64).reshape(-1, 2)
        opp = np.ascontiguousarray(opponents, dtype=np.float64).reshape(-1, 4)
        dt = self.motion.period_s
        desired = (v - s[:, 2:4]) / dt
        stop_asked = np.all(v == 0.0, axis=1)
        st = self.static
        acc, status, trs = K.dss(s, desired, stop_asked, opp, st.obs, st.inner, self.limits, self.cfg,
                                 self.unit_samples(len(s)), self.heuristics)
        return np.asarray(acc), np.asarray(status), np.asarray(trs)

    def filter(self, states: ArrayLike, velocities: ArrayLike, opponents: ArrayLike) -> SafetyResult:
        """Safe velocities: the command where it is safe, the stop (zero) where nothing else is,
        else the velocity one period of the chosen acceleration reaches."""
        s = np.asarray(states, dtype=np.float64).reshape(-1, 4)
        v = np.asarray(velocities, dtype=np.float64).reshape(-1, 2)
        opp = np.asarray(opponents, dtype=np.float64).reshape(-1, 4)
        p = self.params
        if p.crash_closing_m_s > 0.0 and len(opp):
            v = crash_hold(s, v, opp, self.body_m, p.crash_closing_m_s,
                           p.crash_brake_share * self.motion.max_brake_m_s2, p.crash_latency_s)
        acc, status, trs = self.search(s, v, opp)
        out = s[:, 2:4] + acc * self.motion.period_s
        out[status == K.KEPT] = v[status == K.KEPT]
        out[(status == K.STOPPED) | (status == K.STOP_ASKED)] = 0.0
        # the segments' start points and the rest point: the braking path (straight after the period)
        return SafetyResult(out, status, trs[:, :, 2:4].copy())

    def clear(self, states: ArrayLike, accelerations: ArrayLike, opponents: ArrayLike) -> NDArray[np.bool_]:
        """Per robot: is the trajectory of ``accelerations`` clear of all others, opponents and
        static obstacles (the property every search result has)?"""
        s = np.ascontiguousarray(states, dtype=np.float64).reshape(-1, 4)
        a = np.ascontiguousarray(accelerations, dtype=np.float64).reshape(-1, 2)
        opp = np.ascontiguousarray(opponents, dtype=np.float64).reshape(-1, 4)
        st = self.static
        return np.asarray(K.trajectories_clear(s, a, opp, st.obs, st.inner, self.limits, self.cfg))
