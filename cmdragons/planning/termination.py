"""When a planner or a navigator must stop: one condition for all of them (after OMPL's
``PlannerTerminationCondition``).

A :class:`Termination` is a deadline (an absolute ``time.perf_counter()`` time, seconds), a work
budget (a count of the algorithm's own units of work: tree nodes for ERRT, roadmap nodes added for
the dynamic PRM, tangent checks for the visibility graph, candidate velocities for a navigator), or
both. ``a | b`` stops at whichever comes first. A work budget stops an algorithm at the same point
on any machine and under any load, so the same seed gives the same match; a deadline is the safety
net for a stalled machine. Every ``solve`` and every navigator's ``command`` takes one and checks it
between chunks of its work.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

__all__ = ["Termination", "budget", "deadline", "never"]


@dataclass(frozen=True)
class Termination:
    """Stop at ``deadline_s`` (absolute ``time.perf_counter()`` seconds) or once ``work`` units are
    spent, whichever comes first; ``inf`` disables either."""

    deadline_s: float = math.inf
    work: float = math.inf

    def __post_init__(self) -> None:
        if math.isnan(self.deadline_s) or not self.work >= 0.0:
            raise ValueError(f"a termination needs a deadline that is a time and a work budget >= 0, not {self}")

    def __or__(self, other: Termination) -> Termination:
        """Stop when either stops."""
        return Termination(min(self.deadline_s, other.deadline_s), min(self.work, other.work))

    def expired(self) -> bool:
        """The deadline has passed."""
        return time.perf_counter() >= self.deadline_s

    def reached(self, work_done: float) -> bool:
        """``work_done`` units spent exhaust the budget, or the deadline has passed."""
        return work_done >= self.work or self.expired()

    def work_left(self, work_done: float, cap: int) -> int:
        """How many more units may be spent, at most ``cap`` (what a kernel can be told in advance)."""
        left = self.work - work_done
        return int(max(0.0, min(left, float(cap))))


def deadline(seconds: float) -> Termination:
    """Stop ``seconds`` from now."""
    return Termination(deadline_s=time.perf_counter() + seconds)


def budget(work: float) -> Termination:
    """Stop once ``work`` units are spent."""
    return Termination(work=work)


def never() -> Termination:
    """Run until done."""
    return Termination()
