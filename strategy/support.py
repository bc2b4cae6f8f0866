"""Supporter placement (Bruce 2006, B.5): the supporters wait at the best receiving points of the
pass evaluation over a grid of candidate points, spread apart, off the ball and off the point a pass's
receiver waits at (that point was a supporter's: without it, the next supporter took the same spot).

The grid is re-evaluated every ``eval_every_frames`` frames (its cost is the bulk of a frame's
strategy time); the points chosen from it hold in between. Field frame, metres.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from cmdragons.config import Validated, setting
from cmdragons.geometry import Field
from strategy.evaluation import PassEvaluation, PassParams, candidate_grid, pass_values

__all__ = ["SupportParams", "Supporters", "spread_points"]

Array = NDArray[np.float64]


@dataclass(frozen=True)
class SupportParams(Validated):
    eval_every_frames: int = setting(6, lo=1, hi=600)  # the pass grid is re-evaluated this often
    spacing_m: float = setting(1.2, lo=0.0, hi=10.0)  # supporters' points at least this far apart
    min_ball_distance_m: float = setting(1.0, lo=0.0, hi=10.0)  # ... and at least this far from the ball


def spread_points(ev: PassEvaluation, ball: Array, count: int, p: SupportParams,
                  taken: Sequence[tuple[float, float]] = ()) -> list[tuple[float, float]]:
    """Up to ``count`` of the best points of ``ev``, best first, at least ``spacing_m`` apart and from
    each point of ``taken`` (where team-mates of other roles wait), and ``min_ball_distance_m`` from
    ``ball``."""
    order = np.argsort(-ev.values)
    chosen: list[tuple[float, float]] = []
    for i in order:
        if len(chosen) >= count:
            break
        x, y = float(ev.points[i, 0]), float(ev.points[i, 1])
        if math.hypot(x - ball[0], y - ball[1]) < p.min_ball_distance_m:
            continue
        if all(math.hypot(x - a, y - b) >= p.spacing_m for a, b in (*taken, *chosen)):
            chosen.append((x, y))
    return chosen


class Supporters:
    """The pass evaluation over the candidate grid and the supporters' points, kept between the
    frames it is re-evaluated on."""

    def __init__(self, pitch: Field, passing: PassParams, params: SupportParams, obstacle_radius: float) -> None:
        self.field, self.passing, self.p = pitch, passing, params
        self.obstacle_radius = obstacle_radius  # a robot's plus the ball's: whether the ball gets past
        self.grid = candidate_grid(pitch, passing)
        self.evaluation: PassEvaluation | None = None
        self.evaluated_frame = -1  # the frame the evaluation was made on
        self.points: list[tuple[float, float]] = []
        self._ball: Array = np.zeros(2)  # the ball the evaluation was made for
        self._taken: tuple[tuple[float, float], ...] = ()  # the points kept clear when the points were chosen

    def update(self, frame: int, ball: Array, attack_sign: float, opponents: Array, count: int,
               taken: Sequence[tuple[float, float]] = ()) -> None:
        """Re-evaluate the grid on the first frame and every ``eval_every_frames``-th; ``count``
        supporters' points from it, clear of ``taken`` (the pass's receiving point): chosen again from
        the evaluation kept whenever ``taken`` changes in between."""
        taken = tuple(taken)
        if self.evaluation is not None and frame % self.p.eval_every_frames != 0:
            if taken != self._taken:
                self._taken = taken
                self.points = spread_points(self.evaluation, self._ball, count, self.p, taken)
            return
        self.evaluation = pass_values(ball, self.grid, self.field, attack_sign, opponents, self.obstacle_radius,
                                      self.passing)
        self.evaluated_frame = frame
        self._ball, self._taken = ball, taken
        self.points = spread_points(self.evaluation, ball, count, self.p, taken)
