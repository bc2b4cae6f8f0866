"""The safety interface of DESIGN.md, ``make_safe(commands, world) -> commands``, and what every safety
method shares: the translation between commands and arrays.

Field frame, metres, seconds. A safety method sees all own robots at once. It works on arrays:
own robots' states (x, y, vx, vy) and the velocities their commands ask for, the opponents' states;
it answers with the velocities to send and a status per robot. :class:`ArraySafety` turns that into
``make_safe`` over :class:`~cmdragons.messages.RobotCommand` and
:class:`~cmdragons.messages.WorldState`.
"""

from __future__ import annotations

import dataclasses
from abc import ABC, abstractmethod
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

from cmdragons.messages import RobotCommand, WorldState
from cmdragons.safety._kernels import CHANGED, KEPT, STOP_ASKED, STOPPED

__all__ = ["CHANGED", "KEPT", "STOPPED", "STOP_ASKED", "ArraySafety", "Safety", "SafetyResult"]

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class SafetyResult:
    """``velocities`` (n, 2) field-frame m/s to send; ``status`` (n,) KEPT, CHANGED, STOPPED or
    STOP_ASKED per robot; ``braking`` (n, k, 2) the field points of each robot's braking path that
    the method checked (k = 0 when it checks none)."""

    velocities: FloatArray
    status: NDArray[np.int64]
    braking: FloatArray


class Safety(Protocol):
    """A safety method: the last stage between the controller and the robots."""

    def make_safe(self, commands: Sequence[RobotCommand], world: WorldState) -> list[RobotCommand]: ...

    def filter(self, states: ArrayLike, velocities: ArrayLike, opponents: ArrayLike) -> SafetyResult:
        """``states`` (n, 4) x, y, vx, vy of the own robots, ``velocities`` (n, 2) their commands,
        ``opponents`` (m, 4)."""
        ...


class ArraySafety(ABC):
    """``make_safe`` in terms of :meth:`filter`; subclasses implement :meth:`filter`."""

    @abstractmethod
    def filter(self, states: ArrayLike, velocities: ArrayLike, opponents: ArrayLike) -> SafetyResult: ...

    def make_safe(self, commands: Sequence[RobotCommand], world: WorldState) -> list[RobotCommand]:
        """The commands with safe velocities (kick, dribbler and omega untouched). Own robots without
        a command count as stopping; commands for robots the world does not show pass unchanged."""
        if not commands:
            return []
        team = commands[0].team
        own = [r for r in world.robots if r.team == team]
        opp = np.array([(r.x, r.y, r.vx, r.vy) for r in world.robots if r.team != team]).reshape(-1, 4)
        by_id = {c.id: c for c in commands if c.team == team}
        states = np.array([(r.x, r.y, r.vx, r.vy) for r in own]).reshape(-1, 4)
        asked = np.array([(by_id[r.id].vx, by_id[r.id].vy) if r.id in by_id else (0.0, 0.0) for r in own])
        result = self.filter(states, asked.reshape(-1, 2), opp)
        safe = {r.id: result.velocities[i] for i, r in enumerate(own) if r.id in by_id}
        out = []
        for c in commands:
            v = safe.get(c.id) if c.team == team else None
            out.append(c if v is None else dataclasses.replace(c, vx=float(v[0]), vy=float(v[1])))
        return out
