"""The safety benchmark's traversal in the simulator (ground truth): DSS keeps own robots apart where
the unguarded baseline collides, everyone arrives, and a seed fixes the trial."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from cmdragons.bench.safety import _layout, run_trial
from cmdragons.runtime.settings import load_settings

SETTINGS = load_settings(Path(__file__).resolve().parents[2] / "configs")


@pytest.mark.parametrize("n", [2, 4, 6, 11, 22])
def test_layout_crosses_the_field_from_both_sides_on_the_field(n: int) -> None:
    half_width = SETTINGS.field_geometry().half_width
    for seed in range(20):
        starts, goals = _layout(SETTINGS, n, np.random.default_rng(seed))
        assert np.all(np.sign(starts[:, 0]) == -np.sign(goals[:, 0]))
        assert sorted(np.sign(starts[:, 0])) == sorted([-1.0] * ((n + 1) // 2) + [1.0] * (n // 2))
        assert np.abs(np.vstack([starts, goals])[:, 1]).max() <= half_width - 0.1


@pytest.mark.slow
@pytest.mark.parametrize("seed", [0, 1])
def test_dss_traversal_has_no_collisions_and_completes(seed: int) -> None:
    dss = run_trial(SETTINGS, 6, "dss", "default", seed)
    assert dss.collisions == 0 and dss.completed
    none = run_trial(SETTINGS, 6, "none", "default", seed)
    assert none.completed
    # the same seed gives the same trial, timings aside
    again = run_trial(SETTINGS, 6, "dss", "default", seed)
    assert dataclasses.replace(again, brain_ms=0.0) == dataclasses.replace(dss, brain_ms=0.0)
