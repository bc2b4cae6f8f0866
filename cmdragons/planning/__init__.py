"""Motion planning (Bruce 2006 ch. 3 and 4): the collision world, ERRT with its waypoint cache,
dynamic PRM and the exact visibility graph, behind ``solve(problem, deadline) -> PlanResult``."""

from cmdragons.planning.errt import ERRTParams, ERRTPlanner
from cmdragons.planning.prm import DynamicPRMParams, DynamicPRMPlanner
from cmdragons.planning.problem import Planner, PlanProblem, PlanResult, PlanStatus, deadline_in, path_length
from cmdragons.planning.registry import PLANNERS, PlannerParams, make_planner
from cmdragons.planning.visgraph import VisGraphParams, VisibilityGraphPlanner
from cmdragons.planning.world import CollisionParams, CollisionWorld, CompiledWorld, field_world

__all__ = [
    "PLANNERS",
    "CollisionParams",
    "CollisionWorld",
    "CompiledWorld",
    "DynamicPRMParams",
    "DynamicPRMPlanner",
    "ERRTParams",
    "ERRTPlanner",
    "PlanProblem",
    "PlanResult",
    "PlanStatus",
    "Planner",
    "PlannerParams",
    "VisGraphParams",
    "VisibilityGraphPlanner",
    "deadline_in",
    "field_world",
    "make_planner",
    "path_length",
]
