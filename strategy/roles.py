"""Objective assignment (Bruce 2006, appendix B.5): roles in priority order, each taken by the
free robot that reaches its objective at the lowest cost, with hysteresis against flicker.

A role's cost for a robot is the distance from the robot to the role's objective point; the robot
holding the role since the last frame gets ``hysteresis_m`` off its cost, so two robots at nearly
the same distance do not swap roles frame after frame. Among the robots holding roles of one kind
(the defenders, the supporters), the points are then swapped pairwise wherever that shortens their
ways together by more than ``swap_margin_m``: two robots never cross each other's way to their
points (the greedy order with hysteresis could send two defenders through each other).

A role is a value: its kind and, for the kinds a team fills several times (defenders,
supporters), which one (``Role(RoleKind.DEFENDER, 1)``).
"""

from __future__ import annotations

import enum
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from cmdragons.config import Validated, setting

__all__ = ["Objective", "Role", "RoleAssigner", "RoleKind", "RoleParams"]


@dataclass(frozen=True)
class RoleParams(Validated):
    hysteresis_m: float = setting(0.5, lo=0.0, hi=10.0)  # cost bonus of the robot already in the role
    goalie_id: int = setting(0, lo=-1, hi=15)  # -1: whoever is nearest the goal when play starts
    # two robots of one kind swap points when that shortens their two ways together by more than this
    swap_margin_m: float = setting(0.05, lo=0.0, hi=10.0)


class RoleKind(enum.Enum):
    GOALIE = "goalie"
    ATTACKER = "attacker"  # plays the ball
    RECEIVER = "receiver"  # of a pass decided or under way
    DEFENDER = "defender"  # on the edge of our defense area
    SUPPORTER = "supporter"  # at a receiving point of the pass evaluation
    MARKER = "marker"  # in an opponent's passing lane (its index: the opponent's id)
    BLOCKER = "blocker"  # on the ball's line to our goal, in front of the ball


@dataclass(frozen=True)
class Role:
    """One role of the team: its kind and, among several of the same kind, its index."""

    kind: RoleKind
    index: int = 0


@dataclass(frozen=True)
class Objective:
    role: Role
    x: float
    y: float
    fixed_robot: int | None = None  # a role only this robot may take (the goalie)
    costs: Mapping[int, float] | None = None  # per robot, instead of the distance to (x, y)


class RoleAssigner:
    """Keeps the roles of one team from frame to frame."""

    def __init__(self, params: RoleParams) -> None:
        self.params = params
        self.roles: dict[int, Role] = {}  # robot id -> role

    def assign(self, robots: Mapping[int, tuple[float, float]], objectives: Sequence[Objective]) -> dict[int, Role]:
        """``objectives`` in priority order; robots left over get no role. An infinite cost: the robot
        takes that role only when no other is free."""
        free = dict(robots)
        previous = {role: rid for rid, role in self.roles.items()}
        out: dict[int, Role] = {}
        for obj in objectives:
            if not free:
                break
            if obj.fixed_robot is not None:
                if obj.fixed_robot in free:
                    out[obj.fixed_robot] = obj.role
                    del free[obj.fixed_robot]
                    continue
            best, best_cost = None, math.inf
            costs = obj.costs or {}
            for rid, (x, y) in free.items():
                cost = costs[rid] if rid in costs else math.hypot(x - obj.x, y - obj.y)
                if previous.get(obj.role) == rid:
                    cost -= self.params.hysteresis_m
                if best is None or cost < best_cost or (cost == best_cost and rid < best):
                    best, best_cost = rid, cost
            assert best is not None
            out[best] = obj.role
            del free[best]
        self._uncross(out, robots, objectives)
        self.roles = out
        return out

    def _uncross(self, out: dict[int, Role], robots: Mapping[int, tuple[float, float]],
                 objectives: Sequence[Objective]) -> None:
        """Swap the points of two robots of one kind while that shortens their two ways together by
        more than ``swap_margin_m`` (in place). Roles with a fixed robot or their own costs stay."""
        point = {o.role: (o.x, o.y) for o in objectives if o.fixed_robot is None and o.costs is None}
        ids = sorted(rid for rid, role in out.items() if role in point)
        margin = self.params.swap_margin_m

        def way(rid: int, role: Role) -> float:
            return math.dist(robots[rid], point[role])

        swapped = True
        while swapped:  # each swap shortens the total by more than the margin: this ends
            swapped = False
            for k, a in enumerate(ids):
                for b in ids[k + 1:]:
                    ra, rb = out[a], out[b]
                    if ra.kind is rb.kind and way(a, rb) + way(b, ra) < way(a, ra) + way(b, rb) - margin:
                        out[a], out[b] = rb, ra
                        swapped = True
