"""The elastic band (Philippsen 2004 §3.5, after Quinlan and Khatib): a path kept taut and clear as
obstacles move.

The band is a chain of bubbles: each a point of the path with a radius, its clearance (the free
distance from the robot's centre there, obstacles already grown by the robot's radius), capped at
``max_bubble_m``. The union of the bubbles is free space, so a band whose consecutive bubbles
overlap is a collision-free path. Each update moves every inner bubble by two artificial forces
(§3.5.4): the internal contraction toward its neighbours, which pulls the band straight, and the
external repulsion away from obstacles within ``repulsion_range_m``; the part of the force along
the band is dropped (bubbles do not slide along it), and each step is scaled by the bubble's own
radius, so a bubble never jumps out of the free space it knows. The number of bubbles is managed
(§3.5.3): a bubble goes in where two neighbours no longer overlap enough, one goes out where its
neighbours overlap without it. Obstacle masking (§3.5.2) is the caller's: the clearance it gives
is the world's without the masked obstacles (the ball the robot is to reach, say).

Field frame, metres. ``clearance(points) -> (distance (n,), gradient (n, 2))`` is the world's
distance-and-gradient query; :func:`circles_clearance` builds one from discs for tests and tools.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from cmdragons.config import Validated, setting
from cmdragons.geometry import path_length

__all__ = ["BandParams", "Clearance", "ElasticBand", "circles_clearance"]

FloatArray = NDArray[np.float64]
Clearance = Callable[[FloatArray], tuple[FloatArray, FloatArray]]


@dataclass(frozen=True)
class BandParams(Validated):
    """configs/team.yaml ``elastic_band``."""

    max_bubble_m: float = setting(1.0, lo=0.01, hi=10.0)  # bubbles no bigger than this
    min_bubble_m: float = setting(0.005, lo=0.0, hi=1.0)  # a bubble smaller than this: the band is blocked
    contraction_gain: float = setting(0.5, lo=0.0, hi=10.0)  # internal force per unit of tension
    repulsion_gain: float = setting(2.0, lo=0.0, hi=100.0)  # external force per metre inside the range
    repulsion_range_m: float = setting(0.3, lo=0.0, hi=5.0)  # obstacles nearer than this push
    step: float = setting(0.5, lo=0.01, hi=1.0)  # of a bubble's radius per iteration at unit force
    overlap: float = setting(0.75, lo=0.1, hi=1.0)  # neighbours' centres at most this share of their radii apart
    merge: float = setting(0.5, lo=0.05, hi=1.0)  # a bubble goes when its neighbours are this close (share)
    iterations: int = setting(8, lo=1, hi=1000)  # force steps per update
    max_bubbles: int = setting(200, lo=3, hi=10000)


def circles_clearance(circles: ArrayLike, robot_radius_m: float) -> Clearance:
    """A clearance query among discs (x, y, r) grown by ``robot_radius_m``: distance from each point
    to the nearest grown disc's edge and the unit gradient away from it (0 with no disc)."""
    c = np.asarray(circles, dtype=np.float64).reshape(-1, 3)

    def query(points: FloatArray) -> tuple[FloatArray, FloatArray]:
        p = np.asarray(points, dtype=np.float64).reshape(-1, 2)
        if not len(c):
            return np.full(len(p), np.inf), np.zeros_like(p)
        diff = p[:, None, :] - c[None, :, :2]
        dist = np.hypot(diff[..., 0], diff[..., 1])
        edge = dist - c[None, :, 2] - robot_radius_m
        k = np.argmin(edge, axis=1)
        rows = np.arange(len(p))
        d = edge[rows, k]
        centre = np.maximum(dist[rows, k], 1e-12)
        return d, diff[rows, k] / centre[:, None]

    return query


