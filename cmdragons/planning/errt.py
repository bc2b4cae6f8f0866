"""Execution-extended RRT with a waypoint cache (ERRT, Bruce 2006 §4.3).

Field frame, metres. One :class:`ERRTPlanner` per robot keeps what lives across frames: the
waypoint cache (points of earlier plans that the tree is drawn to, §4.3, with the replacement
strategies of §4.3.3) and the last plan, which is reused as long as it stays valid. Each frame
the planner

1. leaves an obstacle it starts in, or moves a blocked goal to the nearest free one (§4.6.2);
2. reuses the last plan when its remainder is still free and the goal has not moved;
3. returns the straight line when it is free;
4. otherwise grows ERRT trees (numba kernel :func:`_kernels.errt_grow`): goal bias, cached waypoints,
   uniform samples, repeated extensions, and in the bidirectional multi-bridge variant (§4.3.4)
   trees from both ends joined by several bridges, the shortest of which wins;
5. smooths the path (shortcuts, then pulls it taut, §4.6.1) and feeds its points to the cache.

The termination condition (:mod:`cmdragons.planning.termination`) is honoured in tree nodes: the
kernel stops when the work budget of nodes is spent (NO_PATH), the planner stops after
``iteration_budget`` iterations (NO_PATH: trees that cannot grow spend no nodes) and the deadline is
checked between chunks of iterations (TIMEOUT); randomness comes from the ``numpy.random.Generator``
given to the planner.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from cmdragons.config import Validated, setting
from cmdragons.geometry import path_length
from cmdragons.planning import _errt_kernels as K
from cmdragons.planning import _smoothing_kernels as S
from cmdragons.planning.problem import PlanProblem, PlanResult, PlanStatus, RobustEnds, prepare
from cmdragons.planning.termination import Termination
from cmdragons.planning.world import CompiledWorld

__all__ = ["ERRTParams", "ERRTPlanner", "SmoothingParams", "smooth"]

FloatArray = NDArray[np.float64]

MAX_NODES = 1_000_000  # the trees never grow beyond this, whatever the termination allows


@dataclass(frozen=True)
class SmoothingParams(Validated):
    """Path smoothing (Bruce 2006 §4.6.1): shortcuts, then passes that pull the path taut."""

    passes: int = setting(3, lo=0, hi=20)  # taut-pulling passes after the shortcuts
    bisections: int = setting(8, lo=1, hi=30)  # steps of the bisection that moves one vertex
    subdivide_m: float = setting(0.4, lo=0.0, hi=10.0)  # split longer segments before a pass (0: never)


def smooth(cw: CompiledWorld, path: FloatArray, params: SmoothingParams) -> FloatArray:
    """Shortcut and pull taut a collision-free polyline (k, 2); the ends stay where they are."""
    out = S.shortcut(cw.cw, np.ascontiguousarray(path, dtype=np.float64))
    if params.passes > 0 and len(out) > 2:
        out = S.pull_taut(cw.cw, out, params.passes, params.bisections, params.subdivide_m)
    return np.asarray(out)


@dataclass(frozen=True)
class ERRTParams(Validated):
    """configs/planner.yaml ``errt`` (Bruce 2006 §4.3, Table 4.5 for the spirit of the values)."""

    step_m: float = setting(0.3, lo=0.01, hi=5.0)  # length of one tree extension
    max_extensions: int = setting(16, lo=1, hi=1000)  # repeated extensions toward one target
    p_goal: float = setting(0.1, lo=0.0, hi=1.0)  # probability that a target is the goal (goal bias)
    p_waypoint: float = setting(0.5, lo=0.0, hi=1.0)  # probability that a target is a cached waypoint
    waypoint_cache: bool = True  # keep and use the waypoint cache
    waypoint_cache_size: int = setting(64, lo=1, hi=10000)  # cached points
    waypoint_replacement: Literal["random", "fifo"] = setting("random", choices=("random", "fifo"))
    waypoint_spacing_m: float = setting(0.3, lo=0.01, hi=10.0)  # spacing of the points cached along a plan
    bidirectional: bool = True  # grow trees from both ends (multi-bridge ERRT, §4.3.4)
    max_bridges: int = setting(4, lo=1, hi=64)  # bridges to collect before choosing the shortest
    extra_iterations: int = setting(24, lo=0, hi=100000)  # more iterations after the first bridge
    connect_radius_m: float = setting(20.0, lo=0.0, hi=100.0)  # longest straight bridge tried
    nearest: Literal["brute", "kdtree"] = setting("brute", choices=("brute", "kdtree"))  # measured: brute wins
    # tree nodes per robot and frame (the work budget of its termination): spent without a path, NO_PATH
    work_budget: int = setting(2000, lo=16, hi=MAX_NODES)
    # iterations per robot and frame; spent without a path: NO_PATH. Trees that cannot grow (a start
    # boxed in) add no nodes, so without this bound only the deadline stopped them, after as many
    # iterations as the machine's speed allowed: the random stream left behind, and every later plan,
    # then depended on the load
    iteration_budget: int = setting(20000, lo=1, hi=100_000_000)
    chunk_iterations: int = setting(256, lo=1, hi=100000)  # iterations between deadline checks (fixed)
    reuse_last_plan: bool = True  # keep the last plan while it stays valid and the goal stays
    goal_tolerance_m: float = setting(0.01, lo=0.0, hi=1.0)  # goal moves less than this: same goal
    smoothing: SmoothingParams = SmoothingParams()

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.p_goal + self.p_waypoint > 1.0:
            raise ValueError("p_goal + p_waypoint must be at most 1")


class WaypointCache:
    """Points of earlier plans (Bruce 2006 §4.3): a fixed-size store with random or FIFO replacement
    (§4.3.3), filled by the numba kernel :func:`_kernels.cache_add` (a microsecond a plan); the
    planner's own rng picks the victims, so runs repeat exactly."""

    def __init__(self, size: int, replacement: str, rng: np.random.Generator) -> None:
        self.points = np.zeros((size, 2))
        self._meta = np.zeros(2, dtype=np.int64)  # count, next (FIFO)
        self._fifo = replacement == "fifo"
        self._rng = rng
        self._u = np.zeros(0)
        self._u_next = 0

    @property
    def count(self) -> int:
        return int(self._meta[0])

    def add(self, pts: FloatArray) -> None:
        if len(self._u) - self._u_next < len(pts):
            self._u, self._u_next = self._rng.random(max(1024, len(pts))), 0
        self._u_next += K.cache_add(self.points, self._meta, pts, self._u[self._u_next :], self._fifo)

    def view(self) -> FloatArray:
        return self.points[: self.count]

    def clear(self) -> None:
        self._meta[:] = 0


