"""The auto-referee on vision: our referee judging the tracked world, where no truth is known.

With an outside simulator (or a real field) the referee sees only what the cameras show: the
tracker's ball and robots. :class:`AutoRef` is the simulator's :class:`~sim.referee.Referee` (the
same rules, restarts and game controller) fed from tracks: each frame's world state becomes the state
the referee judges (:func:`observed`: ball and robots as seen, the ball on the ground), and the events
the simulator would have told are inferred from the ball's track: a goal or a ball out when the
track crosses the goal or a touch line (:class:`BallCrossing`), a touch when its velocity jumps with
a robot at it (:class:`KickDetector`, the kick detector: the double touch, the last touch before a
ball out, dribbling, the defense areas all start from it). The fouls are then the same checks
(:mod:`sim.rules`) with margins for the tracks' noise (:class:`~sim.rules.TrackMargins`).

What the referee decides comes out as it does in the simulator: the game state, its calls (with a
goal and a ball out each a call here, as the league's game events have them) and the teleports a
restart wants (the ball on its spot, the robots in formation), which an outside simulator carries
out as its own teleports. Field frame, metres, seconds.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Sequence

from cmdragons.geometry import Field, Team
from cmdragons.messages import (
    BallOut,
    BallTruth,
    Event,
    GameEvent,
    GameState,
    Goal,
    GroundTruth,
    Kick,
    RefereeCommand,
    RobotTruth,
    Teleport,
    WorldState,
)
from sim.referee import Referee
from sim.referee_params import AutorefParams, RefereeParams
from sim.restarts import ball_out_taker, defender_of, other

__all__ = ["AutoRef", "BallCrossing", "KickDetector", "OwnContacts", "observed"]

Key = tuple[Team, int]


def observed(world: WorldState, ball_xy: tuple[float, float]) -> GroundTruth:
    """The tracked ``world`` in the shape the referee judges: the robots seen in its newest frame
    (a track only predicted is a robot no camera shows: gone off the field, or not there), the ball
    on the ground at its track (where it was last seen, ``ball_xy``, at rest, when there is none)."""
    b = world.ball
    ball = BallTruth(b.x, b.y, 0.0, b.vx, b.vy) if b is not None else BallTruth(*ball_xy, 0.0, 0.0, 0.0)
    robots = tuple(RobotTruth(r.team, r.id, r.x, r.y, r.theta, r.vx, r.vy, r.omega) for r in world.robots
                   if r.visible)
    return GroundTruth(world.frame_number, world.t, ball, robots)


class BallCrossing:
    """Goals and balls out from the ball's track: past a goal line between the posts (a goal at that
    side) or past a touch or goal line elsewhere (out, where it crossed), each once until the ball is
    back on the field. The test the simulator makes on its own ball, here on the track."""

    def __init__(self, pitch: Field) -> None:
        self.field = pitch
        self._pending = False  # a crossing called, the ball not back on the field since

    def see(self, t: float, x: float, y: float, blue_sign: int, last_touch: Team | None) -> Goal | BallOut | None:
        """The crossing the ball at (``x``, ``y``) makes at ``t``, if new; ``blue_sign`` -1 while blue
        defends the goal at -x; ``last_touch``: the team that touched the ball last."""
        f, r = self.field, self.field.league.ball.radius_m
        past_goal_line = abs(x) > f.half_length + r
        if not (past_goal_line or abs(y) > f.half_width + r):
            self._pending = False
            return None
        if self._pending:
            return None
        self._pending = True
        if past_goal_line and abs(y) < f.goal_half_width:
            return Goal(t, other(defender_of(x, blue_sign)), x, y)
        cx = min(max(x, -f.half_length), f.half_length)
        cy = min(max(y, -f.half_width), f.half_width)
        return BallOut(t, cx, cy, last_touch)


class KickDetector:
    """Touches of the ball from its track: its velocity changes by more than
    ``kick_speed_change_m_s`` between two frames (a kick, a push, a bounce off a robot) with a robot's
    body within ``kick_reach_m`` of it at some moment of the last ``kick_memory_s``: the robot last at
    the ball (the nearest in the newest frame that had one) touched it. A ball that jumps farther than
    it could roll (put somewhere, or another ball taken for it) starts the watch afresh."""

    def __init__(self, pitch: Field, params: AutorefParams, max_ball_speed_m_s: float = 10.0) -> None:
        self.p = params
        self.robot_r = pitch.league.robot.radius_m
        self.ball_r = pitch.league.ball.radius_m
        self.max_ball_speed_m_s = max_ball_speed_m_s
        self._last: tuple[float, float, float, float, float] | None = None  # t, x, y, vx, vy
        self._recent: deque[tuple[float, dict[Key, float]]] = deque()  # t, each robot's gap to the ball (m)

    def see(self, world: WorldState) -> Kick | None:
        """The touch ``world``'s ball shows, or None."""
        b, t = world.ball, world.t
        if b is None:
            self._last = None
            self._recent.clear()
            return None
        gaps = {(r.team, r.id): math.hypot(r.x - b.x, r.y - b.y) - self.robot_r - self.ball_r
                for r in world.robots if r.visible}
        last, self._last = self._last, (t, b.x, b.y, b.vx, b.vy)
        self._recent.append((t, gaps))
        while self._recent and t - self._recent[0][0] > self.p.kick_memory_s:
            self._recent.popleft()
        if last is None:
            return None
        t0, x0, y0, vx0, vy0 = last
        jump = math.hypot(b.x - x0, b.y - y0)
        if jump > self.max_ball_speed_m_s * max(t - t0, 1e-3) + self.ball_r:
            self._recent = deque([(t, gaps)])  # put somewhere else: a new watch
            return None
        if math.hypot(b.vx - vx0, b.vy - vy0) <= self.p.kick_speed_change_m_s:
            return None
        for _, g in reversed(self._recent):  # the last robot at the ball (the nearest of that frame)
            near = sorted((gap, k) for k, gap in g.items() if gap <= self.p.kick_reach_m)
            if near:
                key = near[0][1]
                return Kick(t, key[0], key[1], math.hypot(b.vx, b.vy), False)
        return None


