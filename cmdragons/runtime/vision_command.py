"""``cmdragons vision SOURCE...`` as a set-up: a table of stages (:func:`vision_wiring`) and the
loop that feeds it (:func:`run_vision`).

Each frame number is one capture: the runtime reads the next frame of every source and publishes
it on ``camera/<id>/frame`` (the sources are the set-up's outside, as a log is a replay's); one
vision stage per camera turns it into ``detections/<id>``; the detections stage writes every
camera's detections into detections.jsonl (DESIGN.md), counts the whole field per capture and scores
them against a recording's truth. With overlays, a camera's vision stage also draws each frame with
its detections and the fitted field (:func:`vision.run.annotate`): a PNG per still image, a video
per video source or, with ``video``, per camera. The summary's robots and ball count the whole
field per capture: the frames of one number from all cameras; its time per frame is the vision
stages' time on their frames (drawing apart).

Frames of another size than the camera model's, at the same aspect ratio, are processed through
the model scaled to them (:func:`cmdragons.camera.scaled_to`); a source whose first frame has
another aspect ratio stops the run before any frame is processed
(:class:`~vision.sources.FrameSizeError`, one line: the size found, the size expected, the command
that fixes it). A later frame that cannot be read, is empty or has another size than the first is
counted and reported by number; it never stops the run. A video that breaks off (truncated,
corrupt) is processed up to its last good frame and the break is reported by file and frame.
"""

from __future__ import annotations

import functools
import json
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import IO, Any

import cv2
import numpy as np
from numpy.typing import NDArray

from cmdragons.camera import CameraModel
from cmdragons.geometry import LeagueParams
from cmdragons.messages import CameraFrame, DetectionFrame, GroundTruth, StageSummary
from cmdragons.recording import RecordingReader
from cmdragons.runtime.bus import BaseStage, Bus, Publish, Stage, run_frames
from cmdragons.runtime.match import Entry, build
from cmdragons.runtime.stages import SummaryCollector, VisionStage
from cmdragons.runtime.topics import Contract, Port, summary_port
from cmdragons.videoio import VideoError, VideoWriter
from vision.pipeline import VisionParams, VisionPipeline
from vision.run import CaptureCount, RunSummary, annotate, field_layer, first_frame, model_for_frames
from vision.score import Score
from vision.sources import Frame, FrameSource, SourceError

__all__ = ["DetectionsOutStage", "OverlaidVisionStage", "run_vision", "vision_wiring"]

DETECTIONS_OUT = "vision_out"


class DetectionsOutStage(BaseStage):
    """Every camera's detections into detections.jsonl, one line each, counted per capture (the
    whole field: any camera's robots, whether any saw the ball) and scored against the truth of a
    recording's frames when there is one."""

    @staticmethod
    def declare(camera_ids: Sequence[int]) -> Contract:
        return Contract(DETECTIONS_OUT, tuple(Port(f"detections/{i}", DetectionFrame) for i in camera_ids),
                        (summary_port(DETECTIONS_OUT),))

    def __init__(self, camera_ids: Sequence[int], jsonl: IO[str], truth: dict[int, GroundTruth]) -> None:
        self.contract = self.declare(camera_ids)
        self.jsonl = jsonl
        self.truth = truth
        self.seen = CaptureCount()
        self.score = Score() if truth else None

    def on_message(self, topic: str, message: Any, publish: Publish) -> None:
        det: DetectionFrame = message
        self.jsonl.write(json.dumps(det.to_dict(), separators=(",", ":")) + "\n")
        self.seen.saw(det)
        if self.score is not None and det.frame_number in self.truth:
            self.score.add(det, self.truth[det.frame_number])

    def summarize(self, publish: Publish) -> None:
        score = self.score.summary() if self.score is not None else None
        publish(f"summary/{self.name}", StageSummary(self.name, {**self.seen.as_dict(), "score": score}))


