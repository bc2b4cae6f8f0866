"""Local navigation (DESIGN.md): per robot, the global planner's path and the world -> this frame's
velocity command, behind ``set_plan``, ``command(robot, world, termination)``, ``reset``. Trajectory
following with trapezoidal profiles (Bruce 2006 B.4), the dynamic window (§5.2), the Robox stack
(Philippsen 2004: the elastic band over the global path, executed by the dynamic window), and the
reactive methods of the lecture notes: potential fields (plain and extended), Bug1, Bug2, the
tangent bug, VFH, VFH+, the curvature velocity and lane curvature methods, escape and evade."""

from cmdragons.navigation.base import STOP, Arrival, Navigator, NavigatorType, NavStatus, VelocityCommand
from cmdragons.navigation.bug import BugNavigator, BugParams, GridBug2, GridBug2Status, TangentBugParams, bug2_path
from cmdragons.navigation.curvature_velocity import CurvatureParams, CurvatureVelocityNavigator, LaneParams
from cmdragons.navigation.dynamic_window import DynamicWindowNavigator, DynamicWindowParams
from cmdragons.navigation.elastic_band import BandParams
from cmdragons.navigation.escape_evade import EscapeEvadeNavigator, EscapeEvadeParams, MovementModel, reflex
from cmdragons.navigation.potential_field import ExtendedFieldParams, PotentialFieldNavigator, PotentialFieldParams
from cmdragons.navigation.reactive import ReactiveNavigator, ReactiveParams
from cmdragons.navigation.registry import NAVIGATORS, config_sections, make_navigator
from cmdragons.navigation.robox import RoboxNavigator, RoboxParams
from cmdragons.navigation.trajectory import TrajectoryNavigator, TrajectoryParams
from cmdragons.navigation.vfh import VFHNavigator, VFHParams, VFHPlusParams

__all__ = [
    "NAVIGATORS",
    "STOP",
    "Arrival",
    "BandParams",
    "BugNavigator",
    "BugParams",
    "CurvatureParams",
    "CurvatureVelocityNavigator",
    "DynamicWindowNavigator",
    "DynamicWindowParams",
    "EscapeEvadeNavigator",
    "EscapeEvadeParams",
    "ExtendedFieldParams",
    "GridBug2",
    "GridBug2Status",
    "LaneParams",
    "MovementModel",
    "NavStatus",
    "Navigator",
    "NavigatorType",
    "PotentialFieldNavigator",
    "PotentialFieldParams",
    "ReactiveNavigator",
    "ReactiveParams",
    "RoboxNavigator",
    "RoboxParams",
    "TangentBugParams",
    "TrajectoryNavigator",
    "TrajectoryParams",
    "VFHNavigator",
    "VFHParams",
    "VFHPlusParams",
    "VelocityCommand",
    "bug2_path",
    "config_sections",
    "make_navigator",
    "reflex",
]
