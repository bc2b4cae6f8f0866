"""Multi-camera tracking of the ball and all robots: association, track life, latency compensation.

Per set of camera frames the tracker predicts every track to each frame's capture time and takes
that camera's detections, so detections of one object from overlapping cameras fuse as
sequential measurements of one track. Robots are associated by team and id, and a detection whose
Mahalanobis distance to its track is implausible (a wrong id, a reflection) is rejected; a robot
that was really moved (placed by the referee) shows as a run of consistent rejected detections and
its track starts again there. The ball keeps several hypotheses while more than one orange region
is plausible, and reports the most credible. Tracks are confirmed after a few detections, predicted
through occlusion with growing covariance and ``visible = False``, and dropped after a timeout.

The world state handed to the team is predicted ahead to the moment its next command takes effect
(``latency_s``), as the CMDragons tracker did (Bruce 2006, ch. 2); offline tracking asks for the
estimate at the capture time instead (``step(frames, ahead_s=0.0)``).
"""

from __future__ import annotations

import dataclasses
import math
from collections import deque
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from cmdragons.config import Validated, derived, override_derived, setting
from cmdragons.geometry import Team
from cmdragons.messages import BallState, DetectionFrame, PhysicsFacts, RobotCommand, RobotState, WorldState
from cmdragons.tracking import filters
from cmdragons.tracking.filters import BallFilter, BallModelParams, RobotFilter, RobotModelParams
from cmdragons.tracking.physics import OurKick, PhysicsEstimator, PhysicsFactsParams

__all__ = ["Tracker", "TrackerParams", "TrackerStats"]


@dataclass(frozen=True)
class TrackerParams(Validated):
    """configs/tracker.yaml."""

    # capture -> our next command takes effect: the robots' command latency (field.yaml robot)
    latency_s: float = derived("field.robot.command_latency_s", 0.03, lo=0.0, hi=1.0)
    min_confidence: float = setting(0.1, lo=0.0, hi=1.0)  # detections below are ignored
    ball: BallModelParams = BallModelParams()
    robot: RobotModelParams = RobotModelParams()
    max_ball_speed_m_s: float = setting(10.0, lo=0.1, hi=50.0)  # farther jumps are other objects
    ball_jump_margin_m: float = setting(0.05, lo=0.0, hi=2.0)  # plus this, for noise and bounces
    ball_hypotheses: int = setting(4, lo=1, hi=32)  # kept at once, at most
    ball_confirm_detections: int = setting(2, lo=1, hi=100)
    # a hypothesis seen within this of the newest frame counts as seen now: of those, one seen within it
    # before too is reported (a stray detection taken by a stale hypothesis beat the ball seen a frame before)
    ball_recent_s: float = setting(0.05, lo=0.0, hi=1.0)
    ball_timeout_s: float = setting(1.0, lo=0.0, hi=60.0)  # unseen this long: hypothesis dropped
    # a ball lost from sight this near the middle of a robot's front (ball centre to where it would
    # lie on the dribbler) is in the robot's mouth, hidden by it: carried with the robot, unseen ...
    ball_held_m: float = setting(0.04, lo=0.0, hi=0.5)
    ball_held_timeout_s: float = setting(30.0, lo=0.0, hi=600.0)  # ... for at most this long
    # where a held ball lies: the robot's front and the ball's radius, configured once in field.yaml
    robot_front_m: float = derived("field.robot.front_distance_m", 0.07, lo=0.0, hi=1.0)
    ball_radius_m: float = derived("field.ball.radius_m", 0.0215, lo=0.0, hi=0.5)
    robot_gate_chi2: float = setting(60.0, lo=1.0, hi=1e6)  # Mahalanobis^2 (3 dof) for a detection
    robot_reinit_detections: int = setting(3, lo=1, hi=1000)  # consistent rejected detections -> restart
    robot_reinit_spread_m: float = setting(0.05, lo=0.0, hi=5.0)  # ... within this of each other
    robot_confirm_detections: int = setting(3, lo=1, hi=100)
    robot_timeout_s: float = setting(1.0, lo=0.0, hi=60.0)
    physics: PhysicsFactsParams = PhysicsFactsParams()  # the ball's deceleration and the robots' reach, measured