class OverlaidVisionStage(VisionStage):
    """A camera's vision that also draws what it found: on its own detections it draws the frame
    they came from with them (:func:`~vision.run.annotate`), into ``png_dir`` (one PNG a frame) or
    a video at ``video_path``. The drawing is timed apart from the vision (its own input)."""

    @staticmethod
    def declare_overlaid(camera_id: int) -> Contract:
        c = VisionStage.declare(camera_id)
        return Contract(c.name, (*c.reads, *c.writes), c.writes)

    def __init__(self, camera_id: int, pipeline: VisionPipeline, png_dir: Path | None, video_path: Path | None,
                 fps: float) -> None:
        super().__init__(camera_id, pipeline)
        self.contract = self.declare_overlaid(camera_id)
        self.png_dir, self.video_path, self.fps = png_dir, video_path, fps
        self.field = field_layer(pipeline)
        self.image: NDArray[np.uint8] | None = None
        self.writer: VideoWriter | None = None

    def on_message(self, topic: str, message: Any, publish: Publish) -> None:
        if isinstance(message, CameraFrame):
            self.image = message.image
            super().on_message(topic, message, publish)
            return
        det: DetectionFrame = message
        if self.image is None:
            return
        drawn = annotate(self.image, self.pipeline, det, self.field)
        if self.png_dir is not None:
            self.png_dir.mkdir(exist_ok=True)
            cv2.imwrite(str(self.png_dir / f"camera_{self.camera_id}_{det.frame_number:06d}.png"), drawn)
        if self.video_path is not None:
            # H.264 in 4:2:0 takes even sizes: an odd last column or row is left out
            h2, w2 = drawn.shape[0] // 2 * 2, drawn.shape[1] // 2 * 2
            if self.writer is None:
                self.writer = VideoWriter(self.video_path, w2, h2, self.fps, "h264", 23)
            self.writer.write(np.ascontiguousarray(drawn[:h2, :w2]))

    def close(self) -> None:
        if self.writer is not None:
            self.writer.close()
            self.writer = None


def vision_wiring(cameras: Sequence[tuple[FrameSource, CameraModel]], params: VisionParams, league: LeagueParams,
                  out: Path, jsonl: IO[str], truth: dict[int, GroundTruth], video: bool, overlay: bool,
                  fps: float) -> list[Entry]:
    """The table of ``cmdragons vision``: a vision stage per source's camera (``cameras``: each
    source with its camera model, sized to its frames), drawing overlays where asked (``video``:
    an annotated video per camera; ``overlay``: a video per video source, PNGs per still image),
    and the detections stage writing ``jsonl``."""
    rows = []
    for src, model in cameras:
        as_video, as_png = video or (overlay and src.kind == "video"), overlay and src.kind != "video"
        pipeline = functools.partial(VisionPipeline, params, league, model)
        if as_video or as_png:
            build_stage: Callable[[], Stage] = functools.partial(
                _overlaid, model.id, pipeline, out / "overlay" if as_png else None,
                out / f"annotated_camera_{model.id}.mp4" if as_video else None, fps)
            rows.append(Entry(OverlaidVisionStage.declare_overlaid(model.id), "", build_stage))
        else:
            rows.append(Entry(VisionStage.declare(model.id), "", functools.partial(_plain, model.id, pipeline)))
    ids = [model.id for _, model in cameras]
    rows.append(Entry(DetectionsOutStage.declare(ids), "", functools.partial(DetectionsOutStage, ids, jsonl, truth)))
    return rows


def _plain(camera_id: int, pipeline: Callable[[], VisionPipeline]) -> Stage:
    return VisionStage(camera_id, pipeline())


def _overlaid(camera_id: int, pipeline: Callable[[], VisionPipeline], png_dir: Path | None, video_path: Path | None,
              fps: float) -> Stage:
    return OverlaidVisionStage(camera_id, pipeline(), png_dir, video_path, fps)


