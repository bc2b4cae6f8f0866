"""The auto-referee on vision: our referee judging the tracked world, where no truth is known.

With an outside simulator (or a real field) the referee sees only what the cameras show: the
tracker's ball and robots. :class:`AutoRef` is the simulator's :class:`~sim.referee.Referee` (the
same rules, restarts and game controller) fed from tracks: each frame's world state becomes the state
the referee judges (:func:`observed`: ball and robots as seen, the ball on the ground), and the events
the simulator would have told are inferred from the ball's track: a goal or a ball out when the
track crosses the goal or a touch line (:class:`BallCrossing`), a touch when its velocity jumps with
a robot at it (:class:`KickDetector`, the kick detector: the double touch, the last touch before a
ball out, dribbling, the defense areas all start from it). The fouls are then the same checks
(:mod:`sim.rules`) with margins for the tracks' noise (:class:`~sim.rules.TrackMargins`). Beside the
rules it counts the collisions among one team's robots from their tracks (:class:`OwnContacts`), a
figure of the match where no simulator tells its contacts.

What the referee decides comes out as it does in the simulator: the game state, its calls (with a
goal and a ball out each a call here, as the league's game events have them) and the teleports a
restart wants (the ball on its spot, the robots in formation), which an outside simulator carries
out as its own teleports. Field frame, metres, seconds.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Sequence

from cmdragons.geometry import TEAMS, Field, RobotShape, Team
from cmdragons.messages import (
    BallOut,
    BallState,
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

__all__ = ["AutoRef", "BallCrossing", "KickDetector", "OwnContacts", "deflection_path", "hull_gap", "observed",
           "path_gap"]

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


def hull_gap(shape: RobotShape, robot: tuple[float, float, float], x: float, y: float) -> float:
    """From the point (``x``, ``y``) to the body of a robot at ``robot`` (x, y, heading), field frame,
    m (:meth:`~cmdragons.geometry.RobotShape.gap`); negative inside."""
    rx, ry, theta = robot
    c, s = math.cos(theta), math.sin(theta)
    return shape.gap(c * (x - rx) + s * (y - ry), -s * (x - rx) + c * (y - ry))


_SEARCH_STEPS = 40  # the ternary search along a segment: (2/3)^40 of its length, far below a millimetre


def path_gap(shape: RobotShape, robot: tuple[float, float, float], path: Sequence[tuple[float, float]]) -> float:
    """The least :func:`hull_gap` of the points of ``path`` (a polyline, field frame, m): how near the
    ball's centre passed the robot's body, negative where it went through it. Exact up to
    :data:`_SEARCH_STEPS`: the gap to a convex body is convex along a segment."""
    best = math.inf
    for (ax, ay), (bx, by) in zip(path, path[1:], strict=False):
        def gap(u: float, ax: float = ax, ay: float = ay, bx: float = bx, by: float = by) -> float:
            return hull_gap(shape, robot, ax + u * (bx - ax), ay + u * (by - ay))

        lo, hi = 0.0, 1.0
        for _ in range(_SEARCH_STEPS):
            m1, m2 = lo + (hi - lo) / 3.0, hi - (hi - lo) / 3.0
            if gap(m1) < gap(m2):
                hi = m2
            else:
                lo = m1
        best = min(best, gap(0.0), gap(1.0), gap(0.5 * (lo + hi)))
    if len(path) == 1:
        best = hull_gap(shape, robot, *path[0])
    return best


def deflection_path(p0: tuple[float, float], v0: tuple[float, float], p1: tuple[float, float],
                    v1: tuple[float, float], longest_s: float) -> list[tuple[float, float]]:
    """The ball's path between two tracked points (at ``p0`` moving at ``v0``, then at ``p1`` moving at
    ``v1``; field frame, m, m/s) across the touch that changed its velocity: through the deflection
    point, where its old line and its new line meet, when they meet ahead of ``p0`` and behind ``p1``
    within ``longest_s`` of motion on each; else straight from ``p0`` to ``p1`` (a ball stopped, or
    pushed on along its line)."""
    den = v0[0] * v1[1] - v0[1] * v1[0]
    dx, dy = p1[0] - p0[0], p1[1] - p0[1]
    if abs(den) <= _PARALLEL * math.hypot(*v0) * math.hypot(*v1) or den == 0.0:
        return [p0, p1]
    s = (dx * v1[1] - dy * v1[0]) / den  # the time along the old line to the deflection point ...
    u = (v0[0] * dy - v0[1] * dx) / den  # ... and along the new line from it
    if not (0.0 <= s <= longest_s and 0.0 <= u <= longest_s):
        return [p0, p1]
    return [p0, (p0[0] + s * v0[0], p0[1] + s * v0[1]), p1]


_RAY_STEP_M = 0.005  # the steps along a kicker's heading looking for the body its kick met (m)
_PARALLEL = math.sin(math.radians(5.0))  # lines closer to parallel than this meet nowhere the track can tell


class KickDetector:
    """Touches of the ball from its track: its velocity changes by more than
    ``kick_speed_change_m_s`` between two frames (a kick, a push, a bounce off a robot). The toucher
    is the robot the ball's path went nearest, from the earliest frame of the last ``kick_memory_s``
    that moved as the frame before the change did (a turn the track shows late) to now, through the
    deflection point where its old and new lines meet (:func:`deflection_path`): its body (:func:`hull_gap`, a disc
    cut flat at the front, where each robot stood in either frame) within ``kick_reach_m`` of the
    ball; where robots of both teams are that near, the one whose body the path went deepest into or
    passed nearest; but when the ball sped up (a kick) and leaves that robot off its heading (relative
    to its velocity) by more than ``kick_heading_deg``, with the robot that held the ball before in
    reach too (``holder``: the last toucher ``kick_memory_s`` ago), the holder: a robot kicked the ball
    another held into that one's front, which turned it (the changes of the track a kick seen late and
    a bounce), and touched it last. Such a kick where no camera saw the ball (the track coasting the frames
    before) was turned by the first body the ball meets along the kicker's heading from where it was last
    seen, when it can have rolled from there to where it reappeared, moving away (:meth:`_turned_by`); the
    next frame's change that moved the ball on from where that frame showed it (within ``kick_settle_m``)
    is the track's velocity settling after the turn, no new touch.
    When no robot is that near (a kick the track shows a few frames late, the ball gone), the robot
    last at the ball: the nearest within ``kick_reach_m`` in the newest frame of the last
    ``kick_memory_s`` that had one. A ball that jumps farther than it could roll (put somewhere, or
    another ball taken for it) starts the watch afresh."""

    def __init__(self, pitch: Field, params: AutorefParams, max_ball_speed_m_s: float = 10.0) -> None:
        self.p = params
        self.shape = pitch.league.robot
        self.ball_r = pitch.league.ball.radius_m
        self.max_ball_speed_m_s = max_ball_speed_m_s
        self._last: tuple[float, float, float, float, float] | None = None  # t, x, y, vx, vy
        self._ball: deque[tuple[float, float, float, float, float]] = deque()  # the last kick_memory_s of it
        self._poses: dict[Key, tuple[float, float, float]] = {}  # where each robot stood the frame before
        self._recent: deque[tuple[float, dict[Key, float]]] = deque()  # t, each robot's gap to the ball (m)
        self._seen: tuple[float, float, float] | None = None  # t, x, y: where a camera last showed the ball
        self._turned_t = -math.inf  # when a kick out of sight was last seen turned by another robot

    def see(self, world: WorldState, holder: Key | None = None) -> Kick | None:
        """The touch ``world``'s ball shows, or None; ``holder``: the robot at the ball before the
        newest touch (:meth:`AutoRef.holder`)."""
        b, t = world.ball, world.t
        poses = {(r.team, r.id): (r.x, r.y, r.theta) for r in world.robots if r.visible}
        before, self._poses = self._poses, poses
        if b is None:
            self._last = None
            self._seen = None
            self._recent.clear()
            self._ball.clear()
            return None
        seen, self._seen = self._seen, (t, b.x, b.y) if b.visible else self._seen
        gaps = {k: hull_gap(self.shape, pose, b.x, b.y) - self.ball_r for k, pose in poses.items()}
        last, self._last = self._last, (t, b.x, b.y, b.vx, b.vy)
        self._recent.append((t, gaps))
        history = self._ball
        self._ball.append((t, b.x, b.y, b.vx, b.vy))
        while self._recent and t - self._recent[0][0] > self.p.kick_memory_s:
            self._recent.popleft()
        while t - self._ball[0][0] > self.p.kick_memory_s:
            self._ball.popleft()
        if last is None:
            return None
        t0, x0, y0, vx0, vy0 = last
        jump = math.hypot(b.x - x0, b.y - y0)
        if jump > self.max_ball_speed_m_s * max(t - t0, 1e-3) + self.ball_r:
            self._recent = deque([(t, gaps)])  # put somewhere else: a new watch
            self._ball = deque([(t, b.x, b.y, b.vx, b.vy)])
            self._seen = (t, b.x, b.y) if b.visible else None
            return None
        if math.hypot(b.vx - vx0, b.vy - vy0) <= self.p.kick_speed_change_m_s:
            return None
        if self._turned_t == t0 and math.hypot(x0 + b.vx * (t - t0) - b.x, y0 + b.vy * (t - t0) - b.y) \
                <= self.p.kick_settle_m:
            return None  # the turn of the frame before, its velocity settling: the ball went on from there so
        # the old line from the earliest frame remembered that still moved as the last did: a turn the track
        # shows late has the ball past the deflection point already in the frame before
        ta, xa, ya = t0, x0, y0
        for tk, xk, yk, vxk, vyk in reversed(list(history)[:-1]):
            if math.hypot(vxk - vx0, vyk - vy0) > self.p.kick_speed_change_m_s:
                break
            ta, xa, ya = tk, xk, yk
        path = deflection_path((xa, ya), (vx0, vy0), (b.x, b.y), (b.vx, b.vy), t - ta + self.p.kick_memory_s)
        near = sorted((min(path_gap(self.shape, pose, path) for pose in (before.get(k, now), now)) - self.ball_r, k)
                      for k, now in poses.items())
        reach = [k for gap, k in near if gap <= self.p.kick_reach_m]
        if reach:
            key = reach[0]
            kicked = math.hypot(b.vx, b.vy) - math.hypot(vx0, vy0) > self.p.kick_speed_change_m_s
            if kicked and not self._along_heading(world, key, b.vx, b.vy):
                if holder in reach and len(reach) > 1:
                    key = holder  # kicked out of the holder's front, which turned it
                elif seen is not None and seen[0] < t0:  # kicked where no camera saw the ball
                    turned = self._turned_by(poses, key, seen, t, b)
                    if turned is not None:
                        key, self._turned_t = turned, t
            return Kick(t, key[0], key[1], math.hypot(b.vx, b.vy), False)
        for _, g in reversed(self._recent):  # the last robot at the ball (the nearest of that frame)
            at = sorted((gap, k) for k, gap in g.items() if gap <= self.p.kick_reach_m)
            if at:
                key = at[0][1]
                return Kick(t, key[0], key[1], math.hypot(b.vx, b.vy), False)
        return None

    def _turned_by(self, poses: dict[Key, tuple[float, float, float]], kicker: Key,
                   seen: tuple[float, float, float], t: float, b: BallState) -> Key | None:
        """The robot that turned a ball ``kicker`` kicked out of the cameras' sight: the first body the
        ball meets going along the kicker's heading from where it was last ``seen`` (t, x, y), from which
        it can have rolled on to ``b`` (now, at ``t``, no faster than the ball can go, moving away from
        it); None when there is none."""
        t_seen, x0, y0 = seen
        budget = self.max_ball_speed_m_s * (t - t_seen)
        theta = poses[kicker][2]
        hx, hy = math.cos(theta), math.sin(theta)
        steps = max(1, math.ceil(budget / _RAY_STEP_M))
        for k in range(steps + 1):
            s = k * budget / steps
            px, py = x0 + s * hx, y0 + s * hy
            gaps = ((hull_gap(self.shape, pose, px, py), key) for key, pose in poses.items() if key != kicker)
            met = sorted((gap, key) for gap, key in gaps if gap <= self.ball_r)
            if met:
                on = math.hypot(b.x - px, b.y - py)
                away = (b.x - px) * b.vx + (b.y - py) * b.vy > 0.0
                return met[0][1] if s + on <= budget and away else None
        return None

    def _along_heading(self, world: WorldState, key: Key, vx: float, vy: float) -> bool:
        """Does the ball moving at (``vx``, ``vy``) leave robot ``key`` along its heading (relative to
        its velocity, within ``kick_heading_deg``), as a kick by it sends the ball?"""
        r = next(r for r in world.robots if (r.team, r.id) == key)
        rx, ry = vx - r.vx, vy - r.vy
        speed = math.hypot(rx, ry)
        return speed > 0.0 and (rx * math.cos(r.theta) + ry * math.sin(r.theta)) / speed >= math.cos(
            math.radians(self.p.kick_heading_deg))


class OwnContacts:
    """Collisions among one team's robots, from their tracks (no foul: a figure of the match, what the
    simulator's contacts give on the truth): two visible robots of one team whose centres come nearer
    than two radii plus ``own_contact_margin_m`` while closing faster than ``own_contact_closing_m_s``
    (the difference of their tracked velocities the frame before, along the line between them: two
    robots standing side by side, their tracks jittering, never collide). Once per meeting: it lasts
    until they are ``margins.contact_release_m`` farther apart than where it began."""

    def __init__(self, pitch: Field, params: AutorefParams) -> None:
        self.p = params
        self.touch_m = 2.0 * pitch.league.robot.radius_m + params.own_contact_margin_m
        self.each: list[tuple[float, Key, Key]] = []  # per collision: when it began, the two robots
        self._prev: dict[Key, tuple[float, float]] = {}  # each robot's tracked velocity the frame before
        self._meeting: set[tuple[Key, Key]] = set()

    def see(self, world: WorldState) -> list[tuple[float, Key, Key]]:
        """The collisions that begin in ``world``'s frame."""
        robots = sorted((r for r in world.robots if r.visible), key=lambda r: (r.team, r.id))
        new, near = [], set()
        for i, a in enumerate(robots):
            for b in robots[i + 1:]:
                if a.team != b.team:
                    continue
                pair = ((a.team, a.id), (b.team, b.id))
                dx, dy = b.x - a.x, b.y - a.y
                d = math.hypot(dx, dy)
                if d >= self.touch_m + (self.p.margins.contact_release_m if pair in self._meeting else 0.0):
                    continue
                near.add(pair)
                if pair in self._meeting or d < 1e-9:
                    continue
                (vax, vay), (vbx, vby) = (self._prev.get(k, (0.0, 0.0)) for k in pair)
                closing = ((vax - vbx) * dx + (vay - vby) * dy) / d
                if closing > self.p.own_contact_closing_m_s:
                    self._meeting.add(pair)
                    new.append((world.t, *pair))
        self._meeting &= near
        self._prev = {(r.team, r.id): (r.vx, r.vy) for r in robots}
        self.each += new
        return new

    def counts(self) -> dict[Team, int]:
        """Collisions per team so far."""
        return {team: sum(a[0] == team for _, a, _ in self.each) for team in TEAMS}


