"""A navigator is one module, one registry line and one config section: a toy navigator, registered
here in one line, is configured from its own section of the team's config (checked like any other:
file, key, allowed range) and drives the brain's robots toward their goals."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
import pytest
from numpy.typing import ArrayLike

from cmdragons.config import ConfigError, Validated, parse, setting
from cmdragons.control import ControlParams
from cmdragons.messages import BallState, GameState, RobotState, WorldState
from cmdragons.navigation import NAVIGATORS, Arrival, VelocityCommand, config_sections, make_navigator
from cmdragons.planning import CollisionParams, CollisionWorld, Termination
from cmdragons.runtime.settings import load_settings
from cmdragons.team import Brain, TeamParams

SETTINGS = load_settings(Path(__file__).resolve().parents[2] / "configs")
DT_S = 1 / 60


@dataclass(frozen=True)
class ToyParams(Validated):
    """configs/team.yaml ``toy``."""

    speed_m_s: float = setting(0.8, lo=0.1, hi=2.0)  # straight at the goal at this speed
    slow_within_m: float = setting(0.2, lo=0.01, hi=1.0)  # proportionally slower this near it


class ToyNavigator:
    """Straight at the end of the plan, whatever is in the way (the safety stage keeps it clear)."""

    SECTIONS: ClassVar[Mapping[str, type]] = {"toy": ToyParams}
    built: ClassVar[list[ToyNavigator]] = []  # every toy configured, for the test to read their goals

    @classmethod
    def configure(cls, name: str, sections: Mapping[str, Any], control: ControlParams, robot_radius_m: float,
                  collision: CollisionParams) -> ToyNavigator:
        nav = cls(sections["toy"])
        cls.built.append(nav)
        return nav

    def __init__(self, params: ToyParams) -> None:
        self.params = params
        self.goal: tuple[float, float] | None = None

    def set_plan(self, path: ArrayLike, arrival: Arrival) -> None:
        end = np.asarray(path, dtype=np.float64)[-1]
        self.goal = (float(end[0]), float(end[1]))

    def command(self, robot: RobotState, world: CollisionWorld, termination: Termination) -> VelocityCommand:
        if self.goal is None:
            return 0.0, 0.0, 0.0
        dx, dy = self.goal[0] - robot.x, self.goal[1] - robot.y
        d = math.hypot(dx, dy)
        if d < 1e-9:
            return 0.0, 0.0, 0.0
        speed = self.params.speed_m_s * min(1.0, d / self.params.slow_within_m)
        return speed * dx / d, speed * dy / d, 0.0

    def sent(self, vx: float, vy: float) -> None:
        pass

    def reset(self) -> None:
        self.goal = None


@pytest.fixture
def toy(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(NAVIGATORS, "toy", ToyNavigator)  # the one line that adds a navigator
    monkeypatch.setattr(ToyNavigator, "built", [])


@pytest.mark.usefixtures("toy")
def test_a_registered_navigator_drives_the_brains_robots_toward_their_goals() -> None:
    team = dataclasses.replace(SETTINGS.team, navigator="toy")
    brain = Brain("blue", SETTINGS, team)
    ball = BallState(1.0, 0.5, 0.0, 0.0)
    xy = {i: (-3.0 + 0.6 * i, -1.0 + 0.4 * (i % 3)) for i in range(6)}
    start: dict[int, float] = {}
    for k in range(90):  # 1.5 s: robots that act on the command they get at once
        robots = tuple(RobotState("blue", i, x, y, 0.0) for i, (x, y) in xy.items())
        commands = brain.step(WorldState(k * DT_S, ball, robots), GameState(k * DT_S)).commands
        if k == 0:
            goals = {i: nav.goal for i, nav in brain.navigators.items() if isinstance(nav, ToyNavigator)}
            start = {i: math.dist(xy[i], g) for i, g in goals.items() if g is not None}
        for c in commands:
            x, y = xy[c.id]
            xy[c.id] = (x + c.vx * DT_S, y + c.vy * DT_S)
    assert ToyNavigator.built and all(isinstance(nav, ToyNavigator) for nav in brain.navigators.values())
    far = {i for i, d in start.items() if d > 0.5}
    assert len(far) >= 3, start
    for i in far:  # each robot at least 0.5 m nearer the goal it was given first (1.2 m at full speed)
        assert math.dist(xy[i], goals[i]) < start[i] - 0.5, (i, start[i], xy[i], goals[i])


@pytest.mark.usefixtures("toy")
def test_a_registered_navigator_reads_its_own_section_of_the_team_config() -> None:
    assert config_sections()["toy"] is ToyParams
    team = parse(TeamParams, {"navigator": "toy", "toy": {"speed_m_s": 1.5}}, file="team.yaml")
    nav = make_navigator(team.navigator, team.navigator_sections, ControlParams(), 0.09)
    assert isinstance(nav, ToyNavigator) and nav.params == ToyParams(speed_m_s=1.5)
    # a section left out takes its defaults
    assert make_navigator("toy", {}, ControlParams(), 0.09).params == ToyParams()  # type: ignore[attr-defined]


@pytest.mark.usefixtures("toy")
@pytest.mark.parametrize(
    ("raw", "key", "message"),
    [({"toy": {"speed_m_s": 9.0}}, "toy.speed_m_s", "allowed: 0.1 to 2.0"),
     ({"toy": {"sped_m_s": 1.0}}, "toy.sped_m_s", "unknown key; allowed keys: slow_within_m, speed_m_s"),
     ({"toys": {}}, "toys", "did you mean toy?"),
     ({"navigator": "magic"}, "navigator", "allowed: 'trajectory'")],
)
def test_config_errors_name_the_file_the_key_and_what_is_allowed(raw: dict[str, Any], key: str, message: str) -> None:
    with pytest.raises(ConfigError) as err:
        parse(TeamParams, raw, file="team.yaml")
    assert err.value.file == "team.yaml" and key in str(err.value) and message in str(err.value)


def test_without_the_toy_its_section_is_an_unknown_key() -> None:
    with pytest.raises(ConfigError, match="toy: unknown key"):
        parse(TeamParams, {"toy": {"speed_m_s": 1.0}}, file="team.yaml")


def test_the_team_config_lists_every_section_in_its_yaml_order() -> None:
    from cmdragons.config import to_plain

    plain = to_plain(TeamParams())
    assert list(plain)[0] == "navigator" and list(plain)[-3:] == ["brain", "simple_opponent", "defend_opponent"]
    assert set(plain) == {"navigator", "brain", "simple_opponent", "defend_opponent", *config_sections()}
