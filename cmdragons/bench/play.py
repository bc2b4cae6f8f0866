"""``cmdragons bench play``: seeded matches against the simple opponent, our team seeing through the
cameras; and the brain's cycle for 11 v 11 in division A.

Rows per match (goals for and against, shots, passes, own collisions, stage times), a totals row
(matches won, drawn, lost; pass completion; own collisions), and the brain's cycle time (tracker to
commands) for 6 and 11 robots. ``--quick`` plays two 60 s matches instead of ten of 3 minutes.
"""

from __future__ import annotations

import dataclasses
import time
from typing import Any

import numpy as np

from cmdragons.runtime.match import Match
from cmdragons.runtime.settings import Settings

__all__ = ["run"]


def _match_row(settings: Settings, seed: int, seconds: float) -> dict[str, Any]:
    wall = time.perf_counter()
    m = Match(settings, "simple", "vision", seed=seed)
    s = m.run(seconds)
    wall = time.perf_counter() - wall
    c = s["cycle_ms"]
    return {
        "name": f"match_seed_{seed}",
        "goals_for": s["score"]["blue"],
        "goals_against": s["score"]["yellow"],
        "shots": s["shots"],
        "passes_tried": s["passes"]["tried"],
        "passes_completed": s["passes"]["completed"],
        "own_collisions": s["collisions"]["own"],
        "brain_median_ms": c["brain"]["median"],
        "brain_p95_ms": c["brain"]["p95"],
        "tracker_median_ms": c["tracker"]["median"],
        "vision_median_ms": c["vision"]["median"],
        "frame_median_ms": c["frame"]["median"],
        "realtime_factor": s["seconds"] / wall,
    }


def _brain_cycle(settings: Settings, division: str, seconds: float) -> dict[str, Any]:
    """Tracker and brain on noisy true detections, 6 or 11 robots a side: the brain's own cost."""
    league = dataclasses.replace(settings.field, division=division)  # type: ignore[arg-type]
    s = dataclasses.replace(settings, field=league)
    m = Match(s, "self", "truth", seed=3)
    m.run(seconds)
    brain = m.stage_ms["brain"]
    tracker = m.stage_ms["tracker"]
    cycle = np.array(brain) + np.array(tracker)
    return {"name": f"brain_cycle_{league.dims.robots_per_team}_robots", "median_ms": float(np.median(cycle)),
            "p95_ms": float(np.percentile(cycle, 95)), "brain_median_ms": float(np.median(brain)),
            "tracker_median_ms": float(np.median(tracker))}  # fmt: skip


def run(settings: Settings, quick: bool) -> list[dict[str, Any]]:
    seeds = [1, 2] if quick else list(range(1, 11))
    seconds = 60.0 if quick else 180.0
    rows = [_match_row(settings, seed, seconds) for seed in seeds]
    won = sum(r["goals_for"] > r["goals_against"] for r in rows)
    lost = sum(r["goals_for"] < r["goals_against"] for r in rows)
    tried = sum(r["passes_tried"] for r in rows)
    rows.append({
        "name": f"total_{len(rows)}_matches_{seconds:.0f}s",
        "won": won, "drawn": len(rows) - won - lost, "lost": lost,
        "goals_for": sum(r["goals_for"] for r in rows), "goals_against": sum(r["goals_against"] for r in rows),
        "pass_completion": sum(r["passes_completed"] for r in rows) / tried if tried else float("nan"),
        "own_collisions": sum(r["own_collisions"] for r in rows),
        "realtime_factor": float(np.median([r["realtime_factor"] for r in rows])),
    })  # fmt: skip
    rows.append(_brain_cycle(settings, "B", 10.0 if quick else 30.0))
    rows.append(_brain_cycle(settings, "A", 10.0 if quick else 30.0))
    return rows
