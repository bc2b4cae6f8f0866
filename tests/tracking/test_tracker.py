"""The tracker against the simulator's truth: detections are the true state plus seeded noise."""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator

import numpy as np
import pytest

from cmdragons.geometry import TEAMS, LeagueParams
from cmdragons.messages import BallDetection, DetectionFrame, RobotCommand, RobotDetection, WorldState
from cmdragons.tracking import Tracker, TrackerParams
from cmdragons.tracking.filters import BallModelParams, RobotModelParams
from sim.snapshot import Snapshot
from sim.world import BallParams, DribblerParams, KickerParams, PhysicsParams, RobotParams, World

SIGMA = 0.003  # m, like vision at default noise
DT = 1.0 / 60.0
FRONT = 0.07 + 0.0215


def make_world(blue: int = 1, yellow: int = 0) -> World:
    w = World(LeagueParams(), PhysicsParams(), RobotParams(), BallParams(), KickerParams(), DribblerParams(),
              robots_per_team={"blue": blue, "yellow": yellow})
    for i, (team, rid) in enumerate(w.robot_keys()):
        w.place_robot(team, rid, -3.5 + i, -2.5, 0.0)
    w.place_ball(0.0, 1.5)
    return w


def detect(snap: Snapshot, rng: np.random.Generator, camera: int = 0, ball: bool = True,
           sigma: float = SIGMA) -> DetectionFrame:
    balls = ()
    if ball:
        bx, by = snap.ball[:2] + rng.normal(0, sigma, 2)
        balls = (BallDetection(float(bx), float(by), 0.9, (0.0, 0.0)),)
    robots = tuple(
        RobotDetection(TEAMS[int(r[0])], int(r[1]), float(r[2] + rng.normal(0, sigma)),
                       float(r[3] + rng.normal(0, sigma)), float(r[4] + rng.normal(0, 0.02)), 0.9, (0.0, 0.0))
        for r in snap.robots
    )
    return DetectionFrame(camera, snap.frame_number, snap.t, snap.t, balls, robots)


def params(latency: float = 0.0, sigma: float = SIGMA) -> TrackerParams:
    """The tracker told the noise these synthetic detections carry."""
    return TrackerParams(
        latency_s=latency,
        ball=BallModelParams(measurement_sigma_m=sigma),
        robot=RobotModelParams(measurement_sigma_m=sigma, measurement_sigma_rad=0.02),
    )


def ball_error(ws: WorldState, snap: Snapshot) -> tuple[float, float]:
    assert ws.ball is not None
    pos = math.hypot(ws.ball.x - snap.ball[0], ws.ball.y - snap.ball[1])
    vel = math.hypot(ws.ball.vx - snap.ball[3], ws.ball.vy - snap.ball[4])
    return pos, vel


def test_rolling_ball_beats_raw_detections() -> None:
    w = make_world(blue=0)
    w.place_ball(-3.0, 0.0, vx=2.5, vy=0.5)
    tracker = Tracker(params())
    rng = np.random.default_rng(1)
    raw, tracked, vel = [], [], []
    for k in range(240):
        snap = w.snapshot()
        frame = detect(snap, rng)
        ws = tracker.step([frame])
        if k >= 30:
            p, v = ball_error(ws, snap)
            tracked.append(p)
            vel.append(v)
            raw.append(math.hypot(frame.balls[0].x - snap.ball[0], frame.balls[0].y - snap.ball[1]))
        w.step_frame()
    rms = lambda a: float(np.sqrt(np.mean(np.square(a))))  # noqa: E731
    assert rms(tracked) <= 0.7 * rms(raw)
    assert rms(vel) <= 0.1


