"""The top-down view draws each object where the field frame puts it, in its team's colour."""

from __future__ import annotations

import numpy as np

from cmdragons.geometry import Field, LeagueParams
from cmdragons.messages import BallState, GameState, RobotState, WorldState
from cmdragons.runtime.topdown import TopDownView, ViewFrame


def test_robots_ball_and_score_drawn_in_place() -> None:
    view = TopDownView(Field(LeagueParams()), 0.09)
    blue, yellow = RobotState("blue", 7, -2.0, 1.5, 0, 0, 0, 0), RobotState("yellow", 3, 2.5, 0.5, 0, 0, 0, 0)
    robots = (blue, yellow)
    world = WorldState(3.0, BallState(1.0, -1.0, 0.0, 0.0), robots)
    img = view.draw(ViewFrame(3.0, world, None, GameState(3.0, score_blue=2, score_yellow=1)))
    assert img.shape == (view.height, view.width, 3) and img.dtype == np.uint8
    assert view.width % 2 == 0 and view.height % 2 == 0  # H.264 yuv420p
    for (x, y), colour in (((-2.0, 1.5), (235, 140, 20)), ((2.5, 0.5), (20, 220, 240)), ((1.0, -1.0), (0, 140, 255))):
        u, v = view.px(np.array([[x, y]]))[0] // 16
        # a robot's id is printed at its centre: look at the disc 6 px off the centre, inside the rim
        probe = img[v + 6, u - 6] if (x, y) != (1.0, -1.0) else img[v, u]
        assert np.abs(probe.astype(int) - colour).max() <= 10, (x, y, probe)
    # the id digits are drawn inside the disc: white ink on blue
    u, v = view.px(np.array([[-2.0, 1.5]]))[0] // 16
    patch = img[v - 6 : v + 7, u - 6 : u + 7].reshape(-1, 3)
    assert (patch.min(axis=1) > 200).sum() >= 10
    # the band above the field holds the score in white text
    assert (img[: view.band].min(axis=2) > 200).sum() > 200


def test_plans_braking_and_heat_are_drawn() -> None:
    view = TopDownView(Field(LeagueParams()), 0.09)
    base = view.draw(ViewFrame(0.0, None, None, GameState(0.0)))
    plan = np.array([[-3.0, -2.0], [-1.0, -2.0]])
    brake = np.array([[1.0, 2.0], [3.0, 2.0]])
    heat = (np.array([[0.0, 2.5]]), np.array([1.0]))
    img = view.draw(ViewFrame(0.0, None, None, GameState(0.0), plans={1: plan}, braking={1: brake}, pass_heat=heat))
    for (x, y) in ((-2.0, -2.0), (2.0, 2.0), (0.0, 2.5)):
        u, v = view.px(np.array([[x, y]]))[0] // 16
        assert np.abs(img[v - 1 : v + 2, u].astype(int) - base[v - 1 : v + 2, u]).max() > 40, (x, y)
