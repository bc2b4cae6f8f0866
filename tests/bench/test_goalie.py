"""The goalie bench: the shots are seeded, start outside our defense area and aim inside our goal
mouth; a straight shot at the goal's centre scores in an empty goal and is saved by our goalie."""

from __future__ import annotations

from pathlib import Path

import pytest

from cmdragons.bench import goalie as bench
from cmdragons.runtime.settings import Settings, load_settings

CONFIGS = Path(__file__).resolve().parents[2] / "configs"


@pytest.fixture(scope="module")
def settings() -> Settings:
    return load_settings(CONFIGS)


def test_the_shots_are_seeded_from_outside_our_area_at_our_goal_mouth(settings: Settings) -> None:
    f = settings.field_geometry()
    a, b = bench.shots(40, 3, settings), bench.shots(40, 3, settings)
    assert a == b and a != bench.shots(40, 4, settings)
    for k, shot in enumerate(a):
        assert shot.point[0] > f.dims.defense_depth_m and abs(shot.point[1]) < f.half_width
        assert abs(shot.target_y_m) < f.goal_half_width
        assert (shot.pass_speed_m_s > 0.0) == bool(k % 2)  # every other shot follows a pass
        assert f.dims.defense_depth_m < shot.pass_from[0] < 2.0 * f.half_length - f.dims.defense_depth_m


@pytest.mark.parametrize("reflex", [False, True])
def test_a_straight_shot_scores_in_an_empty_goal_and_our_goalie_saves_it(settings: Settings, reflex: bool) -> None:
    shot = bench.Shot((3.0, 0.4), (3.0, 0.4), 0.0, 0.0, 4.0)
    assert bench.shoot(settings, shot, goalie=False)
    assert not bench.shoot(bench.with_reflex(settings, reflex), shot)