@pytest.mark.parametrize("commanded", [False, True])
def test_robot_at_constant_velocity(commanded: bool) -> None:
    # an opponent (no command known) and one of ours (its command as control input) cruising; robot
    # detections 1 mm off (vision's are about 0.3 mm)
    sigma = 0.001
    w = make_world()
    w.place_robot("blue", 0, -3.0, -1.0, 0.0)
    tracker = Tracker(params(sigma=sigma))
    rng = np.random.default_rng(13)
    raw, tracked, vel = [], [], []
    cmd = [RobotCommand("blue", 0, vx=1.2, vy=0.6)]
    for k in range(180):
        snap = w.snapshot()
        if commanded:
            tracker.command_sent(cmd, snap.t)
        frame = detect(snap, rng, sigma=sigma)
        ws = tracker.step([frame])
        if k >= 90:  # cruising for a while: speed reached, filter settled
            r, true = ws.robots[0], snap.robots[0]
            assert math.hypot(true[5], true[6]) == pytest.approx(math.hypot(1.2, 0.6), abs=0.01)
            tracked.append(math.hypot(r.x - true[2], r.y - true[3]))
            raw.append(math.hypot(frame.robots[0].x - true[2], frame.robots[0].y - true[3]))
            vel.append(math.hypot(r.vx - true[5], r.vy - true[6]))
        w.step_frame(cmd)
    rms = lambda a: float(np.sqrt(np.mean(np.square(a))))  # noqa: E731
    # robots are filtered for hard accelerations and pushes (accel_sigma 8 m/s^2): little smoothing,
    # but no lag either
    assert rms(tracked) < rms(raw)
    assert rms(vel) <= 0.1


def test_ball_detection_with_nan_is_ignored() -> None:
    w = make_world(blue=0)
    w.place_ball(0.0, 0.0, vx=1.0)
    tracker = Tracker(params())
    rng = np.random.default_rng(14)
    for k in range(40):
        snap = w.snapshot()
        frame = detect(snap, rng)
        if k == 30:
            bad = BallDetection(math.nan, frame.balls[0].y, 0.9, (0.0, 0.0))
            frame = DetectionFrame(0, frame.frame_number, frame.t_capture, frame.t_sent, (bad,), frame.robots)
        ws = tracker.step([frame])
        if k >= 30:
            pos, vel = ball_error(ws, snap)
            assert ws.ball is not None and ws.ball.visible == (k != 30)
            assert pos < 0.01 and vel < 0.2
        w.step_frame()
    assert tracker.stats.non_finite == 1


def test_kick_reacquired_within_three_frames() -> None:
    w = make_world()
    w.place_robot("blue", 0, 0.0, 0.0, 0.0)
    w.place_ball(FRONT + 0.003, 0.0)
    tracker = Tracker(params())
    rng = np.random.default_rng(2)
    for _ in range(30):  # ball at rest, well tracked
        tracker.step([detect(w.snapshot(), rng)])
        w.step_frame()
    kicked_at = None
    for k in range(40):
        cmd = [RobotCommand("blue", 0, kick_speed=4.0)]
        w.step_frame(cmd)
        snap = w.snapshot()
        ws = tracker.step([detect(snap, rng)])
        if kicked_at is None and snap.ball[3] > 1.0:
            kicked_at = k
        if kicked_at is not None and k == kicked_at + 2:  # the third frame showing the kick
            _, verr = ball_error(ws, snap)
            assert verr <= 0.1 * 4.0
            break
    assert kicked_at is not None
    assert tracker.stats.ball_kicks >= 1


def test_bounce_off_a_wall() -> None:
    w = make_world(blue=0)
    w.place_ball(0.0, 2.6, vy=3.0)
    tracker = Tracker(params())
    rng = np.random.default_rng(3)
    bounced = None
    for k in range(90):
        snap = w.snapshot()
        ws = tracker.step([detect(snap, rng)])
        if bounced is None and snap.ball[4] < 0:
            bounced = k
        if bounced is not None and k == bounced + 3:
            assert ws.ball is not None and ws.ball.vy < 0
            _, verr = ball_error(ws, snap)
            assert verr <= 0.3 * abs(snap.ball[4])
        w.step_frame()
    assert bounced is not None


