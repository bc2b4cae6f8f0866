"""Per-step time of every registered navigator on one seeded scene: a robot crossing the Division B
field among 21 robots that move between steps (the world is built anew each step, as in a match),
driven kinematically. Prints a Markdown table of median and p95 ms per step (wall clock: shared
machines vary by a fifth or more). Run: .venv/bin/python docs/reactive_timing.py [steps]"""

from __future__ import annotations

import sys
import time

import numpy as np

from cmdragons.control import ControlParams
from cmdragons.geometry import Field, LeagueParams
from cmdragons.messages import RobotState
from cmdragons.navigation import NAVIGATORS, Arrival, make_navigator
from cmdragons.planning import deadline, field_world
from cmdragons.team import TeamParams


def main(steps: int = 300) -> None:
    control, field = ControlParams(), Field(LeagueParams())
    dt = control.motion.period_s
    print("| navigator | median ms | p95 ms |")
    print("|---|---|---|")
    for name in sorted(NAVIGATORS):
        rng = np.random.default_rng(0)
        xy = rng.uniform((-3.5, -2.5), (3.5, 2.5), (21, 2))
        vel = rng.uniform(-1.0, 1.0, (21, 2))
        nav = make_navigator(name, TeamParams().navigator_sections, control, 0.09)
        start, goal = (-4.0, 0.3), (4.0, -0.3)
        nav.set_plan(np.array([start, goal]), Arrival(0.0))
        x, y, vx, vy = start[0], start[1], 0.0, 0.0
        times = []
        for k in range(steps + 20):
            xy = np.clip(xy + vel * dt, (-4.4, -2.9), (4.4, 2.9))
            world = field_world(field, xy, vel)
            robot = RobotState("blue", 0, x, y, 0.0, vx, vy, 0.0)
            t0 = time.perf_counter()
            vx, vy, _ = nav.command(robot, world, deadline(1.0))
            if k >= 20:  # the first steps compile and warm up
                times.append((time.perf_counter() - t0) * 1e3)
            nav.sent(vx, vy)
            x, y = x + vx * dt, y + vy * dt
        print(f"| {name} | {np.median(times):.3f} | {np.percentile(times, 95):.3f} |")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 300)
