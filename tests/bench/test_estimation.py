"""The estimation bench: the run is seeded and has at most one sighting a step; the toolbox's EKFs,
replaying our run, give our EKFs' estimates (the same algebra on the same data); the rows are
scored against the truth; without the toolbox our rows stand alone with the reason."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from cmdragons.bench import estimation as bench
from cmdragons.runtime.settings import load_settings

CONFIGS = Path(__file__).resolve().parents[2] / "configs"
STEPS = 120


def test_the_run_is_seeded_with_one_sighting_a_step() -> None:
    a, b = bench.bench_run(STEPS), bench.bench_run(STEPS)
    np.testing.assert_array_equal(a.truth, b.truth)
    assert all(len(s) <= 1 for s in a.sightings)
    assert sum(len(s) for s in a.sightings) > STEPS // 2  # landmarks are in range most of the time
    assert all(u[1] == 0.0 for u in a.odometry)  # no sideways odometry: the toolbox's model has none


# method: RMS position error bound (m), mean NEES bounds (3 for a consistent filter), least fraction in 95%
BOUNDS = {
    "ekf_localisation": (0.1, 1.0, 6.0, 0.8),
    # the map's frame is known no better than the start pose (0.1 m, 0.03 rad off at 7 m from the centre)
    "ekf_slam": (0.5, 1.0, 6.0, 0.8),
    # 500 particles, regularised after each resampling: over the bench's full run the mean NEES is
    # about 2.5 with 95% of the steps inside the interval; its first 120 steps read a little wider
    "particle_filter": (0.1, 1.0, 6.0, 0.8),
}


@pytest.mark.parametrize("method", bench.METHODS)
def test_our_filters_track_the_truth_and_are_consistent(method: str) -> None:
    row = bench.ours(method, bench.bench_run(STEPS)).row(method)
    rms, lo, hi, inside = BOUNDS[method]
    assert row["rms_error_m"] < rms
    assert lo < row["mean_nees"] < hi
    assert row["nees_in_95"] > inside


@pytest.mark.parametrize("method", ["ekf_localisation", "ekf_slam"])
def test_the_toolbox_ekf_on_our_run_gives_our_estimates(method: str) -> None:
    pytest.importorskip("roboticstoolbox", reason="roboticstoolbox-python not installed (the bench extra)")
    run = bench.bench_run(STEPS)
    mine, peer = bench.ours(method, run), bench.toolbox(method, run)
    np.testing.assert_allclose(mine.error_m, peer.error_m, atol=1e-9)  # metres
    np.testing.assert_allclose(mine.nees, peer.nees, rtol=1e-6)


def test_the_toolbox_particle_filter_tracks_our_run() -> None:
    pytest.importorskip("roboticstoolbox", reason="roboticstoolbox-python not installed (the bench extra)")
    peer = bench.toolbox("particle_filter", bench.bench_run(STEPS)).row("pf")
    assert peer["rms_error_m"] < BOUNDS["particle_filter"][0]


def test_without_the_toolbox_our_rows_stand_alone(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(bench, "QUICK_STEPS", 30)
    monkeypatch.setitem(sys.modules, "roboticstoolbox", None)  # import raises ImportError
    rows = bench.run(load_settings(CONFIGS), quick=True)
    assert [r["name"] for r in rows] == list(bench.METHODS)
    assert all(r["peer"] == bench.MISSING and r["error_ratio"] is None for r in rows)


def test_with_the_toolbox_every_method_has_its_peer_row(monkeypatch: pytest.MonkeyPatch) -> None:
    pytest.importorskip("roboticstoolbox", reason="roboticstoolbox-python not installed (the bench extra)")
    monkeypatch.setattr(bench, "QUICK_STEPS", 30)
    rows = bench.run(load_settings(CONFIGS), quick=True)
    assert [r["name"] for r in rows] == [n for m in bench.METHODS for n in (m, f"{m}_toolbox")]
    for mine, peer in zip(rows[::2], rows[1::2], strict=True):
        assert mine["error_ratio"] == pytest.approx(mine["rms_error_m"] / peer["rms_error_m"])
