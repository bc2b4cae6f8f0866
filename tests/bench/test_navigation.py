"""The navigation bench's parts: the scene suite is seeded and hard (the straight line blocked),
every planner solves the U trap, a drive is the same for the same scene, the grid A* row finds the
least cost, the figures are written, and bad options stop with one line."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from cmdragons.bench.navigation import (
    MIN_CLEARANCE_M,
    _bug2_path_row,
    _planner_rows,
    draw,
    drive,
    grid_astar_row,
    scenes,
    u_trap,
)
from cmdragons.cli import main
from cmdragons.planning import PLANNERS
from cmdragons.planning.cells import grid_graph
from cmdragons.planning.graphsearch import search
from cmdragons.planning.termination import never
from cmdragons.runtime.settings import Settings, load_settings

CONFIGS = Path(__file__).resolve().parents[2] / "configs"


@pytest.fixture(scope="module")
def settings() -> Settings:
    return load_settings(CONFIGS)


def test_the_suite_is_seeded_and_every_straight_line_is_blocked(settings: Settings) -> None:
    f, r = settings.field_geometry(), settings.field.robot.radius_m
    a, b = scenes(f, r, 2, 2), scenes(f, r, 2, 2)
    assert [s.name for s in a] == ["static_0", "static_1", "moving_0", "moving_1", "u_trap"]
    for s, t in zip(a, b, strict=True):
        np.testing.assert_array_equal(s.world.circles, t.world.circles)
        assert (s.start, s.goal) == (t.start, t.goal)
        cw = s.world.compile(r)
        assert not cw.segment_free(s.start, s.goal)
        assert min(cw.clearance(*s.start), cw.clearance(*s.goal)) >= MIN_CLEARANCE_M


def test_every_planner_solves_the_u_trap(settings: Settings) -> None:
    paths: dict[str, dict[str, np.ndarray]] = {}
    trap = u_trap(settings.field_geometry())
    rows, optimum, record = _planner_rows(settings, [trap], 1, 1, paths, lambda _: None)
    fixed = {r["name"]: r for r in rows if r["name"].startswith("planner/")}
    assert set(fixed) == {f"planner/{n}" for n in PLANNERS}
    for name, row in fixed.items():
        assert row["success_rate"] == 1.0 and row["trap"] == 1, name
        assert row["length_ratio"] >= 1.0 - 2e-3, name  # none shorter than the optimum (visgraph's polyline)
    assert optimum["u_trap"][0] > 4.0  # round the U: longer than the 4 m straight line
    assert set(paths["u_trap"]) == {f"planner {n}" for n in PLANNERS}


def test_a_drive_is_the_same_for_the_same_scene(settings: Settings) -> None:
    f, r = settings.field_geometry(), settings.field.robot.radius_m
    moving = scenes(f, r, 0, 1)[0]
    a = drive(settings, "dynamic_window", moving, 3.0)
    b = drive(settings, "dynamic_window", moving, 3.0)
    assert a[0] == b[0] and a[3] == b[3]
    np.testing.assert_array_equal(a[1], b[1])
    assert np.hypot(*(a[1][-1] - a[1][0])) > 1.0  # it drove off toward the goal


def test_the_whole_path_bug2_row_leaves_the_trap_beside_the_toolbox_s(settings: Settings) -> None:
    pytest.importorskip("roboticstoolbox")
    trap = u_trap(settings.field_geometry())
    paths: dict[str, dict[str, np.ndarray]] = {}
    _, optimum, _ = _planner_rows(settings, [trap], 1, 1, {}, lambda _: None)
    row = _bug2_path_row(settings, [trap], optimum, 1, paths)
    assert row["our_success_rate"] == 1.0 and row["our_trap"] == 1 and row["success_rate"] == 1.0
    assert min(row["our_length_ratio"], row["length_ratio"]) >= 1.0 - 2e-3  # neither beats the optimum
    np.testing.assert_allclose(paths["u_trap"]["bug2_path (grid)"][[0, -1]], [trap.start, trap.goal])


def test_the_grid_astar_row_finds_the_least_cost() -> None:
    free = np.ones((40, 60), dtype=bool)
    free[5:35, 30] = False
    row = grid_astar_row("wall", free, (2, 20), (57, 20), 1)
    graph = grid_graph(free, 0.0, 0.0, 1.0, 8)
    node = np.cumsum(free.ravel()) - 1
    least = search(graph, int(node[20 * 60 + 2]), int(node[20 * 60 + 57]), "dijkstra", never()).cost
    assert row["length"] == pytest.approx(least, rel=1e-12)
    assert "ratio_to_pyastar2d" in row or "not installed" in row["note"]


def test_the_figures_are_written(settings: Settings, tmp_path: Path) -> None:
    trap = u_trap(settings.field_geometry())
    out = draw(trap, {"a": np.array([trap.start, trap.goal]), "b": np.array([trap.start, (0.0, 2.0), trap.goal])},
               tmp_path, 0.09)
    assert out == tmp_path / "u_trap.png" and out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_bad_figure_options_stop_with_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    file = tmp_path / "a_file"
    file.write_text("x")
    assert main(["bench", "navigation", "--quick", "--figures", str(file)]) == 2
    assert main(["bench", "sim", "--quick", "--figures", str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"cmdragons bench: --figures {file} is a file, not a folder",
                   "cmdragons bench: --figures is for the navigation suite, not sim"]
