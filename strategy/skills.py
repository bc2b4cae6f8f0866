"""Skills: what one robot does this frame, as an :class:`Intent` for navigation.

A skill looks at the world (field frame, metres, radians) and says where the robot should be, how
it should face, and what its kicker and dribbler do; planning, motion control and safety make it
happen. Skills keep no state; plays and roles (``strategy.plays``) choose them.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from cmdragons.config import Validated, derived, setting
from cmdragons.geometry import Field, wrap_angle
from cmdragons.messages import BallState, RobotState
from strategy.ballmodel import BallModel
from strategy.onetouch import chip_heading, kick_heading

__all__ = [
    "Intent",
    "SkillParams",
    "aiming",
    "defend",
    "dribble",
    "drive_through",
    "goalie_block",
    "held_ball",
    "intercept",
    "kick_to",
    "mark",
    "on_face",
    "pass_speed",
    "receive",
    "set_kick",
    "turn_with_ball",
    "waiting_point",
]


@dataclass(frozen=True)
class SkillParams(Validated):
    # our robots' and the ball's shape: configured once, in field.yaml robot and ball
    robot_radius_m: float = derived("field.robot.radius_m", 0.09, lo=0.02, hi=0.5)
    ball_radius_m: float = derived("field.ball.radius_m", 0.0215, lo=0.005, hi=0.2)
    front_distance_m: float = derived("field.robot.front_distance_m", 0.07, lo=0.01, hi=0.5)  # centre to kicker face
    approach_distance_m: float = setting(0.12, lo=0.0, hi=1.0)  # wait this far behind the ball, lined up
    lined_up_rad: float = setting(0.08, lo=0.001, hi=1.0)  # heading error allowed before driving through
    lined_up_m: float = setting(0.03, lo=0.001, hi=0.5)  # lateral error allowed before driving through
    aim_tolerance_m: float = setting(0.1, lo=0.001, hi=2.0)  # a held ball kicked: its way this near the target there
    push_speed_m_s: float = setting(0.8, lo=0.05, hi=5.0)  # speed of the last approach onto the ball
    cone_reach_m: float = setting(0.2, lo=0.0, hi=2.0)  # the approach cone reaches this far past the waiting point
    cone_slope: float = setting(0.25, lo=0.0, hi=2.0)  # lateral error allowed per metre from the ball
    cone_heading_rad_m: float = setting(1.0, lo=0.0, hi=20.0)  # heading error allowed per metre from the ball
    max_kick_m_s: float = setting(6.0, lo=0.1, hi=10.0)  # shots
    pass_arrival_m_s: float = setting(1.5, lo=0.1, hi=6.0)  # the speed a pass should arrive with
    pass_min_m_s: float = setting(1.5, lo=0.1, hi=10.0)
    pass_max_m_s: float = setting(5.0, lo=0.1, hi=10.0)
    # the ball model, for pass speeds and intercepts: configured once, in field.yaml ball
    acc_slide_m_s2: float = derived("field.ball.acc_slide_m_s2", 3.0, lo=0.0, hi=50.0)
    acc_roll_m_s2: float = derived("field.ball.acc_roll_m_s2", 0.26, lo=0.0, hi=10.0)
    slide_to_roll_fraction: float = derived("field.ball.slide_to_roll_fraction", 0.64, lo=0.0, hi=1.0)
    # the ball velocity across the heading (relative to the robot) a kick keeps, as the team believes it
    # (field.yaml robot, measured by the tracker); a kick aims with it (strategy.onetouch)
    kicker_retention: float = derived("field.robot.kick_retention", 0.3, lo=0.0, hi=1.5)
    chip_angle_rad: float = derived("sim.kicker.chip_angle_rad", 0.7854, lo=0.0, hi=1.5707963267948966)  # a chip's tilt
    goalie_depth_m: float = setting(0.15, lo=0.0, hi=2.0)  # goalie stands this far in front of the goal line
    defense_margin_m: float = setting(0.15, lo=0.0, hi=2.0)  # defenders stand this far outside the area
    mark_distance_m: float = setting(0.45, lo=0.2, hi=3.0)  # marker between its opponent and our goal
    intercept_speed_m_s: float = setting(1.8, lo=0.1, hi=10.0)  # robot's average speed when meeting a moving ball
    intercept_horizon_s: float = setting(3.0, lo=0.0, hi=20.0)  # the moving ball is predicted this far ahead
    dribble_speed_m_s: float = setting(1.0, lo=0.05, hi=5.0)  # carrying the ball, and driving onto it to take it
    dribble_hold_m: float = setting(0.03, lo=0.001, hi=0.5)  # ball centre this near the middle of the face: held
    dribble_turn_rad: float = setting(0.3, lo=0.01, hi=3.2)  # ... and the robot facing the target within this
    ball_turn_rad_s: float = setting(9.0, lo=0.1, hi=100.0)  # turning with a held ball: at most this fast
    held_slip_m_s: float = setting(0.5, lo=0.0, hi=5.0)  # a moving ball on the face moving with it within this: held
    contact_slack_m: float = setting(0.02, lo=0.0, hi=0.2)  # lined up: the face up to this past the ball's back
    at_ball_m: float = setting(0.03, lo=0.0, hi=0.5)  # the face this near behind the ball ...
    at_ball_lateral_share: float = setting(0.5, lo=0.0, hi=1.0)  # ... within this share of lined_up_m across: at it
    swing_back_share: float = setting(0.5, lo=0.0, hi=2.0)  # going round the ball: this share of the waiting distance
    swing_side_share: float = setting(1.2, lo=0.0, hi=5.0)  # ... behind it and this share to its side
    through_m: float = setting(0.05, lo=0.0, hi=0.5)  # driving through the ball: the target this far past its centre
    through_dribbler: float = setting(0.3, lo=0.0, hi=1.0)  # ... with the dribbler at this power
    hold_dribbler: float = setting(1.0, lo=0.0, hi=1.0)  # the dribbler's power trapping or carrying the ball
    rest_speed_m_s: float = setting(0.1, lo=0.0, hi=2.0)  # a ball slower than this is met where it lies
    intercept_step_s: float = setting(0.05, lo=0.001, hi=1.0)  # the moving ball's path is predicted in these steps
    receive_moving_m_s: float = setting(0.3, lo=0.0, hi=5.0)  # a ball faster than this is met on its path
    one_touch_facing_rad: float = setting(0.25, lo=0.01, hi=3.2)  # one-touch: kicker armed facing its aim within this
    set_lined_up_m: float = setting(0.015, lo=0.001, hi=0.5)  # a restart's kick: lateral error at the waiting point
    set_lined_up_rad: float = setting(0.05, lo=0.001, hi=1.0)  # ... heading error
    set_settle_m_s: float = setting(0.1, lo=0.0, hi=5.0)  # ... speed across the kick line before driving through
    set_push_m_s: float = setting(0.5, lo=0.05, hi=5.0)  # ... driving through the ball this fast
    set_near_m: float = setting(0.6, lo=0.0, hi=5.0)  # ... within this of the ball (centre to centre) ...
    set_approach_m_s: float = setting(1.0, lo=0.05, hi=10.0)  # ... the way to the waiting point at most this fast
    goalie_post_share: float = setting(0.5, lo=0.0, hi=2.0)  # goalie's centre this share of its radius inside a post
    goalie_shot_speed_m_s: float = setting(0.5, lo=0.0, hi=10.0)  # a ball this fast ...
    goalie_shot_vx_m_s: float = setting(0.2, lo=0.0, hi=10.0)  # ... coming at our goal line this fast: met on its line
    goalie_shade: float = setting(0.5, lo=0.0, hi=1.0)  # else the goalie stands at this share of the ball's y
    mark_max_share: float = setting(0.5, lo=0.0, hi=1.0)  # a marker at most this share of the way to our goal

    @property
    def ball_model(self) -> BallModel:
        """The ball's two-phase model every prediction of a kicked ball's run reads."""
        return BallModel(self.acc_slide_m_s2, self.acc_roll_m_s2, self.slide_to_roll_fraction)

    @property
    def contact_m(self) -> float:
        """Robot centre to ball centre with the ball on the kicker face."""
        return self.front_distance_m + self.ball_radius_m


@dataclass(frozen=True)
class Intent:
    """Where a robot should go and how it should face, plus kicker and dribbler."""

    x: float
    y: float
    theta: float
    kick_speed: float = 0.0
    chip: bool = False
    dribbler: float = 0.0
    avoid_ball: bool = True  # the ball is an obstacle for planning
    allow_own_defense: bool = False  # the goalie may enter our defense area
    allow_any_defense: bool = False  # both defense areas open (placing a ball that lies in or by one)
    max_speed_m_s: float | None = None  # None: the robot's limit
    final_speed_m_s: float = 0.0  # arrive moving (driving through the ball)
    max_omega_rad_s: float | None = None  # turning at most this fast (rad/s); None: the robot's limit


_BISECTIONS = 40  # halvings of the kick speed range in pass_speed: far below a mm/s


def _angle(dx: float, dy: float) -> float:
    return math.atan2(dy, dx)


def waiting_point(ball: BallState, aim: float, p: SkillParams) -> tuple[float, float]:
    """Where a kicker waits, lined up, before driving through the ball along ``aim`` (rad): its
    centre ``contact_m + approach_distance_m`` behind the ball's on the kick line."""
    behind = p.contact_m + p.approach_distance_m
    return ball.x - math.cos(aim) * behind, ball.y - math.sin(aim) * behind


