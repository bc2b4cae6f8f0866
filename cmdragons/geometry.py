"""Field geometry of the small-size league, robot and ball shapes, the standard robot pattern.

Field frame: origin at the centre spot, x along the long side, y to the left, metres, angles in
radians counter-clockwise from +x. All dimensions come from ``configs/field.yaml``
(:class:`LeagueParams`); :class:`Field` derives the lines, goals and areas from them.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Literal, TypeVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from cmdragons.config import Validated, setting

__all__ = [
    "BallShape",
    "Field",
    "FieldDims",
    "LeagueParams",
    "PatternGeometry",
    "RobotShape",
    "Team",
    "path_length",
    "rotate",
    "wrap_angle",
]

Team = Literal["blue", "yellow"]
TEAMS: tuple[Team, Team] = ("blue", "yellow")


AngleT = TypeVar("AngleT", float, NDArray[np.float64])


def wrap_angle(a: AngleT) -> AngleT:
    """Angle(s) wrapped into [-pi, pi): a float, or element-wise an array (radians)."""
    return (a + math.pi) % (2.0 * math.pi) - math.pi


def path_length(path: ArrayLike) -> float:
    """Length (m) of a polyline (k, 2)."""
    pts = np.asarray(path, dtype=np.float64).reshape(-1, 2)
    return float(np.hypot(*np.diff(pts, axis=0).T).sum())


def rotate(v: NDArray[np.float64], theta: float) -> NDArray[np.float64]:
    """Rotate 2D vector(s) of shape (..., 2) counter-clockwise by ``theta`` radians."""
    c, s = math.cos(theta), math.sin(theta)
    out = np.empty_like(v, dtype=np.float64)
    out[..., 0] = c * v[..., 0] - s * v[..., 1]
    out[..., 1] = s * v[..., 0] + c * v[..., 1]
    return out


@dataclass(frozen=True)
class FieldDims(Validated):
    """One division's field dimensions (SSL rules), metres."""

    length_m: float = setting(9.0, lo=1.0, hi=30.0)  # goal line to goal line
    width_m: float = setting(6.0, lo=1.0, hi=30.0)  # touch line to touch line
    boundary_width_m: float = setting(0.3, lo=0.0, hi=2.0)  # lines to the boundary wall
    goal_width_m: float = setting(1.0, lo=0.1, hi=5.0)  # inner width between the posts
    goal_depth_m: float = setting(0.18, lo=0.05, hi=1.0)  # inner depth behind the goal line
    goal_wall_thickness_m: float = setting(0.02, lo=0.001, hi=0.2)
    goal_height_m: float = setting(0.155, lo=0.05, hi=1.0)
    defense_width_m: float = setting(2.0, lo=0.1, hi=10.0)  # along the goal line (y)
    defense_depth_m: float = setting(1.0, lo=0.1, hi=10.0)  # into the field (x)
    center_circle_radius_m: float = setting(0.5, lo=0.05, hi=5.0)
    line_width_m: float = setting(0.01, lo=0.001, hi=0.2)
    robots_per_team: int = setting(6, lo=0, hi=16)  # the league's count for this division
    center_circle: bool = True  # painted; false on a lab field without one
    goal_to_goal_line: bool = True  # the line along x through the centre spot; false where it is not painted
    # the touch and goal lines: painted, or the bases of walls standing where they would be
    # (a lab field: line calibration then leaves them out)
    outer_lines: Literal["painted", "walls"] = "painted"

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.goal_width_m >= self.width_m:
            raise ValueError("goal_width_m must be smaller than width_m")
        if self.defense_width_m >= self.width_m or 2 * self.defense_depth_m >= self.length_m:
            raise ValueError("the defense areas must fit inside the field")


