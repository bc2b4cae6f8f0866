"""The auto-referee: the league's fouls, seen on the simulator's true state frame by frame.

Each foul is a small named check over the truth (field frame, metres, seconds); :class:`FoulWatch`
keeps what the checks need across frames (who touches the ball and since where, which robots are in
contact and since when, who was called already) and answers each frame with the fouls it saw, as
:class:`~cmdragons.messages.GameEvent` values carrying the figure that broke the rule. What a foul
leads to (a free kick, a penalty, a card) the game controller (:mod:`sim.referee`) decides.
"""

from __future__ import annotations

import math
from collections.abc import Collection, Mapping
from dataclasses import dataclass, field

from cmdragons.config import Validated, setting
from cmdragons.geometry import Field, Team
from cmdragons.messages import BallTruth, GameEvent, GroundTruth, RefereeCommand, RobotTruth
from sim.restarts import other

__all__ = ["FOUL_RESTARTS", "FoulWatch", "HeldBall", "NoProgress", "RulesParams", "Situation", "TrackMargins",
           "penalty_set", "placed"]

Key = tuple[Team, int]

# what each foul leads to: a free kick (or a penalty kick) for the other team, or (None) nothing but the count
_FREE, _PENALTY = RefereeCommand.FREE_KICK, RefereeCommand.PENALTY
FOUL_RESTARTS: dict[str, RefereeCommand | None] = {
    "crash": _FREE, "crash_drawn": None, "pushing": _FREE, "ball_too_fast": _FREE, "excessive_dribbling": _FREE,
    "attacker_in_defense_area": _FREE, "defender_in_defense_area": _PENALTY, "double_touch": _FREE,
    "stop_speed": None, "stop_distance": None, "kick_point_distance": None, "keeper_held_ball": _FREE,
    "boundary_crossing": _FREE, "too_many_robots": None,
}


@dataclass(frozen=True)
class RulesParams(Validated):
    """The league's figures (configs/sim.yaml referee.rules; each key names its rule there)."""

    half_s: float = setting(300.0, lo=1.0, hi=3600.0)
    half_time_s: float = setting(300.0, lo=0.0, hi=3600.0)
    timeouts: int = setting(4, lo=0, hi=20)
    timeout_total_s: float = setting(300.0, lo=0.0, hi=3600.0)
    stop_speed_m_s: float = setting(1.5, lo=0.1, hi=10.0)
    stop_distance_m: float = setting(0.5, lo=0.0, hi=5.0)
    stop_grace_s: float = setting(2.0, lo=0.0, hi=30.0)
    ball_speed_limit_m_s: float = setting(6.5, lo=0.1, hi=20.0)
    crash_speed_m_s: float = setting(1.5, lo=0.1, hi=10.0)
    crash_drawn_m_s: float = setting(0.3, lo=0.0, hi=10.0)
    push_distance_m: float = setting(0.2, lo=0.01, hi=5.0)
    dribble_distance_m: float = setting(1.0, lo=0.1, hi=20.0)
    kick_point_distance_m: float = setting(0.5, lo=0.0, hi=5.0)
    kick_point_grace_s: float = setting(1.0, lo=0.0, hi=30.0)
    ball_in_play_m: float = setting(0.05, lo=0.001, hi=1.0)
    placement_time_s: float = setting(30.0, lo=1.0, hi=600.0)
    placement_tolerance_m: float = setting(0.15, lo=0.01, hi=2.0)
    placement_clear_m: float = setting(0.05, lo=0.0, hi=2.0)
    placement_rest_m_s: float = setting(0.1, lo=0.0, hi=5.0)
    placement_failures_max: int = setting(5, lo=1, hi=100)
    fouls_per_yellow_card: int = setting(3, lo=1, hi=100)
    yellow_card_s: float = setting(120.0, lo=1.0, hi=3600.0)
    red_card_yellow_cards: int = setting(3, lo=0, hi=100)
    prepare_timeout_s: float = setting(10.0, lo=0.0, hi=600.0)
    penalty_mark_from_goal_m: float = setting(6.0, lo=0.5, hi=20.0)
    penalty_behind_m: float = setting(1.0, lo=0.0, hi=10.0)
    penalty_time_s: float = setting(10.0, lo=0.5, hi=600.0)
    penalty_back_m_s: float = setting(0.05, lo=0.0, hi=5.0)
    shootout_kicks: int = setting(0, lo=0, hi=100)  # penalty shootout after a drawn match: kicks per team; 0: none
    shootout_always: bool = False  # the shootout after any match (a benchmark's), its kicks only
    touch_margin_m: float = setting(0.015, lo=0.0, hi=0.2)
    contact_margin_m: float = setting(0.01, lo=0.0, hi=0.2)
    keepers: Mapping[Team, int] = field(default_factory=lambda: {"blue": 0, "yellow": 0})


