"""Restarts: after a stop, which command comes next, for whom, and where the ball (and the robots) go.

A :class:`Restart` is what the referee has decided while play is stopped (a kickoff after a goal, a
free kick after the ball left the field or a foul, a penalty, a force start after no progress), due
after the restart delay. The functions here answer the rules' geometric questions (which team defends
the half the ball is in, where the penalty mark is, whether a kick is taken) in the field frame,
metres; ``blue_sign`` is -1 while blue defends the goal at -x. :class:`Moves` gathers what the referee
wants placed in one frame (the ball, robots into formation, off the field, aside, for a shootout kick)
into the :class:`~cmdragons.messages.Teleport` the simulator carries out.
"""

from __future__ import annotations

import enum
import math
from collections.abc import Collection, Mapping, Sequence
from dataclasses import dataclass
from typing import Literal

from cmdragons.geometry import TEAMS, Field, Team
from cmdragons.messages import RefereeCommand, RobotTruth, Teleport

__all__ = [
    "Moves",
    "Restart",
    "RestartKind",
    "aside",
    "attack_sign",
    "ball_out_taker",
    "defender_of",
    "entry_spot",
    "formation",
    "kick_taken",
    "other",
    "park",
    "penalty_mark",
    "restart_of_call",
    "shootout_poses",
]

Key = tuple[Team, int]
Pose = tuple[float, float, float]  # x m, y m, theta rad
Move = tuple[Team, int, float, float, float]  # a robot teleported to x m, y m, theta rad


class RestartKind(enum.Enum):
    """How play restarts: the command it leads to and who puts the ball where."""

    KICKOFF = "kickoff"  # the ball on the centre spot (and, if configured, both teams in formation)
    FREE_KICK = "free_kick"  # the taking team places the ball if it may, else the referee puts it there
    PLACED_FREE_KICK = "placed_free_kick"  # the ball placed already: the free kick where it lies
    PLACED_KICKOFF = "placed_kickoff"  # the ball placed on the centre spot by the kicking team (no teleport)
    PLACED_PENALTY = "placed_penalty"  # the ball placed on the mark by the kicking team (no teleport)
    REFEREE_FREE_KICK = "referee_free_kick"  # the referee puts the ball on the spot (a free kick by hand)
    PENALTY = "penalty"  # the ball on the mark
    FORCE_START = "force_start"  # for both teams, where the ball lies (after no progress)

    @property
    def command(self) -> RefereeCommand:
        """The command this restart gives once the ball is in place."""
        return _COMMANDS[self]

    @property
    def placed(self) -> RestartKind:
        """This restart once the taking team has placed the ball for it."""
        return _PLACED.get(self, RestartKind.PLACED_FREE_KICK)


_COMMANDS = {
    RestartKind.KICKOFF: RefereeCommand.KICKOFF, RestartKind.FREE_KICK: RefereeCommand.FREE_KICK,
    RestartKind.PLACED_FREE_KICK: RefereeCommand.FREE_KICK, RestartKind.REFEREE_FREE_KICK: RefereeCommand.FREE_KICK,
    RestartKind.PENALTY: RefereeCommand.PENALTY, RestartKind.FORCE_START: RefereeCommand.FORCE_START,
    RestartKind.PLACED_KICKOFF: RefereeCommand.KICKOFF, RestartKind.PLACED_PENALTY: RefereeCommand.PENALTY,
}
_PLACED = {RestartKind.KICKOFF: RestartKind.PLACED_KICKOFF, RestartKind.PENALTY: RestartKind.PLACED_PENALTY}


@dataclass(frozen=True)
class Restart:
    """A restart decided while play is stopped: ``kind`` for ``team`` (None: both) at ``spot``
    (field frame, m), due at ``due_t`` (s)."""

    due_t: float
    kind: RestartKind
    team: Team | None
    spot: tuple[float, float]
    formation: bool = False  # a kickoff with both teams put in formation (the second half's)

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


