"""Our goal's defense: the goalie (blocking, or clearing a ball at rest in our area) and the
defenders' slots on the edge of our defense area. Field frame, metres, radians."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from cmdragons.config import Validated, setting
from cmdragons.geometry import Field
from cmdragons.messages import BallState, RobotState
from strategy.skills import Intent, SkillParams, goalie_block, kick_to

__all__ = ["DefenseParams", "ball_to_clear", "clear_target", "defender_slots", "goalie"]


@dataclass(frozen=True)
class DefenseParams(Validated):
    defenders: int = setting(2, lo=0, hi=10)
    defender_spacing_m: float = setting(0.32, lo=0.0, hi=3.0)  # centre to centre: room to be pushed without touching
    clear_ball_speed_m_s: float = setting(0.5, lo=0.0, hi=10.0)  # a ball slower than this in our area is cleared
    clear_depth_share: float = setting(0.5, lo=0.0, hi=1.0)  # ... toward this share of their half deep
    clear_width_share: float = setting(0.6, lo=0.0, hi=1.0)  # ... and this share of the half width out, its side
    clear_kick_m_s: float = setting(4.0, lo=0.1, hi=10.0)  # ... kicked this fast


def defender_slots(p: DefenseParams) -> list[float]:
    """The defenders' sideways offsets (m) along the edge of the area, ``defender_spacing_m`` apart."""
    half_span = 0.5 * p.defender_spacing_m * (p.defenders - 1)
    return [0.0] if p.defenders == 1 else [float(s) for s in np.linspace(-half_span, half_span, p.defenders)]


def ball_to_clear(ball: BallState, pitch: Field, own_sign: float, p: DefenseParams) -> bool:
    """The ball lies (nearly) still in our defense area: the goalie clears it."""
    inside = pitch.in_defense_area(ball.x, ball.y) == int(own_sign)
    return inside and math.hypot(ball.vx, ball.vy) < p.clear_ball_speed_m_s


def clear_target(ball: BallState, pitch: Field, own_sign: float, p: DefenseParams) -> tuple[float, float]:
    """Where the goalie clears the ball to: up the field in their half, out on the ball's side (away
    from the middle)."""
    return (-own_sign * pitch.half_length * p.clear_depth_share,
            math.copysign(pitch.half_width * p.clear_width_share, ball.y or 1.0))  # fmt: skip


def goalie(robot: RobotState, ball: BallState, pitch: Field, own_sign: float, p: DefenseParams,
           skills: SkillParams) -> tuple[Intent, bool]:  # fmt: skip
    """The goalie's intent, and whether it clears the ball (a kick) rather than blocks."""
    if ball_to_clear(ball, pitch, own_sign, p):
        intent = kick_to(robot, ball, clear_target(ball, pitch, own_sign, p), p.clear_kick_m_s, skills)
        return dataclasses.replace(intent, allow_own_defense=True), True
    return goalie_block(ball, pitch, own_sign, skills), False
