"""Referee basics: score, kickoff after a goal, free kick after the ball leaves the field.

The referee turns the simulator's events into the game state and, after a short pause, asks for the
ball to be placed for the restart (and, if configured, the robots in their kickoff formation), as an
automatic ball placement would. It never touches the physics: what it wants placed it returns as a
:class:`~cmdragons.messages.Teleport`, which the simulator carries out (in one process or across a
network alike). Formations are given for the team defending the goal at -x and mirrored for the
other team.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Literal

from cmdragons.config import Validated, setting
from cmdragons.geometry import TEAMS, Field, Team
from cmdragons.messages import BallOut, Contact, Event, GameState, Goal, Kick, Teleport

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
    restart_timeout_s: float = setting(10.0, lo=0.1, hi=600.0)  # a restart not taken by then: play on
    keeper_held_ball_s: float = setting(10.0, lo=0.1, hi=600.0)  # ball this long in a defense area: free kick
    # start poses (x m, y m, theta rad) of the team defending -x, per division; mirrored for the other
    formations: Mapping[Literal["A", "B"], tuple[tuple[float, float, float], ...]] = field(
        default_factory=lambda: dict(_DEFAULT_FORMATIONS)
    )


class Referee:
    """Keeps the score and the game state; restarts play by asking for teleports."""

    def __init__(self, field: Field, robot_keys: Sequence[tuple[Team, int]], params: RefereeParams) -> None:
        self.field = field
        self.robot_keys = list(robot_keys)
        self.params = params
        self.blue_sign: Literal[-1, 1] = -1 if params.blue_defends == "negative_x" else 1
        self.score: dict[Team, int] = {"blue": 0, "yellow": 0}
        self.balls_out = 0
        self.kicks = 0
        self.contacts: list[Contact] = []
        self.command: Literal["kickoff", "free_kick", "normal", "stop"] = "kickoff"
        self.for_team: Team | None = "blue"
        self.t = 0.0
        self._restart: tuple[float, str, Team, tuple[float, float]] | None = None
        self._restart_ball: tuple[float, float] | None = (0.0, 0.0)
        self._restart_t = 0.0  # when the restart in force was given
        self._in_area_since: float | None = None  # normal play with the ball in a defense area since
        self.keeper_held_ball = 0

    def formation(self, team: Team) -> list[tuple[float, float, float]]:
        """Kickoff poses of ``team``'s robots in the field frame."""
        division = self.field.league.division
        poses = self.params.formations.get(division, ())
        n = sum(1 for t, _ in self.robot_keys if t == team)
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

    def kickoff_setup(self, kicking_team: Team = "blue") -> Teleport:
        """Both teams in formation, ball on the centre spot, kickoff for ``kicking_team``."""
        robots = []
        for team in TEAMS:
            ids = [rid for t, rid in self.robot_keys if t == team]
            robots += [(team, rid, x, y, th) for rid, (x, y, th) in zip(ids, self.formation(team), strict=False)]
        self.command, self.for_team = "kickoff", kicking_team
        self._restart_ball = (0.0, 0.0)
        self._restart_t = self.t
        return Teleport(self.t, tuple(robots), (0.0, 0.0))

    def observe(self, t: float, events: Sequence[Event], ball_xy: tuple[float, float]) -> Teleport | None:
        """Take one frame's events at time ``t`` with the ball at ``ball_xy`` (field frame, m);
        returns what a restart due now wants placed, or None."""
        self.t = t
        if not self.params.enabled:
            self.contacts += [e for e in events if isinstance(e, Contact)]
            self.kicks += sum(isinstance(e, Kick) for e in events)
            return None
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
                spot = self.field.free_kick_spot(e.x, e.y, self.params.free_kick_distance_m)
                self.command, self.for_team = "stop", None
                self._restart = (t + self.params.restart_delay_s, "free_kick", taker, spot)
        self._check_keeper_held_ball(t, ball_xy)
        teleport = None
        if self._restart is not None and t >= self._restart[0]:
            _, kind, team, spot = self._restart
            self._restart = None
            if kind == "kickoff" and self.params.place_robots_on_goal:
                teleport = self.kickoff_setup(team)
            else:
                teleport = Teleport(t, (), spot)
                self.command, self.for_team = ("kickoff" if kind == "kickoff" else "free_kick"), team
                self._restart_ball = spot
                self._restart_t = t
            ball_xy = teleport.ball if teleport.ball is not None else ball_xy
        # a restart is taken once the ball moved: normal play; not taken in time, play goes on anyway
        if self.command in ("kickoff", "free_kick") and self._restart_ball is not None:
            bx, by = ball_xy
            moved = math.hypot(bx - self._restart_ball[0], by - self._restart_ball[1]) > 0.05
            if moved or t - self._restart_t > self.params.restart_timeout_s:
                self.command, self.for_team, self._restart_ball = "normal", None, None
        return teleport

    def _check_keeper_held_ball(self, t: float, ball_xy: tuple[float, float]) -> None:
        """Rules (keeper held ball): the ball in a defense area for ``keeper_held_ball_s`` of normal
        play gives the other team a free kick at the nearest legal spot."""
        bx, by = ball_xy
        side = self.field.in_defense_area(bx, by)
        if self.command != "normal" or self._restart is not None or not side:
            self._in_area_since = None
            return
        if self._in_area_since is None:
            self._in_area_since = t
        elif t - self._in_area_since >= self.params.keeper_held_ball_s:
            self._in_area_since = None
            self.keeper_held_ball += 1
            taker: Team = "yellow" if side == self.blue_sign else "blue"
            spot = self.field.free_kick_spot(bx, by, self.params.free_kick_distance_m)
            self.command, self.for_team = "stop", None
            self._restart = (t + self.params.restart_delay_s, "free_kick", taker, spot)

    def state(self) -> GameState:
        return GameState(
            t=self.t, command=self.command, for_team=self.for_team, score_blue=self.score["blue"],
            score_yellow=self.score["yellow"], blue_defends_negative_x=self.blue_sign < 0,
            placement=self._restart[3] if self._restart else self._restart_ball,
        )  # fmt: skip
