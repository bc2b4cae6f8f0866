"""``cmdragons bench robox``: Philippsen's Robox stack (E* -> elastic band -> dynamic window) beside
the shipped ERRT + trajectory following + DSS.

Three parts, each a group of rows:

* ``dynamic_window_step_21_robots``, ``robox_step_21_robots``: one robot's navigator step among 21
  robots that move between steps (the world compiled anew each step, as in a match): the dynamic
  window alone (its kernel, and the whole ``command``), and the Robox navigator's whole step (band
  update and window). The reader's reference is PythonRobotics' DWA
  (``PathPlanning/DynamicWindowApproach``), measured at 35 ms a step on this kind of machine (issue
  #17; not run here).
* ``crossing_<method>``: one robot crosses the field, 1.2 m inside each goal line, through robots that
  wander at random (each drives at its own speed to random points, seeded, and avoids nobody), in the
  simulator (``sim.world.World``, no rendering; the brain sees the true state). The same seeded
  scenes for every method: ``errt_trajectory_dss`` (the shipped team), ``robox_estar_dss`` (E*,
  band and window, DSS behind them as the brain always runs it) and ``robox_estar`` (the stack
  alone, safety off). Contacts with the wanderers (summed), time to goal (median of the trials that
  arrive), the least clearance between the robots' bodies (median over trials of each trial's least,
  and the least of all), trials that time out, brain ms per frame (median).
* ``match_<blue>_vs_<yellow>_seed_<n>``: seeded matches through the cameras between the shipped
  team and a copy of it on the Robox stack (``--opponent self`` with the copy's own settings), ten
  with the ERRT team blue and ten with colours reversed: goals, own collisions and brain time per
  team; then a totals row per pairing.

``--quick``: 50 steps of timing, 4 crossings per method, 2 + 2 matches of 10 s (full: 500 steps, 20
crossings, 10 + 10 matches of 30 s).
"""

from __future__ import annotations

import dataclasses
import math
import time
from typing import Any

import numpy as np

from cmdragons.messages import GameState, RobotCommand, RobotState
from cmdragons.navigation import Arrival, DynamicWindowNavigator, make_navigator
from cmdragons.navigation import _dynamic_window_kernels as NK
from cmdragons.planning import deadline, field_world
from cmdragons.runtime.match import Match
from cmdragons.runtime.settings import Settings
from cmdragons.team import Brain
from sim.world import Contact, World
from strategy.skills import Intent

__all__ = ["crossing", "robox_settings", "run"]

METHODS = ("errt_trajectory_dss", "robox_estar_dss", "robox_estar")
PYTHONROBOTICS_DWA_MS = 35.0  # PythonRobotics' DWA, one step, on this kind of machine (issue #17)
N_MOVING = 21  # robots around the one navigating (a full division A match less one)
WANDERERS = 10  # robots wandering through the crossing
WANDER_SPEED_M_S = (0.5, 1.5)  # each wanderer's speed, drawn once
WANDER_REACHED_M = 0.2  # a wanderer this close to its point draws the next
LINE_OFFSET_M = 1.2  # start and goal this far inside the goal lines (outside the defense areas)
ARRIVED_M = 0.05
TIMEOUT_S = 15.0
WARMUP_FRAMES = 10  # left out of the brain's timing (first calls compile)


def robox_settings(settings: Settings, safety: bool = True) -> Settings:
    """``settings`` with the Robox stack: E* as the planner, the robox navigator (what
    ``--opponent-set team.navigator=robox --opponent-set planner.planner=estar`` gives a team); without
    ``safety``, DSS off as well."""
    out = dataclasses.replace(settings, team=dataclasses.replace(settings.team, navigator="robox"),
                              planner=dataclasses.replace(settings.planner, planner="estar"))
    return out if safety else dataclasses.replace(out, safety=dataclasses.replace(out.safety, method="none"))


