"""``cmdragons bench grid [--maps DIR]``: the grid planners on Moving AI maps, beside their peers.

For every ``.map`` with its ``.map.scen`` in the folder (default ``../shared/benchdata/moving_ai``
beside the repository):

- ``dijkstra8`` / ``astar8``: the 8-connected search on every scenario; ``max_error`` is the largest
  difference to the scenario's optimal length (must be 0 to 1e-6).
- ``estar``: E* toward the goal and the path down its field from the start, on every scenario; the
  path's length against the 8-connected optimum (``ratio_*``: E* cuts corners as any-angle paths do,
  so 0.90 to 1.0 is expected), how many came out in that range, and against the straight line
  from start to goal (``to_straight_line_min`` >= 1: no path is shorter than the straight line; a
  short path round clutter can be more than 10% under the 8-connected one and still be real).

On the first map (or the one named ``8room_000``), side by side in one process:

- ``estar8_full`` and ``estar4_full`` (the interpolation on the 8- and on the 4-neighbourhood, the
  latter the thesis' kernel and the same stencil as fast marching) against scikit-fmm's ``distance``
  on the same grid (``skfmm``, in the bench extra), one call each in turn, and how far the fields are
  apart (``field_diff_*_pct``, beyond five cells from the goal);
- ``estar_repair``: one robot-sized obstacle (a disc of ``BLOB_RADIUS`` cells) moved and the field
  repaired, against recomputing it from scratch;
- ``nf1``: the NF1 wavefront, against the Robotics Toolbox's DistanceTransformPlanner on the same
  map (``roboticstoolbox-python``, in the bench extra), and E*'s repair against the toolbox's D*
  replanning on a 128 x 128 crop.

``--quick`` takes every 25th scenario and fewer repetitions. Peers that are not installed give a row
saying so.
"""

from __future__ import annotations

import math
import statistics
import time
from collections.abc import Callable
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from cmdragons.planning.grid import EStar, nf1, octile_path, read_map, read_scenarios
from cmdragons.runtime.settings import Settings

__all__ = ["default_maps", "run"]

BLOB_RADIUS = 4  # cells: a robot (0.18 m across) on a 2-3 cm grid
ROOT = Path(__file__).resolve().parents[2]


def default_maps() -> Path:
    return ROOT.parent / "shared" / "benchdata" / "moving_ai"


def _median_ms(fn: Callable[[], Any], repeats: int) -> float:
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append((time.perf_counter() - t0) * 1e3)
    return statistics.median(times)


def _cost(free: NDArray[np.bool_]) -> NDArray[np.float64]:
    return np.where(free, 1.0, np.inf)


def _map_rows(name: str, free: NDArray[np.bool_], scen_path: Path, quick: bool) -> list[dict[str, Any]]:
    cost = _cost(free)
    scenarios = read_scenarios(scen_path)
    if quick:
        scenarios = scenarios[::25]
    rows: list[dict[str, Any]] = []
    for label, astar in (("dijkstra8", False), ("astar8", True)):
        errors, times = [], []
        for sc in scenarios:
            t0 = time.perf_counter()
            p = octile_path(cost, (sc.start[1], sc.start[0]), (sc.goal[1], sc.goal[0]), astar=astar)
            times.append((time.perf_counter() - t0) * 1e3)
            errors.append(abs(p.length - sc.optimal))
        rows.append({"name": f"{label}/{name}", "scenarios": len(scenarios), "max_error": max(errors),
                     "median_ms": statistics.median(times), "max_ms": max(times)})
    ratios, to_line, times, failed = [], [], [], 0
    for sc in scenarios:
        t0 = time.perf_counter()
        e = EStar.from_point(cost, (float(sc.goal[0]), float(sc.goal[1])))
        e.compute(until=(sc.start[1], sc.start[0]))
        p = e.path((float(sc.start[0]), float(sc.start[1])))
        times.append((time.perf_counter() - t0) * 1e3)
        if not p.found:
            failed += 1
        elif sc.optimal > 0:
            ratios.append(p.length / sc.optimal)
            to_line.append(p.length / math.dist(sc.start, sc.goal))
    inside = sum(0.90 <= r <= 1.0 + 1e-9 for r in ratios)
    rows.append({"name": f"estar/{name}", "scenarios": len(scenarios), "no_path": failed,
                 "ratio_min": min(ratios), "ratio_median": statistics.median(ratios), "ratio_max": max(ratios),
                 "in_0.9_1.0": inside / max(1, len(ratios)), "to_straight_line_min": min(to_line),
                 "median_ms": statistics.median(times)})
    return rows


