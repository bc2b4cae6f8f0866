"""The robots on the field kept at the count the referee allows, as the league's simulation
controller keeps them in a simulator.

In a tournament played in a simulator no robot handler takes a robot off by hand: the league's
simulation controller adds and removes robots so that each team has on the field the count the
Referee message allows it (``max_allowed_bots``: fewer while a yellow card runs). It acts only while
the game is halted or the ball is at least 2 m from the halfway line (the rules' condition for a
substitution), removes first the robots nearest either crossing of the halfway line and the touch
lines (where the rules have a team take a robot out: a team that drives one there is the one whose
robot goes), and puts a robot back near the halfway line on a free spot. :class:`RobotCount` decides
the same from the tracked world; what it decides an outside simulator carries out (its control
port's ``present: false`` and ``present: true`` teleports). Field frame, metres, seconds.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

from cmdragons.config import Validated, setting
from cmdragons.geometry import TEAMS, Field, Team
from cmdragons.messages import GameState, RefereeCommand, RobotTruth, WorldState
from sim.restarts import entry_spot

__all__ = ["CountChange", "RobotCount", "RobotCountParams"]

Key = tuple[Team, int]


@dataclass(frozen=True)
class RobotCountParams(Validated):
    """When the count is mended (configs/protocols.yaml ``simulation.robot_count``)."""

    keep: bool = True  # mend the count at all (off: the simulator's robots as they are)
    ball_from_halfway_m: float = setting(2.0, lo=0.0, hi=10.0)  # rule: a substitution with the ball this far
    # from the halfway line (or the game halted)
    settle_s: float = setting(1.0, lo=0.0, hi=60.0)  # a count off this long first: a robot the referee or the
    # team is taking out (a vision frame late) is not taken twice


@dataclass(frozen=True)
class CountChange:
    """What to do to the simulator's robots now: those to take off the field, those to put back (team,
    id, x, y, heading)."""

    off: tuple[Key, ...] = ()
    on: tuple[tuple[Team, int, float, float, float], ...] = ()

    def __bool__(self) -> bool:
        return bool(self.off or self.on)


@dataclass
class _Team:
    off: list[int] = field(default_factory=list)  # robots taken off by us, the last last
    wrong_since: float | None = None  # since when the count has been off


class RobotCount:
    """Each team's robots on the field at the referee's allowed count: one :meth:`step` per tracked
    world state with the game state then."""

    def __init__(self, pitch: Field, params: RobotCountParams) -> None:
        self.field, self.p = pitch, params
        self.teams = {team: _Team() for team in TEAMS}
        self.taken_off = 0
        self.put_back = 0

    def on_field(self, world: WorldState, team: Team) -> list[RobotTruth]:
        """``team``'s robots seen on the field now (the field margin included)."""
        b = self.field.dims.boundary_width_m
        return [RobotTruth(r.team, r.id, r.x, r.y, r.theta, r.vx, r.vy, r.omega) for r in world.robots
                if r.team == team and r.visible and self.field.in_field(r.x, r.y, -b)]

    def may_change(self, world: WorldState, game: GameState) -> bool:
        """The rules' condition for a substitution: the game halted or the ball far from the halfway line."""
        b = world.ball
        return game.command == RefereeCommand.HALT or b is None or abs(b.x) >= self.p.ball_from_halfway_m

    def leaving_order(self, robots: Sequence[RobotTruth]) -> list[RobotTruth]:
        """``robots`` nearest first to either crossing of the halfway line and the touch lines."""
        w = self.field.half_width
        return sorted(robots, key=lambda r: (min(math.hypot(r.x, r.y - w), math.hypot(r.x, r.y + w)), r.id))

    def step(self, world: WorldState, game: GameState) -> CountChange:
        """What to take off or put back now (nothing while the count is right, not yet settled, or the
        rules' condition does not hold)."""
        if not self.p.keep:
            return CountChange()
        off: list[Key] = []
        on: list[tuple[Team, int, float, float, float]] = []
        seen = [RobotTruth(r.team, r.id, r.x, r.y, r.theta, r.vx, r.vy, r.omega) for r in world.robots if r.visible]
        for team in TEAMS:
            state = self.teams[team]
            robots = self.on_field(world, team)
            allowed = game.team_info(team).max_robots
            extra = len(robots) - allowed
            if extra == 0 or (extra < 0 and not state.off):
                state.wrong_since = None
                continue
            if state.wrong_since is None:
                state.wrong_since = world.t
            if world.t - state.wrong_since < self.p.settle_s or not self.may_change(world, game):
                continue
            state.wrong_since = None
            if extra > 0:
                for r in self.leaving_order(robots)[:extra]:
                    off.append((team, r.id))
                    state.off.append(r.id)
                continue
            blue_sign = -1 if game.blue_defends_negative_x else 1
            for _ in range(min(-extra, len(state.off))):
                rid = state.off.pop()
                x, y = entry_spot(self.field, seen, team, blue_sign)
                theta = math.pi / 2 if y < 0 else -math.pi / 2  # facing into the field
                on.append((team, rid, x, y, theta))
                seen.append(RobotTruth(team, rid, x, y, theta, 0.0, 0.0, 0.0))
        self.taken_off += len(off)
        self.put_back += len(on)
        return CountChange(tuple(off), tuple(on))