def _timing_rows(settings: Settings, steps: int) -> list[dict[str, Any]]:
    """One navigator step among ``N_MOVING`` moving robots: the window's kernel, its whole command,
    and the Robox navigator's whole step (median and p95 over ``steps`` scenes)."""
    f = settings.field_geometry()
    r = settings.field.robot.radius_m
    rng = np.random.default_rng(17)
    sections = settings.team.navigator_sections
    window = make_navigator("dynamic_window", sections, settings.control, r, settings.planner.collision)
    robox = make_navigator("robox", sections, settings.control, r, settings.planner.collision)
    assert isinstance(window, DynamicWindowNavigator)
    xy = rng.uniform((-f.half_length + 0.5, -f.half_width + 0.5), (f.half_length - 0.5, f.half_width - 0.5),
                     (N_MOVING, 2))
    vel = rng.normal(0.0, 1.0, (N_MOVING, 2))
    times: dict[str, list[float]] = {"kernel": [], "dynamic_window": [], "robox": []}
    me = np.array([-3.0, 0.0])
    for k in range(steps + 3):
        xy = np.clip(xy + vel / 60.0, (-f.half_length, -f.half_width), (f.half_length, f.half_width))
        far = np.hypot(*(xy - me).T) > 2 * r + 0.05
        world = field_world(f, xy[far], vel[far])
        robot = RobotState("blue", 0, float(me[0]), float(me[1]), 0.0, 1.0, 0.2)
        plan = np.array([me, (3.0, 0.5)])
        for name, nav in (("dynamic_window", window), ("robox", robox)):
            nav.set_plan(plan, Arrival(0.0))
            t0 = time.perf_counter()
            nav.command(robot, world, deadline(1.0))
            if k >= 3:
                times[name].append(time.perf_counter() - t0)
        cw = world.compile(r, 0.0, 0.0, settings.planner.collision)
        lim = settings.control.motion.limits()
        t0 = time.perf_counter()
        NK.dynamic_window(cw.obs, cw.inner, me[0], me[1], 1.0, 0.2, 2.0, 0.5, window.window, lim, window.cfg, 10**6)
        if k >= 3:
            times["kernel"].append(time.perf_counter() - t0)
    rows: list[dict[str, Any]] = []
    parts = (("kernel", "dynamic_window_kernel_21_robots", "the window's kernel"),
             ("dynamic_window", "dynamic_window_step_21_robots", "command: world compiled, path, window"),
             ("robox", "robox_step_21_robots", "command: world, band update, window"))
    for name, label, what in parts:
        ms = np.array(times[name]) * 1e3
        rows.append({"name": label, "median_ms": float(np.median(ms)), "p95_ms": float(np.percentile(ms, 95)),
                     "ratio_to_pythonrobotics_dwa": float(np.median(ms)) / PYTHONROBOTICS_DWA_MS,
                     "note": what})
    reference = f"PythonRobotics DWA {PYTHONROBOTICS_DWA_MS:g} ms a step (issue #17, not run here)"
    rows[-1]["note"] = f"{parts[-1][2]}; reference: {reference}"
    return rows


@dataclasses.dataclass(frozen=True)
class Crossing:
    contacts: int
    time_s: float  # to the goal; nan when it timed out
    min_clearance_m: float  # least distance between our robot's body and a wanderer's
    brain_ms: float  # median per frame


def _wander(world: World, targets: np.ndarray, speeds: np.ndarray, rng: np.random.Generator,
            half: tuple[float, float]) -> list[RobotCommand]:
    """The wanderers' commands: straight to their points at their speeds, a new point when reached."""
    snap = world.snapshot().robots
    out = []
    for i, row in enumerate(snap[snap[:, 0] == 1.0]):
        d = targets[i] - row[2:4]
        n = float(np.hypot(*d))
        if n < WANDER_REACHED_M:
            targets[i] = rng.uniform((-half[0] + 0.3, -half[1] + 0.3), (half[0] - 0.3, half[1] - 0.3))
            d, n = targets[i] - row[2:4], float(np.hypot(*(targets[i] - row[2:4])))
        v = d / max(n, 1e-9) * speeds[i]
        out.append(RobotCommand("yellow", int(row[1]), float(v[0]), float(v[1]), 0.0))
    return out


def crossing(settings: Settings, seed: int) -> Crossing:
    """One crossing with ``settings``' planner, navigator and safety; same seed, same scene."""
    sp = settings.sim
    world = World(settings.field, sp.physics, sp.robot, sp.ball, sp.kicker, sp.dribbler,
                  robots_per_team={"blue": 1, "yellow": WANDERERS})
    f = settings.field_geometry()
    half = (f.half_length, f.half_width)
    rng = np.random.default_rng([seed, 41])
    world.place_ball(0.0, f.half_width + 0.15)  # in the boundary strip, out of the way
    x = f.half_length - LINE_OFFSET_M
    start = np.array([-x, rng.uniform(-half[1] + 0.5, half[1] - 0.5)])
    goal = np.array([x, rng.uniform(-half[1] + 0.5, half[1] - 0.5)])
    world.place_robot("blue", 0, float(start[0]), float(start[1]), 0.0)
    spots = rng.uniform((-x + 0.6, -half[1] + 0.3), (x - 0.6, half[1] - 0.3), (WANDERERS, 2))
    for i, (px, py) in enumerate(spots):
        world.place_robot("yellow", i, float(px), float(py), 0.0)
    targets = rng.uniform((-half[0] + 0.3, -half[1] + 0.3), (half[0] - 0.3, half[1] - 0.3), (WANDERERS, 2))
    speeds = rng.uniform(*WANDER_SPEED_M_S, WANDERERS)
    brain = Brain("blue", settings)
    intents = {0: Intent(float(goal[0]), float(goal[1]), 0.0)}
    game = GameState(0.0)
    radius = settings.field.robot.radius_m
    contacts = 0
    least = math.inf
    spent: list[float] = []
    arrived = math.nan
    for frame in range(round(TIMEOUT_S * sp.physics.frame_rate_hz)):
        seen = world.ground_truth().world()
        t0 = time.perf_counter()
        ours = brain.drive(seen, intents, game)
        if frame >= WARMUP_FRAMES:
            spent.append(time.perf_counter() - t0)
        events = world.step_frame([*ours, *_wander(world, targets, speeds, rng, half)])
        contacts += sum(isinstance(e, Contact) and ("blue", 0) in (e.a, e.b) for e in events)
        snap = world.snapshot().robots
        me = snap[snap[:, 0] == 0.0][0]
        others = snap[snap[:, 0] == 1.0]
        least = min(least, float(np.min(np.hypot(others[:, 2] - me[2], others[:, 3] - me[3]))) - 2 * radius)
        if math.hypot(me[2] - goal[0], me[3] - goal[1]) < ARRIVED_M:
            arrived = world.t
            break
    contacts += sum(("blue", 0) in (c.a, c.b) for c in world.open_contacts())
    return Crossing(contacts, arrived, least, float(np.median(spent)) * 1e3 if spent else 0.0)


