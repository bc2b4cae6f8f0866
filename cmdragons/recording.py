"""Recordings on disk: what ``cmdragons sim --record`` writes and ``cmdragons vision`` reads.

A recording is a folder with, per camera, ``camera_<id>.mp4`` (H.264), ``camera_<id>.mkv``
(FFV1, lossless) or ``camera_<id>/<frame>.png`` (lossless), ``cameras.yaml`` (the camera models
used, loadable as configs/cameras.yaml with ``layout: list``, and under ``recording`` the codec and
quality the frames were written with) and ``truth.jsonl`` (one :class:`GroundTruth` a line) where
the truth is known.
"""

from __future__ import annotations

import json
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import IO

import cv2
import numpy as np
import yaml
from numpy.typing import NDArray

from cmdragons.camera import CameraModel, CameraParams, CamerasParams, RecordingParams
from cmdragons.config import ConfigError, load_yaml, parse, to_plain
from cmdragons.messages import GroundTruth, MessageError
from cmdragons.videoio import VideoError, VideoWriter, read_video

__all__ = ["RecordingError", "RecordingReader", "RecordingWriter", "camera_files"]

SUFFIX = {"h264": ".mp4", "ffv1": ".mkv"}


class RecordingError(RuntimeError):
    """A recording folder that cannot be written or read."""


def camera_files(folder: Path, cam: int) -> tuple[str, list[Path]]:
    """Where a recording keeps camera ``cam``'s frames: ``("video", [file])`` or
    ``("images", [png, ...])`` in frame order; RecordingError when it has none."""
    for suffix in (".mp4", ".mkv"):
        video = folder / f"camera_{cam}{suffix}"
        if video.exists():
            return "video", [video]
    images = folder / f"camera_{cam}"
    if images.is_dir():
        return "images", sorted(images.glob("*.png"))
    raise RecordingError(f"{folder}: no frames for camera {cam}")


class RecordingWriter:
    """Writes frames of every camera and their truth into ``folder``, encoded as ``params`` says."""

    def __init__(self, folder: str | Path, cameras: Sequence[CameraModel], fps: float,
                 params: RecordingParams | None = None) -> None:
        self.folder = Path(folder)
        self.folder.mkdir(parents=True, exist_ok=True)
        params = params or RecordingParams()
        self.params, self.fps = params, fps
        self.cameras = {c.id: c for c in cameras}
        meta = CamerasParams(layout="list", cameras=tuple(c.params for c in cameras), recording=params)
        with open(self.folder / "cameras.yaml", "w", encoding="utf-8") as f:
            f.write(f"# written by cmdragons sim --record: the camera models and how the frames are stored "
                    f"({params.codec}{f', crf {params.crf}' if params.codec == 'h264' else ''})\n")
            yaml.safe_dump(to_plain(meta), f, sort_keys=False)
        self._videos: dict[int, VideoWriter] = {}
        self._truth: IO[str] = open(self.folder / "truth.jsonl", "w", encoding="utf-8")  # noqa: SIM115
        self.frames = 0

    def write(self, frame_number: int, images: dict[int, NDArray[np.uint8]], truth: GroundTruth | None) -> None:
        codec = self.params.codec
        for cam, image in images.items():
            if codec == "png":
                d = self.folder / f"camera_{cam}"
                d.mkdir(exist_ok=True)
                if not cv2.imwrite(str(d / f"{frame_number:06d}.png"), image):
                    raise RecordingError(f"could not write a PNG frame into {d}")
                continue
            video = self._videos.get(cam)
            if video is None:
                h, w = image.shape[:2]
                try:
                    video = VideoWriter(self.folder / f"camera_{cam}{SUFFIX[codec]}", w, h, self.fps, codec,
                                        self.params.crf if codec == "h264" else None)
                except VideoError as exc:
                    raise RecordingError(str(exc)) from None
                self._videos[cam] = video
            video.write(image)
        if truth is not None:
            self._truth.write(json.dumps(truth.to_dict(), separators=(",", ":")) + "\n")
        self.frames += 1

    def close(self) -> None:
        for video in self._videos.values():
            video.close()
        self._videos.clear()
        self._truth.close()

    def __enter__(self) -> RecordingWriter:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class RecordingReader:
    """Reads a recording folder back, camera by camera and frame by frame."""

    def __init__(self, folder: str | Path) -> None:
        self.folder = Path(folder)
        if not self.folder.is_dir():
            raise RecordingError(f"{self.folder}: not a recording folder")
        try:
            params = parse(CamerasParams, load_yaml(self.folder / "cameras.yaml"), file=self.folder / "cameras.yaml")
        except ConfigError as exc:
            raise RecordingError(str(exc)) from None
        self.camera_params: dict[int, CameraParams] = {c.id: c for c in params.cameras}
        self.camera_ids = sorted(self.camera_params)
        self.recording = params.recording
        self.truth_broken: str | None = None  # where truth.jsonl broke off, once read

    def camera_model(self, cam: int) -> CameraModel:
        return CameraModel(self.camera_params[cam])

    def frames(self, cam: int) -> Iterator[NDArray[np.uint8]]:
        """The camera's frames in order (BGR uint8); a video that breaks off raises
        :class:`VideoError` after its last good frame."""
        kind, paths = camera_files(self.folder, cam)
        if kind == "video":
            for _, image in read_video(paths[0]):
                yield image
            return
        for path in paths:
            read = cv2.imread(str(path), cv2.IMREAD_COLOR)
            if read is None:
                raise RecordingError(f"{path}: cannot be read as an image")
            yield np.asarray(read, dtype=np.uint8)

    def truth(self) -> Iterator[GroundTruth]:
        """The recording's truth, a frame a line. A last line cut off (a recording that was
        stopped) ends it, with :attr:`truth_broken` saying where; a bad line before the last is a
        :class:`RecordingError` naming the file and line."""
        path = self.folder / "truth.jsonl"
        if not path.exists():
            return
        with open(path, encoding="utf-8") as f:
            lines = f.readlines()
        for k, line in enumerate(lines, start=1):
            if not line.strip():
                continue
            try:
                yield GroundTruth.from_dict(json.loads(line))
            except (json.JSONDecodeError, MessageError) as exc:
                if k == len(lines):
                    self.truth_broken = f"{path}: line {k} is cut off; the truth of the frames before it is used"
                    return
                raise RecordingError(f"{path}: line {k} is not a frame's truth ({exc}); mend or remove that line"
                                     ) from None
