"""``cmdragons bench navigation [--figures DIR]``: every planner of ``PLANNERS`` and every navigator of
``NAVIGATORS`` on one seeded scene suite, beside the implementations users know.

The scenes (Division B field, its defense areas and goal walls, our robot crossing it):

* ``static_<k>``: 14 robots standing about the field, start and goal near the two goal lines, the
  straight line between them blocked;
* ``moving_<k>``: the same kind of scene with the robots driving about (up to 1 m/s, bouncing off
  the field lines, :class:`~cmdragons.planning.scenes.MovingScene`);
* ``u_trap``: a U of walls open toward the start with the goal behind its bottom, where potential
  fields and bug methods are known to struggle.

What is measured:

* ``planner/<name>``: each planner once on every static scene and the trap (its state reset, the
  configured work budget, a generous deadline), and replanning every frame on every moving scene (its
  state kept, as in a match). ``success_rate``: a collision-free path (the exact swept-disc check) to
  the goal; ``trap``: 1 when it solved the trap; ``length_ratio``: the path's length over the
  visibility graph's (the optimum), median over the solved queries; ``plan_ms``: median time per
  plan; ``clearance_m``: median over the solved queries of the path's least clearance (robot
  disc to the nearest obstacle, sampled every centimetre).
* ``navigator/<name>``: each navigator drives an ideal holonomic robot (it goes exactly at the
  commanded velocity, which every navigator keeps within the robot's limits) from the start toward
  the goal, its plan the straight line to the goal each frame (the local problem: no global
  planner helps it), at the control rate, until it is within ``ARRIVED_M`` of the goal, touches an
  obstacle or the time runs out. ``success_rate``: arrived without a contact; ``length_ratio``:
  the driven length over the visibility graph's (at the start); ``step_ms``: median time per
  ``command``; ``clearance_m``: median of each run's least clearance; ``time_s``: median time to
  the goal of the runs that arrive.
* ``search/<planner>/<search>``: each road map and cell decomposition with each graph search on the
  static scenes: length ratio, nodes expanded, time per plan.
* ``peer/<name>``: on the same scenes, the Robotics Toolbox's (``roboticstoolbox-python``)
  DistanceTransformPlanner, DstarPlanner and PRMPlanner beside our nf1, estar and prm, its Bug2
  beside our ``bug2`` navigator when one is registered, and pyvisgraph beside our visibility
  graph, each with its success rate and time and ours, and ``speedup`` (the peer's time over ours).
  The ``bug2`` row times our navigator's whole drive at the control rate against the toolbox's walk
  of the grid; ``peer/rtb_Bug2_path`` compares like with like: our Bug2 as a whole path in one
  query on the same occupancy grid (:func:`~cmdragons.navigation.bug2_path`, one cell a step, as
  the toolbox's), the two called in turn on each scene, with both paths' length and clearance.
  The grid peers get the scene as an occupancy grid of ``GRID_M`` cells (occupied where the robot's
  centre would touch an obstacle); their success is their own (a path returned). pyvisgraph gets
  the same polygons around the obstacles as the trapezoidal decomposition.
* ``grid_astar/<map>``: A* on a uniform grid, ours (:mod:`cmdragons.planning.graphsearch` over the
  8-connected grid graph) against ``pyastar2d`` (C++), the same grid and query, on a static scene's
  occupancy grid and on the longest scenario of a 512 x 512 Moving AI map; the graph build and the
  search timed apart.

Figures: ``<scene>.png`` for ``static_0``, ``moving_0`` and ``u_trap`` in ``--figures DIR`` (default
``logs/bench-navigation``): one panel per method with its path or driven trajectory.

``--quick``: 2 static and 2 moving scenes, 10 frames of replanning, one repetition, the
navigators on the three scenes of the figures with a 6 s limit per drive, the peers on the first
static scene only; the full suite: 8 and 6 scenes, 60 frames,
25 s, 3 repetitions, the peers on every static scene and the trap. Peers that are not installed
give a row saying so.
"""

from __future__ import annotations

import dataclasses
import functools
import gc
import math
import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import shapely
from numpy.typing import NDArray

from cmdragons.geometry import Field
from cmdragons.messages import RobotState
from cmdragons.navigation import NAVIGATORS, Arrival, GridBug2Status, bug2_path, make_navigator
from cmdragons.planning import (
    PLANNERS,
    CollisionWorld,
    PlannerParams,
    PlanProblem,
    PlanResult,
    budget,
    deadline,
    field_world,
    make_planner,
    path_length,
)
from cmdragons.planning.cells import grid_graph
from cmdragons.planning.cspace import obstacle_polygons
from cmdragons.planning.graphsearch import SEARCHES, SearchStatus, grid_search, search
from cmdragons.planning.roadmap import GraphSearchParams
from cmdragons.planning.scenes import MovingScene, Scene
from cmdragons.planning.termination import never
from cmdragons.runtime.settings import Settings

