"""Motion planning (Bruce 2006 ch. 3 and 4): the collision world, ERRT with its waypoint cache,
dynamic PRM and the exact visibility graph, behind ``solve(problem, termination) -> PlanResult``."""

from cmdragons.planning.errt import ERRTParams, ERRTPlanner
from cmdragons.planning.prm import DynamicPRMParams, DynamicPRMPlanner
from cmdragons.planning.problem import Planner, PlanProblem, PlanResult, PlanStatus, path_length
from cmdragons.planning.registry import PLANNERS, PlannerParams, make_planner, make_termination
from cmdragons.planning.termination import Termination, budget, deadline, never
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
    "Termination",
    "PlannerParams",
    "VisGraphParams",
    "VisibilityGraphPlanner",
    "budget",
    "deadline",
    "field_world",
    "make_planner",
    "make_termination",
    "never",
    "path_length",
]
