"""Navigator registry: ``navigator`` in configs/team.yaml picks one of :data:`NAVIGATORS` by name.

A navigator is one module, one line here and one config section: each navigator type declares the
sections of configs/team.yaml it reads (``SECTIONS``: its own, and shared ones such as ``reactive``
or ``trajectory``) and builds itself from them (``configure``, after Nav2's plugins); the team's
config holds the sections of every registered navigator (:func:`config_sections`) beside
``navigator``, checked when it is loaded. Nothing outside this package knows a navigator's params.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from cmdragons.control.motion import ControlParams
from cmdragons.navigation.base import Navigator, NavigatorType
from cmdragons.navigation.bug import BugNavigator
from cmdragons.navigation.curvature_velocity import CurvatureVelocityNavigator
from cmdragons.navigation.dynamic_window import DynamicWindowNavigator
from cmdragons.navigation.escape_evade import EscapeEvadeNavigator
from cmdragons.navigation.potential_field import PotentialFieldNavigator
from cmdragons.navigation.robox import RoboxNavigator
from cmdragons.navigation.trajectory import TrajectoryNavigator
from cmdragons.navigation.vfh import VFHNavigator
from cmdragons.planning.world import CollisionParams

__all__ = ["NAVIGATORS", "config_sections", "make_navigator"]

NAVIGATORS: dict[str, NavigatorType] = {
    "trajectory": TrajectoryNavigator,
    "dynamic_window": DynamicWindowNavigator,
    "robox": RoboxNavigator,
    # the reactive methods of the lecture notes (navigation/reactive.py: the shared section ``reactive``)
    "potential_field": PotentialFieldNavigator,
    "extended_potential_field": PotentialFieldNavigator,
    "bug1": BugNavigator,
    "bug2": BugNavigator,
    "tangent_bug": BugNavigator,
    "vfh": VFHNavigator,
    "vfh_plus": VFHNavigator,
    "curvature_velocity": CurvatureVelocityNavigator,
    "lane_curvature": CurvatureVelocityNavigator,
    "escape_evade": EscapeEvadeNavigator,
}


def config_sections() -> dict[str, type]:
    """The config sections of every registered navigator, name -> params type, in registry order
    (a section two navigators share must have one type)."""
    out: dict[str, type] = {}
    for name, nav in NAVIGATORS.items():
        for section, params in nav.SECTIONS.items():
            if out.setdefault(section, params) is not params:
                raise TypeError(f"navigator {name!r} reads section {section!r} as {params.__name__}, "
                                f"another as {out[section].__name__}")
    return out


def make_navigator(
    name: str, sections: Mapping[str, Any], control: ControlParams, robot_radius_m: float,
    collision: CollisionParams | None = None,
) -> Navigator:
    """A fresh navigator ``name`` for one robot, configured from ``sections`` (the team config's
    sections by name: :attr:`cmdragons.team.TeamParams.navigator_sections`); a section it reads that
    ``sections`` lacks takes its defaults."""
    if name not in NAVIGATORS:
        raise KeyError(f"unknown navigator {name!r}; known: {', '.join(sorted(NAVIGATORS))}")
    nav = NAVIGATORS[name]
    own = {section: sections[section] if section in sections else params() for section, params in nav.SECTIONS.items()}
    return nav.configure(name, own, control, robot_radius_m, collision or CollisionParams())
