"""``cmdragons bench goalie``: what the goalie's escape/evade reflex (``strategy.defense.goalie_reflex``,
seed 003 §5.1, :func:`strategy.defense.goalie_reflex`) is worth, measured on seeded shots at our goal.

Each shot: our goalie alone (blue robot 0, the whole brain: strategy, planning, navigation, control
and safety, on the true state), the ball at rest where a pass starts, the goalie given ``SETTLE_S``
to take its blocking place for it; then the pass rolls to the shooting point and there the ball is
redirected at a point of our goal mouth (a one-touch shot: the goalie stands on the line of the
pass's ball, not of the shot). Half the shots have no pass (a shot from the ball at rest). Pass
length, direction and speed, shooting point, target and shot speed come from the seed. A shot is on
target when it scores in an empty goal (the simulator's goal event within ``SHOT_S``: a slow ball
from far may stop short, one aimed at a post's edge may bounce out). The shots on target are taken
at our goalie with the reflex off and on: per setting the goals and the share of the shots on
target saved.

``--quick``: 16 shots (full: 120).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from cmdragons.messages import Goal, RefereeCommand
from cmdragons.runtime.settings import Settings
from cmdragons.team import Brain
from sim.referee import Referee
from sim.world import World
from strategy.game_states import own_goal_sign

__all__ = ["Shot", "run", "shoot", "shots", "with_reflex"]

SEED = 0
SHOTS, QUICK_SHOTS = 120, 16
SETTLE_S = 1.5  # the goalie takes its place for the ball at rest
SHOT_S = 3.0  # a shot's longest run
PASS_S = 3.0  # a pass's longest run (the shot follows when it reaches the shooting point)
FPS = 60
# where shots come from: this far from our goal line (m), across this share of the field's half width
DISTANCE_M = (1.5, 5.0)
WIDTH_SHARE = 0.8
SPEED_M_S = (1.0, 6.5)  # the kick's speed
MOUTH_SHARE = 0.95  # targets across this share of the goal's width
PASS_M = (0.5, 2.0)  # the pass's length
PASS_SPEED_M_S = (1.0, 3.0)  # and speed


@dataclass(frozen=True)
class Shot:
    """A shot in our goal's frame (x into the field from our goal line, y across): the pass from
    ``pass_from`` to ``point`` at ``pass_speed_m_s`` (none when they are the same), then the shot
    from ``point`` at ``target_y_m`` on our goal line, ``speed_m_s``."""

    pass_from: tuple[float, float]
    point: tuple[float, float]
    pass_speed_m_s: float
    target_y_m: float
    speed_m_s: float


def shots(n: int, seed: int, settings: Settings) -> list[Shot]:
    """``n`` seeded shots from outside our defense area at our goal mouth, every other one after a pass."""
    f = settings.field_geometry()
    rng = np.random.default_rng(seed)
    out: list[Shot] = []
    lo = max(DISTANCE_M[0], f.dims.defense_depth_m + 0.3)  # outside the area: a ball at rest there is cleared
    while len(out) < n:
        point = (float(rng.uniform(lo, DISTANCE_M[1])), float(rng.uniform(-1.0, 1.0) * WIDTH_SHARE * f.half_width))
        target = float(rng.uniform(-1.0, 1.0) * MOUTH_SHARE * f.goal_half_width)
        speed = float(rng.uniform(*SPEED_M_S))
        start, pass_speed = point, 0.0
        if len(out) % 2:
            a, length = float(rng.uniform(-math.pi, math.pi)), float(rng.uniform(*PASS_M))
            start = (point[0] + length * math.cos(a), point[1] + length * math.sin(a))
            pass_speed = float(rng.uniform(*PASS_SPEED_M_S))
            if not lo <= start[0] <= 2.0 * f.half_length - lo or abs(start[1]) > f.half_width - 0.1:
                continue  # a pass from outside the field or from within our defense area
        out.append(Shot(start, point, pass_speed, target, speed))
    return out


def shoot(settings: Settings, shot: Shot, goalie: bool = True) -> bool:
    """One shot at our goal, our goalie there (or none): whether it is a goal."""
    s = settings.sim
    robot = dataclasses.replace(s.robot, command_latency_s=0.0)  # the brain sees the truth of now
    w = World(settings.field, s.physics, robot, s.ball, s.kicker, s.dribbler,
              robots_per_team={"blue": int(goalie), "yellow": 0})
    ref = Referee(w.field, w.robot_keys(), s.referee)
    ref.give(RefereeCommand.FORCE_START)
    own = own_goal_sign("blue", ref.state())
    brain = Brain("blue", settings) if goalie else None
    goal_x = own * w.field.half_length
    if goalie:
        w.place_robot("blue", 0, goal_x - own * 0.3, 0.0, math.pi if own > 0 else 0.0)

    def field(p: tuple[float, float]) -> tuple[float, float]:
        return goal_x - own * p[0], p[1]

    (ax, ay), (bx, by) = field(shot.pass_from), field(shot.point)
    w.place_ball(ax, ay)
    start = round(SETTLE_S * FPS)
    rolling = shot.pass_speed_m_s > 0.0
    shot_at: int | None = None
    for k in range(start + round((PASS_S + SHOT_S) * FPS)):
        if k == start and rolling:
            d = math.hypot(bx - ax, by - ay)
            w.place_ball(ax, ay, shot.pass_speed_m_s * (bx - ax) / d, shot.pass_speed_m_s * (by - ay) / d)
        ball = w.ground_truth().ball
        reached = rolling and k > start and (ball.x - bx) * (bx - ax) + (ball.y - by) * (by - ay) >= 0.0
        if shot_at is None and (k == start and not rolling or reached):
            x, y = (ball.x, ball.y) if rolling else (bx, by)  # the one-touch shot where the pass got to
            dx, dy = goal_x - x, shot.target_y_m - y
            d = math.hypot(dx, dy)
            w.place_ball(x, y, shot.speed_m_s * dx / d, shot.speed_m_s * dy / d)
            shot_at = k
        commands = list(brain.step(w.ground_truth().world(), ref.state()).commands) if brain is not None else []
        events = w.step_frame(commands)
        if shot_at is not None and any(isinstance(e, Goal) and e.x * own > 0 for e in events):
            return True
        if shot_at is not None and k > shot_at + round(SHOT_S * FPS):
            break
    return False


def with_reflex(settings: Settings, on: bool) -> Settings:
    """``settings`` with the goalie's reflex on or off."""
    strategy = settings.strategy
    defense = dataclasses.replace(strategy.defense, goalie_reflex=on)
    return dataclasses.replace(settings, strategy=dataclasses.replace(strategy, defense=defense))


def run(settings: Settings, quick: bool) -> list[dict[str, Any]]:
    todo = shots(QUICK_SHOTS if quick else SHOTS, SEED, settings)
    on_target = [shot for shot in todo if shoot(settings, shot, goalie=False)]
    rows = []
    for on in (False, True):
        s = with_reflex(settings, on)
        goals = sum(shoot(s, shot) for shot in on_target)
        rows.append({"name": f"reflex {'on' if on else 'off'}", "shots": len(todo), "on_target": len(on_target),
                     "goals": goals, "saved": len(on_target) - goals,
                     "save_share": (len(on_target) - goals) / len(on_target) if on_target else math.nan})
    return rows
