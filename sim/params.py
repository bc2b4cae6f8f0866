"""configs/sim.yaml: everything the simulator is tuned by."""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass, field

from cmdragons.config import Validated, setting
from cmdragons.geometry import TEAMS, LeagueParams, Team
from sim.referee_params import RefereeParams
from sim.render import RenderParams
from sim.script import ScriptParams
from sim.world import BallParams, DribblerParams, KickerParams, PhysicsParams, RobotParams

__all__ = ["SimParams", "robot_counts", "robot_keys"]


@dataclass(frozen=True)
class SimParams(Validated):
    seed: int = setting(1, lo=0, hi=2**63 - 1)  # every random choice of the simulator derives from it
    # robots per team; a team left out gets its division's count (configs/field.yaml)
    robots_per_team: Mapping[Team, int] = field(default_factory=dict)
    physics: PhysicsParams = PhysicsParams()
    robot: RobotParams = RobotParams()
    ball: BallParams = BallParams()
    kicker: KickerParams = KickerParams()
    dribbler: DribblerParams = DribblerParams()
    referee: RefereeParams = RefereeParams()
    script: ScriptParams = ScriptParams()
    render: RenderParams = RenderParams()
    # the simulated world off field.yaml's facts, to watch the team measure them (another simulator's
    # ball, slower robots); 0 keeps field.yaml's. The team still believes field.yaml until it measured
    world_ball_acc_roll_m_s2: float = setting(0.0, lo=0.0, hi=10.0)  # the ball's rolling deceleration
    world_robot_max_brake_m_s2: float = setting(0.0, lo=0.0, hi=50.0)  # the robots' braking

    def world_robot(self) -> RobotParams:
        """The simulated robots: :attr:`robot` with ``world_robot_max_brake_m_s2`` where set."""
        b = self.world_robot_max_brake_m_s2
        return dataclasses.replace(self.robot, max_brake_m_s2=b) if b > 0.0 else self.robot

    def world_ball(self) -> BallParams:
        """The simulated ball: :attr:`ball` with ``world_ball_acc_roll_m_s2`` where set."""
        a = self.world_ball_acc_roll_m_s2
        return dataclasses.replace(self.ball, acc_roll_m_s2=a) if a > 0.0 else self.ball

    def __post_init__(self) -> None:
        super().__post_init__()
        for team, n in self.robots_per_team.items():
            if not 0 <= n <= 16:
                raise ValueError(f"robots_per_team.{team} must be 0 to 16 (the pattern has 16 ids), got {n}")


def robot_counts(league: LeagueParams, params: SimParams) -> dict[Team, int]:
    """How many robots each team has on the field (the sim's own count, else the league's)."""
    return {t: params.robots_per_team.get(t, league.dims.robots_per_team) for t in TEAMS}


def robot_keys(league: LeagueParams, params: SimParams) -> list[tuple[Team, int]]:
    """Every robot on the field as (team, id), in the simulator's order."""
    return [(t, rid) for t, n in robot_counts(league, params).items() for rid in range(n)]