__all__ = ["NavScene", "drive", "run", "scenes", "u_trap"]

FloatArray = NDArray[np.float64]
Row = dict[str, Any]

N_ROBOTS = 14  # robots standing or driving about in the static and moving scenes
SPEED_M_S = 1.0  # the moving robots' top speed
START_X_M = 3.2  # start and goal this far from the centre line, on either side
MIN_CLEARANCE_M = 0.15  # start and goal at least this clear of everything
ARRIVED_M = 0.1  # a navigator this close to the goal has arrived
PLAN_DEADLINE_S = 2.0  # generous: the work budgets bound the planners
STEP_DEADLINE_S = 0.5  # a navigator's deadline per step (its work budget binds first)
GRID_M = 0.05  # the occupancy grid of the grid peers
FIGURES = ("static_0", "moving_0", "u_trap")
TOOLBOX_PLANNERS = {"nf1": "DistanceTransformPlanner", "estar": "DstarPlanner", "prm": "PRMPlanner"}
TOOLBOX_NAVIGATORS = {"bug2": "Bug2"}
MISSING = "not installed (pip install -e '.[bench]')"
DEFAULT_FIGURES = Path("logs") / "bench-navigation"


@dataclasses.dataclass
class NavScene:
    """One scene: its world at the start, our robot's start and goal, and for a moving scene the
    robots' motion (``mover``: stepped forward frame by frame)."""

    name: str
    world: CollisionWorld
    start: tuple[float, float]
    goal: tuple[float, float]
    field: Field
    mover: MovingScene | None = None
    seed: int = 0  # of the mover's random turns

    def fresh(self) -> NavScene:
        """The scene at its start, with a mover of its own (each method sees the same robots move)."""
        if self.mover is None:
            return self
        m = self.mover
        mover = MovingScene(m.field, Scene(m.pos, m.vel, self.start, self.goal), np.random.default_rng(self.seed),
                            m.max_speed, m.p_turn)
        return dataclasses.replace(self, mover=mover)

    def step(self, dt_s: float) -> None:
        if self.mover is not None:
            self.mover.step(dt_s)
            self.world = field_world(self.field, self.mover.pos, self.mover.vel)


def _crossing(field: Field, rng: np.random.Generator, radius_m: float, moving: bool) -> tuple[
        CollisionWorld, FloatArray, FloatArray, tuple[float, float], tuple[float, float]]:
    """Robots about the field and a start and goal on either side whose straight line they block."""
    r = field.league.robot.radius_m
    while True:
        pos = rng.uniform((-2.8, -field.half_width + r), (2.8, field.half_width - r), (N_ROBOTS, 2))
        heading = rng.uniform(-math.pi, math.pi, N_ROBOTS)
        speed = rng.uniform(0.2, SPEED_M_S, N_ROBOTS) if moving else np.zeros(N_ROBOTS)
        vel = np.column_stack([speed * np.cos(heading), speed * np.sin(heading)])
        world = field_world(field, pos, vel)
        start = (-START_X_M, float(rng.uniform(-2.5, 2.5)))
        goal = (START_X_M, float(rng.uniform(-2.5, 2.5)))
        cw = world.compile(radius_m)
        clear = min(cw.clearance(*start), cw.clearance(*goal))
        if clear >= MIN_CLEARANCE_M and not cw.segment_free(start, goal):
            return world, pos, vel, start, goal


def u_trap(field: Field) -> NavScene:
    """The U of walls (0.1 m thick, 1.6 m wide inside, 1.1 m deep) open toward the start, the goal
    behind its bottom: the straight line runs into the U."""
    base = field_world(field)
    walls = np.array([[-0.6, 0.8, 0.5, 0.9], [-0.6, -0.9, 0.5, -0.8], [0.4, -0.8, 0.5, 0.8]])
    world = CollisionWorld(base.bounds, boxes=np.vstack([base.boxes, walls]))
    return NavScene("u_trap", world, (-2.0, 0.0), (2.0, 0.0), field)


def scenes(field: Field, radius_m: float, n_static: int, n_moving: int, seed: int = 18) -> list[NavScene]:
    """The seeded suite: static scenes, moving scenes, the U trap."""
    rng = np.random.default_rng(seed)
    out = []
    for k in range(n_static):
        world, _, _, start, goal = _crossing(field, rng, radius_m, False)
        out.append(NavScene(f"static_{k}", world, start, goal, field))
    for k in range(n_moving):
        world, pos, vel, start, goal = _crossing(field, rng, radius_m, True)
        mover = MovingScene(field, Scene(pos, vel, start, goal), np.random.default_rng(0), SPEED_M_S)
        out.append(NavScene(f"moving_{k}", world, start, goal, field, mover, seed * 1000 + k))
    return out + [u_trap(field)]