class ElasticBand:
    """A band between a fixed start and goal; :meth:`update` deforms it in the current world."""

    def __init__(self, params: BandParams) -> None:
        self.p = params
        self.points: FloatArray = np.zeros((0, 2))
        self.radii: FloatArray = np.zeros(0)

    def set_path(self, path: ArrayLike, clearance: Clearance) -> None:
        """Start the band from ``path`` (k, 2): bubbles along it, as many as overlap requires."""
        pts = np.asarray(path, dtype=np.float64).reshape(-1, 2)
        if len(pts) < 2:
            pts = np.vstack([pts, pts]) if len(pts) else np.zeros((2, 2))
        self.points = pts.copy()
        self.radii = self._radii(self.points, clearance)
        self._manage(clearance)

    @property
    def length(self) -> float:
        return path_length(self.points)

    def clear(self) -> bool:
        """Whether the band is a collision-free path: every bubble free and each overlapping the next."""
        if len(self.points) < 2:
            return False
        if np.any(self.radii < self.p.min_bubble_m):
            return False
        gaps = np.hypot(*np.diff(self.points, axis=0).T)
        return bool(np.all(gaps <= self.radii[:-1] + self.radii[1:]))

    def _radii(self, pts: FloatArray, clearance: Clearance) -> FloatArray:
        d, _ = clearance(pts)
        return np.minimum(np.asarray(d, dtype=np.float64), self.p.max_bubble_m)

    def advance(self, start: ArrayLike) -> None:
        """Move the band's start to ``start`` (the robot) and drop the bubbles it has passed: a
        bubble goes while the robot is nearer to the bubble after it than that bubble is."""
        p0 = np.asarray(start, dtype=np.float64).reshape(2)
        pts, radii = self.points, self.radii
        k = 1
        while k < len(pts) - 1 and math.dist(p0, pts[k + 1]) <= math.dist(pts[k], pts[k + 1]):
            k += 1
        self.points = np.vstack([p0, pts[k:]])
        self.radii = np.r_[radii[0], radii[k:]]

    def update(self, clearance: Clearance, start: ArrayLike | None = None, goal: ArrayLike | None = None) -> bool:
        """Move the band's ends to ``start`` / ``goal`` (if given) and deform it ``iterations`` times
        in the world ``clearance`` describes; returns whether the band is clear."""
        p = self.p
        if start is not None:
            self.points[0] = np.asarray(start, dtype=np.float64)
        if goal is not None:
            self.points[-1] = np.asarray(goal, dtype=np.float64)
        for _ in range(p.iterations):
            pts = self.points
            if len(pts) > 2:
                d, grad = clearance(pts[1:-1])
                radii = np.minimum(d, p.max_bubble_m)
                prev, nxt = pts[:-2] - pts[1:-1], pts[2:] - pts[1:-1]
                lp = np.maximum(np.hypot(*prev.T), 1e-12)[:, None]
                ln = np.maximum(np.hypot(*nxt.T), 1e-12)[:, None]
                internal = p.contraction_gain * (prev / lp + nxt / ln)
                push = np.clip(p.repulsion_range_m - d, 0.0, None)
                external = p.repulsion_gain * push[:, None] * grad
                force = internal + external
                # no sliding along the band: drop the force's part along the local tangent
                tangent = pts[2:] - pts[:-2]
                tangent /= np.maximum(np.hypot(*tangent.T), 1e-12)[:, None]
                force -= np.sum(force * tangent, axis=1)[:, None] * tangent
                step = p.step * np.clip(radii, 0.0, None)[:, None]
                norm = np.maximum(np.hypot(*force.T), 1.0)[:, None]  # a unit step at most
                moved = pts[1:-1] + step * force / norm
                # a move into a tighter spot than the bubble allows is not taken
                d_new, _ = clearance(moved)
                ok = d_new > p.min_bubble_m
                pts[1:-1][ok] = moved[ok]
            self.radii = self._radii(self.points, clearance)
            self._manage(clearance)
        return self.clear()

    def _manage(self, clearance: Clearance) -> None:
        """Bubbles in where neighbours do not overlap enough, out where they overlap without it."""
        p = self.p
        pts, radii = list(self.points), list(self.radii)
        i = 0
        while i < len(pts) - 1 and len(pts) < p.max_bubbles:
            gap = math.dist(pts[i], pts[i + 1])
            reach = p.overlap * (max(radii[i], 0.0) + max(radii[i + 1], 0.0))
            if gap > max(reach, 1e-6) and gap > 1e-3:
                mid = 0.5 * (np.asarray(pts[i]) + np.asarray(pts[i + 1]))
                pts.insert(i + 1, mid)
                radii.insert(i + 1, float(self._radii(mid[None, :], clearance)[0]))
                continue
            i += 1
        i = 1
        while i < len(pts) - 1:
            gap = math.dist(pts[i - 1], pts[i + 1])
            if gap < p.merge * (max(radii[i - 1], 0.0) + max(radii[i + 1], 0.0)):
                del pts[i]
                del radii[i]
                continue
            i += 1
        self.points = np.array(pts, dtype=np.float64).reshape(-1, 2)
        self.radii = np.array(radii, dtype=np.float64)
