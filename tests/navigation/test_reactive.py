"""The reactive navigators against their theory (lecture notes 001 and 003): each succeeds where its
theory says it does and fails the known way where it should; the kernels agree with plain-numpy
references.

Scenes are driven kinematically (the robot is where its commands take it, 60 Hz): what is tested
is the method, not the motor model (the contract test drives them in the simulator)."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable

import numpy as np
import pytest

from cmdragons.control import ControlParams
from cmdragons.messages import RobotState
from cmdragons.navigation import NAVIGATORS, Arrival, BugParams, GridBug2Status, NavStatus, bug2_path, make_navigator
from cmdragons.navigation import _bug_kernels as BK
from cmdragons.navigation import _bug_reference as R
from cmdragons.navigation import _escape_evade_kernels as EK
from cmdragons.navigation import _potential_field_kernels as PK
from cmdragons.navigation import _reactive_kernels as RK
from cmdragons.navigation import _vfh_kernels as VK
from cmdragons.navigation.escape_evade import MovementModel, evade_config
from cmdragons.navigation.potential_field import potential_config
from cmdragons.planning import CollisionWorld, deadline
from cmdragons.planning.grid.planners import descend_nf1, nf1
from cmdragons.team import TeamParams

CONTROL = ControlParams()
DT = CONTROL.motion.period_s
RADIUS = 0.09
BOUNDS = (-3.0, -2.0, 3.0, 2.0)
# escape_evade avoids moving objects only: static ones are its plan's business
REACTIVE = sorted(n for n in NAVIGATORS if n not in ("trajectory", "dynamic_window", "robox", "escape_evade"))
# a U open away from the goal at +x: the robot starts inside it, facing the goal through its bottom
U_TRAP = np.array([(0.5, -0.8, 0.6, 0.8), (-0.6, 0.7, 0.6, 0.8), (-0.6, -0.8, 0.6, -0.7)])


def run(nav_name: str, world_at: Callable[[int], CollisionWorld], start: tuple[float, float],
        goal: tuple[float, float], seconds: float, team: TeamParams | None = None
        ) -> tuple[np.ndarray, list[NavStatus], object]:
    """Drive ``nav_name`` kinematically: the robot's positions (k, 2), statuses, the navigator."""
    nav = make_navigator(nav_name, (team or TeamParams()).navigator_sections, CONTROL, RADIUS)
    nav.set_plan(np.array([start, goal]), Arrival(0.0))
    x, y, vx, vy, th = start[0], start[1], 0.0, 0.0, 0.0
    xs, statuses = [], []
    for k in range(round(seconds / DT)):
        robot = RobotState("blue", 0, x, y, th, vx, vy, 0.0)
        vx, vy, om = nav.command(robot, world_at(k), deadline(60.0))
        nav.sent(vx, vy)
        x, y, th = x + vx * DT, y + vy * DT, th + om * DT
        xs.append((x, y))
        statuses.append(getattr(nav, "status", NavStatus.MOVING))
    return np.array(xs), statuses, nav


def least_clearance(world: CollisionWorld, xs: np.ndarray) -> float:
    cw = world.compile(RADIUS)
    return min(cw.clearance(float(p[0]), float(p[1])) for p in xs)


@pytest.mark.parametrize("name", REACTIVE)
def test_every_reactive_navigator_passes_a_convex_obstacle_to_its_goal(name: str) -> None:
    # one disc (a robot) and one box on the line: each method reaches the goal without touching them
    world = CollisionWorld(BOUNDS, np.array([(0.0, 0.05, 0.09)]), boxes=np.array([(1.2, -0.4, 1.4, 0.2)]))
    xs, _, _ = run(name, lambda k: world, (-2.0, 0.0), (2.2, 0.0), 20.0)
    assert math.dist(tuple(xs[-1]), (2.2, 0.0)) < 0.01
    assert least_clearance(world, xs) > -1e-6