def ball_out_taker(last_touch: Team | None, x: float, blue_sign: int) -> Team:
    """The team that takes the free kick after the ball left the field at ``x``: the other team
    than the one that touched it last; when nobody did, the team defending that half."""
    if last_touch is None:
        return defender_of(x, blue_sign)
    return other(last_touch)


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


# --- where the robots go ----------------------------------------------------------------------------


def formation(poses: Sequence[Pose], n: int, side: int) -> list[Pose]:
    """The first ``n`` kickoff ``poses`` (given for the team defending the goal at -x) for the team
    whose goal is at ``side`` (-1: -x; +1: mirrored through the centre spot)."""
    if side < 0:
        return [(x, y, th) for x, y, th in poses[:n]]
    return [(-x, -y, math.atan2(math.sin(th + math.pi), math.cos(th + math.pi))) for x, y, th in poses[:n]]


def park(pitch: Field, index: int, team: Team, distance_m: float) -> tuple[float, float]:
    """Where the ``index``-th robot of the match waits off the field: ``distance_m`` outside the
    boundary on its team's side (blue at -y), beyond the cameras' view."""
    side = -1.0 if team == "blue" else 1.0
    return (-pitch.half_length + 0.4 * index, side * (pitch.boundary_half_width + distance_m))


def entry_spot(pitch: Field, robots: Sequence[RobotTruth], team: Team, blue_sign: int) -> tuple[float, float]:
    """Where a robot whose card ran out comes back: by its touch line (blue at -y), from the
    halfway line into its own half, the first spot two robot diameters clear of every robot."""
    side = -1.0 if team == "blue" else 1.0
    own = blue_sign if team == "blue" else -blue_sign
    r = pitch.league.robot.radius_m
    y = side * (pitch.half_width - 2.0 * r)
    for k in range(40):
        x = own * (2.0 * r) * (k + 1)
        if all(math.hypot(o.x - x, o.y - y) > 4.0 * r for o in robots):
            return (x, y)
    return (own * 2.0 * r, y)


def aside(robots: Sequence[RobotTruth], spot: tuple[float, float], clear_m: float, attack: float,
          off: Collection[Key]) -> list[Move]:
    """The robots nearer ``spot`` than ``clear_m`` (those ``off`` the field aside) moved out to that
    distance, straight away from it (toward -``attack`` along x when on it), so the ball put there
    is not put into a robot."""
    moved = []
    for r in robots:
        dx, dy = r.x - spot[0], r.y - spot[1]
        d = math.hypot(dx, dy)
        if d >= clear_m or (r.team, r.id) in off:
            continue
        ux, uy = (dx / d, dy / d) if d > 1e-6 else (-attack, 0.0)
        moved.append((r.team, r.id, spot[0] + ux * clear_m, spot[1] + uy * clear_m, r.theta))
    return moved


def shootout_poses(pitch: Field, keys: Sequence[Key], off: Collection[Key], keepers: Mapping[Team, int],
                   team: Team, mark: tuple[float, float], attack: float, behind_m: float,
                   parked: Mapping[Key, tuple[float, float]]) -> list[Move]:
    """A shootout kick by ``team`` at ``mark`` (the rules: only the kicker and the other team's
    keeper may move; the robot handlers take the others off): its field player ``behind_m`` behind
    the mark facing the goal it attacks (``attack``: +1.0 for +x), the other keeper on its goal
    line, every other robot on the field at its place in ``parked``."""
    r = pitch.league.robot.radius_m
    moves = []
    for key in keys:
        if key in off:
            continue
        keeper = key[1] == keepers.get(key[0], -1)
        if key[0] == team and not keeper:
            x, y, theta = mark[0] - attack * behind_m, mark[1], 0.0 if attack > 0 else math.pi
        elif key[0] != team and keeper:
            x, y, theta = attack * (pitch.half_length - 0.5 * r), 0.0, math.pi if attack > 0 else 0.0
        else:
            (x, y), theta = parked[key], 0.0
        moves.append((key[0], key[1], x, y, theta))
    return moves


