"""``cmdragons vision SOURCE...``: every camera frame of the sources through the pipeline, into
detections.jsonl (DESIGN.md), an optional annotated video per camera, and a summary. The summary's
robots and ball count the whole field per capture: the frames of one number from all cameras.

A frame that cannot be read, is empty or has the wrong size is counted and reported by number; it
never stops the run. A video that breaks off (truncated, corrupt) is processed up to its last good
frame and the break is reported by file and frame.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import cv2
import numpy as np
from numpy.typing import NDArray

from cmdragons.camera import CameraModel
from cmdragons.geometry import LeagueParams
from cmdragons.messages import DetectionFrame, GroundTruth
from cmdragons.recording import RecordingReader
from cmdragons.videoio import VideoError, VideoWriter
from vision.pipeline import VisionParams, VisionPipeline
from vision.score import Score
from vision.sources import FrameSource, SourceError

__all__ = ["RunSummary", "annotate", "run_vision"]


@dataclass
class RunSummary:
    frames: int = 0
    unreadable: list[str] = field(default_factory=list)  # "<source>#<frame>"
    empty: list[str] = field(default_factory=list)
    wrong_size: list[str] = field(default_factory=list)
    broken_off: list[str] = field(default_factory=list)  # a video's message: file, first frame not read
    # the whole field per capture (the frames of one number from all cameras): the robots any camera
    # saw, and whether any saw the ball (a camera sees part of the field: its own counts read as misses)
    robots_seen: dict[int, set[tuple[str, int]]] = field(default_factory=dict)
    ball_seen: dict[int, bool] = field(default_factory=dict)
    ms: list[float] = field(default_factory=list)
    score: dict[str, float] | None = None

    def saw(self, det: DetectionFrame) -> None:
        """Count one camera's detections into its capture's whole-field figures."""
        self.robots_seen.setdefault(det.frame_number, set()).update((r.team, r.id) for r in det.robots)
        self.ball_seen[det.frame_number] = self.ball_seen.get(det.frame_number, False) or bool(det.balls)

    def as_dict(self) -> dict[str, Any]:
        n = max(1, len(self.ball_seen))
        return {
            "frames": self.frames,
            "captures": len(self.ball_seen),
            "bad_frames": {"unreadable": self.unreadable, "empty": self.empty, "wrong_size": self.wrong_size},
            "broken_off": self.broken_off,
            "robots_per_capture": sum(len(r) for r in self.robots_seen.values()) / n,
            "ball_seen_share": sum(self.ball_seen.values()) / n,
            "ms_per_frame": {
                "median": float(np.median(self.ms)) if self.ms else None,
                "p95": float(np.percentile(self.ms, 95)) if self.ms else None,
            },  # fmt: skip
            "score": self.score,
        }


COLOURS_BGR = {"blue": (255, 160, 0), "yellow": (0, 230, 255), "ball": (0, 140, 255)}


def annotate(image: NDArray[np.uint8], pipe: VisionPipeline, det: DetectionFrame) -> NDArray[np.uint8]:
    """A copy of ``image`` with the regions' boxes, each robot's pattern circle, heading and id,
    and the ball."""
    out = image.copy()
    regions = pipe.last_regions
    if regions is not None:
        for k in range(len(regions)):
            u0, v0, u1, v1 = (int(x) for x in regions.bbox[k])
            cv2.rectangle(out, (u0 - 1, v0 - 1), (u1 + 1, v1 + 1), (200, 200, 200), 1)
    cam, league = pipe.camera, pipe.league
    for r in det.robots:
        z = pipe.heights[r.team]
        c = cam.project_xy(np.array([r.x, r.y]), z)
        tip = cam.project_xy(np.array([r.x + 0.12 * np.cos(r.theta), r.y + 0.12 * np.sin(r.theta)]), z)
        radius = int(round(league.robot.radius_m * cam.pixels_per_metre((r.x, r.y), z)))
        colour = COLOURS_BGR[r.team]
        cv2.circle(out, (int(c[0]), int(c[1])), radius, colour, 1, cv2.LINE_AA)
        cv2.line(out, (int(c[0]), int(c[1])), (int(tip[0]), int(tip[1])), colour, 1, cv2.LINE_AA)
        cv2.putText(out, str(r.id), (int(c[0]) + radius, int(c[1]) - radius), cv2.FONT_HERSHEY_SIMPLEX, 0.5, colour,
                    1, cv2.LINE_AA)  # fmt: skip
    for b in det.balls:
        cv2.circle(out, (int(b.pixel[0]), int(b.pixel[1])), 8, COLOURS_BGR["ball"], 1, cv2.LINE_AA)
    return out


def run_vision(sources: Sequence[FrameSource], cameras: dict[int, CameraModel], params: VisionParams,
               league: LeagueParams, out: Path, video: bool, fps: float, recording: Path | None = None,
               progress: Callable[[int], None] | None = None) -> RunSummary:  # fmt: skip
    """Process every frame of every source; ``cameras`` gives the model of a source that brings
    none (by its camera id). Writes ``out/detections.jsonl`` and, with ``video``,
    ``out/annotated_camera_<id>.mp4``. With a recording's truth, the detections are scored."""
    out.mkdir(parents=True, exist_ok=True)
    summary = RunSummary()
    missing = [s for s in sources if s.camera is None and s.camera_id not in cameras]
    if missing:  # before any frame is processed
        raise SourceError(f"{len(sources)} sources but only {len(cameras)} camera model(s) in the config: "
                          f"{missing[0].name} would be camera {missing[0].camera_id}; give one source per camera "
                          "(or a config whose cameras.yaml lists more)")  # fmt: skip
    for src in sources:  # a file that is no video at all is bad input, said before any work
        if src.kind == "video":
            frames = src.frames()
            try:
                next(frames, None)
            except VideoError as exc:
                raise SourceError(f"{exc}; give a video file (H.264 .mp4, .mkv, .avi)") from None
            finally:
                frames.close()
    truth: dict[int, GroundTruth] = {}
    if recording is not None:
        reader = RecordingReader(recording)
        truth = {t.frame_number: t for t in reader.truth()}
        if reader.truth_broken:
            summary.broken_off.append(reader.truth_broken)
    score = Score() if truth else None
    with open(out / "detections.jsonl", "w", encoding="utf-8") as jsonl:
        for src in sources:
            model = src.camera or cameras[src.camera_id]
            pipe = VisionPipeline(params, league, model)
            writer: VideoWriter | None = None
            frames = src.frames()
            while True:
                try:
                    k, image = next(frames)
                except StopIteration:
                    break
                except VideoError as exc:
                    summary.broken_off.append(f"{exc}; the frames before it were processed")
                    break
                where = f"{src.name}#{k}"
                summary.frames += 1
                if progress is not None:
                    progress(1)
                if image is None:
                    summary.unreadable.append(where)
                    continue
                if image.size == 0:
                    summary.empty.append(where)
                    continue
                if image.shape != pipe.shape:
                    summary.wrong_size.append(where)
                    continue
                t_capture = k / fps
                t0 = time.perf_counter()
                det = pipe.process(image, k, t_capture)
                summary.ms.append((time.perf_counter() - t0) * 1e3)
                summary.saw(det)
                jsonl.write(json.dumps(det.to_dict(), separators=(",", ":")) + "\n")
                if score is not None and k in truth:
                    score.add(det, truth[k])
                if video:
                    # H.264 in 4:2:0 takes even sizes: an odd last column or row is left out
                    w2, h2 = model.width // 2 * 2, model.height // 2 * 2
                    if writer is None:
                        writer = VideoWriter(out / f"annotated_camera_{src.camera_id}.mp4", w2, h2, fps, "h264", 23)
                    writer.write(np.ascontiguousarray(annotate(image, pipe, det)[:h2, :w2]))
            if writer is not None:
                writer.close()
    if score is not None:
        summary.score = score.summary()
    (out / "summary.json").write_text(json.dumps(summary.as_dict(), indent=2) + "\n", encoding="utf-8")
    return summary