def min_clearance(problem: PlanProblem, path: FloatArray, step_m: float = 0.01) -> float:
    """The least clearance (m) of the robot's disc along ``path``, sampled every ``step_m``."""
    pts = [path[:1]]
    for a, b in zip(path[:-1], path[1:], strict=True):
        k = max(1, math.ceil(float(np.hypot(*(b - a))) / step_m))
        pts.append(a + (b - a) * (np.arange(1, k + 1)[:, None] / k))
    clearance, _ = problem.compiled().clearance_gradients(np.vstack(pts))
    return float(clearance.min())


def _ok(problem: PlanProblem, result: PlanResult) -> bool:
    """A path to the goal (or its stand-in) that the exact check passes (after any escape)."""
    if not result.status.reached:
        return False
    first = 1 if result.stats.get("escaped_start") else 0
    return bool(problem.compiled().path_free(result.path[first:]))


@dataclasses.dataclass
class Tally:
    """What one method did over the suite."""

    ok: list[bool] = dataclasses.field(default_factory=list)
    ratio: list[float] = dataclasses.field(default_factory=list)
    ms: list[float] = dataclasses.field(default_factory=list)
    clearance: list[float] = dataclasses.field(default_factory=list)
    trap: bool = False
    extra: dict[str, list[float]] = dataclasses.field(default_factory=dict)

    def row(self, name: str, time_key: str) -> Row:
        return {"name": name, "queries": len(self.ok), "success_rate": float(np.mean(self.ok)) if self.ok else 0.0,
                "trap": int(self.trap), "length_ratio": _median(self.ratio), time_key: _median(self.ms),
                "clearance_m": _median(self.clearance)}


def _median(values: list[float]) -> float:
    return float(statistics.median(values)) if values else math.nan


def _plan(params: PlannerParams, name: str, planner: Any, problem: PlanProblem) -> tuple[PlanResult, float]:
    work = getattr(params, name).work_budget
    t0 = time.perf_counter()
    result = planner.solve(problem, deadline(PLAN_DEADLINE_S) | budget(work))
    return result, (time.perf_counter() - t0) * 1e3


def _problem(scene: NavScene, radius_m: float, settings: Settings) -> PlanProblem:
    return PlanProblem(scene.start, scene.goal, radius_m, scene.world, 0.0, settings.planner.collision)


Record = dict[tuple[str, str], tuple[bool, float]]  # (method, scene) -> (solved, ms) on the fixed scenes


def _planner_rows(settings: Settings, suite: list[NavScene], frames: int, repeats: int,
                  paths: dict[str, dict[str, FloatArray]],
                  say: Callable[[str], None]) -> tuple[list[Row], dict[str, list[float]], Record]:
    """Every planner on every scene; the visibility graph first (its cost is the optimum). Returns
    the rows (``planner/<name>`` on the static scenes and the trap, ``replan/<name>`` every frame of
    the moving scenes), the optimum per query (scene name -> one cost per query) and what each
    planner did on each fixed scene."""
    params = settings.planner
    radius = settings.field.robot.radius_m
    dt = 1.0 / settings.control.motion.frame_rate_hz
    names = ["visgraph"] + sorted(n for n in PLANNERS if n != "visgraph")
    optimum: dict[str, list[float]] = {}
    record: Record = {}
    fixed_rows, moving_rows = [], []
    for name in names:
        say(f"planner {name}")
        planner = make_planner(params, 0, name)
        fixed, moving = Tally(), Tally()
        # compiles outside the timing, every kernel on the way (no clock: a first run's compile is slow)
        planner.solve(_problem(suite[0], radius, settings), budget(getattr(params, name).work_budget))
        for scene in suite:
            scene = scene.fresh()
            best = optimum.setdefault(scene.name, [])
            tally = moving if scene.mover is not None else fixed
            for q in range(frames if scene.mover is not None else 1):
                problem = _problem(scene, radius, settings)
                times = []
                for _ in range(repeats if scene.mover is None else 1):
                    if scene.mover is None:
                        planner.reset()  # a plan from scratch (the moving scenes replan as in a match)
                    result, ms = _plan(params, name, planner, problem)
                    times.append(ms)
                ok = _ok(problem, result)
                if name == "visgraph":
                    best.append(result.cost if ok else math.nan)
                tally.ok.append(ok)
                tally.ms.append(statistics.median(times))
                if scene.mover is None:
                    record[name, scene.name] = (ok, tally.ms[-1])
                if ok:
                    tally.ratio += [result.cost / best[q]] if math.isfinite(best[q]) else []
                    tally.clearance.append(min_clearance(problem, result.path))
                    tally.trap |= scene.name == "u_trap"
                if q == 0 and scene.name in FIGURES:
                    paths.setdefault(scene.name, {})[f"planner {name}"] = result.path if ok else result.path[:1]
                scene.step(dt)
        fixed_rows.append(fixed.row(f"planner/{name}", "plan_ms"))
        row = moving.row(f"replan/{name}", "plan_ms")
        del row["trap"]
        moving_rows.append(row)
    return fixed_rows + moving_rows, optimum, record


