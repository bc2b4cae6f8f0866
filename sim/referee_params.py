"""configs/sim.yaml's ``referee``: how the simulator's referee runs (which rules, the restarts' delays
and timeouts, the kickoff formations), the league's figures it judges by (:class:`sim.rules.RulesParams`)
and what it allows for tracks' noise when it judges vision's world as an auto-referee
(:class:`AutorefParams`)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Literal

from cmdragons.config import Validated, setting
from sim.rules import RulesParams, TrackMargins

__all__ = ["AutorefParams", "RefereeParams"]

_Pose = tuple[float, float, float]
_DEFAULT_FORMATIONS: dict[Literal["A", "B"], tuple[_Pose, ...]] = {
    "B": ((-4.2, 0.0, 0.0), (-3.0, 1.0, 0.0), (-3.0, -1.0, 0.0), (-2.0, 0.0, 0.0), (-1.0, 1.6, 0.0),
          (-1.0, -1.6, 0.0)),
    "A": ((-5.7, 0.0, 0.0), (-4.2, 1.2, 0.0), (-4.2, -1.2, 0.0), (-4.2, 0.0, 0.0), (-3.2, 2.5, 0.0),
          (-3.2, -2.5, 0.0), (-2.4, 0.8, 0.0), (-2.4, -0.8, 0.0), (-1.2, 3.0, 0.0), (-1.2, -3.0, 0.0),
          (-1.0, 0.0, 0.0)),
}


@dataclass(frozen=True)
class AutorefParams(Validated):
    """configs/sim.yaml ``referee.autoref``: the referee judging the tracked world (no truth): how it
    tells a touch of the ball from the ball's track and what it allows for the tracks' noise."""

    # a touch (the kick detector): the ball's tracked velocity changing by more than this from one frame
    # to the next ...
    kick_speed_change_m_s: float = setting(0.8, lo=0.05, hi=20.0)
    kick_reach_m: float = setting(0.05, lo=0.0, hi=1.0)  # ... a robot's body this near the ball ...
    kick_memory_s: float = setting(0.1, lo=0.0, hi=2.0)  # ... at some moment of the last this long
    # a kick (the ball sped up) leaving the robot nearest its path farther than this off its heading (relative
    # to its velocity: a kick leaves along the kicker's heading) was turned by the front of the robot that
    # held the ball, in reach too
    kick_heading_deg: float = setting(30.0, lo=0.0, hi=180.0)
    # the frame after a kick out of the cameras' sight that another robot turned, a change of the ball's
    # velocity that moved it there from where it was (within this) is the track's velocity settling, no new touch
    kick_settle_m: float = setting(0.01, lo=0.0, hi=0.2)
    margins: TrackMargins = TrackMargins(touch_release_m=0.01, contact_release_m=0.0, distance_m=0.05, speed_m_s=0.1,
                                        fast_ball_frames=2, touch_pass_speed_m_s=1.0,
                                        touch_pass_depth_m=0.003, ball_back_m_s=0.25)
    leave_s: float = setting(2.0, lo=0.0, hi=60.0)  # a robot sent off may be seen on the field this long
    # an own collision (two robots of one team, counted for the summary): their centres nearer than two
    # radii plus this ...
    own_contact_margin_m: float = setting(0.0, lo=-0.05, hi=0.2)
    own_contact_closing_m_s: float = setting(0.2, lo=0.0, hi=10.0)  # ... while closing faster than this


@dataclass(frozen=True)
class RefereeParams(Validated):
    enabled: bool = True  # off: no restarts, the ball bounces off the boundary walls
    rules: Literal["full", "basic"] = "full"  # full: the league's game controller and auto-referee
    blue_defends: Literal["negative_x", "positive_x"] = "negative_x"
    restart_delay_s: float = setting(1.0, lo=0.0, hi=30.0)  # goal or out -> ball placed
    # who puts the ball where a restart wants it: the referee by teleport (the kickoffs, penalties and
    # balls the teams failed to place; a free kick is the taking team's placement first, with the full
    # rules), or only ever the teams' ball placement (robots: no teleport at all)
    place_by: Literal["teleport", "robots"] = "teleport"
    place_robots_on_goal: bool = True  # put both teams in their kickoff formation after a goal
    free_kick_distance_m: float = setting(0.2, lo=0.0, hi=2.0)  # from the lines and defense areas
    restart_timeout_s: float = setting(10.0, lo=0.1, hi=600.0)  # a restart not taken by then: play on
    keeper_held_ball_s: float = setting(10.0, lo=0.1, hi=600.0)  # ball this long in a defense area: free kick
    no_progress_s: float = setting(10.0, lo=0.1, hi=600.0)  # the ball this long in one place in play: stop, force start
    no_progress_m: float = setting(0.05, lo=0.0, hi=5.0)  # ... within this of it
    # start poses (x m, y m, theta rad) of the team defending -x, per division; mirrored for the other
    formations: Mapping[Literal["A", "B"], tuple[tuple[float, float, float], ...]] = field(
        default_factory=lambda: dict(_DEFAULT_FORMATIONS)
    )
    figures: RulesParams = RulesParams()  # the league's figures for the full rules
    park_distance_m: float = setting(3.0, lo=0.5, hi=50.0)  # robots sent off wait this far outside the boundary
    autoref: AutorefParams = AutorefParams()  # judging the tracked world (an outside simulator, vision)

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.place_by == "robots" and self.enabled and self.rules != "full":
            raise ValueError("place_by: robots needs rules: full (the teams' ball placement is one of the full rules)")