@dataclass(frozen=True)
class TrackMargins(Validated):
    """What a watch on tracked positions allows for their noise (configs/sim.yaml referee.autoref;
    none on the simulator's truth): a touch or a contact, once begun, lasts until the ball or the
    robots are this much farther apart than where it began, so a track's jitter at the edge does not
    end and start it again (a double touch, a second crash that never happened)."""

    touch_release_m: float = setting(0.0, lo=0.0, hi=0.5)
    contact_release_m: float = setting(0.0, lo=0.0, hi=0.5)
    # a distance foul (at a stop, at the other team's free kick) only this far inside the rule's distance,
    # a speed foul at a stop only this much over the rule's speed: the benefit of the tracks' doubt
    distance_m: float = setting(0.0, lo=0.0, hi=0.5)
    speed_m_s: float = setting(0.0, lo=0.0, hi=2.0)
    # the ball too fast in this many frames in a row (a track's velocity overshoots for a frame after a kick)
    fast_ball_frames: int = setting(1, lo=1, hi=100)
    # a ball passing a robot faster than this (relative to it) starts a touch by coming near it only where
    # its track went into the robot's body deeper than touch_pass_depth_m: near a robot on tracks is not at
    # it (a ball that passed by unchanged was not touched), but a track that runs on straight through a
    # robot missed the graze that turned the ball (none on the truth: near is touching)
    touch_pass_speed_m_s: float = setting(math.inf, lo=0.0)
    touch_pass_depth_m: float = setting(0.0, lo=0.0, hi=0.1)
    # a penalty over by the ball rolling back from the goal only this much faster than the rule's speed: a
    # ball at rest, a robot's front reaching it, moves on its track (its blob pulled toward the robot's)
    ball_back_m_s: float = setting(0.0, lo=0.0, hi=2.0)


@dataclass(frozen=True)
class Situation:
    """What the checks need of the game controller this frame."""

    command: RefereeCommand
    for_team: Team | None
    since: float  # when the command was given (s)
    blue_sign: int  # -1: blue defends the goal at -x
    in_play: bool  # the ball is in play (normal play, or a restart taken)


@dataclass
class _Touch:
    start: tuple[float, float]  # where the ball was when the robot took it
    called: bool = False


@dataclass
class _Contact:
    t: float
    normal: tuple[float, float]  # unit vector from a to b at first touch
    a0: tuple[float, float]
    b0: tuple[float, float]
    pushed: bool = False


def _team_sign(team: Team, blue_sign: int) -> int:
    """The side of the goal ``team`` defends: -1 for -x."""
    return blue_sign if team == "blue" else -blue_sign