def drive(settings: Settings, name: str, scene: NavScene, timeout_s: float) -> tuple[bool, FloatArray, list[float],
                                                                                     float, float]:
    """Navigator ``name`` drives an ideal robot from the scene's start toward its goal (see the module
    docstring). Returns (arrived without contact, the trajectory (k, 2), ms per step, least
    clearance m, time to the goal s or nan)."""
    radius = settings.field.robot.radius_m
    nav = make_navigator(name, settings.team.navigator_sections, settings.control, radius, settings.planner.collision)
    dt = 1.0 / settings.control.motion.frame_rate_hz
    scene = scene.fresh()
    x, y, theta, vx, vy, omega = scene.start[0], scene.start[1], 0.0, 0.0, 0.0, 0.0
    trace = [(x, y)]
    times: list[float] = []
    least = math.inf
    goal = scene.goal
    for k in range(round(timeout_s / dt)):
        cw = scene.world.compile(radius, 0.0, 0.0, settings.planner.collision)
        c = cw.clearance(x, y)
        least = min(least, c)
        if c < 0.0:
            return False, np.array(trace), times, least, math.nan
        if math.hypot(goal[0] - x, goal[1] - y) < ARRIVED_M:
            return True, np.array(trace), times, least, k * dt
        nav.set_plan(np.array([(x, y), goal]), Arrival(0.0))
        robot = RobotState("blue", 0, x, y, theta, vx, vy, omega)
        t0 = time.perf_counter()
        vx, vy, omega = nav.command(robot, scene.world, deadline(STEP_DEADLINE_S))
        times.append((time.perf_counter() - t0) * 1e3)
        nav.sent(vx, vy)
        x, y, theta = x + vx * dt, y + vy * dt, theta + omega * dt
        trace.append((x, y))
        scene.step(dt)
    return False, np.array(trace), times, least, math.nan


def _navigator_rows(settings: Settings, suite: list[NavScene], optimum: dict[str, list[float]], timeout_s: float,
                    paths: dict[str, dict[str, FloatArray]], say: Callable[[str], None]) -> list[Row]:
    rows = []
    for name in sorted(NAVIGATORS):
        say(f"navigator {name}")
        tally = Tally(extra={"time_s": []})
        drive(settings, name, suite[-1], 0.1)  # compiles outside the timing
        for scene in suite:
            ok, trace, times, least, arrived = drive(settings, name, scene, timeout_s)
            tally.ok.append(ok)
            tally.ms += times
            tally.clearance.append(least)
            best = optimum[scene.name][0]
            if ok:
                tally.ratio += [path_length(trace) / best] if math.isfinite(best) else []
                tally.extra["time_s"].append(arrived)
                tally.trap |= scene.name == "u_trap"
            if scene.name in FIGURES:
                paths.setdefault(scene.name, {})[f"navigator {name}"] = trace
        rows.append(tally.row(f"navigator/{name}", "step_ms") | {"time_s": _median(tally.extra["time_s"])})
    return rows


def _search_rows(settings: Settings, suite: list[NavScene], optimum: dict[str, list[float]]) -> list[Row]:
    """Each road map and cell decomposition (the planners searched by a graph search of their
    choice) with each graph search, on the static scenes."""
    radius = settings.field.robot.radius_m
    rows = []
    static = [s for s in suite if s.mover is None and s.name != "u_trap"]
    for name in (n for n in sorted(PLANNERS) if isinstance(getattr(settings.planner, n), GraphSearchParams)):
        for method in SEARCHES:
            section = dataclasses.replace(getattr(settings.planner, name), search=method)
            params = dataclasses.replace(settings.planner, **{name: section})
            planner = make_planner(params, 0, name)
            ratio, expanded, ms = [], [], []
            for scene in static:
                problem = _problem(scene, radius, settings)
                result, t = _plan(params, name, planner, problem)
                ms.append(t)
                if _ok(problem, result):
                    ratio.append(result.cost / optimum[scene.name][0])
                    expanded.append(float(result.stats.get("expanded", 0)))
            rows.append({"name": f"search/{name}/{method}", "solved": len(ratio), "length_ratio": _median(ratio),
                         "expanded": _median(expanded), "plan_ms": _median(ms)})
    return rows