def on_face(robot: RobotState, ball: BallState, p: SkillParams) -> bool:
    """Whether the ball's centre lies within ``dribble_hold_m`` of the middle of ``robot``'s kicker face."""
    contact = p.contact_m
    face_x, face_y = robot.x + math.cos(robot.theta) * contact, robot.y + math.sin(robot.theta) * contact
    return math.hypot(ball.x - face_x, ball.y - face_y) < p.dribble_hold_m


def held_ball(ball: BallState, robots: Iterable[RobotState], p: SkillParams) -> BallState:
    """``ball`` as a team plays it: a moving ball (faster than ``rest_speed_m_s``) on the kicker face
    of one of ``robots`` (:func:`on_face`) that moves with the face (within ``held_slip_m_s`` of its
    velocity, the robot's turn included) goes where the robot takes it, at the robot's velocity. A
    robot turning with the ball swings it round its centre at the face's speed (0.8 m/s at 9 rad/s):
    no run of the ball's own, and predicted along its tangent it would leave the face in a few frames
    (met there, the ball was no longer held and the turn was dropped half way). A ball at rest stays
    at rest (a robot driving slowly onto it does not carry it yet). ``ball`` itself when no robot
    holds it."""
    if math.hypot(ball.vx, ball.vy) <= p.rest_speed_m_s:
        return ball
    contact = p.contact_m
    for r in robots:
        if not on_face(r, ball, p):
            continue
        # the face's middle moves at the robot's velocity plus the swing of its turn about the centre
        fvx = r.vx - r.omega * contact * math.sin(r.theta)
        fvy = r.vy + r.omega * contact * math.cos(r.theta)
        if math.hypot(ball.vx - fvx, ball.vy - fvy) <= p.held_slip_m_s:
            return dataclasses.replace(ball, vx=r.vx, vy=r.vy)
    return ball


