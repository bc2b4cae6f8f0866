"""Referee basics: score, kickoff after a goal, free kick after the ball leaves the field.

The referee turns the world's events into the game state and, after a short pause, places the
ball for the restart (and, if configured, the robots in their kickoff formation), as an automatic
ball placement would. Formations are given for the team defending the goal at -x and mirrored
for the other team.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Literal

from cmdragons.config import Validated, setting
from cmdragons.geometry import TEAMS, Team
from cmdragons.messages import GameState
from sim.world import BallOut, Contact, Goal, Kick, World

__all__ = ["Referee", "RefereeParams"]

_Pose = tuple[float, float, float]
_DEFAULT_FORMATIONS: dict[Literal["A", "B"], tuple[_Pose, ...]] = {
    "B": ((-4.2, 0.0, 0.0), (-3.0, 1.0, 0.0), (-3.0, -1.0, 0.0), (-2.0, 0.0, 0.0), (-1.0, 1.6, 0.0),
          (-1.0, -1.6, 0.0)),
    "A": ((-5.7, 0.0, 0.0), (-4.2, 1.2, 0.0), (-4.2, -1.2, 0.0), (-4.2, 0.0, 0.0), (-3.2, 2.5, 0.0),
          (-3.2, -2.5, 0.0), (-2.4, 0.8, 0.0), (-2.4, -0.8, 0.0), (-1.2, 3.0, 0.0), (-1.2, -3.0, 0.0),
          (-1.0, 0.0, 0.0)),
}  # fmt: skip


@dataclass(frozen=True)
class RefereeParams(Validated):
    enabled: bool = True  # off: no restarts, the ball bounces off the boundary walls
    blue_defends: Literal["negative_x", "positive_x"] = "negative_x"
    restart_delay_s: float = setting(1.0, lo=0.0, hi=30.0)  # goal or out -> ball placed
    place_robots_on_goal: bool = True  # put both teams in their kickoff formation after a goal
    free_kick_distance_m: float = setting(0.2, lo=0.0, hi=2.0)  # from the lines and defense areas
    kickoff_clearance_m: float = setting(0.5, lo=0.0, hi=3.0)  # own robots around the ball in a stop
    restart_timeout_s: float = setting(10.0, lo=0.1, hi=600.0)  # a restart not taken by then: play on
    keeper_held_ball_s: float = setting(10.0, lo=0.1, hi=600.0)  # ball this long in a defense area: free kick
    # start poses (x m, y m, theta rad) of the team defending -x, per division; mirrored for the other
    formations: Mapping[Literal["A", "B"], tuple[tuple[float, float, float], ...]] = field(
        default_factory=lambda: dict(_DEFAULT_FORMATIONS)
    )


class Referee:
    """Keeps the score and the game state; restarts play through the world."""

    def __init__(self, world: World, params: RefereeParams) -> None:
        self.world = world
        self.params = params
        self.blue_sign: Literal[-1, 1] = -1 if params.blue_defends == "negative_x" else 1
        world.blue_defends = self.blue_sign
        self.score: dict[Team, int] = {"blue": 0, "yellow": 0}
        self.balls_out = 0
        self.kicks = 0
        self.contacts: list[Contact] = []
        self.command: Literal["kickoff", "free_kick", "normal", "stop"] = "kickoff"
        self.for_team: Team | None = "blue"
        self._restart: tuple[float, str, Team, tuple[float, float]] | None = None
        self._restart_ball: tuple[float, float] | None = (0.0, 0.0)
        self._restart_t = 0.0  # when the restart in force was given
        self._in_area_since: float | None = None  # normal play with the ball in a defense area since
        self.keeper_held_ball = 0

    def formation(self, team: Team) -> list[tuple[float, float, float]]:
        """Kickoff poses of ``team``'s robots in the field frame."""
        division = self.world.league.division
        poses = self.params.formations.get(division, ())
        n = sum(1 for t, _ in self.world.robot_keys() if t == team)
        if len(poses) < n:
            raise ValueError(
                f"sim.referee.formations.{division} lists {len(poses)} poses but the team has {n} robots"
            )
        sign = self.blue_sign if team == "blue" else -self.blue_sign
        out = []
        for x, y, th in poses[:n]:
            if sign < 0:
                out.append((x, y, th))
            else:
                out.append((-x, -y, math.atan2(math.sin(th + math.pi), math.cos(th + math.pi))))
        return out

    def kickoff_setup(self, kicking_team: Team = "blue") -> None:
        """Both teams in formation, ball on the centre spot, kickoff for ``kicking_team``."""
        for team in TEAMS:
            ids = [rid for t, rid in self.world.robot_keys() if t == team]
            for rid, (x, y, th) in zip(ids, self.formation(team), strict=False):
                self.world.place_robot(team, rid, x, y, th)
        self.world.place_ball(0.0, 0.0)
        self.command, self.for_team = "kickoff", kicking_team
        self._restart_ball = (0.0, 0.0)
        self._restart_t = self.world.t

    def observe(self, events: list[Goal | BallOut | Kick | Contact]) -> None:
        """Take one frame's events; carry out a due restart."""
        if not self.params.enabled:
            self.contacts += [e for e in events if isinstance(e, Contact)]
            self.kicks += sum(isinstance(e, Kick) for e in events)
            return
        t = self.world.t
        for e in events:
            if isinstance(e, Contact):
                self.contacts.append(e)
            elif isinstance(e, Kick):
                self.kicks += 1
            elif isinstance(e, Goal) and self._restart is None:
                self.score[e.scoring_team] += 1
                conceding: Team = "yellow" if e.scoring_team == "blue" else "blue"
                self.command, self.for_team = "stop", None
                self._restart = (t + self.params.restart_delay_s, "kickoff", conceding, (0.0, 0.0))
            elif isinstance(e, BallOut) and self._restart is None:
                self.balls_out += 1
                taker: Team = "yellow" if e.last_touch == "blue" else "blue"
                if e.last_touch is None:  # nobody touched it: the team defending that half
                    taker = "blue" if (e.x < 0) == (self.blue_sign < 0) else "yellow"
                spot = self.world.field.free_kick_spot(e.x, e.y, self.params.free_kick_distance_m)
                self.command, self.for_team = "stop", None
                self._restart = (t + self.params.restart_delay_s, "free_kick", taker, spot)
        self._check_keeper_held_ball(t)
        if self._restart is not None and t >= self._restart[0]:
            _, kind, team, spot = self._restart
            self._restart = None
            if kind == "kickoff" and self.params.place_robots_on_goal:
                self.kickoff_setup(team)
            else:
                self.world.place_ball(*spot)
                self.command, self.for_team = ("kickoff" if kind == "kickoff" else "free_kick"), team
                self._restart_ball = spot
                self._restart_t = t
        # a restart is taken once the ball moved: normal play; not taken in time, play goes on anyway
        if self.command in ("kickoff", "free_kick") and self._restart_ball is not None:
            bx, by = self.world.ball_body.position
            moved = math.hypot(bx - self._restart_ball[0], by - self._restart_ball[1]) > 0.05
            if moved or t - self._restart_t > self.params.restart_timeout_s:
                self.command, self.for_team, self._restart_ball = "normal", None, None

    def _check_keeper_held_ball(self, t: float) -> None:
        """Rules (keeper held ball): the ball in a defense area for ``keeper_held_ball_s`` of normal
        play gives the other team a free kick at the nearest legal spot."""
        bx, by = self.world.ball_body.position
        side = self.world.field.in_defense_area(bx, by)
        if self.command != "normal" or self._restart is not None or not side:
            self._in_area_since = None
            return
        if self._in_area_since is None:
            self._in_area_since = t
        elif t - self._in_area_since >= self.params.keeper_held_ball_s:
            self._in_area_since = None
            self.keeper_held_ball += 1
            taker: Team = "yellow" if side == self.blue_sign else "blue"
            spot = self.world.field.free_kick_spot(bx, by, self.params.free_kick_distance_m)
            self.command, self.for_team = "stop", None
            self._restart = (t + self.params.restart_delay_s, "free_kick", taker, spot)

    def state(self) -> GameState:
        return GameState(
            t=self.world.t, command=self.command, for_team=self.for_team, score_blue=self.score["blue"],
            score_yellow=self.score["yellow"], blue_defends_negative_x=self.blue_sign < 0,
            placement=self._restart[3] if self._restart else self._restart_ball,
        )  # fmt: skip
