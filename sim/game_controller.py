"""The game controller's state machine: the command in force (its counter and time), the stages
(halves, half time, the penalty shootout, the end), the cards (fouls counted into yellow cards,
red cards, robots off the field while their card runs), and the placements and penalties under way
with the match's tally of them.

It decides nothing about the physics: the referee (:mod:`sim.referee`) composes it with the fouls
(:mod:`sim.rules`), the restarts (:mod:`sim.restarts`) and the calls (:mod:`sim.calls`) and turns
what it decides into teleports. What the teams hear of it is its :meth:`GameController.state`, the
league's game state with each team's :func:`team_info`. Times in seconds.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from cmdragons.geometry import TEAMS, Team
from cmdragons.messages import GameStage, GameState, RefereeCommand, TeamInfo
from sim.restarts import RestartKind
from sim.rules import RulesParams

__all__ = [
    "Card",
    "Cards",
    "GameController",
    "Penalty",
    "Placement",
    "Tally",
    "shootout_kicker",
    "stage_after",
    "team_info",
]

Key = tuple[Team, int]


class GameController:
    """The command in force, for which team, whether its normal start is given (``ready``), its
    counter and time; the stage and when it ends; the placement or penalty under way."""

    def __init__(self, rules: RulesParams, halves: bool) -> None:
        """``halves``: the match has the rules' halves (the full rules), else one endless stage."""
        self.rules = rules
        self.command = RefereeCommand.KICKOFF
        self.for_team: Team | None = "blue"
        self.ready = True
        self.counter = 0
        self.command_t = 0.0
        self.stage = GameStage.FIRST_HALF
        self.stage_end = rules.half_s if halves else math.inf
        self.placement: Placement | None = None
        self.penalty: Penalty | None = None

    def give(self, t: float, command: RefereeCommand, for_team: Team | None, ready: bool = True) -> None:
        """Give a command at ``t`` (its counter and time move when it changes)."""
        if (command, for_team, ready) != (self.command, self.for_team, self.ready):
            self.counter += 1
            self.command_t = t
        self.command, self.for_team, self.ready = command, for_team, ready

    def in_play(self) -> bool:
        """The ball is in play: normal play, or a penalty whose normal start is given."""
        return self.command.running or (self.command is RefereeCommand.PENALTY and self.ready)

    def live(self) -> bool:
        """Goals and balls out count: the ball in play, or a kickoff or free kick about to be taken."""
        return self.command.kick_restart or self.in_play()

    def clear_special(self) -> None:
        """Neither a placement nor a penalty under way any more."""
        self.placement = None
        self.penalty = None

    def placing(self) -> Team | None:
        """The team whose placement is under way (a match that ends now cuts it short)."""
        pl = self.placement
        return pl.team if pl is not None and self.command == RefereeCommand.BALL_PLACEMENT else None

    def action_left(self, t: float, kick_left_s: float) -> float:
        """The time left at ``t`` for the action under way: the ball placement, a kickoff or free kick
        (``kick_left_s``: the referee's, till it lets play go on), the penalty's preparation or kick;
        inf for none."""
        r = self.rules
        if self.command == RefereeCommand.BALL_PLACEMENT and self.placement is not None:
            return r.placement_time_s - (t - self.placement.t_start)
        if self.command.kick_restart:
            return kick_left_s
        if self.command == RefereeCommand.PENALTY and self.penalty is not None:
            if self.penalty.t_run is None:
                return r.prepare_timeout_s - (t - self.penalty.t_start)
            return r.penalty_time_s - (t - self.penalty.t_run)
        return math.inf

    def state(self, t: float, score: Mapping[Team, int], blue_sign: float, spot: tuple[float, float] | None,
              kick_left_s: float, upcoming: tuple[RefereeCommand | None, Team | None],
              teams: Mapping[Team, TeamInfo]) -> GameState:
        """The game state at ``t`` as the league's game controller sends it: the ball's designated
        position the placement's target or the penalty mark under way, else ``spot`` (the restart's);
        ``upcoming`` the next command and its team; ``blue_sign`` -1 while blue defends the goal at -x."""
        placement = spot
        if self.placement is not None:
            placement = self.placement.target
        elif self.penalty is not None:
            placement = self.penalty.mark
        nxt, nxt_team = upcoming
        return GameState(
            t=t, command=self.command, for_team=self.for_team, score_blue=score["blue"], score_yellow=score["yellow"],
            blue_defends_negative_x=blue_sign < 0, placement=placement, ready=self.ready, stage=self.stage,
            stage_time_left_s=self.stage_end - t, command_counter=self.counter, command_t=self.command_t,
            action_time_left_s=self.action_left(t, kick_left_s), next_command=nxt, next_for_team=nxt_team,
            blue_team=teams["blue"], yellow_team=teams["yellow"],
        )

    def stage_over(self, t: float) -> bool:
        return t >= self.stage_end

    def enter(self, stage: GameStage, t: float) -> None:
        """Stage ``stage`` from ``t`` on, for as long as the rules give it."""
        r = self.rules
        length = {GameStage.HALF_TIME: r.half_time_s, GameStage.SECOND_HALF: r.half_s}.get(stage, math.inf)
        self.stage, self.stage_end = stage, t + length