def _blob(free: NDArray[np.bool_], rng: np.random.Generator, goal: tuple[int, int]) -> NDArray[np.int64]:
    """The cells of a robot-sized disc at a random free spot clear of the goal's seeded disc."""
    h, w = free.shape
    cells = np.argwhere(free)
    away = np.hypot(cells[:, 0] - goal[0], cells[:, 1] - goal[1]) > BLOB_RADIUS + 7
    cells = cells[away] if away.any() else cells
    r, c = cells[rng.integers(len(cells))]
    span = range(-BLOB_RADIUS, BLOB_RADIUS + 1)
    out = [(r + dr, c + dc) for dr in span for dc in span
           if dr * dr + dc * dc <= BLOB_RADIUS**2 and 0 <= r + dr < h and 0 <= c + dc < w and free[r + dr, c + dc]]
    return np.array(out, dtype=np.int64)


def _speed_rows(name: str, free: NDArray[np.bool_], quick: bool) -> list[dict[str, Any]]:
    cost = _cost(free)
    rng = np.random.default_rng(1)
    cells = np.argwhere(free)
    gr, gc = (int(v) for v in cells[len(cells) // 2])
    repeats = 3 if quick else 9
    rows: list[dict[str, Any]] = []

    def full(neighbours: int = 8) -> EStar:
        e = EStar.from_point(cost, (float(gc), float(gr)), neighbours)
        e.compute()
        return e

    full(), full(4)  # compile
    field = full().value
    try:
        import skfmm
    except ImportError:
        skfmm = None
    if skfmm is not None:
        phi = np.ma.MaskedArray(np.hypot(*(np.mgrid[0 : free.shape[0], 0 : free.shape[1]] - np.array(
            [gr, gc])[:, None, None])) - 2.0, mask=~free)
        skfmm.distance(phi)
    for neighbours in (8, 4):
        # side by side, one call each in turn (a loaded machine slows both alike)
        ours, theirs = [], []
        for _ in range(repeats):
            ours.append(_median_ms(partial(full, neighbours), 1))
            if skfmm is not None:
                theirs.append(_median_ms(lambda: skfmm.distance(phi), 1))
        row: dict[str, Any] = {"name": f"estar{neighbours}_full/{name}", "median_ms": statistics.median(ours)}
        if skfmm is None:
            row["skfmm"] = "not installed (pip install -e '.[bench]')"
        else:
            d = np.ma.filled(skfmm.distance(phi), np.nan) + 2.0
            v = field if neighbours == 8 else full(4).value
            far = np.isfinite(v) & np.isfinite(d) & (d > 5.0)
            rel = np.abs(v[far] - d[far]) / d[far] * 100
            row |= {"skfmm_median_ms": statistics.median(theirs),
                    "ratio_to_skfmm": statistics.median([a / b for a, b in zip(ours, theirs, strict=True)]),
                    "field_diff_median_pct": float(np.median(rel)), "field_diff_p95_pct": float(np.percentile(rel, 95))}
        rows.append(row)

    # repair: one robot-sized obstacle moved, against recomputing
    e = full()
    blob = _blob(free, rng, (gr, gc))
    e.set_costs(blob, np.inf)
    e.compute()
    repair_ms, fresh_ms, touched = [], [], []
    for _ in range(repeats * 3):
        new = _blob(free, rng, (gr, gc))
        t0 = time.perf_counter()
        e.set_costs(blob, 1.0)
        e.set_costs(new, np.inf)
        e.compute()
        repair_ms.append((time.perf_counter() - t0) * 1e3)
        touched.append(e.pops)
        blob = new
    moved = cost.copy()
    moved[blob[:, 0], blob[:, 1]] = np.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        f = EStar.from_point(moved, (float(gc), float(gr)))
        f.compute()
        fresh_ms.append((time.perf_counter() - t0) * 1e3)
    known = np.isfinite(f.value)
    same = float(np.max(np.abs(f.value[known] - e.value[known]), initial=0.0)) if known.any() else 0.0
    if not np.array_equal(known, np.isfinite(e.value)):
        same = math.inf  # a cell known to one field and not to the other
    rows.append({"name": f"estar_repair/{name}", "median_ms": statistics.median(repair_ms),
                 "full_median_ms": statistics.median(fresh_ms),
                 "speedup_vs_full": statistics.median(fresh_ms) / statistics.median(repair_ms),
                 "cells_median": statistics.median(touched), "max_diff_to_full": float(same)})

    nf1(free, (gr, gc))
    nf1_ms = _median_ms(lambda: nf1(free, (gr, gc)), repeats)
    row = {"name": f"nf1/{name}", "median_ms": nf1_ms}
    rtb_ms = _toolbox_plan_ms("DistanceTransformPlanner", free, (gc, gr), metric="manhattan")
    if rtb_ms is None:
        row["rtb"] = "not installed (pip install -e '.[bench]')"
    else:
        row |= {"rtb_distance_transform_ms": rtb_ms, "speedup_vs_rtb": rtb_ms / nf1_ms}
    rows.append(row)
    rows.append(_dstar_row(free, quick))
    return rows


def _dstar_row(free: NDArray[np.bool_], quick: bool) -> dict[str, Any]:
    """E*'s repair against the Robotics Toolbox's D* on a 128 x 128 crop: the first plan and a replan
    after a robot-sized obstacle appears."""
    h, w = free.shape
    n = min(128, h, w)
    crop = free[(h - n) // 2 : (h - n) // 2 + n, (w - n) // 2 : (w - n) // 2 + n].copy()
    cells = np.argwhere(crop)
    gr, gc = (int(v) for v in cells[0])
    cost = _cost(crop)
    t0 = time.perf_counter()
    e = EStar.from_point(cost, (float(gc), float(gr)))
    e.compute()
    plan_ms = (time.perf_counter() - t0) * 1e3
    blob = _blob(crop, np.random.default_rng(2), (gr, gc))
    t0 = time.perf_counter()
    e.set_costs(blob, np.inf)
    e.compute()
    replan_ms = (time.perf_counter() - t0) * 1e3
    row: dict[str, Any] = {"name": f"estar_vs_dstar/{n}x{n}", "plan_ms": plan_ms, "replan_ms": replan_ms}
    rtb_plan = _toolbox_plan_ms("DstarPlanner", crop, (gc, gr))
    if rtb_plan is None:
        row["rtb"] = "not installed (pip install -e '.[bench]')"
    else:
        row |= {"rtb_dstar_plan_ms": rtb_plan, "speedup_plan": rtb_plan / plan_ms}
    return row


def _toolbox_plan_ms(planner: str, free: NDArray[np.bool_], goal_xy: tuple[int, int], **kwargs: Any) -> float | None:
    """Milliseconds the Robotics Toolbox's ``planner`` takes to plan toward ``goal_xy`` on the grid
    (None when the toolbox is not installed)."""
    try:
        import roboticstoolbox
    except ImportError:
        return None
    # by keyword: D*'s first argument is a cost map (free cells would cost nothing), not the occupancy grid
    p = getattr(roboticstoolbox, planner)(occgrid=(~free).astype(int), **kwargs)
    t0 = time.perf_counter()
    p.plan(goal=goal_xy)
    return (time.perf_counter() - t0) * 1e3


def run(settings: Settings, quick: bool, maps: Path | None = None) -> list[dict[str, Any]]:
    folder = Path(maps) if maps is not None else default_maps()
    pairs = [(p, p.with_name(p.name + ".scen")) for p in sorted(folder.glob("*.map"))]
    pairs = [(m, s) for m, s in pairs if s.exists()]
    if not pairs:
        raise FileNotFoundError(f"no .map file with its .map.scen in {folder}")
    rows: list[dict[str, Any]] = []
    speed_map = next((m for m, _ in pairs if m.stem == "8room_000"), pairs[0][0])
    for map_path, scen_path in pairs:
        free = read_map(map_path)
        rows += _map_rows(map_path.stem, free, scen_path, quick)
    rows += _speed_rows(speed_map.stem, read_map(speed_map), quick)
    return [{k: (float(v) if isinstance(v, np.floating) else v) for k, v in r.items()} for r in rows]