def test_occlusion_and_reacquisition() -> None:
    w = make_world(blue=0)
    w.place_ball(-3.0, 0.0, vx=1.5)
    tracker = Tracker(params())
    rng = np.random.default_rng(4)
    covs = []
    for k in range(150):
        snap = w.snapshot()
        hidden = 60 <= k < 90  # 0.5 s without ball detections
        ws = tracker.step([detect(snap, rng, ball=not hidden)])
        assert (ws.ball is None) == (k == 0)  # a new ball is confirmed on its second detection
        if ws.ball is None:
            w.step_frame()
            continue
        if hidden:
            assert not ws.ball.visible
            assert ws.ball.covariance is not None
            covs.append(float(ws.ball.covariance[0, 0] + ws.ball.covariance[1, 1]))
            pos, _ = ball_error(ws, snap)
            assert pos < 0.05  # predicted along the rolling model
        elif k >= 90:
            assert ws.ball.visible
            pos, _ = ball_error(ws, snap)
            assert pos < 0.02
        w.step_frame()
    assert all(b > a for a, b in zip(covs, covs[1:], strict=False))  # uncertainty grows


def test_frame_without_detections_and_timeout() -> None:
    w = make_world()
    tracker = Tracker(params())
    rng = np.random.default_rng(5)
    for _ in range(10):
        tracker.step([detect(w.snapshot(), rng)])
        w.step_frame()
    t = w.t
    ws = tracker.step([DetectionFrame(0, 99, t, t)])
    assert ws.ball is not None and not ws.ball.visible
    assert ws.robots and not ws.robots[0].visible
    ws = tracker.step([DetectionFrame(0, 100, t + 2.0, t + 2.0)])
    assert ws.ball is None and ws.robots == ()


def test_outliers_are_rejected() -> None:
    w = make_world(blue=2)
    w.place_robot("blue", 1, 1.0, 0.0, 0.0)
    tracker = Tracker(params())
    rng = np.random.default_rng(6)
    for _ in range(20):
        tracker.step([detect(w.snapshot(), rng)])
        w.step_frame()
    snap = w.snapshot()
    good = detect(snap, rng)
    r0, r1 = good.robots
    bad_robots = (
        RobotDetection("blue", 0, r0.x + 1.5, r0.y, r0.theta, 0.9, (0.0, 0.0)),  # a far jump
        RobotDetection("blue", 1, math.nan, r1.y, r1.theta, 0.9, (0.0, 0.0)),  # NaN coordinates
        RobotDetection("blue", 1, r0.x, r0.y, r0.theta, 0.9, (0.0, 0.0)),  # robot 0 seen as id 1
    )
    ws = tracker.step([DetectionFrame(0, snap.frame_number, snap.t, snap.t, good.balls, bad_robots)])
    for r in ws.robots:
        true = snap.robots[r.id]
        assert math.hypot(r.x - true[2], r.y - true[3]) < 0.02
    assert tracker.stats.non_finite == 1 and tracker.stats.robot_gated == 2
    # a duplicate from the second camera fuses into the same track
    w.step_frame()
    snap = w.snapshot()
    ws = tracker.step([detect(snap, rng, camera=0), detect(snap, rng, camera=1)])
    assert len(ws.robots) == 2
    assert all(math.hypot(r.x - snap.robots[r.id][2], r.y - snap.robots[r.id][3]) < 0.01 for r in ws.robots)


def test_moved_robot_restarts_its_track() -> None:
    w = make_world()
    tracker = Tracker(params())
    rng = np.random.default_rng(7)
    for _ in range(20):
        tracker.step([detect(w.snapshot(), rng)])
        w.step_frame()
    w.place_robot("blue", 0, 2.0, 2.0, 1.0)  # the referee puts it elsewhere
    for _ in range(10):
        ws = tracker.step([detect(w.snapshot(), rng)])
        w.step_frame()
    assert tracker.stats.robot_restarts == 1
    assert math.hypot(ws.robots[0].x - 2.0, ws.robots[0].y - 2.0) < 0.02


