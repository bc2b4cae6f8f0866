"""Recordings on disk: what ``cmdragons sim --record`` writes and ``cmdragons vision`` reads.

A recording is a folder with, per camera, ``camera_<id>.mp4`` (or ``camera_<id>/<frame>.png``,
lossless), ``cameras.yaml`` (the camera models used, loadable as configs/cameras.yaml with
``layout: list``) and ``truth.jsonl`` (one :class:`GroundTruth` a line) where the truth is known.
"""

from __future__ import annotations

import json
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import IO, Literal

import cv2
import numpy as np
import yaml
from numpy.typing import NDArray

from cmdragons.camera import CameraModel, CameraParams, CamerasParams
from cmdragons.config import ConfigError, load_yaml, parse, to_plain
from cmdragons.messages import GroundTruth

__all__ = ["RecordingError", "RecordingReader", "RecordingWriter"]

VideoFormat = Literal["mp4", "png"]


class RecordingError(RuntimeError):
    """A recording folder that cannot be written or read."""


class RecordingWriter:
    """Writes frames of every camera and their truth into ``folder``."""

    def __init__(self, folder: str | Path, cameras: Sequence[CameraModel], fps: float,
                 fmt: VideoFormat = "mp4") -> None:  # fmt: skip
        self.folder = Path(folder)
        self.folder.mkdir(parents=True, exist_ok=True)
        self.fmt, self.fps = fmt, fps
        self.cameras = {c.id: c for c in cameras}
        params = CamerasParams(layout="list", cameras=tuple(c.params for c in cameras))
        with open(self.folder / "cameras.yaml", "w", encoding="utf-8") as f:
            yaml.safe_dump(to_plain(params), f, sort_keys=False)
        self._videos: dict[int, cv2.VideoWriter] = {}
        self._truth: IO[str] = open(self.folder / "truth.jsonl", "w", encoding="utf-8")  # noqa: SIM115
        self.frames = 0

    def write(self, frame_number: int, images: dict[int, NDArray[np.uint8]], truth: GroundTruth | None) -> None:
        for cam, image in images.items():
            if self.fmt == "png":
                d = self.folder / f"camera_{cam}"
                d.mkdir(exist_ok=True)
                if not cv2.imwrite(str(d / f"{frame_number:06d}.png"), image):
                    raise RecordingError(f"could not write a PNG frame into {d}")
                continue
            video = self._videos.get(cam)
            if video is None:
                h, w = image.shape[:2]
                path = str(self.folder / f"camera_{cam}.mp4")
                video = cv2.VideoWriter(path, cv2.VideoWriter.fourcc(*"mp4v"), self.fps, (w, h))
                if not video.isOpened():
                    raise RecordingError(f"could not open {path} for writing (codec mp4v)")
                self._videos[cam] = video
            video.write(image)
        if truth is not None:
            self._truth.write(json.dumps(truth.to_dict(), separators=(",", ":")) + "\n")
        self.frames += 1

    def close(self) -> None:
        for video in self._videos.values():
            video.release()
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

    def camera_model(self, cam: int) -> CameraModel:
        return CameraModel(self.camera_params[cam])

    def frames(self, cam: int) -> Iterator[NDArray[np.uint8]]:
        """The camera's frames in order (BGR uint8)."""
        video = self.folder / f"camera_{cam}.mp4"
        if video.exists():
            cap = cv2.VideoCapture(str(video))
            if not cap.isOpened():
                raise RecordingError(f"{video}: cannot be opened as a video")
            try:
                while True:
                    ok, image = cap.read()
                    if not ok:
                        return
                    yield np.asarray(image, dtype=np.uint8)
            finally:
                cap.release()
        folder = self.folder / f"camera_{cam}"
        if not folder.is_dir():
            raise RecordingError(f"{self.folder}: no frames for camera {cam}")
        for path in sorted(folder.glob("*.png")):
            read = cv2.imread(str(path), cv2.IMREAD_COLOR)
            if read is None:
                raise RecordingError(f"{path}: cannot be read as an image")
            yield np.asarray(read, dtype=np.uint8)

    def truth(self) -> Iterator[GroundTruth]:
        path = self.folder / "truth.jsonl"
        if not path.exists():
            return
        with open(path, encoding="utf-8") as f:
            for line in f:
                if line.strip():
                    yield GroundTruth.from_dict(json.loads(line))