@pytest.mark.parametrize("obstacle", ["gaussian", "inverse"])
def test_potential_field_descends_on_a_convex_scene(obstacle: str) -> None:
    team = TeamParams()
    field = dataclasses.replace(team.navigator_sections["potential_field"], obstacle=obstacle, escape="none")
    team = team.with_section("potential_field", field)
    world = CollisionWorld(BOUNDS, np.array([(-0.5, 0.1, 0.09), (0.6, -0.2, 0.2)]))
    xs, statuses, _ = run("potential_field", lambda k: world, (-2.0, 0.0), (2.0, 0.0), 8.0, team)
    assert math.dist(tuple(xs[-1]), (2.0, 0.0)) < 0.01
    assert NavStatus.LOCAL_MINIMUM not in statuses and NavStatus.ESCAPING not in statuses
    assert least_clearance(world, xs) > 0.0


@pytest.mark.parametrize("name", ["potential_field", "extended_potential_field"])
def test_potential_field_is_stuck_in_the_u_trap_and_says_so(name: str) -> None:
    team = TeamParams()
    team = team.with_section("potential_field", dataclasses.replace(team.navigator_sections["potential_field"],
                                                                    escape="none"))
    world = CollisionWorld(BOUNDS, boxes=U_TRAP)
    xs, statuses, _ = run(name, lambda k: world, (0.0, 0.0), (2.0, 0.0), 6.0, team)
    assert statuses[-1] is NavStatus.LOCAL_MINIMUM
    assert math.dist(tuple(xs[-1]), (2.0, 0.0)) > 1.0  # still in the trap, at rest
    assert np.hypot(*(xs[-1] - xs[-2])) < 1e-9
    assert least_clearance(world, xs) > 0.0


def test_nf1_escape_leaves_the_u_trap() -> None:
    world = CollisionWorld(BOUNDS, boxes=U_TRAP)
    xs, statuses, _ = run("potential_field", lambda k: world, (0.0, 0.0), (2.0, 0.0), 12.0)
    assert NavStatus.ESCAPING in statuses
    assert math.dist(tuple(xs[-1]), (2.0, 0.0)) < 0.01
    assert least_clearance(world, xs) > -1e-6