def stage_after(stage: GameStage, rules: RulesParams, drawn: bool) -> GameStage:
    """The stage that follows ``stage`` when its time is up: half time (if the rules give one),
    the second half, the penalty shootout (if the rules play one: after a drawn match, or always),
    the end of the match."""
    if stage is GameStage.FIRST_HALF and rules.half_time_s > 0.0:
        return GameStage.HALF_TIME
    if stage in (GameStage.FIRST_HALF, GameStage.HALF_TIME):
        return GameStage.SECOND_HALF
    if stage is GameStage.SECOND_HALF and rules.shootout_kicks > 0 and (rules.shootout_always or drawn):
        return GameStage.PENALTY_SHOOTOUT
    return GameStage.POST_GAME


def shootout_kicker(kicks: Mapping[Team, Mapping[str, int]], rules: RulesParams) -> Team | None:
    """The team to take the shootout's next kick, or None when the shootout is over: the teams in
    turn (yellow first: blue kicked off the match), ``shootout_kicks`` each, then (a drawn match's
    shootout) one each until one team scored more of an equal number. ``kicks``: per team, the
    kicks ``taken`` and ``scored``."""
    taken = {t: kicks[t]["taken"] for t in TEAMS}
    even = taken["blue"] == taken["yellow"]
    decided = even and kicks["blue"]["scored"] != kicks["yellow"]["scored"]
    if even and taken["blue"] >= rules.shootout_kicks and (rules.shootout_always or decided):
        return None
    return "yellow" if even else "blue"


@dataclass
class Card:
    """A yellow card running: ``robot`` (-1: none left to send off) off for ``left_s`` more."""

    team: Team
    robot: int
    left_s: float


class Cards:
    """Fouls, yellow and red cards per team, the yellow cards running and the robots off the field
    (True: for good, a red card)."""

    def __init__(self, rules: RulesParams) -> None:
        self.rules = rules
        self.fouls: dict[Team, int] = {"blue": 0, "yellow": 0}
        self.yellow: dict[Team, int] = {"blue": 0, "yellow": 0}
        self.red: dict[Team, int] = {"blue": 0, "yellow": 0}
        self.running: list[Card] = []
        self.off: dict[Key, bool] = {}

    def foul(self, team: Team) -> bool:
        """One more foul for ``team``; True when it earns a card (every ``fouls_per_yellow_card``-th)."""
        self.fouls[team] += 1
        return self.fouls[team] % self.rules.fouls_per_yellow_card == 0

    def next_is_red(self, team: Team) -> bool:
        """The ``red_card_yellow_cards``-th card running at once is red (0: never)."""
        running = sum(1 for c in self.running if c.team == team)
        return self.rules.red_card_yellow_cards > 0 and running + 1 >= self.rules.red_card_yellow_cards

    def choose(self, team: Team, robot: int | None, keys: Sequence[Key]) -> int | None:
        """The robot a card sends off: the fouling ``robot`` if on the field and not the keeper, else
        the field player of the highest id (the keeper when no other is left)."""
        on = [rid for t, rid in keys if t == team and (t, rid) not in self.off]
        keeper = self.rules.keepers.get(team, -1)
        if robot is not None and robot in on and robot != keeper:
            return robot
        field_players = [rid for rid in on if rid != keeper]
        return max(field_players) if field_players else (max(on) if on else None)

    def book(self, team: Team, off: int | None, red: bool) -> None:
        """A card for ``team`` whose robot ``off`` goes off (the referee sends it: :attr:`off`)."""
        if red:
            self.red[team] += 1
        else:
            self.yellow[team] += 1
            self.running.append(Card(team, -1 if off is None else off, self.rules.yellow_card_s))

    def run(self, dt: float) -> list[Card]:
        """The cards' time runs ``dt``; returns those that ran out (their robots may come back)."""
        out = []
        for c in list(self.running):
            c.left_s -= dt
            if c.left_s > 0.0:
                continue
            self.running.remove(c)
            out.append(c)
        return out

    def back(self, card: Card) -> bool:
        """``card``'s robot comes back on (True) unless it was sent off for good since."""
        key = (card.team, card.robot)
        if self.off.get(key) is False:
            del self.off[key]
            return True
        return False

    def times_left(self, team: Team) -> tuple[float, ...]:
        return tuple(max(0.0, c.left_s) for c in self.running if c.team == team)

    def max_robots(self, team: Team, keys: Sequence[Key]) -> int:
        """Robots ``team`` may have on the field now: its count in ``keys`` less the cards running."""
        return sum(1 for t, _ in keys if t == team) - sum(1 for k in self.off if k[0] == team)