def _crossing_rows(settings: Settings, seeds: list[int]) -> list[dict[str, Any]]:
    rows = []
    chosen = {"errt_trajectory_dss": settings, "robox_estar_dss": robox_settings(settings),
              "robox_estar": robox_settings(settings, safety=False)}
    for method in METHODS:
        s = chosen[method]
        trials = [crossing(s, seed) for seed in seeds]
        times = [t.time_s for t in trials if math.isfinite(t.time_s)]
        rows.append({
            "name": f"crossing_{method}", "trials": len(trials), "contacts": sum(t.contacts for t in trials),
            "time_to_goal_s": float(np.median(times)) if times else float("nan"),
            "min_clearance_m": float(np.median([t.min_clearance_m for t in trials])),
            "least_clearance_m": float(min(t.min_clearance_m for t in trials)),
            "incomplete": sum(not math.isfinite(t.time_s) for t in trials),
            "brain_ms": float(np.median([t.brain_ms for t in trials])),
        })
    return rows


def _match_rows(settings: Settings, seeds: list[int], seconds: float) -> list[dict[str, Any]]:
    """The shipped team against its Robox-stack copy, through the cameras, both colour ways."""
    robox = robox_settings(settings)
    rows: list[dict[str, Any]] = []
    for errt_blue in (True, False):
        blue, yellow = (settings, robox) if errt_blue else (robox, settings)
        pairing = "errt_vs_robox" if errt_blue else "robox_vs_errt"
        part = []
        for seed in seeds:
            wall = time.perf_counter()
            m = Match(blue, "self", "vision", seed=seed, opponent_settings=yellow)
            s = m.run(seconds)
            wall = time.perf_counter() - wall
            c = s["cycle_ms"]
            goals = (s["score"]["blue"], s["score"]["yellow"])
            own = (s["collisions"]["own"], s["opponent_team"]["collisions"]["own"])
            brain = (c["brain"]["median"], c["opponent_brain"]["median"])
            e, r = (0, 1) if errt_blue else (1, 0)  # which colour is which team
            part.append({
                "name": f"match_{pairing}_seed_{seed}", "goals_errt": goals[e], "goals_robox": goals[r],
                "own_collisions_errt": own[e], "own_collisions_robox": own[r],
                "brain_errt_ms": brain[e], "brain_robox_ms": brain[r], "realtime_factor": s["seconds"] / wall,
            })
        rows += part
        rows.append({
            "name": f"total_{pairing}_{len(part)}_matches_{seconds:.0f}s",
            "goals_errt": sum(p["goals_errt"] for p in part), "goals_robox": sum(p["goals_robox"] for p in part),
            "own_collisions_errt": sum(p["own_collisions_errt"] for p in part),
            "own_collisions_robox": sum(p["own_collisions_robox"] for p in part),
            "brain_errt_ms": float(np.median([p["brain_errt_ms"] for p in part])),
            "brain_robox_ms": float(np.median([p["brain_robox_ms"] for p in part])),
            "realtime_factor": float(np.median([p["realtime_factor"] for p in part])),
        })
    return rows


def run(settings: Settings, quick: bool) -> list[dict[str, Any]]:
    rows = _timing_rows(settings, 50 if quick else 500)
    rows += _crossing_rows(settings, list(range(4 if quick else 20)))
    rows += _match_rows(settings, [1, 2] if quick else list(range(1, 11)), 10.0 if quick else 30.0)
    return rows
