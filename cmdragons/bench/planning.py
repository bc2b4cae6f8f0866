"""``cmdragons bench planning``: motion planning on a fixed, seeded suite of small-size scenes.

* ``collision_<broad phase>_<n>``: one swept-circle segment query among n obstacles (robots plus
  the field's defense areas and goal walls), for the broad phases of Bruce 2006 §3.2, timed inside
  numba so that Python's call overhead does not hide the difference; and each world's build time.
* ``nearest_<kind>_<n>``: one nearest-neighbour query in a tree of n nodes (brute force vs KD-tree).
* ``static_<planner>``: every planner on the same static scenes (Division B field, defense areas
  and goal walls as obstacles, 1-21 robots, random free start and goal). ``success_rate`` counts a
  valid path to the goal on the scenes the visibility graph proves solvable; ``length_ratio`` is
  the mean path length over the visibility graph's exact optimum; times are wall-clock per query.
* ``moving_<planner>``: the robots drive about for 300 frames at 60 Hz while our robot follows its
  plan; every planner answers the same query each frame and keeps its own state across frames.
  ERRT runs with and without its waypoint cache (plan reuse off in both, to isolate the cache),
  and in its full configuration. ``blocked_median_ms`` is the median over the frames whose straight
  line to the goal is blocked (the frames where a planner has to search).
* ``crowd_<planner>``: hard replanning (:class:`CrowdScene`): two crowds of robots, each a ring
  around a pocket with one narrow gap (free width 120, 60 or 30 mm for the robot's centre), drift
  and turn about the field while our robot shuttles between the pockets. Every frame's straight
  line is blocked and ERRT without its cache needs hundreds of iterations; ERRT with and without
  the cache (plan reuse off in both), as configured, and OMPL RRTConnect answer the same queries.
  ``median_iterations`` and ``median_nodes`` count ERRT's searching frames; ``waypoint_target_rate``
  is the share of its iterations that aimed at a cached waypoint (p_waypoint when it works).
* ``median_search_ms``: the planning time alone, without compiling the collision world: ERRT's
  search (straight line, trees, smoothing, cache) and OMPL's own solve.
* ``visgraph_exactness``: the visibility graph against closed-form shortest paths.
* OMPL's RRTConnect (with and without its simplifier) and PRM run side by side when ``ompl`` is
  installed; without it a row says so.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import time
from collections.abc import Callable, Iterable, Sequence
from typing import Any, Protocol

import numpy as np
from numpy.typing import NDArray

from cmdragons.geometry import Field
from cmdragons.planning import _errt_kernels as K
from cmdragons.planning import collision
from cmdragons.planning.problem import Planner, PlanProblem, PlanResult, PlanStatus
from cmdragons.planning.registry import PlannerParams, make_planner
from cmdragons.planning.scenes import CrowdScene, MovingScene, random_free_point, random_scene
from cmdragons.planning.termination import Termination, budget, deadline, never
from cmdragons.planning.world import BROAD_PHASES, CollisionParams, CollisionWorld, CompiledWorld, field_world
from cmdragons.runtime.settings import Settings

__all__ = ["run"]

Row = dict[str, Any]
FloatArray = NDArray[np.float64]
SEED = 20061181  # the suite is fixed: the same scenes on every machine
BENCH_BUDGET_S = 0.05  # per query: generous, so success measures the algorithm, p95 the tail
FRAME_S = 1.0 / 60.0
ROBOT_SPEED_M_S = 1.5  # how fast our robot follows its plan in the moving scenes


@dataclasses.dataclass(frozen=True)
class Sizes:
    static_scenes: int
    moving_scenes: int
    frames: int
    optimum_every: int  # frames between visibility-graph optima in the moving scenes
    collision_queries: int
    crowd_scenes: int = 6  # hard moving scenes, cycling through CROWD_GAPS_M


FULL = Sizes(static_scenes=500, moving_scenes=10, frames=300, optimum_every=10, collision_queries=20000)
QUICK = Sizes(static_scenes=60, moving_scenes=2, frames=150, optimum_every=15, collision_queries=5000, crowd_scenes=3)


def run(settings: Settings, quick: bool, sizes: Sizes | None = None) -> list[Row]:
    sizes = sizes or (QUICK if quick else FULL)
    field = settings.field_geometry()
    params = settings.planner
    rows: list[Row] = []
    rows += collision_rows(field, sizes.collision_queries)
    rows += nearest_rows(sizes.collision_queries)
    rows += visgraph_exactness_rows()
    planners = static_planners(params)
    rows += static_rows(field, params.collision, planners, sizes.static_scenes)
    rows += moving_rows(field, params, sizes)
    rows += crowd_rows(field, params, sizes)
    rows += summary_rows(rows)
    return rows


# --- collision and nearest neighbour -----------------------------------------------------------------
def _ns_per_query(fn: Callable[[], object], n: int) -> float:
    fn()  # compile / warm
    best = math.inf
    for _ in range(3):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best / n * 1e9


def collision_rows(field: Field, n_queries: int) -> list[Row]:
    """Broad phases at 10-40 obstacles (8 of them the field's boxes), Bruce 2006 §3.2.4."""
    rows = []
    rng = np.random.default_rng(SEED)
    for n in (10, 20, 30, 40):
        robots = np.column_stack([rng.uniform(-4.4, 4.4, n - 8), rng.uniform(-2.9, 2.9, n - 8)])
        world = field_world(field, robots)
        a = np.column_stack([rng.uniform(-4.5, 4.5, n_queries), rng.uniform(-3.0, 3.0, n_queries)])
        ang = rng.uniform(-np.pi, np.pi, n_queries)
        length = rng.uniform(0.05, 1.0, n_queries)  # extensions and shortcuts: the queries planners make
        seg = np.column_stack([a, a + length[:, None] * np.column_stack([np.cos(ang), np.sin(ang)])])
        for bp in BROAD_PHASES:
            p = CollisionParams(broad_phase=bp)  # type: ignore[arg-type]
            cw = CollisionWorld(world.bounds, world.circles, world.velocities, world.boxes).compile(0.09, params=p)
            build_us = _median_us(functools.partial(_build, world, p))
            ns = _ns_per_query(functools.partial(collision.segments_free, cw.cw, seg), n_queries)
            rows.append({"name": f"collision_{bp}_{n}", "ns_per_query": ns, "build_us": build_us, "n_obstacles": n})
    return rows


def _build(world: CollisionWorld, p: CollisionParams) -> CompiledWorld:
    """A fresh world compiled for a robot: what every frame pays before its first query."""
    return CollisionWorld(world.bounds, world.circles, world.velocities, world.boxes).compile(0.09, params=p)


def _median_us(fn: Callable[[], object], repeats: int = 50) -> float:
    fn()
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return float(np.median(times) * 1e6)


def nearest_rows(n_queries: int) -> list[Row]:
    """Nearest-neighbour search in an RRT-sized tree: numba brute force against the KD-tree."""
    rows = []
    rng = np.random.default_rng(SEED + 1)
    for n in (50, 200, 1000, 5000):
        nodes = rng.uniform((-4.5, -3.0), (4.5, 3.0), (n, 2))
        kdc = np.full((n, 2), -1, dtype=np.int32)
        kdd = np.zeros(n, dtype=np.int32)
        for i in range(1, n):
            K.kd_insert(nodes, kdc, kdd, 0, i)
        q = rng.uniform((-4.5, -3.0), (4.5, 3.0), (n_queries, 2))
        for kind, code in (("brute", K.NN_BRUTE), ("kdtree", K.NN_KDTREE)):
            ns = _ns_per_query(functools.partial(K.nearest_batch, nodes, q, code, kdc, kdd), len(q))
            rows.append({"name": f"nearest_{kind}_{n}", "ns_per_query": ns, "n_nodes": n})
    return rows


# --- planners ------------------------------------------------------------------------------------
def _errt(params: PlannerParams, **changes: Any) -> Callable[[], Planner]:
    p = dataclasses.replace(params, errt=dataclasses.replace(params.errt, **changes))
    return lambda: make_planner(p, name="errt")


def static_planners(params: PlannerParams) -> dict[str, Callable[[], Planner]]:
    """The planners of the static suite, each a factory of a fresh planner."""
    variants: dict[str, Callable[[], Planner]] = {
        "errt": _errt(params),
        "errt_kdtree": _errt(params, nearest="kdtree"),
        "errt_unidirectional": _errt(params, bidirectional=False),
        "prm": lambda: make_planner(params, name="prm"),
        "visgraph": lambda: make_planner(params, name="visgraph"),
    }
    return {**variants, **_ompl_planners()}


def _ompl_planners() -> dict[str, Callable[[], Planner]]:
    from cmdragons.bench.ompl_baseline import OMPLPlanner, ompl_missing

    if ompl_missing():
        return {}
    return {
        "ompl_rrtconnect": lambda: OMPLPlanner("RRTConnect", simplify=False),
        "ompl_rrtconnect_simplified": lambda: OMPLPlanner("RRTConnect", simplify=True),
        "ompl_prm": lambda: OMPLPlanner("PRM", simplify=False),
    }


def _termination(planner: Planner, seconds: float) -> Termination:
    """The bench's deadline and the planner's own configured work budget (none for OMPL's)."""
    work = getattr(getattr(planner, "params", None), "work_budget", math.inf)
    return deadline(seconds) | budget(work)


def _timed_solve(planner: Planner, prob: PlanProblem) -> tuple[PlanResult, float, float]:
    """Solve with a fresh compiled world (compiling it is part of every frame's cost). Returns the
    result, the wall time of the whole call (ms) and the planning time alone, without compiling
    the collision world: for OMPL its own solve (and simplify) without building its objects, for
    ERRT its search (straight line, trees, smoothing, cache), for the others the wall time."""
    prob.world._cache.clear()
    t0 = time.perf_counter()
    res = planner.solve(prob, _termination(planner, BENCH_BUDGET_S))
    wall_ms = (time.perf_counter() - t0) * 1e3
    if type(planner).__name__ == "OMPLPlanner":
        return res, wall_ms, float(res.stats.get("ms", wall_ms))
    return res, wall_ms, float(res.stats.get("search_ms", wall_ms))


def valid(prob: PlanProblem, res: PlanResult) -> bool:
    """A path to the goal (or its free stand-in) that the swept-circle check passes (after the
    escape segment when the start was inside an obstacle)."""
    if not res.status.reached or len(res.path) < 2:
        return False
    first = 1 if res.stats.get("escaped_start") else 0
    return bool(prob.compiled().path_free(res.path[first:])) and tuple(res.path[0]) == prob.start


def _row(name: str, ok: Sequence[bool], ms: Sequence[float], ratios: Sequence[float], **extra: Any) -> Row:
    row: Row = {
        "name": name,
        "success_rate": float(np.mean(ok)) if len(ok) else math.nan,
        "median_ms": float(np.median(ms)) if len(ms) else math.nan,
        "p95_ms": float(np.percentile(ms, 95)) if len(ms) else math.nan,
        "length_ratio": float(np.mean(ratios)) if len(ratios) else math.nan,
        "queries": len(ms),
    }
    return {**row, **extra}


def static_rows(
    field: Field, collision: CollisionParams, planners: dict[str, Callable[[], Planner]], n: int
) -> list[Row]:
    rng = np.random.default_rng(SEED + 2)
    scenes = [random_scene(field, rng) for _ in range(n)]
    optimum = make_planner(PlannerParams(), name="visgraph")
    problems, best = [], []
    for s in scenes:
        prob = s.problem(field, collision)
        res = optimum.solve(prob, deadline(10.0))
        problems.append(prob)
        best.append(res.cost if res.status is PlanStatus.SOLVED else math.inf)
    solvable = [i for i, b in enumerate(best) if np.isfinite(b)]
    rows = []
    for name, factory in planners.items():
        planner = factory()
        _timed_solve(planner, problems[0])  # compile and load outside the measurement
        ok: list[bool] = []
        ms: list[float] = []
        plan_ms: list[float] = []
        ratios: list[float] = []
        raw: list[float] = []
        for i in solvable:
            planner.reset()
            res, t, tp = _timed_solve(planner, problems[i])
            good = valid(problems[i], res)
            ok.append(good)
            ms.append(t)
            plan_ms.append(tp)
            if good:
                ratios.append(res.cost / best[i])
                if "raw_length_m" in res.stats:
                    raw.append(float(res.stats["raw_length_m"]) / best[i])
        rows.append(_row(f"static_{name}", ok, ms, ratios, median_search_ms=_median(plan_ms),
                         length_ratio_raw=float(np.mean(raw)) if raw else math.nan))
    rows.append({"name": "static_scenes", "queries": n, "note": f"{n - len(solvable)} unsolvable scenes left out"})
    return rows


def moving_planners(params: PlannerParams, crowd: bool = False) -> dict[str, Callable[[], Planner]]:
    """ERRT as configured, and with plan reuse off (to isolate the waypoint cache) with and without
    the cache; in the random scenes also the thesis's single-tree form and the dynamic PRM."""
    variants: dict[str, Callable[[], Planner]] = {
        "errt": _errt(params),
        "errt_cache": _errt(params, reuse_last_plan=False),
        "errt_nocache": _errt(params, reuse_last_plan=False, waypoint_cache=False),
    }
    if not crowd:
        variants |= {
            "errt_unidirectional_cache": _errt(params, reuse_last_plan=False, bidirectional=False),
            "errt_unidirectional_nocache": _errt(
                params, reuse_last_plan=False, bidirectional=False, waypoint_cache=False
            ),
            "prm": lambda: make_planner(params, name="prm"),
        }
    ompl = _ompl_planners()
    keep = ("ompl_rrtconnect",) if crowd else ("ompl_rrtconnect", "ompl_rrtconnect_simplified")
    return variants | {k: v for k, v in ompl.items() if k in keep}


class Episode(Protocol):
    """One moving scene of the replanning suites: the robots, our goal, and how they move on."""

    label: str  # groups frames for the per-group cache speed-ups (e.g. the crowd's gap)
    start: tuple[float, float]  # where our robot starts

    def world(self) -> CollisionWorld: ...

    def goal(self) -> tuple[float, float]: ...

    def arrived(self, prob: PlanProblem) -> None:
        """Our robot reached the goal of ``prob``: pick the next one."""

    def step(self, dt_s: float) -> None: ...


class RandomEpisode:
    """Up to 21 robots wandering (:class:`MovingScene`); a new random goal on arrival."""

    label = "random"

    def __init__(self, field: Field, rng: np.random.Generator) -> None:
        self.field, self.rng = field, rng
        scene = random_scene(field, rng)
        self.mover = MovingScene(field, scene, np.random.default_rng(rng.integers(2**63)))
        self.start, self._goal = scene.start, scene.goal

    def world(self) -> CollisionWorld:
        return field_world(self.field, self.mover.pos, self.mover.vel)

    def goal(self) -> tuple[float, float]:
        return self._goal

    def arrived(self, prob: PlanProblem) -> None:
        self._goal = random_free_point(self.field, prob, self.rng, 0.2)

    def step(self, dt_s: float) -> None:
        self.mover.step(dt_s)


class CrowdEpisode:
    """Two drifting crowds with a narrow gap each (:class:`CrowdScene`); our robot shuttles between
    their pockets."""

    def __init__(self, field: Field, rng: np.random.Generator, gap_m: float) -> None:
        self.field = field
        self.crowd = CrowdScene(field, rng, gap_m=gap_m)
        self.start = self.crowd.pocket(0)
        self.label = f"gap_{round(gap_m * 1000)}mm"

    def world(self) -> CollisionWorld:
        return field_world(self.field, self.crowd.robots, self.crowd.velocities)

    def goal(self) -> tuple[float, float]:
        return self.crowd.pocket(self.crowd.target)

    def arrived(self, prob: PlanProblem) -> None:
        self.crowd.target = 1 - self.crowd.target

    def step(self, dt_s: float) -> None:
        self.crowd.step(dt_s)


@dataclasses.dataclass
class Record:
    """What one planner did in one replanning suite, frame by frame."""

    ok: list[bool] = dataclasses.field(default_factory=list)
    ms: list[float] = dataclasses.field(default_factory=list)
    search_ms: list[float] = dataclasses.field(default_factory=list)
    ratios: list[float] = dataclasses.field(default_factory=list)
    blocked_ms: list[float] = dataclasses.field(default_factory=list)
    iterations: list[int] = dataclasses.field(default_factory=list)
    nodes: list[int] = dataclasses.field(default_factory=list)
    waypoint_targets: list[int] = dataclasses.field(default_factory=list)  # searches with a filled cache
    cached_iterations: list[int] = dataclasses.field(default_factory=list)
    by_label: dict[str, list[tuple[float, float]]] = dataclasses.field(default_factory=dict)  # ms, iterations

    def row(self, name: str) -> Row:
        q = int(np.sum(self.cached_iterations))
        return _row(
            name, self.ok, self.ms, self.ratios,
            median_search_ms=_median(self.search_ms),
            blocked_median_ms=_median(self.blocked_ms),
            blocked_frames=len(self.blocked_ms),
            median_iterations=_median(self.iterations),
            p95_iterations=float(np.percentile(self.iterations, 95)) if self.iterations else math.nan,
            median_nodes=_median(self.nodes),
            waypoint_target_rate=float(np.sum(self.waypoint_targets)) / q if q else math.nan,
        )


def _median(xs: Sequence[float]) -> float:
    return float(np.median(xs)) if len(xs) else math.nan


def moving_rows(field: Field, params: PlannerParams, sizes: Sizes) -> list[Row]:
    """Replanning at 60 Hz among robots wandering at random (mostly easy frames)."""
    rng = np.random.default_rng(SEED + 3)
    episodes = (RandomEpisode(field, rng) for _ in range(sizes.moving_scenes))
    return replan_rows("moving", field, params, moving_planners(params), episodes, sizes, rng)


CROWD_GAPS_M = (0.12, 0.06, 0.03)  # free width of each crowd's gap for the robot's centre


def crowd_rows(field: Field, params: PlannerParams, sizes: Sizes) -> list[Row]:
    """Replanning at 60 Hz between two drifting crowds with narrow gaps (hard frames)."""
    rng = np.random.default_rng(SEED + 5)
    episodes = (CrowdEpisode(field, rng, CROWD_GAPS_M[i % len(CROWD_GAPS_M)]) for i in range(sizes.crowd_scenes))
    return replan_rows("crowd", field, params, moving_planners(params, crowd=True), episodes, sizes, rng)


def replan_rows(
    prefix: str,
    field: Field,
    params: PlannerParams,
    factories: dict[str, Callable[[], Planner]],
    episodes: Iterable[Episode],
    sizes: Sizes,
    rng: np.random.Generator,
) -> list[Row]:
    """Every planner answers the same query each frame and keeps its own state across frames; our
    robot follows the configured ERRT's plan at ``ROBOT_SPEED_M_S``."""
    records = {k: Record() for k in factories}
    optimum = make_planner(params, name="visgraph")
    for episode in episodes:
        planners = {k: f() for k, f in factories.items()}
        pos = np.array(episode.start)
        for frame in range(sizes.frames):
            prob = PlanProblem((pos[0], pos[1]), episode.goal(), field.league.robot.radius_m, episode.world(), 0.0,
                               params.collision)
            best = math.inf
            if frame % sizes.optimum_every == 0:
                opt = optimum.solve(prob, deadline(10.0))
                best = opt.cost if opt.status.reached else math.inf
            drive: PlanResult | None = None
            blocked = not prob.compiled().segment_free(prob.start, prob.goal)
            for name, planner in planners.items():
                res, t, tp = _timed_solve(planner, prob)
                rec, good = records[name], valid(prob, res)
                rec.ok.append(good)
                rec.ms.append(t)
                rec.search_ms.append(tp)
                rec.by_label.setdefault(episode.label, []).append((t, float(res.stats.get("iterations", 0))))
                if blocked:
                    rec.blocked_ms.append(t)
                if good and np.isfinite(best):
                    rec.ratios.append(res.cost / best)
                if "nodes" in res.stats:  # ERRT searched (no straight line, no reuse)
                    rec.iterations.append(int(res.stats["iterations"]))
                    rec.nodes.append(int(res.stats["nodes"]))
                    if res.stats["cached"]:
                        rec.waypoint_targets.append(int(res.stats["waypoint_targets"]))
                        rec.cached_iterations.append(int(res.stats["iterations"]))
                if name == "errt":
                    drive = res
            pos = _follow(drive, pos, ROBOT_SPEED_M_S * FRAME_S)
            if np.hypot(pos[0] - prob.goal[0], pos[1] - prob.goal[1]) < 0.05:
                episode.arrived(prob)
            episode.step(FRAME_S)
    rows = [rec.row(f"{prefix}_{k}") for k, rec in records.items()]
    cached, bare = records.get("errt_cache"), records.get("errt_nocache")
    if cached and bare and len(cached.by_label) > 1:
        for label in sorted(cached.by_label):
            a, b = np.array(cached.by_label[label]), np.array(bare.by_label[label])
            rows.append({
                "name": f"waypoint_cache_speedup_{prefix}_{label}",
                "ratio_median": float(np.median(b[:, 0]) / np.median(a[:, 0])),
                "cache_median_ms": float(np.median(a[:, 0])), "nocache_median_ms": float(np.median(b[:, 0])),
                "cache_median_iterations": float(np.median(a[:, 1])),
                "nocache_median_iterations": float(np.median(b[:, 1])), "frames": len(a),
            })
    return rows


def _follow(res: PlanResult | None, pos: FloatArray, step_m: float) -> FloatArray:
    """Where the robot is after driving ``step_m`` along the plan (it stays without one)."""
    if res is None or len(res.path) < 2 or not res.status.reached:
        return pos
    path = res.path
    for a, b in zip(path[:-1], path[1:], strict=True):
        seg = float(np.hypot(*(b - a)))
        if seg >= step_m:
            out: FloatArray = a + (b - a) * (step_m / seg)
            return out
        step_m -= seg
    return np.array(path[-1], dtype=np.float64)


# --- exactness and summary -----------------------------------------------------------------------
def visgraph_exactness_rows() -> list[Row]:
    """The visibility graph around one disc against the closed form: two tangents and the arc."""
    rng = np.random.default_rng(SEED + 4)
    planner = make_planner(PlannerParams(), name="visgraph")
    errors = []
    for _ in range(50):
        r_obs, r, d = rng.uniform(0.05, 0.5), rng.uniform(0.0, 0.2), rng.uniform(0.8, 3.0)
        world = CollisionWorld((-5.0, -5.0, 5.0, 5.0), np.array([[0.0, 0.0, r_obs]]))
        res = planner.solve(PlanProblem((-d, 0.0), (d, 0.0), r, world), never())  # exactness, not speed: no clock
        big = r_obs + r
        exact = 2 * math.sqrt(d * d - big * big) + big * (math.pi - 2 * math.acos(big / d))
        errors.append(abs(res.cost - exact) / exact)
    return [{"name": "visgraph_exactness", "max_rel_error": float(np.max(errors)), "queries": len(errors)}]


def summary_rows(rows: list[Row]) -> list[Row]:
    """The issue's targets as ratios: the waypoint cache's speed-up (plan reuse off in both) in the
    random and the crowd scenes, and ERRT's median against OMPL RRTConnect's: wall time of the same
    call, and ERRT's search alone against OMPL's planning alone (neither building its world)."""
    by = {r["name"]: r for r in rows}
    out: list[Row] = []
    for scope in ("moving", "crowd"):
        for variant in ("errt", "errt_unidirectional"):
            cached, bare = by.get(f"{scope}_{variant}_cache"), by.get(f"{scope}_{variant}_nocache")
            if cached and bare:
                out.append({
                    "name": f"waypoint_cache_speedup_{scope}_{variant}",
                    "ratio_median": bare["median_ms"] / cached["median_ms"],
                    "ratio_p95": bare["p95_ms"] / cached["p95_ms"],
                    "ratio_blocked_median": bare["blocked_median_ms"] / cached["blocked_median_ms"],
                    "ratio_median_iterations": bare["median_iterations"] / cached["median_iterations"],
                })  # fmt: skip
    for scope in ("static", "moving", "crowd"):
        ompl = by.get(f"{scope}_ompl_rrtconnect")
        if ompl:
            errt = by[f"{scope}_errt"]
            out.append({
                "name": f"{scope}_errt_vs_ompl_rrtconnect",
                "ratio_to_ompl_rrtconnect": errt["median_ms"] / ompl["median_ms"],
                "ratio_search_to_ompl_plan_only": errt["median_search_ms"] / ompl["median_search_ms"],
            })  # fmt: skip
    if "static_ompl_rrtconnect" not in by:
        from cmdragons.bench.ompl_baseline import ompl_missing

        out.append({"name": "ompl_baselines", "note": f"skipped: {ompl_missing()}"})
    return out
