"""Navigator registry: ``team.navigator`` in configs/team.yaml picks one of :data:`NAVIGATORS`; each
navigator has its config section there (``team.trajectory``, ``team.dynamic_window``, ``team.robox`` with
``team.elastic_band``; the reactive methods ``team.reactive`` and their own: ``potential_field``,
``extended_potential_field``, ``bug``, ``tangent_bug``, ``vfh``, ``vfh_plus``, ``curvature_velocity``,
``lane_curvature``, ``escape_evade``).

A new navigator is one module, one line here and one config section (a field of
:class:`cmdragons.team.TeamParams` named like its registry key).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from cmdragons.control.motion import ControlParams
from cmdragons.navigation.base import Navigator
from cmdragons.navigation.bug import BugNavigator
from cmdragons.navigation.curvature_velocity import CurvatureVelocityNavigator
from cmdragons.navigation.dynamic_window import DynamicWindowNavigator
from cmdragons.navigation.escape_evade import EscapeEvadeNavigator
from cmdragons.navigation.potential_field import PotentialFieldNavigator
from cmdragons.navigation.robox import RoboxNavigator
from cmdragons.navigation.trajectory import TrajectoryNavigator
from cmdragons.navigation.vfh import VFHNavigator
from cmdragons.planning.world import CollisionParams

__all__ = ["NAVIGATORS", "make_navigator"]

# name -> factory(the config sections by navigator name, the robot model, the robot radius m, the
# collision queries); a navigator reads its own section and may build on another's
Factory = Callable[[Any, ControlParams, float, CollisionParams], Navigator]

NAVIGATORS: dict[str, Factory] = {
    "trajectory": lambda s, control, r, collision: TrajectoryNavigator(s.trajectory, control, r),
    "dynamic_window": lambda s, control, r, collision: DynamicWindowNavigator(s.dynamic_window, control, r, collision,
                                                                              s.trajectory),  # fmt: skip
    "robox": lambda s, control, r, collision: RoboxNavigator(s.robox, s.elastic_band, s.dynamic_window, control, r,
                                                             collision, s.trajectory),  # fmt: skip
    # the reactive methods of the lecture notes (navigation/reactive.py: the shared section ``reactive``)
    "potential_field": lambda s, control, r, collision: PotentialFieldNavigator(
        s.potential_field, s.reactive, control, r, collision, s.trajectory),
    "extended_potential_field": lambda s, control, r, collision: PotentialFieldNavigator(
        s.potential_field, s.reactive, control, r, collision, s.trajectory, s.extended_potential_field),
    "bug1": lambda s, control, r, collision: BugNavigator("bug1", s.bug, s.reactive, control, r, collision,
                                                          s.trajectory),  # fmt: skip
    "bug2": lambda s, control, r, collision: BugNavigator("bug2", s.bug, s.reactive, control, r, collision,
                                                          s.trajectory),  # fmt: skip
    "tangent_bug": lambda s, control, r, collision: BugNavigator("tangent_bug", s.bug, s.reactive, control, r,
                                                                 collision, s.trajectory, s.tangent_bug),  # fmt: skip
    "vfh": lambda s, control, r, collision: VFHNavigator(s.vfh, s.reactive, control, r, collision, s.trajectory),
    "vfh_plus": lambda s, control, r, collision: VFHNavigator(s.vfh, s.reactive, control, r, collision, s.trajectory,
                                                              s.vfh_plus),  # fmt: skip
    "curvature_velocity": lambda s, control, r, collision: CurvatureVelocityNavigator(
        s.curvature_velocity, s.reactive, control, r, collision, s.trajectory),
    "lane_curvature": lambda s, control, r, collision: CurvatureVelocityNavigator(
        s.curvature_velocity, s.reactive, control, r, collision, s.trajectory, s.lane_curvature),
    "escape_evade": lambda s, control, r, collision: EscapeEvadeNavigator(s.escape_evade, s.reactive, control, r,
                                                                          collision, s.trajectory),  # fmt: skip
}


def make_navigator(
    name: str, sections: Any, control: ControlParams, robot_radius_m: float, collision: CollisionParams | None = None
) -> Navigator:
    """A fresh navigator ``name`` for one robot; ``sections`` holds each navigator's config section as
    the attribute of its name (configs/team.yaml: :class:`cmdragons.team.TeamParams`)."""
    if name not in NAVIGATORS:
        raise KeyError(f"unknown navigator {name!r}; known: {', '.join(sorted(NAVIGATORS))}")
    return NAVIGATORS[name](sections, control, robot_radius_m, collision or CollisionParams())
