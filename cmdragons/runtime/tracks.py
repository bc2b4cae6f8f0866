"""``cmdragons vision ... --track``: detections.jsonl -> tracks.jsonl through the tracker.

Detections of all cameras with the same frame number are one tracker step (they come from one
capture). A line that cannot be read is counted and skipped, never fatal.

Each line is a world state (DESIGN.md tracks format), its ``frame_number`` the detections', with two
more keys saying what it holds:
``t_capture``, the capture time of the frame it follows, and ``ahead_s``, how far past it the
state is predicted (``t = t_capture + ahead_s``). Offline the default is 0: the filtered estimate
at each frame's capture time; the live loop's look-ahead (the tracker's ``latency_s``) only on
request, to see what the team was handed.
"""

from __future__ import annotations

import dataclasses
import json
from collections import defaultdict
from pathlib import Path

from cmdragons.messages import DetectionFrame, MessageError
from cmdragons.tracking import Tracker, TrackerParams

__all__ = ["track_detections"]


def track_detections(detections: Path, out: Path, params: TrackerParams, ahead_s: float = 0.0) -> dict[str, int]:
    """Track every frame of ``detections`` (JSONL), writing one world state a line to ``out``,
    predicted ``ahead_s`` past each frame's capture time (s; 0: the estimate at capture time).
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
            world = dataclasses.replace(tracker.step(frames[n], ahead_s), frame_number=n)
            row = {**world.to_dict(), "t_capture": tracker.t, "ahead_s": ahead_s}
            f.write(json.dumps(row, separators=(",", ":"), allow_nan=False) + "\n")
    return {"frames": len(frames), "bad_lines": bad, **tracker.stats.as_dict()}
