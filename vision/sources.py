"""Where camera frames come from: a recording folder, a video file, an image folder or a glob.

A source yields ``(frame_number, image or None)``; None marks a frame that exists but cannot be
read (a corrupt or empty file), so that the caller can count it and go on. A video that breaks
off (truncated, corrupt) yields its frames up to the last good one and then raises
:class:`cmdragons.videoio.VideoError` naming the file and frame.
"""

from __future__ import annotations

import glob
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np
from numpy.typing import NDArray

from cmdragons.camera import CameraModel
from cmdragons.recording import RecordingError, RecordingReader, camera_files
from cmdragons.videoio import read_video

__all__ = ["FrameSizeError", "FrameSource", "SourceError", "open_sources"]

IMAGE_SUFFIXES = {".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff"}
VIDEO_SUFFIXES = {".mp4", ".avi", ".mkv", ".mov", ".webm", ".m4v", ".ts"}
Frame = tuple[int, NDArray[np.uint8] | None]


class SourceError(ValueError):
    """A SOURCE that is none of the kinds ``cmdragons vision`` reads."""


class FrameSizeError(SourceError):
    """A source whose first frame has a size the camera model cannot be scaled to (another aspect
    ratio): one line naming the size found, the size expected and the command that fixes it."""


@dataclass
class FrameSource:
    """One camera's frames; ``camera`` is its model when the source brings one (a recording)."""

    name: str
    camera_id: int
    camera: CameraModel | None
    kind: str
    paths: list[Path]

    def frames(self) -> Iterator[Frame]:
        if self.kind == "video":
            yield from read_video(self.paths[0])
        else:
            for k, path in enumerate(self.paths):
                # recordings name frames by number; other folders count in sorted order
                yield (int(path.stem) if path.stem.isdigit() else k), _image(path)


def _image(path: Path) -> NDArray[np.uint8] | None:
    try:
        if path.stat().st_size == 0:
            return np.zeros((0, 0, 3), dtype=np.uint8)  # empty, not corrupt
        img = cv2.imread(str(path), cv2.IMREAD_COLOR)
    except OSError:
        return None
    return None if img is None else np.asarray(img, dtype=np.uint8)


def _images(paths: list[Path]) -> list[Path]:
    return sorted(p for p in paths if p.suffix.lower() in IMAGE_SUFFIXES)


def open_sources(specs: list[str]) -> tuple[list[FrameSource], Path | None]:
    """The cameras of the SOURCE arguments, and the recording folder if one was given (for its
    truth). A recording brings all its cameras; any other source is one camera, numbered by its
    position among the arguments."""
    out: list[FrameSource] = []
    recording: Path | None = None
    for pos, spec in enumerate(specs):
        path = Path(spec)
        if path.is_dir() and (path / "cameras.yaml").exists():
            try:
                reader = RecordingReader(path)
                recording = path
                for cam in reader.camera_ids:
                    kind, files = camera_files(path, cam)
                    out.append(FrameSource(f"{path.name}/camera_{cam}", cam, reader.camera_model(cam), kind, files))
            except RecordingError as exc:
                raise SourceError(str(exc)) from None
        elif path.is_dir():
            files = _images(list(path.iterdir()))
            if not files:
                raise SourceError(f"{spec}: a folder with no images")
            out.append(FrameSource(spec, pos, None, "images", files))
        elif path.is_file() and path.suffix.lower() in VIDEO_SUFFIXES:
            out.append(FrameSource(spec, pos, None, "video", [path]))
        elif path.is_file() and path.suffix.lower() in IMAGE_SUFFIXES:
            out.append(FrameSource(spec, pos, None, "images", [path]))
        else:
            files = _images([Path(p) for p in glob.glob(spec)])
            if not files:
                raise SourceError(f"{spec}: not a recording, video, image folder or glob that matches images")
            out.append(FrameSource(spec, pos, None, "images", files))
    return out, recording