class FoulWatch:
    """Frame-by-frame foul detection on the true state (or, with ``margins``, on tracks)."""

    def __init__(self, pitch: Field, params: RulesParams, margins: TrackMargins = TrackMargins()) -> None:
        self.field, self.p, self.margins = pitch, params, margins
        self.robot_r = pitch.league.robot.radius_m
        self.ball_r = pitch.league.ball.radius_m
        self.touching: dict[Key, _Touch] = {}
        self.last_touch: Key | None = None
        self.touches = 0  # new touches so far (a touch's start, whoever's)
        self._prev: dict[Key, RobotTruth] = {}
        self._contacts: dict[tuple[Key, Key], _Contact] = {}
        self._called: set[tuple[str, Key]] = set()  # once per robot per stop or restart
        self._called_since = -math.inf
        self._restart_kicker: Key | None = None  # a restart's kicker until another robot touched the ball
        self._kicker_left = False  # ... and whether it let go of the ball since
        self._fast_ball_called = False
        self._fast_frames = 0  # frames in a row the ball was too fast
        self._kicked: list[Key] = []  # new touches by a kick since the last frame judged

    def kicked(self, kicker: Key) -> None:
        """The simulator's kicker fired: a touch, however short (a kick can leave before a frame shows it);
        a new one (the robot not touching the ball already) counts as the frame's new touch for the
        double touch and the defense areas, as one seen by distance does."""
        if kicker not in self.touching:
            self._kicked.append(kicker)
            self.touches += 1
        self.touching.setdefault(kicker, _Touch((math.nan, math.nan), called=True))
        self.last_touch = kicker
        self._fast_ball_called = False

    def restart_taken(self, kicker: Key | None) -> None:
        """A kickoff or free kick was taken by ``kicker`` (None: by no robot seen touching the ball): a
        second touch before another robot's is a foul."""
        self._restart_kicker = kicker
        self._kicker_left = False

    def judge(self, gt: GroundTruth, s: Situation) -> list[GameEvent]:
        if s.since != self._called_since:
            self._called, self._called_since = set(), s.since
        robots = [r for r in gt.robots if self.field.in_field(r.x, r.y, -self.field.dims.boundary_width_m)]
        out: list[GameEvent] = []
        new_touches = self._touches(gt, robots)
        if s.command != RefereeCommand.HALT:
            out += self._crashes(gt, robots)
        if s.in_play:
            out += self._ball_too_fast(gt)
            out += self._dribbling(gt)
            out += self._area_touches(gt, robots, new_touches, s)
            out += self._double_touch(gt, new_touches)
        else:
            self._restart_kicker = None
        if s.command != RefereeCommand.HALT:  # the ball crosses the boundary after the line: play is already stopped
            out += self._boundary(gt)
        if s.command == RefereeCommand.STOP and gt.t - s.since >= self.p.stop_grace_s:
            out += self._stop(gt, robots)
        if s.command.kick_restart and s.for_team is not None and not s.in_play \
                and gt.t - s.since >= self.p.kick_point_grace_s:
            out += self._kick_point(gt, robots, other(s.for_team))
        self._prev = {(r.team, r.id): r for r in robots}
        return out

    # --- ball touches -------------------------------------------------------------------------
    def _touches(self, gt: GroundTruth, robots: list[RobotTruth]) -> list[Key]:
        """Which robots touch the ball now (the ball on the ground): a touch begins with the ball
        within the touch margin of the robot's body (:meth:`_near`; the simulator's contact is at the
        body, not at its round disc, whose reach passes 0.02 m in front of the face) and lasts while
        its centre is within the robot's radius plus the ball's, the margin and the release (a
        track's jitter at the face is no new touch); returns those that started touching it this
        frame."""
        b = gt.ball
        reach = self.robot_r + self.ball_r + self.p.touch_margin_m
        release = self.margins.touch_release_m
        now = {(r.team, r.id) for r in robots if b.z < 2.0 * self.ball_r + 0.05
               and (math.hypot(r.x - b.x, r.y - b.y) < reach + release if (r.team, r.id) in self.touching
                    else self._near(r, b) < reach and not self._passing(r, b))}
        new = [k for k in sorted(now) if k not in self.touching]
        for k in list(self.touching):
            if k not in now:
                del self.touching[k]
                if k == self._restart_kicker:
                    self._kicker_left = True
        for k in new:
            self.touching[k] = _Touch((b.x, b.y))
            self.last_touch = k
            self.touches += 1
            self._fast_ball_called = False
        on = {(r.team, r.id) for r in robots}
        kicked, self._kicked = self._kicked, []
        return new + [k for k in kicked if k not in new and k in on]

    def _near(self, r: RobotTruth, b: BallTruth) -> float:
        """How near the ball's centre is to the body of ``r``, the disc cut flat at the front, as a
        distance from its centre (m): the gap to the body plus its radius (its front face lies 0.02 m
        inside the disc: a ball that near the face, in front of it, has not met it)."""
        c, s = math.cos(r.theta), math.sin(r.theta)
        dx, dy = b.x - r.x, b.y - r.y
        return self.field.league.robot.gap(c * dx + s * dy, -s * dx + c * dy) + self.robot_r

    def _passing(self, r: RobotTruth, b: BallTruth) -> bool:
        """Is the ball near ``r`` only passing it by (:class:`TrackMargins`: faster than
        ``touch_pass_speed_m_s`` relative to it, its centre not ``touch_pass_depth_m`` inside its body)?"""
        m = self.margins
        if math.hypot(b.vx - r.vx, b.vy - r.vy) <= m.touch_pass_speed_m_s:
            return False
        c, s = math.cos(r.theta), math.sin(r.theta)
        dx, dy = b.x - r.x, b.y - r.y
        return self.field.league.robot.gap(c * dx + s * dy, -s * dx + c * dy) - self.ball_r >= -m.touch_pass_depth_m

    def _event(self, t: float, kind: str, key: Key | None, value: float, limit: float, unit: str) -> GameEvent:
        restart = FOUL_RESTARTS[kind]
        team = None if key is None else key[0]
        return GameEvent(t, kind, team, None if key is None else key[1], value, limit, unit, restart,
                         other(team) if restart is not None and team is not None else None)

    def _once(self, kind: str, key: Key) -> bool:
        """True the first time ``kind`` is called on ``key`` since the command changed."""
        if (kind, key) in self._called:
            return False
        self._called.add((kind, key))
        return True

    # --- the checks -----------------------------------------------------------------------------
    def _crashes(self, gt: GroundTruth, robots: list[RobotTruth]) -> list[GameEvent]:
        """Crash: two robots of different teams meet faster than ``crash_speed_m_s`` (the difference
        of their velocities the frame before contact, along the line between them); the faster robot
        (its own speed) is at fault, both when their speeds differ by less than ``crash_drawn_m_s``
        (the rules: "the faster robot committed a foul; if the absolute robot speed difference is
        less than 0.3 m/s, both"). Pushing: an opponent shoved more than ``push_distance_m`` while in
        contact."""
        out = []
        touch = 2.0 * self.robot_r + self.p.contact_margin_m
        blue = [r for r in robots if r.team == "blue"]
        yellow = [r for r in robots if r.team == "yellow"]
        seen = set()
        for a in blue:
            for b in yellow:
                dx, dy = b.x - a.x, b.y - a.y
                d = math.hypot(dx, dy)
                ka, kb = (a.team, a.id), (b.team, b.id)
                pair = (ka, kb)
                if d >= touch + (self.margins.contact_release_m if pair in self._contacts else 0.0) or d < 1e-9:
                    continue
                seen.add(pair)
                n = (dx / d, dy / d)
                c = self._contacts.get(pair)
                if c is None:
                    pa, pb = self._prev.get(ka, a), self._prev.get(kb, b)
                    sa = pa.vx * n[0] + pa.vy * n[1]  # a's speed toward b
                    sb = -(pb.vx * n[0] + pb.vy * n[1])  # b's speed toward a
                    self._contacts[pair] = c = _Contact(gt.t, n, (a.x, a.y), (b.x, b.y))
                    closing = sa + sb
                    if closing > self.p.crash_speed_m_s:
                        va, vb = math.hypot(pa.vx, pa.vy), math.hypot(pb.vx, pb.vy)
                        if abs(va - vb) < self.p.crash_drawn_m_s:
                            out += [self._event(gt.t, "crash_drawn", k, closing, self.p.crash_speed_m_s, "m/s")
                                    for k in (ka, kb)]
                        else:
                            out.append(self._event(gt.t, "crash", ka if va > vb else kb, closing,
                                                   self.p.crash_speed_m_s, "m/s"))
                    continue
                if c.pushed:
                    continue
                nx, ny = c.normal
                b_moved = (b.x - c.b0[0]) * nx + (b.y - c.b0[1]) * ny  # b driven away from a
                a_moved = -((a.x - c.a0[0]) * nx + (a.y - c.a0[1]) * ny)  # a driven away from b
                if b_moved > self.p.push_distance_m and a_moved < 0.0:
                    c.pushed = True
                    out.append(self._event(gt.t, "pushing", ka, b_moved, self.p.push_distance_m, "m"))
                elif a_moved > self.p.push_distance_m and b_moved < 0.0:
                    c.pushed = True
                    out.append(self._event(gt.t, "pushing", kb, a_moved, self.p.push_distance_m, "m"))
        for pair in list(self._contacts):
            if pair not in seen:
                del self._contacts[pair]
        return out

    def _ball_too_fast(self, gt: GroundTruth) -> list[GameEvent]:
        """Ball speed over ``ball_speed_limit_m_s``: the last robot to touch it is at fault (once a touch)."""
        b = gt.ball
        speed = math.sqrt(b.vx * b.vx + b.vy * b.vy + b.vz * b.vz)
        self._fast_frames = self._fast_frames + 1 if speed > self.p.ball_speed_limit_m_s else 0
        if self._fast_frames < self.margins.fast_ball_frames or self._fast_ball_called or self.last_touch is None:
            return []
        self._fast_ball_called = True
        return [self._event(gt.t, "ball_too_fast", self.last_touch, speed, self.p.ball_speed_limit_m_s, "m/s")]

    def _dribbling(self, gt: GroundTruth) -> list[GameEvent]:
        """A robot in touch with the ball all the way since it took it, the ball now farther than
        ``dribble_distance_m`` from where it was then."""
        out = []
        for k, touch in self.touching.items():
            d = math.hypot(gt.ball.x - touch.start[0], gt.ball.y - touch.start[1])
            if d > self.p.dribble_distance_m and not touch.called:
                touch.called = True
                out.append(self._event(gt.t, "excessive_dribbling", k, d, self.p.dribble_distance_m, "m"))
        return out

    def _area_touches(self, gt: GroundTruth, robots: list[RobotTruth], new: list[Key],
                      s: Situation) -> list[GameEvent]:
        """A robot that starts touching the ball inside the opponent's defense area (the ball in
        it); a robot other than the keeper touching it with its centre inside its own."""
        out = []
        by_key = {(r.team, r.id): r for r in robots}
        side = self.field.in_defense_area(gt.ball.x, gt.ball.y)
        for k in new:
            r = by_key[k]
            own = _team_sign(k[0], s.blue_sign)
            if side and side != own:
                out.append(self._event(gt.t, "attacker_in_defense_area", k, 0.0, 0.0, ""))
            elif k[1] != self.p.keepers.get(k[0], -1) and self.field.in_defense_area(r.x, r.y) == own:
                depth = self.field.half_length - abs(r.x)
                out.append(self._event(gt.t, "defender_in_defense_area", k, depth, self.field.dims.defense_depth_m,
                                       "m from the goal line"))
        return out

    def _double_touch(self, gt: GroundTruth, new: list[Key]) -> list[GameEvent]:
        """After a restart its kicker touches the ball again before any other robot did."""
        kicker = self._restart_kicker
        if kicker is None:
            return []
        if kicker not in self.touching:
            self._kicker_left = True
        others = [k for k in new if k != kicker]
        if others:
            self._restart_kicker = None
            return []
        if kicker in new and self._kicker_left:
            self._restart_kicker = None
            return [self._event(gt.t, "double_touch", kicker, 2.0, 1.0, "touches")]
        return []

    def _boundary(self, gt: GroundTruth) -> list[GameEvent]:
        """The ball past the boundary walls (chipped out of the field's enclosure)."""
        b, f = gt.ball, self.field
        if abs(b.x) <= f.boundary_half_length and abs(b.y) <= f.boundary_half_width:
            return []
        key = self.last_touch
        if key is None or not self._once("boundary_crossing", key):
            return []
        beyond = max(abs(b.x) - f.boundary_half_length, abs(b.y) - f.boundary_half_width)
        return [self._event(gt.t, "boundary_crossing", key, beyond, 0.0, "m past the boundary")]

    def _gap(self, r: RobotTruth, gt: GroundTruth) -> float:
        """From the robot's body to the ball's centre (m)."""
        return math.hypot(r.x - gt.ball.x, r.y - gt.ball.y) - self.robot_r

    def _stop(self, gt: GroundTruth, robots: list[RobotTruth]) -> list[GameEvent]:
        """In a stop (after ``stop_grace_s``): faster than ``stop_speed_m_s`` or nearer the ball than
        ``stop_distance_m``; once per robot and stop."""
        out = []
        for r in robots:
            k = (r.team, r.id)
            speed = math.hypot(r.vx, r.vy)
            if speed > self.p.stop_speed_m_s + self.margins.speed_m_s and self._once("stop_speed", k):
                out.append(self._event(gt.t, "stop_speed", k, speed, self.p.stop_speed_m_s, "m/s"))
            gap = self._gap(r, gt)
            if gap < self.p.stop_distance_m - self.margins.distance_m and self._once("stop_distance", k):
                out.append(self._event(gt.t, "stop_distance", k, gap, self.p.stop_distance_m, "m"))
        return out

    def _kick_point(self, gt: GroundTruth, robots: list[RobotTruth], defending: Team) -> list[GameEvent]:
        """At the other team's kickoff or free kick, a robot nearer the ball than ``kick_point_distance_m``."""
        out = []
        for r in robots:
            k = (r.team, r.id)
            if r.team != defending:
                continue
            gap = self._gap(r, gt)
            if gap < self.p.kick_point_distance_m - self.margins.distance_m and self._once("kick_point_distance", k):
                out.append(self._event(gt.t, "kick_point_distance", k, gap, self.p.kick_point_distance_m, "m"))
        return out