def run_vision(sources: Sequence[FrameSource], cameras: dict[int, CameraModel], params: VisionParams,
               league: LeagueParams, out: Path, video: bool, fps: float, recording: Path | None = None,
               progress: Callable[[int], None] | None = None, overlay: bool = False) -> RunSummary:
    """Process every frame of every source through :func:`vision_wiring`'s stages; ``cameras``
    gives the model of a source that brings none (by its camera id). Writes ``out/detections.jsonl``,
    the overlays asked for and ``out/summary.json``; with a recording's truth, the detections are
    scored. ``progress`` is told of every frame read."""
    out.mkdir(parents=True, exist_ok=True)
    summary = RunSummary()
    missing = [s for s in sources if s.camera is None and s.camera_id not in cameras]
    if missing:  # before any frame is processed
        raise SourceError(f"{len(sources)} sources but only {len(cameras)} camera model(s) in the config: "
                          f"{missing[0].name} would be camera {missing[0].camera_id}; give one source per camera "
                          "(or a config whose cameras.yaml lists more)")
    # every source's first frame read and its size checked before any frame is processed
    opened: list[tuple[FrameSource, Iterator[Frame], CameraModel]] = []
    for src in sources:
        frames, first = first_frame(src)
        opened.append((src, frames, model_for_frames(src, src.camera or cameras[src.camera_id], first)))
    ids = [model.id for _, _, model in opened]
    if len(set(ids)) < len(ids):
        raise SourceError(f"two sources are camera {next(i for i in ids if ids.count(i) > 1)}: give one source per "
                          "camera")
    truth: dict[int, GroundTruth] = {}
    if recording is not None:
        reader = RecordingReader(recording)
        truth = {t.frame_number: t for t in reader.truth()}
        if reader.truth_broken:
            summary.broken_off.append(reader.truth_broken)
    collector = SummaryCollector()
    with open(out / "detections.jsonl", "w", encoding="utf-8") as jsonl:
        table = vision_wiring([(src, model) for src, _, model in opened], params, league, out, jsonl, truth, video,
                              overlay, fps)
        frame_ports = [Port(f"camera/{i}/frame", CameraFrame) for i in ids]
        bus = Bus()
        stages = build(table, [collector], outside=frame_ports)
        for stage in stages:
            bus.add(stage)
        bus.start()
        feeds = {model.id: (src, frames, model) for src, frames, model in opened}
        live = set(ids)

        def capture(_i: int) -> None:
            for cid in sorted(live):
                src, frames, model = feeds[cid]
                item = _next_frame(src, frames, summary)
                if item is None:
                    live.discard(cid)
                    continue
                k, image = item
                summary.frames += 1
                if progress is not None:
                    progress(1)
                where = f"{src.name}#{k}"
                if image is None:
                    summary.unreadable.append(where)
                elif image.size == 0:
                    summary.empty.append(where)
                elif image.shape != (model.height, model.width, 3):
                    summary.wrong_size.append(where)
                else:
                    bus.publish(f"camera/{cid}/frame", CameraFrame(cid, k, k / fps, image))
            bus.spin()
            times = bus.take_times()
            summary.ms += [times[key] for cid in ids if (key := f"vision/{cid}:camera/{cid}/frame") in times]

        try:
            run_frames(capture, 2**62, should_stop=lambda: not live)
        finally:
            for stage in stages:
                if isinstance(stage, OverlaidVisionStage):
                    stage.close()
        bus.summarize()
    seen = collector.figures[DETECTIONS_OUT]
    summary.captures, summary.robots_per_capture = seen["captures"], seen["robots_per_capture"]
    summary.ball_seen_share, summary.score = seen["ball_seen_share"], seen["score"]
    (out / "summary.json").write_text(json.dumps(summary.as_dict(), indent=2) + "\n", encoding="utf-8")
    return summary


def _next_frame(src: FrameSource, frames: Iterator[Frame], summary: RunSummary) -> Frame | None:
    """The source's next frame, or None at its end (a video that breaks off is noted and ends)."""
    try:
        return next(frames)
    except StopIteration:
        return None
    except VideoError as exc:
        summary.broken_off.append(f"{exc}; the frames before it were processed")
        return None