class Moves:
    """What the referee wants placed this frame, gathered into one teleport, and where it puts the
    match's robots (``keys``): its kickoff ``formations`` (per division, the poses of the team
    defending the goal at -x), off the field ``park_distance_m`` outside the boundary, aside from a
    ball put down, for a shootout kick."""

    def __init__(self, pitch: Field, keys: Sequence[Key], formations: Mapping[Literal["A", "B"], Sequence[Pose]],
                 park_distance_m: float, teleports: bool = True) -> None:
        """``teleports``: False when nothing may be placed by teleport (the teams place the ball, the
        robot handlers move the robots): every move asked for is left out."""
        self.field = pitch
        self.teleports = teleports
        self.keys = list(keys)
        self.formations = formations
        self.park_distance_m = park_distance_m
        self.pending: list[Teleport] = []

    def add(self, t: float, robots: Sequence[Move] = (), ball: tuple[float, float] | None = None) -> None:
        self.append(Teleport(t, tuple(robots), ball))

    def append(self, teleport: Teleport) -> None:
        if self.teleports:
            self.pending.append(teleport)

    def moving(self) -> set[Key]:
        """The robots placed this frame so far."""
        return {(team, rid) for p in self.pending for team, rid, *_ in p.robots}

    def take(self, t: float) -> Teleport | None:
        """This frame's teleports as one at ``t`` (robots in order, the last ball), or None."""
        if not self.pending:
            return None
        parts, self.pending = self.pending, []
        if len(parts) == 1:
            return parts[0]
        ball = next((p.ball for p in reversed(parts) if p.ball is not None), None)
        return Teleport(t, tuple(r for p in parts for r in p.robots), ball)

    def formation(self, team: Team, blue_sign: int) -> list[Pose]:
        """Kickoff poses of ``team``'s robots in the field frame."""
        division = self.field.league.division
        poses = self.formations.get(division, ())
        n = sum(1 for t, _ in self.keys if t == team)
        if len(poses) < n:
            raise ValueError(
                f"sim.referee.formations.{division} lists {len(poses)} poses but the team has {n} robots"
            )
        return formation(poses, n, blue_sign if team == "blue" else -blue_sign)

    def kickoff(self, t: float, blue_sign: int, off: Collection[Key]) -> Teleport:
        """Both teams in formation (the robots ``off`` the field stay off), the ball on the centre spot."""
        robots = []
        for team in TEAMS:
            ids = [rid for t_, rid in self.keys if t_ == team]
            poses = self.formation(team, blue_sign)
            robots += [(team, rid, x, y, th) for rid, (x, y, th) in zip(ids, poses, strict=False)
                       if (team, rid) not in off]
        return Teleport(t, tuple(robots), (0.0, 0.0))

    def park(self, key: Key) -> tuple[float, float]:
        """Where a robot off the field waits: outside the boundary, beyond the cameras' view."""
        return park(self.field, self.keys.index(key), key[0], self.park_distance_m)

    def send_off(self, t: float, key: Key) -> None:
        x, y = self.park(key)
        self.add(t, [(key[0], key[1], x, y, 0.0)])

    def clear_spot(self, t: float, robots: Sequence[RobotTruth], spot: tuple[float, float], clear_m: float,
                   attack: float, off: Collection[Key]) -> None:
        """The ``robots`` nearer ``spot`` than ``clear_m`` moved aside first (:func:`aside`)."""
        moved = aside(robots, spot, clear_m, attack, off)
        if moved:
            self.add(t, moved)

    def shootout_kick(self, t: float, off: Collection[Key], keepers: Mapping[Team, int], team: Team,
                      mark: tuple[float, float], attack: float, behind_m: float) -> None:
        """The rules: during a shootout attempt only the kicker and the other team's keeper may move
        (the others must not interfere; robots may be substituted between attempts). The robot
        handlers take the kicking team's keeper and the other team's field player off (where robots
        sent off wait) and put the kicker ``behind_m`` behind ``mark`` and the keeper on its goal line
        (:func:`shootout_poses`)."""
        parked = {key: self.park(key) for key in self.keys}
        self.add(t, shootout_poses(self.field, self.keys, off, keepers, team, mark, attack, behind_m, parked))