@dataclass(frozen=True)
class RobotShape(Validated):
    """A robot: its body, a cylinder cut flat at the front (the dribbler and kicker side), and what
    its motors can do (the one place these facts are configured: the simulator, motion control,
    the safety search and the tracker all take them from here)."""

    radius_m: float = setting(0.09, lo=0.02, hi=0.5)
    height_m: float = setting(0.15, lo=0.02, hi=0.5)
    front_distance_m: float = setting(0.07, lo=0.01, hi=0.5)  # centre to the flat front face
    max_speed_m_s: float = setting(3.0, lo=0.01, hi=10.0)
    max_accel_m_s2: float = setting(3.0, lo=0.01, hi=50.0)  # speeding up or turning the velocity
    max_brake_m_s2: float = setting(6.0, lo=0.01, hi=50.0)  # slowing down
    max_omega_rad_s: float = setting(20.0, lo=0.01, hi=100.0)
    max_alpha_rad_s2: float = setting(60.0, lo=0.01, hi=1000.0)  # angular acceleration and braking
    command_latency_s: float = setting(0.03, lo=0.0, hi=1.0)  # command sent -> wheels act on it
    min_kick_m_s: float = setting(0.5, lo=0.01, hi=10.0)  # the kicker's slowest kick, relative to the robot
    # the ball leaves at this share of the kick asked (1: as asked; another simulator's or a real
    # kicker differs, and the tracker measures it: tracker.yaml physics)
    kick_gain: float = setting(1.0, lo=0.1, hi=3.0)
    # the share of the ball's velocity across the heading (relative to the robot) that a kick keeps:
    # a one-touch kick aims with it (strategy.onetouch); the tracker measures it
    kick_retention: float = setting(0.3, lo=0.0, hi=1.5)
    # the fastest kick a gain makes the team send (the rules allow the ball 6.5 m/s: a gain learnt on
    # passes must not push a shot over it)
    max_kick_m_s: float = setting(6.0, lo=0.1, hi=20.0)

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.front_distance_m >= self.radius_m:
            raise ValueError("front_distance_m must be smaller than radius_m")

    def kicker_speed(self, ground_m_s: float, forward_m_s: float) -> float:
        """The kicker's speed that sends the ball off at ``ground_m_s`` over the ground from a robot
        moving ``forward_m_s`` along its heading: a kicker fires relative to the robot that carries
        it (in every simulator and on the field), so the robot's own speed adds to the kick; never
        below ``min_kick_m_s``; 0 (no kick) stays 0."""
        if ground_m_s <= 0.0:
            return 0.0
        return max(ground_m_s - forward_m_s, self.min_kick_m_s)

    @property
    def mouth_half_width_m(self) -> float:
        """Half the width of the flat front face."""
        return math.sqrt(self.radius_m**2 - self.front_distance_m**2)

    def gap(self, x: float, y: float) -> float:
        """From the point (``x``, ``y``) in the robot frame (m) to the body, the disc cut flat at the
        front; negative inside (as deep as the point is in)."""
        r, f = self.radius_m, self.front_distance_m
        d = math.hypot(x, y)
        if d <= r and x <= f:
            return -min(r - d, f - x)
        if d > r and x * r <= f * d:  # the nearest point of the body lies on its round side
            return d - r
        return math.hypot(x - f, max(abs(y) - self.mouth_half_width_m, 0.0))  # ... else on the flat front

    def outline(self, n: int = 24) -> NDArray[np.float64]:
        """Convex outline in the robot frame (x forward), counter-clockwise, shape (k, 2)."""
        a0 = math.atan2(self.mouth_half_width_m, self.front_distance_m)
        angles = np.linspace(a0, 2.0 * math.pi - a0, n)
        return np.stack([self.radius_m * np.cos(angles), self.radius_m * np.sin(angles)], axis=1)