# --- peers ------------------------------------------------------------------------------------------
def occupancy(scene: NavScene, radius_m: float) -> tuple[NDArray[np.bool_], float, float]:
    """The scene's occupancy grid of ``GRID_M`` cells (True: the robot's centre there touches an
    obstacle), row = y, and its origin (x0, y0)."""
    grid = scene.world.compile(radius_m).clearance_grid(GRID_M, cap_m=GRID_M)
    return grid.values < 0.0, grid.x0, grid.y0


def _cell(p: tuple[float, float], x0: float, y0: float) -> tuple[int, int]:
    return int((p[0] - x0) / GRID_M), int((p[1] - y0) / GRID_M)  # (column, row)


def _to_field(cells: FloatArray, x0: float, y0: float) -> FloatArray:
    return np.column_stack([x0 + (cells[:, 0] + 0.5) * GRID_M, y0 + (cells[:, 1] + 0.5) * GRID_M])


def _toolbox_planner(cls: str, occ: NDArray[np.bool_], start: tuple[int, int], goal: tuple[int, int],
                     n_nodes: int) -> FloatArray | None:
    """The toolbox planner's path (cells (k, 2) as x, y) or None when it found none."""
    import roboticstoolbox as rtb

    grid = occ.astype(int)
    try:
        if cls == "PRMPlanner":
            prm = rtb.PRMPlanner(occgrid=grid, npoints=n_nodes, seed=0)
            prm.plan()
            return np.asarray(prm.query(start=start, goal=goal), dtype=np.float64)
        if cls == "Bug2":
            return np.asarray(rtb.Bug2(occgrid=grid).run(start=start, goal=goal, animate=False), dtype=np.float64)
        planner = getattr(rtb, cls)(occgrid=grid)  # (D*'s first argument is a cost map, not this)
        planner.plan(goal=goal)
        out = planner.query(start=start)
        path = out[0] if isinstance(out, tuple) else out
        return np.asarray(path, dtype=np.float64)
    except Exception:  # the toolbox says "no path" by raising (NoPathError and others)
        return None


def _ours(record: Record, name: str, fixed: list[NavScene]) -> dict[str, float]:
    """Our planner ``name``'s success rate and median ms on the scenes ``fixed``."""
    done = [record[name, s.name] for s in fixed]
    return {"success_rate": float(np.mean([ok for ok, _ in done])), "plan_ms": _median([ms for _, ms in done])}


def _peer_rows(settings: Settings, suite: list[NavScene], optimum: dict[str, list[float]], record: Record,
               timeout_s: float, quick: bool, paths: dict[str, dict[str, FloatArray]]) -> list[Row]:
    radius = settings.field.robot.radius_m
    rows: list[Row] = []
    fixed = [s for s in suite if s.mover is None]  # the peers plan once: the static scenes and the trap
    if quick:
        fixed = fixed[:1]
    try:
        import roboticstoolbox  # noqa: F401

        toolbox = True
    except ImportError:
        toolbox = False
    for our, cls in [*TOOLBOX_PLANNERS.items(), *TOOLBOX_NAVIGATORS.items()]:
        name = f"peer/rtb_{cls}"
        is_nav = our in TOOLBOX_NAVIGATORS
        if not toolbox:
            rows.append({"name": name, "note": MISSING})
            continue
        if is_nav and our not in NAVIGATORS:
            rows.append({"name": name, "note": f"no {our!r} navigator registered to compare with"})
            continue
        tally, our_tally = Tally(), Tally()
        for scene in fixed:
            occ, x0, y0 = occupancy(scene, radius)
            t0 = time.perf_counter()
            cells = _toolbox_planner(cls, occ, _cell(scene.start, x0, y0), _cell(scene.goal, x0, y0),
                                     settings.planner.prm.n_nodes)
            tally.ms.append((time.perf_counter() - t0) * 1e3)
            ok = cells is not None and len(cells) > 1
            tally.ok.append(ok)
            if ok and cells is not None:
                path = np.vstack([[scene.start], _to_field(cells, x0, y0), [scene.goal]])
                tally.ratio.append(path_length(path) / optimum[scene.name][0])
                tally.clearance.append(min_clearance(_problem(scene, radius, settings), path))
                tally.trap |= scene.name == "u_trap"
                if scene.name in FIGURES:
                    paths.setdefault(scene.name, {})[f"peer rtb {cls}"] = path
            if is_nav:  # our navigator's whole drive, timed the same way
                t0 = time.perf_counter()
                arrived, *_ = drive(settings, our, scene, timeout_s)
                our_tally.ms.append((time.perf_counter() - t0) * 1e3)
                our_tally.ok.append(arrived)
        row = tally.row(name, "plan_ms")
        if is_nav:
            mine = {"success_rate": float(np.mean(our_tally.ok)), "plan_ms": _median(our_tally.ms)}
        else:
            mine = _ours(record, our, fixed)
        rows.append(row | {"our_success_rate": mine["success_rate"], "our_ms": mine["plan_ms"],
                           "speedup": row["plan_ms"] / mine["plan_ms"], "ours": our})
    if toolbox:
        rows.append(_bug2_path_row(settings, fixed, optimum, 3 if quick else 5, paths))
    rows.append(_pyvisgraph_row(settings, fixed, optimum, _ours(record, "visgraph", fixed), paths))
    return rows


