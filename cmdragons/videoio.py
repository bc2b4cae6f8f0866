"""Video files through PyAV: H.264 (yuv420p, what browsers play) or lossless FFV1.

``VideoWriter(path, width, height, fps, codec="h264" | "ffv1", crf=None)`` takes BGR uint8
frames of (height, width, 3); ``close()`` (or leaving the ``with`` block) flushes the encoder and
writes the container's index, so the file is complete and seekable.
"""

from __future__ import annotations

from fractions import Fraction
from pathlib import Path
from types import TracebackType
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

__all__ = ["VideoWriter"]

Codec = Literal["h264", "ffv1"]


class VideoWriter:
    """One video stream into ``path`` (.mp4 for H.264, .mkv for FFV1)."""

    def __init__(self, path: str | Path, width: int, height: int, fps: float, codec: Codec = "h264",
                 crf: int | None = None) -> None:  # fmt: skip
        import av

        if codec not in ("h264", "ffv1"):
            raise ValueError(f"codec must be h264 or ffv1, not {codec!r}")
        if codec == "h264" and (width % 2 or height % 2):
            raise ValueError(f"H.264 in yuv420p needs an even width and height, not {width}x{height}")
        if not (fps > 0):
            raise ValueError(f"fps must be positive, not {fps}")
        self.path = Path(path)
        self.width, self.height = int(width), int(height)
        self._container: Any = av.open(str(self.path), mode="w")
        rate = Fraction(fps).limit_denominator(1001)
        if codec == "h264":
            options = {"crf": str(23 if crf is None else int(crf)), "preset": "veryfast"}
            self._stream: Any = self._container.add_stream("libx264", rate=rate, options=options)
            self._stream.pix_fmt = "yuv420p"
        else:
            self._stream = self._container.add_stream("ffv1", rate=rate)
            self._stream.pix_fmt = "bgr0"
        self._stream.width, self._stream.height = self.width, self.height
        self._av = av
        self.frames = 0

    def write(self, bgr: NDArray[np.uint8]) -> None:
        """Append one frame, BGR uint8 (height, width, 3)."""
        if bgr.shape != (self.height, self.width, 3) or bgr.dtype != np.uint8:
            raise ValueError(f"a frame must be uint8 of shape {(self.height, self.width, 3)}, not {bgr.dtype} "
                             f"{bgr.shape}")  # fmt: skip
        frame = self._av.VideoFrame.from_ndarray(np.ascontiguousarray(bgr), format="bgr24")
        for packet in self._stream.encode(frame):
            self._container.mux(packet)
        self.frames += 1

    def close(self) -> None:
        if self._container is None:
            return
        for packet in self._stream.encode():
            self._container.mux(packet)
        self._container.close()
        self._container = None

    def __enter__(self) -> VideoWriter:
        return self

    def __exit__(self, kind: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None) -> None:
        self.close()
