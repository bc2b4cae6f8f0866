"""Foxglove's scene topics in a match's log: read back with their schemas from the file alone."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory

from cmdragons.runtime.log import RunLog
from cmdragons.runtime.match import Match
from cmdragons.runtime.scene import FRAME, SceneStage
from cmdragons.runtime.settings import load_settings
from cmdragons.runtime.stages import Tap

SETTINGS = load_settings(Path(__file__).resolve().parents[2] / "configs")


def test_scene_topics_show_the_field_robots_ball_and_plans(tmp_path: Path) -> None:
    path = tmp_path / "run.mcap"
    f = SETTINGS.field
    seen: dict[str, Any] = {}
    with RunLog(path) as log:
        scene = SceneStage(log, SETTINGS.field_geometry(), f.robot.radius_m, f.robot.height_m, f.ball.radius_m)
        tap = Tap("last", ("truth", "report/blue"), seen.__setitem__)
        Match(SETTINGS, "simple", "truth", seed=5, extra=[scene, tap]).run(0.5)
    frames = round(0.5 * SETTINGS.sim.physics.frame_rate_hz)
    updates: dict[str, list[Any]] = {}
    with path.open("rb") as fh:
        for schema, channel, _m, proto in make_reader(fh, decoder_factories=[DecoderFactory()]).iter_decoded_messages():
            assert schema is not None and schema.name == "foxglove.SceneUpdate"
            updates.setdefault(channel.topic, []).append(proto)
    assert len(updates["/scene/field"]) == 1 and len(updates["/scene/objects"]) == frames
    assert len(updates["/scene/plans"]) == frames  # one brain (blue) against the simple team
    field = updates["/scene/field"][0].entities[0]
    assert field.frame_id == FRAME and len(field.lines[0].points) == 2 * len(SETTINGS.field_geometry().line_segments())
    objects = updates["/scene/objects"][-1].entities[0]
    truth = seen["truth"]
    assert len(objects.cylinders) == len(truth.robots) and len(objects.spheres) == 1
    for c, r in zip(objects.cylinders, truth.robots, strict=True):  # the true positions, to float precision
        assert (c.pose.position.x, c.pose.position.y) == pytest.approx((r.x, r.y), abs=1e-9)
    assert objects.spheres[0].pose.position.x == pytest.approx(truth.ball.x, abs=1e-9)
    plans = updates["/scene/plans"][-1].entities[0]
    report = seen["report/blue"]
    with_path = [r for r in report.robots if len(r.path) > 1]
    assert plans.id == "plans/blue" and len(with_path) >= 1
    first = plans.lines[0].points  # the first robot with a path: its path, point by point
    assert [c for p in first for c in (p.x, p.y)] == pytest.approx(with_path[0].path.ravel().tolist(), abs=1e-9)