@dataclass
class Placement:
    """A ball placement under way: by ``team`` to ``target`` (field frame, m) since ``t_start`` (s),
    for the restart ``then``."""

    team: Team
    target: tuple[float, float]
    t_start: float
    then: RestartKind = RestartKind.PLACED_FREE_KICK  # the restart once the ball is placed


@dataclass
class Penalty:
    """A penalty kick under way: by ``team`` from ``mark``, prepared since ``t_start``, started
    (the normal start given) at ``t_run`` (s)."""

    team: Team
    t_start: float
    mark: tuple[float, float]
    t_run: float | None = None


class Tally:
    """The match's placements (tried: ended in success or in failure when the time ran out; cut
    short: ended by the end of a half or of the match first, neither, as the league's game controller
    counts only failures), their durations, and the penalties and shootout kicks taken and scored
    (the shootout decides a drawn match; the match's score stays as it was)."""

    def __init__(self) -> None:
        self.placements: dict[Team, dict[str, int]] = {t: {"tried": 0, "succeeded": 0, "cut_short": 0} for t in TEAMS}
        self.placement_s: dict[Team, list[float]] = {"blue": [], "yellow": []}
        self.placement_failures: dict[Team, int] = {"blue": 0, "yellow": 0}
        self.penalties: dict[Team, dict[str, int]] = {t: {"taken": 0, "scored": 0} for t in TEAMS}
        self.shootout: dict[Team, dict[str, int]] = {t: {"taken": 0, "scored": 0} for t in TEAMS}

    def placed(self, team: Team, took_s: float) -> None:
        self.placements[team]["tried"] += 1
        self.placements[team]["succeeded"] += 1
        self.placement_s[team].append(took_s)

    def failed(self, team: Team) -> None:
        self.placements[team]["tried"] += 1
        self.placement_failures[team] += 1

    def may_place(self, team: Team, failures_max: int) -> bool:
        """``team`` places the ball until it failed ``failures_max`` placements."""
        return self.placement_failures[team] < failures_max

    def figures(self, under_way: Team | None) -> dict[str, object]:
        """The summary's placements (``under_way``: the team whose placement the end cuts short),
        penalties and shootout kicks per team."""
        return {
            "placements": {t: {**self.placements[t], "cut_short": self.placements[t]["cut_short"] + (t == under_way),
                               "median_s": float(np.median(self.placement_s[t])) if self.placement_s[t] else None}
                           for t in TEAMS},
            "penalties": {t: dict(self.penalties[t]) for t in TEAMS},
            "shootout": {t: dict(self.shootout[t]) for t in TEAMS},
        }  # fmt: skip


def team_info(team: Team, cards: Cards, tally: Tally, keys: Sequence[Key], full: bool) -> TeamInfo:
    """What the game controller tells of ``team`` (of ``keys``' robots): its cards and fouls, its
    keeper and timeouts, its failed placements and whether it still places the ball (``full``: only
    with the full rules), how many robots it may have on the field."""
    r = cards.rules
    return TeamInfo(
        red_cards=cards.red[team], yellow_cards=cards.yellow[team], yellow_card_times_s=cards.times_left(team),
        fouls=cards.fouls[team], goalkeeper=r.keepers.get(team, 0), timeouts=r.timeouts,
        timeout_time_s=r.timeout_total_s, placement_failures=tally.placement_failures[team],
        can_place_ball=full and tally.may_place(team, r.placement_failures_max),
        max_robots=cards.max_robots(team, keys),
    )
