"""What ``cmdragons vision SOURCE...`` needs of vision: a run's figures (:class:`RunSummary`,
:class:`CaptureCount`), a frame drawn with its detections and the fitted field (:func:`annotate`),
and each source's camera model checked against its first frame (:func:`model_for_frames`). The
command's stages and loop are :mod:`cmdragons.runtime.vision_command`.
"""

from __future__ import annotations

import itertools
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any

import cv2
import numpy as np
from numpy.typing import NDArray

from cmdragons.camera import CameraModel, scaled_to
from cmdragons.messages import DetectionFrame
from cmdragons.videoio import VideoError
from vision.pipeline import VisionPipeline
from vision.sources import Frame, FrameSizeError, FrameSource, SourceError

__all__ = ["CaptureCount", "RunSummary", "annotate", "field_layer", "first_frame", "model_for_frames"]


@dataclass
class CaptureCount:
    """The whole field per capture (the frames of one number from all cameras): the robots any
    camera saw, and whether any saw the ball (a camera sees part of the field: its own counts read
    as misses)."""

    robots_seen: dict[int, set[tuple[str, int]]] = field(default_factory=dict)
    ball_seen: dict[int, bool] = field(default_factory=dict)

    def saw(self, det: DetectionFrame) -> None:
        """Count one camera's detections into its capture's whole-field figures."""
        self.robots_seen.setdefault(det.frame_number, set()).update((r.team, r.id) for r in det.robots)
        self.ball_seen[det.frame_number] = self.ball_seen.get(det.frame_number, False) or bool(det.balls)

    def as_dict(self) -> dict[str, Any]:
        n = max(1, len(self.ball_seen))
        return {"captures": len(self.ball_seen),
                "robots_per_capture": sum(len(r) for r in self.robots_seen.values()) / n,
                "ball_seen_share": sum(self.ball_seen.values()) / n}  # fmt: skip


@dataclass
class RunSummary:
    """What a run of ``cmdragons vision`` did: frames read, the bad ones by where they are, the
    whole field per capture (:class:`CaptureCount`'s figures), vision's time per frame (ms) and
    the score against a recording's truth."""

    frames: int = 0
    unreadable: list[str] = field(default_factory=list)  # "<source>#<frame>"
    empty: list[str] = field(default_factory=list)
    wrong_size: list[str] = field(default_factory=list)
    broken_off: list[str] = field(default_factory=list)  # a video's message: file, first frame not read
    captures: int = 0
    robots_per_capture: float = 0.0
    ball_seen_share: float = 0.0
    ms: list[float] = field(default_factory=list)
    score: dict[str, float] | None = None

    def as_dict(self) -> dict[str, Any]:
        return {
            "frames": self.frames,
            "captures": self.captures,
            "bad_frames": {"unreadable": self.unreadable, "empty": self.empty, "wrong_size": self.wrong_size},
            "broken_off": self.broken_off,
            "robots_per_capture": self.robots_per_capture,
            "ball_seen_share": self.ball_seen_share,
            "ms_per_frame": {"median": float(np.median(self.ms)) if self.ms else None,
                             "p95": float(np.percentile(self.ms, 95)) if self.ms else None},
            "score": self.score,
        }  # fmt: skip


COLOURS_BGR = {"blue": (255, 160, 0), "yellow": (0, 230, 255), "ball": (0, 140, 255)}


def field_layer(pipe: VisionPipeline) -> tuple[NDArray[np.uint8], NDArray[np.bool_]]:
    """The field lines of configs/field.yaml drawn through the pipeline's camera model on a black
    image (the fitted field, as calibration draws it), and where they are drawn."""
    from vision.field_lines import draw_field

    layer = draw_field(np.zeros(pipe.shape, np.uint8), pipe.camera.params, pipe.league)
    return layer, np.asarray(layer.any(axis=2), dtype=np.bool_)


def annotate(image: NDArray[np.uint8], pipe: VisionPipeline, det: DetectionFrame,
             field: tuple[NDArray[np.uint8], NDArray[np.bool_]] | None = None) -> NDArray[np.uint8]:
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
                    cv2.FONT_HERSHEY_SIMPLEX, scale, colour, 1, cv2.LINE_AA)
    for b in det.balls:
        bu, bv = int(round(b.pixel[0])), int(round(b.pixel[1]))
        radius = max(4, int(round(2.0 * league.ball.radius_m * cam.pixels_per_metre((b.x, b.y), 0.0))))
        cv2.circle(out, (bu, bv), radius, COLOURS_BGR["ball"], 1, cv2.LINE_AA)
        cv2.putText(out, f"{b.confidence:.2f}", (bu + radius, bv + radius), cv2.FONT_HERSHEY_SIMPLEX, scale,
                    COLOURS_BGR["ball"], 1, cv2.LINE_AA)
    return out


def first_frame(src: FrameSource) -> tuple[Iterator[Frame], NDArray[np.uint8] | None]:
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
                         f"size: cmdragons vision calibrate --lines {frame} --camera {model.id}")