class HeldBall:
    """Keeper held ball (the rules): the ball in a defense area for ``limit_s`` of normal play."""

    def __init__(self, pitch: Field, limit_s: float) -> None:
        self.field, self.limit_s = pitch, limit_s
        self._since: float | None = None  # watched, the ball in a defense area since

    def held(self, t: float, ball_xy: tuple[float, float], watched: bool) -> int:
        """The side (-1: the area at -x) of the area the ball has been in ``limit_s`` at ``t`` while
        ``watched`` (normal play, no restart pending), else 0; counting starts again after a call."""
        side = self.field.in_defense_area(*ball_xy)
        if not watched or not side:
            self._since = None
            return 0
        if self._since is None:
            self._since = t
        elif t - self._since >= self.limit_s:
            self._since = None
            return side
        return 0


class NoProgress:
    """No progress in game (the rules): the ball within ``within_m`` of one place for ``limit_s``
    while both teams may play it."""

    def __init__(self, limit_s: float, within_m: float) -> None:
        self.limit_s, self.within_m = limit_s, within_m
        self._still: tuple[float, tuple[float, float]] | None = None  # watched, the ball in one place since, where

    def stuck(self, t: float, ball_xy: tuple[float, float], watched: bool) -> bool:
        """True once the ball lay in one place ``limit_s`` while ``watched``; counting starts again after."""
        if not watched:
            self._still = None
            return False
        if self._still is None or math.dist(ball_xy, self._still[1]) > self.within_m:
            self._still = (t, ball_xy)
        elif t - self._still[0] >= self.limit_s:
            self._still = None
            return True
        return False


