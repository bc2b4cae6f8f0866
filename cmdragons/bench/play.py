"""``cmdragons bench play``: seeded matches against the simple opponent under the league's full rules,
our team seeing through the cameras; and the brain's cycle for 11 v 11 in division A.

A match is two halves of the rules' duration (5 minutes each; the half-time break, in which nothing
moves, is not simulated), the sides changed between them. Rows per match (goals for and against,
shots, passes, own collisions, fouls and cards per team, our placements tried and succeeded, stage
times), a totals row (matches won, drawn, lost; pass completion; own collisions; our fouls by kind,
per match; placements succeeded and their median time), and the brain's cycle time (tracker to
commands) for 6 and 11 robots. ``--quick`` plays two matches of two 30 s halves.
"""

from __future__ import annotations

import dataclasses
import time
from typing import Any

import numpy as np

from cmdragons.runtime.match import Match
from cmdragons.runtime.settings import Settings

__all__ = ["run"]


def _halves(settings: Settings, half_s: float) -> Settings:
    """Full rules, halves of ``half_s`` and no half-time break to wait out."""
    ref = settings.sim.referee
    ref = dataclasses.replace(ref, rules="full", figures=dataclasses.replace(ref.figures, half_s=half_s,
                                                                               half_time_s=0.0))  # fmt: skip
    return dataclasses.replace(settings, sim=dataclasses.replace(settings.sim, referee=ref))


def _match_row(settings: Settings, seed: int, seconds: float) -> dict[str, Any]:
    wall = time.perf_counter()
    m = Match(settings, "simple", "vision", seed=seed)
    s = m.run(seconds)
    wall = time.perf_counter() - wall
    c = s["cycle_ms"]
    rules = s["rules"]
    ours, theirs = rules["fouls"]["blue"], rules["fouls"]["yellow"]
    placed = rules["placements"]["blue"]
    return {
        "name": f"match_seed_{seed}",
        "goals_for": s["score"]["blue"],
        "goals_against": s["score"]["yellow"],
        "shots": s["shots"],
        "passes_tried": s["passes"]["tried"],
        "passes_completed": s["passes"]["completed"],
        "own_collisions": s["collisions"]["own"],
        "fouls_ours": ours["total"],
        "fouls_theirs": theirs["total"],
        "fouls_ours_by_kind": _kinds_text({k: v for k, v in ours.items() if k != "total"}),
        "_kinds": {k: v for k, v in ours.items() if k != "total"},
        "yellow_cards_ours": rules["cards"]["blue"]["yellow"],
        "red_cards_ours": rules["cards"]["blue"]["red"],
        "yellow_cards_theirs": rules["cards"]["yellow"]["yellow"],
        "placements_tried": placed["tried"],
        "placements_succeeded": placed["succeeded"],
        "placement_median_s": placed["median_s"],
        "brain_median_ms": c["brain"]["median"],
        "brain_p95_ms": c["brain"]["p95"],
        "tracker_median_ms": c["tracker"]["median"],
        "vision_median_ms": c["vision"]["median"],
        "frame_median_ms": c["frame"]["median"],
        "realtime_factor": s["seconds"] / wall,
    }


def _kinds_text(kinds: dict[str, int]) -> str:
    """Fouls by kind as one line ("crash 1, stop speed 2"; "none")."""
    return ", ".join(f"{k.replace('_', ' ')} {n}" for k, n in kinds.items()) or "none"


def _sum_kinds(per_match: list[dict[str, int]]) -> dict[str, int]:
    out: dict[str, int] = {}
    for kinds in per_match:
        for k, n in kinds.items():
            out[k] = out.get(k, 0) + n
    return dict(sorted(out.items()))


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
    half = 30.0 if quick else settings.sim.referee.figures.half_s
    seconds = 2.0 * half
    rules = _halves(settings, half)
    rows = [_match_row(rules, seed, seconds) for seed in seeds]
    won = sum(r["goals_for"] > r["goals_against"] for r in rows)
    tried_placing = sum(r["placements_tried"] for r in rows)
    placed = sum(r["placements_succeeded"] for r in rows)
    lost = sum(r["goals_for"] < r["goals_against"] for r in rows)
    tried = sum(r["passes_tried"] for r in rows)
    rows.append({
        "name": f"total_{len(rows)}_matches_{seconds:.0f}s",
        "won": won, "drawn": len(rows) - won - lost, "lost": lost,
        "goals_for": sum(r["goals_for"] for r in rows), "goals_against": sum(r["goals_against"] for r in rows),
        "pass_completion": sum(r["passes_completed"] for r in rows) / tried if tried else float("nan"),
        "own_collisions": sum(r["own_collisions"] for r in rows),
        "fouls_ours_per_match": sum(r["fouls_ours"] for r in rows) / len(rows),
        "fouls_theirs_per_match": sum(r["fouls_theirs"] for r in rows) / len(rows),
        "fouls_ours_by_kind": _kinds_text(_sum_kinds([r.pop("_kinds") for r in rows])),
        "cards_ours": sum(r["yellow_cards_ours"] + r["red_cards_ours"] for r in rows),
        "placements_succeeded_share": placed / tried_placing if tried_placing else float("nan"),
        "realtime_factor": float(np.median([r["realtime_factor"] for r in rows])),
    })  # fmt: skip
    rows.append(_brain_cycle(settings, "B", 10.0 if quick else 30.0))
    rows.append(_brain_cycle(settings, "A", 10.0 if quick else 30.0))
    return rows
