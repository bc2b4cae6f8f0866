"""The vector field histogram, VFH (Borenstein and Koren 1991) and VFH+ (Ulrich and Borenstein 1998),
as local navigators (lecture notes 001, "Obstacle Avoidance: Vector Field Histogram").

Field frame, metres, seconds, radians. The histogram grid is the world itself: a cell is occupied
(certainty 1) where its centre lies in an obstacle. Each occupied cell of the active window adds
c^2 (a - b d) to the polar sector it lies in (:func:`~cmdragons.navigation._vfh_kernels.polar_histogram`).

* **VFH**: the obstacles grown by the robot's radius; the histogram smoothed over ``smoothing``
  sectors each side; sectors under ``threshold`` are free; the valley (run of free sectors) nearest
  the target's sector is taken: a wide one (more than ``wide_sectors``) steers ``wide_sectors / 2``
  in from its border nearest the target (the target itself when it lies inside), a narrow one
  through its middle; the speed falls with the density ahead, V = Vmax (1 - min(h_c, h_m) / h_m).
* **VFH+** (section ``vfh_plus``): the real obstacles, each cell enlarged by the robot's radius plus
  ``safety_m`` (the sectors within asin(r / d) of it); a binary histogram with hysteresis (blocked
  above ``threshold_high``, free below ``threshold_low``, else as last frame); the masked histogram
  of the trajectories the robot can still turn into at its speed (circles of radius v^2 / a); of the
  candidate directions (the valleys' borders moved ``wide_sectors / 2`` in, the target when free,
  a narrow valley's middle) it takes the one of least cost
  G = mu1 D(c, target) + mu2 D(c, direction of motion) + mu3 D(c, previous choice).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from cmdragons.config import Validated, setting
from cmdragons.control.motion import ControlParams
from cmdragons.geometry import wrap_angle
from cmdragons.messages import RobotState
from cmdragons.navigation import _vfh_kernels as K
from cmdragons.navigation.base import NavStatus
from cmdragons.navigation.reactive import ReactiveNavigator, ReactiveParams
from cmdragons.navigation.trajectory import TrajectoryParams
from cmdragons.planning.world import CollisionParams, CompiledWorld

__all__ = ["VFHNavigator", "VFHParams", "VFHPlusParams", "valleys"]


@dataclass(frozen=True)
class VFHParams(Validated):
    """configs/team.yaml ``vfh`` (VFH+ reads it too)."""

    window_m: float = setting(1.0, lo=0.1, hi=10.0)  # radius of the active window
    cell_m: float = setting(0.05, lo=0.005, hi=1.0)  # histogram-grid cells
    sectors: int = setting(72, lo=8, hi=720)  # polar histogram sectors (alpha = 360 / sectors degrees)
    smoothing: int = setting(2, lo=0, hi=20)  # VFH: sectors each side of the smoothing window
    threshold: float = setting(1.0, lo=0.0, hi=1e4)  # VFH: a smoothed sector above this is blocked
    wide_sectors: int = setting(12, lo=1, hi=360)  # s_max: a valley wider than this is wide
    density_limit: float = setting(5.0, lo=1e-3, hi=1e5)  # h_m: the density ahead at which VFH stops


@dataclass(frozen=True)
class VFHPlusParams(Validated):
    """configs/team.yaml ``vfh_plus``."""

    safety_m: float = setting(0.05, lo=0.0, hi=1.0)  # d_s: cells enlarged by the robot's radius plus this
    threshold_low: float = setting(0.5, lo=0.0, hi=1e4)  # tau_low: below, a sector is free
    threshold_high: float = setting(1.5, lo=0.0, hi=1e4)  # tau_high: above, blocked (between: as before)
    target_weight: float = setting(5.0, lo=0.0, hi=100.0)  # mu1
    motion_weight: float = setting(2.0, lo=0.0, hi=100.0)  # mu2
    previous_weight: float = setting(2.0, lo=0.0, hi=100.0)  # mu3

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.threshold_low > self.threshold_high:
            raise ValueError(f"threshold_low {self.threshold_low} must not exceed threshold_high {self.threshold_high}")


def valleys(blocked: NDArray[np.bool_]) -> list[tuple[int, int]]:
    """The runs of free sectors of a circular histogram as (first, length), in sector order; one run
    of every sector when none is blocked."""
    n = len(blocked)
    if not blocked.any():
        return [(0, n)]
    start = int(np.argmax(blocked))  # a blocked sector: runs never wrap past it
    out, run = [], -1
    for s in range(1, n + 1):
        k = (start + s) % n
        if not blocked[k] and run < 0:
            run = s
        if (blocked[k] or s == n) and run >= 0:
            out.append(((start + run) % n, s - run))
            run = -1
    return out


def _gap(a: float, b: float, n: int) -> float:
    d = abs(a - b) % n
    return min(d, n - d)


class VFHNavigator(ReactiveNavigator):
    """VFH or VFH+ (``plus``) for one robot."""

    SECTIONS: ClassVar[Mapping[str, type]] = {**ReactiveNavigator.SECTIONS, "vfh": VFHParams, "vfh_plus": VFHPlusParams}

    @classmethod
    def configure(cls, name: str, sections: Mapping[str, Any], control: ControlParams, robot_radius_m: float,
                  collision: CollisionParams) -> VFHNavigator:
        """``vfh`` from its section; ``vfh_plus`` adds its own section to it. Both read the shared
        ``reactive`` and ``trajectory``."""
        plus = sections["vfh_plus"] if name == "vfh_plus" else None
        return cls(sections["vfh"], sections["reactive"], control, robot_radius_m, collision, sections["trajectory"],
                   plus)

    def __init__(self, params: VFHParams, reactive: ReactiveParams, control: ControlParams, robot_radius_m: float,
                 collision: CollisionParams | None = None, follow: TrajectoryParams | None = None,
                 plus: VFHPlusParams | None = None) -> None:
        super().__init__(reactive, control, robot_radius_m, collision, follow)
        self.params = params
        self.plus = plus
        self.name = "vfh_plus" if plus is not None else "vfh"
        enlarge = robot_radius_m + plus.safety_m if plus is not None else 0.0
        self.cfg = K.HistogramConfig(params.window_m, params.cell_m, params.sectors, enlarge)
        self._blocked = np.zeros(params.sectors, dtype=np.bool_)
        self._previous: float | None = None  # the last chosen sector
        self.histogram = np.zeros(params.sectors)  # the last histogram (smoothed for VFH, primary for VFH+)

    def restart(self, start: tuple[float, float], goal: tuple[float, float]) -> None:
        self._blocked[:] = False
        self._previous = None

    def want(self, robot: RobotState, cw: CompiledWorld, goal: tuple[float, float]) -> tuple[float, float]:
        p, n = self.params, self.params.sectors
        alpha = 2.0 * math.pi / n
        here = (robot.x, robot.y)
        src = cw
        if self.plus is not None and self.world is not None:
            src = self.world.compile(0.0, 0.0, 0.0, self.collision)
        h = K.polar_histogram(src.obs, src.inner, here[0], here[1], self.cfg)
        target = ((math.atan2(goal[1] - here[1], goal[0] - here[0]) + math.pi) / alpha) % n
        speed_now = math.hypot(robot.vx, robot.vy)
        if self.plus is None:
            w = p.smoothing
            weights = np.array([w + 1 - abs(i) for i in range(-w, w + 1)], dtype=np.float64)
            hs = sum(weights[i + w] * np.roll(h, -i) for i in range(-w, w + 1)) / (2 * w + 1)
            self.histogram = hs
            blocked = hs > p.threshold
            choice = self._vfh_direction(blocked, target)
            if choice is None:
                self.status = NavStatus.BLOCKED
                return 0.0, 0.0
            ahead = float(hs[int(choice) % n])
            v = self.cruise(here, goal) * (1.0 - min(ahead, p.density_limit) / p.density_limit)
        else:
            q = self.plus
            self.histogram = h
            blocked = np.where(h > q.threshold_high, True, np.where(h < q.threshold_low, False, self._blocked))
            self._blocked = blocked
            masked = blocked.copy()
            if speed_now > 0.05:  # the masked histogram: the directions the robot cannot turn into
                theta = math.atan2(robot.vy, robot.vx)
                r_turn = speed_now**2 / self.control.motion.max_accel_m_s2
                left, right = K.turning_limits(src.obs, src.inner, here[0], here[1], theta, r_turn,
                                               self.cfg.enlarge, self.cfg)
                centres = ((np.arange(n) + 0.5) * alpha - math.pi).astype(np.float64)
                rel = wrap_angle(centres - theta)
                masked |= (rel > left) | (rel < right)
            motion = ((math.atan2(robot.vy, robot.vx) + math.pi) / alpha) % n if speed_now > 0.05 else target
            choice = self._vfh_plus_direction(masked, target, motion)
            if choice is None:
                self.status = NavStatus.BLOCKED
                return 0.0, 0.0
            v = self.cruise(here, goal)
        self.status = NavStatus.MOVING
        self._previous = choice
        a = (choice + 0.5) * alpha - math.pi if choice != target else math.atan2(goal[1] - here[1], goal[0] - here[0])
        return v * math.cos(a), v * math.sin(a)

    def _vfh_direction(self, blocked: NDArray[np.bool_], target: float) -> float | None:
        n, smax = self.params.sectors, self.params.wide_sectors
        runs = valleys(blocked)
        if len(runs) == 1 and runs[0][1] == n and not blocked.any():
            return target
        best, best_d = None, math.inf
        for first, length in runs:
            if length == n:
                return target
            inside = _gap(target, first + length / 2.0 - 0.5, n) <= length / 2.0 - 0.5
            if inside and length > smax:
                return target
            # the border nearest the target
            near, far = (first, first + length - 1)
            d0, d1 = _gap(target, near, n), _gap(target, far, n)
            border, d = (near, d0) if d0 <= d1 else (far, d1)
            if d < best_d:
                best_d = d
                if length > smax:
                    best = (border + smax / 2.0) % n if border == near else (border - smax / 2.0) % n
                else:
                    best = (first + (length - 1) / 2.0) % n
        return best

    def _vfh_plus_direction(self, blocked: NDArray[np.bool_], target: float, motion: float) -> float | None:
        q, n, smax = self.plus, self.params.sectors, self.params.wide_sectors
        assert q is not None
        candidates: list[float] = []
        for first, length in valleys(blocked):
            if length == n:
                candidates.append(target)
                continue
            last = first + length - 1
            if length > smax:
                candidates += [(first + smax / 2.0) % n, (last - smax / 2.0) % n]
                if _gap(target, first + (length - 1) / 2.0, n) <= (length - 1) / 2.0 - smax / 2.0:
                    candidates.append(target)
            else:
                candidates.append((first + (length - 1) / 2.0) % n)
        if not candidates:
            return None
        prev = self._previous if self._previous is not None else motion

        def cost(c: float) -> float:
            return q.target_weight * _gap(c, target, n) + q.motion_weight * _gap(c, motion, n) \
                + q.previous_weight * _gap(c, prev, n)

        return min(candidates, key=cost)