def random_field(seed: int) -> CollisionWorld:
    """Six to nine discs and boxes between x = -1.5 and 1.5, some touching (concave clusters), with
    start (-2.5, 0) and goal (2.5, 0) left free."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(6, 10))
    circles = np.column_stack([rng.uniform(-1.5, 1.5, n), rng.uniform(-1.2, 1.2, n), rng.uniform(0.09, 0.3, n)])
    m = int(rng.integers(1, 4))
    c = np.column_stack([rng.uniform(-1.2, 1.2, m), rng.uniform(-1.0, 1.0, m)])
    half = rng.uniform(0.05, 0.4, (m, 2))
    boxes = np.column_stack([c - half, c + half])
    return CollisionWorld(BOUNDS, circles, boxes=boxes)


def reachable(world: CollisionWorld, start: tuple[float, float], goal: tuple[float, float]) -> bool:
    grid = world.compile(RADIUS).clearance_grid(0.05)
    free = grid.values > 0.1
    cell = lambda p: (int((p[1] - grid.y0) / 0.05), int((p[0] - grid.x0) / 0.05))  # noqa: E731
    return bool(descend_nf1(nf1(free, cell(goal), 8), cell(start), 8))


# seeds 17, 33 and 58 have gaps narrower than the level line's band that the range sensor sees through
@pytest.mark.parametrize(("name", "seed"), [("bug2", s) for s in range(6)]
                         + [("tangent_bug", s) for s in (*range(6), 17, 33, 58)])
def test_a_bug_method_reaches_the_goal_of_any_finite_obstacle_field(name: str, seed: int) -> None:
    world = random_field(seed)
    start, goal = (-2.5, 0.0), (2.5, 0.0)
    assert reachable(world, start, goal)
    xs, statuses, _ = run(name, lambda k: world, start, goal, 40.0)
    assert math.dist(tuple(xs[-1]), goal) < 0.01, statuses[-1]
    assert least_clearance(world, xs) > -1e-6


@pytest.mark.parametrize("name", ["bug1", "bug2", "tangent_bug"])
def test_the_bug_methods_leave_the_u_trap(name: str) -> None:
    # Bug1 circles the whole U before it leaves: 11 m of boundary at the speed that rounds its corners
    world = CollisionWorld(BOUNDS, boxes=U_TRAP)
    xs, statuses, _ = run(name, lambda k: world, (0.0, 0.0), (2.0, 0.0), 35.0)
    assert NavStatus.FOLLOWING in statuses
    assert math.dist(tuple(xs[-1]), (2.0, 0.0)) < 0.01
    assert least_clearance(world, xs) > -1e-6


@pytest.mark.parametrize("name", ["bug1", "bug2", "tangent_bug"])
def test_a_bug_method_reports_an_enclosed_goal_as_blocked(name: str) -> None:
    # the goal inside a closed ring of boxes: circling it once proves it cannot be reached
    ring = np.array([(0.8, -0.6, 0.9, 0.6), (1.9, -0.6, 2.0, 0.6), (0.8, 0.5, 2.0, 0.6), (0.8, -0.6, 2.0, -0.5)])
    world = CollisionWorld(BOUNDS, boxes=ring)
    xs, statuses, _ = run(name, lambda k: world, (-1.0, 0.0), (1.4, 0.0), 25.0)
    assert statuses[-1] is NavStatus.BLOCKED
    assert least_clearance(world, xs) > -1e-6


def test_escape_evade_keeps_away_from_a_robot_driving_at_it() -> None:
    # our robot holds its goal; another drives through it at 1.5 m/s: the trajectory navigator is hit,
    # escape and evade step aside and come back
    goal = (0.0, 0.0)

    def world_at(k: int) -> CollisionWorld:
        t = k * DT
        return CollisionWorld(BOUNDS, np.array([(-2.0 + 1.5 * t, 0.02, 0.09)]), np.array([(1.5, 0.0)]))

    def gap(xs: np.ndarray) -> float:
        other = np.array([(-2.0 + 1.5 * (k + 1) * DT, 0.02) for k in range(len(xs))])
        return float(np.min(np.hypot(*(xs - other).T)))

    held, _, _ = run("trajectory", world_at, goal, goal, 4.0)
    assert gap(held) < 2 * RADIUS  # the reference: contact
    xs, _, nav = run("escape_evade", world_at, goal, goal, 4.0)
    assert gap(xs) > 2 * RADIUS + 0.05
    assert math.dist(tuple(xs[-1]), goal) < 0.01


# --- Bug2's whole path on an occupancy grid ------------------------------------------------------
CELL_M = 0.05


def occupancy(world: CollisionWorld) -> tuple[np.ndarray, Callable[[tuple[float, float]], tuple[int, int]]]:
    """The world's occupancy grid of 0.05 m cells (occupied where the robot's centre touches an
    obstacle, row = y) and the cell (column, row) of a point."""
    grid = world.compile(RADIUS).clearance_grid(CELL_M, cap_m=CELL_M)
    return grid.values < 0.0, lambda p: (int((p[0] - grid.x0) / CELL_M), int((p[1] - grid.y0) / CELL_M))


def check_moves(occupied: np.ndarray, cells: np.ndarray) -> None:
    """Every cell of the path free, each move to one of the eight neighbours."""
    assert not occupied[cells[:, 1], cells[:, 0]].any()
    steps = np.abs(np.diff(cells, axis=0))
    assert steps.max(initial=1) == 1 and steps.sum(axis=1).min(initial=1) >= 1


@pytest.mark.parametrize("seed", range(9))
def test_grid_bug2_reaches_the_goal_of_any_finite_obstacle_field(seed: int) -> None:
    occupied, cell = occupancy(random_field(seed))
    start, goal = cell((-2.5, 0.0)), cell((2.5, 0.0))
    for side in ("left", "right"):
        found = bug2_path(occupied, start, goal, BugParams(side=side))
        assert found.status is GridBug2Status.REACHED
        assert tuple(found.cells[0]) == start and tuple(found.cells[-1]) == goal
        check_moves(occupied, found.cells)
        assert found.length_cells >= math.dist(start, goal) - 1e-9


def test_grid_bug2_leaves_the_u_trap_and_reports_an_enclosed_goal_as_blocked() -> None:
    occupied, cell = occupancy(CollisionWorld(BOUNDS, boxes=U_TRAP))
    found = bug2_path(occupied, cell((0.0, 0.0)), cell((2.0, 0.0)))
    assert found.status is GridBug2Status.REACHED
    check_moves(occupied, found.cells)
    ring = np.array([(0.8, -0.6, 0.9, 0.6), (1.9, -0.6, 2.0, 0.6), (0.8, 0.5, 2.0, 0.6), (0.8, -0.6, 2.0, -0.5)])
    occupied, cell = occupancy(CollisionWorld(BOUNDS, boxes=ring))
    for side in ("left", "right"):
        found = bug2_path(occupied, cell((-1.0, 0.0)), cell((1.4, 0.0)), BugParams(side=side))
        assert found.status is GridBug2Status.BLOCKED
        check_moves(occupied, found.cells)
    assert bug2_path(occupied, cell((0.85, 0.0)), cell((1.4, 0.0))).status is GridBug2Status.INVALID_START
    assert bug2_path(occupied, cell((-1.0, 0.0)), cell((0.85, 0.0))).status is GridBug2Status.INVALID_GOAL


def test_grid_bug2_reaches_exactly_the_goals_connected_to_the_start() -> None:
    # ground truth: the 8-connected components of the free cells (the robot's moves)
    from scipy import ndimage

    rng = np.random.default_rng(11)
    counted = {True: 0, False: 0}
    for _ in range(300):
        occupied = rng.random(tuple(rng.integers(5, 50, 2))) < rng.uniform(0.05, 0.65)
        label, _ = ndimage.label(~occupied, structure=np.ones((3, 3)))
        ys, xs = np.nonzero(~occupied)
        if len(xs) < 2:
            continue
        i, j = rng.integers(len(xs), size=2)
        start, goal = (int(xs[i]), int(ys[i])), (int(xs[j]), int(ys[j]))
        connected = bool(label[start[1], start[0]] == label[goal[1], goal[0]])
        for side in ("left", "right"):
            found = bug2_path(occupied, start, goal, BugParams(side=side))
            assert found.status is (GridBug2Status.REACHED if connected else GridBug2Status.BLOCKED)
            check_moves(occupied, found.cells)
            counted[connected] += 1
    assert min(counted.values()) > 40


# --- the kernels against plain-numpy references ---------------------------------------------------
def test_potential_gradient_is_the_potential_s_gradient() -> None:
    rng = np.random.default_rng(3)
    world = random_field(1)
    cw = world.compile(RADIUS)
    for obstacle in ("gaussian", "inverse"):
        p = dataclasses.replace(TeamParams().navigator_sections["potential_field"], obstacle=obstacle)
        cfg = potential_config(p, RADIUS)
        checked = 0
        for _ in range(300):
            x, y = rng.uniform(-2.8, 2.8), rng.uniform(-1.8, 1.8)
            if cw.clearance(x, y) < 0.02:
                continue
            _, ex, ey = PK.potential(cw.obs, cw.inner, x, y, 2.0, 0.5, 0.0, 0.0, cfg)
            h = 1e-6
            fx = (PK.potential(cw.obs, cw.inner, x + h, y, 2.0, 0.5, 0.0, 0.0, cfg)[0]
                  - PK.potential(cw.obs, cw.inner, x - h, y, 2.0, 0.5, 0.0, 0.0, cfg)[0]) / (2 * h)
            fy = (PK.potential(cw.obs, cw.inner, x, y + h, 2.0, 0.5, 0.0, 0.0, cfg)[0]
                  - PK.potential(cw.obs, cw.inner, x, y - h, 2.0, 0.5, 0.0, 0.0, cfg)[0]) / (2 * h)
            if abs(fx - ex) + abs(fy - ey) > 1e-4 * (1.0 + abs(ex) + abs(ey)):
                # a kink: where the nearest part of a box switches, or a source's influence ends
                continue
            checked += 1
        assert checked > 250


def test_grid_bug2_kernel_agrees_with_the_reference() -> None:
    rng = np.random.default_rng(7)
    statuses = set()
    for _ in range(200):
        occupied = rng.random(tuple(rng.integers(3, 40, 2))) < rng.uniform(0.0, 0.5)
        h, w = occupied.shape
        start = (int(rng.integers(-1, w + 1)), int(rng.integers(h)))  # now and then off the grid
        goal = (int(rng.integers(w)), int(rng.integers(h)))
        max_steps = int(rng.choice([5, 40, 100_000]))
        for turn in (1, -1):
            status, cells = BK.bug2_grid(occupied, *start, *goal, turn, max_steps)
            name, ref = R.bug2_grid(occupied, start, goal, turn, max_steps)
            assert GridBug2Status(int(status)).name.lower() == name
            assert [tuple(c) for c in cells.tolist()] == ref
            statuses.add(name)
    assert statuses == {"reached", "blocked", "out_of_steps", "invalid_start", "invalid_goal"}


def test_march_agrees_with_dense_sampling() -> None:
    rng = np.random.default_rng(5)
    world = random_field(2)
    cw = world.compile(RADIUS)
    for _ in range(100):
        x, y = rng.uniform(-2.8, 2.8), rng.uniform(-1.8, 1.8)
        if cw.clearance(x, y) <= 0.05:
            continue
        th, kappa = rng.uniform(-math.pi, math.pi), rng.choice([0.0, rng.uniform(-3.0, 3.0)])
        s = RK.march(cw.obs, cw.inner, x, y, th, kappa, 2.0, 0.02, 1e-4)
        ts = np.linspace(0.0, 2.0, 4001)
        if kappa == 0.0:
            px, py = x + ts * math.cos(th), y + ts * math.sin(th)
        else:
            px = x + (np.sin(th + kappa * ts) - math.sin(th)) / kappa
            py = y - (np.cos(th + kappa * ts) - math.cos(th)) / kappa
        c = np.array([cw.clearance(a, b) for a, b in zip(px, py, strict=True)]) - 0.02
        first = ts[np.argmax(c <= 0.0)] if np.any(c <= 0.0) else 2.0
        assert abs(s - first) < 2e-3


def test_escape_and_evade_vectors_agree_with_the_seed_s_formulas() -> None:
    p = TeamParams().navigator_sections["escape_evade"]
    cfg = evade_config(p)
    rng = np.random.default_rng(7)
    for _ in range(200):
        objs = np.zeros((3, 7))
        objs[:, :2] = rng.uniform(-1.0, 1.0, (3, 2))
        objs[:, 2:4] = rng.uniform(-2.0, 2.0, (3, 2))
        objs[:, 6] = rng.uniform(0.0, 0.5, 3)  # V_Y, straight paths (omega 0)
        px, py = rng.uniform(-1.0, 1.0, 2)
        # escape (5.2)-(5.4)
        s = np.zeros(2)
        for o in objs:
            d = np.hypot(px - o[0], py - o[1])
            v = np.hypot(o[2], o[3])
            if d < p.r_max_m and v >= p.min_speed_m_s:
                s += (np.array([px, py]) - o[:2]) / d * (p.r_max_m - d) / p.r_max_m * min(v / p.v_max_m_s, 1.0)
        s = s / max(1.0, np.linalg.norm(s))
        assert np.allclose(EK.escape_vector(px, py, objs, cfg), s, atol=1e-12)
        # evade (5.8)-(5.15)
        s = np.zeros(2)
        for o in objs:
            v = np.hypot(o[2], o[3])
            u = o[2:4] / v
            r = np.array([px, py]) - o[:2]
            dx, cross = float(r @ u), float(u[0] * r[1] - u[1] * r[0])
            if dx < 0.0 or v < p.min_speed_m_s:
                continue
            dmy = p.dy_max_m * (o[6] + 1.0) * (o[6] * dx + 1.0)
            f = (1.0 - min(dx, p.dx_max_m) / p.dx_max_m) * (1.0 - min(abs(cross), dmy) / dmy)
            normal = np.array([-u[1], u[0]]) * (1.0 if cross >= 0.0 else -1.0)
            s += normal * f * min(v / p.v_max_m_s, 1.0)
        s = s / max(1.0, np.linalg.norm(s))
        assert np.allclose(EK.evade_vector(px, py, objs, cfg), s, atol=1e-12)


def test_the_movement_model_finds_a_curve_and_a_jittery_track_s_variance() -> None:
    p = TeamParams().navigator_sections["escape_evade"]
    rng = np.random.default_rng(11)
    smooth, jitter = MovementModel(p, DT), MovementModel(p, DT)
    omega, speed = 1.0, 1.5
    for k in range(300):
        t = k * DT
        pos = np.array([[speed / omega * math.sin(omega * t), speed / omega * (1 - math.cos(omega * t))]])
        vel = np.array([[speed * math.cos(omega * t), speed * math.sin(omega * t)]])
        a = smooth.update(pos, vel)
        b = jitter.update(pos + rng.normal(0.0, 0.01, (1, 2)), vel)
    assert abs(a[0, 4] - omega) < 0.01  # the turn rate, rad/s
    assert a[0, 6] < 0.01 < b[0, 6]  # the noisy track's cross-track variance is the larger


def test_polar_histogram_counts_the_cells_inside_discs_and_boxes() -> None:
    # the primary histogram against a plain-numpy one over the same cells: a cell is occupied when its
    # centre lies in a disc or a box (a box's inside counts as much as a disc's)
    discs, boxes = np.array([(0.5, 0.4, 0.2)]), np.array([(-0.9, -0.5, -0.5, 0.3), (0.2, -0.8, 0.9, -0.6)])
    cw = CollisionWorld(BOUNDS, discs, boxes=boxes).compile(0.0)
    px, py = 0.013, -0.021
    for enlarge in (0.0, 0.14):
        cfg = VK.HistogramConfig(1.0, 0.05, 72, enlarge)
        ks = np.arange(-20, 21)
        cx, cy = (px + ks * 0.05)[None, :], (py + ks * 0.05)[:, None]
        cx, cy = np.broadcast_to(cx, (41, 41)).ravel(), np.broadcast_to(cy, (41, 41)).ravel()
        d = np.hypot(cx - px, cy - py)
        inside = np.hypot(cx - 0.5, cy - 0.4) < 0.2
        for x0, y0, x1, y1 in boxes:
            inside |= (cx > x0) & (cx < x1) & (cy > y0) & (cy < y1)
        keep = inside & (d <= 1.0) & (d > 0.0)
        ref = np.zeros(72)
        for x, y, r in zip(cx[keep], cy[keep], d[keep], strict=True):
            beta = math.atan2(y - py, x - px)
            gam = math.asin(min(1.0, enlarge / r)) if enlarge > 0.0 else 0.0
            for s in range(int(math.floor((beta - gam + math.pi) / (2 * math.pi / 72))),
                           int(math.floor((beta + gam + math.pi) / (2 * math.pi / 72))) + 1):
                ref[s % 72] += 1.0 - r / 1.0
        assert np.allclose(VK.polar_histogram(cw.obs, cw.inner, px, py, cfg), ref, atol=1e-9)
        assert ref[int((math.pi + math.pi) / (2 * math.pi / 72)) % 72] > 1.0  # the box at -x is in it
