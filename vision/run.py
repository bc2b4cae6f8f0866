"""``cmdragons vision SOURCE...``: every camera frame of the sources through the pipeline, into
detections.jsonl (DESIGN.md), optional overlays (each frame with its detections and the fitted field
drawn on it: a PNG per still image, a video per video source or, with ``video``, per camera), and a
summary. The summary's robots and ball count the whole field per capture: the frames of one number
from all cameras.

Frames of another size than the camera model's, at the same aspect ratio, are processed through
the model scaled to them (:func:`cmdragons.camera.scaled_to`); a source whose first frame has
another aspect ratio stops the run before any frame is processed (:class:`FrameSizeError`, one
line: the size found, the size expected, the command that fixes it). A later frame that cannot be
read, is empty or has another size than the first is counted and reported by number; it never
stops the run. A video that breaks off (truncated, corrupt) is processed up to its last good
frame and the break is reported by file and frame.
"""

from __future__ import annotations

import itertools
import json
import time
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import cv2
import numpy as np
from numpy.typing import NDArray

from cmdragons.camera import CameraModel, scaled_to
from cmdragons.geometry import LeagueParams
from cmdragons.messages import DetectionFrame, GroundTruth
from cmdragons.recording import RecordingReader
from cmdragons.videoio import VideoError, VideoWriter
from vision.pipeline import VisionParams, VisionPipeline
from vision.score import Score
from vision.sources import Frame, FrameSizeError, FrameSource, SourceError

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


def field_layer(pipe: VisionPipeline) -> tuple[NDArray[np.uint8], NDArray[np.bool_]]:
    """The field lines of configs/field.yaml drawn through the pipeline's camera model on a black
    image (the fitted field, as calibration draws it), and where they are drawn."""
    from vision.field_lines import draw_field

    layer = draw_field(np.zeros(pipe.shape, np.uint8), pipe.camera.params, pipe.league)
    return layer, np.asarray(layer.any(axis=2), dtype=np.bool_)


def annotate(image: NDArray[np.uint8], pipe: VisionPipeline, det: DetectionFrame,
             field: tuple[NDArray[np.uint8], NDArray[np.bool_]] | None = None) -> NDArray[np.uint8]:  # fmt: skip
    """A copy of ``image`` with the regions' boxes (grey), the fitted field (``field``, from
    :func:`field_layer`), each robot's outline, heading, team, id and confidence (e.g. ``B3 0.97``,
    blue or yellow), and each ball with its confidence (orange)."""
    out = image.copy()
    if field is not None:
        out[field[1]] = field[0][field[1]]
    regions = pipe.last_regions
    if regions is not None:
        for k in range(len(regions)):
            u0, v0, u1, v1 = (int(x) for x in regions.bbox[k])
            cv2.rectangle(out, (u0 - 1, v0 - 1), (u1 + 1, v1 + 1), (200, 200, 200), 1)
    cam, league = pipe.camera, pipe.league
    scale = max(0.4, cam.width / 2000.0)  # text size: legible at any image size
    for r in det.robots:
        z = pipe.heights[r.team]
        c = cam.project_xy(np.array([r.x, r.y]), z)
        tip = cam.project_xy(np.array([r.x + 0.12 * np.cos(r.theta), r.y + 0.12 * np.sin(r.theta)]), z)
        radius = int(round(league.robot.radius_m * cam.pixels_per_metre((r.x, r.y), z)))
        colour = COLOURS_BGR[r.team]
        cu, cv = int(round(c[0])), int(round(c[1]))
        cv2.circle(out, (cu, cv), radius, colour, 1, cv2.LINE_AA)
        cv2.line(out, (cu, cv), (int(round(tip[0])), int(round(tip[1]))), colour, 1, cv2.LINE_AA)
        cv2.putText(out, f"{r.team[0].upper()}{r.id} {r.confidence:.2f}", (cu + radius, cv - radius),
                    cv2.FONT_HERSHEY_SIMPLEX, scale, colour, 1, cv2.LINE_AA)  # fmt: skip
    for b in det.balls:
        bu, bv = int(round(b.pixel[0])), int(round(b.pixel[1]))
        radius = max(4, int(round(2.0 * league.ball.radius_m * cam.pixels_per_metre((b.x, b.y), 0.0))))
        cv2.circle(out, (bu, bv), radius, COLOURS_BGR["ball"], 1, cv2.LINE_AA)
        cv2.putText(out, f"{b.confidence:.2f}", (bu + radius, bv + radius), cv2.FONT_HERSHEY_SIMPLEX, scale,
                    COLOURS_BGR["ball"], 1, cv2.LINE_AA)  # fmt: skip
    return out


