"""OMPL baselines for ``cmdragons bench planning`` (the ``bench`` extra: ``pip install ompl``).

OMPL's RRTConnect (with and without its path simplifier) and PRM, wrapped in our planner interface
so they run on the very same problems: the state space is the robot centre's box of the field, and
both the state validity check and the motion validator ask our compiled :class:`CollisionWorld`
(the same swept-circle query ERRT uses), so the only difference is the algorithm. OMPL calls these
checks back into Python, which is part of what it costs to use it from Python.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from cmdragons.planning.problem import PlanProblem, PlanResult, PlanStatus, Stateless, prepare
from cmdragons.planning.termination import Termination
from cmdragons.planning.world import CompiledWorld

__all__ = ["OMPLPlanner", "ompl_missing"]


def ompl_missing() -> str | None:
    """None when the ``ompl`` package imports, else why not."""
    try:
        import ompl.base  # noqa: F401
        import ompl.geometric  # noqa: F401
    except ImportError as exc:
        return f"ompl not installed ({exc}); pip install 'cmdragons[bench]'"
    return None


def _motion_validator(si: Any, cw: CompiledWorld) -> Any:
    from ompl import base as ob

    class SweptCircleValidator(ob.MotionValidator):  # type: ignore[misc]
        """OMPL motion checks answered by our exact swept-circle query (no sampling resolution)."""

        def checkMotion(self, *args: Any) -> bool:  # noqa: N802 (OMPL's name)
            a, b = args[0], args[1]
            return bool(cw.segment_free((a[0], a[1]), (b[0], b[1])))

    return SweptCircleValidator(si)


class OMPLPlanner(Stateless):
    """One OMPL geometric planner (``"RRTConnect"`` or ``"PRM"``) behind ``solve(problem, termination)`` (its deadline);
    ``simplify`` runs OMPL's path simplifier on the solution (its time counts)."""

    def __init__(self, planner: str, simplify: bool) -> None:
        from ompl import util as ou

        ou.setLogLevel(ou.LogLevel.LOG_NONE)
        self.planner = planner
        self.simplify = simplify
        self.name = f"ompl_{planner.lower()}" + ("_simplified" if simplify else "")

    def solve(self, problem: PlanProblem, termination: Termination) -> PlanResult:
        from ompl import base as ob
        from ompl import geometric as og

        t0 = time.perf_counter()
        cw, ends = prepare(problem)
        if ends.failure is not None:
            return ends.fail(t0)
        space = ob.RealVectorStateSpace(2)
        bounds = ob.RealVectorBounds(2)
        for i in range(2):
            bounds.setLow(i, float(cw.inner[i]))
            bounds.setHigh(i, float(cw.inner[i + 2]))
        space.setBounds(bounds)
        ss = og.SimpleSetup(space)
        ss.setStateValidityChecker(lambda s: cw.point_free(s[0], s[1]))
        si = ss.getSpaceInformation()
        validator = _motion_validator(si, cw)
        si.setMotionValidator(validator)
        start, goal = space.allocState(), space.allocState()
        start[0], start[1] = ends.start
        goal[0], goal[1] = ends.goal
        ss.setStartAndGoalStates(start, goal)
        ss.setPlanner(getattr(og, self.planner)(si))
        objective = ob.PathLengthOptimizationObjective(si)
        objective.setCostThreshold(ob.Cost(float("inf")))  # stop at the first solution (PRM would use all the time)
        ss.setOptimizationObjective(objective)
        setup_ms = (time.perf_counter() - t0) * 1e3
        t1 = time.perf_counter()
        ss.solve(max(1e-4, min(termination.deadline_s - t1, 1e6)))
        stats: dict[str, object] = {"setup_ms": setup_ms}
        if not ss.haveExactSolutionPath():
            stats["ms"] = (time.perf_counter() - t1) * 1e3
            return ends.finish(None, PlanStatus.TIMEOUT, stats)
        if self.simplify:
            ss.simplifySolution(max(1e-4, min(termination.deadline_s - time.perf_counter(), 1e6)))
        p = ss.getSolutionPath()
        path = np.array([[p.getState(i)[0], p.getState(i)[1]] for i in range(p.getStateCount())])
        # the time OMPL takes to plan (and simplify), without building its objects
        stats["ms"] = (time.perf_counter() - t1) * 1e3
        return ends.finish(path, PlanStatus.SOLVED, stats)