def kick_to(robot: RobotState, ball: BallState, target: tuple[float, float], speed: float, p: SkillParams,
            chip: bool = False) -> Intent:
    """Get behind the ball on the line to ``target``, then drive through it with the kicker armed."""
    aim = _angle(target[0] - ball.x, target[1] - ball.y)
    c, s = math.cos(aim), math.sin(aim)
    rx, ry = robot.x - ball.x, robot.y - ball.y
    along, across = rx * c + ry * s, -rx * s + ry * c
    contact = p.contact_m
    # lined up: a kick now would send the ball along the aim (the robot's velocity carries over to it)
    heading_error = abs(wrap_angle(aiming(robot, ball, aim, speed, p, chip) - robot.theta))
    # behind the ball, inside a cone around the kick line that narrows to lined_up_m at contact: driving
    # straight through the ball closes the lateral error on the way (heading likewise)
    gap = max(0.0, -along - contact)
    in_cone = (-along < contact + p.approach_distance_m + p.cone_reach_m
               and abs(across) < p.lined_up_m + p.cone_slope * gap
               and heading_error < p.lined_up_rad + p.cone_heading_rad_m * gap)
    lined_up = along < -contact + p.contact_slack_m and in_cone
    at_ball = along < 0 and along > -contact - p.at_ball_m and abs(across) < p.at_ball_lateral_share * p.lined_up_m
    if lined_up or at_ball:
        return drive_through(robot, ball, aim, speed, p, chip)
    behind = contact + p.approach_distance_m
    px, py = waiting_point(ball, aim, p)
    if along > -contact and abs(across) < behind:
        # on the wrong side of the ball: swing around it at a safe distance first
        side = 1.0 if across >= 0 else -1.0
        px = ball.x - c * p.swing_back_share * behind - s * side * behind * p.swing_side_share
        py = ball.y - s * p.swing_back_share * behind + c * side * behind * p.swing_side_share
    return Intent(px, py, aim, avoid_ball=True)