def _bug2_path_row(settings: Settings, fixed: list[NavScene], optimum: dict[str, list[float]], repeats: int,
                   paths: dict[str, dict[str, FloatArray]]) -> Row:
    """Bug2 as a whole path in one query, ours (:func:`~cmdragons.navigation.bug2_path`) beside the
    toolbox's ``Bug2``, on the same occupancy grid with the same start and goal cells, both stepping
    one cell; the two called in turn ``repeats`` times per scene (median). Success: the path ends
    at the goal (the toolbox's: a path returned)."""
    radius = settings.field.robot.radius_m
    theirs, ours = Tally(), Tally()
    first = fixed[0]
    occ, x0, y0 = occupancy(first, radius)
    bug = settings.team.navigator_sections["bug"]
    bug2_path(occ, _cell(first.start, x0, y0), _cell(first.goal, x0, y0), bug)  # loads the kernel
    for scene in fixed:
        occ, x0, y0 = occupancy(scene, radius)
        start, goal = _cell(scene.start, x0, y0), _cell(scene.goal, x0, y0)
        problem = _problem(scene, radius, settings)
        our_query = functools.partial(bug2_path, occ, start, goal, bug)
        their_query = functools.partial(_toolbox_planner, "Bug2", occ, start, goal, 0)
        ours_ms, theirs_ms = _paired_ms([our_query, their_query], repeats)
        found, cells = our_query(), their_query()
        for tally, ms, ok, route, label in (
                (ours, ours_ms, found.status is GridBug2Status.REACHED, found.cells, "bug2_path (grid)"),
                (theirs, theirs_ms, cells is not None and len(cells) > 1, cells, "peer rtb Bug2 (grid)")):
            tally.ms.append(ms)
            tally.ok.append(ok)
            if ok and route is not None:
                path = np.vstack([[scene.start], _to_field(np.asarray(route, dtype=np.float64), x0, y0), [scene.goal]])
                tally.ratio.append(path_length(path) / optimum[scene.name][0])
                tally.clearance.append(min_clearance(problem, path))
                tally.trap |= scene.name == "u_trap"
                if scene.name in FIGURES and label.startswith("bug2"):
                    paths.setdefault(scene.name, {})[label] = path
    row = theirs.row("peer/rtb_Bug2_path", "plan_ms")
    mine = ours.row("", "plan_ms")
    return row | {"our_success_rate": mine["success_rate"], "our_ms": mine["plan_ms"],
                  "speedup": row["plan_ms"] / mine["plan_ms"], "ours": "bug2_path",
                  "our_trap": mine["trap"], "our_length_ratio": mine["length_ratio"],
                  "our_clearance_m": mine["clearance_m"]}


