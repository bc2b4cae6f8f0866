"""Local navigation (DESIGN.md): per robot, the global planner's path and the world -> this frame's
velocity command, behind ``set_plan``, ``command(robot, world, termination)``, ``reset``. Trajectory
following with trapezoidal profiles (Bruce 2006 B.4) and the dynamic window (§5.2)."""

from cmdragons.navigation.base import STOP, Arrival, Navigator, VelocityCommand
from cmdragons.navigation.dynamic_window import DynamicWindowNavigator, DynamicWindowParams
from cmdragons.navigation.registry import NAVIGATORS, make_navigator
from cmdragons.navigation.trajectory import TrajectoryNavigator, TrajectoryParams

__all__ = [
    "NAVIGATORS",
    "STOP",
    "Arrival",
    "DynamicWindowNavigator",
    "DynamicWindowParams",
    "Navigator",
    "TrajectoryNavigator",
    "TrajectoryParams",
    "VelocityCommand",
    "make_navigator",
]
