"""Local navigation (DESIGN.md): per robot, the global planner's path and the world -> this frame's
velocity command, behind ``set_plan``, ``command(robot, world, termination)``, ``reset``. Trajectory
following with trapezoidal profiles (Bruce 2006 B.4), the dynamic window (§5.2), and the Robox stack
(Philippsen 2004: the elastic band over the global path, executed by the dynamic window)."""

from cmdragons.navigation.base import STOP, Arrival, Navigator, VelocityCommand
from cmdragons.navigation.dynamic_window import DynamicWindowNavigator, DynamicWindowParams
from cmdragons.navigation.elastic_band import BandParams
from cmdragons.navigation.registry import NAVIGATORS, make_navigator
from cmdragons.navigation.robox import RoboxNavigator, RoboxParams
from cmdragons.navigation.trajectory import TrajectoryNavigator, TrajectoryParams

__all__ = [
    "NAVIGATORS",
    "STOP",
    "Arrival",
    "BandParams",
    "DynamicWindowNavigator",
    "DynamicWindowParams",
    "Navigator",
    "RoboxNavigator",
    "RoboxParams",
    "TrajectoryNavigator",
    "TrajectoryParams",
    "VelocityCommand",
    "make_navigator",
]