@pytest.mark.parametrize("with_commands", [False, True])
def test_latency_compensation_predicts_ahead(with_commands: bool) -> None:
    latency = 0.1  # 6 frames
    w = make_world()
    tracker = Tracker(params(latency))
    rng = np.random.default_rng(9)
    states, truth = [], []
    for k in range(180):
        vx = 1.0 if (k // 45) % 2 == 0 else -1.0  # back and forth: the lookahead must see the turns
        cmds = [RobotCommand("blue", 0, vx=vx)]
        snap = w.snapshot()
        if with_commands:
            tracker.command_sent(cmds, snap.t)
        ws = tracker.step([detect(snap, rng)])
        assert ws.t == pytest.approx(snap.t + latency)
        states.append(ws.robots[0].x if ws.robots else math.nan)
        truth.append(snap.robots[0, 2])
        w.step_frame(cmds)
    ahead = [abs(states[k] - truth[k + 6]) for k in range(10, 174)]
    now = [abs(states[k] - truth[k]) for k in range(10, 174)]
    assert float(np.mean(ahead)) < float(np.mean(now))  # it does look ahead
    assert float(np.mean(ahead)) < (0.01 if with_commands else 0.03)


def test_lookahead_follows_commands_already_sent() -> None:
    # a robot told to turn: the look-ahead must use the commands sent in the last latency window,
    # not only the one in force now; 6 frames of latency, in the simulator and the tracker alike
    latency = 6 / 60
    w = World(LeagueParams(), PhysicsParams(), RobotParams(command_latency_s=latency), BallParams(), KickerParams(),
              DribblerParams(), robots_per_team={"blue": 1, "yellow": 0})
    w.place_robot("blue", 0, 0.0, 0.0, 0.0)
    tracker = Tracker(params(latency))
    rng = np.random.default_rng(11)
    states, truth = [], []
    for k in range(90):
        omega = 4.0 if 20 <= k < 50 else 0.0
        cmds = [RobotCommand("blue", 0, omega=omega)]
        snap = w.snapshot()
        tracker.command_sent(cmds, snap.t)
        ws = tracker.step([detect(snap, rng)])
        states.append(ws.robots[0].theta if ws.robots else math.nan)
        truth.append(snap.robots[0, 4])
        w.step_frame(cmds)
    # the prediction 6 frames ahead stays within 0.05 rad of where the robot got to, switches included
    # (following only the command in force now misses by about 0.19 rad here)
    errors = [abs(math.remainder(states[k] - truth[k + 6], 2 * math.pi)) for k in range(10, 84)]
    assert max(errors) < 0.05


def roll_ball(x: float, vx: float, seed: int, frames: int,
              balls_seen: Callable[[int, tuple[BallDetection, ...]], tuple[BallDetection, ...]],
              ) -> Iterator[tuple[int, WorldState, Snapshot]]:
    """A ball rolling along y = 0, its detections of frame k passed through ``balls_seen(k, ...)``."""
    w = make_world(blue=0)
    w.place_ball(x, 0.0, vx=vx)
    tracker = Tracker(params())
    rng = np.random.default_rng(seed)
    for k in range(frames):
        snap = w.snapshot()
        frame = detect(snap, rng)
        frame = DetectionFrame(0, frame.frame_number, frame.t_capture, frame.t_sent, balls_seen(k, frame.balls))
        yield k, tracker.step([frame]), snap
        w.step_frame()


def test_second_ball_hypothesis_does_not_steal_the_track() -> None:
    sock = BallDetection(2.0, -1.0, 0.9, (0.0, 0.0))  # an orange sock at a fixed spot, seen now and then
    for k, ws, snap in roll_ball(-1.0, 1.0, 8, 90, lambda k, b: b + (sock,) if k >= 30 and k % 3 == 0 else b):
        if k >= 30:
            pos, _ = ball_error(ws, snap)
            assert pos < 0.02


def test_single_odd_ball_detection_is_not_a_kick() -> None:
    # a rolling ball seen once 2 cm off (at the edge of a camera, a reflection): the motion goes on
    # as before, the filter neither re-learns the velocity nor starts a new slide
    def odd(k: int, balls: tuple[BallDetection, ...]) -> tuple[BallDetection, ...]:
        return tuple(BallDetection(b.x, b.y + 0.02, b.confidence, b.pixel) for b in balls) if k == 60 else balls

    for k, ws, snap in roll_ball(-3.0, 1.5, 12, 150, odd):
        if k > 61:
            pos, vel = ball_error(ws, snap)
            assert pos < 0.006 and vel < 0.1


def test_tracker_takes_each_ball_detections_sigma() -> None:
    # a ball at rest seen by two cameras; in one frame the second camera alone sees it, cut by its
    # image's edge, 8 mm off with the 6 mm sigma vision gives it: no kick, the estimate stays
    tracker = Tracker(params(sigma=0.0004))
    rng = np.random.default_rng(5)
    for k in range(90):
        t = k * DT
        frames = []
        for cam in (0, 1):
            if k == 60 and cam == 0:
                continue
            x, y, s = (0.508, -0.2, 0.006) if k == 60 else (*(np.array([0.5, -0.2]) + rng.normal(0, 0.0003, 2)), 0.0003)
            frames.append(DetectionFrame(cam, k, t, t, (BallDetection(float(x), float(y), 0.9, (0.0, 0.0), s),)))
        ws = tracker.step(frames)
        if k >= 10:
            assert ws.ball is not None and math.hypot(ws.ball.x - 0.5, ws.ball.y + 0.2) < 0.001
    assert tracker.stats.ball_kicks == 0


def test_two_cameras_that_disagree_a_little_show_no_kick() -> None:
    # a ball rolling through the cameras' overlap, seen by both, the second camera's view 1.2 mm off
    # the first's (their calibrations differ a little) at 0.2 mm sigma each: views of one instant
    # cannot show a kick between them, so none is called, and the estimate lies between the two
    tracker = Tracker(params(sigma=0.0004))
    rng = np.random.default_rng(9)
    for k in range(120):
        t = k * DT
        x = -1.0 + 1.8 * t - 0.13 * t * t  # rolling: 0.26 m/s^2
        frames = [
            DetectionFrame(cam, k, t, t, (BallDetection(float(x + off + rng.normal(0, 0.0002)),
                                                        float(0.3 + rng.normal(0, 0.0002)), 0.9, (0.0, 0.0), 0.0002),))
            for cam, off in ((0, 0.0), (1, 0.0012))
        ]
        ws = tracker.step(frames)
        if k == 30:  # settled (a ball first seen is taken to slide: a kick may be seen before it rolls)
            kicks = tracker.stats.ball_kicks
        if k >= 30:
            assert ws.ball is not None and abs(ws.ball.x - x - 0.0006) < 0.001
    assert tracker.stats.ball_kicks == kicks


@pytest.mark.parametrize("on_face", [True, False])
def test_a_ball_hidden_in_a_robots_mouth_is_carried_not_lost(on_face: bool) -> None:
    # the ball on the dribbler goes out of the cameras' sight (the robot's body hides it) while the
    # robot carries it 1 m: tracked at the robot's front, unseen; a ball lost away from any robot's
    # face is dropped after the timeout as before
    w = make_world()
    w.place_robot("blue", 0, 0.0, 0.0, 0.0)
    w.place_ball(FRONT + 0.003 if on_face else 0.5, 0.0 if on_face else 0.4)
    p = params()
    tracker = Tracker(p)
    rng = np.random.default_rng(5)
    carry = [RobotCommand("blue", 0, vx=0.5, dribbler=1.0)]
    for _ in range(30):  # the ball on the dribbler, seen
        tracker.step([detect(w.snapshot(), rng)])
        w.step_frame([RobotCommand("blue", 0, dribbler=1.0)])
    worst = 0.0
    for _ in range(round(2.0 / DT)):  # carried 1 m, never seen
        w.step_frame(carry if on_face else [])
        snap = w.snapshot()
        ws = tracker.step([detect(snap, rng, ball=False)])
        if on_face:
            assert ws.ball is not None and not ws.ball.visible
            worst = max(worst, ball_error(ws, snap)[0])
    if on_face:
        assert snap.ball[0] > 0.8  # it did travel
        assert worst < 0.03
    else:
        assert ws.ball is None  # lost for 2 s > ball_timeout_s


def test_a_ball_seen_elsewhere_beats_one_hidden_in_a_robots_mouth() -> None:
    # the referee puts the ball on a spot while the tracker has it hidden in a robot's mouth: the
    # ball seen there is the ball from its confirming detections on
    w = make_world()
    w.place_robot("blue", 0, 0.0, 0.0, 0.0)
    w.place_ball(FRONT + 0.003, 0.0)
    p = params()
    tracker = Tracker(p)
    rng = np.random.default_rng(6)
    for k in range(60):  # seen on the dribbler, then hidden there
        tracker.step([detect(w.snapshot(), rng, ball=k < 30)])
        w.step_frame([RobotCommand("blue", 0, dribbler=1.0)])
    w.place_ball(2.0, 1.0)
    for _ in range(p.ball_confirm_detections + 1):
        w.step_frame()
        ws = tracker.step([detect(w.snapshot(), rng)])
    assert ws.ball is not None and ws.ball.visible
    assert math.hypot(ws.ball.x - 2.0, ws.ball.y - 1.0) < 0.02


def test_a_stray_detection_taken_by_a_stale_hypothesis_is_not_the_ball() -> None:
    # the ball at rest at (1.5, 0), then put on the centre spot (the referee's teleport at half-time):
    # the old hypothesis lives on unseen. One frame shows only a stray detection 0.4 m from it (the
    # ER-Force simulator's vision): the old hypothesis takes it and, seen last, was reported as the
    # ball for that frame, 1.9 m off (a kickoff taken, the ball's restart judged on it)
    tracker = Tracker(params())
    rng = np.random.default_rng(3)
    t, k = 0.0, 0

    def see(*balls: tuple[float, float]) -> WorldState:
        nonlocal t, k
        seen = tuple(BallDetection(x + rng.normal(0.0, SIGMA), y + rng.normal(0.0, SIGMA), 0.9, (0.0, 0.0))
                     for x, y in balls)
        ws = tracker.step([DetectionFrame(0, k, t, t, seen)])
        t, k = t + DT, k + 1
        return ws

    for _ in range(60):
        see((1.5, 0.0))
    moved = [see((0.0, 0.0)) for _ in range(20)]
    # the ball put elsewhere is the ball within ball_recent_s and a frame
    late = [ws.ball is not None and math.hypot(ws.ball.x, ws.ball.y) < 0.05 for ws in moved]
    assert all(late[math.ceil(tracker.p.ball_recent_s / DT) + 1 :])
    stray = see((1.9, 0.0))
    assert stray.ball is not None and math.hypot(stray.ball.x, stray.ball.y) < 0.05
    after = see((0.0, 0.0))
    assert after.ball is not None and math.hypot(after.ball.x, after.ball.y) < 0.05


ERFORCE_SIGMA = 0.002  # m: the ER-Force simulator's ball and robot noise (its league rows' recorded detections)


def ball_path(kick_at_s: float, speed_m_s: float, decel_m_s2: float = 3.0) -> Callable[[float], tuple[float, float]]:
    """The ball at the origin until ``kick_at_s``, then along +x at ``speed_m_s`` slowing at ``decel_m_s2``
    (a slide): (x, speed) at time t."""
    def at(t: float) -> tuple[float, float]:
        tau = min(max(0.0, t - kick_at_s), speed_m_s / decel_m_s2)
        return speed_m_s * tau - 0.5 * decel_m_s2 * tau * tau, speed_m_s - decel_m_s2 * tau if t > kick_at_s else 0.0
    return at


def stale_mouth_frames(path: Callable[[float], tuple[float, float]], yellow_y: float, frames: int,
                       rng: np.random.Generator) -> Iterator[tuple[DetectionFrame, float, float]]:
    """A blue robot with the ball at its mouth and an idle yellow robot beside it, ``yellow_y`` off; for three
    frames a stray detection shows at the yellow robot's mouth (the ER-Force simulator's vision), which the
    tracker then holds there, unseen; the ball follows ``path``. Frames with the ball's true x and speed."""
    robots = (("blue", 0, -FRONT, 0.0), ("yellow", 0, -FRONT, yellow_y))
    for k in range(frames):
        t = k * DT
        x, speed = path(t)
        balls = [BallDetection(x + rng.normal(0, ERFORCE_SIGMA), rng.normal(0, ERFORCE_SIGMA), 0.9, (0.0, 0.0))]
        if 20 <= k < 23:
            balls.append(BallDetection(rng.normal(0, ERFORCE_SIGMA), yellow_y + rng.normal(0, ERFORCE_SIGMA), 0.9,
                                       (0.0, 0.0)))
        seen = tuple(RobotDetection(team, rid, rx + rng.normal(0, ERFORCE_SIGMA), ry + rng.normal(0, ERFORCE_SIGMA),
                                    0.0, 0.9, (0.0, 0.0)) for team, rid, rx, ry in robots)
        yield DetectionFrame(0, k, t, t, tuple(balls), seen), x, speed


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize(("situation", "yellow_y", "path"), [
    pytest.param("at rest", 0.6, ball_path(math.inf, 0.0), id="at rest"),
    pytest.param("kicked", 1.0, ball_path(1.0, 5.0), id="kicked at 5 m/s"),
])
def test_a_stale_hypothesis_in_a_robots_mouth_never_makes_the_ball_fast(situation: str, yellow_y: float,
                                                                         path: Callable[[float], tuple[float, float]],
                                                                         seed: int) -> None:
    # the tracker as configured for our vision (0.4 mm) on the ER-Force simulator's (2 mm): the ball tracked
    # to a millimetre lost a detection (a few millimetres off its prediction, or its kick 8 cm from the mouth)
    # to a stale hypothesis held in an idle robot's mouth 0.6-1 m away, which by normalised error explained
    # it better; taking the next from where that one had been put made the ball 12-18 m/s for two frames
    # ("ball too fast" on a ball at rest or kicked at 5 m/s)
    tracker = Tracker(TrackerParams(latency_s=0.0))
    rng = np.random.default_rng(seed)
    worst_speed = worst_pos = 0.0
    for k, (frame, x, speed) in enumerate(stale_mouth_frames(path, yellow_y, 150, rng)):
        ws = tracker.step([frame])
        if k > 30:
            assert ws.ball is not None
            worst_speed = max(worst_speed, math.hypot(ws.ball.vx, ws.ball.vy) - speed)
            if situation == "at rest" or frame.t_capture > 1.0 + 3 * DT:  # the kick re-acquired
                worst_pos = max(worst_pos, math.hypot(ws.ball.x - x, ws.ball.y))
    # 2 mm detections 1/60 s apart, judged at 0.4 mm: velocity noise up to about 0.6 m/s
    assert worst_speed < 1.0
    assert worst_pos < 0.02


@pytest.mark.parametrize("seed", range(2))
@pytest.mark.parametrize("unseen_frames", [5, 6])
def test_a_ball_kicked_unseen_out_of_a_robots_mouth_is_as_fast_as_kicked(unseen_frames: int, seed: int) -> None:
    # the ball at rest in a robot's mouth, hidden there (the tracker carries it) when the robot kicks it
    # at 5 m/s, first seen ``unseen_frames`` after the kick, 0.3-0.5 m out: its speed is the kick's, never
    # one made of the jump from the mouth to that first sighting (11-16 m/s before)
    tracker = Tracker(TrackerParams(latency_s=0.0))
    rng = np.random.default_rng(seed)
    path = ball_path(1.0, 5.0)
    worst = 0.0
    for k in range(120):
        t = k * DT
        x, speed = path(t)
        hidden = 54 <= k < 60 + unseen_frames
        balls = () if hidden else (BallDetection(x + rng.normal(0, ERFORCE_SIGMA), rng.normal(0, ERFORCE_SIGMA), 0.9,
                                                 (0.0, 0.0)),)
        robot = (RobotDetection("blue", 0, -FRONT + rng.normal(0, ERFORCE_SIGMA), rng.normal(0, ERFORCE_SIGMA), 0.0,
                                0.9, (0.0, 0.0)),)
        ws = tracker.step([DetectionFrame(0, k, t, t, balls, robot)])
        if k > 30:
            assert ws.ball is not None
            worst = max(worst, math.hypot(ws.ball.vx, ws.ball.vy) - speed)
            if k > 60 + unseen_frames + 2:
                assert abs(ws.ball.x - x) < 0.02
    assert worst < 1.0  # the velocity noise of 2 mm detections judged at 0.4 mm: about 0.6 m/s
