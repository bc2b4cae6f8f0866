"""Shared scenes of the planning tests: the Division B field of the shipped defaults."""

from __future__ import annotations

import numpy as np
import pytest

from cmdragons.geometry import Field, LeagueParams
from cmdragons.planning import CollisionWorld, PlanProblem, field_world

RADIUS_M = 0.09


@pytest.fixture(scope="session")
def field() -> Field:
    return Field(LeagueParams())


def ring(centre: tuple[float, float], radius_m: float, n: int) -> np.ndarray:
    """n robot centres on a circle: a ring of robots closer than a robot's width is a closed wall."""
    a = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
    return np.column_stack([centre[0] + radius_m * np.cos(a), centre[1] + radius_m * np.sin(a)])


def problem(world: CollisionWorld, start: tuple[float, float], goal: tuple[float, float]) -> PlanProblem:
    return PlanProblem(start, goal, RADIUS_M, world)


def wall_with_gap(field: Field) -> CollisionWorld:
    """A wall of robots across the field at x = 0 with one gap (at y = 1.5) a robot fits through."""
    ys = [y for y in np.arange(-3.0, 3.01, 0.15) if abs(y - 1.5) > 0.3]
    return field_world(field, np.column_stack([np.zeros(len(ys)), ys]))
