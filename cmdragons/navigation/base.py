"""The local navigator interface of DESIGN.md (after Navigation2's controller plugins).

Per robot and frame the brain runs: a global planner (``PLANNERS``) turns the objective into a path;
a local navigator turns path and world into this frame's velocity command; team safety (DSS) makes
all own robots' commands safe together. A navigator sees one robot: field frame, metres, seconds,
radians; it never commands beyond the robot's limits (configs/control.yaml ``motion``).

* :meth:`Navigator.set_plan` hands over the path (k, 2) from the robot to its goal, with how to
  arrive (:class:`Arrival`: heading, speed through the goal, speed cap);
* :meth:`Navigator.command` computes ``(vx, vy, omega)`` for the robot's state in the world it must
  avoid (the frame's :class:`~cmdragons.planning.world.CollisionWorld` without this robot), until
  the termination condition: a navigator that may not work at all (a spent budget, a passed
  deadline) commands the stop, which the safety search always accepts;
* :meth:`Navigator.sent` tells it the command that safety let through to the robot, the start of
  its next frame's profile;
* :meth:`Navigator.reset` forgets the plan and the command history.

A navigator type (:class:`NavigatorType`, after Nav2's ``configure(parent, name)``) names the config
sections it reads (configs/team.yaml: its own, and shared ones such as ``reactive`` or
``trajectory``) and builds itself from them for one robot: the registry maps a name to the type.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from enum import Enum
from typing import Any, Protocol

from numpy.typing import ArrayLike

from cmdragons.control.motion import ControlParams
from cmdragons.messages import RobotState
from cmdragons.planning.termination import Termination
from cmdragons.planning.world import CollisionParams, CollisionWorld

__all__ = ["STOP", "Arrival", "NavStatus", "Navigator", "NavigatorType", "VelocityCommand"]

VelocityCommand = tuple[float, float, float]  # vx, vy (field frame, m/s), omega (rad/s)
STOP: VelocityCommand = (0.0, 0.0, 0.0)


class NavStatus(Enum):
    """What a reactive navigator reports about its last command (a value, never an exception)."""

    IDLE = "idle"  # no goal
    MOVING = "moving"  # on its way by its own method
    FOLLOWING = "following"  # bug methods: following an obstacle's boundary
    ARRIVING = "arriving"  # the last stretch: the trajectory navigator's approach to the goal
    LOCAL_MINIMUM = "local_minimum"  # potential fields: stuck where the forces cancel (it stops)
    ESCAPING = "escaping"  # potential fields: leaving a local minimum along the NF1 path
    BLOCKED = "blocked"  # the method finds no way to the goal (it stops)


@dataclass(frozen=True)
class Arrival:
    """How a robot arrives at the end of its path: facing ``heading_rad``; driving through it at
    ``through_speed_m_s`` along the line from the robot to it (0: stop on it); never faster than
    ``max_speed_m_s`` nor turning faster than ``max_omega_rad_s`` (None: the robot's limits)."""

    heading_rad: float = 0.0
    through_speed_m_s: float = 0.0
    max_speed_m_s: float | None = None
    max_omega_rad_s: float | None = None

    def __post_init__(self) -> None:
        caps = (self.max_speed_m_s, self.max_omega_rad_s)
        if not self.through_speed_m_s >= 0.0 or any(c is not None and not c >= 0.0 for c in caps):
            raise ValueError(f"speeds must be >= 0: {self}")


class Navigator(Protocol):
    """A local navigator for one robot; the state it keeps across frames lives in it."""

    def set_plan(self, path: ArrayLike, arrival: Arrival) -> None:
        """Follow ``path`` (k, 2), field frame, from the robot's position to its goal."""

    def command(self, robot: RobotState, world: CollisionWorld, termination: Termination) -> VelocityCommand:
        """This frame's command for ``robot`` among ``world``'s obstacles, by ``termination``."""
        ...

    def sent(self, vx: float, vy: float) -> None:
        """The velocity (field frame, m/s) that was finally sent to the robot this frame."""

    def reset(self) -> None:
        """Forget the plan and everything learnt from earlier frames."""


class NavigatorType(Protocol):
    """A navigator as the registry holds it: the sections it reads, and how it builds itself."""

    @property
    def SECTIONS(self) -> Mapping[str, type]:
        """Config section name -> its params type (each with defaults): its own, and shared ones."""
        ...

    def configure(self, name: str, sections: Mapping[str, Any], control: ControlParams, robot_radius_m: float,
                  collision: CollisionParams) -> Navigator:
        """A fresh navigator for one robot, registered as ``name``, from ``sections`` (each of
        :attr:`SECTIONS` by name, parsed), the robot model, its radius (m) and the collision queries'
        parameters."""
        ...
