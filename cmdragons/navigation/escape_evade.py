"""Escape and evade: reactive avoidance of moving objects (seed 003, §5.1: the safety reflex and the
movement-model behaviour), as a local navigator and as a reflex for any robot (the goalie's).

Field frame, metres, seconds. Both behaviours make a repelling vector of length at most 1 from the
moving objects (here: every circle of the collision world moving faster than ``min_speed_m_s``):

* **escape** (§5.1.1): straight away from each object within ``r_max_m``, the more the nearer and
  the faster it is (:func:`~cmdragons.navigation._escape_evade_kernels.escape_vector`); it needs no prediction;
* **evade** (§5.1.2): across each object's predicted path toward the robot's side of it, by the
  robot's distance along (dX) and across (dY) that path, the reach across growing with the
  variance of the object's movement model (:func:`~cmdragons.navigation._escape_evade_kernels.evade_vector`).

The **movement model** (:class:`MovementModel`) follows the objects from frame to frame (each
matched to its nearest prediction within ``match_m``): its velocity, its turn rate (the change of
its velocity's direction; a curve is harder to predict) and the variance of the model's prediction
error along (V_X) and across (V_Y) its path, averaged over ``variance_time_s``.

The navigator fuses the vectors with goal attraction as the seed's behaviours add up: the
trajectory navigator's command along the plan plus ``escape_speed_m_s`` times escape's vector plus
``evade_speed_m_s`` times evade's, held to the robot's limits (:mod:`cmdragons.navigation.reactive`).
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
from cmdragons.messages import RobotState
from cmdragons.navigation import _escape_evade_kernels as K
from cmdragons.navigation.base import VelocityCommand
from cmdragons.navigation.reactive import ReactiveNavigator, ReactiveParams
from cmdragons.navigation.trajectory import TrajectoryParams
from cmdragons.planning.termination import Termination, budget
from cmdragons.planning.world import CollisionParams, CollisionWorld, CompiledWorld

__all__ = ["EscapeEvadeNavigator", "EscapeEvadeParams", "MovementModel", "evade_config", "reflex"]

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class EscapeEvadeParams(Validated):
    """configs/team.yaml ``escape_evade``."""

    r_max_m: float = setting(0.5, lo=0.01, hi=10.0)  # escape: area of influence (the seed's 0.5 m)
    v_max_m_s: float = setting(3.0, lo=0.01, hi=20.0)  # an object this fast counts fully
    dx_max_m: float = setting(2.0, lo=0.01, hi=20.0)  # evade: reach along an object's predicted path
    dy_max_m: float = setting(0.4, lo=0.01, hi=10.0)  # evade: reach across it (grown by the variance)
    min_speed_m_s: float = setting(0.2, lo=0.0, hi=10.0)  # slower objects are not moving objects
    escape_speed_m_s: float = setting(2.0, lo=0.0, hi=10.0)  # the escape vector's weight in the fusion
    evade_speed_m_s: float = setting(2.0, lo=0.0, hi=10.0)  # the evade vector's weight
    match_m: float = setting(0.3, lo=0.01, hi=5.0)  # an object is the one nearest its prediction within this
    variance_time_s: float = setting(0.5, lo=0.01, hi=30.0)  # the model's error variance averages over this


def evade_config(p: EscapeEvadeParams) -> K.EvadeConfig:
    """The kernels' numbers from the config section."""
    return K.EvadeConfig(p.r_max_m, p.v_max_m_s, p.dx_max_m, p.dy_max_m, p.min_speed_m_s)