@dataclass
class TrackerStats:
    """What the tracker refused or repaired, for run summaries."""

    frames: int = 0
    detections: int = 0
    non_finite: int = 0  # NaN or infinite coordinates
    low_confidence: int = 0
    robot_gated: int = 0  # implausible for their track (wrong id, reflection, outlier)
    robot_restarts: int = 0  # a robot really moved far: track started again
    ball_kicks: int = 0  # velocity re-acquired after a kick or bounce
    stale_frames: int = 0  # frames older than what the tracker already took

    def as_dict(self) -> dict[str, int]:
        return dict(self.__dict__)


@dataclass
class _RobotTrack:
    filter: RobotFilter
    hits: int = 1
    last_seen: float = 0.0
    rejected: deque[tuple[float, float, float]] = field(default_factory=lambda: deque(maxlen=64))


@dataclass
class _BallTrack:
    filter: BallFilter
    born: float
    hits: int = 1
    last_seen: float = 0.0
    seen_before: float = -math.inf  # when it was seen before the instant of last_seen
    holder: tuple[Team, int] | None = None  # the robot whose mouth hides the ball from the cameras
    held_since: float = math.nan
    z: tuple[float, float] = (math.nan, math.nan)  # the last detection taken
    kicked: bool = False  # ... and whether it looked like a kick or bounce