def set_kick(robot: RobotState, ball: BallState, target: tuple[float, float], speed: float,
             p: SkillParams) -> Intent:
    """A restart's kick at a ball lying still (a free kick, a kickoff), where any touch before the
    kick is the restart's first and the kick a second one: the approach of :func:`kick_to` without
    its cone (lined up within ``set_lined_up_m`` and ``set_lined_up_rad`` at the waiting point, not on
    the way), driving through only once the robot no longer slides across the kick line
    (``set_settle_m_s``) and then at ``set_push_m_s``; within ``set_near_m`` of the ball no faster than
    ``set_approach_m_s`` (a robot that overshoots its waiting point meets the ball off its kicker), and
    the kicker armed all along (a touch on the way is the kick)."""
    lined = dataclasses.replace(p, lined_up_m=p.set_lined_up_m, lined_up_rad=p.set_lined_up_rad, cone_slope=0.0,
                                cone_heading_rad_m=0.0, push_speed_m_s=p.set_push_m_s)
    intent = kick_to(robot, ball, target, speed, lined)
    aim = intent.theta
    sliding = abs(-robot.vx * math.sin(aim) + robot.vy * math.cos(aim)) > p.set_settle_m_s
    if not intent.avoid_ball and sliding:  # lined up but still sliding across: settle at the waiting point first
        intent = Intent(*waiting_point(ball, aim, p), aim)
    if intent.avoid_ball and math.hypot(robot.x - ball.x, robot.y - ball.y) < p.set_near_m:
        intent = dataclasses.replace(intent, max_speed_m_s=p.set_approach_m_s)
    return dataclasses.replace(intent, kick_speed=speed, chip=False)


def aiming(robot: RobotState, ball: BallState, aim: float, speed: float, p: SkillParams, chip: bool = False) -> float:
    """The heading (rad) ``robot`` kicks ``ball`` from to send it along ``aim`` at ``speed`` over the
    ground: the kick is relative to the robot, whose velocity (and part of the ball's across the
    heading) carries over to the ball, so the robot faces the kick's direction less what its
    motion adds (:func:`~strategy.onetouch.kick_heading`, with the robot's and the ball's velocity
    now). A chip likewise, its ``speed`` the kicker's (:func:`~strategy.onetouch.chip_heading`); no
    kick faces the aim."""
    if chip:
        return chip_heading(aim, speed, p.chip_angle_rad, (robot.vx, robot.vy), (ball.vx, ball.vy),
                            p.kicker_retention)
    return kick_heading(aim, speed, (robot.vx, robot.vy), (ball.vx, ball.vy), p.kicker_retention)


