"""Game states and set plays: what the rules ask of our robots outside normal play.

Halt (and a timeout): everyone stands. Stop: every robot at least ``stop_distance_m`` from the ball
and slow. Their kickoff or free kick: the same distance (at a kickoff also in our half, outside the
centre circle). Our kickoff: everyone but the kicker in our half, outside the centre circle. Ball
placement: ours, the robot nearest the ball carries it to the designated position, lets go and
backs off, the others keep away from ball and target; theirs, everyone keeps off the line from the
ball to the target. Penalty: the taker behind the ball, then its shot at the goal's far side;
their keeper aside, everyone else the rules' distance behind the ball; our keeper on its goal line
until the normal start. No ball seen yet: a defensive shape in our half. Field frame, metres, radians.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from cmdragons.config import Validated, setting
from cmdragons.geometry import Field, Team
from cmdragons.messages import BallState, GameState, RefereeCommand, RobotState
from strategy.defense import DefenseParams, clear_target
from strategy.skills import Intent, SkillParams, goalie_block, intercept, kick_to, pass_speed, waiting_point

__all__ = [
    "kickoff_places",
    "GameStateParams",
    "behind_ball",
    "halt",
    "hold_shape",
    "keep_away",
    "keep_off_line",
    "keeper_on_line",
    "leave_field",
    "leaver",
    "our_kickoff",
    "own_goal_sign",
    "penalty_rush",
    "penalty_shot",
    "Placing",
    "place_ball",
    "restart_rules",
]


@dataclass(frozen=True)
class GameStateParams(Validated):
    stop_distance_m: float = setting(0.7, lo=0.5, hi=3.0)  # rule: 0.5 m from the ball in a stop, plus margin
    stop_speed_m_s: float = setting(1.2, lo=0.1, hi=5.0)  # rule: 1.5 m/s in a stop, minus margin
    center_circle_margin_m: float = setting(0.2, lo=0.0, hi=2.0)  # kept outside the centre circle at kickoffs
    halfway_margin_m: float = setting(0.05, lo=0.0, hi=1.0)  # robots' edge this far on our side of the halfway line
    free_spot_steps: int = setting(12, lo=1, hi=180)  # the circle round the ball searched in steps of pi / this
    area_clear_m: float = setting(0.05, lo=0.0, hi=1.0)  # ... for a place this far outside the defense areas
    spread_m: float = setting(0.3, lo=0.0, hi=3.0)  # ... and this far (centres) from every other robot's place
    hold_depth_share: float = setting(0.3, lo=0.0, hi=1.0)  # no ball: the shape starts this share of our half deep
    hold_row_m: float = setting(0.4, lo=0.0, hi=3.0)  # ... its rows this far apart
    hold_rows: int = setting(3, lo=1, hi=11)
    hold_spacing_m: float = setting(0.6, lo=0.0, hi=3.0)  # ... its robots this far apart across the field
    placement_done_m: float = setting(0.04, lo=0.0, hi=0.5)  # placing: the ball this near the target: let go
    placement_near_m: float = setting(0.1, lo=0.0, hi=0.5)  # ... and once let go, not taken again within this
    placement_back_m: float = setting(0.2, lo=0.0, hi=2.0)  # ... back off to this gap from the ball
    placement_back_speed_m_s: float = setting(0.5, lo=0.05, hi=5.0)  # ... this slowly
    placement_carry_speed_m_s: float = setting(0.6, lo=0.05, hi=5.0)  # carrying the ball on the dribbler
    placement_take_speed_m_s: float = setting(0.3, lo=0.05, hi=5.0)  # ... driving onto it this slowly ...
    placement_take_m: float = setting(0.3, lo=0.0, hi=2.0)  # ... from this far (face to ball centre) ...
    placement_press_m: float = setting(0.03, lo=0.0, hi=0.1)  # ... aiming this far into it
    placement_grip_m: float = setting(0.015, lo=0.001, hi=0.1)  # the ball this near the face's middle ...
    placement_grip_s: float = setting(0.25, lo=0.0, hi=2.0)  # ... this long, pressed on meanwhile: held
    placement_rest_m_s: float = setting(0.05, lo=0.0, hi=1.0)  # let go only of a ball this slow
    placement_held_rest_m_s: float = setting(0.15, lo=0.0, hi=1.0)  # ... or held, the robot this slow
    placement_line_m: float = setting(0.65, lo=0.5, hi=3.0)  # rule: 0.5 m off the placement's line, plus margin
    penalty_behind_m: float = setting(1.2, lo=1.0, hi=5.0)  # rule: 1 m behind the ball at a penalty, plus margin
    penalty_aim_share: float = setting(0.6, lo=0.0, hi=1.0)  # the taker aims this share of the half goal aside
    penalty_kick_m_s: float = setting(6.2, lo=0.1, hi=6.5)  # the penalty's shot (rule: a ball over 6.5 m/s is a foul)
    penalty_shoot_from_m: float = setting(1.5, lo=1.0, hi=10.0)  # ... from this far from the goal line, the
    # ball tapped there first (rule: outside the 1 m deep defense area)
    penalty_zone_m: float = setting(0.3, lo=0.0, hi=5.0)  # ... or up to this much farther
    penalty_arrive_m_s: float = setting(0.1, lo=0.0, hi=3.0)  # ... the ball tapped there first, arriving this slow
    penalty_tap_min_m_s: float = setting(0.5, lo=0.05, hi=6.5)  # ... tapped at least this fast
    penalty_follow_m_s: float = setting(0.2, lo=0.0, hi=3.0)  # a tapped ball faster than this is followed, not played
    penalty_follow_gap_m: float = setting(0.15, lo=0.0, hi=2.0)  # ... this much farther back than the waiting point
    penalty_rest_m_s: float = setting(0.08, lo=0.0, hi=1.0)  # the shot waits for the ball slower than this
    penalty_lined_up_rad: float = setting(0.05, lo=0.001, hi=1.0)  # the shot's line-up: heading ...
    penalty_lined_up_m: float = setting(0.01, lo=0.001, hi=0.5)  # ... and lateral error before driving through
    # ... at this speed (slower than in play: a straighter shot)
    penalty_push_m_s: float = setting(0.5, lo=0.05, hi=3.0)
    penalty_rush_moved_m: float = setting(0.1, lo=0.0, hi=2.0)  # their penalty: the ball this far off the mark
    # is in play (rule: 0.05 m, plus margin), our keeper goes out to it ...
    penalty_rush_away_m_s: float = setting(0.3, lo=0.0, hi=5.0)  # ... unless it moves away from our goal this fast
    penalty_keeper_share: float = setting(0.6, lo=0.0, hi=1.0)  # our keeper's centre this share of its radius
    # inside the goal line while the penalty is prepared (the rules: touching the line)
    leave_after_s: float = setting(2.0, lo=0.0, hi=60.0)  # more robots on the field than the referee allows this
    # long (the referee's robot handlers take a robot sent off out at once): one drives out ...
    leave_out_m: float = setting(0.1, lo=0.0, hi=1.0)  # ... to the touch line at the halfway line, its centre this
    # far outside the line (the rules: a substitution at most 1 m from the halfway line, partly in the field margin)


def leaver(own: Mapping[int, RobotState], keeper: int, pitch: Field) -> int | None:
    """Of ``own`` robots but the ``keeper``, the one that leaves the field when the team has too many:
    the nearest to either crossing of the halfway line and the touch lines (where the rules have a
    robot substituted, and the robot the league's simulation controller takes out first)."""
    w = pitch.half_width
    players = [rid for rid in own if rid != keeper] or list(own)
    if not players:
        return None
    return min(players, key=lambda rid: (min(math.hypot(own[rid].x, own[rid].y - w),
                                             math.hypot(own[rid].x, own[rid].y + w)), rid))


def leave_field(robot: RobotState, pitch: Field, p: GameStateParams) -> Intent:
    """Drive out at the halfway line: onto the nearer touch line, the centre ``leave_out_m`` outside it,
    facing out (the robot handlers or the simulation controller take it from there)."""
    side = 1.0 if robot.y >= 0.0 else -1.0
    return Intent(0.0, side * (pitch.half_width + p.leave_out_m), side * math.pi / 2)


def own_goal_sign(team: Team, game: GameState) -> float:
    """-1.0 when ``team`` defends the goal at negative x, else +1.0."""
    return -1.0 if (team == "blue") == game.blue_defends_negative_x else 1.0


def halt(own: Mapping[int, RobotState]) -> dict[int, Intent]:
    """Every robot stands where it is."""
    return {rid: Intent(r.x, r.y, r.theta, max_speed_m_s=0.0) for rid, r in own.items()}


def hold_shape(own: Mapping[int, RobotState], pitch: Field, own_sign: float, p: GameStateParams) -> dict[int, Intent]:
    """No ball seen yet: a defensive shape in our half, rows of ``hold_rows``."""
    out = {}
    for k, rid in enumerate(sorted(own)):
        x = own_sign * (pitch.half_length * p.hold_depth_share + p.hold_row_m * (k % p.hold_rows))
        y = (k - len(own) / 2) * p.hold_spacing_m
        out[rid] = Intent(x, y, 0.0 if own_sign < 0 else math.pi)
    return out


def _in_own_half(x: float, own_sign: float, radius: float, p: GameStateParams) -> float:
    """``x`` moved into our half, the robot's edge ``halfway_margin_m`` short of the halfway line."""
    return own_sign * max(own_sign * x, radius + p.halfway_margin_m)


def _circle_clearance(pitch: Field, radius: float, p: GameStateParams) -> float:
    """How far a robot's centre keeps from the centre spot at kickoffs."""
    return pitch.dims.center_circle_radius_m + p.center_circle_margin_m + radius


def kickoff_places(points: NDArray[np.float64], pitch: Field, own_sign: float, p: GameStateParams,
                   radius: float) -> NDArray[np.float64]:
    """Where robots sent to ``points`` (n, 2) stand at our kickoff, as :func:`our_kickoff` moves
    them: into our half, and sideways out of the centre circle."""
    x = own_sign * np.maximum(own_sign * points[:, 0], radius + p.halfway_margin_m)
    y = points[:, 1].copy()
    r_c = _circle_clearance(pitch, radius, p)
    inside = np.hypot(x, y) < r_c
    y[inside] = np.copysign(r_c, np.where(y[inside] != 0.0, y[inside], 1.0))
    return np.column_stack((x, y))


def our_kickoff(intents: Mapping[int, Intent], pitch: Field, own_sign: float, p: GameStateParams, radius: float,
                kicker: int | None) -> dict[int, Intent]:
    """At our kickoff everyone but the kicker stays in our half, outside the centre circle (moved
    sideways out of it)."""
    out = {}
    r_c = _circle_clearance(pitch, radius, p)
    for rid, it in intents.items():
        if rid == kicker:
            out[rid] = it
            continue
        x = _in_own_half(it.x, own_sign, radius, p)
        y = it.y
        if math.hypot(x, y) < r_c:
            y = math.copysign(r_c, y if y != 0 else 1.0)
        out[rid] = dataclasses.replace(it, x=x, y=y)
    return out


def keep_away(intents: Mapping[int, Intent], ball: BallState, pitch: Field, own_sign: float, p: GameStateParams,
              radius: float, kickoff: bool, slow: bool,
              distance_m: float | None = None) -> dict[int, Intent]:
    """Every target at least ``distance_m`` (default ``stop_distance_m``: the rules' 0.5 m plus a
    margin) from the ball, on the field; at their kickoff also in our half and outside the centre
    circle; slow (``stop_speed_m_s``) in a stop. ``radius``: the robots'."""
    d_min = (p.stop_distance_m if distance_m is None else distance_m) + radius
    r_c = _circle_clearance(pitch, radius, p)
    lim_x, lim_y = pitch.half_length - radius, pitch.half_width - radius
    places: dict[int, tuple[float, float]] = {}  # the places that stay, then each moved one as it is found
    moved = []
    for rid, it in intents.items():
        x, y = it.x, it.y
        if kickoff:
            x = _in_own_half(x, own_sign, radius, p)
            if math.hypot(x, y) < r_c:
                ang = math.atan2(y, x) if math.hypot(x, y) > 1e-6 else (0.0 if own_sign > 0 else math.pi)
                x, y = r_c * math.cos(ang), r_c * math.sin(ang)
        if math.hypot(x - ball.x, y - ball.y) < d_min:
            moved.append((rid, x, y))
        else:
            places[rid] = (x, y)
    for rid, x, y in moved:
        dx, dy = x - ball.x, y - ball.y
        if math.hypot(dx, dy) < 1e-6:
            dx, dy = own_sign, 0.0
        # the nearest point of the circle around the ball that lies on the field (where the cameras see
        # us), outside the defense areas the robot may not enter (a place in one has no path: the robot
        # stops at the area's edge, by the ball) and spread_m from the other places (two robots sent to
        # one spot stand body to body: a push moves one into the other); without a spread one, the
        # nearest of the rest
        allowed = int(own_sign) if intents[rid].allow_own_defense else 0
        base = math.atan2(dy, dx)
        steps = p.free_spot_steps
        first = None
        for turn in (0.0, *(sign * k * math.pi / steps for k in range(1, steps + 1) for sign in (1.0, -1.0))):
            x, y = ball.x + d_min * math.cos(base + turn), ball.y + d_min * math.sin(base + turn)
            if abs(x) <= lim_x and abs(y) <= lim_y \
                    and pitch.in_defense_area(x, y, radius + p.area_clear_m) in (0, allowed):
                first = first or (x, y)
                if all(math.hypot(x - q[0], y - q[1]) >= p.spread_m for q in places.values()):
                    break
        else:
            x, y = first or (x, y)
        places[rid] = (x, y)
    out = {}
    for rid, it in intents.items():
        x, y = places[rid]
        out[rid] = Intent(x, y, it.theta, dribbler=0.0, avoid_ball=True, allow_own_defense=it.allow_own_defense,
                          max_speed_m_s=p.stop_speed_m_s if slow else it.max_speed_m_s)
    return out


def restart_rules(intents: Mapping[int, Intent], game: GameState, ours: bool, ball: BallState, pitch: Field,
                  own_sign: float, p: GameStateParams, radius: float,
                  kicker: int | None) -> dict[int, Intent]:
    """The normal-play ``intents`` held to the rules of ``game``'s command: keep away in a stop and
    at their kickoff or free kick, our half at our kickoff (``kicker`` excepted). ``ours``: the
    restart is for our team."""
    out = dict(intents)
    if game.command == RefereeCommand.STOP or (game.command.kick_restart and not ours):
        # slow in a stop (the rules) and at their kickoff (robots put in formation then cross round the
        # ball to their places: fast, they swing in past the rules' distance)
        out = keep_away(out, ball, pitch, own_sign, p, radius, game.command == RefereeCommand.KICKOFF,
                        game.command in (RefereeCommand.STOP, RefereeCommand.KICKOFF))
    if game.command == RefereeCommand.KICKOFF and ours:
        out = our_kickoff(out, pitch, own_sign, p, radius, kicker)
    return out


def _capsule_push(x: float, y: float, a: tuple[float, float], b: tuple[float, float],
                  d_min: float) -> tuple[float, float]:
    """(x, y) moved out of the capsule of radius ``d_min`` round the segment a-b, the short way."""
    ax, ay = a
    dx, dy = b[0] - ax, b[1] - ay
    length2 = dx * dx + dy * dy
    u = 0.0 if length2 < 1e-12 else max(0.0, min(1.0, ((x - ax) * dx + (y - ay) * dy) / length2))
    qx, qy = ax + u * dx, ay + u * dy
    ox, oy = x - qx, y - qy
    d = math.hypot(ox, oy)
    if d >= d_min:
        return x, y
    if d < 1e-6:  # on the line: step to its left
        n = math.hypot(dx, dy)
        ox, oy, d = (-dy / n, dx / n, 1.0) if n > 1e-9 else (1.0, 0.0, 1.0)
    return qx + ox / d * d_min, qy + oy / d * d_min


def _capsule_outline(a: tuple[float, float], b: tuple[float, float], d_min: float,
                     steps: int) -> list[tuple[float, float]]:
    """Points on the outline of the capsule of radius ``d_min`` round the segment a-b: both sides in
    ``steps`` pieces and each end's half circle in steps of pi / ``steps``."""
    dx, dy = b[0] - a[0], b[1] - a[1]
    n = math.hypot(dx, dy)
    ux, uy = (dx / n, dy / n) if n > 1e-9 else (1.0, 0.0)
    pts = []
    for k in range(steps + 1):
        t = k / steps
        cx, cy = a[0] + t * dx, a[1] + t * dy
        pts += [(cx - uy * d_min, cy + ux * d_min), (cx + uy * d_min, cy - ux * d_min)]
    base = math.atan2(uy, ux)
    for k in range(1, steps):
        turn = math.pi / 2 - k * math.pi / steps  # from the left side round the end
        pts.append((b[0] + d_min * math.cos(base + turn), b[1] + d_min * math.sin(base + turn)))
        pts.append((a[0] - d_min * math.cos(base + turn), a[1] - d_min * math.sin(base + turn)))
    return pts


def keep_off_line(intents: Mapping[int, Intent], start: tuple[float, float], end: tuple[float, float], pitch: Field,
                  p: GameStateParams, radius: float) -> dict[int, Intent]:
    """Every target ``placement_line_m`` (plus the robot's radius) off the segment from the ball
    ``start`` to the placement's target ``end``, on the field (across the line when the field's
    edge leaves no room on the near side; in a corner, where neither side has room, the nearest point
    of the way round the line's ends that is on the field: clamped into the field, a robot moved off
    the line stood by the ball again, in the placer's way)."""
    d_min = p.placement_line_m + radius
    lim_x, lim_y = pitch.half_length - radius, pitch.half_width - radius

    def on_field(q: tuple[float, float]) -> bool:
        return abs(q[0]) <= lim_x and abs(q[1]) <= lim_y

    out = {}
    for rid, it in intents.items():
        x, y = _capsule_push(it.x, it.y, start, end, d_min)
        if not on_field((x, y)):
            # mirror through the line: the far side
            far = _capsule_push(2.0 * x - it.x, 2.0 * y - it.y, start, end, d_min)
            room = [far] if on_field(far) else [q for q in _capsule_outline(start, end, d_min, p.free_spot_steps)
                                                if on_field(q)]
            if room:
                x, y = min(room, key=lambda q: math.hypot(q[0] - it.x, q[1] - it.y))
        x, y = max(-lim_x, min(lim_x, x)), max(-lim_y, min(lim_y, y))
        out[rid] = Intent(x, y, it.theta, avoid_ball=True, allow_own_defense=it.allow_own_defense,
                          max_speed_m_s=it.max_speed_m_s)
    return out


@dataclass(frozen=True)
class Placing:
    """One robot's ball placement from frame to frame: which robot, since when (s) it has seen the
    ball on its face (None: not), and whether it has let the ball go at the target."""

    robot: int
    grip_since: float | None = None
    released: bool = False


def place_ball(robot: RobotState, ball: BallState, target: tuple[float, float], skills: SkillParams,
               p: GameStateParams, t: float, state: Placing | None = None) -> tuple[Intent, Placing]:
    """Ball placement by one robot: take the ball on the dribbler from where the robot stands (no
    going round it: a ball by the line or past it is pulled back), carry it without turning until
    it lies within ``placement_done_m`` of ``target``, let go, and back off slowly to
    ``placement_back_m`` from it. ``state``: the frame before's (None or another robot's: a new
    placement); returns the intent and the state now.

    The robot presses on until it has seen the ball on its face ``placement_grip_s`` (a ball by a
    robot is seen a centimetre or so off: seen on the face, it may not be on the dribbler yet, and a
    carry backwards would leave it behind); from then on it counts as held until it is
    ``dribble_hold_m`` off the face (a ball in the robot's mouth is seen late). Once it let go, it
    backs off whatever it sees while the ball lies within ``placement_near_m`` of the target (the
    tracker keeps a ball in a robot's mouth with it: backing off, the ball is seen to follow it)."""
    if state is None or state.robot != robot.id:
        state = Placing(robot.id)
    off = math.hypot(ball.x - target[0], ball.y - target[1])
    contact = skills.contact_m
    c, s = math.cos(robot.theta), math.sin(robot.theta)
    # on the face: the ball against its middle (tighter than the dribble skill's test: a carry that
    # starts without the grip walks away from the ball), looser once it is held
    face_gap = math.hypot(ball.x - (robot.x + c * contact), ball.y - (robot.y + s * contact))
    held = state.grip_since is not None and t - state.grip_since >= p.placement_grip_s
    on_face = face_gap < (skills.dribble_hold_m if held else p.placement_grip_m)
    grip_since = (t if state.grip_since is None else state.grip_since) if on_face else None
    # a ball on the face moves as the robot does, whose speed the cameras see only to a few cm/s
    resting = math.hypot(ball.vx, ball.vy) < (p.placement_held_rest_m_s if on_face else p.placement_rest_m_s)
    let_go = (state.released and off <= p.placement_near_m) or (off <= p.placement_done_m and resting) \
        or (off <= p.placement_near_m and not on_face)
    if let_go:
        away = math.atan2(robot.y - ball.y, robot.x - ball.x)
        reach = contact + p.placement_back_m
        return Intent(ball.x + reach * math.cos(away), ball.y + reach * math.sin(away), robot.theta,
                      allow_any_defense=True, max_speed_m_s=p.placement_back_speed_m_s), \
            Placing(robot.id, None, released=True)
    state = Placing(robot.id, grip_since)
    if held and on_face:  # carry: the robot where the ball lies on the target, facing as it does
        return Intent(target[0] - c * contact, target[1] - s * contact, robot.theta, dribbler=skills.hold_dribbler,
                      avoid_ball=False, allow_any_defense=True,
                      max_speed_m_s=p.placement_carry_speed_m_s), state
    heading = math.atan2(ball.y - robot.y, ball.x - robot.x)
    near = math.hypot(ball.x - robot.x, ball.y - robot.y) < contact + p.placement_take_m
    reach = contact - p.placement_press_m  # a little into the ball: the face meets it before the robot stops
    return Intent(ball.x - math.cos(heading) * reach, ball.y - math.sin(heading) * reach, heading,
                  dribbler=skills.hold_dribbler, avoid_ball=False, allow_any_defense=True,
                  max_speed_m_s=p.placement_take_speed_m_s if near else None), state


def behind_ball(intents: Mapping[int, Intent], ball: BallState, attack_sign: float, pitch: Field,
                p: GameStateParams, radius: float) -> dict[int, Intent]:
    """A penalty's rule for everyone but the taker and the defending keeper: ``penalty_behind_m``
    behind the ball (toward the kicking team's own goal), on the field."""
    limit = ball.x - attack_sign * (p.penalty_behind_m + radius)
    lim_x = pitch.half_length - radius
    out = {}
    for rid, it in intents.items():
        x = it.x if (it.x - limit) * attack_sign <= 0.0 else limit
        out[rid] = dataclasses.replace(it, x=max(-lim_x, min(lim_x, x)), kick_speed=0.0, avoid_ball=True)
    return out


def penalty_shot(robot: RobotState, ball: BallState, attack_sign: float, keeper: RobotState | None, pitch: Field,
                 skills: SkillParams, p: GameStateParams, ready: bool) -> Intent:
    """The taker (the rules: after the normal start the kicker may play the ball as often as it
    likes within 10 s, the ball only ever moving toward the goal). Prepared: behind the ball facing
    the goal's centre. Started: a tap toward the goal's centre so the ball comes to rest
    ``penalty_shoot_from_m`` from the goal line (outside the defense area: no touching the ball in
    it), following it at a distance while it rolls; from there, once it rests, a shot at full legal
    speed at the side of the goal the keeper leaves open, lined up tighter than in play."""
    goal_x = attack_sign * pitch.half_length
    to_line = (goal_x - ball.x) * attack_sign
    centre = math.atan2(-ball.y, goal_x - ball.x)
    behind = skills.contact_m + skills.approach_distance_m
    if not ready:
        return Intent(*waiting_point(ball, centre, skills), centre)
    # hands off while it rolls: behind it on its way, far enough back to line up afresh
    speed = math.hypot(ball.vx, ball.vy)
    way = math.atan2(ball.vy, ball.vx) if speed > p.penalty_rest_m_s else centre
    follow = behind + p.penalty_follow_gap_m
    follow_at = Intent(ball.x - follow * math.cos(way), ball.y - follow * math.sin(way), centre)
    if to_line > p.penalty_shoot_from_m + p.penalty_zone_m:
        if ball.vx * attack_sign > p.penalty_follow_m_s:
            return follow_at
        tap = pass_speed(to_line - p.penalty_shoot_from_m, skills, p.penalty_arrive_m_s, p.penalty_tap_min_m_s)
        return kick_to(robot, ball, (goal_x, 0.0), tap, skills)
    if speed > p.penalty_rest_m_s:
        return follow_at  # the shot from a ball at rest: lined up, not caught up with a rolling ball
    side = -math.copysign(1.0, keeper.y) if keeper is not None and abs(keeper.y) > 1e-3 else 1.0
    aim = (goal_x, side * pitch.goal_half_width * p.penalty_aim_share)
    # lined up before driving through, not on the way (no cone that narrows toward the ball)
    tight = dataclasses.replace(skills, lined_up_rad=p.penalty_lined_up_rad, lined_up_m=p.penalty_lined_up_m,
                                cone_slope=0.0, cone_heading_rad_m=0.0, push_speed_m_s=p.penalty_push_m_s)
    return kick_to(robot, ball, aim, p.penalty_kick_m_s, tight)


def penalty_rush(robot: RobotState, ball: BallState, mark: tuple[float, float] | None, pitch: Field,
                 own_sign: float, skills: SkillParams, defense: DefenseParams,
                 p: GameStateParams) -> Intent | None:
    """Our keeper at their penalty once the ball is in play (the rules: from then on it moves
    freely): out to meet the ball where it can (:func:`intercept`) and clear it back up the field
    before the taker shoots from close in (a shot at full speed from a few metres beats any keeper
    on its line); None while the ball is still on the ``mark`` (``penalty_rush_moved_m``) or
    already past the keeper's reach (moving away from our goal)."""
    if mark is None or math.hypot(ball.x - mark[0], ball.y - mark[1]) < p.penalty_rush_moved_m:
        return None
    if ball.vx * own_sign < -p.penalty_rush_away_m_s:
        return None
    meet = intercept(robot, ball, skills, pitch)
    intent = kick_to(robot, meet, clear_target(meet, pitch, own_sign, defense), defense.clear_kick_m_s, skills)
    return dataclasses.replace(intent, allow_own_defense=True)


def keeper_on_line(ball: BallState, pitch: Field, own_sign: float, skills: SkillParams,
                   p: GameStateParams) -> Intent:
    """Our keeper while their penalty is prepared: touching the goal line, across from the ball."""
    block = goalie_block(ball, pitch, own_sign, skills)
    x = own_sign * (pitch.half_length - p.penalty_keeper_share * skills.robot_radius_m)
    return dataclasses.replace(block, x=x)
