"""Restarts: after a stop, which command comes next, for whom, and where the ball goes.

A :class:`Restart` is what the referee has decided while play is stopped (a kickoff after a goal, a
free kick after the ball left the field or a foul, a penalty, a force start after no progress), due
after the restart delay. The functions here answer the rules' geometric questions (which team defends
the half the ball is in, where the penalty mark is, whether a kick is taken) in the field frame,
metres; ``blue_sign`` is -1 while blue defends the goal at -x.
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass

from cmdragons.geometry import Field, Team
from cmdragons.messages import RefereeCommand

__all__ = [
    "Restart",
    "RestartKind",
    "attack_sign",
    "defender_of",
    "kick_taken",
    "other",
    "penalty_mark",
    "restart_of_call",
]


class RestartKind(enum.Enum):
    """How play restarts: the command it leads to and who puts the ball where."""

    KICKOFF = "kickoff"  # the ball on the centre spot (and, if configured, both teams in formation)
    FREE_KICK = "free_kick"  # the taking team places the ball if it may, else the referee puts it there
    PLACED_FREE_KICK = "placed_free_kick"  # the ball placed already: the free kick where it lies
    REFEREE_FREE_KICK = "referee_free_kick"  # the referee puts the ball on the spot (a free kick by hand)
    PENALTY = "penalty"  # the ball on the mark
    FORCE_START = "force_start"  # for both teams, where the ball lies (after no progress)

    @property
    def command(self) -> RefereeCommand:
        """The command this restart gives once the ball is in place."""
        return _COMMANDS[self]


_COMMANDS = {
    RestartKind.KICKOFF: RefereeCommand.KICKOFF, RestartKind.FREE_KICK: RefereeCommand.FREE_KICK,
    RestartKind.PLACED_FREE_KICK: RefereeCommand.FREE_KICK, RestartKind.REFEREE_FREE_KICK: RefereeCommand.FREE_KICK,
    RestartKind.PENALTY: RefereeCommand.PENALTY, RestartKind.FORCE_START: RefereeCommand.FORCE_START,
}  # fmt: skip


@dataclass(frozen=True)
class Restart:
    """A restart decided while play is stopped: ``kind`` for ``team`` (None: both) at ``spot``
    (field frame, m), due at ``due_t`` (s)."""

    due_t: float
    kind: RestartKind
    team: Team | None
    spot: tuple[float, float]

    def next_command(self, may_place: bool) -> tuple[RefereeCommand, Team | None]:
        """The command that follows the stop: the taking team's ball placement for a free kick it
        ``may_place`` (the full rules, its placements not failed too often), else the restart's own."""
        if self.kind is RestartKind.FREE_KICK and self.team is not None and may_place:
            return RefereeCommand.BALL_PLACEMENT, self.team
        return self.kind.command, self.team


def restart_of_call(command: RefereeCommand) -> RestartKind:
    """The restart of a call that names ``command`` (a foul's free kick or penalty)."""
    if command is RefereeCommand.PENALTY:
        return RestartKind.PENALTY
    if command is RefereeCommand.FREE_KICK:
        return RestartKind.FREE_KICK
    raise ValueError(f"a call restarts with a free kick or a penalty, not {command}")


def other(team: Team) -> Team:
    return "yellow" if team == "blue" else "blue"


def defender_of(x: float, blue_sign: int) -> Team:
    """The team defending the half at ``x``."""
    return "blue" if (x < 0) == (blue_sign < 0) else "yellow"


def attack_sign(team: Team, blue_sign: int) -> float:
    """+1.0 when ``team`` attacks the goal at +x."""
    return -float(blue_sign if team == "blue" else -blue_sign)


def penalty_mark(pitch: Field, from_goal_m: float, team: Team, blue_sign: int) -> tuple[float, float]:
    """The penalty mark ``from_goal_m`` in front of the goal ``team`` attacks."""
    return (attack_sign(team, blue_sign) * (pitch.half_length - from_goal_m), 0.0)


def kick_taken(ball_xy: tuple[float, float], placed_at: tuple[float, float], ball_in_play_m: float) -> bool:
    """A kickoff's or free kick's ball is in play once it moved more than ``ball_in_play_m`` from
    where it was placed (the rules)."""
    return math.hypot(ball_xy[0] - placed_at[0], ball_xy[1] - placed_at[1]) > ball_in_play_m