class ERRTPlanner:
    """ERRT for one robot (Bruce 2006 §4.3); see the module docstring for one frame's steps."""

    name = "errt"

    def __init__(self, params: ERRTParams, rng: np.random.Generator) -> None:
        self.params = params
        self.rng = rng
        p = params
        self.cache = WaypointCache(p.waypoint_cache_size, p.waypoint_replacement, rng)
        self.last_path: FloatArray | None = None
        self.last_goal: tuple[float, float] | None = None
        self._allocate(p.work_budget)
        self._roots = np.array([0, 1], dtype=np.int32)
        self._counts = np.zeros(K.N_COUNTS, dtype=np.int64)
        self._bridges = np.zeros((p.max_bridges, 3))
        nn = K.NN_KDTREE if p.nearest == "kdtree" else K.NN_BRUTE
        self._config = K.GrowConfig(p.p_goal, p.p_waypoint if p.waypoint_cache else 0.0, p.step_m, p.connect_radius_m,
                                    p.max_extensions, p.bidirectional, p.max_bridges, p.extra_iterations, nn)
        self._no_waypoints = np.zeros((0, 2))
        self._rand = np.zeros((0, 3))
        self._rand_next = 0
        self._t_search = 0.0

    def _allocate(self, cap: int) -> None:
        """Room for ``cap`` tree nodes (the arrays the kernel grows the trees in)."""
        self._nodes = np.zeros((cap, 2))
        self._parent = np.full(cap, -1, dtype=np.int32)
        self._tree = np.zeros(cap, dtype=np.int8)
        self._cost = np.zeros(cap)
        self._kdc = np.full((cap, 2), -1, dtype=np.int32)
        self._kdd = np.zeros(cap, dtype=np.int32)
        self._stack = np.zeros((cap, 2))

    def _grow_room(self) -> None:
        """Double the room for tree nodes, keeping the trees grown so far."""
        n = len(self._nodes)
        old: tuple[NDArray[np.generic], ...] = (self._nodes, self._parent, self._tree, self._cost, self._kdc, self._kdd)
        self._allocate(min(2 * n, MAX_NODES))
        grown: tuple[NDArray[np.generic], ...] = (self._nodes, self._parent, self._tree, self._cost, self._kdc,
                                                  self._kdd)
        for new, a in zip(grown, old, strict=True):
            new[:n] = a

    def reset(self) -> None:
        self.cache.clear()
        self.last_path = None
        self.last_goal = None

    def solve(self, problem: PlanProblem, termination: Termination) -> PlanResult:
        """Plan from ``problem.start`` to ``problem.goal`` until ``termination`` (work: tree nodes)."""
        t0 = time.perf_counter()
        cw, ends = prepare(problem)
        if ends.failure is not None:
            return ends.fail(t0)
        self._t_search = time.perf_counter()  # the search alone, without compiling the world
        reused = self._reuse(cw, ends)
        if reused is not None:
            return self._done(ends, reused, PlanStatus.SOLVED, {"reused": True, "iterations": 0}, t0, cache=False)
        s, g = ends.start, ends.goal
        if cw.segment_free(s, g):
            path = np.array([s, g], dtype=np.float64)
            return self._done(ends, path, PlanStatus.SOLVED, {"reused": False, "iterations": 0}, t0)
        waypoints = self.cache.view() if self.params.waypoint_cache else self._no_waypoints
        code, timed_out = self._grow(cw, s, g, waypoints, termination)
        counts = self._counts
        n_bridges = int(counts[K.N_BRIDGES])
        stats: dict[str, object] = {"reused": False, "iterations": int(counts[K.ITERATIONS]),
                                    "nodes": int(counts[K.N_NODES]), "bridges": n_bridges,
                                    "waypoint_targets": int(counts[K.WAYPOINT_TARGETS]), "cached": len(waypoints)}
        if n_bridges == 0:
            self.last_path = None
            status = PlanStatus.TIMEOUT if timed_out else PlanStatus.NO_PATH
            partial = self._branch(self._closest_to(g))[::-1]
            stats["search_ms"] = (time.perf_counter() - self._t_search) * 1e3
            stats["ms"] = (time.perf_counter() - t0) * 1e3
            return ends.finish(partial, status, stats)
        b = int(np.argmin(self._bridges[:n_bridges, 2]))
        a0, a1 = int(self._bridges[b, 0]), int(self._bridges[b, 1])
        raw = np.vstack([self._branch(a0)[::-1], self._branch(a1)])
        stats["raw_length_m"] = path_length(raw)
        path = smooth(cw, raw, self.params.smoothing)
        return self._done(ends, path, PlanStatus.SOLVED, stats, t0, cache_points=raw)

    # --- steps ----------------------------------------------------------------------------------
    def _reuse(self, cw: CompiledWorld, ends: RobustEnds) -> FloatArray | None:
        """The last plan from the current start, when the goal is the same and the rest still free."""
        last = self.last_path
        if not self.params.reuse_last_plan or last is None or self.last_goal is None or ends.escaped:
            return None
        if np.hypot(ends.goal[0] - self.last_goal[0], ends.goal[1] - self.last_goal[1]) > self.params.goal_tolerance_m:
            return None
        # join the plan at the farthest vertex in sight: the robot has moved along (or off) it
        for k in range(len(last) - 1, 0, -1):
            if cw.segment_free(ends.start, last[k]):
                rest = last[k:]
                if len(rest) == 1 or cw.path_free(rest):
                    return np.vstack([np.asarray(ends.start)[None, :], rest])
                return None
        return None

    def _grow(
        self, cw: CompiledWorld, s: tuple[float, float], g: tuple[float, float], waypoints: FloatArray,
        termination: Termination,
    ) -> tuple[int, bool]:
        """Run the ERRT kernel in chunks until it finishes, spends the termination's budget of nodes or
        the planner's budget of iterations (``iteration_budget``), or its deadline passes."""
        self._nodes[0], self._nodes[1] = s, g
        self._parent[:2] = -1
        self._tree[0], self._tree[1] = 0, 1
        self._cost[:2] = 0.0
        self._kdc[:2] = -1
        self._kdd[:2] = 0
        self._counts[:] = 0
        self._counts[K.N_NODES] = 2  # the two roots
        chunk = self.params.chunk_iterations
        limit = termination.work_left(0, MAX_NODES)
        while True:
            left = self.params.iteration_budget - int(self._counts[K.ITERATIONS])
            if left <= 0:
                return K.GROW_RUNNING, False  # the iteration budget is spent: NO_PATH unless bridged
            rand = self._random_rows(min(chunk, left))
            before = int(self._counts[K.ITERATIONS])
            trees = K.Trees(self._nodes, self._parent, self._tree, self._cost, self._kdc, self._kdd, self._roots,
                            self._stack, self._counts, self._bridges)
            code = K.errt_grow(cw.cw, trees, rand, waypoints, self._config, min(limit, len(self._nodes)))
            self._rand_next += int(self._counts[K.ITERATIONS]) - before
            if code == K.GROW_FULL and len(self._nodes) < min(limit, MAX_NODES):
                self._grow_room()  # the budget allows more nodes than there is room for
                continue
            if code != K.GROW_RUNNING:
                return int(code), False
            if termination.expired():
                return int(code), True
            # chunks keep a fixed size: the search's result must not depend on the machine's speed
            # (where the chunks end shows in the result), only a deadline that is hit may cut it

    def _random_rows(self, n: int) -> FloatArray:
        """The next ``n`` rows of the planner's stream of uniforms (three per iteration). Only the rows
        an iteration used are consumed, so the plans do not depend on how the deadline chunked the
        work: the same seed and history give the same paths."""
        if self._rand_next + n > len(self._rand):
            rest = self._rand[self._rand_next :]
            block = max(n - len(rest), 4096)
            self._rand = np.vstack([rest, self.rng.random((block, 3))])
            self._rand_next = 0
        return self._rand[self._rand_next : self._rand_next + n]

    def _branch(self, i: int) -> FloatArray:
        """Node i and its ancestors up to its tree's root, in that order."""
        idx = []
        while i >= 0:
            idx.append(i)
            i = int(self._parent[i])
        return self._nodes[idx].copy()

    def _closest_to(self, g: tuple[float, float]) -> int:
        n = int(self._counts[K.N_NODES])
        d = np.hypot(self._nodes[:n, 0] - g[0], self._nodes[:n, 1] - g[1])
        d[self._tree[:n] != 0] = np.inf
        return int(np.argmin(d))

    def _done(
        self,
        ends: RobustEnds,
        path: FloatArray,
        status: PlanStatus,
        stats: dict[str, object],
        t0: float,
        cache: bool = True,
        cache_points: FloatArray | None = None,
    ) -> PlanResult:
        """Remember the plan and feed the waypoint cache with points every ``waypoint_spacing_m`` along
        the tree's own path (Bruce 2006 §4.3), which keeps some clearance, rather than along the
        smoothed path that touches the obstacles and is the first to be blocked when they move."""
        if cache and self.params.waypoint_cache:
            along = cache_points if cache_points is not None else path
            self.cache.add(K.resample(along, self.params.waypoint_spacing_m)[1:-1])
        self.last_path = path
        if cache:  # a plan reused keeps the goal it was made for: a goal creeping less than the tolerance
            # a frame (a robot following a pushed ball) would otherwise drag it along, the path left behind
            self.last_goal = ends.goal
        now = time.perf_counter()
        stats["search_ms"] = (now - self._t_search) * 1e3
        stats["ms"] = (now - t0) * 1e3
        return ends.finish(path, status, stats)
