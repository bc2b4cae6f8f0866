"""Config loading: every kind of mistake gets a message naming the file, the key and what is allowed."""

from __future__ import annotations

import dataclasses
import shutil
from collections.abc import Mapping
from pathlib import Path

import numpy as np
import pytest

from cmdragons.config import ConfigError, Validated
from cmdragons.control import motion_commands
from cmdragons.messages import BallState, GameState, RobotState, WorldState
from cmdragons.runtime.settings import CONCERNS, load_settings
from cmdragons.safety.registry import make_safety
from cmdragons.team import Brain
from sim.params import SimParams
from strategy.skills import Intent

REPO_CONFIGS = Path(__file__).resolve().parents[2] / "configs"


@pytest.fixture()
def configs(tmp_path: Path) -> Path:
    folder = tmp_path / "configs"
    shutil.copytree(REPO_CONFIGS, folder)
    return folder


def test_shipped_configs_equal_the_dataclass_defaults() -> None:
    # the YAML files show every default; they must not drift from the code's defaults
    s = load_settings(REPO_CONFIGS)
    for name, cls in CONCERNS.items():
        assert getattr(s, name) == cls(), name
    assert sorted(p.stem for p in REPO_CONFIGS.glob("*.yaml")) == sorted(CONCERNS)


def test_each_fact_is_configured_once_and_reaches_every_user() -> None:
    s = load_settings(REPO_CONFIGS, ["field.robot.max_accel_m_s2=2.5", "field.robot.command_latency_s=0.05",
                                     "field.ball.acc_roll_m_s2=0.3"])
    assert s.sim.robot.max_accel_m_s2 == s.tracker.robot.max_accel_m_s2 == 2.5
    assert s.sim.robot.command_latency_s == s.tracker.latency_s == 0.05
    assert s.sim.ball.acc_roll_m_s2 == s.tracker.ball.acc_roll_m_s2 == 0.3


@pytest.mark.parametrize("brake", [4.0, 6.0])
def test_the_robots_braking_reaches_control_the_brains_path_following_and_safety(brake: float) -> None:
    # one source: field.yaml robot; a robot at 2 m/s along +x, dt one control period
    s = load_settings(REPO_CONFIGS, [f"field.robot.max_brake_m_s2={brake}"])
    v, dt = 2.0, s.control.motion.period_s
    # control: told to stop where it is, it brakes at full strength for one period
    cmd = motion_commands([[0.0, 0.0, 0.0, v, 0.0, 0.0]], [[0.0, 0.0, 0.0, 0.0, 0.0]], s.control)
    assert cmd[0] == pytest.approx((v - brake * dt, 0.0, 0.0), abs=1e-12)
    # the brain (planner, navigator, safety) driving it to a goal 0.3 m ahead, nearer than it can stop
    # at either figure (v^2 / 2 brake: 0.5 and 0.33 m): it brakes at full strength
    w = WorldState(0.0, BallState(3.0, 2.0, 0.0, 0.0), (RobotState("blue", 0, -1.0, 0.0, 0.0, v, 0.0),))
    (out,) = Brain("blue", s).drive(w, {0: Intent(-0.7, 0.0, 0.0)}, GameState(0.0))
    assert (out.vx, out.vy) == pytest.approx((v - brake * dt, 0.0), abs=1e-12)
    # the safety search: a robot asked to stop rests v^2 / (2 brake) on; one that keeps its speed, a
    # period later plus that
    safety = make_safety(s.safety, s.control, s.field.robot.radius_m, None)
    for asked, rest_m in (((0.0, 0.0), v * v / (2 * brake)), ((v, 0.0), v * dt + v * v / (2 * brake))):
        braking = safety.filter([[0.0, 0.0, v, 0.0]], [asked], np.zeros((0, 4))).braking[0]
        assert braking[-1] == pytest.approx((rest_m, 0.0), abs=1e-12)


def test_control_yaml_refuses_the_robots_limits() -> None:
    with pytest.raises(ConfigError, match="configured once, as field.robot.max_brake_m_s2"):
        load_settings(REPO_CONFIGS, ["control.motion.max_brake_m_s2=4"])


def test_a_derived_value_built_in_code_is_still_range_checked() -> None:
    from sim.world import RobotParams

    with pytest.raises(ValueError, match="max_accel_m_s2"):
        RobotParams(max_accel_m_s2=-1.0)