def drive_through(robot: RobotState, ball: BallState, aim: float, speed: float, p: SkillParams,
                  chip: bool = False) -> Intent:
    """Drive through the ball along ``aim`` with the kicker armed: it fires when the ball touches the
    front. The robot faces the heading that sends the ball along ``aim`` (:func:`aiming`)."""
    c, s = math.cos(aim), math.sin(aim)
    heading = aiming(robot, ball, aim, speed, p, chip)
    return Intent(ball.x + c * p.through_m, ball.y + s * p.through_m, heading, kick_speed=speed, chip=chip,
                  avoid_ball=False, max_speed_m_s=p.push_speed_m_s, final_speed_m_s=p.push_speed_m_s,
                  dribbler=p.through_dribbler)


def dribble(robot: RobotState, ball: BallState, target: tuple[float, float], p: SkillParams) -> Intent:
    """Carry the ball to ``target`` on the kicker face, dribbler on: take it from behind on the line
    to the target (the approach of :func:`kick_to`, driving onto it at ``dribble_speed_m_s`` with no
    kick), then drive so that the ball arrives at the target, facing the way."""
    aim = _angle(target[0] - ball.x, target[1] - ball.y)
    contact = p.contact_m
    arriving = math.hypot(target[0] - ball.x, target[1] - ball.y) < contact  # the aim swings: keep the heading
    if on_face(robot, ball, p) and (arriving or abs(wrap_angle(aim - robot.theta)) < p.dribble_turn_rad):
        # where the robot stands when the ball lies on the target
        heading = robot.theta if arriving else aim
        x, y = target[0] - math.cos(heading) * contact, target[1] - math.sin(heading) * contact
        return Intent(x, y, heading, dribbler=p.hold_dribbler, avoid_ball=False, max_speed_m_s=p.dribble_speed_m_s)
    take = kick_to(robot, ball, target, 0.0, p)
    if take.avoid_ball:
        return Intent(take.x, take.y, take.theta, dribbler=p.hold_dribbler)  # getting behind the ball
    return Intent(take.x, take.y, take.theta, dribbler=p.hold_dribbler, avoid_ball=False,
                  max_speed_m_s=p.dribble_speed_m_s,
                  final_speed_m_s=min(p.push_speed_m_s, p.dribble_speed_m_s))


def turn_with_ball(robot: RobotState, ball: BallState, target: tuple[float, float], speed: float,
                   p: SkillParams) -> Intent | None:
    """Holding the ball on the kicker face (its centre within ``dribble_hold_m`` of the face's
    middle): turn where the robot stands toward ``target``, the dribbler holding the ball as it
    swings round with the face, at most ``ball_turn_rad_s`` (faster, the ball is lost); facing the
    target within ``lined_up_rad`` and so that the ball passes within ``aim_tolerance_m`` of it,
    drive through it with the kicker armed at ``speed``. None when the ball is not held (going round
    it to line up would leave it: a trapped ball was given away so). The heading turned to and judged
    lined up is the one that sends the ball at the target (:func:`aiming`): the kick is relative to
    the robot, and the turn moves the ball across its heading.

    The intent's heading is the one to face at the end, under a turn rate cap, so that motion control
    runs one profile through the whole turn (a heading a short step ahead each frame is a target the
    heading's profile stops on: it turned at the rate it can stop from within the step, a third of the
    cap). The robot turns about its own centre: going round the ball instead moves the centre on a
    circle of ``contact_m``, whose centripetal acceleration the robot's ``max_accel`` holds far below
    the cap."""
    if not on_face(robot, ball, p):
        return None
    aim = _angle(target[0] - ball.x, target[1] - ball.y)
    heading = aiming(robot, ball, aim, speed, p)
    error = wrap_angle(heading - robot.theta)
    # the kick fires at once: lined up when the ball would pass within aim_tolerance_m of the target
    reach = math.hypot(target[0] - ball.x, target[1] - ball.y)
    if abs(error) < min(p.lined_up_rad, math.atan2(p.aim_tolerance_m, reach)):
        return drive_through(robot, ball, aim, speed, p)
    return Intent(robot.x, robot.y, heading, dribbler=p.hold_dribbler, avoid_ball=False,
                  max_omega_rad_s=p.ball_turn_rad_s)


