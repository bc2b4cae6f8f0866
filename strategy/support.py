"""Supporter placement (Bruce 2006, B.5): the supporters wait at the best receiving points of the
pass evaluation over a grid of candidate points, spread apart, off the ball and off the point a pass's
receiver waits at (that point was a supporter's: without it, the next supporter took the same spot).

The grid is re-evaluated every ``eval_every_frames`` frames (its cost is the bulk of a frame's
strategy time); the points chosen from it hold in between. Field frame, metres.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
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
                  taken: Sequence[tuple[float, float]] = (), placed: Array | None = None) -> list[tuple[float, float]]:
    """Up to ``count`` of the best points of ``ev``, best first, at least ``spacing_m`` apart and from
    each point of ``taken`` (where team-mates of other roles wait), and ``min_ball_distance_m`` from
    ``ball``; ``placed``: where a supporter sent to each of ``ev``'s points stands now (None: on it),
    the spacing and the points returned being those places."""
    order = np.argsort(-ev.values)
    places = ev.points if placed is None else placed
    chosen: list[tuple[float, float]] = []
    for i in order:
        if len(chosen) >= count:
            break
        x, y = float(places[i, 0]), float(places[i, 1])
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
        self._placed: Array | None = None  # where supporters sent to the grid's points stand (None: on them)
        self._held: list[tuple[float, float]] | None = None  # the points held through our kickoff

    def update(self, frame: int, ball: Array, attack_sign: float, opponents: Array, count: int,
               taken: Sequence[tuple[float, float]] = (), hold: bool = False,
               place: Callable[[Array], Array] | None = None) -> None:
        """Re-evaluate the grid on the first frame and every ``eval_every_frames``-th; ``count``
        supporters' points from it, clear of ``taken`` (the pass's receiving point): chosen again from
        the evaluation kept whenever ``taken`` changes in between.

        ``hold``: our kickoff's ball waits for its kick: the points chosen on its first frame hold
        until it is over (those clear of ``taken``, topped up from the evaluation, which goes on for
        the pass). Chosen anew each time, every point moved as the opponents came to their places, the
        robots were assigned round among them and the kicker's receiver changed with them: a Division A
        kickoff waited 5 s, or its 10 s out. ``place``: where a supporter sent to each of the grid's
        points stands now (our kickoff: in our half; None: on it), the points spread on those places
        (else two chosen points beyond the halfway line put two robots side by side on it)."""
        taken = tuple(taken)
        if not hold:
            self._held = None
        if place is None:
            self._placed = None  # the places of our kickoff, over with it
        if self.evaluation is None or frame % self.p.eval_every_frames == 0 or (hold and self._held is None):
            self.evaluation = pass_values(ball, self.grid, self.field, attack_sign, opponents, self.obstacle_radius,
                                          self.passing)
            self.evaluated_frame = frame
            self._ball = ball
            self._placed = place(self.evaluation.points) if place is not None else None
        elif taken == self._taken and not hold:
            return
        self._taken = taken
        if hold and self._held is not None:
            keep = [q for q in self._held if all(math.dist(q, t) >= self.p.spacing_m for t in taken)][:count]
            if len(keep) < count:
                keep += spread_points(self.evaluation, self._ball, count - len(keep), self.p, (*taken, *keep),
                                      self._placed)
            self.points = keep
            return
        self.points = spread_points(self.evaluation, self._ball, count, self.p, taken, self._placed)
        if hold:
            self._held = list(self.points)