class OwnContacts:
    """Contacts between robots of one team, from their tracks: no foul (the rules leave a team's own
    robots to it), but each one a fault of its play. Two robots of a team whose centres come within
    ``touch_m`` begin one, which lasts until they are ``release_m`` farther apart than that (the
    tracks' jitter at the edge is no new contact); a robot out of sight ends its contacts."""

    def __init__(self, touch_m: float, release_m: float) -> None:
        self.touch_m, self.release_m = touch_m, release_m
        self.count: dict[Team, int] = {"blue": 0, "yellow": 0}
        self._open: set[tuple[Key, Key]] = set()

    def see(self, robots: Sequence[RobotTruth]) -> int:
        """One frame's robots (those seen): the contacts that begin in it are counted; how many."""
        began = 0
        touching: set[tuple[Key, Key]] = set()
        ordered = sorted(robots, key=lambda r: (r.team, r.id))
        for i, a in enumerate(ordered):
            for b in ordered[i + 1:]:
                if b.team != a.team:
                    continue
                pair = ((a.team, a.id), (b.team, b.id))
                reach = self.touch_m + (self.release_m if pair in self._open else 0.0)
                if math.hypot(b.x - a.x, b.y - a.y) < reach:
                    touching.add(pair)
                    if pair not in self._open:
                        self.count[a.team] += 1
                        began += 1
        self._open = touching
        return began


class AutoRef:
    """The referee on the tracked world: one :meth:`observe` per world state. ``keys``: the match's
    robots (team, id), as the game controller knows them."""

    def __init__(self, pitch: Field, keys: Sequence[Key], params: RefereeParams) -> None:
        a = params.autoref
        self.referee = Referee(pitch, keys, params, a.margins, a.leave_s)
        self.crossing = BallCrossing(pitch)
        self.kicks = KickDetector(pitch, a)
        self.own_contacts = OwnContacts(2.0 * pitch.league.robot.radius_m + params.figures.contact_margin_m,
                                        a.own_contact_release_m)
        self._ball = (0.0, 0.0)  # where the ball was last seen

    def start(self) -> Teleport:
        """The match's first kickoff for blue: both teams in formation, the ball on the centre spot."""
        return self.referee.kickoff_setup("blue")

    def observe(self, world: WorldState) -> Teleport | None:
        """Judge one tracked frame; returns what a restart due now wants placed, or None. The
        frame's calls are then :attr:`calls` (goals and balls out among them)."""
        r = self.referee
        if world.ball is not None:
            self._ball = (world.ball.x, world.ball.y)
        events: list[Event] = []
        kick = self.kicks.see(world)
        if kick is not None and (kick.team, kick.id) == r.watch.last_touch:
            kick = None  # the last toucher's own touch seen late (the track's velocity lags the kick): no new one
        if kick is not None:
            events.append(kick)
        last = r.watch.last_touch if kick is None else (kick.team, kick.id)
        crossing = self.crossing.see(world.t, *self._ball, r.blue_sign, None if last is None else last[0])
        if crossing is not None:
            events.append(crossing)
        score, outs, sign = dict(r.score), r.balls_out, r.blue_sign
        seen = observed(world, self._ball)
        self.own_contacts.see(seen.robots)
        teleport = r.observe(world.t, events, self._ball, seen)
        if isinstance(crossing, Goal):
            scorer = next((team for team in r.score if r.score[team] > score[team]), None)
            if scorer is not None:
                r.calls.call(GameEvent(world.t, "goal", scorer, None, float(r.score[scorer]), math.nan, "goals",
                                       RefereeCommand.KICKOFF, other(scorer)))
        elif isinstance(crossing, BallOut) and r.balls_out > outs:
            taker = ball_out_taker(crossing.last_touch, crossing.x, sign)
            r.calls.call(GameEvent(world.t, "ball_out", crossing.last_touch, None if last is None else last[1],
                                   restart=RefereeCommand.FREE_KICK, for_team=taker))
        return teleport

    @property
    def calls(self) -> list[GameEvent]:
        """The calls of the frame last observed."""
        return self.referee.calls.new

    def state(self) -> GameState:
        """The game state now, as the league's game controller sends it."""
        return self.referee.state()

    def summary(self) -> dict[str, object]:
        """The match's figures as the referee's summary gives them, with goals and balls out, and the
        contacts between robots of one team (:class:`OwnContacts`)."""
        r = self.referee
        return {"score": dict(r.score), "balls_out": r.balls_out, "kicks_seen": r.kicks,
                "keeper_held_ball": r.keeper_held_ball, "own_contacts": dict(self.own_contacts.count), **r.summary()}