def speed_after(speed: float, distance: float, p: SkillParams) -> float:
    """Ball speed after rolling ``distance`` from a kick at ``speed`` (0 if it stops before)."""
    return p.ball_model.speed_after(speed, distance)


def pass_speed(distance: float, p: SkillParams, arrival_m_s: float | None = None,
               min_m_s: float | None = None) -> float:
    """Kick speed so the ball arrives at ``distance`` with about ``arrival_m_s`` (default
    ``pass_arrival_m_s``; bisection), between ``min_m_s`` (default ``pass_min_m_s``) and ``pass_max_m_s``."""
    arrival = p.pass_arrival_m_s if arrival_m_s is None else arrival_m_s
    lo, hi = 0.0, p.pass_max_m_s
    for _ in range(_BISECTIONS):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if speed_after(mid, distance, p) < arrival else (lo, mid)
    return min(max(hi, p.pass_min_m_s if min_m_s is None else min_m_s), p.pass_max_m_s)


def intercept(robot: RobotState, ball: BallState, p: SkillParams, field: Field | None = None) -> BallState:
    """The moving ball where ``robot`` can meet it: the first point of its predicted path (rolling
    deceleration, stopping at the field's edge) the robot reaches in time at ``intercept_speed_m_s``.
    A ball at rest (slower than ``rest_speed_m_s``) is returned as it is."""
    speed = math.hypot(ball.vx, ball.vy)
    if speed < p.rest_speed_m_s:
        return ball
    ux, uy = ball.vx / speed, ball.vy / speed
    t_stop = speed / max(p.acc_roll_m_s2, 1e-9)
    limit_x = field.half_length if field is not None else math.inf
    limit_y = field.half_width if field is not None else math.inf
    x, y, v = ball.x, ball.y, speed
    t = 0.0
    while t <= min(p.intercept_horizon_s, t_stop):
        v = speed - p.acc_roll_m_s2 * t
        d = speed * t - 0.5 * p.acc_roll_m_s2 * t * t
        nx, ny = ball.x + ux * d, ball.y + uy * d
        if abs(nx) > limit_x or abs(ny) > limit_y:
            break  # the ball leaves the field (or bounces) here: meet it before
        x, y = nx, ny
        if math.hypot(x - robot.x, y - robot.y) <= p.intercept_speed_m_s * t:
            break
        t += p.intercept_step_s
    v = max(v, 0.0)
    return BallState(x, y, ux * v, uy * v, ball.visible)


def receive(robot: RobotState, ball: BallState, wait_at: tuple[float, float], p: SkillParams,
            shoot_at: tuple[float, float] | None = None, shot_speed: float = 0.0) -> Intent:
    """Meet the moving ball on its path near ``wait_at``; with ``shoot_at``, a one-touch shot
    aimed with the kick model (B.6, :func:`aiming`), else stop it with the dribbler facing it. The
    one-touch kick is armed only while the robot faces its heading within ``one_touch_facing_rad``:
    a kicker fires along the robot's heading, so a ball that arrives before the robot has turned
    would be sent back the way it came; until then the dribbler is on, and a ball that arrives
    early is trapped."""
    speed = math.hypot(ball.vx, ball.vy)
    px, py = wait_at
    moving = speed > p.receive_moving_m_s
    if moving:
        # the point of the ball's path nearest the waiting point
        ux, uy = ball.vx / speed, ball.vy / speed
        t = max(0.0, (px - ball.x) * ux + (py - ball.y) * uy)
        px, py = ball.x + ux * t, ball.y + uy * t
    toward_ball = _angle(ball.x - px, ball.y - py)
    contact = p.contact_m
    if shoot_at is not None and moving:
        heading = aiming(robot, ball, _angle(shoot_at[0] - px, shoot_at[1] - py), shot_speed, p)
        # stand so the ball meets the middle of the kicker face
        cx, cy = px - math.cos(heading) * contact, py - math.sin(heading) * contact
        if abs(wrap_angle(heading - robot.theta)) > p.one_touch_facing_rad:
            return Intent(cx, cy, heading, avoid_ball=False, dribbler=p.hold_dribbler)
        return Intent(cx, cy, heading, kick_speed=shot_speed, avoid_ball=False, dribbler=0.0)
    cx, cy = px - math.cos(toward_ball) * contact, py - math.sin(toward_ball) * contact
    return Intent(cx, cy, toward_ball, dribbler=p.hold_dribbler, avoid_ball=False)


