"""Planner registry and the ``planner`` config concern (configs/planner.yaml).

A new algorithm is one module plus one line in :data:`PLANNERS` (and its params beside it here).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from cmdragons.config import Validated, setting
from cmdragons.planning.cells import QuadtreeParams, QuadtreePlanner, UniformCellsParams, UniformCellsPlanner
from cmdragons.planning.errt import ERRTParams, ERRTPlanner
from cmdragons.planning.gridplan import EStarParams, EStarPlanner, GridParams, NF1Params, NF1Planner
from cmdragons.planning.prm import DynamicPRMParams, DynamicPRMPlanner
from cmdragons.planning.problem import Planner
from cmdragons.planning.termination import Termination, budget, deadline
from cmdragons.planning.trapezoidal import TrapezoidalParams, TrapezoidalPlanner
from cmdragons.planning.visgraph import VisGraphParams, VisibilityGraphPlanner
from cmdragons.planning.voronoi import VoronoiParams, VoronoiPlanner
from cmdragons.planning.world import CollisionParams

__all__ = ["PLANNERS", "PlannerParams", "make_planner", "make_termination"]


PLANNERS: dict[str, Callable[[PlannerParams, np.random.Generator], Planner]] = {
    "errt": lambda p, rng: ERRTPlanner(p.errt, rng),
    "prm": lambda p, rng: DynamicPRMPlanner(p.prm, rng),
    "visgraph": lambda p, rng: VisibilityGraphPlanner(p.visgraph, rng),
    "estar": lambda p, rng: EStarPlanner(p.estar, p.grid, rng),
    "nf1": lambda p, rng: NF1Planner(p.nf1, p.grid, rng),
    "voronoi": lambda p, rng: VoronoiPlanner(p.voronoi, rng),
    "trapezoidal": lambda p, rng: TrapezoidalPlanner(p.trapezoidal, rng),
    "uniform_cells": lambda p, rng: UniformCellsPlanner(p.uniform_cells, rng),
    "quadtree": lambda p, rng: QuadtreePlanner(p.quadtree, rng),
}


@dataclass(frozen=True)
class PlannerParams(Validated):
    """configs/planner.yaml: which global planner drives the robots and how each one is tuned."""

    planner: str = setting("errt", choices=tuple(PLANNERS))  # which of PLANNERS drives the robots
    seed: int = setting(1, lo=0, hi=2**63 - 1)  # each robot's planner draws from (seed, robot id)
    # the termination's deadline per robot and frame: only the safety net for a stalled machine, the
    # planners' work budgets bound planning so that a loaded machine plays the same match
    deadline_ms: float = setting(250.0, lo=0.01, hi=10000.0)
    horizon_s: float = setting(0.0, lo=0.0, hi=10.0)  # moving robots are avoided over [0, horizon]
    collision: CollisionParams = CollisionParams()
    errt: ERRTParams = ERRTParams()
    prm: DynamicPRMParams = DynamicPRMParams()
    visgraph: VisGraphParams = VisGraphParams()
    grid: GridParams = GridParams()  # the cost grid of estar and nf1
    estar: EStarParams = EStarParams()
    nf1: NF1Params = NF1Params()
    voronoi: VoronoiParams = VoronoiParams()
    trapezoidal: TrapezoidalParams = TrapezoidalParams()
    uniform_cells: UniformCellsParams = UniformCellsParams()
    quadtree: QuadtreeParams = QuadtreeParams()


def make_planner(params: PlannerParams, robot_id: int = 0, name: str | None = None) -> Planner:
    """A fresh planner for one robot: ``name`` (default ``params.planner``) seeded from
    (``params.seed``, ``robot_id``)."""
    key = name or params.planner
    if key not in PLANNERS:
        raise KeyError(f"unknown planner {key!r}; known: {', '.join(sorted(PLANNERS))}")
    return PLANNERS[key](params, np.random.default_rng([params.seed, robot_id]))


def make_termination(params: PlannerParams, name: str | None = None) -> Termination:
    """One robot's planning termination for this frame: ``deadline_ms`` from now or the work budget
    of planner ``name`` (default ``params.planner``), whichever comes first."""
    key = name or params.planner
    work: int = getattr(params, key).work_budget
    return deadline(params.deadline_ms * 1e-3) | budget(work)
