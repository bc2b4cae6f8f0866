"""`cmdragons vision RECORDING --track`: tracks.jsonl follows the recording's truth."""

from __future__ import annotations

import json
import math
from pathlib import Path

from cmdragons.cli import main
from cmdragons.messages import GroundTruth, WorldState


def test_vision_track_writes_tracks_close_to_truth(tmp_path: Path) -> None:
    rec = tmp_path / "rec"
    assert main(["sim", "--seconds", "2", "--record", "--format", "png", "--out", str(rec), "--no-progress"]) == 0
    out = tmp_path / "vision"
    assert main(["vision", str(rec), "--out", str(out), "--track", "--no-progress"]) == 0
    tracks = [WorldState.from_dict(json.loads(line)) for line in (out / "tracks.jsonl").read_text().splitlines()]
    truth = {t.frame_number: t for t in (GroundTruth.from_dict(json.loads(line))
                                         for line in (rec / "truth.jsonl").read_text().splitlines())}  # fmt: skip
    assert len(tracks) == len(truth) == 120
    errors = []
    for k, world in enumerate(tracks[10:], start=10):
        # the world state is predicted latency_s ahead: compare with the truth that much later
        later = truth.get(k + round(0.03 * 60))
        if later is None:
            continue
        true = {(r.team, r.id): r for r in later.robots}
        for r in world.robots:
            t = true[(r.team, r.id)]
            errors.append(math.hypot(r.x - t.x, r.y - t.y))
    assert len(errors) > 100
    assert max(errors) < 0.02  # every tracked robot within 2 cm of where it really is (seen: < 1 cm)
