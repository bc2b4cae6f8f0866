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
                           collision or CollisionParams())


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
    ])
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
                 p_turn: float = 0.02) -> None:
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


class CrowdScene:
    """Hard replanning (Bruce 2006 §4.3.1): two crowds of robots, each a ring around a free pocket
    with one narrow gap, drift and turn about the field, one in each half; our robot shuttles
    between the pockets (its goal is the centre of the pocket it is not in). The straight line is
    blocked by both rings, and a tree has to find the gap out of one pocket and into the other,
    which takes an ERRT without a waypoint cache hundreds of iterations. The remaining robots
    (up to 21 in all) wander as in :class:`MovingScene`.

    ``ring_m``: ring radius (robot centres); ``gap_m``: the free width of the gap for the robot's
    centre (0.0 would close it); robots on the ring are ``spacing_m`` apart (a closed wall when
    under two grown radii, 0.36 m)."""

    def __init__(self, field: Field, rng: np.random.Generator, n_robots: int = 21, ring_m: float = 0.55,
                 gap_m: float = 0.12, spacing_m: float = 0.3, max_speed_m_s: float = 0.8,
                 max_turn_rad_s: float = 0.5) -> None:
        self.field = field
        self.rng = rng
        r = field.league.robot.radius_m
        block = 4.0 * r  # centre distance of two robots that touch when grown by the robot's radius
        # angles of the ring's robots: the gap is between the last and the first
        gap_angle = 2.0 * np.arcsin(min(1.0, (block + gap_m) / (2.0 * ring_m)))
        step = 2.0 * np.arcsin(min(1.0, spacing_m / (2.0 * ring_m)))
        n_ring = int((2.0 * np.pi - gap_angle) // step) + 1
        self.ring_angles = np.arange(n_ring) * (2.0 * np.pi - gap_angle) / (n_ring - 1)
        self.ring_m = ring_m
        # each crowd roams one half, clear of the defense areas
        x_lim = field.half_length - field.dims.defense_depth_m - ring_m - 2 * r
        y_lim = field.half_width - ring_m - 2 * r
        self.box = np.array([[-x_lim, -y_lim, -ring_m - 2 * r, y_lim], [ring_m + 2 * r, -y_lim, x_lim, y_lim]])
        self.centre = np.column_stack([rng.uniform(self.box[:, 0], self.box[:, 2]),
                                       rng.uniform(self.box[:, 1], self.box[:, 3])])
        speed = rng.uniform(0.2, max_speed_m_s, 2)
        heading = rng.uniform(-np.pi, np.pi, 2)
        self.vel = np.column_stack([speed * np.cos(heading), speed * np.sin(heading)])
        # the gaps start facing away from each other (the straight line hits both rings)
        self.theta = np.array([np.pi, 0.0]) + rng.uniform(-0.5, 0.5, 2) + gap_angle / 2.0
        self.omega = rng.uniform(-max_turn_rad_s, max_turn_rad_s, 2)
        n_free = max(0, n_robots - 2 * n_ring)
        others = random_scene(field, rng, max_robots=max(1, n_free), max_speed_m_s=max_speed_m_s)
        self.wander = MovingScene(field, Scene(others.robots[:n_free], others.velocities[:n_free],
                                               (0.0, 0.0), (0.0, 0.0)), rng, max_speed_m_s)
        self.target = 1  # the pocket our robot heads for

    @property
    def robots(self) -> FloatArray:
        return np.vstack([self._ring(0)[0], self._ring(1)[0], self.wander.pos])

    @property
    def velocities(self) -> FloatArray:
        return np.vstack([self._ring(0)[1], self._ring(1)[1], self.wander.vel])

    def _ring(self, k: int) -> tuple[FloatArray, FloatArray]:
        a = self.ring_angles + self.theta[k]
        off = self.ring_m * np.column_stack([np.cos(a), np.sin(a)])
        vel = self.vel[k] + self.omega[k] * np.column_stack([-off[:, 1], off[:, 0]])
        return self.centre[k] + off, vel

    def pocket(self, k: int) -> tuple[float, float]:
        return float(self.centre[k, 0]), float(self.centre[k, 1])

    def step(self, dt_s: float) -> None:
        self.centre += self.vel * dt_s
        self.theta += self.omega * dt_s
        lo, hi = self.box[:, :2], self.box[:, 2:]
        out = (self.centre < lo) | (self.centre > hi)
        self.vel[out] *= -1.0
        self.centre = np.clip(self.centre, lo, hi)
        self.wander.step(dt_s)