class Tracker:
    """Detections of every camera in, one :class:`WorldState` per frame out; beside them, the physics
    facts measured so far (:attr:`physics`)."""

    def __init__(self, params: TrackerParams) -> None:
        self.p = params
        self.configured = params  # what the configuration says; :attr:`p` with the physics facts in use
        self.estimator = PhysicsEstimator(params.physics) if params.physics.measure else None
        self.physics = PhysicsFacts(-math.inf)  # the facts as measured last
        self.handed = self.physics  # the facts whose values in use the tracker's models (and the brain) took last
        self.robots: dict[tuple[Team, int], _RobotTrack] = {}
        self.balls: list[_BallTrack] = []
        self.stats = TrackerStats()
        self.t = -math.inf  # capture time of the newest frame taken
        self._commands: dict[tuple[Team, int], deque[tuple[float, tuple[float, float, float]]]] = {}
        # the last flat kick armed: (from, until (s, in force), m/s)
        self._kicks: dict[tuple[Team, int], tuple[float, float, float]] = {}
        self._free_ball: tuple[float, float, float] | None = None  # the tracked ball clear of robots, last: (t, vx, vy)
        self._steady_updates = filters.SteadyUpdates()
        self._robots_sorted = True  # self.robots in key order

    # --- input --------------------------------------------------------------------------------
    def command_sent(self, commands: Iterable[RobotCommand], t_sent: float) -> None:
        """Our own commands, sent at ``t_sent``: the robots' control input once the latency passed."""
        for c in commands:
            if all(math.isfinite(v) for v in (c.vx, c.vy, c.omega)):
                self._commands.setdefault((c.team, c.id), deque(maxlen=32)).append(
                    (t_sent + self.p.latency_s, (c.vx, c.vy, c.omega))
                )
            if c.kick_speed > 0.0 and not c.chip and math.isfinite(c.kick_speed):
                t_on, armed = t_sent + self.p.latency_s, self._kicks.get((c.team, c.id))
                since = armed[0] if armed is not None and t_on - armed[1] <= self.p.physics.kick_within_s else t_on
                self._kicks[(c.team, c.id)] = (since, t_on, c.kick_speed)

    def _command_at(self, key: tuple[Team, int], t: float) -> tuple[float, float, float] | None:
        history = self._commands.get(key)
        if not history:
            return None
        current = None
        for t_effect, cmd in history:
            if t_effect <= t + 1e-9:
                current = cmd
            else:
                break
        return current

    def _apply_commands(self) -> None:
        """Each robot filter's control input: our command in force at the filter's time (robots we
        sent nothing, the opponents, keep none)."""
        for key in self._commands:
            track = self.robots.get(key)
            if track is not None:
                track.filter.command = self._command_at(key, track.filter.t)

    def step(self, frames: Sequence[DetectionFrame], ahead_s: float | None = None) -> WorldState:
        """Take one set of camera frames (any order, any cameras) and return the world state
        predicted to the newest capture time plus ``ahead_s``: by default ``latency_s``, what the
        live loop hands the team; 0 gives the filtered estimate at the capture time (offline
        tracks, scoring against truth). The same as :meth:`take` for each frame in capture-time
        order, then :meth:`finish`."""
        for frame in sorted(frames, key=lambda f: f.t_capture):
            self.take(frame)
        return self.finish(ahead_s)

    def take(self, frame: DetectionFrame) -> None:
        """Take one camera frame of the set in progress: every track predicted to its capture time,
        its detections fused. A frame older than one already taken is counted stale and left out,
        so a caller that takes frames as they come gives them in capture-time order."""
        if frame.t_capture < self.t - 1e-9 or not math.isfinite(frame.t_capture):
            self.stats.stale_frames += 1
            return
        self._take(frame)

    def finish(self, ahead_s: float | None = None) -> WorldState:
        """Close the set of frames taken since the last call (tracks no camera saw miss, held balls
        move with their holder, old tracks go) and return the world state, as :meth:`step` does."""
        self.stats.frames += 1
        if self.estimator is not None and self.t - self.physics.t >= self.p.physics.update_period_s:
            self._learn(self.estimator.facts(self.t))
        for track in self.robots.values():
            if track.last_seen != self.t:
                track.filter.miss()
        self._carry_held_balls()
        self._drop_stale()
        return self.world_state(self.t + (self.p.latency_s if ahead_s is None else ahead_s))

    def _take(self, frame: DetectionFrame) -> None:
        t = frame.t_capture
        self.t = t
        self._apply_commands()
        filters.predict_robots([track.filter for track in self.robots.values()], t)
        robots_xy = np.array([r.filter.kf.x[:2] for r in self.robots.values()]).reshape(-1, 2)
        for ball in self.balls:
            d = np.hypot(*(robots_xy - ball.filter.position).T) if len(robots_xy) else np.zeros(0)
            ball.filter.predict(t, float(d.min()) if len(d) else math.inf)
        # a settled robot's first detection of the frame goes with the others into one steady-state
        # update; the rest (new or unsettled tracks, second views, rejected detections) one by one,
        # in their order, after it
        steady: dict[tuple[Team, int], tuple[float, float, float]] = {}
        one_by_one: list[tuple[tuple[Team, int], tuple[float, float, float]]] = []
        for det in frame.robots:
            self.stats.detections += 1
            if not (math.isfinite(det.x) and math.isfinite(det.y) and math.isfinite(det.theta)):
                self.stats.non_finite += 1
                continue
            if det.confidence < self.p.min_confidence:
                self.stats.low_confidence += 1
                continue
            key, z = (det.team, det.id), (det.x, det.y, det.theta)
            known = self.robots.get(key)
            if known is not None and key not in steady and known.filter.steady_pending:
                steady[key] = z
            else:
                one_by_one.append((key, z))
        if steady:
            settled = [self.robots[key] for key in steady]
            taken = self._steady_updates.take([tr.filter for tr in settled], list(steady.values()),
                                              self.p.robot_gate_chi2)
            rejected = []
            for (key, z), robot, ok in zip(steady.items(), settled, taken.tolist(), strict=True):
                if ok:
                    robot.hits += 1
                    robot.last_seen = t
                    robot.rejected.clear()
                else:
                    rejected.append((key, z))
            one_by_one = rejected + one_by_one
        for key, z in one_by_one:
            self._take_robot(key, z, t)
        balls = []
        for bd in frame.balls:
            self.stats.detections += 1
            if not (math.isfinite(bd.x) and math.isfinite(bd.y)):
                self.stats.non_finite += 1
            elif bd.confidence < self.p.min_confidence:
                self.stats.low_confidence += 1
            else:
                balls.append((np.array([bd.x, bd.y]), bd.sigma_m))
        self._take_balls(balls, t)
        if self.estimator is not None:
            self._measure(frame)

    # --- physics facts ------------------------------------------------------------------------
    def _measure(self, frame: DetectionFrame) -> None:
        """This frame's detections of the tracked ball and of our commanded robots to the estimator."""
        t = self.t
        est = self.estimator
        assert est is not None
        keys = list(self.robots)
        xy = np.array([track.filter.kf.x[:2] for track in self.robots.values()]).reshape(-1, 2)
        ball = self.best_ball()
        if ball is not None and ball.last_seen == t:
            gaps = np.hypot(*(xy - ball.z).T)
            near = float(gaps.min()) if len(xy) else math.inf
            kick = self._our_kick(keys, gaps) if ball.kicked else None
            est.ball(t, ball.z[0], ball.z[1], near, ball.kicked, kick)
            if near >= est.p.clear_m:
                self._free_ball = (t, float(ball.filter.kf.x[2]), float(ball.filter.kf.x[3]))
        for det in frame.robots:
            key = (det.team, det.id)
            track = self.robots.get(key)
            if key not in self._commands or track is None or track.last_seen != t or not math.isfinite(det.x):
                continue
            cmd = self._command_at(key, t)
            others = np.hypot(*(xy - (det.x, det.y)).T)
            others[keys.index(key)] = math.inf
            if cmd is not None and len(others) and others.min() < est.p.robot_clear_m:
                cmd = None  # another robot this near may push or block it: not its own acceleration
            vx, vy = track.filter.kf.x[3:5].tolist()
            est.robot(key, t, det.x, det.y, (vx, vy), None if cmd is None else (cmd[0], cmd[1]))

    def _learn(self, facts: PhysicsFacts) -> None:
        """The facts of now; when those in use changed (another set, or a value moved by more than
        ``retune_change``) they are handed on: the ball and robot models take them (new filters get them)."""
        new, old = facts.in_use(), self.handed.in_use()
        change = self.p.physics.retune_change
        if new.keys() != old.keys() or any(abs(v - old[k]) > change * abs(old[k]) for k, v in new.items()):
            self.handed = facts
            self.p = override_derived(self.configured, new)
            self.p = dataclasses.replace(self.p, physics=self.configured.physics)
        self.physics = facts

    def _our_kick(self, keys: list[tuple[Team, int]], gaps: NDArray[np.float64]) -> OurKick | None:
        """A kick just seen, when one of our robots near the ball had its kicker armed just now
        (physics ``kick_near_m``, ``kick_within_s``): the ball's speed over the ground it asked (the
        kicker's speed sent plus the robot's own along its heading), the robot's heading and
        velocity, and the ball's velocity as it came in: tracked the last time it was clear of the
        robots (physics ``clear_m``), at most ``retention_incoming_s`` before (what a one-touch aim
        reckons with: a kicker that catches the ball first keeps none of it); else None."""
        p = self.p.physics
        for i in np.argsort(gaps):
            if gaps[i] > p.kick_near_m:
                break
            armed = self._kicks.get(keys[i])
            if armed is not None and armed[0] <= self.t <= armed[1] + p.kick_within_s:
                x = self.robots[keys[i]].filter.kf.x
                free = self._free_ball
                came = free is not None and self.t - free[0] <= p.retention_incoming_s
                return OurKick(armed[2] + float(x[3] * math.cos(x[2]) + x[4] * math.sin(x[2])), float(x[2]),
                               (float(x[3]), float(x[4])), (free[1], free[2]) if free is not None and came else None)
        return None

    # --- robots -------------------------------------------------------------------------------
    def _take_robot(self, key: tuple[Team, int], z: tuple[float, float, float], t: float) -> None:
        track = self.robots.get(key)
        if track is None:
            self.robots[key] = _RobotTrack(RobotFilter(self.p.robot, z[0], z[1], z[2], t), last_seen=t)
            self._robots_sorted = False
            return
        if track.filter.nis(z) <= self.p.robot_gate_chi2:
            track.filter.update(z)
            track.hits += 1
            track.last_seen = t
            track.rejected.clear()
            return
        self.stats.robot_gated += 1
        track.filter.miss()
        track.rejected.append((t, z[0], z[1]))
        recent = [r for r in track.rejected if t - r[0] <= 0.5]
        if len(recent) >= self.p.robot_reinit_detections:
            pts = np.array([(x, y) for _, x, y in recent[-self.p.robot_reinit_detections :]])
            if float(np.max(np.linalg.norm(pts - pts[-1], axis=1))) <= self.p.robot_reinit_spread_m:
                self.robots[key] = _RobotTrack(RobotFilter(self.p.robot, z[0], z[1], z[2], t), last_seen=t,
                                               hits=self.p.robot_confirm_detections)
                self.stats.robot_restarts += 1

    # --- ball ---------------------------------------------------------------------------------
    def _take_balls(self, detections: list[tuple[np.ndarray, float]], t: float) -> None:
        """Ball detections (position, its standard deviation per axis or NaN) to hypotheses."""
        if not detections:
            return
        # each pair's cost: the negative log-likelihood of the detection under the hypothesis, as its
        # motion predicts it (a Gaussian) or, where likelier, as a jump (a kick, a bounce, another
        # object): anywhere in the disc the ball can have reached since it was seen, with equal
        # density. A hypothesis seen a frame ago confines the ball to a few centimetres; one unseen
        # for a second, held in a robot's mouth, to metres: by normalised error alone that one took
        # the detection of a ball kicked or stopped next to the ball tracked to a millimetre
        pairs = []
        for i, track in enumerate(self.balls):
            reach = self.p.max_ball_speed_m_s * max(t - track.last_seen, 1e-3) + self.p.ball_jump_margin_m
            jump = math.log(math.pi * reach * reach)
            px, py = track.filter.position.tolist()
            for j, (z, sigma) in enumerate(detections):
                d = math.hypot(z[0] - px, z[1] - py)
                if d <= reach:
                    nis, cost = track.filter.nis_nll(z, sigma)
                    pairs.append((min(cost, jump), d, i, j, nis))
        pairs.sort()
        used_tracks: set[int] = set()
        used_dets: set[int] = set()
        for _, _, i, j, nis in pairs:
            if i in used_tracks or j in used_dets:
                continue
            used_tracks.add(i)
            used_dets.add(j)
            track = self.balls[i]
            z, sigma = detections[j]
            track.kicked = track.filter.update(z, nis, sigma)
            if track.kicked:
                self.stats.ball_kicks += 1
            track.z = (float(z[0]), float(z[1]))
            track.hits += 1
            if t > track.last_seen:
                track.seen_before = track.last_seen
            track.last_seen = t
        for j, (z, _) in enumerate(detections):
            if j not in used_dets:
                new = BallFilter(self.p.ball, z[0], z[1], t)
                self.balls.append(_BallTrack(new, born=t, last_seen=t, z=(float(z[0]), float(z[1]))))
        if len(self.balls) > self.p.ball_hypotheses:
            self.balls.sort(key=self._ball_rank, reverse=True)
            del self.balls[self.p.ball_hypotheses :]

    def _carry_held_balls(self) -> None:
        """A ball in a robot's mouth (within ``ball_held_m`` of where the dribbler holds it) and lost
        from sight there is hidden by that robot, not lost: it goes where the robot carries it, with
        the robot's velocity, until it is seen again off the robot's face (or ``ball_held_timeout_s``)."""
        t = self.t
        front = self.p.robot_front_m + self.p.ball_radius_m
        for ball in self.balls:
            bx, by = ball.filter.position.tolist()
            seen = ball.last_seen == t
            robot = self.robots.get(ball.holder) if ball.holder is not None else None
            if robot is not None:
                x, y, theta = robot.filter.kf.x[:3].tolist()
                if math.hypot(bx - x - front * math.cos(theta), by - y - front * math.sin(theta)) > self.p.ball_held_m:
                    robot = None  # off the face: no longer held (let go, kicked, or taken off it)
            if robot is None:
                ball.holder = None
                best = self.p.ball_held_m
                for key, track in self.robots.items():
                    x, y, theta = track.filter.kf.x[:3].tolist()
                    gap = math.hypot(bx - x - front * math.cos(theta), by - y - front * math.sin(theta))
                    if gap < best:
                        best, ball.holder, robot = gap, key, track
                if robot is None:
                    continue
                ball.held_since = t
            if not seen:
                x, y, theta, vx, vy = robot.filter.kf.x[:5].tolist()
                ball.filter.hold(x + front * math.cos(theta), y + front * math.sin(theta), vx, vy, self.p.ball_held_m)

    def _ball_rank(self, track: _BallTrack) -> tuple[bool, bool, bool, float]:
        confirmed = track.hits >= self.p.ball_confirm_detections
        # a ball seen since beats one hidden in a robot's mouth (the referee moved it, or the robot let it go
        # unseen); of those seen lately, one seen lately before that too (in the ER-Force simulator a stray
        # detection at a robot's front, taken by a hypothesis held there since the ball was put elsewhere,
        # was the ball for a frame: 3 m away, a kickoff taken and two robots too near it)
        recent = self.t - self.p.ball_recent_s
        return (confirmed, track.last_seen >= recent, track.seen_before >= recent, track.last_seen)

    def _held(self, ball: _BallTrack) -> bool:
        return ball.holder is not None and self.t - ball.held_since <= self.p.ball_held_timeout_s

    def _drop_stale(self) -> None:
        t = self.t
        self.robots = {k: r for k, r in self.robots.items() if t - r.last_seen <= self.p.robot_timeout_s}
        self.balls = [b for b in self.balls if t - b.last_seen <= self.p.ball_timeout_s or self._held(b)]

    # --- output -------------------------------------------------------------------------------
    def best_ball(self) -> _BallTrack | None:
        confirmed = [b for b in self.balls if b.hits >= self.p.ball_confirm_detections]
        return max(confirmed, key=self._ball_rank) if confirmed else None

    def world_state(self, t: float) -> WorldState:
        """All confirmed tracks predicted to time ``t``; ``visible`` means seen in the newest frame."""
        ball = None
        best = self.best_ball()
        if best is not None:
            x, cov = best.filter.predicted(t)
            ball = BallState(float(x[0]), float(x[1]), float(x[2]), float(x[3]), best.last_seen == self.t, cov)
        if not self._robots_sorted:  # by team and id; the order only changes when a track is born
            self.robots = dict(sorted(self.robots.items()))
            self._robots_sorted = True
        confirmed = [(key, track) for key, track in self.robots.items()
                     if track.hits >= self.p.robot_confirm_detections]
        self._apply_commands()
        states = filters.predicted_states([track.filter for _, track in confirmed], t,
                                  [self._commands.get(key, ()) for key, _ in confirmed])
        robots = tuple(RobotState(team, rid, x[0], x[1], x[2], x[3], x[4], x[5], track.last_seen == self.t)
                       for ((team, rid), track), x in zip(confirmed, states.tolist(), strict=True))
        return WorldState(t, ball, robots)
