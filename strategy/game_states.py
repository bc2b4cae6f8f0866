"""Game states and set plays: what the rules ask of our robots outside normal play.

Halt: everyone stands. Stop: every robot at least ``stop_distance_m`` from the ball and slow.
Their kickoff or free kick: the same distance (at a kickoff also in our half, outside the centre
circle). Our kickoff: everyone but the kicker in our half, outside the centre circle. No ball
seen yet: a defensive shape in our half. Field frame, metres, radians.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass

from cmdragons.config import Validated, setting
from cmdragons.geometry import Field, Team
from cmdragons.messages import BallState, GameState, RobotState
from strategy.skills import Intent

__all__ = ["GameStateParams", "halt", "hold_shape", "keep_away", "our_kickoff", "own_goal_sign", "restart_rules"]


@dataclass(frozen=True)
class GameStateParams(Validated):
    stop_distance_m: float = setting(0.65, lo=0.5, hi=3.0)  # rule: 0.5 m from the ball in a stop, plus margin
    stop_speed_m_s: float = setting(1.2, lo=0.1, hi=5.0)  # rule: 1.5 m/s in a stop, minus margin
    center_circle_margin_m: float = setting(0.15, lo=0.0, hi=2.0)  # kept outside the centre circle at kickoffs
    halfway_margin_m: float = setting(0.05, lo=0.0, hi=1.0)  # robots' edge this far on our side of the halfway line
    free_spot_steps: int = setting(12, lo=1, hi=180)  # the circle round the ball searched in steps of pi / this
    hold_depth_share: float = setting(0.3, lo=0.0, hi=1.0)  # no ball: the shape starts this share of our half deep
    hold_row_m: float = setting(0.4, lo=0.0, hi=3.0)  # ... its rows this far apart
    hold_rows: int = setting(3, lo=1, hi=11)
    hold_spacing_m: float = setting(0.6, lo=0.0, hi=3.0)  # ... its robots this far apart across the field


def own_goal_sign(team: Team, game: GameState) -> float:
    """-1.0 when ``team`` defends the goal at negative x, else +1.0."""
    return -1.0 if (team == "blue") == game.blue_defends_negative_x else 1.0


def halt(own: Mapping[int, RobotState]) -> dict[int, Intent]:
    """Every robot stands where it is."""
    return {rid: Intent(r.x, r.y, r.theta, max_speed_m_s=0.0) for rid, r in own.items()}


def hold_shape(own: Mapping[int, RobotState], pitch: Field, own_sign: float, p: GameStateParams) -> dict[int, Intent]:
    """No ball seen yet: a defensive shape in our half, rows of ``hold_rows``."""
    out = {}
    for k, rid in enumerate(sorted(own)):
        x = own_sign * (pitch.half_length * p.hold_depth_share + p.hold_row_m * (k % p.hold_rows))
        y = (k - len(own) / 2) * p.hold_spacing_m
        out[rid] = Intent(x, y, 0.0 if own_sign < 0 else math.pi)
    return out


def _in_own_half(x: float, own_sign: float, radius: float, p: GameStateParams) -> float:
    """``x`` moved into our half, the robot's edge ``halfway_margin_m`` short of the halfway line."""
    return own_sign * max(own_sign * x, radius + p.halfway_margin_m)


def _circle_clearance(pitch: Field, radius: float, p: GameStateParams) -> float:
    """How far a robot's centre keeps from the centre spot at kickoffs."""
    return pitch.dims.center_circle_radius_m + p.center_circle_margin_m + radius


def our_kickoff(intents: Mapping[int, Intent], pitch: Field, own_sign: float, p: GameStateParams, radius: float,
                kicker: int | None) -> dict[int, Intent]:  # fmt: skip
    """At our kickoff everyone but the kicker stays in our half, outside the centre circle (moved
    sideways out of it)."""
    out = {}
    r_c = _circle_clearance(pitch, radius, p)
    for rid, it in intents.items():
        if rid == kicker:
            out[rid] = it
            continue
        x = _in_own_half(it.x, own_sign, radius, p)
        y = it.y
        if math.hypot(x, y) < r_c:
            y = math.copysign(r_c, y if y != 0 else 1.0)
        out[rid] = dataclasses.replace(it, x=x, y=y)
    return out


def keep_away(intents: Mapping[int, Intent], ball: BallState, pitch: Field, own_sign: float, p: GameStateParams,
              radius: float, kickoff: bool, slow: bool,
              distance_m: float | None = None) -> dict[int, Intent]:  # fmt: skip
    """Every target at least ``distance_m`` (default ``stop_distance_m``: the rules' 0.5 m plus a
    margin) from the ball, on the field; at their kickoff also in our half and outside the centre
    circle; slow (``stop_speed_m_s``) in a stop. ``radius``: the robots'."""
    out = {}
    d_min = (p.stop_distance_m if distance_m is None else distance_m) + radius
    r_c = _circle_clearance(pitch, radius, p)
    for rid, it in intents.items():
        x, y = it.x, it.y
        if kickoff:
            x = _in_own_half(x, own_sign, radius, p)
            if math.hypot(x, y) < r_c:
                ang = math.atan2(y, x) if math.hypot(x, y) > 1e-6 else (0.0 if own_sign > 0 else math.pi)
                x, y = r_c * math.cos(ang), r_c * math.sin(ang)
        dx, dy = x - ball.x, y - ball.y
        d = math.hypot(dx, dy)
        if d < d_min:
            if d < 1e-6:
                dx, dy, d = own_sign, 0.0, 1.0
            # the nearest point of the circle around the ball that lies on the field (where the cameras see us)
            lim_x, lim_y = pitch.half_length - radius, pitch.half_width - radius
            base = math.atan2(dy, dx)
            steps = p.free_spot_steps
            for turn in (0.0, *(sign * k * math.pi / steps for k in range(1, steps + 1) for sign in (1.0, -1.0))):
                x, y = ball.x + d_min * math.cos(base + turn), ball.y + d_min * math.sin(base + turn)
                if abs(x) <= lim_x and abs(y) <= lim_y:
                    break
        out[rid] = Intent(x, y, it.theta, dribbler=0.0, avoid_ball=True, allow_own_defense=it.allow_own_defense,
                          max_speed_m_s=p.stop_speed_m_s if slow else it.max_speed_m_s)  # fmt: skip
    return out


def restart_rules(intents: Mapping[int, Intent], game: GameState, ours: bool, ball: BallState, pitch: Field,
                  own_sign: float, p: GameStateParams, radius: float,
                  kicker: int | None) -> dict[int, Intent]:  # fmt: skip
    """The normal-play ``intents`` held to the rules of ``game``'s command: keep away in a stop and
    at their kickoff or free kick, our half at our kickoff (``kicker`` excepted). ``ours``: the
    restart is for our team."""
    out = dict(intents)
    if game.command == "stop" or (game.command in ("kickoff", "free_kick") and not ours):
        out = keep_away(out, ball, pitch, own_sign, p, radius, game.command == "kickoff", game.command == "stop")
    if game.command == "kickoff" and ours:
        out = our_kickoff(out, pitch, own_sign, p, radius, kicker)
    return out
