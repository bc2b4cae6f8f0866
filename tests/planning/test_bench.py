"""``cmdragons bench planning`` runs end to end on a tiny suite and reports every planner."""

from __future__ import annotations

from pathlib import Path

import pytest

from cmdragons.bench import SUITES
from cmdragons.bench.planning import Sizes, run
from cmdragons.runtime.settings import load_settings

CONFIGS = Path(__file__).resolve().parents[2] / "configs"


@pytest.mark.slow
def test_tiny_planning_suite_reports_every_planner() -> None:
    assert "planning" in SUITES
    sizes = Sizes(static_scenes=4, moving_scenes=1, frames=6, optimum_every=3, collision_queries=50, crowd_scenes=2)
    rows = {r["name"]: r for r in run(load_settings(CONFIGS), True, sizes)}
    for name in ("static_errt", "static_prm", "static_visgraph", "moving_errt_cache", "moving_errt_nocache"):
        row = rows[name]
        assert row["success_rate"] == 1.0, name
        assert 0 < row["median_ms"] <= row["p95_ms"]
        assert row["length_ratio"] >= 1.0 - 1e-9
    assert rows["static_visgraph"]["length_ratio"] == 1.0
    assert rows["visgraph_exactness"]["max_rel_error"] < 1e-3
    assert {"collision_masks_40", "collision_aabb_tree_40", "collision_linear_40", "nearest_kdtree_1000"} <= set(rows)
    assert {"waypoint_cache_speedup_moving_errt", "waypoint_cache_speedup_crowd_errt"} <= set(rows)
    # the crowd scenes are hard: every frame's straight line is blocked and ERRT has to search
    crowd = rows["crowd_errt_nocache"]
    assert crowd["blocked_frames"] == crowd["queries"] == 12 and crowd["median_iterations"] > 10
    assert rows["crowd_errt_cache"]["success_rate"] > 0.5  # a 2000-node budget can run out in a 30 mm gap
    assert "waypoint_cache_speedup_crowd_gap_120mm" in rows and "waypoint_cache_speedup_crowd_gap_60mm" in rows
    assert 0.3 < rows["crowd_errt_cache"]["waypoint_target_rate"] < 0.7  # p_waypoint = 0.5
    # OMPL is a benchmark extra: either its rows or a note that says why they are missing
    assert "static_ompl_rrtconnect" in rows or "not installed" in rows["ompl_baselines"]["note"]


def test_without_ompl_the_suite_says_so(monkeypatch) -> None:  # type: ignore[no-untyped-def]
    import cmdragons.bench.ompl_baseline as baseline

    monkeypatch.setattr(baseline, "ompl_missing", lambda: "ompl not installed (test)")
    sizes = Sizes(static_scenes=2, moving_scenes=1, frames=2, optimum_every=2, collision_queries=20, crowd_scenes=1)
    rows = {r["name"]: r for r in run(load_settings(CONFIGS), True, sizes)}
    assert not any("ompl" in name for name in rows if name != "ompl_baselines")
    assert "ompl not installed" in rows["ompl_baselines"]["note"]