def placed(gt: GroundTruth, team: Team, target: tuple[float, float], pitch: Field,
           p: RulesParams) -> tuple[float, bool]:
    """Ball placement by ``team``: how far the ball is off ``target`` (m), and whether the
    placement succeeded: the ball within ``placement_tolerance_m`` of it, at rest (slower than
    ``placement_rest_m_s``), the team's robots ``placement_clear_m`` clear of it."""
    b = gt.ball
    off = math.hypot(b.x - target[0], b.y - target[1])
    clear = pitch.league.robot.radius_m + pitch.league.ball.radius_m + p.placement_clear_m
    cleared = all(math.hypot(o.x - b.x, o.y - b.y) >= clear for o in gt.robots if o.team == team)
    return off, off <= p.placement_tolerance_m and math.hypot(b.vx, b.vy) <= p.placement_rest_m_s and cleared


def penalty_set(gt: GroundTruth, team: Team, mark: tuple[float, float], attack: float, pitch: Field,
                p: RulesParams, off: Collection[Key]) -> bool:
    """A penalty by ``team`` at ``mark`` (``attack``: +1.0 toward +x) is ready for its normal start:
    every robot on the field (those ``off`` aside) but the kicker (the team's nearest to the mark)
    and the other keeper ``penalty_behind_m`` behind the ball, that keeper on its goal line."""
    keeper = (other(team), p.keepers.get(other(team), -1))
    ours = [r for r in gt.robots if r.team == team and (r.team, r.id) not in off]
    kicker = min(ours, key=lambda r: math.hypot(r.x - mark[0], r.y - mark[1]), default=None)
    for o in gt.robots:
        key = (o.team, o.id)
        if key in off or o is kicker:
            continue
        if key == keeper:
            if abs(abs(o.x) - pitch.half_length) > pitch.league.robot.radius_m:
                return False
        elif (o.x - mark[0]) * attack > -p.penalty_behind_m:
            return False
    return True