@dataclass(frozen=True)
class BallShape(Validated):
    """The ball and how it rolls on the carpet: the two-phase model (it slides at ``acc_slide``
    after a kick or bounce until its speed falls to ``slide_to_roll_fraction`` of the speed the slide
    began with, then rolls at ``acc_roll``), configured once for the simulator, tracker and strategy."""

    radius_m: float = setting(0.0215, lo=0.005, hi=0.2)
    acc_slide_m_s2: float = setting(3.0, lo=0.0, hi=50.0)  # deceleration while sliding
    acc_roll_m_s2: float = setting(0.26, lo=0.0, hi=10.0)  # deceleration while rolling
    slide_to_roll_fraction: float = setting(0.64, lo=0.0, hi=1.0)  # of the speed the slide began with


_DEFAULT_DOTS = ((0.035, 0.054772), (0.035, -0.054772), (-0.054772, 0.035), (-0.054772, -0.035))
_DEFAULT_IDS = (
    "PPGP", "GPGP", "GGGP", "PGGP", "PPPG", "GPPG", "GGPG", "PGPG",
    "GGGG", "PPPP", "PPGG", "GGPP", "GPGG", "GPPP", "PGGG", "PGPP",
)


@dataclass(frozen=True)
class PatternGeometry(Validated):
    """The league's standard robot top pattern (2010): robot frame, metres.

    ``ids[i]`` lists the colours of the id dots in the order of ``dot_positions_m``
    (front-left, front-right, back-left, back-right), P for pink and G for green.
    """

    center_dot_diameter_m: float = setting(0.05, lo=0.005, hi=0.2)
    id_dot_diameter_m: float = setting(0.04, lo=0.005, hi=0.2)
    dot_positions_m: tuple[tuple[float, float], ...] = _DEFAULT_DOTS
    ids: tuple[str, ...] = _DEFAULT_IDS

    def __post_init__(self) -> None:
        super().__post_init__()
        for code in self.ids:
            if len(code) != len(self.dot_positions_m) or set(code) - {"P", "G"}:
                raise ValueError(
                    f"pattern id {code!r} must have one letter P or G per id dot ({len(self.dot_positions_m)})"
                )
        if len(set(self.ids)) != len(self.ids):
            raise ValueError("pattern ids must be distinct")

    def dot_is_pink(self, robot_id: int) -> tuple[bool, ...]:
        return tuple(c == "P" for c in self.ids[robot_id % len(self.ids)])


@dataclass(frozen=True)
class LeagueParams(Validated):
    """configs/field.yaml: the division in force and the league's fixed shapes."""

    division: Literal["A", "B"] = "B"
    divisions: Mapping[Literal["A", "B"], FieldDims] = field(
        default_factory=lambda: {
            "B": FieldDims(),
            "A": FieldDims(
                length_m=12.0, width_m=9.0, goal_width_m=1.8, defense_width_m=3.6, defense_depth_m=1.8,
                robots_per_team=11,
            ),
        }
    )
    robot: RobotShape = RobotShape()
    ball: BallShape = BallShape()
    pattern: PatternGeometry = PatternGeometry()

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.division not in self.divisions:
            raise ValueError(f"division {self.division!r} has no entry under divisions")

    @property
    def dims(self) -> FieldDims:
        return self.divisions[self.division]


@dataclass(frozen=True)
class Segment:
    a: tuple[float, float]
    b: tuple[float, float]