@pytest.mark.parametrize(
    ("file", "text", "key", "fragment"),
    [
        ("sim.yaml", "physics:\n  substepz: 4\n", "physics.substepz", "unknown key; allowed keys:"),
        ("sim.yaml", "physics:\n  substeps: fast\n", "physics.substeps", "expected an integer"),
        ("sim.yaml", "physics:\n  substeps: 0\n", "physics.substeps", "out of range; allowed: 1 to 100"),
        ("field.yaml", "robot:\n  max_speed_m_s: -1.0\n", "robot.max_speed_m_s", "allowed: 0.01 to 10.0"),
        ("sim.yaml", "robot:\n  max_speed_m_s: 2.0\n", "robot.max_speed_m_s", "configured once, as field.robot"),
        ("tracker.yaml", "ball:\n  acc_roll_m_s2: 0.3\n", "ball.acc_roll_m_s2", "as field.ball.acc_roll_m_s2"),
        ("field.yaml", "division: C\n", "division", "allowed: 'A', 'B'"),
        ("sim.yaml", "physics:\n  wall_elasticity: .nan\n", "physics.wall_elasticity", "finite"),
        ("cameras.yaml", "auto:\n  grid: [2]\n", "auto.grid", "a list of 2 values"),
        ("field.yaml", "robot:\n  front_distance_m: 0.2\n", "robot", "smaller than radius_m"),
        ("planner.yaml", "planner: astar\n", "planner", "allowed: 'errt', 'prm', 'visgraph'"),
        ("safety.yaml", "method: magic\n", "method", "allowed: 'none', 'dss'"),
        ("safety.yaml", "dss:\n  own_margin_m: -0.1\n", "dss.own_margin_m", "allowed: 0.0 to 1.0"),
        ("planner.yaml", "errt:\n  p_goal: 0.6\n  p_waypoint: 0.6\n", "errt", "p_goal + p_waypoint"),
        ("planner.yaml", "errt:\n  nearest: octree\n", "errt.nearest", "allowed: 'brute', 'kdtree'"),
    ],
)
def test_bad_values_name_file_key_and_allowed(configs: Path, file: str, text: str, key: str, fragment: str) -> None:
    (configs / file).write_text(text)
    with pytest.raises(ConfigError) as err:
        load_settings(configs)
    assert err.value.file.endswith(file)
    assert err.value.key == key
    assert fragment in str(err.value)


def test_malformed_yaml_names_its_line(configs: Path) -> None:
    (configs / "sim.yaml").write_text("seed: 1\nphysics:\n  substeps: [1, 2\n  frame_rate_hz: 60\n")
    with pytest.raises(ConfigError) as err:
        load_settings(configs)
    assert err.value.file.endswith("sim.yaml")
    assert "malformed YAML at line" in str(err.value)


def test_missing_folder_and_unknown_file(tmp_path: Path, configs: Path) -> None:
    with pytest.raises(ConfigError, match="config folder not found"):
        load_settings(tmp_path / "nowhere")
    (configs / "simm.yaml").write_text("seed: 2\n")
    allowed = ", ".join(f"{c}.yaml" for c in CONCERNS)
    with pytest.raises(ConfigError, match=f"unknown config file; allowed: {allowed}"):
        load_settings(configs)


def test_missing_file_takes_defaults_and_missing_yaml_file_is_reported(configs: Path, tmp_path: Path) -> None:
    (configs / "sim.yaml").unlink()
    assert load_settings(configs).sim == SimParams()
    from cmdragons.config import load_yaml

    with pytest.raises(ConfigError, match="file not found"):
        load_yaml(tmp_path / "absent.yaml")


def test_set_overrides(configs: Path) -> None:
    s = load_settings(configs, ["sim.physics.substeps=8", "field.division=A", "sim.robots_per_team={blue: 3}"])
    assert s.sim.physics.substeps == 8
    assert s.field.dims.length_m == 12.0
    assert s.sim.robots_per_team == {"blue": 3}
    s = load_settings(configs, ["field.pattern.dot_positions_m.0=[0.03, 0.05]"])
    assert s.field.pattern.dot_positions_m[0] == (0.03, 0.05)


@pytest.mark.parametrize(
    ("assignment", "fragment"),
    [
        ("sim.physics.substeps=-3", "out of range"),
        ("sim.physics.nope=3", "unknown key"),
        ("simm.seed=3", "unknown concern; allowed: " + ", ".join(sorted(CONCERNS))),
        ("sim.seed", "expected concern.key.path=value"),
        ("seed=3", "expected at least concern.key"),
    ],
)
def test_bad_overrides(configs: Path, assignment: str, fragment: str) -> None:
    with pytest.raises(ConfigError) as err:
        load_settings(configs, [assignment])
    assert fragment in str(err.value)
    assert "--set" in err.value.file


def test_cli_reports_config_errors(configs: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from cmdragons.cli import main

    (configs / "sim.yaml").write_text("physics:\n  substeps: 0\n")
    assert main(["sim", "--config", str(configs), "--seconds", "0.1", "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert "sim.yaml: physics.substeps: 0 is out of range; allowed: 1 to 100" in err


def _param_types(obj: object, path: str = "") -> list[tuple[str, type]]:
    """Every params dataclass reachable from ``obj`` with where it sits."""
    if isinstance(obj, Mapping):
        return [t for k, v in obj.items() for t in _param_types(v, f"{path}.{k}")]
    if not (dataclasses.is_dataclass(obj) and not isinstance(obj, type)):
        return []
    out = [(path, type(obj))]
    for f in dataclasses.fields(obj):
        out += _param_types(getattr(obj, f.name), f"{path}.{f.name}".strip("."))
    return out


def test_every_params_object_validates_its_ranges_however_it_is_built() -> None:
    s = load_settings(REPO_CONFIGS)
    types = {t: path for path, t in _param_types(s) if t is not type(s)}
    assert [path for t, path in types.items() if not issubclass(t, Validated)] == []
