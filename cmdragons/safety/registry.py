"""Safety registry and the ``safety`` config concern (configs/safety.yaml).

A new method is one module plus one line in :data:`SAFETY` (and its params beside it here).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from cmdragons.config import Validated, setting
from cmdragons.control.motion import ControlParams
from cmdragons.planning.world import CollisionWorld
from cmdragons.safety.base import KEPT, ArraySafety, Safety, SafetyResult
from cmdragons.safety.dss import DSSParams, DynamicsSafetySearch

__all__ = ["SAFETY", "NoSafety", "SafetyParams", "make_safety"]


class NoSafety(ArraySafety):
    """No safety stage: every command passes unchanged (the baseline)."""

    def filter(self, states: ArrayLike, velocities: ArrayLike, opponents: ArrayLike) -> SafetyResult:
        v = np.array(velocities, dtype=np.float64).reshape(-1, 2)
        return SafetyResult(v, np.full(len(v), KEPT, dtype=np.int64), np.zeros((len(v), 0, 2)))


Factory = Callable[["SafetyParams", ControlParams, float, CollisionWorld | None, np.random.Generator], Safety]

SAFETY: dict[str, Factory] = {
    "none": lambda p, c, r, w, rng: NoSafety(),
    "dss": lambda p, c, r, w, rng: DynamicsSafetySearch(p.dss, c.motion, r, w, rng),
}


@dataclass(frozen=True)
class SafetyParams(Validated):
    """configs/safety.yaml: which safety stage guards the commands and how each one is tuned."""

    method: str = setting("dss", choices=tuple(SAFETY))  # which of SAFETY guards the robots
    seed: int = setting(1, lo=0, hi=2**63 - 1)  # the search's random samples draw from (seed, team)
    dss: DSSParams = DSSParams()


def make_safety(
    params: SafetyParams,
    control: ControlParams,
    robot_radius_m: float,
    static: CollisionWorld | None,
    name: str | None = None,
    stream: int = 0,
) -> Safety:
    """A fresh safety stage ``name`` (default ``params.method``) for one team, its random numbers
    seeded from (``params.seed``, ``stream``); ``static`` holds the walls and fixed obstacles."""
    key = name or params.method
    if key not in SAFETY:
        raise KeyError(f"unknown safety method {key!r}; known: {', '.join(sorted(SAFETY))}")
    return SAFETY[key](params, control, robot_radius_m, static, np.random.default_rng([params.seed, stream]))