class MovementModel:
    """The moving objects' movement models, frame after frame: rows x, y, vx, vy, omega, V_X, V_Y
    (m, m/s, rad/s, m^2) for the kernels."""

    def __init__(self, params: EscapeEvadeParams, period_s: float) -> None:
        self.params = params
        self.period = period_s
        self.objects: FloatArray = np.zeros((0, 7))

    def reset(self) -> None:
        self.objects = np.zeros((0, 7))

    def update(self, positions: FloatArray, velocities: FloatArray) -> FloatArray:
        """This frame's objects (positions (n, 2), velocities (n, 2)): each matched to the nearest
        prediction of last frame's models, its turn rate and error variances updated."""
        p, dt = self.params, self.period
        keep = np.hypot(velocities[:, 0], velocities[:, 1]) >= p.min_speed_m_s
        pos, vel = positions[keep], velocities[keep]
        out = np.zeros((len(pos), 7))
        out[:, :2], out[:, 2:4] = pos, vel
        out[:, 5:] = 0.0
        old = self.objects
        blend = min(1.0, dt / p.variance_time_s)
        if len(old) and len(pos):
            pred = old[:, :2] + old[:, 2:4] * dt
            for i in range(len(pos)):
                d = np.hypot(pred[:, 0] - pos[i, 0], pred[:, 1] - pos[i, 1])
                j = int(np.argmin(d))
                if d[j] > p.match_m:
                    continue
                ux, uy = old[j, 2:4] / max(math.hypot(*old[j, 2:4]), 1e-9)
                ex, ey = pos[i] - pred[j]
                along, across = ex * ux + ey * uy, ex * -uy + ey * ux
                turn = math.atan2(ux * vel[i, 1] - uy * vel[i, 0], ux * vel[i, 0] + uy * vel[i, 1]) / dt
                out[i, 4] = (1.0 - blend) * old[j, 4] + blend * turn
                out[i, 5] = (1.0 - blend) * old[j, 5] + blend * along * along / (dt * dt)
                out[i, 6] = (1.0 - blend) * old[j, 6] + blend * across * across / (dt * dt)
        self.objects = out
        return out


def reflex(here: tuple[float, float], objects: FloatArray, params: EscapeEvadeParams) -> tuple[float, float]:
    """The escape and evade vectors fused (m/s): ``escape_speed_m_s`` F_escape + ``evade_speed_m_s``
    F_evade for a robot at ``here`` among ``objects`` (:class:`MovementModel` rows)."""
    cfg = evade_config(params)
    objs = np.ascontiguousarray(objects, dtype=np.float64).reshape(-1, 7)
    sx, sy = K.escape_vector(here[0], here[1], objs, cfg)
    ex, ey = K.evade_vector(here[0], here[1], objs, cfg)
    return params.escape_speed_m_s * sx + params.evade_speed_m_s * ex, params.escape_speed_m_s * sy + \
        params.evade_speed_m_s * ey


class EscapeEvadeNavigator(ReactiveNavigator):
    """Goal attraction along the plan plus the escape and evade vectors, for one robot."""

    name = "escape_evade"

    SECTIONS: ClassVar[Mapping[str, type]] = {**ReactiveNavigator.SECTIONS, "escape_evade": EscapeEvadeParams}

    @classmethod
    def configure(cls, name: str, sections: Mapping[str, Any], control: ControlParams, robot_radius_m: float,
                  collision: CollisionParams) -> EscapeEvadeNavigator:
        """From the section ``escape_evade`` and the shared ``reactive`` and ``trajectory``."""
        return cls(sections["escape_evade"], sections["reactive"], control, robot_radius_m, collision,
                   sections["trajectory"])

    def __init__(self, params: EscapeEvadeParams, reactive: ReactiveParams, control: ControlParams,
                 robot_radius_m: float, collision: CollisionParams | None = None,
                 follow: TrajectoryParams | None = None) -> None:
        super().__init__(reactive, control, robot_radius_m, collision, follow)
        self.params = params
        self.model = MovementModel(params, control.motion.period_s)
        self.last_repulsion = (0.0, 0.0)  # m/s, the fused vectors of the last frame

    def restart(self, start: tuple[float, float], goal: tuple[float, float]) -> None:
        self.model.reset()

    def command(self, robot: RobotState, world: CollisionWorld, termination: Termination) -> VelocityCommand:
        """Goal attraction plus the repelling vectors of this frame's moving objects."""
        objects = self.model.update(world.circles[:, :2], world.velocities)
        self.last_repulsion = reflex((robot.x, robot.y), objects, self.params)
        return super().command(robot, world, termination)

    def hands_over(self) -> bool:
        # the last stretch is goal attraction alone only while nothing repels
        return self.last_repulsion == (0.0, 0.0)

    def want(self, robot: RobotState, cw: CompiledWorld, goal: tuple[float, float]) -> tuple[float, float]:
        if self.approached:  # back from the last stretch: the plan again
            self.follow.set_plan(self.plan, self.arrival)
            self.approached = False
        vx, vy, _ = self.follow.command(robot, cw.world, budget(1))
        rx, ry = self.last_repulsion
        return vx + rx, vy + ry
