"""The planner interface of DESIGN.md: ``solve(problem, termination) -> PlanResult``.

Field frame, metres. A :class:`PlanProblem` holds the start, the goal, the robot's radius and the
:class:`CollisionWorld`; a planner answers with a :class:`PlanResult` whose ``status`` is a value,
never an exception.

Termination (:mod:`cmdragons.planning.termination`): a deadline (an absolute
``time.perf_counter()`` time, so that all robots of one frame can share the frame's deadline), a
work budget in the planner's own unit, or both. A planner returns by the deadline plus the time of
one of its work chunks (tens of microseconds), and as soon as its work budget is spent.

Robust planning (Bruce 2006 §4.6.2) is shared by all planners through :func:`robust_ends`: a start
inside an obstacle first leaves it by the shortest way (the first segment of the path moves
straight to the nearest free position and is the one segment allowed to start in collision); a goal
inside an obstacle is replaced by the nearest free goal (status APPROXIMATE).
"""

from __future__ import annotations

import enum
import math
import time
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, Protocol

import numpy as np
from numpy.typing import NDArray

from cmdragons.geometry import path_length
from cmdragons.planning.termination import Termination
from cmdragons.planning.world import CollisionParams, CollisionWorld, CompiledWorld

__all__ = [
    "PlanProblem",
    "PlanResult",
    "PlanStatus",
    "Planner",
    "RobustEnds",
    "Stateless",
    "path_length",
    "prepare",
    "robust_ends",
]

FloatArray = NDArray[np.float64]


class PlanStatus(enum.Enum):
    """How a plan ended (after OMPL's PlannerStatus)."""

    SOLVED = "solved"  # a collision-free path from start to goal
    APPROXIMATE = "approximate"  # the goal is blocked: a path to the nearest free goal instead
    NO_PATH = "no_path"  # the planner gave up without reaching the goal (its budget of work is spent)
    TIMEOUT = "timeout"  # the deadline came first
    INVALID_START = "invalid_start"  # the start is not a finite point or has no free position near it
    INVALID_GOAL = "invalid_goal"  # the goal is not a finite point or has no free position near it

    @property
    def reached(self) -> bool:
        """True when ``path`` ends at the goal (or its nearest free stand-in)."""
        return self in (PlanStatus.SOLVED, PlanStatus.APPROXIMATE)


@dataclass(frozen=True, eq=False)
class PlanProblem:
    """One planning query, field frame, metres.

    ``horizon_s`` is the time window the moving robots are swept over: 0 plans among the robots
    where they are now; a positive horizon keeps clear of where they will be within it."""

    start: tuple[float, float]
    goal: tuple[float, float]
    radius_m: float
    world: CollisionWorld
    horizon_s: float = 0.0
    collision: CollisionParams = field(default_factory=CollisionParams)

    def __post_init__(self) -> None:
        object.__setattr__(self, "start", (float(self.start[0]), float(self.start[1])))
        object.__setattr__(self, "goal", (float(self.goal[0]), float(self.goal[1])))

    def compiled(self) -> CompiledWorld:
        return self.world.compile(self.radius_m, 0.0, self.horizon_s, self.collision)


@dataclass(frozen=True, eq=False)
class PlanResult:
    """``path`` (k, 2) runs from the start; ``cost`` is its length in metres (inf without a path to
    the goal); ``stats`` has the planner's counters (iterations, nodes, milliseconds, ...)."""

    status: PlanStatus
    path: FloatArray
    cost: float
    stats: Mapping[str, Any] = field(default_factory=dict)


class Planner(Protocol):
    """A global planner. One object per robot: state that lives across frames (ERRT's waypoint
    cache and last plan, a roadmap) lives in it."""

    def solve(self, problem: PlanProblem, termination: Termination) -> PlanResult: ...

    def reset(self) -> None:
        """Forget everything learnt from earlier frames."""


class Stateless:
    """For planners that keep nothing across frames."""

    def reset(self) -> None:
        """Nothing to forget."""


@dataclass(frozen=True)
class RobustEnds:
    """The ends a planner actually connects: ``start`` (after leaving an obstacle) and ``goal``
    (the nearest free goal when the asked one is blocked); ``prefix`` is the escape path that leads
    from the true start to ``start`` (just the start when it was free)."""

    start: tuple[float, float]
    goal: tuple[float, float]
    prefix: FloatArray
    escaped: bool
    goal_moved: bool
    failure: PlanStatus | None = None

    def finish(self, path: FloatArray | None, status: PlanStatus, stats: Mapping[str, Any]) -> PlanResult:
        """Join the escape prefix and a planned path (start..goal) into the problem's result."""
        stats = {**stats, "escaped_start": self.escaped, "goal_moved": self.goal_moved}
        if path is None or len(path) == 0:
            return PlanResult(status, self.prefix.copy(), float("inf"), stats)
        full = np.vstack([self.prefix[:-1], path]) if len(self.prefix) > 1 else path
        if status is PlanStatus.SOLVED and self.goal_moved:
            status = PlanStatus.APPROXIMATE
        cost = path_length(full) if status.reached else float("inf")
        return PlanResult(status, full, cost, stats)

    def fail(self, t0: float) -> PlanResult:
        """The result for ends that cannot be planned between (``failure``), timed from ``t0``."""
        assert self.failure is not None
        return PlanResult(self.failure, self.prefix.copy(), float("inf"), {"ms": (time.perf_counter() - t0) * 1e3})


def prepare(problem: PlanProblem) -> tuple[CompiledWorld, RobustEnds]:
    """What every planner does first: the compiled world of the problem and its robust ends."""
    cw = problem.compiled()
    return cw, robust_ends(cw, problem.start, problem.goal)


def robust_ends(cw: CompiledWorld, start: tuple[float, float], goal: tuple[float, float]) -> RobustEnds:
    """Robust planning (Bruce 2006 §4.6.2): where to plan from and to when the start or the goal lies
    in an obstacle or outside the field."""
    prefix = np.array([start], dtype=np.float64)
    start_ok = math.isfinite(start[0]) and math.isfinite(start[1])
    if not (start_ok and math.isfinite(goal[0]) and math.isfinite(goal[1])):
        bad = PlanStatus.INVALID_GOAL if start_ok else PlanStatus.INVALID_START
        return RobustEnds(start, goal, prefix, False, False, bad)
    escaped = False
    if not cw.point_free(*start):
        out = cw.nearest_free(*start)
        if out is None:
            return RobustEnds(start, goal, prefix, False, False, PlanStatus.INVALID_START)
        prefix = np.array([start, out], dtype=np.float64)
        start, escaped = out, True
    goal_moved = False
    if not cw.point_free(*goal):
        g = cw.nearest_free(*goal)
        if g is None:
            return RobustEnds(start, goal, prefix, escaped, False, PlanStatus.INVALID_GOAL)
        goal, goal_moved = g, True
    return RobustEnds(start, goal, prefix, escaped, goal_moved)
