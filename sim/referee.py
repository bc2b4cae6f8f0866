"""The simulator's referee: the league's game controller and, with the full rules, its auto-referee.

Basic rules: score, kickoff after a goal, free kick after the ball leaves the field, the keeper's
held ball; after a short pause the referee places the ball for the restart itself (and, if
configured, the robots in their kickoff formation), as an automatic ball placement would.

Full rules (the default) add what the league's game controller and auto-referees do: two halves with
the sides changed between them, the fouls of :mod:`sim.rules` with the restart each leads to, a
yellow card for every few fouls (a robot off for the card's time) and red cards, ball placement by
the team that takes the free kick (within the rules' time and tolerance, else by the referee and the
free kick to the other team), penalty kicks (prepared, started, over when scored, missed or timed
out), and too many robots on the field. Every call is a :class:`~cmdragons.messages.GameEvent`.

The referee is the composition of its parts: the fouls and their figures (:mod:`sim.rules`), the
restarts (:mod:`sim.restarts`: which command comes next, where the ball and the robots go, the
frame's moves gathered into one teleport), the game controller's state machine
(:mod:`sim.game_controller`: commands, stages, cards, the game state it tells) and the calls
(:mod:`sim.calls`); what is left here turns what the parts decide into commands and moves. It never
touches the physics: what it wants placed (a ball, a formation, a robot sent off or back) it returns
as a :class:`~cmdragons.messages.Teleport`, which the simulator carries out (in one process or
across a network alike). Formations are given for the team defending the goal at -x and mirrored for
the other team.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Literal

from cmdragons.geometry import TEAMS, Field, Team
from cmdragons.messages import (
    BallOut,
    Contact,
    Event,
    GameEvent,
    GameStage,
    GameState,
    Goal,
    GroundTruth,
    Kick,
    RefereeCommand,
    Teleport,
)
from sim.calls import Calls
from sim.game_controller import (
    Cards,
    GameController,
    Penalty,
    Placement,
    Tally,
    shootout_kicker,
    stage_after,
    team_info,
)
from sim.referee_params import RefereeParams
from sim.restarts import (
    Moves,
    Restart,
    RestartKind,
    attack_sign,
    ball_out_taker,
    defender_of,
    entry_spot,
    kick_taken,
    other,
    penalty_mark,
    restart_of_call,
)
from sim.rules import FOUL_RESTARTS, FoulWatch, HeldBall, NoProgress, Situation, TrackMargins, penalty_set, placed

__all__ = ["Referee"]

Key = tuple[Team, int]


class Referee:
    """Keeps the score and the game state; restarts play by asking for teleports; with the full
    rules also the stages, fouls, cards, placements and penalties."""

    def __init__(self, field: Field, robot_keys: Sequence[tuple[Team, int]], params: RefereeParams,
                 margins: TrackMargins | None = None, leave_s: float = 0.0) -> None:
        """``margins`` and ``leave_s``: what judging tracked robots allows (the auto-referee on
        vision): the foul watch's margins, and how long a robot sent off may still be seen on the
        field before its team has too many robots (on the truth it leaves at once)."""
        self.field = field
        self.robot_keys = list(robot_keys)
        self.params = params
        self.blue_sign: Literal[-1, 1] = -1 if params.blue_defends == "negative_x" else 1
        self.score: dict[Team, int] = {"blue": 0, "yellow": 0}
        self.balls_out = 0
        self.kicks = 0
        self.contacts: list[Contact] = []
        self.t = 0.0
        self._restart: Restart | None = None  # decided while play is stopped, due after the restart delay
        self._restart_ball: tuple[float, float] | None = (0.0, 0.0)
        self._restart_t = 0.0  # when the restart in force was given
        self._restart_seen = True  # its ball was seen on its spot (one put there waits for it)
        self._restart_touches = 0  # the touches counted when it was given
        self._held = HeldBall(field, params.keeper_held_ball_s)
        self._no_progress = NoProgress(params.no_progress_s, params.no_progress_m)
        self.keeper_held_ball = 0
        # the full rules
        self.full = params.enabled and params.rules == "full"
        self.rules = params.figures
        self.game = GameController(self.rules, halves=self.full)
        self.watch = FoulWatch(field, self.rules, margins if margins is not None else TrackMargins())
        self.leave_s = leave_s
        self._sent_off_t: dict[Team, float] = {}  # per team: when the referee last sent one of its robots off
        self._too_many: set[Team] = set()  # teams called for too many robots, not down to what they may have since
        self.calls = Calls()
        self.cards = Cards(self.rules)
        self.tally = Tally()
        self._last_t = 0.0
        self.moves = Moves(field, robot_keys, params.formations, params.park_distance_m,
                           teleports=params.place_by == "teleport")
        self._truth: GroundTruth | None = None  # the last true state seen (where the robots stand)

    # --- commands ---------------------------------------------------------------------------
    def _set(self, command: RefereeCommand, for_team: Team | None, ready: bool = True) -> None:
        self.game.give(self.t, command, for_team, ready)

    def give(self, command: RefereeCommand, for_team: Team | None = None, ready: bool = True) -> None:
        """A command by hand (what a human referee or a scripted scene gives); restarts that need a
        ball in place are :meth:`free_kick`, :meth:`start_placement` and :meth:`start_penalty`."""
        self._restart = None
        self.game.clear_special()
        self._set(command, for_team, ready)

    def free_kick(self, team: Team, spot: tuple[float, float]) -> Teleport:
        """A free kick for ``team`` with the ball put at ``spot`` (the teleport to carry out)."""
        self.give(RefereeCommand.STOP)
        self._start_restart(RestartKind.REFEREE_FREE_KICK, team, spot, spot)
        teleport = self.moves.take(self.t)
        assert teleport is not None
        return teleport

    def start_placement(self, team: Team, target: tuple[float, float]) -> None:
        """Ball placement by ``team`` to ``target`` now, a free kick for it to follow."""
        self.give(RefereeCommand.STOP)
        self._start_restart(RestartKind.FREE_KICK, team, target, target)

    def start_penalty(self, team: Team) -> Teleport:
        """A penalty kick for ``team``: the ball on the mark (the teleport to carry out), prepared."""
        self.give(RefereeCommand.STOP)
        self._start_restart(RestartKind.PENALTY, team, self._mark(team), (0.0, 0.0))
        teleport = self.moves.take(self.t)
        assert teleport is not None
        return teleport

    def _live(self) -> bool:
        """Do goals and balls out count now? (Basic rules: whenever no restart is pending.)"""
        return not self.full or self.game.live()

    def kickoff_setup(self, kicking_team: Team = "blue") -> Teleport:
        """Both teams in formation, ball on the centre spot, kickoff for ``kicking_team`` (robots
        sent off stay off)."""
        teleport = self.moves.kickoff(self.t, self.blue_sign, self.cards.off)
        self._set(RefereeCommand.KICKOFF, kicking_team)
        self._restart_ball = (0.0, 0.0)
        self._restart_t = self.t
        self._restart_seen = False
        self._restart_touches = self.watch.touches
        return teleport

    # --- one frame --------------------------------------------------------------------------
    def observe(self, t: float, events: Sequence[Event], ball_xy: tuple[float, float],
                truth: GroundTruth | None = None) -> Teleport | None:
        """Take one frame's events at time ``t`` with the ball at ``ball_xy`` (field frame, m) and,
        for the full rules, the true state ``truth`` the auto-referee judges; returns what a restart
        due now wants placed, or None."""
        self.t = t
        self.calls.next_frame()
        if not self.params.enabled:
            self.contacts += [e for e in events if isinstance(e, Contact)]
            self.kicks += sum(isinstance(e, Kick) for e in events)
            return None
        dt, self._last_t = t - self._last_t, t
        for e in events:
            self._take(e)
        if truth is not None:
            self._truth = truth
        if self.full and truth is not None:
            self._judge(truth)
            self._follow_placement(truth)
            self._follow_penalty(truth)
            self._follow_cards(dt, truth)
            self._follow_stage()
        self._check_keeper_held_ball(t, ball_xy)
        self._check_progress(t, ball_xy)
        if self._restart is not None and t >= self._restart.due_t:
            due, self._restart = self._restart, None
            self._start_restart(due.kind, due.team, due.spot, ball_xy, due.formation)
        teleport = self.moves.take(self.t)
        # the ball as seen, not where the teleport puts it: an auto-referee on tracked vision sees it
        # there frames later (taken for seen on the spot, the ball still seen in the goal the next
        # frame was the kickoff taken)
        self._follow_kick(ball_xy)
        return teleport

    def _take(self, e: Event) -> None:
        """One of the simulator's events: contacts and kicks counted, goals and balls out judged."""
        if isinstance(e, Contact):
            self.contacts.append(e)
        elif isinstance(e, Kick):
            self.kicks += 1
            self.watch.kicked((e.team, e.id))
        elif isinstance(e, Goal) and self._restart is None and self._live():
            self._goal(other(defender_of(e.x, self.blue_sign)))
        elif isinstance(e, BallOut) and self._restart is None and self._live():
            self.balls_out += 1
            if self.game.stage == GameStage.PENALTY_SHOOTOUT:  # the kick missed
                self._next_shootout_kick()
                return
            taker = ball_out_taker(e.last_touch, e.x, self.blue_sign)
            self._award(RestartKind.FREE_KICK, taker, self._spot(RestartKind.FREE_KICK, taker, (e.x, e.y)))

    def _goal(self, scorer: Team) -> None:
        """A goal for ``scorer``: the kickoff for the other team (in a shootout: the next kick)."""
        if self.game.stage == GameStage.PENALTY_SHOOTOUT:
            if self.game.for_team == scorer:
                self.tally.shootout[scorer]["scored"] += 1
            self._next_shootout_kick()
            return
        self.score[scorer] += 1
        if self.game.command == RefereeCommand.PENALTY and self.game.for_team == scorer:
            self.tally.penalties[scorer]["scored"] += 1
        self._award(RestartKind.KICKOFF, other(scorer), (0.0, 0.0))

    def _follow_kick(self, ball_xy: tuple[float, float]) -> None:
        """A kickoff or free kick is taken once the ball moved: normal play; not taken in time, play
        goes on anyway. A ball the referee put on its spot has moved only once it was seen there: an
        auto-referee on tracked vision sees a teleported ball arrive some frames late (in grSim the
        kickoff after a goal was taken at once, the ball still seen in the goal)."""
        if not self.game.command.kick_restart or self._restart_ball is None:
            return
        away = kick_taken(ball_xy, self._restart_ball, self.rules.ball_in_play_m)
        self._restart_seen = self._restart_seen or not away
        if away and self._restart_seen:
            kicking = self.game.for_team
            self._set(RefereeCommand.NORMAL, None)
            self._restart_ball = None
            self.watch.restart_taken(self._restart_kicker(kicking))
        elif self.t - self._restart_t > self.params.restart_timeout_s:
            self._set(RefereeCommand.FORCE_START if self.full else RefereeCommand.NORMAL, None)
            self._restart_ball = None

    def _restart_kicker(self, kicking: Team | None) -> Key | None:
        """Who took the restart of ``kicking``: the last robot to touch the ball when it is of that
        team and touched it since the restart was given (or touches it still); else nobody. (A robot
        of the other team that touched the ball before a kickoff, when the ball seen moving off the
        centre spot was a track catching up with the teleported ball, was called for a double touch
        on its next touch.)"""
        last = self.watch.last_touch
        if last is None or last[0] != kicking:
            return None
        if self.watch.touches > self._restart_touches or last in self.watch.touching:
            return last
        return None

    def _start_restart(self, kind: RestartKind, team: Team | None, spot: tuple[float, float],
                       ball_xy: tuple[float, float], formation: bool = False) -> None:
        """The restart due now: the ball (and robots) where it wants them, its command given
        (``formation``: a kickoff with both teams put in formation)."""
        t = self.t
        by_robots = not self.moves.teleports
        if kind is RestartKind.FORCE_START or team is None:  # after no progress: where the ball lies, for both
            self._set(RefereeCommand.FORCE_START, None)
        elif by_robots and kind in (RestartKind.KICKOFF, RestartKind.PENALTY) \
                and self.game.stage != GameStage.PENALTY_SHOOTOUT:
            self._set(RefereeCommand.BALL_PLACEMENT, team)  # the kicking team puts the ball on its spot
            self.game.placement = Placement(team, spot, t, kind.placed)
        elif kind is RestartKind.KICKOFF and (self.params.place_robots_on_goal or formation) and not by_robots:
            self.moves.append(self.kickoff_setup(team))
        elif kind is RestartKind.FREE_KICK and self.full and self._can_place(team):
            self._set(RefereeCommand.BALL_PLACEMENT, team)
            self.game.placement = Placement(team, spot, t)
        elif kind in (RestartKind.PENALTY, RestartKind.PLACED_PENALTY):
            if self.game.stage == GameStage.PENALTY_SHOOTOUT:
                self.moves.shootout_kick(self.t, self.cards.off, self.rules.keepers, team, spot,
                                         self._attack_sign(team), self.rules.penalty_behind_m)
            else:
                self._clear_spot(spot, self._attack_sign(team))
            self.moves.add(self.t, ball=spot)
            self._set(RefereeCommand.PENALTY, team, ready=False)
            self.game.penalty = Penalty(team, t, spot)
            kicks = self.tally.shootout if self.game.stage == GameStage.PENALTY_SHOOTOUT else self.tally.penalties
            kicks[team]["taken"] += 1
        else:  # with no teleports a free kick whose ball nobody may place is taken where the ball lies
            placed = kind in (RestartKind.PLACED_FREE_KICK, RestartKind.PLACED_KICKOFF) or by_robots
            if not placed:
                self.moves.add(self.t, ball=spot)
            self._set(kind.command, team)
            self._restart_ball = ball_xy if placed else spot
            self._restart_t = t
            self._restart_seen = placed
            self._restart_touches = self.watch.touches

    def _clear_spot(self, spot: tuple[float, float], attack: float) -> None:
        """Robots standing where the referee puts the ball moved aside first (straight away from it,
        toward the kicking team's half when on it) so the ball is not put into a robot."""
        if self._truth is None:
            return
        clear = self.field.league.robot.radius_m + self.field.league.ball.radius_m + self.rules.placement_clear_m
        self.moves.clear_spot(self.t, self._truth.robots, spot, clear, attack, self.cards.off)

    def _shootout_teams(self) -> None:
        """The rules: in a shootout one attacker and the keeper per team; the others go off (the
        keeper and the field player of the lowest id stay)."""
        for team in TEAMS:
            keeper = self.rules.keepers.get(team, -1)
            on = sorted(rid for t, rid in self.robot_keys if t == team and (t, rid) not in self.cards.off)
            players = [rid for rid in on if rid != keeper]
            for rid in players[1:]:
                self._send_off((team, rid), True)

    def _can_place(self, team: Team) -> bool:
        return self.tally.may_place(team, self.rules.placement_failures_max)

    def _call(self, event: GameEvent) -> None:
        self.calls.call(event)

    def _award(self, kind: RestartKind, team: Team, spot: tuple[float, float]) -> None:
        """Stop play; after the restart delay ``kind`` for ``team`` at ``spot`` (in a penalty
        shootout: its next kick, this one over)."""
        if self.game.stage == GameStage.PENALTY_SHOOTOUT:
            self._next_shootout_kick()
            return
        self.game.clear_special()
        self._set(RefereeCommand.STOP, None)
        self._restart = Restart(self.t + self.params.restart_delay_s, kind, team, spot)

    def _attack_sign(self, team: Team) -> float:
        return attack_sign(team, self.blue_sign)

    def _mark(self, team: Team) -> tuple[float, float]:
        """The penalty mark in front of the goal ``team`` attacks."""
        return penalty_mark(self.field, self.rules.penalty_mark_from_goal_m, team, self.blue_sign)

    def _spot(self, kind: RestartKind, team: Team, ball: tuple[float, float]) -> tuple[float, float]:
        """Where the ball goes for ``kind``: the penalty mark, else the free-kick spot nearest ``ball``."""
        if kind is RestartKind.PENALTY:
            return self._mark(team)
        return self.field.free_kick_spot(*ball, self.params.free_kick_distance_m)

    # --- fouls and cards ------------------------------------------------------------------------
    def _judge(self, truth: GroundTruth) -> None:
        g = self.game
        situation = Situation(g.command, g.for_team, g.command_t, self.blue_sign, g.in_play())
        for ev in self.watch.judge(truth, situation):
            self._call(ev)
            if ev.team is not None:
                self._foul(ev.team, ev.robot)
            if ev.restart is not None and ev.for_team is not None and self._restart is None and self.game.in_play():
                kind = restart_of_call(ev.restart)
                self._award(kind, ev.for_team, self._spot(kind, ev.for_team, (truth.ball.x, truth.ball.y)))
        self._count_robots(truth)

    def _foul(self, team: Team, robot: int | None) -> None:
        """One more foul for ``team``: every ``fouls_per_yellow_card`` one gives a yellow card."""
        if self.cards.foul(team):
            self.card(team, robot)

    def card(self, team: Team, robot: int | None = None) -> None:
        """A yellow card for ``team`` (the ``red_card_yellow_cards``-th running at once: a red one):
        a robot goes off, the fouling one unless it is the keeper."""
        red = self.cards.next_is_red(team)
        off = self.cards.choose(team, robot, self.robot_keys)
        self.cards.book(team, off, red)
        if red:
            self._call(GameEvent(self.t, "red_card", team, off, unit="for the match"))
        else:
            self._call(GameEvent(self.t, "yellow_card", team, off, self.rules.yellow_card_s, unit="s"))
        if off is not None:
            self._send_off((team, off), red)

    def _send_off(self, key: Key, red: bool) -> None:
        self.cards.off[key] = red
        self.moves.send_off(self.t, key)
        self._sent_off_t[key[0]] = self.t

    def _follow_cards(self, dt: float, truth: GroundTruth) -> None:
        """Cards run while the game is not halted; a robot whose card ran out comes back at the
        halfway line, by the touch line, on a free spot."""
        if self.game.command == RefereeCommand.HALT:
            return
        for c in self.cards.run(dt):
            if self.cards.back(c):
                x, y = entry_spot(self.field, truth.robots, c.team, self.blue_sign)
                self.moves.add(self.t, [(c.team, c.robot, x, y, 0.0)])
                self._call(GameEvent(self.t, "yellow_card_over", c.team, c.robot))

    def _count_robots(self, truth: GroundTruth) -> None:
        """Too many robots: a team with more on the field than it may have; the extra go off (a
        robot sent off that came back first)."""
        leaving = self.moves.moving()  # sent off this frame
        for team in TEAMS:
            on = [r for r in truth.robots if r.team == team and (team, r.id) not in leaving
                  and self.field.in_field(r.x, r.y, -self.field.dims.boundary_width_m)]
            allowed = self.cards.max_robots(team, self.robot_keys)
            extra = len(on) - allowed
            if extra <= 0:
                self._too_many.discard(team)
                continue
            if team in self._too_many or self.t - self._sent_off_t.get(team, -math.inf) < self.leave_s:
                continue  # called already (until the team is down to what it may have), or leaving now
            self._too_many.add(team)
            ids = sorted((r.id for r in on), key=lambda rid: ((team, rid) not in self.cards.off, -rid))[:extra]
            self._call(GameEvent(self.t, "too_many_robots", team, ids[0], float(len(on)), float(allowed),
                                 "robots"))
            self._foul(team, None)
            for rid in ids:  # off (its card's robot back for good, any other until the end)
                self.moves.send_off(self.t, (team, rid))
            self._sent_off_t[team] = self.t

    # --- placement, penalty, stages ----------------------------------------------------------
    def _follow_placement(self, truth: GroundTruth) -> None:
        """A placement succeeds when the ball rests within the tolerance of the designated position
        with the placing team's robots clear of it; it fails when the time is up."""
        pl = self.game.placement
        if pl is None or self.game.command != RefereeCommand.BALL_PLACEMENT:
            return
        r = self.rules
        off, done = placed(truth, pl.team, pl.target, self.field, r)
        took = self.t - pl.t_start
        if done:
            self.tally.placed(pl.team, took)
            self._call(GameEvent(self.t, "placement_succeeded", pl.team, None, took, r.placement_time_s, "s"))
            self._award(pl.then, pl.team, pl.target)
        elif took > r.placement_time_s and pl.then is not RestartKind.PLACED_FREE_KICK:
            # (no teleports) a kickoff or penalty whose ball its team did not place: taken where the ball lies
            self.tally.failed(pl.team)
            self._call(GameEvent(self.t, "placement_failed", pl.team, None, off, r.placement_tolerance_m, "m",
                                 pl.then.command, pl.team))
            self._award(pl.then, pl.team, (truth.ball.x, truth.ball.y))
        elif took > r.placement_time_s:
            self.tally.failed(pl.team)
            self._call(GameEvent(self.t, "placement_failed", pl.team, None, off, r.placement_tolerance_m, "m",
                                 RefereeCommand.FREE_KICK, other(pl.team)))
            if self.moves.teleports:
                self.moves.add(self.t, ball=pl.target)  # the referee places it
                self._award(RestartKind.PLACED_FREE_KICK, other(pl.team), pl.target)
            else:  # the other team's free kick, placed by it if it may
                self._award(RestartKind.FREE_KICK, other(pl.team), pl.target)

    def _follow_penalty(self, truth: GroundTruth) -> None:
        pen = self.game.penalty
        if pen is None or self.game.command != RefereeCommand.PENALTY:
            return
        if not self.game.ready:
            if self.t - pen.t_start >= self.rules.prepare_timeout_s or penalty_set(
                    truth, pen.team, pen.mark, self._attack_sign(pen.team), self.field, self.rules, self.cards.off):
                pen.t_run = self.t
                self._set(RefereeCommand.PENALTY, pen.team, ready=True)
            return
        assert pen.t_run is not None
        b = truth.ball
        attack = self._attack_sign(pen.team)
        moved = kick_taken((b.x, b.y), pen.mark, self.rules.ball_in_play_m)
        took = self.t - pen.t_run
        # over (the rules) after the kicker's time, or once the ball in play moves away from the goal (the
        # keeper turned it back, or the kicker broke the rule that it only ever moves toward the goal); a
        # ball at rest waits for the kicker, who may play it again
        back_m_s = self.rules.penalty_back_m_s + self.watch.margins.ball_back_m_s
        if took > self.rules.penalty_time_s or (moved and b.vx * attack < -back_m_s):
            shootout = self.game.stage == GameStage.PENALTY_SHOOTOUT
            self._call(GameEvent(self.t, "penalty_over", pen.team, None, took, self.rules.penalty_time_s, "s",
                                 None if shootout else RefereeCommand.FREE_KICK,
                                 None if shootout else other(pen.team)))
            if shootout:
                self._next_shootout_kick()
            else:
                spot = self._spot(RestartKind.FREE_KICK, pen.team, (b.x, b.y))
                self._award(RestartKind.FREE_KICK, other(pen.team), spot)

    def _follow_stage(self) -> None:
        """Halves, half time (halted) and the end; the sides change for the second half, where the
        team that did not kick off first kicks off."""
        if not self.game.stage_over(self.t):
            return
        under_way = self.game.placing()
        if under_way is not None:
            self.tally.placements[under_way]["cut_short"] += 1
        stage = stage_after(self.game.stage, self.rules, drawn=self.score["blue"] == self.score["yellow"])
        if stage is GameStage.POST_GAME:
            self._end_match()
        else:
            self.game.enter(stage, self.t)
        if stage is GameStage.HALF_TIME:
            self._restart = None
            self.game.clear_special()
            self._set(RefereeCommand.HALT, None)
        elif stage is GameStage.SECOND_HALF:
            self.blue_sign = -1 if self.blue_sign > 0 else 1
            self._restart = None
            self.game.clear_special()
            if self.moves.teleports and self.game.command != RefereeCommand.HALT:
                # straight from play (no half time): a stop first, then the formation, as after a
                # goal (a robot holding the ball on its dribbler, teleported at once, flung it off
                # the field in grSim, whose dribbler holds the ball by a joint)
                self._set(RefereeCommand.STOP, None)
                self._restart = Restart(self.t + self.params.restart_delay_s, RestartKind.KICKOFF, "yellow",
                                        (0.0, 0.0), formation=True)
            elif self.moves.teleports:
                self.moves.append(self.kickoff_setup("yellow"))
            else:  # the ball placed on the centre spot by the kicking team first
                self._award(RestartKind.KICKOFF, "yellow", (0.0, 0.0))
        elif stage is GameStage.PENALTY_SHOOTOUT:
            self._shootout_teams()
            self._call(GameEvent(self.t, f"stage_{self.game.stage}"))
            self._next_shootout_kick()
            return
        self._call(GameEvent(self.t, f"stage_{self.game.stage}"))

    def _end_match(self) -> None:
        self.game.enter(GameStage.POST_GAME, self.t)
        self._restart = None
        self.game.clear_special()
        self._set(RefereeCommand.HALT, None)

    def _next_shootout_kick(self) -> None:
        """The shootout's next kick after the restart delay: the teams in turn (yellow first: blue kicked
        off the match), ``shootout_kicks`` each, then (a drawn match's shootout) one each until one
        team scored more of an equal number; then the game is over."""
        self.game.clear_special()
        self._set(RefereeCommand.STOP, None)
        team = shootout_kicker(self.tally.shootout, self.rules)
        if team is None:
            self._end_match()
            self._call(GameEvent(self.t, f"stage_{self.game.stage}"))
            return
        self._restart = Restart(self.t + self.params.restart_delay_s, RestartKind.PENALTY, team, self._mark(team))

    def _check_keeper_held_ball(self, t: float, ball_xy: tuple[float, float]) -> None:
        """Rules (keeper held ball): the ball in a defense area for ``keeper_held_ball_s`` of normal
        play gives the other team a free kick at the nearest legal spot."""
        side = self._held.held(t, ball_xy, self.game.command.running and self._restart is None)
        if side:
            bx, by = ball_xy
            self.keeper_held_ball += 1
            holder: Team = "blue" if side == self.blue_sign else "yellow"
            taker = other(holder)
            spot = self.field.free_kick_spot(bx, by, self.params.free_kick_distance_m)
            if self.full:
                self._call(GameEvent(t, "keeper_held_ball", holder, self.rules.keepers.get(holder),
                                     self.params.keeper_held_ball_s, self.params.keeper_held_ball_s, "s",
                                     RefereeCommand.FREE_KICK, taker))
                self._foul(holder, self.rules.keepers.get(holder))
            self._award(RestartKind.FREE_KICK, taker, spot)

    def _check_progress(self, t: float, ball_xy: tuple[float, float]) -> None:
        """Rules (no progress in game): the ball within ``no_progress_m`` of one place for
        ``no_progress_s`` while both teams may play it (two robots stuck at it, neither getting it
        away): a stop, then a force start where it lies."""
        if self._no_progress.stuck(t, ball_xy, self.full and self.game.command.running and self._restart is None):
            self._call(GameEvent(t, "no_progress", None, None, self.params.no_progress_s, self.params.no_progress_s,
                                 "s", RefereeCommand.FORCE_START))
            self._set(RefereeCommand.STOP, None)
            self._restart = Restart(t + self.params.restart_delay_s, RestartKind.FORCE_START, None, ball_xy)

    # --- out --------------------------------------------------------------------------------
    def _next(self) -> tuple[RefereeCommand | None, Team | None]:
        if self._restart is None:
            return None, None
        team = self._restart.team
        return self._restart.next_command(self.full and team is not None and self._can_place(team))

    def state(self) -> GameState:
        """The game state now, as the league's game controller sends it."""
        spot = self._restart.spot if self._restart is not None else self._restart_ball
        kick_left_s = self.params.restart_timeout_s - (self.t - self._restart_t)
        teams = {team: team_info(team, self.cards, self.tally, self.robot_keys, self.full) for team in TEAMS}
        return self.game.state(self.t, self.score, self.blue_sign, spot, kick_left_s, self._next(), teams)

    def summary(self) -> dict[str, object]:
        """The rules' figures of the match: fouls per team by kind, cards, placements, penalties."""
        by_kind = self.calls.by_kind(set(FOUL_RESTARTS))
        return {
            "rules": self.params.rules if self.params.enabled else "off",
            "game_stage": self.game.stage,
            "fouls": {t: {"total": self.cards.fouls[t], **by_kind[t]} for t in TEAMS},
            "cards": {t: {"yellow": self.cards.yellow[t], "red": self.cards.red[t]} for t in TEAMS},
            **self.tally.figures(self.game.placing()),
        }
