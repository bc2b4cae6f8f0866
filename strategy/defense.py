"""Our goal's defense: the goalie (blocking, or clearing a ball at rest in our area; with
``goalie_reflex`` the escape/evade reflex of seed 003 turned round toward a shot's line) and the
defenders' slots on the edge of our defense area. Field frame, metres, radians."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from cmdragons.config import Validated, setting
from cmdragons.geometry import Field
from cmdragons.messages import BallState, RobotState
from cmdragons.navigation.escape_evade import EscapeEvadeParams, reflex
from strategy.skills import Intent, SkillParams, goalie_block, kick_to

__all__ = ["DefenseParams", "ball_to_clear", "clear_target", "defender_slots", "goalie", "goalie_reflex"]


@dataclass(frozen=True)
class DefenseParams(Validated):
    defenders: int = setting(2, lo=0, hi=10)
    defender_spacing_m: float = setting(0.32, lo=0.0, hi=3.0)  # centre to centre: room to be pushed without touching
    clear_ball_speed_m_s: float = setting(0.5, lo=0.0, hi=10.0)  # a ball slower than this in our area is cleared
    clear_depth_share: float = setting(0.5, lo=0.0, hi=1.0)  # ... toward this share of their half deep
    clear_width_share: float = setting(0.6, lo=0.0, hi=1.0)  # ... and this share of the half width out, its side
    clear_kick_m_s: float = setting(4.0, lo=0.1, hi=10.0)  # ... kicked this fast
    goalie_reflex: bool = setting(False)  # the goalie's escape/evade reflex toward a shot's line
    goalie_reflex_gain_s: float = setting(0.3, lo=0.0, hi=5.0)  # its vector (m/s) times this: the step (m)
    goalie_reflex_evade: EscapeEvadeParams = EscapeEvadeParams()  # the reflex's vectors (the ball the object)


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
            math.copysign(pitch.half_width * p.clear_width_share, ball.y or 1.0))


def goalie(robot: RobotState, ball: BallState, pitch: Field, own_sign: float, p: DefenseParams,
           skills: SkillParams) -> tuple[Intent, bool]:
    """The goalie's intent, and whether it clears the ball (a kick) rather than blocks."""
    if ball_to_clear(ball, pitch, own_sign, p):
        intent = kick_to(robot, ball, clear_target(ball, pitch, own_sign, p), p.clear_kick_m_s, skills)
        return dataclasses.replace(intent, allow_own_defense=True), True
    intent = goalie_block(ball, pitch, own_sign, skills)
    if p.goalie_reflex:
        intent = goalie_reflex(intent, robot, ball, pitch, own_sign, p, skills)
    return intent, False


def goalie_reflex(intent: Intent, robot: RobotState, ball: BallState, pitch: Field, own_sign: float,
                  p: DefenseParams, skills: SkillParams) -> Intent:
    """The escape/evade reflex (seed 003 §5.1) turned round for the goalie: while the ball runs at
    our goal line, blocking's point moves along the goalie's line toward the ball's path by
    ``goalie_reflex_gain_s`` times the part along the line of the fused vector at the goalie (the
    vector pushes off the path; the goalie goes the other way), never past the path nor a post."""
    if ball.vx * own_sign <= 0.0:
        return intent
    t = (intent.x - ball.x) / ball.vx
    if t <= 0.0:
        return intent
    path_y = ball.y + ball.vy * t  # where the ball's path crosses the goalie's line
    objects = np.array([[ball.x, ball.y, ball.vx, ball.vy, 0.0, 0.0, 0.0]])
    _, ry = reflex((robot.x, robot.y), objects, p.goalie_reflex_evade)
    step, gap = -p.goalie_reflex_gain_s * ry, path_y - intent.y
    if step * gap <= 0.0:
        return intent  # nothing repels, or not toward the path (blocking's point on it already)
    half = pitch.goal_half_width - skills.robot_radius_m * skills.goalie_post_share
    y = min(max(intent.y + math.copysign(min(abs(step), abs(gap)), step), -half), half)
    return dataclasses.replace(intent, y=y, theta=math.atan2(ball.y - y, ball.x - intent.x))