class AutoRef:
    """The referee on the tracked world: one :meth:`observe` per world state. ``keys``: the match's
    robots (team, id), as the game controller knows them."""

    def __init__(self, pitch: Field, keys: Sequence[Key], params: RefereeParams) -> None:
        a = params.autoref
        self.referee = Referee(pitch, keys, params, a.margins, a.leave_s)
        self.crossing = BallCrossing(pitch)
        self.kicks = KickDetector(pitch, a)
        self.own_contacts = OwnContacts(pitch, a)
        self._ball = (0.0, 0.0)  # where the ball was last seen
        self._touchers: deque[tuple[float, Key | None]] = deque([(-math.inf, None)])  # each last touch, from when

    def holder(self, t: float) -> Key | None:
        """The robot at the ball before the touches of the last ``kick_memory_s`` (a kick of the ball
        another held, which the track shows in steps): the last toucher as it was that long ago."""
        last = self.referee.watch.last_touch
        if last != self._touchers[-1][1]:
            self._touchers.append((t, last))
        then = t - self.kicks.p.kick_memory_s
        while len(self._touchers) > 1 and self._touchers[1][0] <= then:
            self._touchers.popleft()
        return self._touchers[0][1]

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
        self.own_contacts.see(world)
        kick = self.kicks.see(world, self.holder(world.t))
        if kick is not None and (kick.team, kick.id) == r.watch.last_touch:
            kick = None  # the last toucher's own touch seen late (the track's velocity lags the kick): no new one
        if kick is not None:
            events.append(kick)
        last = r.watch.last_touch if kick is None else (kick.team, kick.id)
        # a line crossed only where a camera shows the ball: a track coasting on unseen (a ball off the post,
        # a frame passed over) ran past the goal line and was called a goal before the ball went in
        seen = world.ball is not None and world.ball.visible
        crossing = self.crossing.see(world.t, *self._ball, r.blue_sign, None if last is None else last[0]) \
            if seen else None
        if crossing is not None:
            events.append(crossing)
        score, outs, sign = dict(r.score), r.balls_out, r.blue_sign
        teleport = r.observe(world.t, events, self._ball, self._within_walls(observed(world, self._ball), world))
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

    def _within_walls(self, seen: GroundTruth, world: WorldState) -> GroundTruth:
        """``seen`` with a ball no camera shows held within the boundary walls: a track coasting on
        unseen past the wall it bounced off (the cameras' view ends there) is no ball over the boundary."""
        if world.ball is None or world.ball.visible:
            return seen
        f, b = self.crossing.field, seen.ball
        x = min(max(b.x, -f.boundary_half_length), f.boundary_half_length)
        y = min(max(b.y, -f.boundary_half_width), f.boundary_half_width)
        return GroundTruth(seen.frame_number, seen.t, BallTruth(x, y, b.z, b.vx, b.vy), seen.robots)

    @property
    def calls(self) -> list[GameEvent]:
        """The calls of the frame last observed."""
        return self.referee.calls.new

    def state(self) -> GameState:
        """The game state now, as the league's game controller sends it."""
        return self.referee.state()

    def summary(self) -> dict[str, object]:
        """The match's figures as the referee's summary gives them, with goals and balls out, and the
        own collisions (per team, and each: when, whose, which two robots)."""
        r = self.referee
        own: dict[str, object] = dict(self.own_contacts.counts().items())
        own["each"] = [{"t": round(t, 4), "team": a[0], "ids": [a[1], b[1]]} for t, a, b in self.own_contacts.each]
        return {"score": dict(r.score), "balls_out": r.balls_out, "kicks_seen": r.kicks,
                "keeper_held_ball": r.keeper_held_ball, "own_collisions": own, **r.summary()}