def _pyvisgraph_row(settings: Settings, fixed: list[NavScene], optimum: dict[str, list[float]], our: dict[str, float],
                    paths: dict[str, dict[str, FloatArray]]) -> Row:
    name = "peer/pyvisgraph"
    try:
        import pyvisgraph as vg
    except ImportError:
        return {"name": name, "note": MISSING}
    radius = settings.field.robot.radius_m
    tally = Tally()
    quad_segs = settings.planner.trapezoidal.quad_segs
    for scene in fixed:
        cw = scene.world.compile(radius)
        # pyvisgraph wants disjoint simple polygons: the union of ours, clipped to the field's inside
        union = shapely.unary_union(obstacle_polygons(cw, quad_segs)).intersection(shapely.box(*cw.inner))
        parts = [g for g in getattr(union, "geoms", [union]) if isinstance(g, shapely.Polygon) and not g.is_empty]
        polys = [[vg.Point(float(x), float(y)) for x, y in np.asarray(p.exterior.coords)[:-1]] for p in parts]
        t0 = time.perf_counter()
        graph = vg.VisGraph()
        graph.build(polys, workers=1, status=False)
        route = graph.shortest_path(vg.Point(*scene.start), vg.Point(*scene.goal))
        tally.ms.append((time.perf_counter() - t0) * 1e3)
        path = np.array([(p.x, p.y) for p in route])
        ok = len(path) >= 2 and bool(cw.path_free(path))
        tally.ok.append(ok)
        if ok:
            tally.ratio.append(path_length(path) / optimum[scene.name][0])
            tally.clearance.append(min_clearance(_problem(scene, radius, settings), path))
            tally.trap |= scene.name == "u_trap"
        if scene.name in FIGURES and len(path):
            paths.setdefault(scene.name, {})["peer pyvisgraph"] = path
    row = tally.row(name, "plan_ms")
    return row | {"our_success_rate": our["success_rate"], "our_ms": our["plan_ms"],
                  "speedup": row["plan_ms"] / our["plan_ms"], "ours": "visgraph"}


def _paired_ms(fns: list[Callable[[], Any]], repeats: int) -> list[float]:
    """Median ms of each of ``fns``, called in turn ``repeats`` times (so that a change of the
    machine's load hits them alike), the garbage collector held off while they run (as timeit
    does: a collection of the whole bench's objects would land in whichever call set it off)."""
    times: list[list[float]] = [[] for _ in fns]
    was_on = gc.isenabled()
    gc.collect()
    gc.disable()
    try:
        for _ in range(repeats):
            for fn, out in zip(fns, times, strict=True):
                t0 = time.perf_counter()
                fn()
                out.append((time.perf_counter() - t0) * 1e3)
    finally:
        if was_on:
            gc.enable()
    return [float(statistics.median(t)) for t in times]


def grid_astar_row(name: str, free: NDArray[np.bool_], start: tuple[int, int], goal: tuple[int, int],
                   repeats: int) -> Row:
    """Our A* on the 8-connected grid of ``free`` (row = y) against pyastar2d, ``start`` and ``goal``
    as (column, row), lengths in cells: ``search_ms`` the grid search (the graph's neighbours by
    index), ``graph_ms`` the same search over the built CSR graph and ``build_ms`` building it.
    pyastar2d's diagonal step costs 1 (ours the diagonal's length, sqrt 2): its length is in its own
    metric. Our grid graph lets a diagonal pass between two blocked cells' corners (its cells are wholly
    free), which Moving AI's optimal lengths do not."""
    s, g = (start[1], start[0]), (goal[1], goal[0])
    found = grid_search(free, s, g, "astar", never())
    graph = grid_graph(free, 0.0, 0.0, 1.0, 8)
    node = np.cumsum(free.ravel()) - 1
    src, dst = int(node[s[0] * free.shape[1] + s[1]]), int(node[g[0] * free.shape[1] + g[1]])
    try:
        import pyastar2d
    except ImportError:
        pyastar2d = None
    weights = np.where(free, 1.0, np.inf).astype(np.float32)
    # ours and the peer in turn (the same load for both), then the graph's build and search apart
    pair: list[Callable[[], Any]] = [lambda: grid_search(free, s, g, "astar", never())]
    if pyastar2d is not None:
        pair.append(lambda: pyastar2d.astar_path(weights, s, g, allow_diagonal=True))
    search_ms, *peer_ms = _paired_ms(pair, repeats)
    graph_ms, build_ms = _paired_ms([lambda: search(graph, src, dst, "astar", never()),
                                     lambda: grid_graph(free, 0.0, 0.0, 1.0, 8)], repeats)
    row: Row = {"name": f"grid_astar/{name}", "cells": int(free.size), "length": found.cost, "expanded": found.expanded,
                "search_ms": search_ms, "graph_ms": graph_ms, "build_ms": build_ms}
    if found.status is not SearchStatus.FOUND:
        row["note"] = "our A* found no path"
    if pyastar2d is None:
        return row | {"note": f"pyastar2d {MISSING}"}
    p = pyastar2d.astar_path(weights, s, g, allow_diagonal=True)
    theirs_ms = peer_ms[0]
    length = float(np.sum(np.max(np.abs(np.diff(p, axis=0)), axis=1))) if p is not None else math.nan
    return row | {"pyastar2d_length": length, "pyastar2d_ms": theirs_ms, "ratio_to_pyastar2d": search_ms / theirs_ms}


