"""Seeded small-size planning scenes for the benchmark and the tests (field frame, metres, m/s).

A scene is a Division B field with its defense areas and goal walls, up to 21 other robots and a
random free start and goal. :class:`MovingScene` lets the robots drive about (bouncing off the
field lines, changing course now and then) for replanning at the camera rate.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from cmdragons.geometry import Field
from cmdragons.planning.problem import PlanProblem
from cmdragons.planning.world import CollisionParams, field_world

__all__ = ["MovingScene", "Scene", "random_free_point", "random_scene"]

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class Scene:
    robots: FloatArray  # (n, 2) other robots' centres
    velocities: FloatArray  # (n, 2)
    start: tuple[float, float]
    goal: tuple[float, float]

    def problem(self, field: Field, collision: CollisionParams | None = None, horizon_s: float = 0.0) -> PlanProblem:
        world = field_world(field, self.robots, self.velocities)
        return PlanProblem(self.start, self.goal, field.league.robot.radius_m, world, horizon_s,
                           collision or CollisionParams())  # fmt: skip


def random_free_point(
    field: Field, probe: PlanProblem, rng: np.random.Generator, margin_m: float
) -> tuple[float, float]:
    """A uniform point of the playing area (inside the field lines, ``margin_m`` in) that is free
    in ``probe``'s world."""
    cw = probe.compiled()
    for _ in range(10000):
        x = rng.uniform(-field.half_length + margin_m, field.half_length - margin_m)
        y = rng.uniform(-field.half_width + margin_m, field.half_width - margin_m)
        if cw.point_free(x, y):
            return float(x), float(y)
    raise RuntimeError("no free point found: the scene is full")


def random_scene(field: Field, rng: np.random.Generator, max_robots: int = 21, max_speed_m_s: float = 2.0) -> Scene:
    """Between 1 and ``max_robots`` robots anywhere in the playing area, moving at up to
    ``max_speed_m_s``, and a free start and goal at least a metre apart."""
    n = int(rng.integers(1, max_robots + 1))
    r = field.league.robot.radius_m
    robots = np.column_stack([
        rng.uniform(-field.half_length + r, field.half_length - r, n),
        rng.uniform(-field.half_width + r, field.half_width - r, n),
    ])  # fmt: skip
    speed = rng.uniform(0.0, max_speed_m_s, n)
    heading = rng.uniform(-np.pi, np.pi, n)
    vel = np.column_stack([speed * np.cos(heading), speed * np.sin(heading)])
    probe = Scene(robots, vel, (0.0, 0.0), (0.0, 0.0)).problem(field)
    margin = 2 * r
    while True:
        start = random_free_point(field, probe, rng, margin)
        goal = random_free_point(field, probe, rng, margin)
        if np.hypot(goal[0] - start[0], goal[1] - start[1]) >= 1.0:
            return Scene(robots, vel, start, goal)


class MovingScene:
    """A scene whose robots move on: straight at their velocity, bouncing off the field lines, and
    turning to a new random velocity with probability ``p_turn`` a frame."""

    def __init__(self, field: Field, scene: Scene, rng: np.random.Generator, max_speed_m_s: float = 2.0,
                 p_turn: float = 0.02) -> None:  # fmt: skip
        self.field = field
        self.rng = rng
        self.pos = scene.robots.copy()
        self.vel = scene.velocities.copy()
        self.max_speed = max_speed_m_s
        self.p_turn = p_turn

    def step(self, dt_s: float) -> None:
        r = self.field.league.robot.radius_m
        self.pos += self.vel * dt_s
        lim = np.array([self.field.half_length - r, self.field.half_width - r])
        out = np.abs(self.pos) > lim
        self.vel[out] *= -1.0
        self.pos = np.clip(self.pos, -lim, lim)
        turn = self.rng.random(len(self.pos)) < self.p_turn
        if turn.any():
            k = int(turn.sum())
            speed = self.rng.uniform(0.0, self.max_speed, k)
            heading = self.rng.uniform(-np.pi, np.pi, k)
            self.vel[turn] = np.column_stack([speed * np.cos(heading), speed * np.sin(heading)])
