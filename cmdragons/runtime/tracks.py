"""``cmdragons vision ... --track``: detections.jsonl -> tracks.jsonl through the tracker.

Detections of all cameras with the same frame number are one tracker step (they come from one
capture). A line that cannot be read is counted and skipped, never fatal.
"""

from __future__ import annotations

import json
from collections import defaultdict
from pathlib import Path

from cmdragons.messages import DetectionFrame, MessageError
from cmdragons.tracking import Tracker, TrackerParams

__all__ = ["track_detections"]


def track_detections(detections: Path, out: Path, params: TrackerParams) -> dict[str, int]:
    """Track every frame of ``detections`` (JSONL), writing one world state a line to ``out``.
    Returns counts: frames tracked, bad lines, and the tracker's own statistics."""
    frames: dict[int, list[DetectionFrame]] = defaultdict(list)
    bad = 0
    with open(detections, encoding="utf-8") as f:
        for line in f:
            if not line.strip():
                continue
            try:
                d = DetectionFrame.from_dict(json.loads(line))
            except (json.JSONDecodeError, MessageError):
                bad += 1
                continue
            frames[d.frame_number].append(d)
    tracker = Tracker(params)
    with open(out, "w", encoding="utf-8") as f:
        for n in sorted(frames):
            world = tracker.step(frames[n])
            f.write(json.dumps(world.to_dict(), separators=(",", ":"), allow_nan=False) + "\n")
    return {"frames": len(frames), "bad_lines": bad, **tracker.stats.as_dict()}