def _grid_astar_rows(settings: Settings, suite: list[NavScene], repeats: int) -> list[Row]:
    from cmdragons.bench.grid import default_maps
    from cmdragons.planning.grid import read_map, read_scenarios

    scene = suite[0]
    occ, x0, y0 = occupancy(scene, settings.field.robot.radius_m)
    rows = [grid_astar_row(f"{scene.name}_{occ.shape[1]}x{occ.shape[0]}", ~occ, _cell(scene.start, x0, y0),
                           _cell(scene.goal, x0, y0), repeats)]
    path = default_maps() / "8room_000.map"
    if path.exists() and path.with_name(path.name + ".scen").exists():
        free = read_map(path)
        longest = max(read_scenarios(path.with_name(path.name + ".scen")), key=lambda s: s.optimal)
        rows.append(grid_astar_row(f"8room_000_{free.shape[1]}x{free.shape[0]}", free, longest.start, longest.goal,
                                   repeats) | {"optimal": longest.optimal})
    return rows


# --- figures ----------------------------------------------------------------------------------------
def draw(scene: NavScene, paths: dict[str, FloatArray], out: Path, radius_m: float) -> Path:
    """One panel per method: the field inside the walls, the obstacles (robots as they stand at the
    start), the start, the goal and the method's path."""
    from matplotlib.patches import Circle, Rectangle

    from cmdragons.runtime.report import pyplot

    plt = pyplot()
    names = list(paths)
    cols = 4
    rows = max(1, math.ceil(len(names) / cols))
    fig, axes = plt.subplots(rows, cols, figsize=(4.2 * cols, 3.0 * rows), dpi=80, squeeze=False)
    x0, y0, x1, y1 = scene.world.bounds
    for ax, name in zip(axes.ravel(), [*names, *[None] * (rows * cols - len(names))], strict=True):
        ax.set_axis_off()
        if name is None:
            continue
        ax.add_patch(Rectangle((x0, y0), x1 - x0, y1 - y0, fill=False, color="0.3"))
        for bx0, by0, bx1, by1 in scene.world.boxes:
            ax.add_patch(Rectangle((bx0, by0), bx1 - bx0, by1 - by0, color="0.55"))
        for cx, cy, r in scene.world.circles:
            ax.add_patch(Circle((cx, cy), r, color="0.35"))
        p = paths[name]
        ax.plot(p[:, 0], p[:, 1], color="tab:red", lw=1.4)
        ax.plot(*scene.start, "o", color="tab:green", ms=5)
        ax.plot(*scene.goal, "*", color="tab:blue", ms=9)
        ax.set_xlim(x0, x1)
        ax.set_ylim(y0, y1)
        ax.set_aspect("equal")
        ax.set_title(name, fontsize=9)
    fig.suptitle(f"cmdragons bench navigation: {scene.name}" + (" (robots as at the start)" if scene.mover else ""))
    fig.tight_layout()
    out.mkdir(parents=True, exist_ok=True)
    target = out / f"{scene.name}.png"
    fig.savefig(target)
    plt.close(fig)
    return target


def _progress() -> Callable[[str], None]:
    """A line on stderr as each part starts, with the seconds the suite has run."""
    t0 = time.perf_counter()

    def say(what: str) -> None:
        print(f"bench navigation: {time.perf_counter() - t0:5.1f} s  {what}", file=sys.stderr, flush=True)

    return say


def run(settings: Settings, quick: bool, figures: Path | None = None) -> list[Row]:
    say = _progress()
    radius = settings.field.robot.radius_m
    field = settings.field_geometry()
    suite = scenes(field, radius, 2 if quick else 8, 2 if quick else 6)
    frames, repeats, timeout_s = (10, 1, 6.0) if quick else (60, 3, 25.0)
    paths: dict[str, dict[str, FloatArray]] = {}
    rows, optimum, record = _planner_rows(settings, suite, frames, repeats, paths, say)
    drives = [s for s in suite if s.name in FIGURES] if quick else suite
    rows += _navigator_rows(settings, drives, optimum, timeout_s, paths, say)
    say("graph searches")
    rows += _search_rows(settings, suite, optimum)
    say("peers")
    rows += _peer_rows(settings, suite, optimum, record, timeout_s, quick, paths)
    say("grid A*")
    rows += _grid_astar_rows(settings, suite, 5 if quick else 21)
    folder = Path(figures) if figures is not None else DEFAULT_FIGURES
    written = [draw(s, paths[s.name], folder, radius) for s in suite if s.name in FIGURES and s.name in paths]
    rows.append({"name": "figures", "note": ", ".join(str(p) for p in written)})
    say("done")
    return [{k: (float(v) if isinstance(v, np.floating) else v) for k, v in r.items()} for r in rows]