def goalie_block(ball: BallState, field: Field, own_sign: float, p: SkillParams) -> Intent:
    """Stand between the ball and our goal; meet a ball heading for the goal on its line."""
    gx = own_sign * field.half_length
    x = gx - own_sign * p.goalie_depth_m
    half = field.goal_half_width - p.robot_radius_m * p.goalie_post_share
    speed = math.hypot(ball.vx, ball.vy)
    y = ball.y * p.goalie_shade  # default: shade toward the ball
    if speed > p.goalie_shot_speed_m_s and (ball.vx * own_sign) > p.goalie_shot_vx_m_s:
        t = (x - ball.x) / ball.vx
        if t > 0:
            y = ball.y + ball.vy * t
    else:
        # on the line from the ball to the goal centre
        dx = gx - ball.x
        if abs(dx) > 1e-6:
            y = ball.y + (0.0 - ball.y) * (x - ball.x) / dx
    y = min(max(y, -half), half)
    face = _angle(ball.x - x, ball.y - y)
    return Intent(x, y, face, allow_own_defense=True, avoid_ball=False)


def defend(ball: BallState, field: Field, own_sign: float, slot: float, p: SkillParams) -> Intent:
    """Stand on the edge of our defense area (plus a margin) on the line from the goal centre to the
    ball, shifted sideways by ``slot`` metres (``StrategyParams.defender_spacing_m`` apart)."""
    gx = own_sign * field.half_length
    depth = field.dims.defense_depth_m + p.defense_margin_m + p.robot_radius_m
    half_w = field.dims.defense_width_m / 2 + p.defense_margin_m + p.robot_radius_m
    dx, dy = ball.x - gx, ball.y
    ang = math.atan2(dy, -own_sign * abs(dx) if abs(dx) > 1e-6 else -own_sign)
    ux, uy = math.cos(ang), math.sin(ang)
    # where the ray from the goal centre leaves the grown defense rectangle
    t_front = depth / max(abs(ux), 1e-9)
    t_side = half_w / max(abs(uy), 1e-9)
    t = min(t_front, t_side)
    x, y = gx + ux * t, uy * t
    x += -uy * slot * (1 if own_sign < 0 else -1)
    y += ux * slot * (1 if own_sign < 0 else -1)
    y = float(np.clip(y, -field.half_width + p.robot_radius_m, field.half_width - p.robot_radius_m))
    return Intent(x, y, _angle(ball.x - x, ball.y - y))


def mark(opponent: RobotState, field: Field, own_sign: float, p: SkillParams) -> Intent:
    """Stand between an opponent and our goal centre, ``mark_distance_m`` from the opponent."""
    gx = own_sign * field.half_length
    dx, dy = gx - opponent.x, 0.0 - opponent.y
    d = math.hypot(dx, dy)
    k = min(p.mark_distance_m, d * p.mark_max_share) / max(d, 1e-9)
    x, y = opponent.x + dx * k, opponent.y + dy * k
    return Intent(x, y, _angle(opponent.x - x, opponent.y - y))