def _first_frame(src: FrameSource) -> tuple[Iterator[Frame], NDArray[np.uint8] | None]:
    """The source's frames (the first read ahead and put back) and its first image (None when the
    first frame cannot be read or the source has none)."""
    frames = src.frames()
    try:
        first = next(frames)
    except StopIteration:
        return src.frames(), None
    except VideoError as exc:
        if src.kind == "video":  # a file that is no video at all is bad input, said before any work
            raise SourceError(f"{exc}; give a video file (H.264 .mp4, .mkv, .avi)") from None
        return src.frames(), None  # read again in the run, which reports the break
    image = first[1]
    return itertools.chain([first], frames), image if image is not None and image.size else None


def model_for_frames(src: FrameSource, model: CameraModel, image: NDArray[np.uint8] | None) -> CameraModel:
    """``model`` for the size of the source's first frame ``image``: itself, scaled to it (same
    aspect ratio), or :class:`FrameSizeError` naming the sizes and the command that fixes it."""
    if image is None or image.ndim != 3 or image.shape[2] != 3:
        return model
    h, w = image.shape[:2]
    scaled = scaled_to(model.params, w, h)
    if scaled is not None:
        return model if scaled is model.params else CameraModel(scaled)
    frame = str(src.paths[0]) if src.kind == "images" else "FRAME.png (one frame of it saved as an image)"
    raise FrameSizeError(f"{src.name}: frames are {w}x{h}, camera {model.id}'s model is {model.width}x"
                         f"{model.height} (another aspect ratio, cannot be scaled); calibrate the camera at this "
                         f"size: cmdragons vision calibrate --lines {frame} --camera {model.id}")  # fmt: skip


def run_vision(sources: Sequence[FrameSource], cameras: dict[int, CameraModel], params: VisionParams,
               league: LeagueParams, out: Path, video: bool, fps: float, recording: Path | None = None,
               progress: Callable[[int], None] | None = None, overlay: bool = False) -> RunSummary:  # fmt: skip
    """Process every frame of every source; ``cameras`` gives the model of a source that brings
    none (by its camera id). Writes ``out/detections.jsonl``; with ``video``, and with
    ``overlay`` for a video source, ``out/annotated_camera_<id>.mp4``; with ``overlay`` for still
    images, ``out/overlay/camera_<id>_<frame>.png`` each (:func:`annotate`). With a recording's
    truth, the detections are scored."""
    out.mkdir(parents=True, exist_ok=True)
    summary = RunSummary()
    missing = [s for s in sources if s.camera is None and s.camera_id not in cameras]
    if missing:  # before any frame is processed
        raise SourceError(f"{len(sources)} sources but only {len(cameras)} camera model(s) in the config: "
                          f"{missing[0].name} would be camera {missing[0].camera_id}; give one source per camera "
                          "(or a config whose cameras.yaml lists more)")  # fmt: skip
    # every source's first frame read and its size checked before any frame is processed
    opened = []
    for src in sources:
        frames, first = _first_frame(src)
        opened.append((src, frames, model_for_frames(src, src.camera or cameras[src.camera_id], first)))
    truth: dict[int, GroundTruth] = {}
    if recording is not None:
        reader = RecordingReader(recording)
        truth = {t.frame_number: t for t in reader.truth()}
        if reader.truth_broken:
            summary.broken_off.append(reader.truth_broken)
    score = Score() if truth else None
    with open(out / "detections.jsonl", "w", encoding="utf-8") as jsonl:
        for src, frames, model in opened:
            pipe = VisionPipeline(params, league, model)
            writer: VideoWriter | None = None
            as_video, as_png = video or (overlay and src.kind == "video"), overlay and src.kind != "video"
            field = field_layer(pipe) if as_video or as_png else None
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
                if as_png:
                    (out / "overlay").mkdir(exist_ok=True)
                    cv2.imwrite(str(out / "overlay" / f"camera_{src.camera_id}_{k:06d}.png"),
                                annotate(image, pipe, det, field))  # fmt: skip
                if as_video:
                    # H.264 in 4:2:0 takes even sizes: an odd last column or row is left out
                    w2, h2 = model.width // 2 * 2, model.height // 2 * 2
                    if writer is None:
                        writer = VideoWriter(out / f"annotated_camera_{src.camera_id}.mp4", w2, h2, fps, "h264", 23)
                    writer.write(np.ascontiguousarray(annotate(image, pipe, det, field)[:h2, :w2]))
            if writer is not None:
                writer.close()
    if score is not None:
        summary.score = score.summary()
    (out / "summary.json").write_text(json.dumps(summary.as_dict(), indent=2) + "\n", encoding="utf-8")
    return summary