class Field:
    """Derived field geometry for one division: lines, goals, defense areas, legality tests."""

    def __init__(self, league: LeagueParams) -> None:
        self.league = league
        d = league.dims
        self.dims = d
        self.half_length = d.length_m / 2.0
        self.half_width = d.width_m / 2.0
        self.boundary_half_length = self.half_length + d.boundary_width_m
        self.boundary_half_width = self.half_width + d.boundary_width_m
        self.goal_half_width = d.goal_width_m / 2.0

    # --- markings -------------------------------------------------------------------------
    def line_segments(self) -> list[Segment]:
        """Straight field markings (centre lines of the painted lines)."""
        hl, hw = self.half_length, self.half_width
        dd, dw = self.dims.defense_depth_m, self.dims.defense_width_m / 2.0
        segs = [
            Segment((-hl, -hw), (hl, -hw)),
            Segment((-hl, hw), (hl, hw)),
            Segment((-hl, -hw), (-hl, hw)),
            Segment((hl, -hw), (hl, hw)),
            Segment((0.0, -hw), (0.0, hw)),
            Segment((-hl, 0.0), (hl, 0.0)),
        ]
        for s in (-1.0, 1.0):
            x0, x1 = s * hl, s * (hl - dd)
            segs += [Segment((x0, -dw), (x1, -dw)), Segment((x0, dw), (x1, dw)), Segment((x1, -dw), (x1, dw))]
        return segs

    def painted_segments(self, outer: bool = True) -> list[Segment]:
        """The straight markings painted on this field: :meth:`line_segments` without the line
        from goal to goal where field.yaml says none is painted, and without the touch and goal
        lines when ``outer`` is false."""
        segs = self.line_segments()
        keep = [outer] * 4 + [True, self.dims.goal_to_goal_line] + [True] * (len(segs) - 6)
        return [s for s, k in zip(segs, keep, strict=True) if k]

    def goal_walls(self, side: float) -> list[tuple[float, float, float, float]]:
        """Goal walls of the goal at x = side * half_length as axis-aligned boxes (x0, y0, x1, y1)."""
        hl, gw = self.half_length, self.goal_half_width
        depth, t = self.dims.goal_depth_m, self.dims.goal_wall_thickness_m
        x_back0, x_back1 = hl + depth, hl + depth + t
        boxes = [
            (x_back0, -gw - t, x_back1, gw + t),  # back wall
            (hl, gw, hl + depth, gw + t),  # left side wall
            (hl, -gw - t, hl + depth, -gw),  # right side wall
        ]
        if side < 0:
            boxes = [(-b[2], b[1], -b[0], b[3]) for b in boxes]
        return boxes

    # --- tests ------------------------------------------------------------------------------
    def in_field(self, x: float, y: float, margin: float = 0.0) -> bool:
        """Inside the playing area (lines included), shrunk by ``margin``."""
        return abs(x) <= self.half_length - margin and abs(y) <= self.half_width - margin

    def in_goal(self, x: float, y: float) -> int:
        """+1 inside the goal at +x, -1 inside the goal at -x, 0 elsewhere (past the goal line)."""
        if abs(y) < self.goal_half_width and self.half_length < abs(x) <= self.half_length + self.dims.goal_depth_m:
            return 1 if x > 0 else -1
        return 0

    def in_defense_area(self, x: float, y: float, margin: float = 0.0) -> int:
        """+1 / -1 inside the defense area at +x / -x (grown by ``margin``), 0 elsewhere."""
        dw = self.dims.defense_width_m / 2.0 + margin
        dd = self.dims.defense_depth_m + margin
        if abs(y) <= dw and self.half_length - dd <= abs(x) <= self.half_length + margin:
            return 1 if x > 0 else -1
        return 0

    def free_kick_spot(self, x: float, y: float, distance_m: float = 0.2) -> tuple[float, float]:
        """The nearest legal ball placement to (x, y): ``distance_m`` inside the field lines and
        outside both defense areas (SSL rules: 0.2 m from the boundary lines)."""
        px = min(max(x, -self.half_length + distance_m), self.half_length - distance_m)
        py = min(max(y, -self.half_width + distance_m), self.half_width - distance_m)
        side = self.in_defense_area(px, py, margin=distance_m)
        if side:
            dw = self.dims.defense_width_m / 2.0 + distance_m
            front = self.half_length - self.dims.defense_depth_m - distance_m
            # leave the area by its nearest edge: the front line or a side line
            to_front = abs(px) - front
            to_side = dw - abs(py)
            if to_front <= to_side:
                px = side * front
            else:
                py = math.copysign(dw, py if py != 0 else 1.0)
        return px, py
